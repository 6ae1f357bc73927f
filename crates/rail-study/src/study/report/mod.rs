//! Study outputs: CSVs behind every plot, SVG charts, `study.json` and `REPORT.md`.

use std::fmt::Write as _;
use std::path::Path;

use crate::study::configurations::configuration;
use crate::study::critical::Critical;
use crate::study::run::{ConfigResult, StudyError, StudyResults};
use crate::study::vehicle::VehicleModel;
use master::output::{write_bytes_atomic, write_json_atomic};

/// Timing of the whole study, measured by the caller.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Timing {
    pub wall_s: f64,
    pub threads: usize,
}

impl Timing {
    /// Simulated seconds per wall-clock second over the whole study.
    pub fn sim_per_wall(&self, r: &StudyResults) -> f64 {
        if self.wall_s > 0.0 {
            r.simulated_s / self.wall_s
        } else {
            0.0
        }
    }
}

/// The seed's Table 4-3 (R14): c_v [kNs/m], rms acc [m/s^2], F_max \[kN\], rms power \[kW\].
pub const SEED_TABLE_4_3: [(f64, f64, f64, f64); 4] = [
    (210.0, 7.08, 20.369, 0.357),
    (270.0, 5.98, 23.491, 0.280),
    (330.0, 3.91, 23.100, 0.242),
    (390.0, 2.63, 24.570, 0.194),
];

fn label_of(id: &str) -> &'static str {
    configuration(id).map_or("?", |c| c.label)
}

fn fmt_opt(v: Option<f64>, scale: f64, prec: usize) -> String {
    v.map_or("failed".to_string(), |x| format!("{:.*}", prec, x * scale))
}

/// The stem of each figure (`<stem>.svg`, its data `<stem>.csv`): the write sites name them
/// here, so that [`FIGURE_STEMS`] (what a new study removes first) lists every one.
pub mod stem {
    pub const RMS_VS_SPEED: &str = "rms_vs_speed";
    pub const CARBODY_VS_SPEED: &str = "carbody_vs_speed";
    pub const COMFORT_VS_SPEED: &str = "comfort_vs_speed";
    pub const HISTORY_DISPLACEMENT: &str = "history_displacement";
    pub const HISTORY_ACCELERATION: &str = "history_acceleration";
    pub const HISTORY_FORCE: &str = "history_force";
    pub const HISTORY_COMMAND: &str = "history_command";
    pub const HISTORY_CARBODY: &str = "history_carbody";
    pub const HISTORY_DISPLACEMENT_DETAIL: &str = "history_displacement_detail";
    pub const HISTORY_ACCELERATION_DETAIL: &str = "history_acceleration_detail";
    pub const HISTORY_FORCE_DETAIL: &str = "history_force_detail";
    pub const HISTORY_COMMAND_DETAIL: &str = "history_command_detail";
    pub const HISTORY_CARBODY_DETAIL: &str = "history_carbody_detail";
    pub const FULL_ACTIVE_FORCE: &str = "full_active_force";
    pub const PERTURBATION: &str = "perturbation";
    pub const MPPT_COMMAND_CLOSED_START: &str = "mppt_command_closed_start";
    pub const MPPT_COMMAND_OPEN_START: &str = "mppt_command_open_start";
    pub const SLOW_VALVE_DISPLACEMENT: &str = "slow_valve_displacement";
    pub const SLOW_VALVE_OPENING: &str = "slow_valve_opening";
    pub const SKYHOOK_VALVE_ZOOM: &str = "skyhook_valve_zoom";
    pub const CV_ACCELERATION: &str = "cv_acceleration";
    pub const CV_FORCE: &str = "cv_force";
}

/// The figures a study may write into its output folder, each as `<stem>.svg` with its data
/// in `<stem>.csv` (which of them depends on the vehicle and on the runs that succeeded).
pub const FIGURE_STEMS: [&str; 22] = [
    stem::RMS_VS_SPEED,
    stem::CARBODY_VS_SPEED,
    stem::COMFORT_VS_SPEED,
    stem::HISTORY_DISPLACEMENT,
    stem::HISTORY_ACCELERATION,
    stem::HISTORY_FORCE,
    stem::HISTORY_COMMAND,
    stem::HISTORY_CARBODY,
    stem::HISTORY_DISPLACEMENT_DETAIL,
    stem::HISTORY_ACCELERATION_DETAIL,
    stem::HISTORY_FORCE_DETAIL,
    stem::HISTORY_COMMAND_DETAIL,
    stem::HISTORY_CARBODY_DETAIL,
    stem::FULL_ACTIVE_FORCE,
    stem::PERTURBATION,
    stem::MPPT_COMMAND_CLOSED_START,
    stem::MPPT_COMMAND_OPEN_START,
    stem::SLOW_VALVE_DISPLACEMENT,
    stem::SLOW_VALVE_OPENING,
    stem::SKYHOOK_VALVE_ZOOM,
    stem::CV_ACCELERATION,
    stem::CV_FORCE,
];

/// The names of every file [`write_outputs`] may write into a study's output folder: the
/// figures and their CSVs, the c_v table, `study.json` and `REPORT.md`.
pub fn output_files() -> Vec<String> {
    let mut files: Vec<String> = FIGURE_STEMS
        .iter()
        .flat_map(|stem| [format!("{stem}.svg"), format!("{stem}.csv")])
        .collect();
    files.extend(
        ["cv_sensitivity.csv", "study.json", "REPORT.md"]
            .iter()
            .map(|f| f.to_string()),
    );
    files
}

/// Writes every output file and REPORT.md into `out`; returns the report text.
pub fn write_outputs(r: &StudyResults, out: &Path, timing: &Timing) -> Result<String, StudyError> {
    std::fs::create_dir_all(out).map_err(|source| master::output::OutputError::Io {
        path: out.to_path_buf(),
        source,
    })?;
    // the numbers first: a plotting problem must not lose them
    write_json_atomic(&out.join("study.json"), r)?;
    let mut figures: Vec<(String, &str)> = Vec::new();
    speed_figures(r, out, &mut figures)?;
    history_figures(r, out, &mut figures)?;
    hil_figures(r, out, &mut figures)?;
    cv_figures(r, out, &mut figures)?;

    let text = report_markdown(r, timing, &figures);
    write_bytes_atomic(&out.join("REPORT.md"), text.as_bytes())?;
    Ok(text)
}

mod figures;
mod markdown;

#[cfg(test)]
use figures::{between, busiest_second, moving_mean, HISTORY_DETAIL_CAPTION};
use figures::{cv_figures, hil_figures, history_figures, speed_figures};
#[cfg(test)]
mod tests;

pub use markdown::{
    comfort_speeds, force_bound_note, gain_over_passive, report_markdown, within_limit_above,
    ActuatorBound, DIFFERENCES, DIFFERENCES_COACH,
};
