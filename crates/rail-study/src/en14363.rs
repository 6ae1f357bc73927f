//! Running-stability assessment in the manner of EN 14363 (seed section 4.2).
//!
//! Seed 4.2: the lateral acceleration is band-pass filtered +-2 Hz around the main peak of its
//! spectrum, its rms is taken over 100 m of track in steps of 10 m, and compared with
//! `a_lim = (12 - m_bogie/5)/2` [m/s^2], `m_bogie` in tonnes (5.39 m/s^2 for 6.1 t).
//!
//! EN 14363:2016 (stability, rms criteria) also bounds the rms of the sum of guiding forces
//! of a wheelset by half the Prud'homme limit with alpha = 1:
//! `(Sum Y)_lim = (10 + 2 Q0 / 3) / 2` \[kN\], `Q0` the static wheel load in kN (2 Q0 = axle
//! load P0 in the usual `10 + P0/3`). The same filter and window are used.
//!
//! Interpretations: the filter is a zero-phase (forward-backward) Butterworth band-pass
//! [`signal_processing::BandPass`] of prototype order 2 per pass, edges f0 - 2 Hz and f0 + 2 Hz
//! (lower edge clamped to 0.1 Hz); the dominant frequency comes from a Welch spectrum of
//! 8.192 s segments (at any sampling rate, [`crate::signal::DOMINANT_SEGMENT_S`]) searched
//! between 0.5 and 20 Hz unless given. The speed is taken as constant over the run.

use signal_processing::BandPass;

use crate::signal::{check, dominant_frequency, sliding_rms_distance, SignalError};

/// EN 14363 lateral-acceleration limit [m/s^2] for a bogie mass in tonnes: (12 - m/5)/2.
pub fn acceleration_limit(bogie_mass_t: f64) -> f64 {
    (12.0 - bogie_mass_t / 5.0) / 2.0
}

/// Static wheel loads the guiding-force criterion takes \[N\]: 300 kN is a wheel under an
/// axle load of 60 t, twice the heaviest freight axle.
pub const STATIC_WHEEL_LOAD_RANGE_N: std::ops::RangeInclusive<f64> = 1e3..=3e5;

/// EN 14363 limit of the rms of the sum of guiding forces \[kN\] for a static wheel load \[kN\]:
/// (10 + 2 Q0/3)/2.
pub fn guiding_force_limit_kn(static_wheel_load_kn: f64) -> f64 {
    (10.0 + 2.0 * static_wheel_load_kn / 3.0) / 2.0
}

/// Settings of the assessment.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StabilitySettings {
    /// rms window length along the track \[m\] (EN 14363: 100 m).
    pub window_m: f64,
    /// window advance \[m\] (EN 14363: 10 m).
    pub step_m: f64,
    /// half band width around the dominant frequency \[Hz\] (EN 14363: 2 Hz).
    pub half_band_hz: f64,
    /// Butterworth prototype order per pass.
    pub filter_order: usize,
    /// dominant frequency \[Hz\]; `None` = find it from the spectrum.
    pub dominant_frequency_hz: Option<f64>,
    /// search range for the dominant frequency \[Hz\].
    pub search_hz: (f64, f64),
    /// samples discarded at the start (initial transient of the simulation) \[s\].
    pub skip_s: f64,
}

impl Default for StabilitySettings {
    fn default() -> Self {
        StabilitySettings {
            window_m: 100.0,
            step_m: 10.0,
            half_band_hz: 2.0,
            filter_order: 2,
            dominant_frequency_hz: None,
            search_hz: (0.5, 20.0),
            skip_s: 0.0,
        }
    }
}

impl StabilitySettings {
    /// Track a record of `duration_s` at `speed_kmh` covers once `skip_s` is dropped \[m\]: the
    /// assessment needs at least one window of `window_m`.
    pub fn assessed_m(&self, duration_s: f64, speed_kmh: f64) -> f64 {
        (duration_s - self.skip_s) * speed_kmh / 3.6
    }
}

/// Why an assessment could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AssessError {
    #[error(transparent)]
    Signal(#[from] SignalError),
}

/// Result of one rms assessment.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Assessment {
    /// f0, the centre of the band: the spectrum's peak, or the frequency given
    /// ([`StabilitySettings::dominant_frequency_hz`]).
    pub dominant_frequency_hz: f64,
    /// Whether f0 was given rather than found in the spectrum.
    pub f0_given: bool,
    /// The spectrum's own peak in [`StabilitySettings::search_hz`] (`None`: f0 was given and
    /// the record has no peak there), to compare with a given f0.
    pub spectrum_peak_hz: Option<f64>,
    pub band_hz: (f64, f64),
    pub limit: f64,
    pub max_rms: f64,
    /// (window centre along the track from the record's first sample \[m\] (the skipped
    /// start-up included), rms)
    pub rms: Vec<(f64, f64)>,
    /// `max_rms <= limit`
    pub stable: bool,
}

/// A parameter check: `ok` and finite, or an error naming the parameter.
fn param(
    name: &'static str,
    value: f64,
    ok: bool,
    reason: &'static str,
) -> Result<(), AssessError> {
    Ok(check(name, value, ok, reason)?)
}

/// Filtered sliding-window rms of a signal sampled at `fs` \[Hz\] at constant `speed_mps`,
/// compared with `limit` (same unit as the signal).
pub fn assess_rms(
    signal: &[f64],
    fs: f64,
    speed_mps: f64,
    limit: f64,
    s: &StabilitySettings,
) -> Result<Assessment, AssessError> {
    param("fs", fs, fs > 0.0, "sampling rate must be > 0")?;
    param("speed_mps", speed_mps, speed_mps > 0.0, "speed must be > 0")?;
    param("limit", limit, limit > 0.0, "limit must be > 0")?;
    param(
        "half_band_hz",
        s.half_band_hz,
        s.half_band_hz > 0.0,
        "must be > 0",
    )?;
    param("skip_s", s.skip_s, s.skip_s >= 0.0, "must be >= 0")?;
    let skip = ((s.skip_s * fs).round() as usize).min(signal.len());
    let x = &signal[skip..];
    let peak = || dominant_frequency(x, fs, s.search_hz.0, s.search_hz.1);
    let (f0, spectrum_peak_hz) = match s.dominant_frequency_hz {
        Some(f) => {
            param("dominant_frequency_hz", f, f > 0.0, "must be > 0")?;
            (f, peak().ok())
        }
        None => {
            let f = peak()?;
            (f, Some(f))
        }
    };
    let lo = (f0 - s.half_band_hz).max(0.1);
    let hi = f0 + s.half_band_hz;
    let bp = BandPass::butterworth(s.filter_order, lo, hi, 1.0 / fs).map_err(SignalError::from)?;
    // odd-reflection padding continues a sine with its amplitude; 8 / band width seconds let
    // the start transient (mostly from the reflected mean) die out before the real signal
    let pad = (8.0 * fs / (hi - lo)).ceil() as usize;
    let y = bp.filtfilt(x, pad);
    // a filtered signal that overflowed is refused there (not finite); its windows' rms stay
    // finite for any finite sample
    let mut rms = sliding_rms_distance(&y, fs, speed_mps, s.window_m, s.step_m)?;
    // positions from the record's first sample, not from the end of the skipped start-up
    let skipped_m = skip as f64 / fs * speed_mps;
    rms.iter_mut().for_each(|(x, _)| *x += skipped_m);
    let max_rms = rms.iter().map(|r| r.1).fold(0.0, f64::max);
    Ok(Assessment {
        dominant_frequency_hz: f0,
        f0_given: s.dominant_frequency_hz.is_some(),
        spectrum_peak_hz,
        band_hz: (lo, hi),
        limit,
        max_rms,
        rms,
        stable: max_rms <= limit,
    })
}

/// Lateral acceleration [m/s^2] criterion with `a_lim = (12 - m_bogie/5)/2`.
pub fn assess_lateral_acceleration(
    acc_mps2: &[f64],
    fs: f64,
    speed_mps: f64,
    bogie_mass_t: f64,
    s: &StabilitySettings,
) -> Result<Assessment, AssessError> {
    param(
        "bogie_mass_t",
        bogie_mass_t,
        bogie_mass_t > 0.0 && bogie_mass_t < 60.0,
        "bogie mass must be in (0, 60) t",
    )?;
    assess_rms(acc_mps2, fs, speed_mps, acceleration_limit(bogie_mass_t), s)
}

/// Sum-of-guiding-forces criterion: signal in N, static wheel load in N; rms and limit are
/// reported in kN.
pub fn assess_guiding_forces(
    sum_y_n: &[f64],
    fs: f64,
    speed_mps: f64,
    static_wheel_load_n: f64,
    s: &StabilitySettings,
) -> Result<Assessment, AssessError> {
    param(
        "static_wheel_load_n",
        static_wheel_load_n,
        STATIC_WHEEL_LOAD_RANGE_N.contains(&static_wheel_load_n),
        "a static wheel load must lie within 1 .. 300 kN",
    )?;
    let kn: Vec<f64> = sum_y_n.iter().map(|v| v / 1000.0).collect();
    assess_rms(
        &kn,
        fs,
        speed_mps,
        guiding_force_limit_kn(static_wheel_load_n / 1000.0),
        s,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::PI;

    fn sine(a: f64, f: f64, fs: f64, secs: f64) -> Vec<f64> {
        (0..(secs * fs) as usize)
            .map(|i| a * (2.0 * PI * f * i as f64 / fs).sin())
            .collect()
    }

    #[test]
    fn a_huge_sample_never_gives_a_stable_verdict() {
        let mut x = sine(10.0, 6.0, 1000.0, 20.0);
        let s = StabilitySettings::default();
        let unstable = assess_rms(&x, 1000.0, 300.0 / 3.6, 5.39, &s).unwrap();
        assert!(!unstable.stable);
        // never "stable": a spike the window sums carry is assessed (its windows far above
        // the limit); one that overflows the filter gives no verdict
        for spikes in [&[1e160][..], &[1e308], &[1e308, 1e308, -1e308, 1e308]] {
            x[5500..5500 + spikes.len()].copy_from_slice(spikes);
            match assess_rms(&x, 1000.0, 300.0 / 3.6, 5.39, &s) {
                Ok(a) => assert!(!a.stable && a.max_rms > 1e150, "{spikes:?}: {}", a.max_rms),
                // no verdict, with the reason (an overflow, or no spectral peak left)
                Err(e) => assert!(!e.to_string().is_empty()),
            }
        }
    }

    #[test]
    fn limits() {
        // seed 4.2: 5.39 m/s^2 for 6.1 t
        assert_relative_eq!(acceleration_limit(6.1), 5.39, epsilon = 1e-12);
        // Q0 = 75 kN: (10 + 50)/2 = 30 kN
        assert_relative_eq!(guiding_force_limit_kn(75.0), 30.0, epsilon = 1e-12);
    }

    #[test]
    fn sine_in_band_gives_a_over_sqrt2_and_out_of_band_is_removed() {
        let fs = 200.0;
        let a = 6.0;
        // hunting at 3.5 Hz plus 0.5 Hz drift and 15 Hz vibration of the same amplitude
        let mut x = sine(a, 3.5, fs, 40.0);
        for (v, (l, h)) in x
            .iter_mut()
            .zip(sine(a, 0.5, fs, 40.0).iter().zip(sine(a, 15.0, fs, 40.0)))
        {
            *v += 0.6 * l + 0.6 * h;
        }
        let r =
            assess_lateral_acceleration(&x, fs, 300.0 / 3.6, 6.1, &StabilitySettings::default())
                .unwrap();
        assert!(
            (r.dominant_frequency_hz - 3.5).abs() < 0.05,
            "{}",
            r.dominant_frequency_hz
        );
        // a window of T seconds that is not a whole number of periods changes the rms of a
        // sine by at most 1/(4 pi f T) relative; the filter passes |H(f)|^2 (0.993 at 3.5 Hz
        // for the 1.5-5.5 Hz band); what leaks of the 0.5 and 15 Hz parts (|H|^2 < 0.006)
        // adds cross terms below 0.5 %
        let tol = 1.0 / (4.0 * PI * 3.5 * (100.0 / (300.0 / 3.6))) + 5e-3;
        let bp = BandPass::butterworth(2, r.band_hz.0, r.band_hz.1, 1.0 / fs).unwrap();
        let expected = a / 2f64.sqrt() * bp.magnitude(3.5, 1.0 / fs).powi(2);
        assert!(bp.magnitude(3.5, 1.0 / fs).powi(2) > 0.99);
        assert_relative_eq!(r.max_rms, expected, max_relative = tol);
        for (_, v) in &r.rms {
            assert_relative_eq!(*v, expected, max_relative = tol);
        }
        assert!(r.stable); // 6/sqrt(2) = 4.24 < 5.39
    }

    #[test]
    fn verdict_against_the_limit() {
        let fs = 200.0;
        let s = StabilitySettings {
            dominant_frequency_hz: Some(4.0),
            ..Default::default()
        };
        // rms 5.0 < 5.39: stable; rms 5.8 > 5.39: unstable
        let ok =
            assess_lateral_acceleration(&sine(5.0 * 2f64.sqrt(), 4.0, fs, 30.0), fs, 70.0, 6.1, &s)
                .unwrap();
        let tol = 1.0 / (4.0 * PI * 4.0 * (100.0 / 70.0)) + 0.005;
        assert_relative_eq!(ok.max_rms, 5.0, max_relative = tol);
        assert!(ok.stable);
        let bad =
            assess_lateral_acceleration(&sine(5.8 * 2f64.sqrt(), 4.0, fs, 30.0), fs, 70.0, 6.1, &s)
                .unwrap();
        assert!(!bad.stable);
        // 30 s at 70 m/s = 2100 m: (2100 - 100)/10 + 1 = 201 windows
        assert_eq!(ok.rms.len(), 201);
        assert_relative_eq!(ok.rms[0].0, 50.0);
    }

    #[test]
    fn growing_oscillation_is_localised_by_the_window() {
        // 20 s quiet, then 20 s of 8 m/s^2 amplitude at 4 Hz: max rms = 8/sqrt2, first windows ~0
        let fs = 200.0;
        let x: Vec<f64> = sine(8.0, 4.0, fs, 40.0)
            .into_iter()
            .enumerate()
            .map(|(i, v)| if i < 4000 { 0.0 } else { v })
            .collect();
        let s = StabilitySettings {
            dominant_frequency_hz: Some(4.0),
            ..Default::default()
        };
        let r = assess_lateral_acceleration(&x, fs, 50.0, 6.1, &s).unwrap();
        let tol = 1.0 / (4.0 * PI * 4.0 * 2.0) + 0.005;
        assert_relative_eq!(r.max_rms, 8.0 / 2f64.sqrt(), max_relative = tol);
        assert!(r.rms[0].1 < 0.05, "{}", r.rms[0].1);
        assert!(!r.stable);
    }

    #[test]
    fn guiding_forces_in_kn() {
        let fs = 200.0;
        let s = StabilitySettings {
            dominant_frequency_hz: Some(3.0),
            ..Default::default()
        };
        // 40 kN amplitude sum of guiding forces -> 28.3 kN rms, limit 30 kN at Q0 = 75 kN
        let r = assess_guiding_forces(&sine(40e3, 3.0, fs, 30.0), fs, 80.0, 75e3, &s).unwrap();
        assert_relative_eq!(r.limit, 30.0);
        let tol = 1.0 / (4.0 * PI * 3.0 * 1.25) + 0.005;
        assert_relative_eq!(r.max_rms, 40.0 / 2f64.sqrt(), max_relative = tol);
        assert!(r.stable);
    }

    #[test]
    fn bad_parameters_are_named() {
        let x = sine(1.0, 4.0, 200.0, 10.0);
        let s = StabilitySettings::default();
        let e = assess_lateral_acceleration(&x, 200.0, -1.0, 6.1, &s).unwrap_err();
        assert!(e.to_string().contains("speed_mps"));
        let e = assess_lateral_acceleration(&x, 200.0, 50.0, f64::NAN, &s).unwrap_err();
        assert!(e.to_string().contains("bogie_mass_t"));
        // 10 s at 50 m/s = 500 m is enough; at 100 m / 5 s windows, 2 s is not
        let e = assess_lateral_acceleration(&x[..400], 200.0, 20.0, 6.1, &s).unwrap_err();
        assert!(
            matches!(e, AssessError::Signal(SignalError::TooShort { .. })),
            "{e}"
        );
    }
}
