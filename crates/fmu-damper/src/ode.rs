//! Stiff-safe internal integrator shared by every model of the crate.
//!
//! # Choice and why
//! The pressure states are stiff: their own eigenvalue is `(K/V0) dQ/dP`, which for
//! the regularised (laminar) orifice near `dP = 0` reaches 1e5-1e7 1/s, and the
//! regularised Coulomb friction of the actuator adds another fast mode. An explicit
//! scheme would need sub-steps of ~1 us everywhere. We use the **linearly implicit
//! Rosenbrock pair of Shampine & Reichelt (1997) ("ode23s" in MATLAB)**: L-stable,
//! second order with an embedded third-order error estimate, so the internal step size
//! is chosen by error control (not by stability) and grows to the communication step
//! whenever the solution is smooth. It needs no Newton iteration (one LU of
//! `W = I - h d J` per attempt), which keeps a step bounded in cost and allocation-free.
//! The Jacobian is built by forward differences; non-smooth points (dead zone, rate
//! limit, clamp) only cost rejected internal steps.
//!
//! Inputs are held constant over one communication interval (zero-order hold, as in
//! FMI co-simulation), so every right-hand side is autonomous within a step.

// Index loops read like the textbook formulas of the small dense linear algebra.
#![allow(clippy::needless_range_loop)]

use serde::{Deserialize, Serialize};

use crate::error::StepError;

/// A right-hand side `dy/dt = f(y)` with `N` states (inputs frozen during the step).
pub trait Rhs<const N: usize> {
    /// Evaluates `f(y)`. May return non-finite values; the integrator rejects them.
    fn rhs(&self, y: &[f64; N]) -> [f64; N];

    /// States whose derivative is exactly zero for any `y` during this step (e.g. an ideal
    /// valve's opening or an imposed rod velocity). Their Jacobian columns are not built: in
    /// `W = I - h d J` such a column only ever multiplies a stage increment that is exactly
    /// zero, so the step is bit for bit the one with the finite-difference column, at one
    /// right-hand-side evaluation less per frozen state and internal step.
    fn frozen(&self) -> [bool; N] {
        [false; N]
    }
}

/// Settings of the internal integrator.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SolverSettings {
    /// Relative tolerance of the local error test.
    pub rtol: f64,
    /// Maximum number of internal steps (accepted + rejected) per communication step:
    /// bounds the work (and time) of one step, e.g. for a real-time or HIL host. Reaching it
    /// fails the step ([`StepError::Integration`]; the FMUs return fmi2Discard with the state
    /// unchanged, and the master may retry with a smaller communication step). The default
    /// (20 000) is far above need: a 1 ms step of the crate's models needs 1-50 attempts in
    /// normal use and at most about 200 with absurd but finite inputs (velocities up to
    /// 1e6 m/s, spool commands up to 1 m).
    pub max_internal_steps: u32,
    /// Smallest internal step before the step is declared failed, s.
    pub min_step_s: f64,
}

impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            rtol: 1e-6,
            max_internal_steps: 20_000,
            min_step_s: 1e-12,
        }
    }
}

impl SolverSettings {
    pub(crate) fn validate(&self) -> Result<(), crate::ParamError> {
        crate::error::in_range(
            "solver.rtol",
            self.rtol,
            1e-12,
            1e-2,
            "relative tolerance must lie in [1e-12, 1e-2]",
        )?;
        crate::error::positive("solver.min_step_s", self.min_step_s)?;
        if self.max_internal_steps == 0 {
            return Err(crate::ParamError::NotPositive {
                name: "solver.max_internal_steps",
                value: 0.0,
            });
        }
        Ok(())
    }
}

const D: f64 = 1.0 / (2.0 + std::f64::consts::SQRT_2);
const E32: f64 = 6.0 + std::f64::consts::SQRT_2;

/// Integrates `y` over `h_total` seconds. `h_internal` carries the last proposed
/// internal step size from one call to the next (part of the model state).
/// Returns the number of accepted internal steps.
pub(crate) fn integrate<S: Rhs<N>, const N: usize>(
    sys: &S,
    y: &mut [f64; N],
    atol: &[f64; N],
    h_total: f64,
    h_internal: &mut f64,
    settings: &SolverSettings,
) -> Result<u32, StepError> {
    if !(h_total.is_finite() && h_total > 0.0) {
        return Err(StepError::BadStepSize { h: h_total });
    }
    let rtol = settings.rtol;
    let mut t = 0.0;
    let mut h = if h_internal.is_finite() && *h_internal > 0.0 {
        h_internal.min(h_total)
    } else {
        h_total
    };
    let mut attempts: u32 = 0;
    let mut accepted: u32 = 0;
    let mut h_proposed = h;
    // ode23s is FSAL: the last stage's derivative at an accepted state is that state's f0 (the
    // inputs are frozen within the step, so the right-hand side is the same function of y)
    let mut f_accepted: Option<[f64; N]> = None;

    while t < h_total * (1.0 - 1e-12) {
        let last = h >= (h_total - t) * (1.0 - 1e-9);
        if last {
            h = h_total - t;
        }
        let f0 = match f_accepted.take() {
            Some(f) => f,
            None => sys.rhs(y),
        };
        if !all_finite(&f0) {
            return Err(StepError::Integration {
                at_s: t,
                reason: "non-finite derivative at an accepted state",
            });
        }
        let jac = jacobian(sys, y, &f0, atol);
        loop {
            attempts += 1;
            if attempts > settings.max_internal_steps {
                return Err(StepError::Integration {
                    at_s: t,
                    reason: "the internal step count reached solver.max_internal_steps",
                });
            }
            let trial = rosenbrock_attempt(sys, y, &f0, &jac, h);
            let err_norm = match &trial {
                Some((ynew, err, _)) => {
                    let mut m: f64 = 0.0;
                    for i in 0..N {
                        let sc = atol[i] + rtol * y[i].abs().max(ynew[i].abs());
                        m = m.max((err[i] / sc).abs());
                    }
                    if m.is_finite() {
                        m
                    } else {
                        f64::INFINITY
                    }
                }
                None => f64::INFINITY,
            };
            if err_norm <= 1.0 {
                if let Some((ynew, _, f_new)) = trial {
                    *y = ynew;
                    f_accepted = Some(f_new);
                }
                t += h;
                accepted += 1;
                let fac = if err_norm > 0.0 {
                    (0.9 * err_norm.powf(-1.0 / 3.0)).min(5.0)
                } else {
                    5.0
                };
                let h_next = h * fac;
                // A truncated final step says nothing about the natural step size.
                h_proposed = if last { h_proposed.max(h_next) } else { h_next };
                h = h_next;
                break;
            }
            let fac = if err_norm.is_finite() {
                (0.9 * err_norm.powf(-1.0 / 3.0)).clamp(0.1, 0.5)
            } else {
                0.1
            };
            h *= fac;
            if h < settings.min_step_s {
                return Err(StepError::Integration {
                    at_s: t,
                    reason: "internal step size fell below min_step_s",
                });
            }
        }
    }
    *h_internal = h_proposed.max(settings.min_step_s);
    Ok(accepted)
}

fn all_finite<const N: usize>(v: &[f64; N]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// One ode23s attempt: the new state, its error estimate and the derivative at the new state
/// (the last stage's); `None` if the linear system is singular or a stage is non-finite.
#[allow(clippy::type_complexity)]
fn rosenbrock_attempt<S: Rhs<N>, const N: usize>(
    sys: &S,
    y: &[f64; N],
    f0: &[f64; N],
    jac: &[[f64; N]; N],
    h: f64,
) -> Option<([f64; N], [f64; N], [f64; N])> {
    let mut w = [[0.0; N]; N];
    for i in 0..N {
        for j in 0..N {
            w[i][j] = if i == j { 1.0 } else { 0.0 } - h * D * jac[i][j];
        }
    }
    let lu = Lu::factor(w)?;
    let k1 = lu.solve(f0);
    let mut y1 = *y;
    for i in 0..N {
        y1[i] += 0.5 * h * k1[i];
    }
    let f1 = sys.rhs(&y1);
    if !all_finite(&f1) {
        return None;
    }
    let mut r = [0.0; N];
    for i in 0..N {
        r[i] = f1[i] - k1[i];
    }
    let mut k2 = lu.solve(&r);
    for i in 0..N {
        k2[i] += k1[i];
    }
    let mut ynew = *y;
    for i in 0..N {
        ynew[i] += h * k2[i];
    }
    if !all_finite(&ynew) {
        return None;
    }
    let f2 = sys.rhs(&ynew);
    if !all_finite(&f2) {
        return None;
    }
    for i in 0..N {
        r[i] = f2[i] - E32 * (k2[i] - f1[i]) - 2.0 * (k1[i] - f0[i]);
    }
    let k3 = lu.solve(&r);
    let mut err = [0.0; N];
    for i in 0..N {
        err[i] = h / 6.0 * (k1[i] - 2.0 * k2[i] + k3[i]);
    }
    Some((ynew, err, f2))
}

/// Forward-difference Jacobian.
fn jacobian<S: Rhs<N>, const N: usize>(
    sys: &S,
    y: &[f64; N],
    f0: &[f64; N],
    atol: &[f64; N],
) -> [[f64; N]; N] {
    let mut jac = [[0.0; N]; N];
    let sq = f64::EPSILON.sqrt();
    let frozen = sys.frozen();
    for j in 0..N {
        if frozen[j] {
            continue;
        }
        let delta = sq * y[j].abs().max(1e3 * atol[j]).max(1e-300);
        let mut yp = *y;
        yp[j] += delta;
        let actual = yp[j] - y[j];
        let fp = sys.rhs(&yp);
        for i in 0..N {
            let d = (fp[i] - f0[i]) / actual;
            jac[i][j] = if d.is_finite() { d } else { 0.0 };
        }
    }
    jac
}

/// LU factorisation with partial pivoting of a small dense matrix.
struct Lu<const N: usize> {
    a: [[f64; N]; N],
    piv: [usize; N],
}

impl<const N: usize> Lu<N> {
    fn factor(mut a: [[f64; N]; N]) -> Option<Self> {
        let mut piv = [0usize; N];
        for (i, p) in piv.iter_mut().enumerate() {
            *p = i;
        }
        for k in 0..N {
            let mut p = k;
            let mut best = a[k][k].abs();
            for (i, row) in a.iter().enumerate().skip(k + 1) {
                if row[k].abs() > best {
                    best = row[k].abs();
                    p = i;
                }
            }
            if !(best.is_finite() && best > 1e-300) {
                return None;
            }
            a.swap(k, p);
            piv.swap(k, p);
            for i in (k + 1)..N {
                let m = a[i][k] / a[k][k];
                a[i][k] = m;
                for j in (k + 1)..N {
                    a[i][j] -= m * a[k][j];
                }
            }
        }
        Some(Self { a, piv })
    }

    fn solve(&self, b: &[f64; N]) -> [f64; N] {
        let mut x = [0.0; N];
        for i in 0..N {
            x[i] = b[self.piv[i]];
        }
        for i in 0..N {
            for j in 0..i {
                x[i] -= self.a[i][j] * x[j];
            }
        }
        for i in (0..N).rev() {
            for j in (i + 1)..N {
                x[i] -= self.a[i][j] * x[j];
            }
            x[i] /= self.a[i][i];
        }
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Stiff linear test problem y' = -lambda (y - cos t)-like, autonomous version:
    /// y0' = -1000 (y0 - y1), y1' = -y1 (exact solution known).
    struct Stiff;
    impl Rhs<2> for Stiff {
        fn rhs(&self, y: &[f64; 2]) -> [f64; 2] {
            [-1000.0 * (y[0] - y[1]), -y[1]]
        }
    }

    #[test]
    fn stiff_linear_problem_is_accurate_with_large_steps() {
        let mut y = [0.0, 1.0];
        let mut hi = 0.0;
        let s = SolverSettings::default();
        for _ in 0..200 {
            integrate(&Stiff, &mut y, &[1e-10, 1e-10], 5e-3, &mut hi, &s).unwrap();
        }
        // t = 1: y1 = e^-1, y0 = 1000/999 e^-1 (fast transient long gone)
        let e = (-1.0f64).exp();
        assert!((y[1] - e).abs() < 1e-6 * 10.0, "{}", y[1]);
        assert!((y[0] - 1000.0 / 999.0 * e).abs() < 1e-5, "{}", y[0]);
    }

    /// [`Stiff`] recording where it is evaluated.
    struct Recorded(std::cell::RefCell<Vec<[u64; 2]>>);
    impl Rhs<2> for Recorded {
        fn rhs(&self, y: &[f64; 2]) -> [f64; 2] {
            self.0.borrow_mut().push(y.map(f64::to_bits));
            Stiff.rhs(y)
        }
    }

    /// ode23s is FSAL: an accepted internal step's last stage, the derivative at the new state,
    /// is the next step's f0, so no state is evaluated twice (without it every accepted state
    /// but the last would be: once as a stage, once as f0); the result is the same.
    #[test]
    fn the_last_stage_of_an_accepted_step_is_the_next_f0() {
        let recorded = Recorded(std::cell::RefCell::new(Vec::new()));
        let (mut y, mut hi) = ([0.0, 1.0], 1e-5);
        let s = SolverSettings {
            rtol: 1e-9,
            ..SolverSettings::default()
        };
        let accepted = integrate(&recorded, &mut y, &[1e-12; 2], 1e-2, &mut hi, &s).unwrap();
        assert!(accepted > 3, "{accepted} internal steps: too few to tell");
        let mut points = recorded.0.into_inner();
        let evaluations = points.len();
        points.sort_unstable();
        points.dedup();
        assert_eq!(points.len(), evaluations, "a state was evaluated twice");
        let (mut y_plain, mut hi_plain) = ([0.0, 1.0], 1e-5);
        integrate(&Stiff, &mut y_plain, &[1e-12; 2], 1e-2, &mut hi_plain, &s).unwrap();
        assert_eq!(y.map(f64::to_bits), y_plain.map(f64::to_bits));
    }

    #[test]
    fn rejects_bad_step() {
        let mut y = [0.0, 1.0];
        let mut hi = 0.0;
        let s = SolverSettings::default();
        assert!(integrate(&Stiff, &mut y, &[1e-10; 2], f64::NAN, &mut hi, &s).is_err());
        assert!(integrate(&Stiff, &mut y, &[1e-10; 2], -1.0, &mut hi, &s).is_err());
    }
}
