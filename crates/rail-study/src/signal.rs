//! Signal processing for the assessment: FFT, Welch spectrum, dominant frequency, rms over
//! sliding distance windows. The Butterworth band-pass is the shared one of the
//! `signal-processing` crate.

use std::f64::consts::PI;

pub use signal_processing::rms;
use signal_processing::{Complex64, DesignError};

/// A signal-processing input problem, naming the parameter.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SignalError {
    #[error("parameter '{name}' = {}: {reason}", master::show::num(*.value))]
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
    #[error(
        "sample {index} is not finite, or the signal's values are too large to filter (beyond \
         about 1e150)"
    )]
    NonFinite { index: usize },
    #[error(
        "no spectral peak between {} and {} Hz",
        master::show::num(*.f_min),
        master::show::num(*.f_max)
    )]
    NoPeak { f_min: f64, f_max: f64 },
    #[error("band-pass design: {0}")]
    Design(#[from] DesignError),
}

/// A parameter check: `ok` and finite, or an error naming the parameter.
pub(crate) fn check(
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

/// In-place radix-2 FFT; `x.len()` must be a power of two (not checked beyond debug).
pub fn fft(x: &mut [Complex64]) {
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
        let w = Complex64::cis(-2.0 * PI / len as f64);
        for start in (0..n).step_by(len) {
            let mut wk = Complex64::new(1.0, 0.0);
            for k in 0..len / 2 {
                let a = x[start + k];
                let b = x[start + k + len / 2] * wk;
                x[start + k] = a + b;
                x[start + k + len / 2] = a - b;
                wk *= w;
            }
        }
        len <<= 1;
    }
}

/// Welch power spectral density (Hann window, 50 % overlap, segments of `seg_len` samples
/// rounded up to a power of two, mean removed per segment). Returns (frequencies \[Hz\], PSD
/// [unit^2/Hz], one-sided).
pub fn welch(x: &[f64], fs: f64, seg_len: usize) -> Result<(Vec<f64>, Vec<f64>), SignalError> {
    welch_padded(x, fs, seg_len.max(8).next_power_of_two())
}

/// Welch power spectral density over segments of exactly `seg_len` samples (at least 8; Hann
/// window over the segment, 50 % overlap, mean removed per segment), each zero-padded to the
/// next power of two for the FFT. The resolution follows the segment's duration, the padding
/// only samples the same spectrum more finely. Returns (frequencies \[Hz\], PSD [unit^2/Hz],
/// one-sided).
pub fn welch_padded(
    x: &[f64],
    fs: f64,
    seg_len: usize,
) -> Result<(Vec<f64>, Vec<f64>), SignalError> {
    check("fs", fs, fs > 0.0, "sampling rate must be > 0")?;
    check_finite(x)?;
    let len = seg_len.max(8);
    let n = len.next_power_of_two();
    if x.len() < len {
        return Err(SignalError::TooShort {
            samples: x.len(),
            needed: len,
            what: "one Welch segment",
        });
    }
    let win: Vec<f64> = (0..len)
        .map(|i| 0.5 - 0.5 * (2.0 * PI * i as f64 / len as f64).cos())
        .collect();
    let wss: f64 = win.iter().map(|w| w * w).sum();
    let mut psd = vec![0.0; n / 2 + 1];
    let mut segments = 0usize;
    let mut buf = vec![Complex64::default(); n];
    let mut start = 0;
    while start + len <= x.len() {
        let seg = &x[start..start + len];
        let mean = seg.iter().sum::<f64>() / len as f64;
        for (b, (s, w)) in buf.iter_mut().zip(seg.iter().zip(&win)) {
            *b = Complex64::new((s - mean) * w, 0.0);
        }
        buf[len..].fill(Complex64::default());
        fft(&mut buf);
        for (k, p) in psd.iter_mut().enumerate() {
            let scale = if k == 0 || k == n / 2 { 1.0 } else { 2.0 };
            *p += scale * buf[k].norm().powi(2) / (fs * wss);
        }
        segments += 1;
        start += len / 2;
    }
    psd.iter_mut().for_each(|p| *p /= segments as f64);
    let freqs = (0..=n / 2).map(|k| k as f64 * fs / n as f64).collect();
    Ok((freqs, psd))
}

/// Duration of the Welch segments that find the dominant frequency \[s\]: 8192 samples at
/// 1 kHz. A duration, not a number of samples: the frequency resolution, and so the peak
/// found, is the same at any sampling rate (a 100 Hz file gives the full-rate frequency).
pub const DOMINANT_SEGMENT_S: f64 = 8.192;

/// Samples of one Welch segment for [`dominant_frequency`]: [`DOMINANT_SEGMENT_S`], halved
/// until it fits in `samples` (at least 8 samples). At 1 kHz this is the largest power of
/// two of samples that fits, up to 8192.
pub fn dominant_segment_len(samples: usize, fs: f64) -> usize {
    let mut duration_s = DOMINANT_SEGMENT_S;
    let mut len = (duration_s * fs).round() as usize;
    while len > samples && len > 8 {
        duration_s /= 2.0;
        len = (duration_s * fs).round() as usize;
    }
    len.max(8)
}

/// Frequency of the largest Welch-PSD peak in `[f_min, f_max]`, refined by a parabola through
/// the peak bin and its neighbours (of the log PSD). Segments of [`DOMINANT_SEGMENT_S`] (or
/// the longest halving of it that fits in a shorter signal).
pub fn dominant_frequency(x: &[f64], fs: f64, f_min: f64, f_max: f64) -> Result<f64, SignalError> {
    check("fs", fs, fs > 0.0, "sampling rate must be > 0")?;
    check("f_min", f_min, f_min >= 0.0, "must be >= 0")?;
    check("f_max", f_max, f_max > f_min, "must be > f_min")?;
    // the peak's frequency does not depend on the signal's scale, but the PSD squares the
    // samples: beyond 1e100 (or below 1e-100) they would overflow (or underflow) on the way,
    // so they are scaled first, by a power of two (exactly)
    let peak = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let scaled: Vec<f64>;
    let x = if peak.is_finite() && peak > 0.0 && !(1e-100..=1e100).contains(&peak) {
        // in two factors: 2^1074 (a subnormal peak's) is beyond f64 on its own
        let exponent = -peak.log2().round();
        let (a, b) = (
            (exponent / 2.0).floor().exp2(),
            (exponent - (exponent / 2.0).floor()).exp2(),
        );
        scaled = x.iter().map(|v| v * a * b).collect();
        &scaled[..]
    } else {
        x
    };
    let (f, p) = welch_padded(x, fs, dominant_segment_len(x.len(), fs))?;
    spectral_peak(&f, &p, f_min, f_max)
}

/// The largest peak of a spectrum `p` at frequencies `f` in `[f_min, f_max]`, refined by a
/// parabola through the log of the peak bin and its neighbours.
fn spectral_peak(f: &[f64], p: &[f64], f_min: f64, f_max: f64) -> Result<f64, SignalError> {
    let best = (1..p.len().saturating_sub(1))
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

/// RMS over sliding windows of `window_m` metres advanced by `step_m` metres, for a signal
/// sampled at `fs` while running at constant `speed_mps`. Returns (window centre \[m\], rms).
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
    // a window step shorter than a sample would start window after window at the same sample
    // (at 1e308 km/h: without end, until memory runs out)
    check(
        "speed_mps",
        speed_mps,
        step_m / speed_mps * fs >= 1.0,
        "the window step must last at least one sample at this speed",
    )?;
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
    // each window summed on its own (a window step of 10 m in 100 m windows counts each
    // sample about 10 times): a prefix sum would carry one huge sample's square into every
    // later window and lose them to cancellation; the squares are scaled by the window's
    // largest magnitude, so a sample up to 1e308 neither overflows nor swamps the sum
    let mut out = Vec::new();
    let mut k = 0usize;
    loop {
        let start_m = k as f64 * step_m;
        let i0 = (start_m / speed_mps * fs).round() as usize;
        let i1 = i0 + win;
        if i1 > x.len() {
            break;
        }
        let w = &x[i0..i1];
        let scale = w.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let rms = if scale > 0.0 {
            let ms = w.iter().map(|v| (v / scale) * (v / scale)).sum::<f64>() / win as f64;
            scale * ms.sqrt()
        } else {
            0.0
        };
        out.push((start_m + window_m / 2.0, rms));
        k += 1;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn sine(a: f64, f: f64, fs: f64, secs: f64, phase: f64) -> Vec<f64> {
        signal_processing::sampled(|t| a * (2.0 * PI * f * t + phase).sin(), fs, secs)
    }

    #[test]
    fn fft_of_a_cosine() {
        let n = 64;
        let mut x: Vec<Complex64> = (0..n)
            .map(|i| Complex64::new((2.0 * PI * 5.0 * i as f64 / n as f64).cos(), 0.0))
            .collect();
        fft(&mut x);
        assert_relative_eq!(x[5].re, 32.0, epsilon = 1e-9);
        assert_relative_eq!(x[59].re, 32.0, epsilon = 1e-9);
        assert!(x[4].norm() < 1e-9 && x[0].norm() < 1e-9);
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
    fn the_dominant_segment_is_a_duration() {
        assert_eq!(dominant_segment_len(15_000, 1000.0), 8192);
        assert_eq!(dominant_segment_len(8_192, 1000.0), 8192);
        assert_eq!(dominant_segment_len(8_191, 1000.0), 4096);
        assert_eq!(dominant_segment_len(1_500, 100.0), 819);
        assert_eq!(dominant_segment_len(500, 100.0), 410);
        assert_eq!(dominant_segment_len(5, 100.0), 8);
    }

    #[test]
    fn the_dominant_frequency_does_not_depend_on_the_sampling_rate() {
        // two peaks 0.25 Hz apart: 2 bins apart in 8.192 s segments, 1.3 bins in the 5.12 s
        // that 512 samples last at 100 Hz
        let two = |fs: f64| {
            let mut x = sine(1.0, 4.0, fs, 14.0, 0.0);
            let y = sine(0.8, 4.25, fs, 14.0, 1.0);
            x.iter_mut().zip(&y).for_each(|(a, b)| *a += b);
            x
        };
        let full = dominant_frequency(&two(1000.0), 1000.0, 0.5, 20.0).unwrap();
        let low = dominant_frequency(&two(100.0), 100.0, 0.5, 20.0).unwrap();
        let (f, p) = welch(&two(100.0), 100.0, 512).unwrap();
        let samples = spectral_peak(&f, &p, 0.5, 20.0).unwrap();
        // measured: 4.0315 at 1 kHz, 4.0136 at 100 Hz (the padded bins lie elsewhere), 4.0798
        // at 100 Hz over 512 samples
        assert!((low - full).abs() < 0.02, "100 Hz {low} vs 1 kHz {full}");
        assert!(
            (samples - full).abs() > 0.04,
            "512 samples {samples} vs 1 kHz {full}"
        );
    }

    #[test]
    fn the_dominant_frequency_does_not_depend_on_the_signals_scale() {
        let fs = 1000.0;
        let x: Vec<f64> = (0..20_000)
            .map(|k| {
                let t = k as f64 / fs;
                (2.0 * PI * 6.0 * t).sin() + 0.3 * (2.0 * PI * 19.0 * t).sin()
            })
            .collect();
        let at = |scale: f64| {
            let y: Vec<f64> = x.iter().map(|v| v * scale).collect();
            dominant_frequency(&y, fs, 1.0, 30.0).unwrap()
        };
        let f = at(1.0);
        assert!((f - 6.0).abs() < 0.1, "{f}");
        for scale in [1e153, 1e300, 1e-150, 1e-300, 1e-310] {
            assert!((at(scale) - f).abs() < 1e-9, "{scale:e}: {} Hz", at(scale));
        }
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
        // the 10 m step lasts one sample at 1000 m/s and 100 Hz; faster, less than one
        assert!(sliding_rms_distance(&x, fs, 1000.0, 100.0, 10.0).is_ok());
        for v in [1001.0, 1e308] {
            let e = sliding_rms_distance(&x, fs, v, 100.0, 10.0).unwrap_err();
            assert!(e.to_string().contains("at least one sample"), "{e}");
        }
        let mut bad = x.clone();
        bad[7] = f64::NAN;
        assert_eq!(
            sliding_rms_distance(&bad, fs, 20.0, 100.0, 10.0).unwrap_err(),
            SignalError::NonFinite { index: 7 }
        );
    }
}
