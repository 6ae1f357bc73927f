//! What the study runs: the full default study and the reduced `--quick` one, on either
//! vehicle model.

use crate::study::configurations::CONFIGURATIONS;
use crate::study::vehicle::VehicleModel;
use master::results::ResultsFormat;

/// Everything that sizes the study.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct StudySettings {
    /// The vehicle the dampers act on.
    pub vehicle: VehicleModel,
    /// Configuration ids (see [`crate::study::configurations::CONFIGURATIONS`]).
    pub configurations: Vec<&'static str>,
    /// Speeds of the rms sweep [km/h].
    pub speeds_kmh: Vec<f64>,
    /// Level of the ERRI B176 lateral alignment of every run on irregular track.
    pub track_level: TrackLevel,
    /// Track seeds of the internal ERRI B176 generator.
    pub seeds: Vec<u32>,
    /// Length of a sweep run \[s\].
    pub sweep_stop_s: f64,
    /// Start-up transient excluded from every number \[s\].
    pub skip_s: f64,
    /// Final part used for oscillation amplitudes and mean valve commands \[s\].
    pub tail_s: f64,
    /// Bisection of the critical speed down to this bracket width [km/h]; `None` = no bisection.
    pub bisection_tol_kmh: Option<f64>,
    /// Initial-perturbation runs of the passive vehicle (coach: Figs. 4.4-4.6, R16; bogie:
    /// Figs. 5.11-5.13, R7) [km/h].
    pub perturbation_speeds_kmh: Vec<f64>,
    /// Initial lateral displacement of the bogie for those runs \[m\].
    pub perturbation_lateral_m: f64,
    pub perturbation_stop_s: f64,
    /// Full-active c_v sensitivity (Table 4-3, R14): gains [N s/m], speed, run length.
    pub cv_values_nspm: Vec<f64>,
    pub cv_speed_kmh: f64,
    pub cv_stop_s: f64,
    /// Speed of the time-history comparison passive / MPPT2 / sky-hook (Figs. 4.18, 4.21).
    pub history_speed_kmh: f64,
    /// Speed of the MPPT1 vs MPPT2 valve-command comparison from a closed valve (Fig. 4.16).
    pub mppt_low_speed_kmh: f64,
    /// Speed of the slow-valve runs of the HIL chapter (Figs. 5.19-5.24, R12); ideal track,
    /// initial lateral displacement `perturbation_lateral_m`.
    pub hil_speed_kmh: f64,
    /// Initial MPPT command of the HIL runs (seed: fully open valve, 80 %) \[V\].
    pub hil_initial_command_v: f64,
    /// Length of the scenario runs (histories, MPPT, HIL) \[s\].
    pub scenario_stop_s: f64,
    /// Format of every run's stored results: Parquet at the full rate, or CSV decimated to
    /// `stored_rate_hz` through an anti-aliasing low-pass.
    pub stored_format: ResultsFormat,
    /// Sampling rate of a run's results when stored as CSV, and of the time histories the
    /// plots draw \[Hz\] (the numbers are computed from the full-rate signals).
    pub stored_rate_hz: f64,
}

/// ERRI B176 (ORE B176) track quality of the irregular-track runs: the study's default is the
/// low level (high-speed lines); the high level has 2.9 times its spectrum.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum TrackLevel {
    /// A = 2.119e-7 m rad (high-speed lines; the study's default).
    #[default]
    Low,
    /// A = 6.125e-7 m rad.
    High,
}

impl TrackLevel {
    /// The value of the vehicle FMUs' `track.level` Enumeration.
    pub fn fmu_value(self) -> i64 {
        match self {
            TrackLevel::Low => 0,
            TrackLevel::High => 1,
        }
    }

    /// As the report writes it: "low-level", "high-level".
    pub fn name(self) -> &'static str {
        match self {
            TrackLevel::Low => "low-level",
            TrackLevel::High => "high-level",
        }
    }
}

fn range(from: f64, to: f64, step: f64) -> Vec<f64> {
    let n = ((to - from) / step).round() as usize;
    (0..=n).map(|k| from + k as f64 * step).collect()
}

impl StudySettings {
    /// The full study: 200-400 km/h (coach: 200-440 km/h) in 10 km/h steps, 2 seeds,
    /// bisection to 2 km/h.
    pub fn full(vehicle: VehicleModel) -> Self {
        StudySettings {
            vehicle,
            configurations: CONFIGURATIONS
                .iter()
                .filter(|c| vehicle == VehicleModel::Coach || c.on_bogie())
                .map(|c| c.id)
                .collect(),
            // the coach's MPPT and full-active curves are still well under the limit at
            // 400 km/h: 40 km/h more show where they end
            speeds_kmh: match vehicle {
                VehicleModel::Coach => range(200.0, 440.0, 10.0),
                VehicleModel::Bogie2Dof => range(200.0, 400.0, 10.0),
            },
            track_level: TrackLevel::Low,
            seeds: vec![1, 2],
            // 5 s start-up + 10 s assessed: 556 m (46 windows of 100 m) at 200 km/h
            sweep_stop_s: 15.0,
            skip_s: 5.0,
            tail_s: 3.0,
            bisection_tol_kmh: Some(2.0),
            perturbation_speeds_kmh: match vehicle {
                VehicleModel::Coach => vec![240.0, 280.0, 300.0],
                VehicleModel::Bogie2Dof => vec![220.0, 285.0, 320.0],
            },
            perturbation_lateral_m: 3e-3,
            perturbation_stop_s: 10.0,
            cv_values_nspm: vec![210e3, 270e3, 330e3, 390e3],
            cv_speed_kmh: 380.0,
            cv_stop_s: 15.0,
            history_speed_kmh: 300.0,
            mppt_low_speed_kmh: 220.0,
            hil_speed_kmh: 260.0,
            hil_initial_command_v: 8.0,
            scenario_stop_s: 40.0,
            stored_format: ResultsFormat::Parquet,
            stored_rate_hz: 100.0,
        }
    }

    /// The reduced study for CI: 1 seed, shorter runs. Bogie: 5 speeds (40 km/h apart) and a
    /// coarse bisection to 10 km/h (two rounds of one run per configuration), so that the tests
    /// can check critical speeds to +-10 km/h rather than +-40 km/h. Coach: 5 speeds (260-420
    /// km/h, 40 km/h apart), bisection to 5 km/h (three rounds) so that its tests can check the
    /// passive 280-300 km/h, and 20 s scenario runs.
    pub fn quick(vehicle: VehicleModel) -> Self {
        let (speeds_kmh, tol, scenario_stop_s) = match vehicle {
            VehicleModel::Coach => (range(260.0, 420.0, 40.0), 5.0, 20.0),
            VehicleModel::Bogie2Dof => (vec![240.0, 280.0, 320.0, 360.0, 400.0], 10.0, 40.0),
        };
        StudySettings {
            speeds_kmh,
            seeds: vec![1],
            sweep_stop_s: 12.0,
            bisection_tol_kmh: Some(tol),
            perturbation_stop_s: 8.0,
            cv_stop_s: 12.0,
            scenario_stop_s,
            ..Self::full(vehicle)
        }
    }

    /// Number of runs before bisection (for the start message).
    pub fn planned_runs(&self) -> usize {
        self.configurations.len() * self.speeds_kmh.len() * self.seeds.len()
            + self.perturbation_speeds_kmh.len()
            + self.cv_values_nspm.len() * self.seeds.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn full_and_quick_sizes() {
        let f = StudySettings::full(VehicleModel::Bogie2Dof);
        assert_eq!(f.speeds_kmh.len(), 21);
        assert_eq!(f.speeds_kmh[0], 200.0);
        assert_eq!(f.speeds_kmh[20], 400.0);
        assert_eq!(f.configurations.len(), CONFIGURATIONS.len() - 2);
        assert_eq!(
            StudySettings::full(VehicleModel::Coach)
                .configurations
                .len(),
            CONFIGURATIONS.len()
        );
        // several 100 m windows after the skip at the lowest speed
        let assessed_m = (f.sweep_stop_s - f.skip_s) * f.speeds_kmh[0] / 3.6;
        assert!(assessed_m >= 500.0, "{assessed_m}");
        let q = StudySettings::quick(VehicleModel::Bogie2Dof);
        assert!(q.planned_runs() < f.planned_runs() / 4);
        let c = StudySettings::quick(VehicleModel::Coach);
        assert_eq!(c.speeds_kmh, [260.0, 300.0, 340.0, 380.0, 420.0]);
        assert!(c.planned_runs() < f.planned_runs() / 2);
        assert_eq!(
            StudySettings::full(VehicleModel::Coach).perturbation_speeds_kmh,
            [240.0, 280.0, 300.0]
        );
        assert!(q.bisection_tol_kmh.unwrap() > f.bisection_tol_kmh.unwrap());
        let assessed_m = (q.sweep_stop_s - q.skip_s) * q.speeds_kmh[0] / 3.6;
        assert!(assessed_m >= 300.0, "{assessed_m}");
    }
}
