//! The Bogie2Dof FMU driven through the glue's state machine (same checks as the C API).

#![allow(clippy::unwrap_used, clippy::panic)] // test helpers outside #[test] fns

use fmu_bogie2dof::fmu::{Bogie2Dof, FMU_DEFAULT_INITIAL_LATERAL_M, FMU_DEFAULT_SPEED_MPS};
use fmu_bogie2dof::{Bogie, Inputs, Params, PsdLevel, TrackSource};
use model_description::testing::{get, initialising, logged, real_outputs, set, vr};
use model_description::{rust_component, Causality, FmuModel, InstanceContext, Status};

type M = Bogie2Dof;

#[test]
fn default_experiment_is_finite_and_hunts() {
    let e = M::INFO.default_experiment;
    let (mut c, log) = rust_component::<M>(InstanceContext::default()).unwrap();
    assert_eq!(
        c.setup_experiment(e.start_time, Some(e.stop_time)),
        Status::Ok
    );
    assert_eq!(c.enter_initialization_mode(), Status::Ok);
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    let names = real_outputs::<M>();
    let n = ((e.stop_time - e.start_time) / e.step_size).round() as usize;
    let mut t = e.start_time;
    let mut peak: f64 = 0.0;
    for k in 0..n {
        let target = e.start_time + (k + 1) as f64 * e.step_size;
        assert_eq!(c.do_step(t, target - t), Status::Ok, "{:?}", log.take());
        t = target;
        for name in &names {
            let x = get::<M>(&mut c, name);
            assert!(x.is_finite(), "{name} = {x} at t = {t}");
        }
        if t > 2.0 {
            peak = peak.max(get::<M>(&mut c, "wheelset_front.lateral_displacement").abs());
        }
    }
    assert!(log.take().is_empty());
    // something to see: hunting into flange contact without yaw dampers
    println!(
        "default experiment: peak front wheelset {:.2} mm",
        peak * 1e3
    );
    assert!(peak > 5e-3 && peak < 8e-3, "{peak}");
}

/// Same parameters, same inputs -> the FMU outputs equal the physics bit for bit.
#[test]
fn fmu_equals_plain_physics_bit_for_bit() {
    let (mut c, log) = initialising::<M>();
    assert_eq!(set::<M>(&mut c, "vehicle.speed", 280.0 / 3.6), Status::Ok);
    assert_eq!(
        c.set_integer(&[vr::<M>("track.source")], &[2]),
        Status::Ok,
        "{:?}",
        log.take()
    );
    assert_eq!(c.set_integer(&[vr::<M>("track.level")], &[1]), Status::Ok);
    assert_eq!(c.set_integer(&[vr::<M>("track.seed")], &[7]), Status::Ok);
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    let p = Params {
        speed_mps: 280.0 / 3.6,
        initial_lateral_m: FMU_DEFAULT_INITIAL_LATERAL_M,
        track: TrackSource::Internal {
            level: PsdLevel::High,
            seed: 7,
        },
        ..Params::default()
    };
    let mut b = Bogie::new(p).unwrap();
    let h = 2e-3;
    let mut t = 0.0;
    for k in 0..500 {
        // a damper force that changes every step
        let f = 3e3 * ((k as f64) * 0.05).sin();
        let i = Inputs {
            damper_left_force_n: f,
            damper_right_force_n: -0.5 * f,
            track_lateral_m: 0.0,
        };
        assert_eq!(
            c.set_real(
                &[vr::<M>("damper_left.force"), vr::<M>("damper_right.force")],
                &[i.damper_left_force_n, i.damper_right_force_n]
            ),
            Status::Ok
        );
        assert_eq!(c.do_step(t, h), Status::Ok);
        // the glue steps from its own time to t + h: the same effective step here
        let o = b.step((t + h) - t, &i).unwrap();
        t += h;
        let pairs = [
            ("damper_left.elongation", o.damper_left_elongation_m),
            (
                "damper_right.elongation_velocity",
                o.damper_right_velocity_mps,
            ),
            ("frame.lateral_acceleration_front", o.frame_acc_front_mps2),
            ("frame.lateral_acceleration_rear", o.frame_acc_rear_mps2),
            ("wheelset_rear.guiding_force", o.guiding_force_rear_n),
            (
                "wheelset_front.lateral_displacement_relative",
                o.wheelset_front_rel_track_m,
            ),
            ("bogie.yaw_angle", o.yaw_rad),
            (
                "damper_left.end_absolute_acceleration",
                1.35 * o.yaw_acc_radps2,
            ),
            ("track.alignment_rear", o.track_rear_m),
        ];
        for (name, x) in pairs {
            assert_eq!(
                get::<M>(&mut c, name).to_bits(),
                x.to_bits(),
                "{name} step {k}"
            );
        }
    }
}

/// A parameter that passes its range but leaves the dynamics faster than any step can follow
/// (a bogie of 1e-300 kg) is refused at initialisation, naming it and saying why.
#[test]
fn parameters_too_stiff_to_integrate_are_refused() {
    let (mut c, log) = initialising::<M>();
    assert_eq!(set::<M>(&mut c, "inertia.mass", 1e-300), Status::Ok);
    assert_eq!(c.exit_initialization_mode(), Status::Error);
    let l = log.take();
    assert!(logged(&l, Status::Error, "'inertia.mass'"), "{l:?}");
    assert!(logged(&l, Status::Error, "internal steps of"), "{l:?}");
}

/// A new wheel load alone leaves the load-dependent creep coefficients and gravitational
/// stiffness at their 70 kN values: the exit says so (fmi2Warning), and is silent when they are
/// set too.
#[test]
fn a_new_wheel_load_alone_warns_that_its_dependent_parameters_stay() {
    // the exit's status and messages with these start values
    let exit_with = |values: &[(&str, f64)]| {
        let (mut c, log) = initialising::<M>();
        for &(name, x) in values {
            assert_eq!(set::<M>(&mut c, name, x), Status::Ok, "{name}");
        }
        (c.exit_initialization_mode(), log.take())
    };
    let (status, l) = exit_with(&[("wheelset.wheel_load", 50e3)]);
    assert_eq!(status, Status::Warning);
    assert!(
        logged(
            &l,
            Status::Warning,
            "'wheelset.wheel_load' = 50 kN, but 'creep.f11', 'creep.f22', \
             'linear.gravitational_stiffness' keep the values given for 70 kN"
        ),
        "{l:?}"
    );
    // one of them set: the others are named
    let (status, l) = exit_with(&[("wheelset.wheel_load", 50e3), ("creep.f11", 9.2e6)]);
    assert_eq!(status, Status::Warning);
    assert!(
        logged(
            &l,
            Status::Warning,
            "but 'creep.f22', 'linear.gravitational_stiffness' keep"
        ),
        "{l:?}"
    );
    // all three set: silent
    let (status, l) = exit_with(&[
        ("wheelset.wheel_load", 50e3),
        ("creep.f11", 9.2e6),
        ("creep.f22", 8.3e6),
        ("linear.gravitational_stiffness", 1.4e6),
    ]);
    assert_eq!(status, Status::Ok);
    assert!(l.is_empty());
}

/// Negative values are rejected when set (declared min); zero, speed and friction at
/// fmi2ExitInitializationMode by the physics' validation; the FMI variable is named.
#[test]
fn bad_parameters_are_rejected_by_name() {
    fn at_init(name: &str, x: f64) {
        let (mut c, log) = initialising::<M>();
        assert_eq!(set::<M>(&mut c, name, x), Status::Ok, "{name} = {x}");
        assert_eq!(c.exit_initialization_mode(), Status::Error, "{name} = {x}");
        let msgs = log.take();
        assert!(
            logged(&msgs, Status::Error, &format!("'{name}'")),
            "{name}: {msgs:?}"
        );
    }
    fn at_set(name: &str, x: f64) {
        let (mut c, log) = initialising::<M>();
        assert_eq!(set::<M>(&mut c, name, x), Status::Error, "{name} = {x}");
        let msgs = log.take();
        assert!(
            logged(&msgs, Status::Error, &format!("'{name}'")),
            "{name}: {msgs:?}"
        );
        assert_eq!(c.exit_initialization_mode(), Status::Ok);
    }
    for name in [
        "inertia.mass",
        "inertia.yaw",
        "suspension.lateral_stiffness",
        "suspension.longitudinal_stiffness",
        "creep.f11",
        "wheelset.wheel_load",
    ] {
        at_set(name, -1.0);
    }
    for name in [
        "inertia.mass",
        "inertia.yaw",
        "creep.f22",
        "creep.reduction_factor",
        "wheelset.wheel_load",
        "vehicle.speed",
        "contact.friction_coefficient",
    ] {
        at_init(name, 0.0);
    }
    at_set("contact.friction_coefficient", 1.2);
    at_set("vehicle.speed", -10.0);
    at_set("inertia.mass", f64::NAN);
    // a contact table that does not exist
    let (mut c, log) = initialising::<M>();
    assert_eq!(
        c.set_string(&[vr::<M>("contact.table")], &["/nonexistent/table.csv"]),
        Status::Ok
    );
    assert_eq!(c.exit_initialization_mode(), Status::Error);
    assert!(logged(&log.take(), Status::Error, "'contact.table'"));
    // an out-of-range choice
    let (mut c, log) = initialising::<M>();
    assert_eq!(
        c.set_integer(&[vr::<M>("contact.model")], &[2]),
        Status::Error
    );
    assert!(logged(
        &log.take(),
        Status::Error,
        "'contact.model' = 2 is not an item of the enumeration WheelRailForceLaw"
    ));
}

/// Accelerations change at once when the damper forces are set (declared feedthrough);
/// elongations do not (from the states; declared without feedthrough).
#[test]
fn outputs_without_stepping_feedthrough_is_real() {
    let (mut c, _log) = initialising::<M>();
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    let names = [
        "frame.lateral_acceleration_front",
        "frame.lateral_acceleration_rear",
        "wheelset_front.lateral_acceleration",
        "damper_left.end_absolute_acceleration",
        "damper_right.end_absolute_acceleration",
        "damper_left.elongation",
        "damper_right.elongation_velocity",
        "bogie.yaw_angle",
    ];
    let before: Vec<f64> = names.iter().map(|n| get::<M>(&mut c, n)).collect();
    assert_eq!(set::<M>(&mut c, "damper_left.force", 10e3), Status::Ok);
    let after: Vec<f64> = names.iter().map(|n| get::<M>(&mut c, n)).collect();
    let p = Params::default();
    // left tension -> moment -b F_L -> sigma'' = -b F/J
    let sdd = -p.damper_arm_m * 10e3 / p.bogie_yaw_inertia_kgm2;
    let d = |k: usize| after[k] - before[k];
    assert!((d(0) - (-p.half_wheelbase_m * sdd)).abs() < 1e-9);
    assert!((d(1) - (p.half_wheelbase_m * sdd)).abs() < 1e-9);
    assert!((d(2) - d(0)).abs() < 1e-12);
    assert!((d(3) - p.damper_arm_m * sdd).abs() < 1e-9);
    assert!((d(4) + p.damper_arm_m * sdd).abs() < 1e-9);
    for k in 5..names.len() {
        assert_eq!(before[k].to_bits(), after[k].to_bits(), "{}", names[k]);
    }
    // initial elongation from the start values: e_L = b sigma0 = 0, y0 = 3 mm
    assert_eq!(get::<M>(&mut c, "bogie.lateral_displacement"), 3e-3);
    // the declared feedthrough matches
    for v in M::variables() {
        if v.meta.causality == Causality::Output {
            let has = v.meta.feedthrough.contains(&"damper_left.force");
            let expect = v.meta.name.contains("acceleration");
            assert_eq!(has, expect, "{}", v.meta.name);
        }
    }
}

#[test]
fn start_values_and_contact_tables() {
    let (mut c, _log) = initialising::<M>();
    assert_eq!(get::<M>(&mut c, "vehicle.speed"), FMU_DEFAULT_SPEED_MPS);
    let mut model = [0];
    assert_eq!(
        c.get_integer(&[vr::<M>("contact.model")], &mut model),
        Status::Ok
    );
    assert_eq!(model[0], 1);
    // the A/A table shipped in resources/ is found by its name
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("resources");
    let ctx = InstanceContext {
        instance_name: "b".into(),
        resource_dir: Some(dir),
    };
    let run = |table: &str| -> f64 {
        let (mut c, log) = rust_component::<M>(ctx.clone()).unwrap();
        assert_eq!(c.setup_experiment(0.0, None), Status::Ok);
        assert_eq!(c.enter_initialization_mode(), Status::Ok);
        assert_eq!(
            c.set_string(&[vr::<M>("contact.table")], &[table]),
            Status::Ok
        );
        assert_eq!(
            c.exit_initialization_mode(),
            Status::Ok,
            "{table}: {:?}",
            log.take()
        );
        for k in 0..200 {
            assert_eq!(c.do_step(k as f64 * 1e-3, 1e-3), Status::Ok);
        }
        get::<M>(&mut c, "wheelset_front.guiding_force")
    };
    let aa_file = run("wheel_rail_A_A.csv");
    let aa_kw = run("AA");
    assert_eq!(aa_file.to_bits(), aa_kw.to_bits());
    let worn_file = run("wheel_rail_worn_surrogate.csv");
    let worn = run("");
    assert!((worn_file - worn).abs() <= 1e-6 * worn.abs().max(1.0));
    assert!((worn - aa_kw).abs() > 1.0);
}

/// A restored state whose internal sub-step was forged (checksum resealed) cannot make a step
/// run for ever: a sub-step below the shortest any parameter set builds is reported as a
/// corrupted state (fmi2Error), and one that would take more sub-steps than a call computes
/// discards the step (the state unchanged).
#[test]
fn a_forged_internal_sub_step_is_refused_at_the_step() {
    let substep = Bogie::new(Params::default()).unwrap().substep_s();
    let forged = |value: f64| {
        let (mut c, log) = initialising::<M>();
        assert_eq!(c.exit_initialization_mode(), Status::Ok);
        let state = c.get_fmu_state().unwrap();
        let mut bytes = c.serialize_fmu_state(&state).unwrap();
        let at: Vec<usize> = bytes
            .windows(8)
            .enumerate()
            .filter(|(_, w)| *w == substep.to_le_bytes())
            .map(|(k, _)| k)
            .collect();
        assert_eq!(at.len(), 1, "the sub-step {substep} s once in the state");
        bytes[at[0]..at[0] + 8].copy_from_slice(&value.to_le_bytes());
        model_description::testing::reseal_state(&mut bytes);
        let restored = c
            .deserialize_fmu_state(&bytes)
            .unwrap_or_else(|_| panic!("{value}: {:?}", log.take()));
        assert_eq!(c.set_fmu_state(&restored), Status::Ok);
        log.take();
        (c, log)
    };
    // (a NaN is refused when the state is read)
    for corrupted in [1e-12, 0.0, -1e-3] {
        let (mut c, log) = forged(corrupted);
        assert_eq!(c.do_step(0.0, 1e-3), Status::Error, "{corrupted}");
        assert!(
            logged(&log.take(), Status::Error, "corrupted FMU state"),
            "{corrupted}"
        );
    }
    // 2e-7 s is above the shortest sub-step: a 1 ms step runs, a 10 s one is discarded at once
    let (mut c, log) = forged(2e-7);
    assert_eq!(c.do_step(0.0, 1e-3), Status::Ok);
    let before = get::<M>(&mut c, "wheelset_front.lateral_displacement");
    assert_eq!(c.do_step(1e-3, 10.0), Status::Discard);
    assert!(
        logged(
            &log.take(),
            Status::Discard,
            "take shorter communication steps"
        ),
        "discard reason"
    );
    assert_eq!(
        get::<M>(&mut c, "wheelset_front.lateral_displacement").to_bits(),
        before.to_bits()
    );
}
