//! Numbers taken from one recorded run (pure functions of the recorded columns).
//!
//! * EN 14363 rms ([`crate::en14363::assess_lateral_acceleration`]): band-pass +-2 Hz around
//!   the dominant frequency, rms over 100 m windows in 10 m steps, start-up transient skipped;
//!   evaluated for every frame acceleration over an axle box (the coach's four, the bogie's
//!   two wheelsets), the run's value is the largest.
//! * Wheelset oscillation amplitude: half the peak-to-peak lateral displacement over the last
//!   `tail_s` seconds (the largest over the wheelsets): a limit cycle shows as a steady
//!   amplitude, a decaying motion as a small one.
//! * Car body (coach): rms of the floor lateral acceleration and the EN 12299 lateral comfort
//!   N_y ([`crate::en12299`]), the largest over front, mid-length and rear.
//! * Damper force peak, rms hydraulic power (full-active), mean valve command over the tail.
//! * Yaw-damper stroke (coach): the amplitude of the sinusoid with the elongation's rms about
//!   its mean after the skip, sqrt(2) x std, the largest over the dampers: what a damper must
//!   take, and the amplitude at which its linearisation holds (`master root-locus --damper
//!   semi-active:OPENING:STROKE:FREQ`).

use crate::en12299::{lateral_comfort, ComfortError};
use crate::en14363::{assess_lateral_acceleration, AssessError, StabilitySettings};
use crate::study::vehicle::Signals;
use master::coupling::SimOutput;

/// Bogie mass of the seed \[t\] (a_lim = 5.39 m/s^2, seed 4.2).
pub const BOGIE_MASS_T: f64 = 6.1;

/// Why a run could not be evaluated.
#[derive(Debug, thiserror::Error)]
pub enum MetricsError {
    #[error("column '{0}' is not in the recorded results")]
    MissingColumn(String),
    #[error("run too short: {samples} samples after skipping {skip_s} s")]
    TooShort { samples: usize, skip_s: f64 },
    #[error("EN 14363 assessment of '{column}': {source}")]
    Assess {
        column: String,
        #[source]
        source: AssessError,
    },
    #[error("EN 12299 comfort of '{column}': {source}")]
    Comfort {
        column: String,
        #[source]
        source: ComfortError,
    },
    #[error("no EN 14363 signal to assess")]
    NoStabilitySignal,
}

/// How a run is evaluated.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct MetricSpec {
    /// Start-up transient excluded from every number \[s\].
    pub skip_s: f64,
    /// Length of the final part used for amplitudes and mean commands \[s\].
    pub tail_s: f64,
    pub speed_kmh: f64,
}

/// The numbers of one run.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RunMetrics {
    /// EN 14363 max sliding rms of each assessed acceleration, in [`Signals::stability`]
    /// order [m/s^2].
    pub rms_by_signal: Vec<f64>,
    /// Dominant frequency of the first assessed acceleration \[Hz\].
    pub frequency_hz: f64,
    /// Half peak-to-peak wheelset displacement over the tail (max of both) \[m\].
    pub tail_amplitude_m: f64,
    /// Max |wheelset displacement| after the skip \[m\].
    pub max_displacement_m: f64,
    /// Max |damper force| after the skip, both sides \[N\].
    pub peak_force_n: f64,
    /// rms of the damper force after the skip, mean over the dampers \[N\], if recorded.
    pub rms_force_n: Option<f64>,
    /// Max |reference force| of the full-active controllers after the skip \[N\], if recorded:
    /// above the actuator's force bound the peak force is the bound, not `c_v v`.
    pub peak_reference_force_n: Option<f64>,
    /// rms of the mechanical power F v per actuator (mean of both sides; the seed's
    /// "dissipated power" of Table 4-3) \[W\], if recorded.
    pub rms_power_w: Option<f64>,
    /// rms of the hydraulic supply power per actuator (mean of both sides) \[W\], if recorded.
    pub rms_hydraulic_power_w: Option<f64>,
    /// Mean valve command over the tail (all dampers) \[V\], if recorded.
    pub tail_command_v: Option<f64>,
    /// Mean valve command over the tail of each damper, in [`Signals::commands`] order \[V\]
    /// (empty if none is recorded): dampers of one bogie may settle far apart.
    #[serde(default)]
    pub tail_command_by_damper_v: Vec<f64>,
    /// rms of the car-body floor lateral acceleration after the skip, largest over the
    /// measuring points [m/s^2]; `None` without a car body.
    pub carbody_rms_mps2: Option<f64>,
    /// EN 12299 lateral comfort N_y = 6 a_YP95 (W_d), largest over the measuring points;
    /// `None` without a car body or when less than one 5 s window follows the skip.
    pub comfort_ny: Option<f64>,
    /// Stroke amplitude of the yaw dampers after the skip, sqrt(2) x the standard deviation of
    /// the elongation, largest over the dampers \[m\]; `None` if no elongation is recorded.
    #[serde(default)]
    pub damper_stroke_m: Option<f64>,
}

impl RunMetrics {
    /// The EN 14363 value of the run: the largest over the assessed accelerations.
    pub fn rms(&self) -> f64 {
        self.rms_by_signal.iter().fold(0.0, |m: f64, &r| m.max(r))
    }

    /// The same runs over several track seeds as one: each quantity the largest over them (the
    /// worst case, as a sweep point is the worst over its seeds), the dominant frequency that
    /// of the run with the largest EN 14363 rms. `None` for no runs.
    pub fn largest_over(runs: &[RunMetrics]) -> Option<RunMetrics> {
        let worst = runs.iter().max_by(|a, b| a.rms().total_cmp(&b.rms()))?;
        let max = |f: fn(&RunMetrics) -> f64| runs.iter().map(f).fold(f64::NEG_INFINITY, f64::max);
        let max_opt =
            |f: fn(&RunMetrics) -> Option<f64>| runs.iter().filter_map(f).reduce(f64::max);
        // a list per signal or damper: each entry the largest over the runs that have it
        let each_max = |f: fn(&RunMetrics) -> &[f64]| -> Vec<f64> {
            let n = runs.iter().map(|r| f(r).len()).max().unwrap_or(0);
            (0..n)
                .map(|k| {
                    runs.iter()
                        .filter_map(|r| f(r).get(k).copied())
                        .fold(f64::NEG_INFINITY, f64::max)
                })
                .collect()
        };
        Some(RunMetrics {
            rms_by_signal: each_max(|r| &r.rms_by_signal),
            frequency_hz: worst.frequency_hz,
            tail_amplitude_m: max(|r| r.tail_amplitude_m),
            max_displacement_m: max(|r| r.max_displacement_m),
            peak_force_n: max(|r| r.peak_force_n),
            rms_force_n: max_opt(|r| r.rms_force_n),
            peak_reference_force_n: max_opt(|r| r.peak_reference_force_n),
            rms_power_w: max_opt(|r| r.rms_power_w),
            rms_hydraulic_power_w: max_opt(|r| r.rms_hydraulic_power_w),
            tail_command_v: max_opt(|r| r.tail_command_v),
            tail_command_by_damper_v: each_max(|r| &r.tail_command_by_damper_v),
            carbody_rms_mps2: max_opt(|r| r.carbody_rms_mps2),
            comfort_ny: max_opt(|r| r.comfort_ny),
            damper_stroke_m: max_opt(|r| r.damper_stroke_m),
        })
    }
}

fn col(out: &SimOutput, name: &str) -> Result<Vec<f64>, MetricsError> {
    out.column(name)
        .ok_or_else(|| MetricsError::MissingColumn(name.to_string()))
}

/// Sampling rate of the recorded output \[Hz\] from its time column.
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

/// Mean over the recorded columns of `names` of `f(column)`; `None` if none is recorded.
fn mean_over(out: &SimOutput, names: &[String], f: impl Fn(&[f64]) -> f64) -> Option<f64> {
    let v: Vec<f64> = names
        .iter()
        .filter_map(|n| out.column(n))
        .map(|c| f(&c))
        .collect();
    (!v.is_empty()).then(|| mean(&v))
}

/// Evaluates one run.
pub fn run_metrics(
    out: &SimOutput,
    spec: &MetricSpec,
    signals: &Signals,
) -> Result<RunMetrics, MetricsError> {
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
    let mut rms_by_signal = Vec::with_capacity(signals.stability.len());
    let mut frequency_hz = None;
    for column in &signals.stability {
        let a = col(out, column)?;
        let r = assess_lateral_acceleration(&a, fs, speed, BOGIE_MASS_T, &settings).map_err(
            |source| MetricsError::Assess {
                column: column.clone(),
                source,
            },
        )?;
        rms_by_signal.push(r.max_rms);
        frequency_hz.get_or_insert(r.dominant_frequency_hz);
    }
    let frequency_hz = frequency_hz.ok_or(MetricsError::NoStabilitySignal)?;
    let mut tail_amplitude_m = 0.0f64;
    let mut max_displacement_m = 0.0f64;
    for column in &signals.displacements {
        let y = col(out, column)?;
        tail_amplitude_m = tail_amplitude_m.max(half_peak_to_peak(&y[tail..]));
        max_displacement_m = max_displacement_m.max(max_abs(&y[skip..]));
    }
    let peak_force_n = signals
        .forces
        .iter()
        .filter_map(|name| out.column(name))
        .fold(0.0f64, |m, f| m.max(max_abs(&f[skip..])));
    let references: Vec<Vec<f64>> = signals
        .reference_forces
        .iter()
        .filter_map(|name| out.column(name))
        .collect();
    let peak_reference_force_n = (!references.is_empty()).then(|| {
        references
            .iter()
            .fold(0.0f64, |m, f| m.max(max_abs(&f[skip..])))
    });
    // per actuator (the seed's Table 4-3 is per damper): mean of the dampers' rms
    let rms_after_skip = |x: &[f64]| crate::signal::rms(&x[skip..]);
    let rms_force_n = mean_over(out, &signals.forces, rms_after_skip);
    let rms_power_w = mean_over(out, &signals.powers, rms_after_skip);
    let rms_hydraulic_power_w = mean_over(out, &signals.hydraulic_powers, rms_after_skip);
    let tail_command_by_damper_v: Vec<f64> = signals
        .commands
        .iter()
        .filter_map(|n| out.column(n))
        .map(|c| mean(&c[tail..]))
        .collect();
    let tail_command_v =
        (!tail_command_by_damper_v.is_empty()).then(|| mean(&tail_command_by_damper_v));
    let damper_stroke_m = signals
        .elongations
        .iter()
        .filter_map(|name| out.column(name))
        .map(|e| std::f64::consts::SQRT_2 * standard_deviation(&e[skip..]))
        .reduce(f64::max);
    let mut carbody_rms_mps2: Option<f64> = None;
    let mut comfort_ny: Option<f64> = None;
    for column in &signals.carbody {
        let a = col(out, column)?;
        let r = rms_after_skip(&a);
        carbody_rms_mps2 = Some(carbody_rms_mps2.map_or(r, |m| m.max(r)));
        // a run shorter than one 5 s comfort window after the skip has no comfort number
        match lateral_comfort(&a, fs, spec.skip_s) {
            Ok(c) => comfort_ny = Some(comfort_ny.map_or(c.n_y, |m| m.max(c.n_y))),
            Err(ComfortError::TooShort { .. }) => {}
            Err(source) => {
                return Err(MetricsError::Comfort {
                    column: column.clone(),
                    source,
                })
            }
        }
    }
    Ok(RunMetrics {
        rms_by_signal,
        frequency_hz,
        tail_amplitude_m,
        max_displacement_m,
        peak_force_n,
        rms_force_n,
        peak_reference_force_n,
        rms_power_w,
        rms_hydraulic_power_w,
        tail_command_v,
        tail_command_by_damper_v,
        carbody_rms_mps2,
        comfort_ny,
        damper_stroke_m,
    })
}

/// Standard deviation (population) of `x`.
fn standard_deviation(x: &[f64]) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    let m = mean(x);
    (x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / x.len() as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::vehicle::VehicleModel;
    use std::f64::consts::PI;

    fn bogie() -> Signals {
        Signals::of(VehicleModel::Bogie2Dof)
    }

    /// A synthetic run: hunting at `f` Hz with acceleration amplitude `acc` and displacement
    /// amplitude `acc / w^2`, sampled at 500 Hz for `t_end` s.
    pub(crate) fn synthetic(acc: f64, f: f64, t_end: f64, with_command: bool) -> SimOutput {
        let b = bogie();
        let mut header: Vec<String> = vec![
            "time [s]".into(),
            format!("{} [m]", b.displacements[0]),
            format!("{} [m]", b.displacements[1]),
            format!("{} [m/s2]", b.stability[0]),
            format!("{} [m/s2]", b.stability[1]),
            format!("{} [N]", b.forces[0]),
        ];
        if with_command {
            header.push(format!("{} [V]", b.commands[0]));
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
        crate::study::run::recorded(header, data)
    }

    /// Appends the columns `names` to `out`, their values in each row `values(time)`.
    fn with_columns(out: &mut SimOutput, names: &[String], values: impl Fn(f64) -> Vec<f64>) {
        let width = out.header.len();
        out.header.extend(names.iter().cloned());
        let rows: Vec<Vec<f64>> = out.data.chunks(width).map(<[f64]>::to_vec).collect();
        out.data.clear();
        for mut row in rows {
            row.extend(values(row[0]));
            out.data.extend(row);
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
        let m = run_metrics(&out, &spec, &bogie()).unwrap();
        // a sine of amplitude 6 has rms 6/sqrt(2) = 4.24; the band-pass passes it
        assert!(
            (m.rms_by_signal[0] - 6.0 / 2f64.sqrt()).abs() < 0.1,
            "{m:?}"
        );
        assert!(
            (m.rms_by_signal[1] - 3.0 / 2f64.sqrt()).abs() < 0.1,
            "{m:?}"
        );
        assert!((m.rms() - m.rms_by_signal[0]).abs() < 1e-12);
        assert_eq!((m.carbody_rms_mps2, m.comfort_ny), (None, None));
        assert!((m.frequency_hz - 4.0).abs() < 0.3, "{m:?}");
        let y = 6.0 / (2.0 * PI * 4.0).powi(2);
        assert!((m.tail_amplitude_m - y).abs() < 0.02 * y, "{m:?}");
        assert!((m.max_displacement_m - y).abs() < 0.02 * y);
        assert!((m.peak_force_n - 8e3).abs() < 10.0);
        // one damper recorded: its rms, 8 kN / sqrt(2); no full-active reference recorded
        let rms_force = m.rms_force_n.unwrap();
        assert!((rms_force - 8e3 / 2f64.sqrt()).abs() < 20.0, "{rms_force}");
        assert_eq!(m.peak_reference_force_n, None);
        assert_eq!(m.rms_power_w, None);
        assert_eq!(m.rms_hydraulic_power_w, None);
        assert!((m.tail_command_v.unwrap() - 2.0).abs() < 1e-12);
        // no elongation recorded: no stroke
        assert_eq!(m.damper_stroke_m, None);
    }

    /// The stroke is the amplitude of the elongation about its mean after the skip, the larger
    /// of the dampers: 2 mm on an offset of 5 mm, whatever a large start-up swing before it.
    #[test]
    fn damper_stroke_is_the_elongation_amplitude_after_the_skip() {
        let mut out = synthetic(6.0, 4.0, 20.0, false);
        let b = bogie();
        let names = [
            format!("{} [m]", b.elongations[0]),
            format!("{} [m]", b.elongations[1]),
        ];
        with_columns(&mut out, &names, |t| {
            let swing = if t < 5.0 { 0.03 } else { 0.0 };
            let s = (2.0 * PI * 4.0 * t).sin();
            vec![5e-3 + (2e-3 + swing) * s, 1e-3 * s]
        });
        let spec = MetricSpec {
            skip_s: 5.0,
            tail_s: 4.0,
            speed_kmh: 300.0,
        };
        let m = run_metrics(&out, &spec, &b).unwrap();
        let stroke = m.damper_stroke_m.unwrap();
        assert!((stroke - 2e-3).abs() < 0.01 * 2e-3, "{stroke}");
    }

    /// Each damper's tail command is its own; the mean command is their mean (one damper at
    /// 2 V, the other at 8 V: 5 V, which no damper holds).
    #[test]
    fn tail_command_is_given_per_damper() {
        let b = bogie();
        let mut out = synthetic(6.0, 4.0, 20.0, true);
        with_columns(&mut out, &[format!("{} [V]", b.commands[1])], |t| {
            vec![if t < 10.0 { 0.0 } else { 8.0 }]
        });
        let spec = MetricSpec {
            skip_s: 5.0,
            tail_s: 4.0,
            speed_kmh: 300.0,
        };
        let m = run_metrics(&out, &spec, &b).unwrap();
        assert_eq!(m.tail_command_by_damper_v, vec![2.0, 8.0]);
        assert_eq!(m.tail_command_v, Some(5.0));
        // over two runs each damper's the larger
        let mut other = m.clone();
        other.tail_command_by_damper_v = vec![3.0, 1.0];
        let worst = RunMetrics::largest_over(&[m, other]).unwrap();
        assert_eq!(worst.tail_command_by_damper_v, vec![3.0, 8.0]);
    }

    #[test]
    fn peak_reference_force_is_the_largest_after_the_skip() {
        let b = bogie();
        let mut out = synthetic(6.0, 4.0, 20.0, false);
        let width = out.header.len();
        out.header.push(format!("{} [N]", b.reference_forces[0]));
        let rows = out.data.len() / width;
        let mut data = Vec::with_capacity(out.data.len() + rows);
        for (k, row) in out.data.chunks(width).enumerate() {
            data.extend_from_slice(row);
            // 30 kN before the skip (start-up), then a 21 kN peak
            let t = row[0];
            data.push(if t < 5.0 {
                30e3
            } else if k == rows - 1 {
                -21e3
            } else {
                1e3
            });
        }
        out.data = data;
        let spec = MetricSpec {
            skip_s: 5.0,
            tail_s: 4.0,
            speed_kmh: 300.0,
        };
        let m = run_metrics(&out, &spec, &b).unwrap();
        assert_eq!(m.peak_reference_force_n, Some(21e3));
    }

    #[test]
    fn missing_column_and_short_run_are_errors() {
        let mut out = synthetic(1.0, 4.0, 10.0, false);
        let spec = MetricSpec {
            skip_s: 5.0,
            tail_s: 2.0,
            speed_kmh: 300.0,
        };
        assert!(run_metrics(&out, &spec, &bogie())
            .unwrap()
            .tail_command_v
            .is_none());
        out.header[3] = "other [m/s2]".into();
        let e = run_metrics(&out, &spec, &bogie()).unwrap_err().to_string();
        assert!(e.contains(&bogie().stability[0]), "{e}");
        let short = synthetic(1.0, 4.0, 5.01, false);
        assert!(matches!(
            run_metrics(&short, &spec, &bogie()),
            Err(MetricsError::TooShort { .. })
        ));
    }

    #[test]
    fn car_body_columns_give_rms_and_comfort() {
        // the bogie's synthetic run with a car-body floor signal of 0.3 m/s^2 at 1 Hz added
        let mut out = synthetic(1.0, 4.0, 20.0, false);
        let w = out.header.len();
        let mut signals = bogie();
        signals.carbody = vec!["vehicle.carbody.lateral_acceleration_mid".into()];
        out.header.push(format!("{} [m/s2]", signals.carbody[0]));
        let rows: Vec<Vec<f64>> = out
            .data
            .chunks(w)
            .map(|r| {
                let mut r = r.to_vec();
                r.push(0.3 * (2.0 * PI * r[0]).sin());
                r
            })
            .collect();
        out.data = rows.concat();
        let spec = MetricSpec {
            skip_s: 5.0,
            tail_s: 2.0,
            speed_kmh: 300.0,
        };
        let m = run_metrics(&out, &spec, &signals).unwrap();
        let rms = 0.3 / 2f64.sqrt();
        assert!(
            (m.carbody_rms_mps2.unwrap() - rms).abs() < 0.01 * rms,
            "{m:?}"
        );
        // W_d(1 Hz) = 1.011
        let ny = 6.0 * 1.011 * rms;
        assert!((m.comfort_ny.unwrap() - ny).abs() < 0.02 * ny, "{m:?}");
        // shorter than one comfort window after the skip: rms, but no comfort number
        let short = MetricSpec {
            skip_s: 16.0,
            ..spec.clone()
        };
        let m = run_metrics(&out, &short, &signals).unwrap();
        assert!(
            m.carbody_rms_mps2.is_some() && m.comfort_ny.is_none(),
            "{m:?}"
        );
        signals
            .carbody
            .push("vehicle.carbody.lateral_acceleration_front".into());
        let e = run_metrics(&out, &spec, &signals).unwrap_err().to_string();
        assert!(e.contains("lateral_acceleration_front"), "{e}");
    }

    fn metrics(
        rms: [f64; 2],
        frequency_hz: f64,
        peak_force_n: f64,
        power: Option<f64>,
    ) -> RunMetrics {
        RunMetrics {
            rms_by_signal: rms.to_vec(),
            frequency_hz,
            tail_amplitude_m: 1e-3 * rms[0],
            max_displacement_m: 2e-3 * rms[1],
            peak_force_n,
            rms_force_n: Some(0.5 * peak_force_n),
            peak_reference_force_n: Some(2.0 * peak_force_n),
            rms_power_w: power,
            rms_hydraulic_power_w: None,
            tail_command_v: None,
            tail_command_by_damper_v: Vec::new(),
            carbody_rms_mps2: Some(0.1 * rms[1]),
            comfort_ny: Some(rms[0]),
            damper_stroke_m: Some(1e-3),
        }
    }

    #[test]
    fn largest_over_seeds_takes_each_quantity_from_its_worst_run() {
        let a = metrics([3.0, 1.0], 4.0, 19e3, Some(140.0));
        let b = metrics([2.0, 2.5], 4.5, 22.7e3, None);
        let m = RunMetrics::largest_over(&[a.clone(), b.clone()]).unwrap();
        // per signal, not the run with the larger maximum
        assert_eq!(m.rms_by_signal, vec![3.0, 2.5]);
        assert_eq!(m.rms(), 3.0);
        // the dominant frequency of the run with the largest EN 14363 rms
        assert_eq!(m.frequency_hz, 4.0);
        assert_eq!(m.peak_force_n, 22.7e3);
        assert_eq!(m.peak_reference_force_n, Some(45.4e3));
        assert_eq!(m.rms_force_n, Some(11.35e3));
        assert_eq!(m.max_displacement_m, 5e-3);
        assert_eq!(m.tail_amplitude_m, 3e-3);
        assert_eq!(m.carbody_rms_mps2, Some(0.25));
        assert_eq!(m.comfort_ny, Some(3.0));
        // a quantity one run did not record comes from the others
        assert_eq!(m.rms_power_w, Some(140.0));
        assert_eq!(m.rms_hydraulic_power_w, None);
        // one run is itself; none is nothing
        assert_eq!(RunMetrics::largest_over(std::slice::from_ref(&b)), Some(b));
        assert_eq!(RunMetrics::largest_over(&[]), None);
    }
}
