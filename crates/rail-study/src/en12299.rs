//! Ride comfort of the car body in the lateral direction after EN 12299:2009 (the standard
//! method's lateral term).
//!
//! * The floor's lateral acceleration is weighted by W_d ([`signal_processing::WdWeighting`]).
//! * Continuous comfort (EN 12299 5.3): `C_Cy(t)` = rms of the weighted acceleration over the
//!   preceding 5 s.
//! * Mean comfort, standard method (EN 12299 5.2): `N_MV = 6 sqrt(a_XP95^2 + a_YP95^2 +
//!   a_ZP95^2)` with `a_P95` the 95th percentile of the 5 s rms values. The lateral term alone
//!   is `N_y = 6 a_YP95` (no longitudinal or vertical motion in the lateral model); scale: < 1
//!   very comfortable, 1-2 comfortable, 2-4 medium, 4-5 uncomfortable, > 5 very uncomfortable.
//!
//! Interpretation: the standard takes 60 consecutive 5 s blocks (5 minutes of running). The
//! study's runs are 10-35 s long, so the 5 s rms is evaluated in 1 s steps and the 95th
//! percentile taken over those overlapping windows (linear interpolation between order
//! statistics); on a stationary signal this converges to the same number, on a short run it is
//! close to the largest 5 s rms. The weighting filter starts at t = 0, so a skipped start-up
//! also removes its transient.

use signal_processing::WdWeighting;

/// EN 12299 window of the continuous comfort \[s\].
pub const WINDOW_S: f64 = 5.0;
/// Step of the overlapping windows (our interpretation, see the module) \[s\].
pub const STEP_S: f64 = 1.0;

/// Why a signal could not be evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ComfortError {
    #[error("sampling rate {0} Hz: the W_d weighting needs a finite rate above 10 Hz")]
    SampleRate(f64),
    #[error("{available_s:.2} s after the skip, a 5 s comfort window needs at least 5 s")]
    TooShort { available_s: f64 },
    #[error("the acceleration signal is not finite at sample {0}")]
    NotFinite(usize),
}

/// The lateral comfort numbers of one signal.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LateralComfort {
    /// rms of the W_d-weighted acceleration after the skip [m/s^2].
    pub weighted_rms_mps2: f64,
    /// 95th percentile of the 5 s rms values, a_YP95 [m/s^2].
    pub p95_mps2: f64,
    /// N_y = 6 a_YP95 (the lateral term of N_MV).
    pub n_y: f64,
}

/// 95th percentile by linear interpolation between order statistics (`p` in [0, 1]).
fn percentile(mut v: Vec<f64>, p: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        return 0.0;
    }
    let x = p * (n - 1) as f64;
    let i = x.floor() as usize;
    let j = (i + 1).min(n - 1);
    v[i] + (x - i as f64) * (v[j] - v[i])
}

/// Lateral comfort of a floor acceleration sampled at `fs_hz`, the first `skip_s` left out.
pub fn lateral_comfort(
    acc_mps2: &[f64],
    fs_hz: f64,
    skip_s: f64,
) -> Result<LateralComfort, ComfortError> {
    if let Some(i) = acc_mps2.iter().position(|a| !a.is_finite()) {
        return Err(ComfortError::NotFinite(i));
    }
    let w = WdWeighting::new(1.0 / fs_hz).ok_or(ComfortError::SampleRate(fs_hz))?;
    let skip = ((skip_s.max(0.0) * fs_hz).round() as usize).min(acc_mps2.len());
    let window = (WINDOW_S * fs_hz).round() as usize;
    let available = acc_mps2.len() - skip;
    if available < window || window == 0 {
        return Err(ComfortError::TooShort {
            available_s: available as f64 / fs_hz,
        });
    }
    let weighted = w.filter(acc_mps2);
    let y = &weighted[skip..];
    let step = ((STEP_S * fs_hz).round() as usize).max(1);
    let windows: Vec<f64> = (0..=(y.len() - window) / step)
        .map(|k| signal_processing::rms(&y[k * step..k * step + window]))
        .collect();
    let p95 = percentile(windows, 0.95);
    Ok(LateralComfort {
        weighted_rms_mps2: signal_processing::rms(y),
        p95_mps2: p95,
        n_y: 6.0 * p95,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{PI, SQRT_2};

    #[test]
    fn a_sine_gives_the_weighted_rms_and_six_times_it() {
        // 0.5 m/s^2 at 1 Hz: W_d(1 Hz) = 1.011 (ISO 2631-1 Table 3), so a_P95 = 0.5 * 1.011 /
        // sqrt(2) = 0.3574 and N_y = 2.14 ("medium"); at 4 Hz W_d = 0.512.
        for (f, amp, wd) in [(1.0, 0.5, 1.011), (4.0, 1.0, 0.512)] {
            let fs = 1000.0;
            let x = signal_processing::sampled(|t| amp * (2.0 * PI * f * t).sin(), fs, 30.0);
            let c = lateral_comfort(&x, fs, 10.0).unwrap();
            let expected = amp * wd / SQRT_2;
            assert!(
                (c.p95_mps2 - expected).abs() < 0.01 * expected,
                "{f} Hz: {c:?}"
            );
            assert!((c.weighted_rms_mps2 - expected).abs() < 0.01 * expected);
            assert!((c.n_y - 6.0 * c.p95_mps2).abs() < 1e-12);
        }
    }

    #[test]
    fn the_percentile_picks_the_rough_part_and_bad_input_is_refused() {
        // 20 s calm, 10 s rough: the windows of the rough part dominate the 95th percentile
        let fs = 200.0;
        let x = signal_processing::sampled(
            |t| if t < 20.0 { 0.01 } else { 1.0 } * (2.0 * PI * t).sin(),
            fs,
            30.0,
        );
        let c = lateral_comfort(&x, fs, 0.0).unwrap();
        assert!((c.p95_mps2 - 1.011 / SQRT_2).abs() < 0.02, "{c:?}");
        assert!(c.weighted_rms_mps2 < c.p95_mps2);
        assert_eq!(percentile(vec![3.0, 1.0, 2.0], 0.5), 2.0);
        assert!((percentile(vec![0.0, 10.0], 0.95) - 9.5).abs() < 1e-12);
        assert!(matches!(
            lateral_comfort(&x[..900], fs, 0.0),
            Err(ComfortError::TooShort { .. })
        ));
        assert!(matches!(
            lateral_comfort(&x, 5.0, 0.0),
            Err(ComfortError::SampleRate(_))
        ));
        let mut bad = x.clone();
        bad[7] = f64::NAN;
        assert_eq!(
            lateral_comfort(&bad, fs, 0.0),
            Err(ComfortError::NotFinite(7))
        );
    }
}
