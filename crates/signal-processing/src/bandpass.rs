//! Butterworth band-pass: design, streaming, causal and zero-phase filtering.

use std::f64::consts::PI;

use num_complex::Complex64;
use serde::{Deserialize, Serialize};

use crate::{principal_sqrt, Biquad};

/// Which design input is wrong.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DesignParameter {
    SampleTime,
    LowEdge,
    HighEdge,
    Order,
}

impl std::fmt::Display for DesignParameter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            DesignParameter::SampleTime => "sample time",
            DesignParameter::LowEdge => "lower band edge",
            DesignParameter::HighEdge => "upper band edge",
            DesignParameter::Order => "filter order",
        })
    }
}

/// A band-pass that cannot be designed; callers map [`DesignParameter`] to their own names.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{parameter}: {reason}")]
pub struct DesignError {
    pub parameter: DesignParameter,
    pub reason: String,
}

fn bad(parameter: DesignParameter, reason: impl Into<String>) -> DesignError {
    DesignError {
        parameter,
        reason: reason.into(),
    }
}

/// Highest prototype order [`BandPass::butterworth`] designs.
pub const MAX_PROTOTYPE_ORDER: usize = 10;

/// Butterworth band-pass as a cascade of second-order sections, each scaled to unit gain at the
/// (geometric) digital centre frequency; -3 dB at the two edges.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BandPass {
    pub sections: Vec<Biquad>,
}

impl BandPass {
    /// Design from the analogue Butterworth low-pass prototype of order `prototype_order`
    /// (1..=10; the band-pass has twice that order and as many sections) with edges
    /// `f_low_hz < f_high_hz` \[Hz\] at sample time `dt_s` \[s\]. The analogue edges are pre-warped,
    /// `w = (2/T) tan(pi f T)`, so the digital -3 dB points are exact.
    pub fn butterworth(
        prototype_order: usize,
        f_low_hz: f64,
        f_high_hz: f64,
        dt_s: f64,
    ) -> Result<Self, DesignError> {
        use DesignParameter as P;
        if !(dt_s.is_finite() && dt_s > 0.0) {
            return Err(bad(P::SampleTime, "must be finite and > 0"));
        }
        if !(f_low_hz.is_finite() && f_low_hz > 0.0) {
            return Err(bad(P::LowEdge, "must be finite and > 0"));
        }
        if !(f_high_hz.is_finite() && f_high_hz > f_low_hz) {
            return Err(bad(P::HighEdge, "must be finite and > the lower band edge"));
        }
        let nyquist = 0.5 / dt_s;
        if f_high_hz >= nyquist {
            return Err(bad(
                P::HighEdge,
                format!("must be below the Nyquist frequency {nyquist} Hz"),
            ));
        }
        if !(1..=MAX_PROTOTYPE_ORDER).contains(&prototype_order) {
            return Err(bad(
                P::Order,
                format!("prototype order must be 1..={MAX_PROTOTYPE_ORDER}, got {prototype_order}"),
            ));
        }
        let k = 2.0 / dt_s;
        let w1 = k * (PI * f_low_hz * dt_s).tan();
        let w2 = k * (PI * f_high_hz * dt_s).tan();
        let bw = w2 - w1;
        let w0sq = w1 * w2;
        // digital centre frequency [rad/sample], where every section has unit gain
        let wt0 = 2.0 * (w0sq.sqrt() / k).atan();
        // z = (1 + s T/2) / (1 - s T/2) = (k + s) / (k - s)
        let to_z = |s: Complex64| (Complex64::new(k, 0.0) + s) / (Complex64::new(k, 0.0) - s);
        let mut sections = Vec::with_capacity(prototype_order);
        for p in upper_prototype_poles(prototype_order) {
            // low-pass to band-pass: s_lp = (s^2 + w0^2) / (bw s)  =>  s^2 - p bw s + w0^2 = 0
            let pb = p.scale(bw);
            let disc = principal_sqrt(pb * pb - Complex64::new(4.0 * w0sq, 0.0));
            let s1 = (pb + disc).scale(0.5);
            let s2 = (pb - disc).scale(0.5);
            let pairs = if p.im == 0.0 {
                // real prototype pole: s1, s2 are a conjugate pair or both real, one section
                vec![(s1, s2)]
            } else {
                // complex prototype pole: its conjugate gives conj(s1), conj(s2)
                vec![(s1, s1.conj()), (s2, s2.conj())]
            };
            for (sa, sb) in pairs {
                let (za, zb) = (to_z(sa), to_z(sb));
                let a1 = -(za + zb).re;
                let a2 = (za * zb).re;
                // zeros at z = +1 and z = -1 (s = 0 and s = infinity)
                let mut section = Biquad::new([1.0, 0.0, -1.0], [a1, a2]);
                let g = section.gain_at(wt0).norm();
                if !(g.is_finite() && g > 0.0) {
                    return Err(bad(P::LowEdge, "filter design failed"));
                }
                section.b = [1.0 / g, 0.0, -1.0 / g];
                sections.push(section);
            }
        }
        Ok(Self { sections })
    }

    /// One sample through every section.
    pub fn process(&mut self, x: f64) -> f64 {
        let mut y = x;
        for s in &mut self.sections {
            y = s.process(y);
        }
        y
    }

    /// Back to zero state.
    pub fn reset(&mut self) {
        for s in &mut self.sections {
            s.reset();
        }
    }

    /// |H| at `f_hz` for sample time `dt_s` (product of the sections' magnitudes).
    pub fn magnitude(&self, f_hz: f64, dt_s: f64) -> f64 {
        let wt = 2.0 * PI * f_hz * dt_s;
        self.sections.iter().map(|s| s.gain_at(wt).norm()).product()
    }

    /// Causal filtering of a whole signal from zero state (the filter's own state is untouched).
    pub fn filter(&self, x: &[f64]) -> Vec<f64> {
        crate::biquad::cascade_filter(&self.sections, x)
    }

    /// Zero-phase filtering (forward and backward; gain |H|^2), with odd reflection padding of
    /// `pad` samples at both ends to shorten the start transients.
    pub fn filtfilt(&self, x: &[f64], pad: usize) -> Vec<f64> {
        crate::biquad::cascade_filtfilt(&self.sections, x, pad)
    }
}

/// Poles of the analogue Butterworth low-pass prototype (unit cut-off) in the upper half plane
/// and on the real axis, `exp(i pi (2k + n + 1) / (2n))` for `k = 0..n` with angle <= pi; the
/// real pole of an odd order is exactly -1.
pub(crate) fn upper_prototype_poles(n: usize) -> Vec<Complex64> {
    (0..n)
        .filter_map(|k| {
            let num = 2 * k + n + 1;
            if num == 2 * n {
                Some(Complex64::new(-1.0, 0.0))
            } else if num < 2 * n {
                Some(Complex64::cis(PI * num as f64 / (2 * n) as f64))
            } else {
                None
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    use crate::{rms, sampled};

    fn sine(a: f64, f: f64, fs: f64, secs: f64, phase: f64) -> Vec<f64> {
        sampled(|t| a * (2.0 * PI * f * t + phase).sin(), fs, secs)
    }

    #[test]
    fn prototype_poles_are_the_butterworth_ones() {
        // order 2: the pole at 3 pi / 4 (the design of the controllers' 4th-order band-pass)
        assert_eq!(upper_prototype_poles(2), vec![Complex64::cis(0.75 * PI)]);
        assert_eq!(upper_prototype_poles(1), vec![Complex64::new(-1.0, 0.0)]);
        for n in 1..=MAX_PROTOTYPE_ORDER {
            let p = upper_prototype_poles(n);
            assert_eq!(p.len(), n.div_ceil(2));
            for z in p {
                assert_relative_eq!(z.norm(), 1.0, epsilon = 1e-15);
                assert!(z.re < 0.0 && z.im >= 0.0);
            }
        }
    }

    #[test]
    fn edges_centre_and_the_analogue_response() {
        let dt = 1.0 / 500.0;
        for n in [1, 2, 3, 5] {
            let bp = BandPass::butterworth(n, 2.0, 6.0, dt).unwrap();
            assert_eq!(bp.sections.len(), n);
            // the digital response equals the analogue Butterworth magnitude
            // 1/sqrt(1 + q^(2n)), q = (w^2 - w1 w2)/(w (w2 - w1)), at the pre-warped frequency
            let warp = |f: f64| 2.0 / dt * (PI * f * dt).tan();
            let (w1, w2) = (warp(2.0), warp(6.0));
            // unit gain at the centre (geometric in the pre-warped domain), -3 dB at the edges
            let centre = ((w1 * w2).sqrt() * dt / 2.0).atan() / (PI * dt);
            assert_relative_eq!(bp.magnitude(centre, dt), 1.0, epsilon = 1e-12);
            assert_relative_eq!(bp.magnitude(2.0, dt), 0.5f64.sqrt(), epsilon = 1e-9);
            assert_relative_eq!(bp.magnitude(6.0, dt), 0.5f64.sqrt(), epsilon = 1e-9);
            for f in [0.5, 1.0, 3.0, 5.0, 9.0, 20.0, 100.0] {
                let w = warp(f);
                let q = (w * w - w1 * w2) / (w * (w2 - w1));
                let analogue = 1.0 / (1.0 + q.powi(2 * n as i32)).sqrt();
                assert_relative_eq!(bp.magnitude(f, dt), analogue, max_relative = 1e-9);
            }
        }
    }

    #[test]
    fn streaming_equals_causal_filtering() {
        let dt = 1e-3;
        let x = sine(1.0, 4.0, 1.0 / dt, 3.0, 0.1);
        let mut bp = BandPass::butterworth(2, 2.0, 6.0, dt).unwrap();
        let batch = bp.filter(&x);
        let streamed: Vec<f64> = x.iter().map(|&v| bp.process(v)).collect();
        assert_eq!(batch, streamed);
        bp.reset();
        assert_eq!(bp.process(x[0]), batch[0]);
    }

    #[test]
    fn filtfilt_keeps_in_band_and_removes_out_of_band() {
        let fs = 500.0;
        let dt = 1.0 / fs;
        let bp = BandPass::butterworth(2, 2.0, 6.0, dt).unwrap();
        let a = 2.0;
        let x = sine(a, 4.0, fs, 40.0, 0.3);
        let y = bp.filtfilt(&x, 1000);
        let core = &y[2500..y.len() - 2500];
        let expected = a / 2f64.sqrt() * bp.magnitude(4.0, dt).powi(2);
        assert_relative_eq!(rms(core), expected, max_relative = 1e-3);
        // zero phase: peaks stay where they were
        let i = (0..core.len())
            .max_by(|&p, &q| core[p].total_cmp(&core[q]))
            .unwrap();
        assert!((core[i] - x[2500 + i]).abs() < 0.03 * a);
        let out = sine(a, 25.0, fs, 40.0, 0.0);
        let y = bp.filtfilt(&out, 1000);
        assert!(rms(&y[2500..y.len() - 2500]) < 1e-3 * a);
        let dc = vec![5.0; 20000];
        assert!(rms(&bp.filtfilt(&dc, 1000)) < 1e-5);
        assert!(bp.filtfilt(&[], 10).is_empty());
    }

    #[test]
    fn bad_designs_name_the_parameter() {
        let p = |r: Result<BandPass, DesignError>| r.unwrap_err().parameter;
        use DesignParameter as P;
        assert_eq!(p(BandPass::butterworth(2, 2.0, 6.0, 0.0)), P::SampleTime);
        assert_eq!(p(BandPass::butterworth(2, -1.0, 6.0, 1e-3)), P::LowEdge);
        assert_eq!(p(BandPass::butterworth(2, 6.0, 2.0, 1e-3)), P::HighEdge);
        assert_eq!(p(BandPass::butterworth(2, 2.0, 500.0, 1e-3)), P::HighEdge);
        assert_eq!(p(BandPass::butterworth(0, 2.0, 6.0, 1e-3)), P::Order);
        assert_eq!(p(BandPass::butterworth(11, 2.0, 6.0, 1e-3)), P::Order);
    }
}
