//! One second-order section.

use num_complex::Complex64;
use serde::{Deserialize, Serialize};

/// Second-order section `(b0 + b1 z^-1 + b2 z^-2) / (1 + a1 z^-1 + a2 z^-2)` in direct form II
/// transposed, with its two state values:
/// `y[n] = b0 x[n] + s1`, `s1 = b1 x[n] - a1 y[n] + s2`, `s2 = b2 x[n] - a2 y[n]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Biquad {
    /// `b0, b1, b2`.
    pub b: [f64; 3],
    /// `a1, a2` (`a0 = 1`).
    pub a: [f64; 2],
    s1: f64,
    s2: f64,
}

impl Biquad {
    /// A section with zero state.
    pub fn new(b: [f64; 3], a: [f64; 2]) -> Self {
        Self {
            b,
            a,
            s1: 0.0,
            s2: 0.0,
        }
    }

    /// One sample through the section.
    pub fn process(&mut self, x: f64) -> f64 {
        let y = self.b[0] * x + self.s1;
        self.s1 = self.b[1] * x - self.a[0] * y + self.s2;
        self.s2 = self.b[2] * x - self.a[1] * y;
        y
    }

    /// Back to zero state.
    pub fn reset(&mut self) {
        self.s1 = 0.0;
        self.s2 = 0.0;
    }

    /// Complex gain at the normalised angular frequency `wt = omega T` [rad/sample].
    pub fn gain_at(&self, wt: f64) -> Complex64 {
        let z1 = Complex64::cis(-wt);
        let z2 = z1 * z1;
        let num = Complex64::new(self.b[0], 0.0) + z1.scale(self.b[1]) + z2.scale(self.b[2]);
        let den = Complex64::new(1.0, 0.0) + z1.scale(self.a[0]) + z2.scale(self.a[1]);
        num / den
    }
}

/// Causal filtering of a whole signal through a cascade of sections, each from zero state
/// (the sections' own state is untouched).
pub(crate) fn cascade_filter(sections: &[Biquad], x: &[f64]) -> Vec<f64> {
    let mut y = x.to_vec();
    for s in sections {
        let mut s = Biquad::new(s.b, s.a);
        for v in y.iter_mut() {
            *v = s.process(*v);
        }
    }
    y
}

/// Zero-phase filtering through a cascade (forward and backward; gain |H|^2), with odd
/// reflection padding of `pad` samples at both ends to shorten the start transients.
pub(crate) fn cascade_filtfilt(sections: &[Biquad], x: &[f64], pad: usize) -> Vec<f64> {
    let n = x.len();
    if n == 0 {
        return Vec::new();
    }
    let pad = pad.min(n - 1);
    let mut ext = Vec::with_capacity(n + 2 * pad);
    for i in (1..=pad).rev() {
        ext.push(2.0 * x[0] - x[i]);
    }
    ext.extend_from_slice(x);
    for i in 1..=pad {
        ext.push(2.0 * x[n - 1] - x[n - 1 - i]);
    }
    let mut y = cascade_filter(sections, &ext);
    y.reverse();
    let mut y = cascade_filter(sections, &y);
    y.reverse();
    y[pad..pad + n].to_vec()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn impulse_response_of_a_known_section() {
        // y[n] = x[n] + 0.5 y[n-1]: impulse response 0.5^n
        let mut s = Biquad::new([1.0, 0.0, 0.0], [-0.5, 0.0]);
        let y: Vec<f64> = (0..5)
            .map(|n| s.process(if n == 0 { 1.0 } else { 0.0 }))
            .collect();
        assert_eq!(y, vec![1.0, 0.5, 0.25, 0.125, 0.0625]);
        // DC gain 1 / (1 - 0.5) = 2, Nyquist gain 1 / 1.5
        assert!((s.gain_at(0.0).re - 2.0).abs() < 1e-15);
        assert!((s.gain_at(std::f64::consts::PI).norm() - 1.0 / 1.5).abs() < 1e-15);
        s.reset();
        assert_eq!(s.process(1.0), 1.0);
    }
}
