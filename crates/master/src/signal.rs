//! Signal processing for the assessment: FFT, Welch spectrum, dominant frequency, Butterworth
//! band-pass (zero-phase), rms over sliding distance windows.

use std::f64::consts::PI;
use std::ops::{Add, Div, Mul, Sub};

/// A signal-processing input problem, naming the parameter.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SignalError {
    #[error("parameter '{name}' = {value}: {reason}")]
    InvalidParameter {
        name: &'static str,
        value: f64,
        reason: &'static str,
    },
    #[error("signal has {samples} samples, needs at least {needed} ({what})")]
    TooShort {
        samples: usize,
        needed: usize,
        what: &'static str,
    },
    #[error("signal contains a non-finite value at sample {index}")]
    NonFinite { index: usize },
    #[error("no spectral peak between {f_min} and {f_max} Hz")]
    NoPeak { f_min: f64, f_max: f64 },
}

fn check(
    name: &'static str,
    value: f64,
    ok: bool,
    reason: &'static str,
) -> Result<(), SignalError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(SignalError::InvalidParameter {
            name,
            value,
            reason,
        })
    }
}

fn check_finite(x: &[f64]) -> Result<(), SignalError> {
    match x.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(SignalError::NonFinite { index }),
        None => Ok(()),
    }
}

/// Minimal complex number.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct C64 {
    pub re: f64,
    pub im: f64,
}

impl C64 {
    pub const fn new(re: f64, im: f64) -> Self {
        C64 { re, im }
    }
    pub fn scale(self, s: f64) -> C64 {
        C64::new(self.re * s, self.im * s)
    }
    pub fn abs(self) -> f64 {
        self.re.hypot(self.im)
    }
    pub fn sqrt(self) -> C64 {
        let r = self.abs();
        let re = ((r + self.re) / 2.0).max(0.0).sqrt();
        let im = ((r - self.re) / 2.0).max(0.0).sqrt();
        C64::new(re, if self.im < 0.0 { -im } else { im })
    }
    pub fn expj(theta: f64) -> C64 {
        C64::new(theta.cos(), theta.sin())
    }
}

impl std::ops::Add for C64 {
    type Output = C64;
    fn add(self, o: C64) -> C64 {
        C64::new(self.re + o.re, self.im + o.im)
    }
}

impl std::ops::Sub for C64 {
    type Output = C64;
    fn sub(self, o: C64) -> C64 {
        C64::new(self.re - o.re, self.im - o.im)
    }
}

impl std::ops::Mul for C64 {
    type Output = C64;
    fn mul(self, o: C64) -> C64 {
        C64::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
}

impl std::ops::Div for C64 {
    type Output = C64;
    fn div(self, o: C64) -> C64 {
        let d = o.re * o.re + o.im * o.im;
        C64::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
}

/// In-place radix-2 FFT; `x.len()` must be a power of two (not checked beyond debug).
pub fn fft(x: &mut [C64]) {
    let n = x.len();
    if n < 2 {
        return;
    }
    let mut j = 0;
    for i in 1..n {
        let mut bit = n >> 1;
        while j & bit != 0 {
            j ^= bit;
            bit >>= 1;
        }
        j |= bit;
        if i < j {
            x.swap(i, j);
        }
    }
    let mut len = 2;
    while len <= n {
        let w = C64::expj(-2.0 * PI / len as f64);
        for start in (0..n).step_by(len) {
            let mut wk = C64::new(1.0, 0.0);
            for k in 0..len / 2 {
                let a = x[start + k];
                let b = x[start + k + len / 2].mul(wk);
                x[start + k] = a.add(b);
                x[start + k + len / 2] = a.sub(b);
                wk = wk.mul(w);
            }
        }
        len <<= 1;
    }
}

/// Welch power spectral density (Hann window, 50 % overlap, segments of `seg_len` samples
/// rounded up to a power of two, mean removed per segment). Returns (frequencies [Hz], PSD
/// [unit^2/Hz], one-sided).
pub fn welch(x: &[f64], fs: f64, seg_len: usize) -> Result<(Vec<f64>, Vec<f64>), SignalError> {
    check("fs", fs, fs > 0.0, "sampling rate must be > 0")?;
    check_finite(x)?;
    let n = seg_len.max(8).next_power_of_two();
    if x.len() < n {
        return Err(SignalError::TooShort {
            samples: x.len(),
            needed: n,
            what: "one Welch segment",
        });
    }
    let win: Vec<f64> = (0..n)
        .map(|i| 0.5 - 0.5 * (2.0 * PI * i as f64 / n as f64).cos())
        .collect();
    let wss: f64 = win.iter().map(|w| w * w).sum();
    let mut psd = vec![0.0; n / 2 + 1];
    let mut segments = 0usize;
    let mut buf = vec![C64::default(); n];
    let mut start = 0;
    while start + n <= x.len() {
        let seg = &x[start..start + n];
        let mean = seg.iter().sum::<f64>() / n as f64;
        for (b, (s, w)) in buf.iter_mut().zip(seg.iter().zip(&win)) {
            *b = C64::new((s - mean) * w, 0.0);
        }
        fft(&mut buf);
        for (k, p) in psd.iter_mut().enumerate() {
            let scale = if k == 0 || k == n / 2 { 1.0 } else { 2.0 };
            *p += scale * buf[k].abs().powi(2) / (fs * wss);
        }
        segments += 1;
        start += n / 2;
    }
    psd.iter_mut().for_each(|p| *p /= segments as f64);
    let freqs = (0..=n / 2).map(|k| k as f64 * fs / n as f64).collect();
    Ok((freqs, psd))
}

/// Frequency of the largest Welch-PSD peak in `[f_min, f_max]`, refined by a parabola through
/// the peak bin and its neighbours. Segments of about 10 s (or the whole signal if shorter).
pub fn dominant_frequency(x: &[f64], fs: f64, f_min: f64, f_max: f64) -> Result<f64, SignalError> {
    check("f_min", f_min, f_min >= 0.0, "must be >= 0")?;
    check("f_max", f_max, f_max > f_min, "must be > f_min")?;
    let seg = ((10.0 * fs) as usize).min(x.len()).max(8);
    // largest power of two not above the signal length, so at least one segment fits
    let seg = if seg.is_power_of_two() {
        seg
    } else {
        seg.next_power_of_two() / 2
    };
    let (f, p) = welch(x, fs, seg)?;
    let best = (1..p.len() - 1)
        .filter(|&k| f[k] >= f_min && f[k] <= f_max)
        .max_by(|&a, &b| p[a].total_cmp(&p[b]))
        .filter(|&k| p[k] > 0.0)
        .ok_or(SignalError::NoPeak { f_min, f_max })?;
    let (a, b, c) = (p[best - 1].ln(), p[best].ln(), p[best + 1].ln());
    let den = a - 2.0 * b + c;
    let shift = if den.abs() > 0.0 && den.is_finite() {
        (0.5 * (a - c) / den).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    Ok(f[best] + shift * (f[1] - f[0]))
}

/// One second-order section: b0 + b1 z^-1 + b2 z^-2 over 1 + a1 z^-1 + a2 z^-2.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Biquad {
    pub b: [f64; 3],
    pub a: [f64; 2],
}

impl Biquad {
    fn response(&self, z1: C64) -> C64 {
        // z1 = z^-1
        let z2 = z1.mul(z1);
        let num = C64::new(self.b[0], 0.0)
            .add(z1.scale(self.b[1]))
            .add(z2.scale(self.b[2]));
        let den = C64::new(1.0, 0.0)
            .add(z1.scale(self.a[0]))
            .add(z2.scale(self.a[1]));
        num.div(den)
    }
}

/// Digital Butterworth band-pass of prototype order `order` (the band-pass has order
/// 2*order), edges `f_lo`, `f_hi` [Hz] (-3 dB), by the band-pass transform of the analogue
/// prototype and the bilinear transform with pre-warped edges; unit gain at the centre.
#[derive(Debug, Clone, PartialEq)]
pub struct BandPass {
    pub sections: Vec<Biquad>,
    pub fs: f64,
}

impl BandPass {
    pub fn butterworth(order: usize, f_lo: f64, f_hi: f64, fs: f64) -> Result<Self, SignalError> {
        check("fs", fs, fs > 0.0, "sampling rate must be > 0")?;
        check("f_lo", f_lo, f_lo > 0.0, "lower band edge must be > 0")?;
        check(
            "f_hi",
            f_hi,
            f_hi > f_lo && f_hi < fs / 2.0,
            "upper band edge must lie between f_lo and fs/2",
        )?;
        check(
            "order",
            order as f64,
            (1..=10).contains(&order),
            "filter order must be 1..=10",
        )?;
        let w1 = 2.0 * fs * (PI * f_lo / fs).tan();
        let w2 = 2.0 * fs * (PI * f_hi / fs).tan();
        let w0 = (w1 * w2).sqrt();
        let bw = w2 - w1;
        let mut poles = Vec::with_capacity(2 * order);
        for k in 0..order {
            let p = C64::expj(PI * (2 * k + order + 1) as f64 / (2 * order) as f64);
            let half = p.scale(bw / 2.0);
            let root = half.mul(half).sub(C64::new(w0 * w0, 0.0)).sqrt();
            for s in [half.add(root), half.sub(root)] {
                let two_fs = C64::new(2.0 * fs, 0.0);
                poles.push(two_fs.add(s).div(two_fs.sub(s)));
            }
        }
        let mut sections = Vec::new();
        let mut reals = Vec::new();
        for z in &poles {
            if z.im > 1e-12 {
                sections.push(Biquad {
                    b: [1.0, 0.0, -1.0],
                    a: [-2.0 * z.re, z.re * z.re + z.im * z.im],
                });
            } else if z.im.abs() <= 1e-12 {
                reals.push(z.re);
            }
        }
        for pair in reals.chunks(2) {
            let (p1, p2) = (pair[0], pair.get(1).copied().unwrap_or(0.0));
            sections.push(Biquad {
                b: [1.0, 0.0, -1.0],
                a: [-(p1 + p2), p1 * p2],
            });
        }
        let mut f = BandPass { sections, fs };
        let wc = 2.0 * (w0 / (2.0 * fs)).atan();
        let g = f.gain_at_omega(wc);
        if let Some(s) = f.sections.first_mut() {
            s.b.iter_mut().for_each(|b| *b /= g);
        }
        Ok(f)
    }

    fn gain_at_omega(&self, w: f64) -> f64 {
        let z1 = C64::expj(-w);
        self.sections
            .iter()
            .fold(C64::new(1.0, 0.0), |acc, s| acc.mul(s.response(z1)))
            .abs()
    }

    /// |H(f)| of one pass.
    pub fn gain(&self, f: f64) -> f64 {
        self.gain_at_omega(2.0 * PI * f / self.fs)
    }

    /// Causal filtering (direct form II transposed, zero initial state).
    pub fn filter(&self, x: &[f64]) -> Vec<f64> {
        let mut y = x.to_vec();
        for s in &self.sections {
            let (mut z1, mut z2) = (0.0, 0.0);
            for v in y.iter_mut() {
                let xin = *v;
                let out = s.b[0] * xin + z1;
                z1 = s.b[1] * xin - s.a[0] * out + z2;
                z2 = s.b[2] * xin - s.a[1] * out;
                *v = out;
            }
        }
        y
    }

    /// Zero-phase filtering (forward and backward; gain |H|^2), with odd reflection padding of
    /// `pad` samples at both ends to shorten the start transients.
    pub fn filtfilt(&self, x: &[f64], pad: usize) -> Vec<f64> {
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
        let mut y = self.filter(&ext);
        y.reverse();
        let mut y = self.filter(&y);
        y.reverse();
        y[pad..pad + n].to_vec()
    }
}

/// Root mean square.
pub fn rms(x: &[f64]) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt()
}

/// RMS over sliding windows of `window_m` metres advanced by `step_m` metres, for a signal
/// sampled at `fs` while running at constant `speed_mps`. Returns (window centre [m], rms).
pub fn sliding_rms_distance(
    x: &[f64],
    fs: f64,
    speed_mps: f64,
    window_m: f64,
    step_m: f64,
) -> Result<Vec<(f64, f64)>, SignalError> {
    check("fs", fs, fs > 0.0, "sampling rate must be > 0")?;
    check("speed_mps", speed_mps, speed_mps > 0.0, "speed must be > 0")?;
    check(
        "window_m",
        window_m,
        window_m > 0.0,
        "window length must be > 0",
    )?;
    check("step_m", step_m, step_m > 0.0, "window step must be > 0")?;
    check_finite(x)?;
    let win = (window_m / speed_mps * fs).round() as usize;
    let win = win.max(1);
    if x.len() < win {
        return Err(SignalError::TooShort {
            samples: x.len(),
            needed: win,
            what: "one rms window",
        });
    }
    // prefix sums of squares (compensated) so every window costs O(1)
    let mut pre = Vec::with_capacity(x.len() + 1);
    pre.push(0.0);
    let (mut sum, mut comp) = (0.0f64, 0.0f64);
    for v in x {
        let y = v * v - comp;
        let t = sum + y;
        comp = (t - sum) - y;
        sum = t;
        pre.push(sum);
    }
    let mut out = Vec::new();
    let mut k = 0usize;
    loop {
        let start_m = k as f64 * step_m;
        let i0 = (start_m / speed_mps * fs).round() as usize;
        let i1 = i0 + win;
        if i1 > x.len() {
            break;
        }
        let ms = ((pre[i1] - pre[i0]) / win as f64).max(0.0);
        out.push((start_m + window_m / 2.0, ms.sqrt()));
        k += 1;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn sine(a: f64, f: f64, fs: f64, secs: f64, phase: f64) -> Vec<f64> {
        (0..(secs * fs) as usize)
            .map(|i| a * (2.0 * PI * f * i as f64 / fs + phase).sin())
            .collect()
    }

    #[test]
    fn fft_of_a_cosine() {
        let n = 64;
        let mut x: Vec<C64> = (0..n)
            .map(|i| C64::new((2.0 * PI * 5.0 * i as f64 / n as f64).cos(), 0.0))
            .collect();
        fft(&mut x);
        assert_relative_eq!(x[5].re, 32.0, epsilon = 1e-9);
        assert_relative_eq!(x[59].re, 32.0, epsilon = 1e-9);
        assert!(x[4].abs() < 1e-9 && x[0].abs() < 1e-9);
    }

    #[test]
    fn welch_integrates_to_the_variance() {
        let fs = 200.0;
        let x = sine(3.0, 7.3, fs, 60.0, 0.2);
        let (f, p) = welch(&x, fs, 1024).unwrap();
        let var: f64 = p.iter().sum::<f64>() * (f[1] - f[0]);
        // Hann-window leakage stays inside the sum: variance A^2/2 = 4.5 within 2 %
        assert_relative_eq!(var, 4.5, max_relative = 0.02);
    }

    #[test]
    fn dominant_frequency_of_noisy_sine() {
        let fs = 200.0;
        let mut x = sine(1.0, 3.7, fs, 60.0, 0.0);
        let y = sine(0.3, 11.0, fs, 60.0, 1.0);
        x.iter_mut().zip(&y).for_each(|(a, b)| *a += b);
        let f = dominant_frequency(&x, fs, 1.0, 20.0).unwrap();
        assert!((f - 3.7).abs() < 0.05, "{f}");
        // restricting the search range finds the other one
        let f = dominant_frequency(&x, fs, 8.0, 20.0).unwrap();
        assert!((f - 11.0).abs() < 0.05, "{f}");
    }

    #[test]
    fn butterworth_bandpass_gains() {
        let fs = 500.0;
        let bp = BandPass::butterworth(2, 2.0, 6.0, fs).unwrap();
        assert_eq!(bp.sections.len(), 2);
        let centre = (2.0f64 * 6.0).sqrt();
        assert_relative_eq!(bp.gain(centre), 1.0, epsilon = 1e-9);
        // -3 dB at both edges (pre-warped)
        assert_relative_eq!(bp.gain(2.0), 0.5f64.sqrt(), epsilon = 1e-6);
        assert_relative_eq!(bp.gain(6.0), 0.5f64.sqrt(), epsilon = 1e-6);
        // analogue Butterworth magnitude: 1/sqrt(1 + ((w^2 - w0^2)/(w B))^(2N)); at 4 Hz
        let q: f64 = (16.0 - 12.0) / (4.0 * 4.0);
        assert_relative_eq!(bp.gain(4.0), 1.0 / (1.0 + q.powi(4)).sqrt(), epsilon = 1e-3);
        // the digital response equals the analogue one at the pre-warped frequency
        for f in [0.5, 1.0, 3.0, 5.0, 9.0, 20.0, 100.0] {
            let w = 2.0 * fs * (PI * f / fs).tan();
            let w1 = 2.0 * fs * (PI * 2.0 / fs).tan();
            let w2 = 2.0 * fs * (PI * 6.0 / fs).tan();
            let q = (w * w - w1 * w2) / (w * (w2 - w1));
            assert_relative_eq!(
                bp.gain(f),
                1.0 / (1.0 + q.powi(4)).sqrt(),
                max_relative = 1e-9
            );
        }
        assert!(bp.gain(0.5) < 0.03 && bp.gain(20.0) < 0.045);
        assert!(BandPass::butterworth(2, 2.0, 300.0, fs).is_err());
        assert!(BandPass::butterworth(0, 2.0, 6.0, fs).is_err());
    }

    #[test]
    fn filtfilt_keeps_in_band_and_removes_out_of_band() {
        let fs = 500.0;
        let bp = BandPass::butterworth(2, 2.0, 6.0, fs).unwrap();
        let a = 2.0;
        let x = sine(a, 4.0, fs, 40.0, 0.3);
        let y = bp.filtfilt(&x, 1000);
        let core = &y[2500..y.len() - 2500];
        let expected = a / 2f64.sqrt() * bp.gain(4.0).powi(2);
        assert_relative_eq!(rms(core), expected, max_relative = 1e-3);
        assert_relative_eq!(rms(core), a / 2f64.sqrt(), max_relative = 0.01);
        // zero phase: peaks stay where they were
        let i = (0..core.len())
            .max_by(|&p, &q| core[p].total_cmp(&core[q]))
            .unwrap();
        assert!((core[i] - x[2500 + i]).abs() < 0.03 * a);
        let out = sine(a, 25.0, fs, 40.0, 0.0);
        let y = bp.filtfilt(&out, 1000);
        assert!(rms(&y[2500..y.len() - 2500]) < 1e-3 * a);
        let dc = vec![5.0; 20000];
        let y = bp.filtfilt(&dc, 1000);
        assert!(rms(&y) < 1e-5, "{}", rms(&y)); // 5.0 in, padding transient only
    }

    #[test]
    fn sliding_rms_windows() {
        // 10 s at 20 m/s = 200 m: windows of 100 m every 10 m -> 11 windows
        let fs = 100.0;
        let x: Vec<f64> = (0..1000).map(|i| if i < 500 { 1.0 } else { 3.0 }).collect();
        let w = sliding_rms_distance(&x, fs, 20.0, 100.0, 10.0).unwrap();
        assert_eq!(w.len(), 11);
        assert_relative_eq!(w[0].0, 50.0);
        assert_relative_eq!(w[0].1, 1.0, epsilon = 1e-12);
        assert_relative_eq!(w[10].1, 3.0, epsilon = 1e-12);
        // half and half: sqrt((1 + 9)/2)
        assert_relative_eq!(w[5].1, 5f64.sqrt(), epsilon = 1e-12);
        let e = sliding_rms_distance(&x[..100], fs, 20.0, 100.0, 10.0).unwrap_err();
        assert!(matches!(
            e,
            SignalError::TooShort {
                samples: 100,
                needed: 500,
                ..
            }
        ));
        let e = sliding_rms_distance(&x, fs, 0.0, 100.0, 10.0).unwrap_err();
        assert!(e.to_string().contains("speed_mps"));
        let mut bad = x.clone();
        bad[7] = f64::NAN;
        assert_eq!(
            sliding_rms_distance(&bad, fs, 20.0, 100.0, 10.0).unwrap_err(),
            SignalError::NonFinite { index: 7 }
        );
    }
}
