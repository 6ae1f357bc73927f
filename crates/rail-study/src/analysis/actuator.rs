//! Full-active actuator characterisation (seed 3.4.4): FRFs `u -> rod velocity` of the
//! full-order, reduced-order and linearised models at two command amplitudes, with the R3 and
//! R4 checks in the summary. The physics is `fmu_damper::characterise`.
//!
//! Units in the files: modulus (m/s)/m = 1/s, phase in degrees.

use std::sync::atomic::AtomicBool;

use fmu_damper::characterise::{
    actuator_frf, linearised_actuator_frf, log_space, ActuatorFrfPoint,
};
use fmu_damper::{ActuatorModel, ActuatorParams};
use rayon::prelude::*;

use super::damper::{check_band, option_err, round_sig, SEED_R3_RADPS, SEED_R4_AGREEMENT_RADPS};
use super::figures::Scale;
use super::{check_cancel, AnalysisError, Artefacts, Table};
use crate::plot::Chart;

/// What to run for the full-active actuator.
#[derive(Debug, Clone, PartialEq)]
pub struct ActuatorOptions {
    /// Band \[Hz\] (seed Fig. 3.18-3.22: 1-320 Hz).
    pub band_hz: (f64, f64),
    /// Number of log-spaced frequencies.
    pub points: usize,
    /// Command amplitudes as multiples of alpha (seed: 1 and 0.3).
    pub amplitudes_alpha: Vec<f64>,
    /// Linearisation point P_L_hat / P_S (seed: 0.75).
    pub load_pressure_ratio: f64,
}

impl Default for ActuatorOptions {
    fn default() -> Self {
        ActuatorOptions {
            band_hz: (1.0, 320.0),
            points: 30,
            amplitudes_alpha: vec![1.0, 0.3],
            load_pressure_ratio: 0.75,
        }
    }
}

/// FRFs of the three models at one command amplitude.
#[derive(Debug, Clone, PartialEq)]
pub struct ActuatorFrfSet {
    /// Amplitude / alpha.
    pub amplitude_alpha: f64,
    pub amplitude_m: f64,
    pub full: Vec<ActuatorFrfPoint>,
    pub reduced: Vec<ActuatorFrfPoint>,
    pub linearised: Vec<ActuatorFrfPoint>,
    /// R4 on its own dense grid up to 600 rad/s (`None` when the response is zero).
    pub r4: Option<R4Agreement>,
}

/// R4, full against reduced order, on [`R4_POINTS`] log-spaced frequencies from 1 Hz to the
/// seed's 600 rad/s, whatever grid the FRFs were asked on (a coarse grid steps over the steep
/// fall near 70 Hz, where the two differ most).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct R4Agreement {
    /// Largest |20 log10(full / reduced)| \[dB\].
    pub worst_db: f64,
    /// Where it is \[Hz\].
    pub worst_at_hz: f64,
    /// The largest where the full modulus is above a tenth of its value at 1 Hz \[dB\].
    pub worst_above_tenth_db: f64,
}

/// Frequencies of the R4 comparison.
pub const R4_POINTS: usize = 300;

fn r4_agreement(
    params: &ActuatorParams,
    amplitude_m: f64,
    cancel: &AtomicBool,
) -> Result<R4Agreement, AnalysisError> {
    let top_hz = SEED_R4_AGREEMENT_RADPS / (2.0 * std::f64::consts::PI);
    let freqs = log_space(1.0, top_hz, R4_POINTS);
    let both = [ActuatorModel::FullOrder, ActuatorModel::ReducedOrder]
        .par_iter()
        .map(|&m| {
            check_cancel(cancel)?;
            Ok(actuator_frf(params, m, amplitude_m, &freqs)?)
        })
        .collect::<Result<Vec<_>, AnalysisError>>()?;
    let (full, reduced) = (&both[0], &both[1]);
    let reference = full.first().map_or(0.0, |p| p.modulus_per_s);
    let mut r = R4Agreement {
        worst_db: 0.0,
        worst_at_hz: 0.0,
        worst_above_tenth_db: 0.0,
    };
    for (f, q) in full.iter().zip(reduced) {
        if !(f.modulus_per_s > 0.0 && q.modulus_per_s > 0.0) {
            continue;
        }
        let db = (20.0 * (f.modulus_per_s / q.modulus_per_s).log10()).abs();
        if db > r.worst_db {
            r.worst_db = db;
            r.worst_at_hz = f.freq_hz;
        }
        if f.modulus_per_s > 0.1 * reference {
            r.worst_above_tenth_db = r.worst_above_tenth_db.max(db);
        }
    }
    Ok(r)
}

/// Below this modulus [1/s] an FRF counts as identically zero (dead zone): about 1e-6 of
/// the response at |u| = alpha (~200 1/s); the integrators leave residues up to ~2e-5 1/s.
const ZERO_MODULUS_PER_S: f64 = 1e-4;

impl ActuatorFrfSet {
    /// Largest modulus of the three models [1/s].
    pub fn max_modulus(&self) -> f64 {
        self.full
            .iter()
            .chain(&self.reduced)
            .chain(&self.linearised)
            .map(|p| p.modulus_per_s)
            .fold(0.0, f64::max)
    }

    /// True when every model gives no response (command inside the dead zone).
    pub fn is_zero(&self) -> bool {
        self.max_modulus() < ZERO_MODULUS_PER_S
    }

    fn label(&self) -> String {
        if self.amplitude_alpha == 1.0 {
            "alpha".into()
        } else {
            format!("{}alpha", round_sig(self.amplitude_alpha))
        }
    }
}

/// Removes 360 deg jumps between consecutive phases (frequency order), so a phase that
/// passes -180 deg keeps falling instead of jumping to +180.
pub fn unwrap_deg(phases: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(phases.len());
    let mut offset = 0.0;
    let mut prev: Option<f64> = None;
    for &p in phases {
        if let Some(q) = prev {
            if p.is_finite() && q.is_finite() {
                let d = p - q;
                offset -= 360.0 * (d / 360.0).round();
            }
        }
        if p.is_finite() {
            prev = Some(p);
        }
        out.push(p + offset);
    }
    out
}

fn unwrapped(pts: &[ActuatorFrfPoint]) -> Vec<ActuatorFrfPoint> {
    let ph = unwrap_deg(&pts.iter().map(|p| p.phase_deg).collect::<Vec<_>>());
    pts.iter()
        .zip(ph)
        .map(|(p, phase_deg)| ActuatorFrfPoint { phase_deg, ..*p })
        .collect()
}

/// Actuator FRFs (all models, all amplitudes).
#[derive(Debug, Clone, PartialEq)]
pub struct ActuatorResults {
    pub params: ActuatorParams,
    pub sets: Vec<ActuatorFrfSet>,
}

/// Runs the actuator FRFs, parallel over (amplitude, model, frequency).
pub fn characterise_actuator(
    params: &ActuatorParams,
    opts: &ActuatorOptions,
    cancel: &AtomicBool,
) -> Result<ActuatorResults, AnalysisError> {
    params.validate()?;
    check_band(
        "--actuator-f-min/--actuator-f-max",
        opts.band_hz,
        opts.points,
    )?;
    if let Some(&bad) = opts
        .amplitudes_alpha
        .iter()
        .find(|a| !(a.is_finite() && **a > 0.0))
    {
        return Err(option_err(
            "amplitude/alpha",
            master::show::num(bad),
            "must be finite and > 0",
        ));
    }
    let freqs = log_space(opts.band_hz.0, opts.band_hz.1, opts.points);
    let models = [ActuatorModel::FullOrder, ActuatorModel::ReducedOrder];
    let mut grid: Vec<(f64, ActuatorModel, f64)> = Vec::new();
    for &a in &opts.amplitudes_alpha {
        for &m in &models {
            grid.extend(freqs.iter().map(|&f| (a, m, f)));
        }
    }
    let pts = grid
        .par_iter()
        .map(|&(a, m, f)| {
            check_cancel(cancel)?;
            let v = actuator_frf(params, m, a * params.alpha_m, &[f]).map_err(|e| match e {
                // a free rod moves further the lower the frequency: name the option that
                // asked for it
                fmu_damper::StepError::BeyondStroke { .. } => option_err(
                    "--actuator-f-min",
                    master::show::num(opts.band_hz.0),
                    &format!(
                        "at {} Hz (spool amplitude {} alpha) the free rod leaves its stroke: \
                         {e}; raise --actuator-f-min",
                        master::show::num(f),
                        master::show::num(a)
                    ),
                ),
                e => e.into(),
            })?;
            v.into_iter()
                .next()
                .ok_or(AnalysisError::Damper(fmu_damper::StepError::NonFinite {
                    name: "actuator FRF point",
                }))
        })
        .collect::<Result<Vec<_>, AnalysisError>>()?;
    let n = freqs.len();
    let mut sets = Vec::new();
    for (i, &a) in opts.amplitudes_alpha.iter().enumerate() {
        let base = i * 2 * n;
        let amp = a * params.alpha_m;
        let mut set = ActuatorFrfSet {
            amplitude_alpha: a,
            amplitude_m: amp,
            full: unwrapped(&pts[base..base + n]),
            reduced: unwrapped(&pts[base + n..base + 2 * n]),
            linearised: unwrapped(&linearised_actuator_frf(
                params,
                amp,
                opts.load_pressure_ratio * params.supply_pressure_pa,
                &freqs,
            )?),
            r4: None,
        };
        if !set.is_zero() {
            set.r4 = Some(r4_agreement(params, amp, cancel)?);
        }
        sets.push(set);
    }
    Ok(ActuatorResults {
        params: *params,
        sets,
    })
}

impl ActuatorResults {
    /// One long CSV (all amplitudes and models) and, for each amplitude with a non-zero
    /// response, a log-log modulus and a log-x phase figure.
    pub fn add_artefacts(&self, a: &mut Artefacts) -> Result<(), AnalysisError> {
        let mut t = Table::new(&[
            "amplitude/alpha",
            "amplitude [m]",
            "frequency [Hz]",
            "omega [rad/s]",
            "full modulus [1/s]",
            "full phase [deg]",
            "reduced modulus [1/s]",
            "reduced phase [deg]",
            "linearised modulus [1/s]",
            "linearised phase [deg]",
        ]);
        for s in &self.sets {
            // the phase of a zero response is meaningless: NaN
            let ph = |p: &ActuatorFrfPoint| {
                if p.modulus_per_s < ZERO_MODULUS_PER_S {
                    f64::NAN
                } else {
                    p.phase_deg
                }
            };
            for ((f, r), l) in s.full.iter().zip(&s.reduced).zip(&s.linearised) {
                t.rows.push(vec![
                    s.amplitude_alpha,
                    s.amplitude_m,
                    f.freq_hz,
                    f.omega_radps,
                    f.modulus_per_s,
                    ph(f),
                    r.modulus_per_s,
                    ph(r),
                    l.modulus_per_s,
                    ph(l),
                ]);
            }
        }
        a.add_table("actuator_frf.csv", &t)?;
        for s in self.sets.iter().filter(|s| !s.is_zero()) {
            let label = s.label();
            let title = |what: &str| {
                format!(
                    "Actuator FRF u -> rod velocity (rod free), |u| = {} alpha: {what}",
                    round_sig(s.amplitude_alpha)
                )
            };
            let series = |pts: &[ActuatorFrfPoint], g: fn(&ActuatorFrfPoint) -> f64| {
                pts.iter().map(|p| (p.freq_hz, g(p))).collect::<Vec<_>>()
            };
            let modulus = Chart::new(&title("modulus"), "frequency [Hz]", "|v/u| [1/s]")
                .with_series("full order", series(&s.full, |p| p.modulus_per_s))
                .with_series("reduced order", series(&s.reduced, |p| p.modulus_per_s))
                .with_series("linearised", series(&s.linearised, |p| p.modulus_per_s));
            let phase = Chart::new(&title("phase"), "frequency [Hz]", "phase of v/u [deg]")
                .with_series("full order", series(&s.full, |p| p.phase_deg))
                .with_series("reduced order", series(&s.reduced, |p| p.phase_deg))
                .with_series("linearised", series(&s.linearised, |p| p.phase_deg));
            a.add_scaled_lines(
                &format!("actuator_frf_modulus_{label}.svg"),
                &modulus,
                Scale::Log,
                Scale::Log,
            )?;
            a.add_scaled_lines(
                &format!("actuator_frf_phase_{label}.svg"),
                &phase,
                Scale::Log,
                Scale::Linear,
            )?;
        }
        Ok(())
    }

    /// R3 eigenfrequency, per amplitude: low-frequency gain, peak, full/reduced agreement
    /// (R4), or the statement that the response is zero (dead zone).
    pub fn summary(&self) -> String {
        let p = &self.params;
        let mut s = format!(
            "R3 cylinder eigenfrequency (3.68): {:.1} rad/s ({:.1} Hz), damping ratio {:.3}; seed: about {SEED_R3_RADPS} rad/s\n",
            p.cylinder_eigenfrequency_radps(),
            p.cylinder_eigenfrequency_radps() / (2.0 * std::f64::consts::PI),
            p.cylinder_damping_ratio()
        );
        s.push_str(&format!(
            "   (leakage C_L = {:e} m^3/(s Pa): Table 3-2's number in m^3, the physics' default; the FMU's default is the litre reading, {:e}; dead zone beta = {:e} m = {} alpha)\n",
            p.leakage_coeff_m3ps_per_pa,
            fmu_damper::full_active::LEAKAGE_LITRE_READING_M3PS_PER_PA,
            p.beta_m,
            round_sig(p.beta_m / p.alpha_m)
        ));
        for set in &self.sets {
            let a = round_sig(set.amplitude_alpha);
            if set.is_zero() {
                s.push_str(&format!(
                    "actuator FRF |u| = {a} alpha: all zero (largest modulus {:.1e} 1/s): the command never leaves the dead zone |v| < beta = {} alpha ((3.47)), so no flow and no rod motion; not plotted\n",
                    set.max_modulus(),
                    round_sig(p.beta_m / p.alpha_m)
                ));
                continue;
            }
            let peak = |pts: &[ActuatorFrfPoint]| {
                pts.iter()
                    .copied()
                    .max_by(|x, y| x.modulus_per_s.total_cmp(&y.modulus_per_s))
            };
            s.push_str(&format!("actuator FRF |u| = {a} alpha:"));
            for (name, pts) in [
                ("full", &set.full),
                ("reduced", &set.reduced),
                ("linearised", &set.linearised),
            ] {
                if let (Some(first), Some(pk)) = (pts.first(), peak(pts)) {
                    s.push_str(&format!(
                        " {name}: {:.1} 1/s at {:.1} Hz, peak {:.1} 1/s at {:.0} rad/s;",
                        first.modulus_per_s, first.freq_hz, pk.modulus_per_s, pk.omega_radps
                    ));
                }
            }
            s.pop();
            s.push('\n');
            if let Some(r) = set.r4 {
                s.push_str(&format!(
                    "R4 full vs reduced order, |u| = {a} alpha, {R4_POINTS} frequencies up to {SEED_R4_AGREEMENT_RADPS} rad/s: moduli within {:.2} dB where above a tenth of their 1 Hz value, {:.2} dB at most (at {:.1} Hz, in the steep fall) (seed: close up to about 600-1000 rad/s)\n",
                    r.worst_above_tenth_db, r.worst_db, r.worst_at_hz
                ));
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_band_names_the_option() {
        let cancel = AtomicBool::new(false);
        let opts = ActuatorOptions {
            band_hz: (10.0, 1.0),
            ..ActuatorOptions::default()
        };
        let e = characterise_actuator(&ActuatorParams::default(), &opts, &cancel).unwrap_err();
        assert!(
            e.to_string().contains("--actuator-f-min/--actuator-f-max"),
            "{e}"
        );
    }

    #[test]
    fn phase_unwrapping() {
        let u = unwrap_deg(&[-10.0, -170.0, 170.0, 90.0, f64::NAN, -100.0]);
        assert_eq!(&u[..4], &[-10.0, -170.0, -190.0, -270.0]);
        assert!(u[4].is_nan());
        assert_eq!(u[5], -100.0);
    }
}
