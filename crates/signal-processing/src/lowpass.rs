//! Butterworth low-pass: the anti-aliasing filter applied before a signal is decimated.

use std::f64::consts::PI;

use num_complex::Complex64;
use serde::{Deserialize, Serialize};

use crate::bandpass::{upper_prototype_poles, MAX_PROTOTYPE_ORDER};
use crate::biquad::{cascade_filter, cascade_filtfilt};
use crate::{Biquad, DesignError, DesignParameter};

/// Butterworth low-pass as a cascade of sections (second order, one first-order section for
/// an odd order), each with unit gain at 0 Hz; -3 dB at the cut-off.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LowPass {
    pub sections: Vec<Biquad>,
}

impl LowPass {
    /// Design from the analogue Butterworth prototype of order `order` (1..=10) with cut-off
    /// `cutoff_hz` below the Nyquist frequency of the sample time `dt_s` \[s\], by the bilinear
    /// transform with a pre-warped cut-off (the digital -3 dB point is exact).
    pub fn butterworth(order: usize, cutoff_hz: f64, dt_s: f64) -> Result<Self, DesignError> {
        let bad = |parameter, reason: String| DesignError { parameter, reason };
        if !(dt_s.is_finite() && dt_s > 0.0) {
            return Err(bad(
                DesignParameter::SampleTime,
                "must be finite and > 0".into(),
            ));
        }
        let nyquist = 0.5 / dt_s;
        if !(cutoff_hz.is_finite() && cutoff_hz > 0.0 && cutoff_hz < nyquist) {
            return Err(bad(
                DesignParameter::HighEdge,
                format!("the cut-off must be > 0 and below the Nyquist frequency {nyquist} Hz"),
            ));
        }
        if !(1..=MAX_PROTOTYPE_ORDER).contains(&order) {
            return Err(bad(
                DesignParameter::Order,
                format!("order must be 1..={MAX_PROTOTYPE_ORDER}, got {order}"),
            ));
        }
        let k = 2.0 / dt_s;
        let wc = k * (PI * cutoff_hz * dt_s).tan();
        let to_z = |s: Complex64| (Complex64::new(k, 0.0) + s) / (Complex64::new(k, 0.0) - s);
        let sections = upper_prototype_poles(order)
            .into_iter()
            .map(|p| {
                let z = to_z(p.scale(wc));
                if p.im == 0.0 {
                    // real pole: (1 + z^-1) / (1 - z z^-1), scaled to unit gain at z = 1
                    let a1 = -z.re;
                    let g = (1.0 + a1) / 2.0;
                    Biquad::new([g, g, 0.0], [a1, 0.0])
                } else {
                    // the pole and its conjugate, two zeros at z = -1 (s = infinity)
                    let a1 = -2.0 * z.re;
                    let a2 = z.norm_sqr();
                    let g = (1.0 + a1 + a2) / 4.0;
                    Biquad::new([g, 2.0 * g, g], [a1, a2])
                }
            })
            .collect();
        Ok(Self { sections })
    }

    /// |H| at `f_hz` for sample time `dt_s`.
    pub fn magnitude(&self, f_hz: f64, dt_s: f64) -> f64 {
        let wt = 2.0 * PI * f_hz * dt_s;
        self.sections.iter().map(|s| s.gain_at(wt).norm()).product()
    }

    /// Causal filtering of a whole signal from zero state.
    pub fn filter(&self, x: &[f64]) -> Vec<f64> {
        cascade_filter(&self.sections, x)
    }

    /// Zero-phase filtering (forward and backward; gain |H|^2), with odd reflection padding of
    /// `pad` samples at both ends: a constant or a ramp passes unchanged, so the ends of a
    /// record carry no start transient.
    pub fn filtfilt(&self, x: &[f64], pad: usize) -> Vec<f64> {
        cascade_filtfilt(&self.sections, x, pad)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    use crate::{rms, sampled};

    #[test]
    fn response_is_the_analogue_butterworth_one() {
        let dt = 1e-3;
        for n in [1, 2, 3, 4, 7] {
            let lp = LowPass::butterworth(n, 40.0, dt).unwrap();
            assert_eq!(lp.sections.len(), n.div_ceil(2));
            assert_relative_eq!(lp.magnitude(0.0, dt), 1.0, epsilon = 1e-12);
            assert_relative_eq!(lp.magnitude(40.0, dt), 0.5f64.sqrt(), epsilon = 1e-9);
            let warp = |f: f64| (PI * f * dt).tan();
            for f in [1.0, 10.0, 25.0, 60.0, 100.0, 300.0] {
                let q = warp(f) / warp(40.0);
                let analogue = 1.0 / (1.0 + q.powi(2 * n as i32)).sqrt();
                assert_relative_eq!(lp.magnitude(f, dt), analogue, max_relative = 1e-9);
            }
        }
    }

    #[test]
    fn zero_phase_keeps_the_pass_band_and_removes_the_stop_band() {
        let fs = 1000.0;
        let dt = 1.0 / fs;
        let lp = LowPass::butterworth(4, 40.0, dt).unwrap();
        let slow = sampled(|t| 3.0 * (2.0 * PI * 5.0 * t).sin() + 1.5, fs, 10.0);
        let y = lp.filtfilt(&slow, 500);
        let worst = y
            .iter()
            .zip(&slow)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        // |H(5 Hz)|^2 = 1 - 6e-8: the in-band sine and the offset pass, in phase, to the ends
        assert!(worst < 1e-3, "{worst}");
        let fast = sampled(|t| (2.0 * PI * 120.0 * t).sin(), fs, 10.0);
        let y = lp.filtfilt(&fast, 500);
        let expected = lp.magnitude(120.0, dt).powi(2) / 2f64.sqrt();
        assert!(rms(&y[1000..9000]) < 1.5 * expected && expected < 2e-4);
    }

    #[test]
    fn bad_designs_name_the_parameter() {
        let p = |r: Result<LowPass, DesignError>| r.unwrap_err().parameter;
        assert_eq!(
            p(LowPass::butterworth(4, 40.0, 0.0)),
            DesignParameter::SampleTime
        );
        assert_eq!(
            p(LowPass::butterworth(4, 500.0, 1e-3)),
            DesignParameter::HighEdge
        );
        assert_eq!(
            p(LowPass::butterworth(4, f64::NAN, 1e-3)),
            DesignParameter::HighEdge
        );
        assert_eq!(
            p(LowPass::butterworth(11, 40.0, 1e-3)),
            DesignParameter::Order
        );
    }
}
