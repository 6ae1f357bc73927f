//! Frequency weighting W_d of whole-body vibration for horizontal accelerations (EN 12299:2009
//! Annex A, identical to ISO 2631-1:1997 Table 3), the weighting of EN 12299's lateral ride
//! comfort.
//!
//! The weighting is the product of three analogue sections (EN 12299 A.2, ISO 2631-1 Annex A):
//! * band limiting high-pass, 2nd-order Butterworth at f1 = 0.4 Hz: `s^2 / (s^2 + w1 s/Q1 + w1^2)`;
//! * band limiting low-pass, 2nd-order Butterworth at f2 = 100 Hz: `w2^2 / (s^2 + w2 s/Q1 + w2^2)`;
//! * acceleration-velocity transition, f3 = f4 = 2 Hz, Q4 = 0.63:
//!   `(1 + s/w3) / (1 + s/(Q4 w4) + s^2/w4^2)`;
//!
//! with Q1 = 1/sqrt(2) and gain K = 1. Each section becomes a [`Biquad`] by the bilinear
//! transform pre-warped at its corner frequency. The band-limiting low-pass is left out when
//! f2 is above 0.45 times the sampling rate (the sampling itself then limits the band; the
//! weighting above 50 Hz is below 0.1 and hunting and car-body modes lie under 10 Hz).

use crate::Biquad;
use std::f64::consts::{PI, SQRT_2};

/// Corner frequencies and quality factors of W_d (EN 12299 Table A.1).
const F1_HZ: f64 = 0.4;
const F2_HZ: f64 = 100.0;
const F3_HZ: f64 = 2.0;
const F4_HZ: f64 = 2.0;
const Q1: f64 = 1.0 / SQRT_2;
const Q4: f64 = 0.63;

/// Analogue section `(n2 s^2 + n1 s + n0) / (d2 s^2 + d1 s + d0)` through the bilinear
/// transform `s = c (1 - z^-1)/(1 + z^-1)`, with `c = w0 / tan(w0 T / 2)` (pre-warped at `w0`).
fn bilinear(n: [f64; 3], d: [f64; 3], w0: f64, dt_s: f64) -> Biquad {
    let c = w0 / (w0 * dt_s / 2.0).tan();
    let c2 = c * c;
    let [n0, n1, n2] = n;
    let [d0, d1, d2] = d;
    let a0 = d2 * c2 + d1 * c + d0;
    Biquad::new(
        [
            (n2 * c2 + n1 * c + n0) / a0,
            2.0 * (n0 - n2 * c2) / a0,
            (n2 * c2 - n1 * c + n0) / a0,
        ],
        [2.0 * (d0 - d2 * c2) / a0, (d2 * c2 - d1 * c + d0) / a0],
    )
}

/// The W_d weighting filter at one sampling interval (causal, as the standard's filters).
#[derive(Debug, Clone, PartialEq)]
pub struct WdWeighting {
    sections: Vec<Biquad>,
}

impl WdWeighting {
    /// The filter for sampling interval `dt_s` \[s\]; `None` unless `dt_s` is finite, > 0 and
    /// the sampling rate is above 10 Hz (the transition section at 2 Hz needs it).
    pub fn new(dt_s: f64) -> Option<Self> {
        if !(dt_s.is_finite() && dt_s > 0.0 && 1.0 / dt_s > 10.0) {
            return None;
        }
        let (w1, w2, w3, w4) = (
            2.0 * PI * F1_HZ,
            2.0 * PI * F2_HZ,
            2.0 * PI * F3_HZ,
            2.0 * PI * F4_HZ,
        );
        let mut sections = vec![bilinear([0.0, 0.0, 1.0], [w1 * w1, w1 / Q1, 1.0], w1, dt_s)];
        if F2_HZ < 0.45 / dt_s {
            sections.push(bilinear(
                [w2 * w2, 0.0, 0.0],
                [w2 * w2, w2 / Q1, 1.0],
                w2,
                dt_s,
            ));
        }
        // (1 + s/w3) / (1 + s/(Q4 w4) + s^2/w4^2), times w4^2 above and below
        sections.push(bilinear(
            [w4 * w4, w4 * w4 / w3, 0.0],
            [w4 * w4, w4 / Q4, 1.0],
            w4,
            dt_s,
        ));
        Some(Self { sections })
    }

    /// `|W_d|` of the digital filter at `f_hz`.
    pub fn magnitude(&self, f_hz: f64, dt_s: f64) -> f64 {
        let wt = 2.0 * PI * f_hz * dt_s;
        self.sections
            .iter()
            .map(|s| s.gain_at(wt))
            .fold(crate::Complex64::new(1.0, 0.0), |a, g| a * g)
            .norm()
    }

    /// The weighted signal (from zero state).
    pub fn filter(&self, x: &[f64]) -> Vec<f64> {
        let mut s = self.sections.clone();
        x.iter()
            .map(|&v| s.iter_mut().fold(v, |y, b| b.process(y)))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ISO 2631-1:1997 Table 3, W_d (x 1000) at the one-third-octave centre frequencies; the
    /// standard allows +-1 dB (12 %) around the nominal; the exact analogue product matches
    /// these rounded values within 0.5 %, the digital filter at 1 kHz within 1 %.
    const TABLE_3: [(f64, f64); 16] = [
        (0.5, 853.0),
        (0.63, 944.0),
        (0.8, 992.0),
        (1.0, 1011.0),
        (1.25, 1008.0),
        (1.6, 968.0),
        (2.0, 890.0),
        (2.5, 776.0),
        (3.15, 642.0),
        (4.0, 512.0),
        (5.0, 409.0),
        (6.3, 323.0),
        (8.0, 253.0),
        (10.0, 202.0),
        (12.5, 161.0),
        (16.0, 125.0),
    ];

    #[test]
    fn magnitude_matches_the_iso_2631_table() {
        let dt = 1e-3;
        let w = WdWeighting::new(dt).unwrap();
        for (f, table) in TABLE_3 {
            let m = w.magnitude(f, dt) * 1000.0;
            assert!(
                (m - table).abs() <= 0.01 * table,
                "W_d({f} Hz) = {m:.1}, table {table}"
            );
        }
    }

    #[test]
    fn a_sine_is_weighted_by_the_table_value_and_bad_rates_are_refused() {
        // 4 Hz sine of amplitude 1 m/s^2: weighted rms 0.512 / sqrt(2) after the transient
        let dt = 1e-3;
        let x = crate::sampled(|t| (2.0 * PI * 4.0 * t).sin(), 1.0 / dt, 20.0);
        let y = WdWeighting::new(dt).unwrap().filter(&x);
        let r = crate::rms(&y[10_000..]);
        assert!((r - 0.512 / SQRT_2).abs() < 0.01 * 0.512, "{r}");
        // at 100 Hz sampling the band-limiting low-pass is left out; the weighting stays
        let w = WdWeighting::new(0.01).unwrap();
        assert_eq!(w.sections.len(), 2);
        assert!((w.magnitude(4.0, 0.01) - 0.512).abs() < 0.015 * 0.512);
        for bad in [0.0, -1e-3, f64::NAN, 0.2] {
            assert!(WdWeighting::new(bad).is_none(), "{bad}");
        }
    }
}
