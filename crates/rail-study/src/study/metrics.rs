//! Numbers taken from one recorded run (pure functions of the recorded columns).
//!
//! * EN 14363 rms ([`crate::en14363::assess_lateral_acceleration`]): band-pass +-2 Hz around
//!   the dominant frequency, rms over 100 m windows in 10 m steps, start-up transient skipped;
//!   evaluated for the front and the rear wheelset, the run's value is the larger one.
//! * Wheelset oscillation amplitude: half the peak-to-peak lateral displacement over the last
//!   `tail_s` seconds (the larger of the two wheelsets): a limit cycle shows as a steady
//!   amplitude, a decaying motion as a small one.
//! * Damper force peak, rms hydraulic power (full-active), mean valve command over the tail.

use crate::en14363::{assess_lateral_acceleration, AssessError, StabilitySettings};
use crate::study::config::var;
use master::coupling::SimOutput;

/// Bogie mass of the seed [t] (a_lim = 5.39 m/s^2, seed 4.2).
pub const BOGIE_MASS_T: f64 = 6.1;

/// Why a run could not be evaluated.
#[derive(Debug, thiserror::Error)]
pub enum MetricsError {
    #[error("column '{0}' is not in the recorded results")]
    MissingColumn(&'static str),
    #[error("run too short: {samples} samples after skipping {skip_s} s")]
    TooShort { samples: usize, skip_s: f64 },
    #[error("EN 14363 assessment of '{column}': {source}")]
    Assess {
        column: &'static str,
        #[source]
        source: AssessError,
    },
}

/// How a run is evaluated.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct MetricSpec {
    /// Start-up transient excluded from every number [s].
    pub skip_s: f64,
    /// Length of the final part used for amplitudes and mean commands [s].
    pub tail_s: f64,
    pub speed_kmh: f64,
}

/// The numbers of one run.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RunMetrics {
    /// EN 14363 max sliding rms of the front / rear wheelset lateral acceleration [m/s^2].
    pub rms_front: f64,
    pub rms_rear: f64,
    /// Dominant frequency of the front wheelset acceleration [Hz].
    pub frequency_hz: f64,
    /// Half peak-to-peak wheelset displacement over the tail (max of both) [m].
    pub tail_amplitude_m: f64,
    /// Max |wheelset displacement| after the skip [m].
    pub max_displacement_m: f64,
    /// Max |damper force| after the skip, both sides [N].
    pub peak_force_n: f64,
    /// rms of the mechanical power F v per actuator (mean of both sides; the seed's
    /// "dissipated power" of Table 4-3) [W], if recorded.
    pub rms_power_w: Option<f64>,
    /// rms of the hydraulic supply power per actuator (mean of both sides) [W], if recorded.
    pub rms_hydraulic_power_w: Option<f64>,
    /// Mean valve command over the tail (both sides) [V], if recorded.
    pub tail_command_v: Option<f64>,
}

impl RunMetrics {
    /// The EN 14363 value of the run: the larger of the two wheelsets.
    pub fn rms(&self) -> f64 {
        self.rms_front.max(self.rms_rear)
    }
}

fn col(out: &SimOutput, name: &'static str) -> Result<Vec<f64>, MetricsError> {
    out.column(name).ok_or(MetricsError::MissingColumn(name))
}

/// Sampling rate of the recorded output [Hz] from its time column.
pub fn sample_rate(out: &SimOutput) -> Option<f64> {
    let t = out.column("time")?;
    let n = t.len();
    if n < 2 {
        return None;
    }
    let dt = (t[n - 1] - t[0]) / (n - 1) as f64;
    (dt > 0.0).then_some(1.0 / dt)
}

fn half_peak_to_peak(x: &[f64]) -> f64 {
    let (lo, hi) = x
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    if hi >= lo {
        (hi - lo) / 2.0
    } else {
        0.0
    }
}

fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |m, v| m.max(v.abs()))
}

fn mean(x: &[f64]) -> f64 {
    if x.is_empty() {
        0.0
    } else {
        x.iter().sum::<f64>() / x.len() as f64
    }
}

/// Evaluates one run.
pub fn run_metrics(out: &SimOutput, spec: &MetricSpec) -> Result<RunMetrics, MetricsError> {
    let fs = sample_rate(out).ok_or(MetricsError::TooShort {
        samples: out.rows().count(),
        skip_s: spec.skip_s,
    })?;
    let skip = ((spec.skip_s * fs).round() as usize).min(out.rows().count());
    let n = out.rows().count();
    if n.saturating_sub(skip) < 16 {
        return Err(MetricsError::TooShort {
            samples: n.saturating_sub(skip),
            skip_s: spec.skip_s,
        });
    }
    let tail = n - ((spec.tail_s * fs).round() as usize).clamp(1, n - skip);
    let settings = StabilitySettings {
        skip_s: spec.skip_s,
        ..StabilitySettings::default()
    };
    let speed = spec.speed_kmh / 3.6;
    let assess = |column: &'static str| -> Result<(f64, f64), MetricsError> {
        let a = col(out, column)?;
        let r = assess_lateral_acceleration(&a, fs, speed, BOGIE_MASS_T, &settings)
            .map_err(|source| MetricsError::Assess { column, source })?;
        Ok((r.max_rms, r.dominant_frequency_hz))
    };
    let (rms_front, frequency_hz) = assess(var::WS_FRONT_ACC)?;
    let (rms_rear, _) = assess(var::WS_REAR_ACC)?;
    let yf = col(out, var::WS_FRONT_Y)?;
    let yr = col(out, var::WS_REAR_Y)?;
    let tail_amplitude_m = half_peak_to_peak(&yf[tail..]).max(half_peak_to_peak(&yr[tail..]));
    let max_displacement_m = max_abs(&yf[skip..]).max(max_abs(&yr[skip..]));
    let mut peak_force_n = 0.0f64;
    for name in [
        var::FORCE_LEFT_DAMPER,
        var::FORCE_RIGHT_DAMPER,
        var::FORCE_LEFT_ACTUATOR,
        var::FORCE_RIGHT_ACTUATOR,
    ] {
        if let Some(f) = out.column(name) {
            peak_force_n = peak_force_n.max(max_abs(&f[skip..]));
        }
    }
    // per actuator (the seed's Table 4-3 is per damper): mean of the two sides' rms
    let rms_sum = |left: &str, right: &str| match (out.column(left), out.column(right)) {
        (Some(l), Some(r)) => {
            Some((crate::signal::rms(&l[skip..]) + crate::signal::rms(&r[skip..])) / 2.0)
        }
        (Some(l), None) => Some(crate::signal::rms(&l[skip..])),
        _ => None,
    };
    let rms_power_w = rms_sum(var::POWER_LEFT, var::POWER_RIGHT);
    let rms_hydraulic_power_w = rms_sum(var::HYDRAULIC_POWER_LEFT, var::HYDRAULIC_POWER_RIGHT);
    let tail_command_v = match (
        out.column(var::COMMAND_LEFT),
        out.column(var::COMMAND_RIGHT),
    ) {
        (Some(l), Some(r)) => Some((mean(&l[tail..]) + mean(&r[tail..])) / 2.0),
        (Some(l), None) => Some(mean(&l[tail..])),
        _ => None,
    };
    Ok(RunMetrics {
        rms_front,
        rms_rear,
        frequency_hz,
        tail_amplitude_m,
        max_displacement_m,
        peak_force_n,
        rms_power_w,
        rms_hydraulic_power_w,
        tail_command_v,
    })
}

/// Keeps every `factor`-th row (the first always), for compact results files.
pub fn decimate(out: &SimOutput, factor: usize) -> SimOutput {
    let factor = factor.max(1);
    let w = out.header.len().max(1);
    let data: Vec<f64> = out
        .data
        .chunks(w)
        .step_by(factor)
        .flat_map(|r| r.iter().copied())
        .collect();
    SimOutput {
        header: out.header.clone(),
        data,
        summary: out.summary.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use master::coupling::Summary;
    use std::f64::consts::PI;

    /// A synthetic run: hunting at `f` Hz with acceleration amplitude `acc` and displacement
    /// amplitude `acc / w^2`, sampled at 500 Hz for `t_end` s.
    pub(crate) fn synthetic(acc: f64, f: f64, t_end: f64, with_command: bool) -> SimOutput {
        let mut header: Vec<String> = vec![
            "time [s]".into(),
            format!("{} [m]", var::WS_FRONT_Y),
            format!("{} [m]", var::WS_REAR_Y),
            format!("{} [m/s2]", var::WS_FRONT_ACC),
            format!("{} [m/s2]", var::WS_REAR_ACC),
            format!("{} [N]", var::FORCE_LEFT_DAMPER),
        ];
        if with_command {
            header.push(format!("{} [V]", var::COMMAND_LEFT));
        }
        let fs = 500.0;
        let n = (t_end * fs) as usize + 1;
        let w = 2.0 * PI * f;
        let mut data = Vec::new();
        for k in 0..n {
            let t = k as f64 / fs;
            let a = acc * (w * t).sin();
            data.extend([
                t,
                -a / (w * w),
                -0.5 * a / (w * w),
                a,
                0.5 * a,
                8e3 * (w * t).cos(),
            ]);
            if with_command {
                data.push(if t < t_end / 2.0 { 10.0 } else { 2.0 });
            }
        }
        SimOutput {
            header,
            data,
            summary: Summary {
                steps: n as u64,
                rejected_steps: 0,
                simulated_time_s: t_end,
                wall_time_s: 1.0,
                realtime_ratio: t_end,
            },
        }
    }

    #[test]
    fn sine_gives_its_rms_frequency_amplitude_and_force() {
        let out = synthetic(6.0, 4.0, 20.0, true);
        let spec = MetricSpec {
            skip_s: 5.0,
            tail_s: 4.0,
            speed_kmh: 300.0,
        };
        let m = run_metrics(&out, &spec).unwrap();
        // a sine of amplitude 6 has rms 6/sqrt(2) = 4.24; the band-pass passes it
        assert!((m.rms_front - 6.0 / 2f64.sqrt()).abs() < 0.1, "{m:?}");
        assert!((m.rms_rear - 3.0 / 2f64.sqrt()).abs() < 0.1, "{m:?}");
        assert!((m.rms() - m.rms_front).abs() < 1e-12);
        assert!((m.frequency_hz - 4.0).abs() < 0.3, "{m:?}");
        let y = 6.0 / (2.0 * PI * 4.0).powi(2);
        assert!((m.tail_amplitude_m - y).abs() < 0.02 * y, "{m:?}");
        assert!((m.max_displacement_m - y).abs() < 0.02 * y);
        assert!((m.peak_force_n - 8e3).abs() < 10.0);
        assert_eq!(m.rms_power_w, None);
        assert_eq!(m.rms_hydraulic_power_w, None);
        assert!((m.tail_command_v.unwrap() - 2.0).abs() < 1e-12);
    }

    #[test]
    fn missing_column_and_short_run_are_errors() {
        let mut out = synthetic(1.0, 4.0, 10.0, false);
        let spec = MetricSpec {
            skip_s: 5.0,
            tail_s: 2.0,
            speed_kmh: 300.0,
        };
        assert!(run_metrics(&out, &spec).unwrap().tail_command_v.is_none());
        out.header[3] = "other [m/s2]".into();
        let e = run_metrics(&out, &spec).unwrap_err().to_string();
        assert!(e.contains(var::WS_FRONT_ACC), "{e}");
        let short = synthetic(1.0, 4.0, 5.01, false);
        assert!(matches!(
            run_metrics(&short, &spec),
            Err(MetricsError::TooShort { .. })
        ));
    }

    #[test]
    fn decimation_keeps_every_nth_row() {
        let out = synthetic(1.0, 4.0, 1.0, false);
        let d = decimate(&out, 5);
        assert_eq!(d.rows().count(), 101);
        assert!((sample_rate(&d).unwrap() - 100.0).abs() < 1e-9);
        assert_eq!(decimate(&out, 0).data, out.data);
    }
}
