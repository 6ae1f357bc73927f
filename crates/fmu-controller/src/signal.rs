//! Discrete-time signal processing used by the control boards: Butterworth band-pass (the
//! shared design of the `signal-processing` crate), moving rms window, absolute-velocity
//! estimator (high-pass + leaky integrator).
//!
//! All filters are designed for a fixed sample time with the bilinear (Tustin) transform; the
//! band-pass edges are pre-warped so that the -3 dB points are exact in the digital domain.

use serde::{Deserialize, Serialize};
pub use signal_processing::{BandPass, Biquad};
use signal_processing::{Complex64, DesignParameter};

use crate::ParamError;

/// Butterworth band-pass of the boards (the shared design of `signal-processing`), with the
/// controllers' parameter names and limits.
///
/// `order` is the band-pass order: 2 (one section, from a 1st-order low-pass prototype) or
/// 4 (two sections, from the 2nd-order Butterworth prototype). The upper edge must stay below
/// 0.9 x Nyquist (the board's anti-aliasing margin).
pub fn band_pass(
    order: u32,
    f_low_hz: f64,
    f_high_hz: f64,
    dt_s: f64,
) -> Result<BandPass, ParamError> {
    // The boards' own messages name their parameters, and the lower edge in the upper's.
    let nyq = 0.5 / dt_s;
    if !(f_low_hz.is_finite() && f_low_hz > 0.0) {
        return Err(ParamError::new("band_low_hz", "must be finite and > 0"));
    }
    if !(f_high_hz.is_finite() && f_high_hz > f_low_hz) {
        return Err(ParamError::new(
            "band_high_hz",
            "must be finite and > band_low_hz",
        ));
    }
    if f_high_hz >= 0.9 * nyq {
        return Err(ParamError::new(
            "band_high_hz",
            format!(
                "must be below 0.9 x Nyquist of sample_time_s = {} Hz",
                0.9 * nyq
            ),
        ));
    }
    let prototype_order = match order {
        2 => 1,
        4 => 2,
        _ => {
            return Err(ParamError::new(
                "filter_order",
                format!("must be 2 or 4, got {order}"),
            ))
        }
    };
    BandPass::butterworth(prototype_order, f_low_hz, f_high_hz, dt_s).map_err(|e| {
        let name = match e.parameter {
            DesignParameter::SampleTime => "sample_time_s",
            DesignParameter::LowEdge => "band_low_hz",
            DesignParameter::HighEdge => "band_high_hz",
            DesignParameter::Order => "filter_order",
        };
        ParamError::new(name, e.reason)
    })
}

/// Moving rms over the last `len` samples (ring buffer of squares, allocated once).
/// Before the window is full, the rms is taken over the samples seen so far.
/// A deserialised window (a saved FMU state, say) is checked for the ring's invariants.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RmsRing")]
pub struct RmsWindow {
    squares: Vec<f64>,
    head: usize,
    filled: usize,
    sum: f64,
}

/// The serialised form of [`RmsWindow`] before its checks.
#[derive(Deserialize)]
struct RmsRing {
    squares: Vec<f64>,
    head: usize,
    filled: usize,
    sum: f64,
}

impl TryFrom<RmsRing> for RmsWindow {
    type Error = String;
    fn try_from(r: RmsRing) -> Result<Self, String> {
        let len = r.squares.len();
        if len == 0 || r.head >= len || r.filled > len {
            return Err(format!(
                "rms window: {len} samples, head {}, filled {}: not a ring",
                r.head, r.filled
            ));
        }
        Ok(RmsWindow {
            squares: r.squares,
            head: r.head,
            filled: r.filled,
            sum: r.sum,
        })
    }
}

impl RmsWindow {
    pub fn new(len: usize) -> Self {
        Self {
            squares: vec![0.0; len.max(1)],
            head: 0,
            filled: 0,
            sum: 0.0,
        }
    }

    pub fn len(&self) -> usize {
        self.squares.len()
    }

    pub fn is_empty(&self) -> bool {
        self.filled == 0
    }

    pub fn push(&mut self, x: f64) {
        let sq = x * x;
        let old = self.squares[self.head];
        self.squares[self.head] = sq;
        self.head += 1;
        if self.filled < self.squares.len() {
            self.filled += 1;
            self.sum += sq;
        } else {
            self.sum += sq - old;
        }
        if self.head == self.squares.len() {
            self.head = 0;
            // Exact re-summation once per window: no drift from the running subtraction.
            self.sum = self.squares[..self.filled].iter().sum();
        }
    }

    pub fn rms(&self) -> f64 {
        if self.filled == 0 {
            0.0
        } else {
            (self.sum.max(0.0) / self.filled as f64).sqrt()
        }
    }

    pub fn reset(&mut self) {
        self.squares.iter_mut().for_each(|s| *s = 0.0);
        self.head = 0;
        self.filled = 0;
        self.sum = 0.0;
    }
}

/// Absolute velocity from an accelerometer, practical sky-hook scheme of section 2.3.2:
/// a first-order high-pass on the acceleration (removes offset / thermal drift) followed by a
/// leaky integrator, both with corner `fc`: `G(s) = s / (s + wc)^2`.
///
/// Relative to an ideal integrator at `f`, the gain is `1/(1 + (fc/f)^2)` and the phase lead
/// `2 atan(fc/f)`: at 4 Hz with fc = 0.3 Hz, -0.6 % and +8.6 deg. A constant acceleration offset
/// gives zero velocity in steady state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VelocityEstimator {
    filter: Biquad,
}

impl VelocityEstimator {
    pub fn new(corner_hz: f64, dt_s: f64) -> Self {
        let k = 2.0 / dt_s;
        let wc = 2.0 * std::f64::consts::PI * corner_hz;
        let a0 = (k + wc) * (k + wc);
        let r = (wc - k) / (k + wc);
        Self {
            filter: Biquad::new([k / a0, 0.0, -k / a0], [2.0 * r, r * r]),
        }
    }

    pub fn process(&mut self, accel: f64) -> f64 {
        self.filter.process(accel)
    }

    /// Complex gain relative to `1/(j w)` at `f_hz` (ideal integrator = 1 + 0j).
    pub fn relative_gain(&self, f_hz: f64, dt_s: f64) -> Complex64 {
        let w = 2.0 * std::f64::consts::PI * f_hz;
        let g = self.filter.gain_at(w * dt_s);
        // multiply by j w
        Complex64::new(-g.im * w, g.re * w)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::PI;

    #[test]
    fn a_deserialised_rms_window_must_be_a_ring() {
        let mut w = RmsWindow::new(4);
        w.push(1.0);
        let good = serde_json::to_value(&w).unwrap();
        assert_eq!(
            serde_json::from_value::<RmsWindow>(good.clone()).unwrap(),
            w
        );
        for (field, value) in [
            ("head", serde_json::json!(4)),
            ("filled", serde_json::json!(5)),
            ("squares", serde_json::json!([])),
        ] {
            let mut bad = good.clone();
            bad[field] = value;
            let e = serde_json::from_value::<RmsWindow>(bad).unwrap_err();
            assert!(e.to_string().contains("rms window"), "{field}: {e}");
        }
    }

    /// Steady-state rms of the filter output for a unit sinusoid, measured by simulation.
    fn sim_gain(bp: &mut BandPass, f: f64, dt: f64) -> f64 {
        bp.reset();
        let n_settle = (5.0 / dt) as usize;
        let n_meas = (10.0 / f / dt).round() as usize; // 10 periods
        let mut w = RmsWindow::new(n_meas);
        for i in 0..(n_settle + n_meas) {
            let y = bp.process((2.0 * PI * f * i as f64 * dt).sin());
            if i >= n_settle {
                w.push(y);
            }
        }
        w.rms() * 2f64.sqrt()
    }

    #[test]
    fn bandpass_unit_gain_at_centre_and_small_outside() {
        let dt = 1e-3;
        for order in [2, 4] {
            let mut bp = band_pass(order, 2.0, 6.0, dt).unwrap();
            let fc = (2.0f64 * 6.0).sqrt();
            // Analytic response: 1 at the geometric centre, 1/sqrt(2) at the edges.
            assert_relative_eq!(bp.magnitude(fc, dt), 1.0, epsilon = 1e-6);
            assert_relative_eq!(bp.magnitude(2.0, dt), 0.5f64.sqrt(), epsilon = 1e-9);
            assert_relative_eq!(bp.magnitude(6.0, dt), 0.5f64.sqrt(), epsilon = 1e-9);
            // Simulated steady-state gain agrees with the analytic one.
            assert_relative_eq!(sim_gain(&mut bp, fc, dt), 1.0, epsilon = 0.01);
            assert_relative_eq!(
                sim_gain(&mut bp, 4.0, dt),
                bp.magnitude(4.0, dt),
                epsilon = 0.01
            );
            // Far outside: Butterworth |H| at f = 0.2 Hz and 50 Hz.
            let lim = if order == 2 { 0.12 } else { 0.012 };
            assert!(bp.magnitude(0.2, dt) < lim, "order {order}");
            assert!(bp.magnitude(50.0, dt) < lim, "order {order}");
            assert!(sim_gain(&mut bp, 50.0, dt) < lim);
        }
        // Analog 2nd-order BP value at 0.2 Hz: B w / sqrt((w0^2-w^2)^2 + (B w)^2) with B = 4 Hz.
        let bp2 = band_pass(2, 2.0, 6.0, 1e-4).unwrap();
        let (w, w0sq, b): (f64, f64, f64) = (0.2, 12.0, 4.0);
        let analog = b * w / ((w0sq - w * w) * (w0sq - w * w) + (b * w) * (b * w)).sqrt();
        assert_relative_eq!(bp2.magnitude(0.2, 1e-4), analog, max_relative = 1e-3);
    }

    #[test]
    fn bandpass_rejects_bad_design() {
        assert_eq!(
            band_pass(3, 2.0, 6.0, 1e-3).unwrap_err().name,
            "filter_order"
        );
        assert_eq!(
            band_pass(4, 6.0, 2.0, 1e-3).unwrap_err().name,
            "band_high_hz"
        );
        assert_eq!(
            band_pass(4, 2.0, 490.0, 1e-3).unwrap_err().name,
            "band_high_hz"
        );
        assert_eq!(
            band_pass(4, -1.0, 6.0, 1e-3).unwrap_err().name,
            "band_low_hz"
        );
    }

    #[test]
    fn rms_of_sinusoid_is_amplitude_over_sqrt2() {
        let dt = 1e-3;
        let a = 3.7;
        // 1 s window over a 4 Hz sine: exactly 4 periods.
        let mut w = RmsWindow::new(1000);
        for i in 0..5000 {
            w.push(a * (2.0 * PI * 4.0 * i as f64 * dt + 0.3).sin());
        }
        assert_relative_eq!(w.rms(), a / 2f64.sqrt(), max_relative = 1e-9);
        // Constant signal, partially filled window.
        let mut w2 = RmsWindow::new(100);
        for _ in 0..10 {
            w2.push(-2.0);
        }
        assert_relative_eq!(w2.rms(), 2.0, max_relative = 1e-12);
    }

    #[test]
    fn velocity_estimator_integrates_at_hunting_frequency_and_rejects_offset() {
        let dt = 1e-3;
        let fc = 0.3;
        let f = 4.0;
        let est = VelocityEstimator::new(fc, dt);
        let g = est.relative_gain(f, dt);
        let (mag, phase) = (g.norm(), g.arg());
        let q = fc / f;
        assert_relative_eq!(mag, 1.0 / (1.0 + q * q), max_relative = 1e-3);
        assert_relative_eq!(phase, 2.0 * q.atan(), max_relative = 1e-2);
        // Time domain: x = X sin(wt) -> a = -X w^2 sin(wt), v = X w cos(wt).
        let mut est = VelocityEstimator::new(fc, dt);
        let w = 2.0 * PI * f;
        let x_amp = 2e-3;
        let mut err = RmsWindow::new(1000);
        for k in 0..20_000 {
            let t = k as f64 * dt;
            // plus an accelerometer offset of 0.2 m/s^2 which must not drift the velocity
            let v = est.process(-x_amp * w * w * (w * t).sin() + 0.2);
            if k >= 19_000 {
                err.push(v - x_amp * w * (w * t).cos());
            }
        }
        // rms error / rms velocity ~ |1 - G_rel| = about 2 sin(phase/2) = 0.15 at 4 Hz
        let rel = err.rms() / (x_amp * w / 2f64.sqrt());
        assert!(rel < 0.16, "relative error {rel}");
        assert!(rel > 0.10, "phase lead should show, relative error {rel}");
    }
}
