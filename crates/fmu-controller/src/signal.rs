//! Discrete-time signal processing used by the control boards: biquads, Butterworth band-pass,
//! moving rms window, absolute-velocity estimator (high-pass + leaky integrator).
//!
//! All filters are designed for a fixed sample time with the bilinear (Tustin) transform; the
//! band-pass edges are pre-warped so that the -3 dB points are exact in the digital domain.

use serde::{Deserialize, Serialize};

use crate::ParamError;

/// Second-order section, direct form II transposed.
/// `y[n] = b0 x[n] + b1 x[n-1] + b2 x[n-2] - a1 y[n-1] - a2 y[n-2]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Biquad {
    pub b: [f64; 3],
    pub a: [f64; 2],
    s1: f64,
    s2: f64,
}

impl Biquad {
    pub fn new(b: [f64; 3], a: [f64; 2]) -> Self {
        Self {
            b,
            a,
            s1: 0.0,
            s2: 0.0,
        }
    }

    /// One sample.
    pub fn process(&mut self, x: f64) -> f64 {
        let y = self.b[0] * x + self.s1;
        self.s1 = self.b[1] * x - self.a[0] * y + self.s2;
        self.s2 = self.b[2] * x - self.a[1] * y;
        y
    }

    pub fn reset(&mut self) {
        self.s1 = 0.0;
        self.s2 = 0.0;
    }

    /// Complex gain at normalised angular frequency `wt = omega * T` (rad/sample).
    pub fn gain_at(&self, wt: f64) -> (f64, f64) {
        let z1 = C::expj(-wt);
        let z2 = z1.mul(z1);
        let num = C::re(self.b[0])
            .add(z1.scale(self.b[1]))
            .add(z2.scale(self.b[2]));
        let den = C::re(1.0).add(z1.scale(self.a[0])).add(z2.scale(self.a[1]));
        let g = num.div(den);
        (g.re, g.im)
    }
}

/// Minimal complex arithmetic (private; avoids a dependency).
#[derive(Debug, Clone, Copy)]
struct C {
    re: f64,
    im: f64,
}

impl C {
    fn new(re: f64, im: f64) -> Self {
        Self { re, im }
    }
    fn re(re: f64) -> Self {
        Self { re, im: 0.0 }
    }
    fn expj(phi: f64) -> Self {
        Self::new(phi.cos(), phi.sin())
    }
    fn add(self, o: C) -> C {
        C::new(self.re + o.re, self.im + o.im)
    }
    fn sub(self, o: C) -> C {
        C::new(self.re - o.re, self.im - o.im)
    }
    fn mul(self, o: C) -> C {
        C::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
    fn scale(self, k: f64) -> C {
        C::new(self.re * k, self.im * k)
    }
    fn div(self, o: C) -> C {
        let d = o.re * o.re + o.im * o.im;
        C::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
    fn conj(self) -> C {
        C::new(self.re, -self.im)
    }
    fn abs(self) -> f64 {
        self.re.hypot(self.im)
    }
    /// Principal square root.
    fn sqrt(self) -> C {
        let r = self.abs();
        let re = ((r + self.re) * 0.5).max(0.0).sqrt();
        let im = ((r - self.re) * 0.5).max(0.0).sqrt();
        C::new(re, if self.im < 0.0 { -im } else { im })
    }
}

/// Butterworth band-pass as a cascade of second-order sections, unit gain at the (geometric)
/// centre frequency, -3 dB at the two edges.
///
/// `order` is the band-pass order: 2 (one section, from a 1st-order low-pass prototype) or
/// 4 (two sections, from the 2nd-order Butterworth prototype).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BandPass {
    pub sections: Vec<Biquad>,
}

impl BandPass {
    /// Design for edges `f_low_hz < f_high_hz` at sample time `dt_s`.
    pub fn butterworth(
        order: u32,
        f_low_hz: f64,
        f_high_hz: f64,
        dt_s: f64,
    ) -> Result<Self, ParamError> {
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
        // Pre-warped analog edges so the digital -3 dB points are exact.
        let k = 2.0 / dt_s;
        let w1 = k * (std::f64::consts::PI * f_low_hz * dt_s).tan();
        let w2 = k * (std::f64::consts::PI * f_high_hz * dt_s).tan();
        let bw = w2 - w1;
        let w0sq = w1 * w2;
        // Digital centre frequency (rad/sample) where the gain is exactly 1.
        let wt0 = 2.0 * (w0sq.sqrt() / k).atan();
        // Upper-half-plane prototype poles.
        let proto: Vec<C> = match order {
            2 => vec![C::re(-1.0)],
            4 => vec![C::expj(0.75 * std::f64::consts::PI)],
            _ => {
                return Err(ParamError::new(
                    "filter_order",
                    format!("must be 2 or 4, got {order}"),
                ))
            }
        };
        let to_z = |s: C| {
            // z = (1 + s T/2) / (1 - s T/2) = (k + s)/(k - s)
            C::re(k).add(s).div(C::re(k).sub(s))
        };
        let mut sections = Vec::new();
        for p in proto {
            // Low-pass to band-pass: s_lp = (s^2 + w0^2)/(bw s)  =>  s^2 - p bw s + w0^2 = 0.
            let pb = p.scale(bw);
            let disc = pb.mul(pb).sub(C::re(4.0 * w0sq)).sqrt();
            let s1 = pb.add(disc).scale(0.5);
            let s2 = pb.sub(disc).scale(0.5);
            let pairs: Vec<(C, C)> = if p.im.abs() < 1e-12 {
                // Real prototype pole: s1, s2 are a conjugate pair or both real -> one section.
                vec![(s1, s2)]
            } else {
                // Complex prototype pole: its conjugate gives conj(s1), conj(s2).
                vec![(s1, s1.conj()), (s2, s2.conj())]
            };
            for (sa, sb) in pairs {
                let za = to_z(sa);
                let zb = to_z(sb);
                let a1 = -(za.add(zb)).re;
                let a2 = za.mul(zb).re;
                // Zeros at z = +1 and z = -1 (s = 0 and s = infinity).
                let mut bq = Biquad::new([1.0, 0.0, -1.0], [a1, a2]);
                let (gr, gi) = bq.gain_at(wt0);
                let g = gr.hypot(gi);
                if !(g.is_finite() && g > 0.0) {
                    return Err(ParamError::new("band_low_hz", "filter design failed"));
                }
                bq.b = [1.0 / g, 0.0, -1.0 / g];
                sections.push(bq);
            }
        }
        Ok(Self { sections })
    }

    pub fn process(&mut self, x: f64) -> f64 {
        let mut y = x;
        for s in &mut self.sections {
            y = s.process(y);
        }
        y
    }

    /// Magnitude of the frequency response at `f_hz` for sample time `dt_s`.
    pub fn magnitude(&self, f_hz: f64, dt_s: f64) -> f64 {
        let wt = 2.0 * std::f64::consts::PI * f_hz * dt_s;
        self.sections
            .iter()
            .map(|s| {
                let (r, i) = s.gain_at(wt);
                r.hypot(i)
            })
            .product()
    }

    pub fn reset(&mut self) {
        for s in &mut self.sections {
            s.reset();
        }
    }
}

/// Moving rms over the last `len` samples (ring buffer of squares, allocated once).
/// Before the window is full, the rms is taken over the samples seen so far.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RmsWindow {
    squares: Vec<f64>,
    head: usize,
    filled: usize,
    sum: f64,
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
    pub fn relative_gain(&self, f_hz: f64, dt_s: f64) -> (f64, f64) {
        let w = 2.0 * std::f64::consts::PI * f_hz;
        let (r, i) = self.filter.gain_at(w * dt_s);
        // multiply by j w
        (-i * w, r * w)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::PI;

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
            let mut bp = BandPass::butterworth(order, 2.0, 6.0, dt).unwrap();
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
        let bp2 = BandPass::butterworth(2, 2.0, 6.0, 1e-4).unwrap();
        let (w, w0sq, b): (f64, f64, f64) = (0.2, 12.0, 4.0);
        let analog = b * w / ((w0sq - w * w) * (w0sq - w * w) + (b * w) * (b * w)).sqrt();
        assert_relative_eq!(bp2.magnitude(0.2, 1e-4), analog, max_relative = 1e-3);
    }

    #[test]
    fn bandpass_rejects_bad_design() {
        assert_eq!(
            BandPass::butterworth(3, 2.0, 6.0, 1e-3).unwrap_err().name,
            "filter_order"
        );
        assert_eq!(
            BandPass::butterworth(4, 6.0, 2.0, 1e-3).unwrap_err().name,
            "band_high_hz"
        );
        assert_eq!(
            BandPass::butterworth(4, 2.0, 490.0, 1e-3).unwrap_err().name,
            "band_high_hz"
        );
        assert_eq!(
            BandPass::butterworth(4, -1.0, 6.0, 1e-3).unwrap_err().name,
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
        let (r, i) = est.relative_gain(f, dt);
        let mag = r.hypot(i);
        let phase = i.atan2(r);
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
