//! Semi-active damper characterisation (seed 3.3.4): hysteresis loops, force/displacement
//! FRFs with equivalent stiffness and damping (the actuator's FRFs: [`super::actuator`]). The
//! physics is `fmu_damper::characterise`; this module runs it over the seed's grids (in
//! parallel), builds the result tables and figures, and the summary.
//!
//! Units in the files: displacement mm, force kN, stiffness kN/mm (= MN/m), damping kN s/m.

use std::sync::atomic::AtomicBool;

use fmu_damper::characterise::{
    damper_frf_point, hysteresis_loop, log_space, DamperFrfPoint, HysteresisLoop,
};
use fmu_damper::SemiActiveParams;
use rayon::prelude::*;

use super::figures::Scale;
use super::{check_cancel, AnalysisError, Artefacts, Table};
use crate::plot::Chart;

/// Seed R1: peak force at 0 % opening, 4 Hz, 1 and 3 mm \[kN\].
pub const SEED_R1_CLOSED_KN: (f64, f64) = (12.0, 20.0);
/// Seed R1: peak force at 100 % opening \[kN\].
pub const SEED_R1_OPEN_KN: (f64, f64) = (0.5, 1.0);
/// Seed R3: cylinder eigenfrequency from (3.68) with Table 3-2 [rad/s] (REFERENCE.md: 319.7).
pub const SEED_R3_RADPS: f64 = 320.0;
/// Seed R4: full and reduced order agree up to about this angular frequency [rad/s].
pub const SEED_R4_AGREEMENT_RADPS: f64 = 600.0;

/// What to run for the semi-active damper.
#[derive(Debug, Clone, PartialEq)]
pub struct DamperOptions {
    /// Frequency of the hysteresis loops \[Hz\] (seed Fig. 3.10-3.13: 4 Hz).
    pub loop_freq_hz: f64,
    /// Stroke amplitudes of the loops \[m\] (seed: 1 and 3 mm).
    pub loop_amplitudes_m: Vec<f64>,
    /// Valve openings of the loops, 0..1 (seed: 0, 20, 50, 100 %).
    pub loop_openings: Vec<f64>,
    /// Valve openings of the FRFs (seed Fig. 3.14-3.15 plus the passive 30 %).
    pub frf_openings: Vec<f64>,
    /// Stroke amplitude of the FRFs \[m\] (seed: 1 mm).
    pub frf_amplitude_m: f64,
    /// FRF band \[Hz\] (seed: 0.5-20 Hz).
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

pub(super) fn option_err(
    option: &'static str,
    value: impl ToString,
    reason: &str,
) -> AnalysisError {
    AnalysisError::Option {
        option,
        value: value.to_string(),
        reason: reason.to_string(),
    }
}

pub(super) fn check_band(
    option: &'static str,
    band: (f64, f64),
    points: usize,
) -> Result<(), AnalysisError> {
    if !(band.0.is_finite() && band.1.is_finite() && band.0 > 0.0 && band.1 > band.0) {
        return Err(option_err(
            option,
            format!(
                "{}..{}",
                master::show::num(band.0),
                master::show::num(band.1)
            ),
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
    check_band(
        "--damper-f-min/--damper-f-max",
        opts.frf_band_hz,
        opts.frf_points,
    )?;
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
pub(super) fn round_sig(v: f64) -> f64 {
    (v * 1e6).round() / 1e6
}

fn pct(opening: f64) -> f64 {
    round_sig(opening * 100.0)
}

impl DamperResults {
    /// Peak |force| of the loop at (opening, amplitude) \[N\].
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
        assert!(
            e.to_string().contains("--damper-f-min/--damper-f-max"),
            "{e}"
        );
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
