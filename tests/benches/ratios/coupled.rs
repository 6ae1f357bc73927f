//! The coupled passive system (`systems/passive.json`) in our master and the same physics
//! stepped in plain Rust, and a run set of it.

use std::time::Instant;

use fmu_bogie2dof::model::{Bogie, Inputs};
use fmu_bogie2dof::params::{Params, PsdLevel, TrackSource};
use fmu_damper::semi_active::{SemiActiveDamper, SemiActiveInputs, SemiActiveParams};
use master::coupling::{RunOptions, SimOutput};
use master::runset::{execute, run_job, RunSet};
use master::system::{LoadedSystem, PreparedSystem};

use crate::{cpu_seconds, repo, COUPLED_STOP_S, STEP_S};

/// The passive system with its stop time replaced.
pub fn passive_system(stop_s: f64) -> LoadedSystem {
    let path = repo().join("systems/passive.json");
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    v["stop_time"] = serde_json::json!(stop_s);
    LoadedSystem::from_json_str(&v.to_string(), &repo().join("systems"), "passive.json").unwrap()
}

/// The recorded variables of `systems/passive.json`, in its order (the direct run records the
/// same values).
pub const PASSIVE_RECORD: [&str; 7] = [
    "bogie.wheelset_front.lateral_displacement_relative",
    "bogie.wheelset_rear.lateral_displacement_relative",
    "bogie.wheelset_front.lateral_acceleration",
    "bogie.wheelset_rear.lateral_acceleration",
    "bogie.wheelset_front.guiding_force",
    "damper_left.damper.force",
    "damper_right.damper.force",
];

/// One coupled run: wall time of the simulation loop per simulated second, and the recorded
/// rows after the start (time, then [`PASSIVE_RECORD`]).
pub struct Timed {
    pub per_sim_s: f64,
    pub rows: Vec<f64>,
}

/// Master: preparation (unpacking and loading the FMUs) is not timed. Returns the wall time
/// per simulated second and the output; its rows are taken outside (see [`master_timed`]), so
/// that callgrind's inclusive count of this function holds the run and no extraction of
/// result columns.
#[inline(never)]
pub fn master_passive(stop_s: f64) -> (f64, SimOutput) {
    let system = PreparedSystem::prepare(&passive_system(stop_s)).unwrap();
    let changes = system
        .changes(&std::collections::BTreeMap::new(), None, "bench")
        .unwrap();
    let started = Instant::now();
    let out = system.run(&changes, &RunOptions::default()).unwrap();
    (started.elapsed().as_secs_f64() / stop_s, out)
}

/// [`master_passive`] with the recorded rows after the start (time, then [`PASSIVE_RECORD`]).
pub fn master_timed(stop_s: f64) -> Timed {
    let (per_sim_s, out) = master_passive(stop_s);
    let time = out.column("time").unwrap();
    let columns: Vec<Vec<f64>> = PASSIVE_RECORD
        .iter()
        .map(|c| out.column(c).unwrap())
        .collect();
    let mut rows = Vec::with_capacity(time.len() * (1 + columns.len()));
    for k in 1..time.len() {
        rows.push(time[k]);
        rows.extend(columns.iter().map(|c| c[k]));
    }
    Timed { per_sim_s, rows }
}

/// The front wheelset's displacement in the last row.
pub fn front_displacement(rows: &[f64]) -> f64 {
    rows[rows.len() - PASSIVE_RECORD.len()]
}

/// The largest difference between the direct and the master's rows, relative to the largest
/// magnitude of its column.
pub fn largest_difference(direct: &[f64], master: &[f64]) -> f64 {
    assert_eq!(direct.len(), master.len(), "not as many recorded values");
    let width = 1 + PASSIVE_RECORD.len();
    (0..width)
        .map(|c| {
            let column = |rows: &[f64]| rows.iter().skip(c).step_by(width).copied().collect();
            let (d, m): (Vec<f64>, Vec<f64>) = (column(direct), column(master));
            let scale = d.iter().fold(0.0f64, |a, x| a.max(x.abs())).max(1e-300);
            d.iter()
                .zip(&m)
                .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()))
                / scale
        })
        .fold(0.0, f64::max)
}

/// The same physics, parameters, order and step without FMI; records the same 7 values per
/// step as the system's record list: the bogie's outputs at the end of the step with the
/// dampers' new forces (as the master reads them after the dampers set them).
#[inline(never)]
pub fn direct_passive(stop_s: f64) -> Timed {
    let n = (stop_s / STEP_S).round() as usize;
    let mut rec: Vec<f64> = Vec::with_capacity((n + 1) * 8);
    let params = Params {
        speed_mps: 83.333_333_333_333_33,
        track: TrackSource::Internal {
            level: PsdLevel::Low,
            seed: 1,
        },
        initial_lateral_m: 0.0,
        initial_yaw_rad: 0.0,
        ..Params::default()
    };
    let started = Instant::now();
    let mut bogie = Bogie::new(params).unwrap();
    let mut left = SemiActiveDamper::new(SemiActiveParams::passive_reference()).unwrap();
    let mut right = SemiActiveDamper::new(SemiActiveParams::passive_reference()).unwrap();
    let mut inputs = Inputs::default();
    let mut out = bogie.outputs(&inputs).unwrap();
    for k in 0..n {
        let _t = k as f64 * STEP_S;
        out = bogie.step(STEP_S, &inputs).unwrap();
        let l = left
            .step(
                STEP_S,
                &SemiActiveInputs {
                    elongation_m: out.damper_left_elongation_m,
                    elongation_velocity_mps: out.damper_left_velocity_mps,
                    ..SemiActiveInputs::default()
                },
            )
            .unwrap();
        let r = right
            .step(
                STEP_S,
                &SemiActiveInputs {
                    elongation_m: out.damper_right_elongation_m,
                    elongation_velocity_mps: out.damper_right_velocity_mps,
                    ..SemiActiveInputs::default()
                },
            )
            .unwrap();
        inputs.damper_left_force_n = l.force_n;
        inputs.damper_right_force_n = r.force_n;
        let now = bogie.outputs(&inputs).unwrap();
        rec.extend_from_slice(&[
            now.time_s,
            now.wheelset_front_rel_track_m,
            now.wheelset_rear_rel_track_m,
            now.wheelset_front_acc_mps2,
            now.wheelset_rear_acc_mps2,
            now.guiding_force_front_n,
            l.force_n,
            r.force_n,
        ]);
    }
    let elapsed_s = started.elapsed().as_secs_f64();
    std::hint::black_box(&out);
    Timed {
        per_sim_s: elapsed_s / stop_s,
        rows: rec,
    }
}

/// A run set of 4 speeds of the passive system on `threads` workers: (wall [s], CPU [s]).
pub fn runset_wall(threads: usize) -> (f64, f64) {
    let path = repo().join("systems/passive.json");
    let mut base: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    base["stop_time"] = serde_json::json!(COUPLED_STOP_S);
    let set = serde_json::json!({
        "system": base,
        "product": {"bogie.vehicle.speed": [69.4, 75.0, 80.6, 86.1]}
    });
    let (base, jobs) =
        RunSet::from_str_with_base(&set.to_string(), &repo().join("systems"), "bench").unwrap();
    let out = tempfile::tempdir().unwrap();
    let cancel = std::sync::atomic::AtomicBool::new(false);
    let started = Instant::now();
    let cpu0 = cpu_seconds();
    let system = PreparedSystem::prepare(&base).unwrap();
    let reports = execute(&jobs, out.path(), threads, false, |job| {
        run_job(&system, job, &cancel)
    })
    .unwrap();
    let wall = started.elapsed().as_secs_f64();
    assert!(reports.iter().all(|r| r.ok), "a run failed: {reports:?}");
    (wall, cpu_seconds() - cpu0)
}
