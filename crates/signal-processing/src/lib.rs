//! Digital filters written once for every crate that needs them: the controllers' boards
//! (`fmu-controller`, sample by sample inside an FMU) and the EN 14363 assessment of the study
//! (`rail-study`, whole recorded signals, zero phase).
//!
//! * [`Biquad`]: one second-order section in direct form II transposed, with its state.
//! * [`BandPass`]: Butterworth band-pass designed by the low-pass to band-pass transform of the
//!   analogue prototype and the bilinear (Tustin) transform with pre-warped edges, as a cascade
//!   of biquads each scaled to unit gain at the centre; streaming ([`BandPass::process`]),
//!   causal over a slice ([`BandPass::filter`]) and zero-phase ([`BandPass::filtfilt`]).
//! * [`LowPass`]: Butterworth low-pass of the same design (the anti-aliasing filter of
//!   decimated results), causal and zero-phase.
//! * [`WdWeighting`]: the W_d frequency weighting of horizontal whole-body vibration (EN 12299,
//!   ISO 2631-1) for the ride-comfort index of the study.
//! * [`principal_sqrt`]: the complex square root the design uses; [`rms`]; [`sampled`] (test
//!   signals).
//!
//! The crate knows no model and no FMI: plain functions of numbers, so a model crate may
//! depend on it.

mod bandpass;
mod biquad;
mod lowpass;
mod weighting;

pub use bandpass::{BandPass, DesignError, DesignParameter};
pub use biquad::Biquad;
pub use lowpass::LowPass;
pub use num_complex::Complex64;
pub use weighting::WdWeighting;

/// Root mean square (0 for an empty signal).
pub fn rms(x: &[f64]) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt()
}

/// `signal(t)` sampled at `fs` \[Hz\] for `secs` seconds, `t = i / fs` (test signals).
pub fn sampled(signal: impl Fn(f64) -> f64, fs: f64, secs: f64) -> Vec<f64> {
    (0..(secs * fs) as usize)
        .map(|i| signal(i as f64 / fs))
        .collect()
}

/// Principal square root by the algebraic formula
/// `sqrt(z) = sqrt((|z| + re)/2) + i sign(im) sqrt((|z| - re)/2)`.
///
/// Used instead of `Complex64::sqrt` (which goes through polar form, `sqrt(r) e^(i theta/2)`)
/// because the filter coefficients of the controllers were designed with this formula; the polar
/// form differs in the last bits.
pub fn principal_sqrt(z: Complex64) -> Complex64 {
    let r = z.norm();
    let re = ((r + z.re) * 0.5).max(0.0).sqrt();
    let im = ((r - z.re) * 0.5).max(0.0).sqrt();
    Complex64::new(re, if z.im < 0.0 { -im } else { im })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rms_of_a_sampled_sine() {
        let x = sampled(
            |t| 3.0 * (2.0 * std::f64::consts::PI * 5.0 * t).sin(),
            1000.0,
            2.0,
        );
        assert_eq!(x.len(), 2000);
        assert!((rms(&x) - 3.0 / 2f64.sqrt()).abs() < 1e-12);
        assert_eq!(rms(&[]), 0.0);
    }

    #[test]
    fn principal_sqrt_squares_back_and_takes_the_right_half_plane() {
        for z in [
            Complex64::new(4.0, 0.0),
            Complex64::new(-4.0, 0.0),
            Complex64::new(3.0, -4.0),
            Complex64::new(-1e-3, 2.5e3),
        ] {
            let s = principal_sqrt(z);
            assert!(s.re >= 0.0, "{z}");
            assert!((s * s - z).norm() <= 1e-12 * z.norm(), "{z}: {s}");
        }
        assert_eq!(
            principal_sqrt(Complex64::new(-4.0, 0.0)),
            Complex64::new(0.0, 2.0)
        );
    }
}
