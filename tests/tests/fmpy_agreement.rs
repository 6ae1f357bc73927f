//! fmpy's simulation of each packaged FMU (written by tests/fmpy/check_fmus.py, which the test
//! command runs first and points to with RAIL_FMPY_RESULTS) agrees with the same model driven
//! directly from Rust (same state machine, no FMI, no C ABI) to rounding.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use model_description::{rust_component, value_reference, FmuModel, InstanceContext, Status};

fn results_dir() -> Option<std::path::PathBuf> {
    match std::env::var_os("RAIL_FMPY_RESULTS") {
        Some(d) => Some(d.into()),
        None => {
            tests::missing_external(
                "RAIL_FMPY_RESULTS not set: run scripts/test.sh (it runs fmpy first)",
            );
            None
        }
    }
}

fn check<M: FmuModel>() {
    let Some(dir) = results_dir() else { return };
    let name = M::INFO.name;
    let path = dir.join(format!("{name}.csv"));
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e} (fmpy did not simulate {name})", path.display()));
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    let vrs: Vec<u32> = header[1..]
        .iter()
        .map(|n| value_reference::<M>(n).unwrap_or_else(|| panic!("{name}: no variable {n}")))
        .collect();

    let de = M::INFO.default_experiment;
    let (mut c, _log) = rust_component::<M>(InstanceContext::default()).unwrap();
    assert_eq!(
        c.setup_experiment(de.start_time, Some(de.stop_time)),
        Status::Ok
    );
    assert_eq!(c.enter_initialization_mode(), Status::Ok);
    assert!(c.exit_initialization_mode() <= Status::Warning);
    let mut out = vec![0.0; vrs.len()];
    let mut max_err: f64 = 0.0;
    for (k, row) in rows.iter().enumerate() {
        let t = de.start_time + k as f64 * de.step_size;
        assert!(
            (row[0] - t).abs() < 1e-9,
            "{name}: time grid differs at row {k}"
        );
        if k > 0 {
            let t_prev = de.start_time + (k - 1) as f64 * de.step_size;
            assert!(c.do_step(t_prev, t - t_prev) <= Status::Warning);
        }
        assert!(c.get_real(&vrs, &mut out) <= Status::Warning);
        for (j, (&a, &b)) in row[1..].iter().zip(&out).enumerate() {
            let err = (a - b).abs() / (1.0 + b.abs());
            max_err = max_err.max(err);
            assert!(
                err < 1e-12,
                "{name}: {} at t = {t}: fmpy {a} vs direct {b}",
                header[j + 1]
            );
        }
    }
    assert!(rows.len() > 10, "{name}: too few rows from fmpy");
    eprintln!(
        "{name}: {} rows agree, max relative difference {max_err:e}",
        rows.len()
    );
}

#[test]
fn mass_spring() {
    check::<fmu_examples::MassSpring>();
}

#[test]
fn spring_damper_mass() {
    check::<fmu_examples::SpringDamperMass>();
}

#[test]
fn semi_active_damper() {
    check::<fmu_damper::fmu::SemiActiveDamper>();
}

#[test]
fn passive_yaw_damper() {
    check::<fmu_damper::fmu::PassiveYawDamper>();
}

#[test]
fn full_active_actuator() {
    check::<fmu_damper::fmu::FullActiveActuator>();
}

#[test]
fn mppt_controller() {
    check::<fmu_controller::fmu::MpptController>();
}

#[test]
fn sky_hook_controller() {
    check::<fmu_controller::fmu::SkyHookController>();
}

#[test]
fn ideal_damper_force_controller() {
    check::<fmu_controller::fmu::IdealDamperForceController>();
}

#[test]
fn bogie_2dof() {
    check::<fmu_bogie2dof::fmu::Bogie2Dof>();
}

#[test]
fn rail_vehicle() {
    check::<fmu_vehicle::fmu::RailVehicle>();
}
