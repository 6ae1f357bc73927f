//! Root locus of the linear coach over speed, through `fmu_vehicle::eigen`: every eigenvalue per
//! speed, the least-damped oscillatory mode named by its kinetic-energy shares (bogie or
//! car-body hunting), the linear critical speed by bisection with the mode that crosses (R15).
//!
//! The default damper is the coach crate's representation of the passive reference damper
//! ([`fmu_vehicle::calibration::passive_damper`]: the Maxwell element of the 2-dof bogie's
//! calibration, on all four dampers), optionally behind a mounting (series) stiffness of the
//! installation.

use fmu_vehicle::calibration::passive_damper;
use fmu_vehicle::eigen::{
    analyse, critical_speed, CriticalSpeed, EigenError, EigenResult, Mode, YawDamperModel,
};
use fmu_vehicle::VehicleParams;

use super::locus::{DamperSpec, Onset};
use super::locus_figures::{damping_ratio, speeds_line, LocusFigures, LocusSpeed};
use super::{AnalysisError, Artefacts, Table};

/// Seed R15: linear critical speed of the coach with the passive reference damper [km/h].
pub const SEED_R15_KMH: (f64, f64) = (280.0, 290.0);
/// Speed range searched for the critical speed [m/s] (the coach accepts up to 200).
pub const CRITICAL_SEARCH_MPS: (f64, f64) = (5.0, 199.0);

/// The damper of the coach's linear model for a spec: the spec behind `mounting_n_per_m`.
pub fn damper_model(spec: DamperSpec, mounting_n_per_m: Option<f64>) -> YawDamperModel {
    let representation = spec
        .linear()
        .unwrap_or_else(|| passive_damper().representation);
    YawDamperModel {
        representation,
        mounting_stiffness_n_per_m: mounting_n_per_m.or(if spec == DamperSpec::Passive {
            passive_damper().mounting_stiffness_n_per_m
        } else {
            None
        }),
    }
}

/// Result of a coach root-locus run.
#[derive(Debug, Clone, PartialEq)]
pub struct VehicleLocus {
    pub damper: DamperSpec,
    pub mounting_n_per_m: Option<f64>,
    pub speeds_kmh: Vec<f64>,
    pub results: Vec<EigenResult>,
    /// Linear critical speed in [`CRITICAL_SEARCH_MPS`], or why there is none.
    pub critical: Result<CriticalSpeed, String>,
    /// sqrt(lambda / (r0 s)) [rad/m]: times the speed, the angular frequency of a free
    /// wheelset's kinematic (Klingel) oscillation, above which no hunting mode of the coach lies.
    pub kinematic_rad_per_m: f64,
    /// The linear model's equivalent conicity, and whether it was changed from the calibrated
    /// default.
    pub conicity: f64,
    pub conicity_changed: bool,
}

fn vehicle_err(e: EigenError) -> AnalysisError {
    AnalysisError::LinearModel(format!("coach: {e}"))
}

/// Eigenvalues over the speed grid and the linear critical speed.
pub fn vehicle_root_locus(
    params: &VehicleParams,
    damper: DamperSpec,
    mounting_n_per_m: Option<f64>,
    speeds_kmh: &[f64],
) -> Result<VehicleLocus, AnalysisError> {
    let model = damper_model(damper, mounting_n_per_m);
    let results = speeds_kmh
        .iter()
        .map(|v| analyse(params, v / 3.6, &model))
        .collect::<Result<Vec<_>, _>>()
        .map_err(vehicle_err)?;
    let critical =
        match critical_speed(params, &model, CRITICAL_SEARCH_MPS.0, CRITICAL_SEARCH_MPS.1) {
            Ok(c) => Ok(c),
            Err(EigenError::NoCrossing { .. }) => Err(format!(
                "stable up to {:.0} km/h (no stability boundary found)",
                CRITICAL_SEARCH_MPS.1 * 3.6
            )),
            Err(EigenError::UnstableAtLowerEnd { .. }) => Err(format!(
                "unstable already at {:.0} km/h",
                CRITICAL_SEARCH_MPS.0 * 3.6
            )),
            Err(e) => return Err(vehicle_err(e)),
        };
    let kinematic_rad_per_m = kinematic_rad_per_m(params);
    Ok(VehicleLocus {
        damper,
        mounting_n_per_m,
        speeds_kmh: speeds_kmh.to_vec(),
        results,
        critical,
        kinematic_rad_per_m,
        conicity: params.wheel_rail.conicity,
        conicity_changed: params.wheel_rail.conicity
            != VehicleParams::default().wheel_rail.conicity,
    })
}

/// [`Onset`] of the linear coach with `spec` behind `mounting_n_per_m`: when nothing crosses,
/// the hunting mode at the top of [`CRITICAL_SEARCH_MPS`], the least-damped oscillation below
/// the free wheelset's kinematic frequency (as [`VehicleLocus::hunting_mode`] starts).
pub fn vehicle_onset(
    params: &VehicleParams,
    spec: DamperSpec,
    mounting_n_per_m: Option<f64>,
) -> Result<Onset, String> {
    let model = damper_model(spec, mounting_n_per_m);
    let (lo, hi) = CRITICAL_SEARCH_MPS;
    match critical_speed(params, &model, lo, hi) {
        Ok(c) => Ok(Onset::Crosses(c.mode.freq_hz)),
        Err(EigenError::NoCrossing { .. }) => {
            let top = analyse(params, hi, &model).map_err(|e| e.to_string())?;
            let hunting = hunting_candidate(&top, kinematic_rad_per_m(params) * hi);
            Ok(Onset::Stable(
                hunting.map(|e| e.1 / (2.0 * std::f64::consts::PI)),
            ))
        }
        Err(EigenError::UnstableAtLowerEnd { .. }) => Ok(Onset::Stable(None)),
        Err(e) => Err(e.to_string()),
    }
}

/// The hunting mode where nothing crosses: the least-damped oscillatory eigenvalue of `r`
/// below the free wheelset's kinematic frequency `kinematic_rad_per_s` (bogie and car-body
/// hunting both lie below it; a stiff damper's least-damped mode overall may be a 66 Hz one of
/// the bogies).
fn hunting_candidate(r: &EigenResult, kinematic_rad_per_s: f64) -> Option<(f64, f64)> {
    r.eigenvalues
        .iter()
        .filter(|e| e.1 > 0.0 && e.1 <= kinematic_rad_per_s)
        .min_by(|a, b| damping_ratio(a.0, a.1).total_cmp(&damping_ratio(b.0, b.1)))
        .copied()
}

/// The free wheelset's kinematic (Klingel) wavenumber [rad/m]: sqrt(conicity / (r0 b)).
fn kinematic_rad_per_m(params: &VehicleParams) -> f64 {
    (params.wheel_rail.conicity
        / (params.wheelset.wheel_radius_m * params.wheelset.half_contact_gauge_m))
        .sqrt()
}

/// Number of the mode kind in the CSV (0 car body, 1 front bogie, 2 rear bogie, 3 both).
fn kind_code(m: &Mode) -> f64 {
    use fmu_vehicle::eigen::ModeKind::*;
    match m.kind {
        CarBody => 0.0,
        FrontBogie => 1.0,
        RearBogie => 2.0,
        BothBogies => 3.0,
    }
}

impl VehicleLocus {
    fn least_damped(&self) -> Vec<(f64, Mode)> {
        self.speeds_kmh
            .iter()
            .zip(&self.results)
            .filter_map(|(v, r)| r.least_damped.map(|m| (*v, m)))
            .collect()
    }

    /// The hunting mode (re, im) at each speed of the grid, followed from the mode that
    /// crosses at the critical speed: each neighbouring speed takes its oscillatory eigenvalue
    /// nearest to the one before. The least-damped mode is another one at low speeds (the
    /// passive coach: a 90 Hz mode of the bogies below 215 km/h), which made the frequency
    /// figure jump from 90 to 3.5 Hz. Without a crossing (a stiff damper) the start is the
    /// least-damped oscillatory eigenvalue at the highest speed among those below the free
    /// wheelset's kinematic frequency there (bogie and car-body hunting both lie below it;
    /// the closed semi-active valve's least-damped mode overall is a 66 Hz one of the bogies).
    pub fn hunting_mode(&self) -> Vec<Option<(f64, f64)>> {
        let mut followed = vec![None; self.results.len()];
        let nearest = |k: usize, to: (f64, f64)| {
            self.results[k]
                .eigenvalues
                .iter()
                .filter(|e| e.1 > 0.0)
                .min_by(|a, b| {
                    let d = |e: &&(f64, f64)| (e.0 - to.0).hypot(e.1 - to.1);
                    d(a).total_cmp(&d(b))
                })
                .copied()
        };
        let start = match &self.critical {
            Ok(c) => self
                .speeds_kmh
                .iter()
                .enumerate()
                .min_by(|a, b| {
                    (a.1 - c.speed_kmh)
                        .abs()
                        .total_cmp(&(b.1 - c.speed_kmh).abs())
                })
                .and_then(|(k, _)| Some((k, nearest(k, (c.mode.re, c.mode.im))?))),
            Err(_) => {
                let top = self.results.len().checked_sub(1);
                let kinematic = |k: usize| self.kinematic_rad_per_m * self.speeds_kmh[k] / 3.6;
                top.and_then(|k| hunting_candidate(&self.results[k], kinematic(k)).map(|e| (k, e)))
                    // no oscillation below it (conicity 0: no kinematic oscillation at all): the
                    // least-damped mode at the highest speed
                    .or_else(|| {
                        self.results
                            .iter()
                            .enumerate()
                            .rev()
                            .find_map(|(k, r)| r.least_damped.map(|m| (k, (m.re, m.im))))
                    })
            }
        };
        let Some((k0, mode)) = start else {
            return followed;
        };
        followed[k0] = Some(mode);
        for range in [
            (k0 + 1..self.results.len()).collect::<Vec<_>>(),
            (0..k0).rev().collect(),
        ] {
            let mut last = mode;
            for k in range {
                let Some(next) = nearest(k, last) else { break };
                followed[k] = Some(next);
                last = next;
            }
        }
        followed
    }

    /// The eigenvalues per speed and the hunting mode, as the shared figures take them.
    fn figures(&self) -> LocusFigures<'_> {
        LocusFigures {
            model: "coach",
            damper: self.damper.describe(),
            mode: "hunting mode",
            mode_column: if self.critical.is_ok() {
                "hunting mode (followed from the critical speed)"
            } else {
                "hunting mode (followed from the least-damped mode below the kinematic frequency at the highest speed)"
            },
            frequency_title: "Frequency of the hunting mode vs speed (linear coach)".into(),
            speeds: LocusSpeed::over(
                &self.speeds_kmh,
                self.results
                    .iter()
                    .zip(self.hunting_mode())
                    .map(|(r, m)| (r.eigenvalues.as_slice(), m)),
            ),
        }
    }

    pub fn add_artefacts(&self, a: &mut Artefacts) -> Result<(), AnalysisError> {
        let figures = self.figures();
        figures.add_eigenvalue_table(a)?;
        let mut modes = Table::new(&[
            "speed [km/h]",
            "real part [1/s]",
            "imaginary part [rad/s]",
            "frequency [Hz]",
            "damping ratio [-]",
            "car-body energy share [-]",
            "front bogie energy share [-]",
            "rear bogie energy share [-]",
            "mode (0 car body, 1 front bogie, 2 rear bogie, 3 both bogies)",
            // the least-damped mode is not always a hunting one (the passive coach: a 90 Hz
            // mode of the bogies below 215 km/h); hunting modes lie below the free wheelset's
            // kinematic frequency
            "hunting (1: below the kinematic frequency, 0: another mode)",
        ]);
        let ld = self.least_damped();
        for (v, m) in &ld {
            let hunting = m.im <= self.kinematic_rad_per_m * v / 3.6;
            modes.rows.push(vec![
                *v,
                m.re,
                m.im,
                m.freq_hz,
                m.damping_ratio,
                m.shares.carbody,
                m.shares.front_bogie,
                m.shares.rear_bogie,
                kind_code(m),
                f64::from(u8::from(hunting)),
            ]);
        }
        a.add_table("root_locus_least_damped.csv", &modes)?;
        figures.add_figures(a)
    }

    /// The key numbers for `root-locus.json`: the linear critical speed (null, with the
    /// reason, when nothing crosses), the onset's frequency and mode, the set-up.
    pub fn results_json(&self) -> serde_json::Value {
        let (critical, reason) = super::locus::critical_json(&self.critical, |c| {
            serde_json::json!({
                "speed_kmh": c.speed_kmh,
                "frequency_hz": c.mode.freq_hz,
                "im_rad_per_s": c.mode.im,
                "mode": c.mode.kind.label(),
                "energy_carbody": c.mode.shares.carbody,
                "energy_front_bogie": c.mode.shares.front_bogie,
                "energy_rear_bogie": c.mode.shares.rear_bogie,
            })
        });
        serde_json::json!({
            "model": "vehicle",
            "damper": self.damper.describe(),
            "mounting_stiffness_n_per_m": self.mounting_n_per_m,
            "conicity": self.conicity,
            "critical": critical,
            "no_crossing": reason,
        })
    }

    /// Critical speed, frequency and mode at onset next to the seed's.
    pub fn summary(&self) -> String {
        let mounting = self
            .mounting_n_per_m
            .map_or("rigid mounting".to_string(), |k| {
                format!("mounting stiffness {:.1} MN/m", k * 1e-6)
            });
        let conicity = if self.conicity_changed {
            format!(
                "fmu-vehicle defaults, conicity {:.3} instead of the calibrated {:.3}",
                self.conicity,
                VehicleParams::default().wheel_rail.conicity
            )
        } else {
            format!(
                "calibrated fmu-vehicle defaults, conicity {:.3}",
                self.conicity
            )
        };
        let mut s = format!(
            "linear coach ({conicity}), damper: {}, {mounting}\n",
            self.damper.describe()
        );
        s.push_str(&speeds_line(&self.speeds_kmh));
        match &self.critical {
            Ok(c) => {
                s.push_str(&format!(
                    "linear critical speed: {:.1} km/h (seed R15: {}-{} km/h with the passive damper)\n",
                    c.speed_kmh, SEED_R15_KMH.0, SEED_R15_KMH.1
                ));
                s.push_str(&format!(
                    "mode at onset: {}, Im {:.1} rad/s, frequency {:.2} Hz (kinetic energy: car body {:.0} %, front bogie {:.0} %, rear bogie {:.0} %)\n",
                    c.mode.kind.label(),
                    c.mode.im,
                    c.mode.freq_hz,
                    100.0 * c.mode.shares.carbody,
                    100.0 * c.mode.shares.front_bogie,
                    100.0 * c.mode.shares.rear_bogie
                ));
            }
            Err(why) => s.push_str(&format!("linear critical speed: none, {why}\n")),
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::locus::speed_grid_kmh;

    /// The calibrated coach with the passive damper over `from..=to` km/h in `step`s.
    fn passive_locus(from: f64, to: f64, step: f64) -> (Vec<f64>, VehicleLocus) {
        let speeds = speed_grid_kmh(from, to, step).unwrap();
        let locus = vehicle_root_locus(
            &VehicleParams::default(),
            DamperSpec::Passive,
            None,
            &speeds,
        )
        .unwrap();
        (speeds, locus)
    }

    #[test]
    fn passive_coach_root_locus_gives_r15_and_names_the_mode() {
        let (speeds, r) = passive_locus(200.0, 320.0, 40.0);
        let c = r.critical.as_ref().unwrap();
        // fmu-vehicle is calibrated to 285 km/h (R15: 280-290)
        assert!((280.0..=290.0).contains(&c.speed_kmh), "{}", c.speed_kmh);
        assert!((3.0..=5.0).contains(&c.mode.freq_hz), "{:?}", c.mode);
        let mut a = Artefacts::default();
        r.add_artefacts(&mut a).unwrap();
        for f in [
            "root_locus.svg",
            "root_locus_least_damped.csv",
            "damping_ratio.svg",
        ] {
            assert!(a.names().contains(&f), "{f}");
        }
        let s = r.summary();
        assert!(
            s.contains("linear critical speed: 28") && s.contains("hunting"),
            "{s}"
        );
        // a soft mounting in series with the damper changes the critical speed (measured: 5
        // MN/m raises it from 285.0 to 309.6 km/h: the yaw stiffness between bogie and car
        // body falls, the damping at the hunting frequency rises)
        let soft = vehicle_root_locus(
            &VehicleParams::default(),
            DamperSpec::Passive,
            Some(5e6),
            &speeds,
        )
        .unwrap();
        let v_soft = soft.critical.as_ref().unwrap().speed_kmh;
        assert!((v_soft - 309.6).abs() < 3.0, "{v_soft} vs {}", c.speed_kmh);
    }

    #[test]
    fn without_a_crossing_the_figures_follow_hunting_not_a_wheelset_mode() {
        // the closed valve linearised at +-2 mm, 4 Hz (`--damper semi-active:0:2e-3`): stable
        // to the end of the search; its least-damped mode is a 66 Hz one of the bogies
        let speeds = speed_grid_kmh(100.0, 400.0, 50.0).unwrap();
        let r = vehicle_root_locus(
            &VehicleParams::default(),
            DamperSpec::KelvinVoigt(6.43e6, 202.5e3),
            None,
            &speeds,
        )
        .unwrap();
        assert!(r.critical.is_err(), "{:?}", r.critical);
        let top = r.results.last().unwrap().least_damped.unwrap();
        assert!(top.freq_hz > 50.0, "{top:?}");
        for (v, m) in speeds.iter().zip(r.hunting_mode()) {
            let f = m.unwrap().1 / (2.0 * std::f64::consts::PI);
            // measured: 2.5 Hz at 100 km/h to 4.6 Hz at 400
            assert!((1.5..=6.0).contains(&f), "{v} km/h: {f} Hz");
        }
        assert!(r.figures().mode_column.contains("kinematic frequency"));
        // conicity 0: no kinematic oscillation, no eigenvalue below it: the least-damped mode
        let mut flat = VehicleParams::default();
        flat.wheel_rail.conicity = 0.0;
        let r = vehicle_root_locus(&flat, DamperSpec::Passive, None, &speeds).unwrap();
        assert!(r.hunting_mode().iter().all(|m| m.is_some()));
    }

    #[test]
    fn the_figures_follow_the_hunting_mode_not_the_least_damped_one() {
        let (speeds, r) = passive_locus(100.0, 400.0, 10.0);
        let hunting = r.hunting_mode();
        let ld: Vec<_> = r.results.iter().map(|e| e.least_damped.unwrap()).collect();
        // below about 215 km/h the least-damped mode is a 90 Hz mode of the bogies
        assert!(ld[0].freq_hz > 50.0, "{:?}", ld[0]);
        for (k, (v, m)) in speeds.iter().zip(&hunting).enumerate() {
            let (re, im) = m.unwrap();
            let f = im / (2.0 * std::f64::consts::PI);
            // kinematic hunting (measured 1.83 Hz at 100 km/h to 4.56 at 400), rising with speed
            assert!((1.5..=5.0).contains(&f), "{v} km/h: {f} Hz");
            if k > 0 {
                let before = hunting[k - 1].unwrap().1;
                assert!(im >= before - 0.5, "{v} km/h: {im} after {before}");
            }
            // above the crossing of the two it is the least-damped mode, and it crosses
            if *v >= 230.0 {
                assert_eq!((re, im), (ld[k].re, ld[k].im), "{v} km/h");
            }
            assert_eq!(
                re > 0.0,
                *v > r.critical.as_ref().unwrap().speed_kmh,
                "{v} km/h"
            );
        }
        // the least-damped table says which rows are not a hunting mode
        let mut files = Artefacts::default();
        r.add_artefacts(&mut files).unwrap();
        let (_, csv) = files
            .files
            .iter()
            .find(|(n, _)| n == "root_locus_least_damped.csv")
            .unwrap();
        let csv = String::from_utf8(csv.clone()).unwrap();
        let hunting: Vec<(f64, &str)> = csv
            .lines()
            .skip(1)
            .map(|l| {
                let cells: Vec<&str> = l.split(',').collect();
                (cells[0].parse().unwrap(), *cells.last().unwrap())
            })
            .collect();
        assert_eq!(hunting.len(), speeds.len());
        for (v, h) in hunting {
            let f = ld[speeds.iter().position(|s| *s == v).unwrap()].freq_hz;
            assert_eq!(h, if f > 50.0 { "0" } else { "1" }, "{v} km/h, {f} Hz");
        }
    }
}
