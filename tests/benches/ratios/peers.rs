//! Our master against third-party C++ hosts (libcosim, Ecos) on the same SSP: the coupled
//! passive system exported by `master export-ssp`, run by each host from the archive.

use std::path::Path;
use std::time::Instant;

use master::coupling::RunOptions;
use master::ssp::{export, import, ImportOptions};
use master::system::{LoadedSystem, PreparedSystem};

use crate::{cpu_seconds, python_script, repo, reported, COUPLED_STOP_S, REPEATS, STEP_S};

/// The variable every host reports after the last step (to check that they ran the same).
pub const FINAL_VARIABLE: &str = "bogie.wheelset_front.lateral_displacement_relative";

/// One host's fastest run: wall and CPU time per simulated second, and [`FINAL_VARIABLE`].
#[derive(Debug, Clone, Copy)]
pub struct HostRun {
    pub wall_per_sim_s: f64,
    pub cpu_per_sim_s: f64,
    pub final_value: f64,
}

/// `systems/passive.json` for the SSP hosts: libcosim and Ecos cannot set FMI 2.0 Enumeration
/// parameters, so the bogie keeps its defaults (non-linear contact, track alignment from the
/// unconnected input: an ideal track) and starts from a 3 mm lateral displacement at 300 km/h;
/// Jacobi, as those hosts exchange; the passive system's record list.
fn peer_system() -> LoadedSystem {
    let path = repo().join("systems/passive.json");
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    v["instances"][0]["parameters"] = serde_json::json!({
        "vehicle.speed": 83.333_333_333_333_33,
        "initial.lateral_displacement": 0.003,
    });
    v["algorithm"] = serde_json::json!("jacobi");
    v["stop_time"] = serde_json::json!(COUPLED_STOP_S);
    LoadedSystem::from_json_str(&v.to_string(), &repo().join("systems"), "peer.json").unwrap()
}

/// Our master on the SSP (imported as the `master run x.ssp` command does); loading is not
/// timed, as the hosts' is not.
fn ours(ssp: &Path) -> HostRun {
    let imported = import(ssp, &ImportOptions::default()).unwrap();
    let system = PreparedSystem::prepare(&imported.system).unwrap();
    let changes = system
        .changes(&std::collections::BTreeMap::new(), None, "peers")
        .unwrap();
    let mut best: Option<HostRun> = None;
    for _ in 0..REPEATS {
        let (started, cpu0) = (Instant::now(), cpu_seconds());
        let out = system.run(&changes, &RunOptions::default()).unwrap();
        let (wall, cpu) = (started.elapsed().as_secs_f64(), cpu_seconds() - cpu0);
        let column = out.column(FINAL_VARIABLE).unwrap();
        let run = HostRun {
            wall_per_sim_s: wall / COUPLED_STOP_S,
            cpu_per_sim_s: cpu / COUPLED_STOP_S,
            final_value: column[column.len() - 1],
        };
        if best.is_none_or(|b| run.wall_per_sim_s < b.wall_per_sim_s) {
            best = Some(run);
        }
    }
    best.unwrap()
}

/// A third-party host through `tests/ssp/bench_hosts.py`, or why it was not measured.
fn host(name: &str, ssp: &Path) -> Result<HostRun, String> {
    let (stop, step) = (COUPLED_STOP_S.to_string(), STEP_S.to_string());
    let text = python_script(
        "tests/ssp/bench_hosts.py",
        &[
            name.as_ref(),
            ssp.as_os_str(),
            stop.as_ref(),
            step.as_ref(),
            "3".as_ref(),
            FINAL_VARIABLE.as_ref(),
        ],
    )?;
    Ok(HostRun {
        wall_per_sim_s: reported(&text, "wall_per_sim_s")?,
        cpu_per_sim_s: reported(&text, "cpu_per_sim_s")?,
        final_value: reported(&text, "final")?,
    })
}

/// Our master, libcosim and Ecos on one exported SSP: (host, run or why not measured).
pub fn peers() -> Vec<(&'static str, Result<HostRun, String>)> {
    let dir = tempfile::tempdir().unwrap();
    let ssp = dir.path().join("passive.ssp");
    export(&peer_system(), &ssp).unwrap();
    vec![
        ("our master", Ok(ours(&ssp))),
        ("libcosim (libcosimpy)", host("libcosim", &ssp)),
        ("Ecos (ecospy)", host("ecos", &ssp)),
    ]
}
