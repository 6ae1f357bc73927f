//! Damper and actuator characterisation (seed 3.3.4 and 3.4.4, issue 3 item 6): hysteresis
//! loops, force/displacement FRFs with equivalent stiffness and damping, actuator FRFs
//! `u -> rod velocity`. The physics is `fmu_damper::characterise`; this module runs it over
//! the seed's grids (in parallel), builds the result tables and figures, and the summary.
//!
//! Units in the files: displacement mm, force kN, stiffness kN/mm (= MN/m), damping kN s/m,
//! actuator modulus (m/s)/m = 1/s.

use std::sync::atomic::AtomicBool;

use fmu_damper::characterise::{
    actuator_frf, damper_frf_point, hysteresis_loop, linearised_actuator_frf, log_space,
    ActuatorFrfPoint, DamperFrfPoint, HysteresisLoop,
};
use fmu_damper::{ActuatorModel, ActuatorParams, SemiActiveParams};
use rayon::prelude::*;

use super::figures::Scale;
use super::{check_cancel, AnalysisError, Artefacts, Table};
use crate::plot::Chart;

/// Seed R1: peak force at 0 % opening, 4 Hz, 1 and 3 mm [kN].
pub const SEED_R1_CLOSED_KN: (f64, f64) = (12.0, 20.0);
/// Seed R1: peak force at 100 % opening [kN].
pub const SEED_R1_OPEN_KN: (f64, f64) = (0.5, 1.0);
/// Seed R3: cylinder eigenfrequency from (3.68) with Table 3-2 [rad/s] (REFERENCE.md: 319.7).
pub const SEED_R3_RADPS: f64 = 320.0;
/// Seed R4: full and reduced order agree up to about this angular frequency [rad/s].
pub const SEED_R4_AGREEMENT_RADPS: f64 = 600.0;

/// What to run for the semi-active damper.
#[derive(Debug, Clone, PartialEq)]
pub struct DamperOptions {
    /// Frequency of the hysteresis loops [Hz] (seed Fig. 3.10-3.13: 4 Hz).
    pub loop_freq_hz: f64,
    /// Stroke amplitudes of the loops [m] (seed: 1 and 3 mm).
    pub loop_amplitudes_m: Vec<f64>,
    /// Valve openings of the loops, 0..1 (seed: 0, 20, 50, 100 %).
    pub loop_openings: Vec<f64>,
    /// Valve openings of the FRFs (seed Fig. 3.14-3.15 plus the passive 30 %).
    pub frf_openings: Vec<f64>,
    /// Stroke amplitude of the FRFs [m] (seed: 1 mm).
    pub frf_amplitude_m: f64,
    /// FRF band [Hz] (seed: 0.5-20 Hz).
    pub frf_band_hz: (f64, f64),
    /// Number of log-spaced FRF frequencies.
    pub frf_points: usize,
}

impl Default for DamperOptions {
    fn default() -> Self {
        DamperOptions {
            loop_freq_hz: 4.0,
            loop_amplitudes_m: vec![1e-3, 3e-3],
            loop_openings: vec![0.0, 0.2, 0.5, 1.0],
            frf_openings: vec![0.0, 0.2, 0.3, 0.5, 1.0],
            frf_amplitude_m: 1e-3,
            frf_band_hz: (0.5, 20.0),
            frf_points: 25,
        }
    }
}

fn option_err(option: &'static str, value: impl ToString, reason: &str) -> AnalysisError {
    AnalysisError::Option {
        option,
        value: value.to_string(),
        reason: reason.to_string(),
    }
}

fn check_band(option: &'static str, band: (f64, f64), points: usize) -> Result<(), AnalysisError> {
    if !(band.0.is_finite() && band.1.is_finite() && band.0 > 0.0 && band.1 > band.0) {
        return Err(option_err(
            option,
            format!("{}..{}", band.0, band.1),
            "needs 0 < low < high",
        ));
    }
    if points < 2 {
        return Err(option_err(option, points, "needs at least 2 frequencies"));
    }
    Ok(())
}

/// Loops and FRFs of the semi-active damper.
#[derive(Debug, Clone, PartialEq)]
pub struct DamperResults {
    pub loops: Vec<HysteresisLoop>,
    /// (opening, FRF over the band)
    pub frfs: Vec<(f64, Vec<DamperFrfPoint>)>,
    pub options: DamperOptions,
}

/// Runs the loops and FRFs (parallel over the grid points; `cancel` is checked per point).
pub fn characterise_damper(
    params: &SemiActiveParams,
    opts: &DamperOptions,
    cancel: &AtomicBool,
) -> Result<DamperResults, AnalysisError> {
    params.validate()?;
    check_band("--damper-band", opts.frf_band_hz, opts.frf_points)?;
    let loop_grid: Vec<(f64, f64)> = opts
        .loop_openings
        .iter()
        .flat_map(|&o| opts.loop_amplitudes_m.iter().map(move |&a| (o, a)))
        .collect();
    let loops = loop_grid
        .par_iter()
        .map(|&(o, a)| {
            check_cancel(cancel)?;
            Ok(hysteresis_loop(params, o, opts.loop_freq_hz, a)?)
        })
        .collect::<Result<Vec<_>, AnalysisError>>()?;
    let freqs = log_space(opts.frf_band_hz.0, opts.frf_band_hz.1, opts.frf_points);
    let frf_grid: Vec<(f64, f64)> = opts
        .frf_openings
        .iter()
        .flat_map(|&o| freqs.iter().map(move |&f| (o, f)))
        .collect();
    let points = frf_grid
        .par_iter()
        .map(|&(o, f)| {
            check_cancel(cancel)?;
            Ok(damper_frf_point(params, o, f, opts.frf_amplitude_m)?)
        })
        .collect::<Result<Vec<_>, AnalysisError>>()?;
    let frfs = opts
        .frf_openings
        .iter()
        .zip(points.chunks(freqs.len()))
        .map(|(&o, c)| (o, c.to_vec()))
        .collect();
    Ok(DamperResults {
        loops,
        frfs,
        options: opts.clone(),
    })
}

/// "1mm", "0.5mm" for file names.
fn mm_tag(amplitude_m: f64) -> String {
    format!("{}mm", round_sig(amplitude_m * 1e3))
}

/// Rounds away binary noise (3.0000000000000004 -> 3) for labels.
fn round_sig(v: f64) -> f64 {
    (v * 1e6).round() / 1e6
}

fn pct(opening: f64) -> f64 {
    round_sig(opening * 100.0)
}

impl DamperResults {
    /// Peak |force| of the loop at (opening, amplitude) [N].
    pub fn peak_force_n(&self, opening: f64, amplitude_m: f64) -> Option<f64> {
        self.loops
            .iter()
            .find(|l| {
                (l.opening - opening).abs() < 1e-9 && (l.amplitude_m - amplitude_m).abs() < 1e-12
            })
            .map(|l| l.peak_force_n)
    }

    /// Result files: loops (one long CSV, F-x and F-v figures per amplitude), peak forces,
    /// FRFs (CSV, modulus, phase, k_eq, c_eq figures).
    pub fn add_artefacts(&self, a: &mut Artefacts) -> Result<(), AnalysisError> {
        let mut t = Table::new(&[
            "opening [%]",
            "amplitude [mm]",
            "frequency [Hz]",
            "time [s]",
            "displacement [mm]",
            "velocity [m/s]",
            "force [kN]",
        ]);
        for l in &self.loops {
            for k in 0..l.time_s.len() {
                t.rows.push(vec![
                    pct(l.opening),
                    round_sig(l.amplitude_m * 1e3),
                    l.freq_hz,
                    l.time_s[k],
                    l.displacement_m[k] * 1e3,
                    l.velocity_mps[k],
                    l.force_n[k] * 1e-3,
                ]);
            }
        }
        a.add_table("damper_hysteresis.csv", &t)?;
        let f = self.options.loop_freq_hz;
        for &amp in &self.options.loop_amplitudes_m {
            let tag = mm_tag(amp);
            let label = tag.replace("mm", " mm");
            let mut fx = Chart::new(
                &format!("Semi-active damper: force vs displacement, {label} at {f} Hz"),
                "displacement (elongation) [mm]",
                "force (tension +) [kN]",
            );
            let mut fv = Chart::new(
                &format!("Semi-active damper: force vs velocity, {label} at {f} Hz"),
                "velocity [m/s]",
                "force (tension +) [kN]",
            );
            for l in self.loops.iter().filter(|l| l.amplitude_m == amp) {
                let name = format!("{} % opening", pct(l.opening));
                // close the loop: repeat the first sample at the end
                let close = |xs: &[f64], sx: f64| -> Vec<(f64, f64)> {
                    let mut v: Vec<(f64, f64)> = xs
                        .iter()
                        .zip(&l.force_n)
                        .map(|(x, f)| (x * sx, f * 1e-3))
                        .collect();
                    if let Some(&p) = v.first() {
                        v.push(p);
                    }
                    v
                };
                fx = fx.with_series(&name, close(&l.displacement_m, 1e3));
                fv = fv.with_series(&name, close(&l.velocity_mps, 1.0));
            }
            a.add_lines(
                &format!("damper_hysteresis_{tag}_force_displacement.svg"),
                &fx,
            )?;
            a.add_lines(&format!("damper_hysteresis_{tag}_force_velocity.svg"), &fv)?;
        }
        let mut pk = Table::new(&[
            "opening [%]",
            "amplitude [mm]",
            "frequency [Hz]",
            "peak force [kN]",
        ]);
        for l in &self.loops {
            pk.rows.push(vec![
                pct(l.opening),
                round_sig(l.amplitude_m * 1e3),
                l.freq_hz,
                l.peak_force_n * 1e-3,
            ]);
        }
        a.add_table("damper_peak_forces.csv", &pk)?;

        let mut ft = Table::new(&[
            "opening [%]",
            "amplitude [mm]",
            "frequency [Hz]",
            "modulus |F/x| [kN/mm]",
            "phase [deg]",
            "k_eq [kN/mm]",
            "c_eq [kN s/m]",
        ]);
        let amp_tag = mm_tag(self.options.frf_amplitude_m).replace("mm", " mm");
        let title =
            |what: &str| format!("Semi-active damper FRF force/displacement ({amp_tag}): {what}");
        let mut modulus = Chart::new(&title("modulus"), "frequency [Hz]", "|F/x| [kN/mm]");
        let mut phase = Chart::new(&title("phase"), "frequency [Hz]", "phase of F/x [deg]");
        let mut keq = Chart::new(
            &title("equivalent stiffness"),
            "frequency [Hz]",
            "k_eq = Re(F/x) [kN/mm]",
        );
        let mut ceq = Chart::new(
            &title("equivalent damping"),
            "frequency [Hz]",
            "c_eq = Im(F/x)/omega [kN s/m]",
        );
        for (o, pts) in &self.frfs {
            let name = format!("{} % opening", pct(*o));
            for p in pts {
                ft.rows.push(vec![
                    pct(*o),
                    round_sig(self.options.frf_amplitude_m * 1e3),
                    p.freq_hz,
                    p.modulus_n_per_m * 1e-6,
                    p.phase_deg,
                    p.k_eq_n_per_m * 1e-6,
                    p.c_eq_ns_per_m * 1e-3,
                ]);
            }
            let series = |g: fn(&DamperFrfPoint) -> f64| -> Vec<(f64, f64)> {
                pts.iter().map(|p| (p.freq_hz, g(p))).collect()
            };
            modulus = modulus.with_series(&name, series(|p| p.modulus_n_per_m * 1e-6));
            phase = phase.with_series(&name, series(|p| p.phase_deg));
            keq = keq.with_series(&name, series(|p| p.k_eq_n_per_m * 1e-6));
            ceq = ceq.with_series(&name, series(|p| p.c_eq_ns_per_m * 1e-3));
        }
        a.add_table("damper_frf.csv", &ft)?;
        a.add_scaled_lines("damper_frf_modulus.svg", &modulus, Scale::Log, Scale::Log)?;
        a.add_scaled_lines("damper_frf_phase.svg", &phase, Scale::Log, Scale::Linear)?;
        a.add_scaled_lines("damper_frf_k_eq.svg", &keq, Scale::Log, Scale::Linear)?;
        a.add_scaled_lines("damper_frf_c_eq.svg", &ceq, Scale::Log, Scale::Linear)?;
        Ok(())
    }

    /// R1 table (opening x amplitude) with the seed's ranges, and the phase at the loop
    /// frequency per opening (R2).
    pub fn summary(&self) -> String {
        let o = &self.options;
        let mut s = format!(
            "R1 semi-active damper peak force [kN], sinusoidal stroke at {} Hz\n",
            o.loop_freq_hz
        );
        s.push_str("  opening");
        for &a in &o.loop_amplitudes_m {
            s.push_str(&format!(" | {:>7}", mm_tag(a).replace("mm", " mm")));
        }
        s.push_str(" | seed\n");
        for &op in &o.loop_openings {
            s.push_str(&format!("  {:>5} %", pct(op)));
            for &a in &o.loop_amplitudes_m {
                match self.peak_force_n(op, a) {
                    Some(f) => s.push_str(&format!(" | {:>7.2}", f * 1e-3)),
                    None => s.push_str(" |       -"),
                }
            }
            let seed = if op == 0.0 {
                format!("{}-{} kN", SEED_R1_CLOSED_KN.0, SEED_R1_CLOSED_KN.1)
            } else if op == 1.0 {
                format!("{}-{} kN", SEED_R1_OPEN_KN.0, SEED_R1_OPEN_KN.1)
            } else {
                "-".into()
            };
            s.push_str(&format!(" | {seed}\n"));
        }
        if let Some(&a) = o.loop_amplitudes_m.first() {
            s.push_str(&format!(
                "R2 phase of F/x at {} Hz, {} (seed: rises toward 90 deg as the valve opens):",
                o.loop_freq_hz,
                mm_tag(a).replace("mm", " mm")
            ));
            for l in self.loops.iter().filter(|l| l.amplitude_m == a) {
                s.push_str(&format!(
                    " {} %: {:.0} deg;",
                    pct(l.opening),
                    l.transfer.arg().to_degrees()
                ));
            }
            s.pop();
            s.push('\n');
        }
        s
    }
}

/// What to run for the full-active actuator.
#[derive(Debug, Clone, PartialEq)]
pub struct ActuatorOptions {
    /// Band [Hz] (seed Fig. 3.18-3.22: 1-320 Hz).
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

    /// Largest |1 - |full|/|reduced|| below `omega_max` [rad/s] (R4).
    pub fn full_reduced_mismatch(&self, omega_max: f64) -> Option<f64> {
        self.full
            .iter()
            .zip(&self.reduced)
            .filter(|(f, r)| f.omega_radps <= omega_max && r.modulus_per_s > 0.0)
            .map(|(f, r)| (f.modulus_per_s / r.modulus_per_s - 1.0).abs())
            .reduce(f64::max)
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
    check_band("--actuator-band", opts.band_hz, opts.points)?;
    if let Some(&bad) = opts
        .amplitudes_alpha
        .iter()
        .find(|a| !(a.is_finite() && **a > 0.0))
    {
        return Err(option_err("amplitude/alpha", bad, "must be finite and > 0"));
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
            let v = actuator_frf(params, m, a * params.alpha_m, &[f])?;
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
        sets.push(ActuatorFrfSet {
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
        });
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
            "   (leakage C_L = {:e} m^3/(s Pa), dead zone beta = {:e} m = {} alpha)\n",
            p.leakage_coeff_m3ps_per_pa,
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
            if let Some(m) = set.full_reduced_mismatch(SEED_R4_AGREEMENT_RADPS) {
                s.push_str(&format!(
                    "R4 full vs reduced order, |u| = {a} alpha: moduli within {:.1} % up to {SEED_R4_AGREEMENT_RADPS} rad/s (seed: close up to about 600-1000 rad/s)\n",
                    m * 100.0
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
    fn tags_and_bad_options() {
        assert_eq!(mm_tag(3e-3), "3mm");
        assert_eq!(mm_tag(0.5e-3), "0.5mm");
        assert_eq!(pct(0.3), 30.0);
        let cancel = AtomicBool::new(false);
        let opts = DamperOptions {
            frf_points: 1,
            ..DamperOptions::default()
        };
        let e = characterise_damper(&SemiActiveParams::default(), &opts, &cancel).unwrap_err();
        assert!(e.to_string().contains("--damper-band"), "{e}");
        let opts = ActuatorOptions {
            band_hz: (10.0, 1.0),
            ..ActuatorOptions::default()
        };
        let e = characterise_actuator(&ActuatorParams::default(), &opts, &cancel).unwrap_err();
        assert!(e.to_string().contains("--actuator-band"), "{e}");
    }

    #[test]
    fn phase_unwrapping() {
        let u = unwrap_deg(&[-10.0, -170.0, 170.0, 90.0, f64::NAN, -100.0]);
        assert_eq!(&u[..4], &[-10.0, -170.0, -190.0, -270.0]);
        assert!(u[4].is_nan());
        assert_eq!(u[5], -100.0);
    }

    #[test]
    fn cancelled_run_returns_cancelled() {
        let cancel = AtomicBool::new(true);
        let e = characterise_damper(
            &SemiActiveParams::default(),
            &DamperOptions::default(),
            &cancel,
        )
        .unwrap_err();
        assert!(matches!(e, AnalysisError::Cancelled));
    }

    #[test]
    fn small_damper_run_gives_r1_and_files() {
        let cancel = AtomicBool::new(false);
        let opts = DamperOptions {
            loop_openings: vec![0.0, 1.0],
            frf_openings: vec![0.3],
            frf_points: 2,
            frf_band_hz: (2.0, 4.0),
            ..DamperOptions::default()
        };
        let r = characterise_damper(&SemiActiveParams::default(), &opts, &cancel).unwrap();
        for amp in [1e-3, 3e-3] {
            let closed = r.peak_force_n(0.0, amp).unwrap() * 1e-3;
            assert!((12.0..=20.0).contains(&closed), "R1 0 %: {closed} kN");
            let open = r.peak_force_n(1.0, amp).unwrap() * 1e-3;
            assert!((0.5..=1.0).contains(&open), "R1 100 %: {open} kN");
        }
        let mut a = Artefacts::default();
        r.add_artefacts(&mut a).unwrap();
        let names = a.names();
        for n in [
            "damper_hysteresis.csv",
            "damper_hysteresis_1mm_force_displacement.svg",
            "damper_hysteresis_3mm_force_velocity.svg",
            "damper_frf.csv",
            "damper_frf_modulus.svg",
            "damper_frf_c_eq.svg",
        ] {
            assert!(names.contains(&n), "{n} missing from {names:?}");
        }
        assert!(r.summary().contains("R1"));
    }
}
