//! Lateral track alignment: ERRI B176 spectrum, sum-of-cosines synthesis, and a spatial
//! delay line for an external input. Shared by the time-domain models: a model with several
//! wheelsets evaluates one generator at each wheelset's position
//! ([`TrackGenerator::eval_behind`]), or records an external input at the leading wheelset in
//! one [`DelayLine`] and reads it back at each following wheelset's distance.
//!
//! Spectrum (one-sided, m^2/(rad/m)):
//! S(Omega) = A Omega_c^2 / ((Omega^2 + Omega_r^2)(Omega^2 + Omega_c^2)),
//! Omega_c = 0.8246 rad/m, Omega_r = 0.0206 rad/m, A = 2.119e-7 (low) / 6.125e-7 (high) m rad.
//! Signal: y(x) = sum_i a_i cos(Omega_i x + phi_i), a_i = sqrt(2 S(Omega_i) dOmega_i), phases
//! uniform from ChaCha8(seed); bins log-spaced over the wavelength band, each Omega_i drawn
//! uniformly inside its bin so the signal does not repeat. Its variance is sum a_i^2/2, the
//! integral of S over the band.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// Level of the ERRI B176 lateral alignment spectrum.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum PsdLevel {
    /// A = 2.119e-7 m rad.
    #[default]
    Low,
    /// A = 6.125e-7 m rad.
    High,
}

/// Omega_c [rad/m].
pub const OMEGA_C: f64 = 0.8246;
/// Omega_r [rad/m].
pub const OMEGA_R: f64 = 0.0206;

/// Spectrum constant A [m rad] of a level.
pub fn psd_a(level: PsdLevel) -> f64 {
    match level {
        PsdLevel::Low => 2.119e-7,
        PsdLevel::High => 6.125e-7,
    }
}

/// S(Omega) [m^2/(rad/m)].
pub fn psd(level: PsdLevel, omega: f64) -> f64 {
    let a = psd_a(level);
    a * OMEGA_C * OMEGA_C
        / ((omega * omega + OMEGA_R * OMEGA_R) * (omega * omega + OMEGA_C * OMEGA_C))
}

/// Integral of S over [omega_lo, omega_hi] (closed form by partial fractions) [m^2].
pub fn psd_integral(level: PsdLevel, omega_lo: f64, omega_hi: f64) -> f64 {
    let (c, r) = (OMEGA_C, OMEGA_R);
    let prim = |w: f64| ((w / r).atan() / r - (w / c).atan() / c) / (c * c - r * r);
    psd_a(level) * c * c * (prim(omega_hi) - prim(omega_lo))
}

/// Sum-of-cosines track alignment generator (plain data, serialisable).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrackGenerator {
    omega: Vec<f64>,
    amp: Vec<f64>,
    phase: Vec<f64>,
    /// Band [rad/m].
    pub omega_lo: f64,
    /// Band [rad/m].
    pub omega_hi: f64,
}

impl TrackGenerator {
    /// Default band: wavelengths 1 m to 120 m, 400 components.
    pub fn new(level: PsdLevel, seed: u64) -> Self {
        Self::with_band(level, seed, 1.0, 120.0, 400)
    }

    /// Generator over wavelengths [lambda_min_m, lambda_max_m] with `n` components.
    /// Arguments are clamped to sane values (n >= 1, lambda_min < lambda_max).
    pub fn with_band(
        level: PsdLevel,
        seed: u64,
        lambda_min_m: f64,
        lambda_max_m: f64,
        n: usize,
    ) -> Self {
        let n = n.max(1);
        let lmin = lambda_min_m.abs().max(1e-3);
        let lmax = lambda_max_m.abs().max(lmin * 1.001);
        let two_pi = 2.0 * std::f64::consts::PI;
        let (lo, hi) = (two_pi / lmax, two_pi / lmin);
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let ratio = (hi / lo).powf(1.0 / n as f64);
        let (mut omega, mut amp, mut phase) = (vec![], vec![], vec![]);
        let mut w0 = lo;
        for _ in 0..n {
            let w1 = w0 * ratio;
            let w = w0 + rng.gen::<f64>() * (w1 - w0);
            // bin power = exact integral over the bin, put at a random frequency inside it
            let power = psd_integral(level, w0, w1);
            omega.push(w);
            amp.push((2.0 * power).sqrt());
            phase.push(rng.gen::<f64>() * two_pi);
            w0 = w1;
        }
        Self {
            omega,
            amp,
            phase,
            omega_lo: lo,
            omega_hi: hi,
        }
    }

    /// Lateral alignment at track position x [m].
    pub fn eval(&self, x: f64) -> f64 {
        let mut s = 0.0;
        for i in 0..self.omega.len() {
            s += self.amp[i] * (self.omega[i] * x + self.phase[i]).cos();
        }
        s
    }

    /// Alignment under several wheelsets: `behind_m[k]` is how far wheelset k runs behind the
    /// track position x [m] (0 for the leading one); entry k is `eval(x - behind_m[k])`.
    pub fn eval_behind<const N: usize>(&self, x: f64, behind_m: [f64; N]) -> [f64; N] {
        behind_m.map(|d| self.eval(x - d))
    }

    /// Theoretical variance of the synthesised signal, sum a_i^2/2 [m^2].
    pub fn variance(&self) -> f64 {
        self.amp.iter().map(|a| 0.5 * a * a).sum()
    }
}

/// What [`DelayLine::undo`] needs to take back one push.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DelayUndo {
    head: usize,
    len: usize,
    slot: usize,
    x: f64,
    v: f64,
}

/// Spatial delay line: records the external alignment input at the front wheelset against
/// travelled distance, so the wheelsets behind it (e.g. the bogie's rear wheelset, 2p behind)
/// see the same track. Samples are stored every `spacing` metres at most (bounded memory for
/// any speed/step): 2048 samples over the delay it was made for.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DelayLine {
    x: Vec<f64>,
    v: Vec<f64>,
    head: usize,
    len: usize,
    spacing: f64,
}

impl DelayLine {
    /// Line able to look back `delay_m` metres (the distance of the last wheelset behind the
    /// first).
    pub fn new(delay_m: f64) -> Self {
        let cap = 4096;
        Self {
            x: vec![0.0; cap],
            v: vec![0.0; cap],
            head: 0,
            len: 0,
            spacing: (delay_m.abs() / (cap as f64 / 2.0)).max(1e-9),
        }
    }

    /// As [`Self::push`], returning what [`Self::undo`] needs to take it back (so a failed
    /// step leaves the line unchanged).
    pub fn push_undoable(&mut self, x: f64, value: f64) -> DelayUndo {
        let cap = self.x.len();
        let slot = if self.len >= 2 && x - self.x[(self.head + cap - 2) % cap] < self.spacing {
            (self.head + cap - 1) % cap
        } else {
            self.head
        };
        let u = DelayUndo {
            head: self.head,
            len: self.len,
            slot,
            x: self.x[slot],
            v: self.v[slot],
        };
        self.push(x, value);
        u
    }

    /// Takes back the push that returned `u` (must be the last change).
    pub fn undo(&mut self, u: DelayUndo) {
        self.head = u.head;
        self.len = u.len;
        self.x[u.slot] = u.x;
        self.v[u.slot] = u.v;
    }

    /// Records the value at position x (x non-decreasing).
    pub fn push(&mut self, x: f64, value: f64) {
        let cap = self.x.len();
        if self.len >= 2 {
            let last = (self.head + cap - 1) % cap;
            let prev = (self.head + cap - 2) % cap;
            if x - self.x[prev] < self.spacing {
                // closer than `spacing` to the sample before: replace the newest one
                self.x[last] = x;
                self.v[last] = value;
                return;
            }
        }
        self.x[self.head] = x;
        self.v[self.head] = value;
        self.head = (self.head + 1) % cap;
        self.len = (self.len + 1).min(cap);
    }

    /// Value at position x (linear interpolation); before the first sample, the first value
    /// (the track is taken as straight before the start); `None` if nothing was recorded.
    pub fn at(&self, x: f64) -> Option<f64> {
        if self.len == 0 {
            return None;
        }
        let cap = self.x.len();
        let idx = |k: usize| (self.head + cap - self.len + k) % cap; // k = 0 oldest
        let first = idx(0);
        if x <= self.x[first] {
            return Some(self.v[first]);
        }
        let last = idx(self.len - 1);
        if x >= self.x[last] {
            return Some(self.v[last]);
        }
        // binary search over the logical order
        let (mut lo, mut hi) = (0usize, self.len - 1);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if self.x[idx(mid)] <= x {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let (a, b) = (idx(lo), idx(hi));
        let dx = self.x[b] - self.x[a];
        if dx <= 0.0 {
            return Some(self.v[b]);
        }
        let t = (x - self.x[a]) / dx;
        Some(self.v[a] + t * (self.v[b] - self.v[a]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integral_matches_quadrature() {
        let (lo, hi) = (0.05, 6.0);
        let n = 200_000;
        let dw = (hi - lo) / n as f64;
        let q: f64 = (0..n)
            .map(|i| psd(PsdLevel::High, lo + (i as f64 + 0.5) * dw) * dw)
            .sum();
        let exact = psd_integral(PsdLevel::High, lo, hi);
        assert!((q - exact).abs() / exact < 1e-6, "{q} {exact}");
    }

    #[test]
    fn signal_variance_equals_psd_integral() {
        for (level, seed) in [(PsdLevel::Low, 1u64), (PsdLevel::High, 7u64)] {
            let g = TrackGenerator::new(level, seed);
            let target = psd_integral(level, g.omega_lo, g.omega_hi);
            assert!((g.variance() - target).abs() / target < 1e-9);
            // sample variance over 20 km of track (many longest wavelengths)
            let dx = 0.25;
            let n = 80_000;
            let (mut s, mut s2) = (0.0, 0.0);
            for i in 0..n {
                let y = g.eval(i as f64 * dx);
                s += y;
                s2 += y * y;
            }
            let mean = s / n as f64;
            let var = s2 / n as f64 - mean * mean;
            assert!(
                (var - target).abs() / target < 0.05,
                "{level:?}: var {var:e} vs integral {target:e}"
            );
        }
        // high level, 1-120 m: rms of a few mm
        let g = TrackGenerator::new(PsdLevel::High, 3);
        let rms = g.variance().sqrt();
        assert!(rms > 1e-3 && rms < 5e-3, "{rms}");
    }

    #[test]
    fn generator_is_reproducible() {
        let a = TrackGenerator::new(PsdLevel::Low, 42);
        let b = TrackGenerator::new(PsdLevel::Low, 42);
        let c = TrackGenerator::new(PsdLevel::Low, 43);
        assert_eq!(a.eval(123.4), b.eval(123.4));
        assert_ne!(a.eval(123.4), c.eval(123.4));
    }

    #[test]
    fn eval_behind_is_eval_at_each_wheelset() {
        let g = TrackGenerator::new(PsdLevel::High, 5);
        let x = 37.25;
        let ys = g.eval_behind(x, [0.0, 2.5, 17.5, 20.0]);
        for (y, d) in ys.iter().zip([0.0, 2.5, 17.5, 20.0]) {
            assert_eq!(y.to_bits(), g.eval(x - d).to_bits());
        }
        assert_ne!(ys[0], ys[1]);
    }

    #[test]
    fn delay_line_returns_past_values() {
        let mut d = DelayLine::new(2.5);
        assert!(d.at(0.0).is_none());
        for k in 0..100_000 {
            let x = k as f64 * 1e-3;
            d.push(x, x.sin());
        }
        let x = 99.999 - 2.5;
        let v = d.at(x).unwrap();
        assert!((v - x.sin()).abs() < 1e-5, "{v} {}", x.sin());
    }
}
