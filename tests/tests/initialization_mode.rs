//! Every FMU of the workspace, in Initialization Mode: the values a host reads after setting
//! parameters and inputs there are the ones the FMU has right after
//! fmi2ExitInitializationMode (a host that solves its initial coupling in that mode must not
//! see the start values of outputs the values set have changed).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use fmu_bogie2dof::fmu::Bogie2Dof;
use fmu_controller::fmu::{IdealDamperForceController, MpptController, SkyHookController};
use fmu_damper::fmu::{FullActiveActuator, PassiveYawDamper, SemiActiveDamper};
use fmu_examples::{MassSpring, SpringDamperMass};
use fmu_vehicle::fmu::RailVehicle;
use model_description::testing::{initialising, logged, set, vr};
use model_description::{Causality, Component, FmuModel, Status, VarType, Variability};

/// Every Real of `M` by value reference (0, 1, ... in declaration order).
fn read_all_reals<M: FmuModel>(c: &mut Component) -> (Status, Vec<f64>) {
    let n = M::variables()
        .iter()
        .filter(|v| v.meta.var_type == VarType::Real)
        .count();
    let vrs: Vec<u32> = (0..n as u32).collect();
    let mut values = vec![f64::NAN; n];
    let status = c.get_real(&vrs, &mut values);
    (status, values)
}

fn real_names<M: FmuModel>() -> Vec<String> {
    M::variables()
        .iter()
        .filter(|v| v.meta.var_type == VarType::Real)
        .map(|v| v.meta.name.clone())
        .collect()
}

/// A value of a Real input other than `start`, within its range.
fn moved(start: f64, min: Option<f64>, max: Option<f64>) -> f64 {
    let step = 0.25 * start.abs().max(1e-3);
    let up = start + step;
    if max.is_none_or(|hi| up <= hi) {
        up
    } else {
        (start - step).max(min.unwrap_or(f64::NEG_INFINITY))
    }
}

/// Sets `choices` (Enumeration parameters by item name) and `parameters` (Reals by name),
/// moves every Real input off its start, and compares every Real read in Initialization Mode
/// with the same Real of a twin instance set the same way that read nothing before its exit,
/// and the two instances over 50 steps, bit for bit. Returns the names of the outputs that the
/// values set changed (read before and after setting them, both in Initialization Mode).
fn initial_reads_match_exit<M: FmuModel>(
    choices: &[(&str, &str)],
    parameters: &[(&str, f64)],
) -> Vec<String> {
    let vars = M::variables();
    let names = real_names::<M>();
    let (mut c, log) = initialising::<M>();
    // the twin is set the same way and reads nothing before its exit
    let (mut twin, twin_log) = initialising::<M>();
    for (name, item) in choices {
        let (index, meta) = vars
            .iter()
            .enumerate()
            .find(|(_, v)| v.meta.name == *name)
            .map(|(i, v)| (i, &v.meta))
            .unwrap_or_else(|| panic!("{}: no variable {name}", M::INFO.name));
        let enumeration = meta.enumeration.expect("an Enumeration");
        let value = enumeration
            .items
            .iter()
            .find(|i| i.name == *item)
            .unwrap_or_else(|| panic!("{name}: no item {item}"))
            .value;
        let vr = vars[..index]
            .iter()
            .filter(|v| v.meta.var_type == VarType::Integer)
            .count() as u32;
        assert_eq!(c.set_integer(&[vr], &[value]), Status::Ok, "{name}");
        assert_eq!(twin.set_integer(&[vr], &[value]), Status::Ok, "{name}");
    }
    let (status, before) = read_all_reals::<M>(&mut c);
    assert_eq!(status, Status::Ok, "{}: {:?}", M::INFO.name, log.take());
    for (name, x) in parameters {
        assert_eq!(set::<M>(&mut c, name, *x), Status::Ok, "{name}");
        assert_eq!(set::<M>(&mut twin, name, *x), Status::Ok, "{name}");
    }
    let mut real_vr = 0u32;
    let mut inputs = 0;
    for v in &vars {
        if v.meta.var_type != VarType::Real {
            continue;
        }
        let vr = real_vr;
        real_vr += 1;
        if v.meta.causality != Causality::Input || v.meta.variability == Variability::Constant {
            continue;
        }
        let x = moved(before[vr as usize], v.meta.min, v.meta.max);
        assert_eq!(c.set_real(&[vr], &[x]), Status::Ok, "{}", v.meta.name);
        assert_eq!(twin.set_real(&[vr], &[x]), Status::Ok, "{}", v.meta.name);
        inputs += 1;
    }
    assert!(inputs > 0, "{} has no Real input", M::INFO.name);
    let (status, initial) = read_all_reals::<M>(&mut c);
    assert_eq!(status, Status::Ok, "{}: {:?}", M::INFO.name, log.take());
    assert!(
        c.exit_initialization_mode() <= Status::Warning,
        "{}: {:?}",
        M::INFO.name,
        log.take()
    );
    assert!(
        twin.exit_initialization_mode() <= Status::Warning,
        "{}: {:?}",
        M::INFO.name,
        twin_log.take()
    );
    let differing = |what: &str, a: &[f64], b: &[f64]| -> Vec<String> {
        names
            .iter()
            .zip(a.iter().zip(b))
            .filter(|(_, (x, y))| x.to_bits() != y.to_bits())
            .map(|(n, (x, y))| format!("{n}: {x:?} {what}, {y:?} in the twin"))
            .collect()
    };
    let (status, twin_after_exit) = read_all_reals::<M>(&mut twin);
    assert_eq!(status, Status::Ok);
    let d = differing("in Initialization Mode", &initial, &twin_after_exit);
    assert!(d.is_empty(), "{}: {d:#?}", M::INFO.name);
    // and the two run on bit for bit, whatever one of them read before its exit
    let h = 1e-3;
    let mut t = 0.0;
    for k in 0..50 {
        let (status, a) = read_all_reals::<M>(&mut c);
        assert_eq!(status, Status::Ok);
        let (status, b) = read_all_reals::<M>(&mut twin);
        assert_eq!(status, Status::Ok);
        let d = differing(&format!("after step {k}"), &a, &b);
        assert!(d.is_empty(), "{}: {d:#?}", M::INFO.name);
        assert!(c.do_step(t, h) <= Status::Warning, "{:?}", log.take());
        assert!(
            twin.do_step(t, h) <= Status::Warning,
            "{:?}",
            twin_log.take()
        );
        t += h;
    }
    let outputs: Vec<&str> = vars
        .iter()
        .filter(|v| v.meta.var_type == VarType::Real && v.meta.causality == Causality::Output)
        .map(|v| v.meta.name.as_str())
        .collect();
    names
        .iter()
        .zip(before.iter().zip(&initial))
        .filter(|(n, (a, b))| outputs.contains(&n.as_str()) && a.to_bits() != b.to_bits())
        .map(|(n, _)| n.clone())
        .collect()
}

/// `changed` holds every name of `expected`.
fn assert_changed(model: &str, changed: &[String], expected: &[&str]) {
    for name in expected {
        assert!(
            changed.iter().any(|c| c == name),
            "{model}: '{name}' did not follow the values set in Initialization Mode; changed: {changed:?}"
        );
    }
}

#[test]
fn bogie_track_and_wheelset_outputs_follow_the_external_track_input() {
    let changed = initial_reads_match_exit::<Bogie2Dof>(&[("track.source", "external")], &[]);
    assert_changed(
        "Bogie2Dof",
        &changed,
        &[
            "track.alignment_front",
            "wheelset_front.lateral_displacement_relative",
        ],
    );
}

#[test]
fn vehicle_track_outputs_follow_the_external_track_input() {
    let changed = initial_reads_match_exit::<RailVehicle>(&[("track.source", "external")], &[]);
    assert_changed(
        "RailVehicle",
        &changed,
        &["wheelset_1.track_alignment", "wheelset_1.guiding_force"],
    );
}

#[test]
fn damper_outputs_follow_their_inputs() {
    let changed = initial_reads_match_exit::<SemiActiveDamper>(&[], &[]);
    assert_changed("SemiActiveDamper", &changed, &["valve.opening"]);
    initial_reads_match_exit::<PassiveYawDamper>(&[], &[]);
    let changed = initial_reads_match_exit::<FullActiveActuator>(&[], &[]);
    assert!(!changed.is_empty(), "FullActiveActuator: no output changed");
}

#[test]
fn controller_outputs_follow_their_inputs() {
    initial_reads_match_exit::<MpptController>(&[], &[]);
    initial_reads_match_exit::<SkyHookController>(&[], &[]);
    initial_reads_match_exit::<IdealDamperForceController>(&[], &[]);
}

#[test]
fn example_outputs_follow_their_inputs_and_initial_values() {
    for model in [
        initial_reads_match_exit::<MassSpring>(&[], &[("initial_position", 0.2345)]),
        initial_reads_match_exit::<SpringDamperMass>(&[], &[("initial_position", 0.2345)]),
    ] {
        assert_changed("example", &model, &["position"]);
    }
}

#[test]
fn a_parameter_the_exit_refuses_gives_a_warning_naming_it_and_the_exit_refuses_it() {
    // vehicle.speed = 0 is within the declared range (min 0) but the bogie needs a speed
    let (mut c, log) = initialising::<Bogie2Dof>();
    assert_eq!(set::<Bogie2Dof>(&mut c, "vehicle.speed", 0.0), Status::Ok);
    let mut x = [f64::NAN];
    let status = c.get_real(&[vr::<Bogie2Dof>("track.lateral_alignment")], &mut x);
    assert_eq!(status, Status::Warning);
    let messages = log.take();
    assert!(
        logged(&messages, Status::Warning, "vehicle.speed")
            && logged(
                &messages,
                Status::Warning,
                "fmi2ExitInitializationMode refuses"
            ),
        "{messages:?}"
    );
    // every read warns while the value stands; a valid one reads without a warning
    assert_eq!(c.get_real(&[0], &mut x), Status::Warning);
    assert_eq!(set::<Bogie2Dof>(&mut c, "vehicle.speed", 50.0), Status::Ok);
    assert_eq!(c.get_real(&[0], &mut x), Status::Ok);
    assert_eq!(set::<Bogie2Dof>(&mut c, "vehicle.speed", 0.0), Status::Ok);
    assert_eq!(c.exit_initialization_mode(), Status::Error);
    assert!(logged(
        &log.take(),
        Status::Error,
        "fmi2ExitInitializationMode"
    ));
}
