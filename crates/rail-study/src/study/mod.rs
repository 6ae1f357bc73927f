//! The stability study of the seed's chapter 4: passive, semi-active (MPPT1/2, sky-hook on/off
//! and continuous, each with an ideal and a slow valve; on the coach also the seed's
//! accelerometer-based on/off sky-hook) and full-active (IDF) yaw dampers on
//! the coach (default, four dampers) or the non-linear 2-dof bogie (the seed's HIL
//! configuration, two dampers), assessed by the EN 14363 rms criterion, with the car body's
//! lateral acceleration and ride comfort (EN 12299) on the coach.
//!
//! * [`vehicle`]: the two vehicle models, their signal names and the coach's generated systems.
//! * [`configurations`]: the configurations (bogie system descriptions in `systems/*.json`).
//! * [`config`]: system descriptions on a vehicle model and run requests.
//! * [`settings`]: the full and the `--quick` study.
//! * [`metrics`]: numbers of one run (EN 14363 rms, oscillation amplitude, peak force...).
//! * [`critical`]: critical speed from an rms curve, bisection.
//! * [`run`]: runs the batches through [`master::runset`] (parallel, one folder per run).
//! * [`report`]: CSVs, SVG charts and REPORT.md.
//!
//! From a test: `run_study(&StudySettings::quick(VehicleModel::Coach), &opts)` gives [`run::StudyResults`].

pub mod config;
pub mod configurations;
pub mod critical;
pub mod metrics;
pub mod report;
pub mod run;
pub mod settings;
pub mod vehicle;

pub use config::Sources;
pub use configurations::{Configuration, CONFIGURATIONS};
pub use critical::Critical;
pub use report::{write_outputs, Timing};
pub use run::{run_study, run_study_checked, StudyError, StudyOptions, StudyResults};
pub use settings::{StudySettings, TrackLevel};
pub use vehicle::VehicleModel;
