//! The master's library against the example FMUs `MassSpring` and `SpringDamperMass` from dist/
//! (the same through the `master` binary: crates/rail-study/tests/cli_runs.rs).
//! dist/ is built by the test command (scripts/test.sh) before `cargo test`; by hand:
//! `cargo run --release -p model-description --bin package-fmus`.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use std::path::{Path, PathBuf};

use master::coupling::{Algorithm, RunOptions};
use master::fmu::FmuArchive;
use master::slave::{Slave, VarBatch, VarRef};
use master::system::LoadedSystem;

fn dist() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../dist")
}

const P: (f64, f64, f64, f64, f64, f64, f64) = (
    1.0,   // m1
    100.0, // k1 (ms to ground)
    0.5,   // d1
    0.5,   // m2
    200.0, // kc coupling
    1.0,   // dc
    0.1,   // x1(0)
);

fn system_json(alg: &str, step: f64, stop: f64) -> String {
    let d = dist();
    format!(
        r#"{{
  "instances": [
    {{"name": "sdm", "fmu": "{}", "parameters": {{"mass": {m2}, "coupling_stiffness": {kc}, "coupling_damping": {dc}, "ground_stiffness": 0.0, "ground_damping": 0.0}}}},
    {{"name": "ms", "fmu": "{}", "parameters": {{"mass": {m1}, "stiffness": {k1}, "damping": {d1}, "initial_position": {x0}}}}}
  ],
  "connections": [
    {{"from": "ms.position", "to": "sdm.input_position"}},
    {{"from": "ms.velocity", "to": "sdm.input_velocity"}},
    {{"from": "sdm.coupling_force", "to": "ms.force"}}
  ],
  "stop_time": {stop}, "step": {step}, "algorithm": "{alg}"
}}"#,
        d.join("SpringDamperMass.fmu").display(),
        d.join("MassSpring.fmu").display(),
        m1 = P.0,
        k1 = P.1,
        d1 = P.2,
        m2 = P.3,
        kc = P.4,
        dc = P.5,
        x0 = P.6,
    )
}

/// Monolithic RK4 (step 1e-5) of the coupled system: (x1, x2) at `stop`.
fn reference(stop: f64) -> (f64, f64) {
    let (m1, k1, d1, m2, kc, dc, x0) = P;
    let f = |s: [f64; 4]| {
        let fc = kc * (s[2] - s[0]) + dc * (s[3] - s[1]);
        [s[1], (-k1 * s[0] - d1 * s[1] + fc) / m1, s[3], -fc / m2]
    };
    let mut s = [x0, 0.0, 0.0, 0.0];
    let n = (stop / 1e-5).round() as usize;
    let h = stop / n as f64;
    for _ in 0..n {
        let a = f(s);
        let b = f(std::array::from_fn(|i| s[i] + 0.5 * h * a[i]));
        let c = f(std::array::from_fn(|i| s[i] + 0.5 * h * b[i]));
        let d = f(std::array::from_fn(|i| s[i] + h * c[i]));
        s = std::array::from_fn(|i| s[i] + h / 6.0 * (a[i] + 2.0 * b[i] + 2.0 * c[i] + d[i]));
    }
    (s[0], s[2])
}

fn final_error(alg: &str, step: f64) -> f64 {
    let sys =
        LoadedSystem::from_json_str(&system_json(alg, step, 1.0), Path::new("/"), "test").unwrap();
    let out = sys.run(&RunOptions::default()).unwrap();
    let x1 = *out.column("ms.position").unwrap().last().unwrap();
    let x2 = *out.column("sdm.position").unwrap().last().unwrap();
    let (r1, r2) = reference(1.0);
    (x1 - r1).abs().max((x2 - r2).abs())
}

#[test]
fn gauss_seidel_order_is_derived_from_feedthrough() {
    let sys = LoadedSystem::from_json_str(
        &system_json("gauss-seidel", 1e-3, 1.0),
        Path::new("/"),
        "test",
    )
    .unwrap();
    let a = sys.open_fmus().unwrap();
    let plan = sys.plan(&[&a[0].model, &a[1].model]).unwrap();
    // sdm.coupling_force depends directly on sdm's inputs: ms (index 1) must step first
    assert_eq!(plan.order, vec![1, 0]);
    assert_eq!(plan.algorithm, Algorithm::GaussSeidel);
}

#[test]
fn coupled_fmus_converge_to_the_monolithic_solution_and_gs_beats_jacobi() {
    let j1 = final_error("jacobi", 2e-3);
    let j2 = final_error("jacobi", 1e-3);
    let g1 = final_error("gauss-seidel", 2e-3);
    let g2 = final_error("gauss-seidel", 1e-3);
    eprintln!("final error: Jacobi {j1:.3e} -> {j2:.3e}, Gauss-Seidel {g1:.3e} -> {g2:.3e}");
    // first-order coupling error: halving the step roughly halves it
    for (a, b) in [(j1, j2), (g1, g2)] {
        assert!(b < 0.7 * a && b > 0.3 * a, "{a} -> {b}");
    }
    assert!(g1 < j1 && g2 < j2);
    assert!(g2 < 5e-3);
}

#[test]
fn fmu_state_save_and_restore_round_trip() {
    let a = FmuArchive::open(&dist().join("MassSpring.fmu")).unwrap();
    let (_, pos) = a.model.variable("position").unwrap();
    let pos = VarBatch::new(vec![VarRef::real(pos.value_reference)]);
    let mut s = a.instantiate("ms", false).unwrap();
    s.setup_experiment(0.0, 1.0).unwrap();
    s.enter_initialization_mode().unwrap();
    s.exit_initialization_mode().unwrap();
    s.do_step(0.0, 0.01).unwrap();
    s.save_state().unwrap();
    s.do_step(0.01, 0.01).unwrap();
    let mut first = [0.0];
    s.get(&pos, &mut first).unwrap();
    s.restore_state().unwrap();
    s.do_step(0.01, 0.01).unwrap();
    let mut again = [0.0];
    s.get(&pos, &mut again).unwrap();
    assert_eq!(first, again);
    assert!(first[0] != 0.1, "the mass moved");
    s.terminate().unwrap();
}

/// The precompiled macro step of the common case (Gauss-Seidel, every instance stepping at
/// every point, no step retry) gives bit for bit the results of the general engine: the
/// coupled passive system (Bogie2Dof and two PassiveYawDamper FMUs) and the example FMUs
/// (whose coupling force feeds through).
#[test]
fn common_case_macro_step_equals_the_general_engine_bit_for_bit() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(repo.join("systems/passive.json")).unwrap())
            .unwrap();
    v["stop_time"] = serde_json::json!(1.0);
    let passive =
        LoadedSystem::from_json_str(&v.to_string(), &repo.join("systems"), "passive.json").unwrap();
    let examples = LoadedSystem::from_json_str(
        &system_json("gauss-seidel", 1e-3, 1.0),
        Path::new("/"),
        "test",
    )
    .unwrap();
    for (what, sys) in [("passive", passive), ("examples", examples)] {
        let fast = sys.run(&RunOptions::default()).unwrap();
        let general = sys
            .run(&RunOptions {
                general_engine: true,
                ..RunOptions::default()
            })
            .unwrap();
        assert_eq!(fast.header, general.header, "{what}");
        assert_eq!(fast.data.len(), general.data.len(), "{what}");
        assert!(fast.data.len() > 1000, "{what}");
        let differing = fast
            .data
            .iter()
            .zip(&general.data)
            .filter(|(a, b)| a.to_bits() != b.to_bits())
            .count();
        assert_eq!(differing, 0, "{what}: {differing} values differ");
    }
}
