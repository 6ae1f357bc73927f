//! Eigenvalues of the models' state matrices: balanced, with a bounded QR iteration (a
//! matrix the iteration does not reduce gives an error, not a hang), robust 2x2 blocks.

use nalgebra::{Complex, DMatrix};

/// Most QR iterations the eigenvalue solver may take, per eigenvalue of the matrix: far beyond
/// what a balanced state matrix needs (a few per eigenvalue), so reaching it means the
/// iteration does not converge (it then ends with [`eigenvalues`] returning `None` instead of
/// running for ever).
const QR_ITERATIONS_PER_EIGENVALUE: usize = 100;

/// Damping ratio -re / |lambda| of an eigenvalue (negative = unstable; 0 at lambda = 0).
pub fn damping_ratio(l: Complex<f64>) -> f64 {
    let n = l.norm();
    if n > 0.0 {
        -l.re / n
    } else {
        0.0
    }
}

/// Eigenvalues of a real square matrix, `None` when the QR iteration does not converge (or the
/// matrix holds a value that is not finite). The matrix is balanced first (diagonal scaling by
/// powers of two, as LAPACK's `dgebal` does, so no rounding is introduced): a state matrix with
/// a stiff element (a Maxwell damper's mounting of 10 GN/m beside masses of tonnes) has rows
/// and columns of very different norms, and unbalanced the QR iteration loses the slow,
/// hunting eigenvalues to the fast ones' rounding. nalgebra's Schur iteration can stall on a
/// matrix whose transpose it reduces at once (same eigenvalues), so that is tried second; the
/// eigenvalues of the 2x2 blocks are taken here, as nalgebra gives NaN for a block of two
/// equal real eigenvalues.
pub fn eigenvalues(a: &DMatrix<f64>) -> Option<Vec<Complex<f64>>> {
    if !a.is_square() || a.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let mut b = a.clone();
    balance(&mut b);
    let limit = QR_ITERATIONS_PER_EIGENVALUE * b.nrows().max(1);
    let schur = nalgebra::linalg::Schur::try_new(b.clone(), f64::EPSILON, limit)
        .or_else(|| nalgebra::linalg::Schur::try_new(b.transpose(), f64::EPSILON, limit))?;
    let values = quasi_triangular_eigenvalues(&schur.unpack().1);
    values
        .iter()
        .all(|l| l.re.is_finite() && l.im.is_finite())
        .then_some(values)
}

/// Eigenvalues of a real quasi-upper-triangular matrix (a real Schur form): its 1x1 diagonal
/// entries and the pairs of its 2x2 diagonal blocks.
fn quasi_triangular_eigenvalues(t: &DMatrix<f64>) -> Vec<Complex<f64>> {
    let n = t.nrows();
    let mut out = Vec::with_capacity(n);
    let mut i = 0;
    while i < n {
        if i + 1 < n && t[(i + 1, i)] != 0.0 {
            let (a, b, c, d) = (t[(i, i)], t[(i, i + 1)], t[(i + 1, i)], t[(i + 1, i + 1)]);
            let mean = 0.5 * (a + d);
            let half_diff = 0.5 * (a - d);
            // (a - d)^2 / 4 + b c without cancellation in the common case of b c < 0
            let disc = half_diff * half_diff + b * c;
            if disc >= 0.0 {
                let r = disc.sqrt();
                out.push(Complex::new(mean + r, 0.0));
                out.push(Complex::new(mean - r, 0.0));
            } else {
                let w = (-disc).sqrt();
                out.push(Complex::new(mean, w));
                out.push(Complex::new(mean, -w));
            }
            i += 2;
        } else {
            out.push(Complex::new(t[(i, i)], 0.0));
            i += 1;
        }
    }
    out
}

/// Balances `a` in place: scales row i by 1/d_i and column i by d_i (a similarity transform,
/// same eigenvalues) until each row's and column's off-diagonal 1-norms are within a factor of
/// two (Parlett and Reinsch 1969; LAPACK `dgebal`, scaling step).
fn balance(a: &mut DMatrix<f64>) {
    const RADIX: f64 = 2.0;
    let n = a.nrows();
    // each pass changes a scale by a factor of at least 2; 64 passes per element bound the
    // loop for any finite matrix
    for _ in 0..64 * n.max(1) {
        let mut converged = true;
        for i in 0..n {
            let mut c = 0.0;
            let mut r = 0.0;
            for j in 0..n {
                if j != i {
                    c += a[(j, i)].abs();
                    r += a[(i, j)].abs();
                }
            }
            if c == 0.0 || r == 0.0 {
                continue;
            }
            let s = c + r;
            let mut f = 1.0;
            let mut cc = c;
            let mut rr = r;
            while cc < rr / RADIX {
                cc *= RADIX;
                rr /= RADIX;
                f *= RADIX;
            }
            while cc >= rr * RADIX {
                cc /= RADIX;
                rr *= RADIX;
                f /= RADIX;
            }
            if (cc + rr) < 0.95 * s {
                converged = false;
                for j in 0..n {
                    a[(i, j)] /= f;
                }
                for j in 0..n {
                    a[(j, i)] *= f;
                }
            }
        }
        if converged {
            break;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sorted(mut v: Vec<Complex<f64>>) -> Vec<Complex<f64>> {
        v.sort_by(|a, b| a.re.total_cmp(&b.re).then(a.im.total_cmp(&b.im)));
        v
    }

    #[test]
    fn a_badly_scaled_matrix_keeps_its_slow_eigenvalues() {
        // a lightly damped oscillator (about 1 rad/s) coupled to two fast first-order states,
        // then scaled by the similarity diag(1e-10, 1, 1e10, 1e20): same eigenvalues, rows of
        // norms 20 orders apart. Unbalanced, the QR iteration moves the slow pair's real
        // part by 2 % (-0.005097 against -0.004998); balanced, it keeps 9 digits.
        let a = DMatrix::from_row_slice(
            4,
            4,
            &[
                0.0, 1.0, 0.0, 0.0, -1.0, -0.02, 1.0, 0.5, 0.0, 1.0, -100.0, 2.0, 0.3, 0.0, 1.0,
                -1e3,
            ],
        );
        let d = [1e-10, 1.0, 1e10, 1e20];
        let scaled = DMatrix::from_fn(4, 4, |i, j| a[(i, j)] * d[j] / d[i]);
        let exact = sorted(eigenvalues(&a).unwrap());
        let ev = sorted(eigenvalues(&scaled).unwrap());
        for (x, y) in exact.iter().zip(&ev) {
            assert!(
                (x - y).norm() < 1e-9 * x.norm().max(1.0),
                "{exact:?} {ev:?}"
            );
        }
        let slow = ev.iter().find(|l| l.im > 0.5).unwrap();
        assert!((slow.re + 0.004_997_508).abs() < 1e-9, "{slow:?}");
    }

    #[test]
    fn a_block_of_two_real_eigenvalues_gives_them() {
        // the 2x2 block nalgebra's Schur form of the coach kept for two equal rates of
        // 200 1/s (a Kelvin-Voigt damper of 10 GN/m on a mounting of 10 GN/m): its
        // discriminant is +1e-27, and nalgebra's complex_eigenvalues, which takes every block
        // as a complex pair, gives it NaN imaginary parts
        let block = DMatrix::from_row_slice(
            2,
            2,
            &[
                -2.000_000_000_000_002e2,
                1.164_267_819_329_932e-13,
                -1.339_787_225_039_945e-13,
                -1.999_999_999_999_999_4e2,
            ],
        );
        for l in quasi_triangular_eigenvalues(&block) {
            assert!((l.re + 200.0).abs() < 1e-9 && l.im.abs() < 1e-9, "{l:?}");
        }
        // a block with two distinct real eigenvalues, (5 +- sqrt 33) / 2, and a complex pair
        let ev =
            quasi_triangular_eigenvalues(&DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 3.0, 4.0]));
        let r = 33f64.sqrt() / 2.0;
        assert_eq!(ev, [Complex::new(2.5 + r, 0.0), Complex::new(2.5 - r, 0.0)]);
        let ev =
            quasi_triangular_eigenvalues(&DMatrix::from_row_slice(2, 2, &[-1.0, 4.0, -1.0, -1.0]));
        assert_eq!(ev, [Complex::new(-1.0, 2.0), Complex::new(-1.0, -2.0)]);
    }

    #[test]
    fn a_matrix_the_plain_iteration_stalls_on_is_reduced_or_refused() {
        // the companion matrix of x^11 - 1.7748..., on which nalgebra's unbounded Schur
        // iteration loops for ever; here it returns, and any answer it gives is right
        let n = 11;
        let mut a = DMatrix::zeros(n, n);
        a[(0, n - 1)] = 1.774_809_211_101_797_7;
        for i in 1..n {
            a[(i, i - 1)] = 1.0;
        }
        if let Some(ev) = eigenvalues(&a) {
            let r = 1.774_809_211_101_797_7f64.powf(1.0 / 11.0);
            for l in ev {
                assert!((l.norm() - r).abs() < 1e-9, "{l:?}");
            }
        }
        let mut nan = DMatrix::identity(3, 3);
        nan[(1, 2)] = f64::NAN;
        assert!(eigenvalues(&nan).is_none());
        assert!(eigenvalues(&DMatrix::zeros(2, 3)).is_none());
    }
}
