//! The three controller FMUs through the glue's Rust-side component (same state machine and
//! checks as the C API): default experiments, agreement with the plain physics, parameter
//! validation at initialisation, step-size independence, no direct feedthrough, logging.

// Test-only helpers below are not #[test] fns, so the workspace lint allowance does not reach them.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::f64::consts::PI;

use fmu_controller::fmu::{IdealDamperForceController, MpptController, SkyHookController};
use fmu_controller::{
    Idf, IdfInputs, IdfParams, Mppt, MpptInputs, MpptParams, SkyHook, SkyHookInputs, SkyHookMode,
    SkyHookParams,
};
use model_description::{
    rust_component, value_reference, Causality, CollectLog, Component, FmiState, FmuModel,
    InstanceContext, Status, VarType,
};

fn vr<M: FmuModel>(name: &str) -> u32 {
    value_reference::<M>(name).unwrap_or_else(|| panic!("no variable {name}"))
}

/// Instantiated, experiment set up, in initialization mode.
fn init<M: FmuModel>() -> (Component, CollectLog) {
    let (mut c, log) = rust_component::<M>(InstanceContext::default()).unwrap();
    assert_eq!(c.setup_experiment(0.0, None), Status::Ok);
    assert_eq!(c.enter_initialization_mode(), Status::Ok);
    (c, log)
}

fn set_r<M: FmuModel>(c: &mut Component, name: &str, x: f64) -> Status {
    c.set_real(&[vr::<M>(name)], &[x])
}

fn set_i<M: FmuModel>(c: &mut Component, name: &str, x: i32) -> Status {
    c.set_integer(&[vr::<M>(name)], &[x])
}

fn get_r<M: FmuModel>(c: &mut Component, name: &str) -> f64 {
    let mut v = [f64::NAN];
    assert!(c.get_real(&[vr::<M>(name)], &mut v) <= Status::Warning);
    v[0]
}

fn get_i<M: FmuModel>(c: &mut Component, name: &str) -> i32 {
    let mut v = [0];
    assert!(c.get_integer(&[vr::<M>(name)], &mut v) <= Status::Warning);
    v[0]
}

fn get_b<M: FmuModel>(c: &mut Component, name: &str) -> bool {
    let mut v = [false];
    assert!(c.get_boolean(&[vr::<M>(name)], &mut v) <= Status::Warning);
    v[0]
}

/// Names of the Real outputs of M.
fn real_outputs<M: FmuModel>() -> Vec<String> {
    M::variables()
        .iter()
        .filter(|v| v.meta.causality == Causality::Output && v.meta.var_type == VarType::Real)
        .map(|v| v.meta.name.clone())
        .collect()
}

fn all_real_outputs<M: FmuModel>(c: &mut Component) -> Vec<f64> {
    let names = real_outputs::<M>();
    let vrs: Vec<u32> = names.iter().map(|n| vr::<M>(n)).collect();
    let mut out = vec![f64::NAN; vrs.len()];
    assert!(c.get_real(&vrs, &mut out) <= Status::Warning);
    out
}

fn run_default_experiment<M: FmuModel>() -> Component {
    let (mut c, log) = init::<M>();
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    let de = M::INFO.default_experiment;
    let n = ((de.stop_time - de.start_time) / de.step_size).round() as usize;
    assert!(n > 100);
    for k in 0..n {
        let t = de.start_time + k as f64 * de.step_size;
        assert_eq!(
            c.do_step(t, de.step_size),
            Status::Ok,
            "{} step {k}",
            M::INFO.name
        );
        for (name, x) in real_outputs::<M>()
            .iter()
            .zip(all_real_outputs::<M>(&mut c))
        {
            assert!(x.is_finite(), "{}: {name} = {x}", M::INFO.name);
        }
    }
    assert!((c.time() - de.stop_time).abs() < 1e-9);
    assert!(log
        .take()
        .iter()
        .all(|(s, _, _)| *s != Status::Error && *s != Status::Warning));
    c
}

#[test]
fn default_experiments_run_with_finite_outputs() {
    let mut c = run_default_experiment::<MpptController>();
    // 10 s with a 1 s period: ten updates; with zero inputs J = 0 and the valve stays closed.
    assert_eq!(get_i::<MpptController>(&mut c, "hill_climb.updates"), 10);
    assert_eq!(get_r::<MpptController>(&mut c, "valve.command"), 0.0);
    let mut c = run_default_experiment::<SkyHookController>();
    // zero inputs: condition 0 counts as "on" -> c_max -> closed valve
    assert!(get_b::<SkyHookController>(&mut c, "control.on_state"));
    assert_eq!(get_r::<SkyHookController>(&mut c, "valve.command"), 0.0);
    let mut c = run_default_experiment::<IdealDamperForceController>();
    assert_eq!(
        get_r::<IdealDamperForceController>(&mut c, "spool.command"),
        0.0
    );
}

// ---------------------------------------------------------------------------------------------
// FMU vs plain physics, same input sequence, bitwise identical outputs.

fn mppt_drive(t: f64) -> (f64, f64) {
    // rises above the (3.5) threshold after 4 s, so the override path is exercised too
    let amp = if t < 4.0 { 3.0 } else { 9.0 };
    (
        amp * (2.0 * PI * 3.7 * t).sin() + 0.3 * (2.0 * PI * 11.0 * t).sin(),
        4e3 * amp * (2.0 * PI * 3.7 * t + 1.0).cos(),
    )
}

#[test]
fn mppt_fmu_equals_physics() {
    type M = MpptController;
    let (mut c, _log) = init::<M>();
    // MPPT1 preset from a half-open valve
    assert_eq!(set_r::<M>(&mut c, "cost.force_weight", 0.0), Status::Ok);
    assert_eq!(set_r::<M>(&mut c, "valve.initial_command", 5.0), Status::Ok);
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    let mut p = Mppt::new(MpptParams {
        initial_command_v: 5.0,
        ..MpptParams::mppt1()
    })
    .unwrap();
    let h = 1e-3;
    let (ua, uf) = (
        vr::<M>("bogie.lateral_acceleration"),
        vr::<M>("damper.force"),
    );
    let mut moved = false;
    for k in 0..8000 {
        let t = k as f64 * h;
        let (a, f) = mppt_drive(t);
        assert_eq!(c.set_real(&[ua, uf], &[a, f]), Status::Ok);
        assert!(c.do_step(t, h) <= Status::Warning);
        let o = p
            .step(
                h,
                &MpptInputs {
                    bogie_accel_mps2: a,
                    damper_force_n: f,
                },
            )
            .unwrap();
        assert_eq!(get_r::<M>(&mut c, "valve.command"), o.command_v, "t={t}");
        assert_eq!(get_r::<M>(&mut c, "valve.opening"), o.opening);
        assert_eq!(get_r::<M>(&mut c, "cost.value"), o.cost);
        assert_eq!(
            get_r::<M>(&mut c, "cost.rms_acceleration"),
            o.rms_accel_mps2
        );
        assert_eq!(get_r::<M>(&mut c, "cost.rms_force"), o.rms_force_n);
        assert_eq!(
            get_r::<M>(&mut c, "band_pass.acceleration"),
            o.filtered_accel_mps2
        );
        assert_eq!(
            f64::from(get_i::<M>(&mut c, "hill_climb.direction")),
            o.direction,
            "t={t}"
        );
        assert_eq!(get_b::<M>(&mut c, "override.active"), o.override_active);
        assert_eq!(get_i::<M>(&mut c, "hill_climb.updates") as u64, o.updates);
        assert!(!get_b::<M>(&mut c, "board.input_fault"));
        moved |= o.command_v != 5.0;
    }
    assert!(moved, "the drive should move the valve");
    assert!(p.outputs().override_active, "override expected after 4 s");
}

fn skyhook_drive(t: f64) -> (f64, f64, f64) {
    let w = 2.0 * PI * 3.5;
    (
        -2e-3 * w * w * (w * t).sin() + 0.5 * (2.0 * PI * 9.0 * t).sin(),
        1.1e-3 * w * (w * t + 0.2).cos(),
        1e-3 * w * (w * t + 0.4).cos(),
    )
}

#[test]
fn skyhook_fmu_equals_physics() {
    type M = SkyHookController;
    for (mode, source) in [(0, 0), (1, 0), (1, 1)] {
        let (mut c, _log) = init::<M>();
        assert_eq!(set_i::<M>(&mut c, "control.mode", mode), Status::Ok);
        assert_eq!(
            set_i::<M>(&mut c, "sensor.velocity_source", source),
            Status::Ok
        );
        assert_eq!(set_r::<M>(&mut c, "damping.sky_hook", 200e3), Status::Ok);
        assert_eq!(c.exit_initialization_mode(), Status::Ok);
        let mut p = SkyHook::new(SkyHookParams {
            mode: if mode == 1 {
                SkyHookMode::Continuous
            } else {
                SkyHookMode::OnOff
            },
            velocity_source: if source == 1 {
                fmu_controller::VelocitySource::Ideal
            } else {
                fmu_controller::VelocitySource::EstimatedFromAcceleration
            },
            c_sky_nspm: 200e3,
            ..Default::default()
        })
        .unwrap();
        let ins = [
            vr::<M>("sensor.acceleration"),
            vr::<M>("sensor.velocity"),
            vr::<M>("damper.elongation_velocity"),
        ];
        let h = 1e-3;
        let (mut n_on, mut n_off) = (0, 0);
        for k in 0..3000 {
            let t = k as f64 * h;
            let (a, xa, ve) = skyhook_drive(t);
            assert_eq!(c.set_real(&ins, &[a, xa, ve]), Status::Ok);
            assert!(c.do_step(t, h) <= Status::Warning);
            let o = p
                .step(
                    h,
                    &SkyHookInputs {
                        sensor_accel_mps2: a,
                        abs_velocity_mps: xa,
                        elongation_velocity_mps: ve,
                    },
                )
                .unwrap();
            assert_eq!(get_r::<M>(&mut c, "valve.command"), o.command_v);
            assert_eq!(get_r::<M>(&mut c, "valve.opening"), o.opening);
            assert_eq!(get_r::<M>(&mut c, "damping.desired"), o.c_desired_nspm);
            assert_eq!(get_r::<M>(&mut c, "control.condition"), o.condition);
            assert_eq!(
                get_r::<M>(&mut c, "sensor.absolute_velocity"),
                o.abs_velocity_mps
            );
            assert_eq!(get_b::<M>(&mut c, "control.on_state"), o.on_state);
            if o.on_state {
                n_on += 1;
            } else {
                n_off += 1;
            }
        }
        assert!(
            n_on > 100 && n_off > 100,
            "law should switch: {n_on} {n_off}"
        );
    }
}

#[test]
fn idf_fmu_equals_physics() {
    type M = IdealDamperForceController;
    let (mut c, _log) = init::<M>();
    assert_eq!(
        set_i::<M>(&mut c, "force_loop.command_sign", -1),
        Status::Ok
    );
    assert_eq!(set_r::<M>(&mut c, "force_loop.gain", 2e-7), Status::Ok);
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    let mut p = Idf::new(IdfParams {
        command_sign: -1.0,
        k_p_m_per_n: 2e-7,
        ..Default::default()
    })
    .unwrap();
    let ins = [
        vr::<M>("damper.elongation_velocity"),
        vr::<M>("damper.force"),
    ];
    let h = 1e-3;
    let mut saturated = 0;
    for k in 0..2000 {
        let t = k as f64 * h;
        let v = 0.05 * (2.0 * PI * 4.0 * t).cos();
        let f = 12e3 * (2.0 * PI * 4.0 * t + 0.5).sin();
        assert_eq!(c.set_real(&ins, &[v, f]), Status::Ok);
        assert!(c.do_step(t, h) <= Status::Warning);
        let o = p
            .step(
                h,
                &IdfInputs {
                    elongation_velocity_mps: v,
                    measured_force_n: f,
                },
            )
            .unwrap();
        assert_eq!(get_r::<M>(&mut c, "spool.command"), o.spool_command_m);
        assert_eq!(get_r::<M>(&mut c, "reference.force"), o.force_ref_n);
        assert_eq!(get_r::<M>(&mut c, "force_loop.error"), o.force_error_n);
        assert_eq!(get_b::<M>(&mut c, "spool.command_saturated"), o.saturated);
        saturated += usize::from(o.saturated);
    }
    assert!(saturated > 0 && saturated < 2000);
}

// ---------------------------------------------------------------------------------------------
// Parameter validation: rejected at fmi2ExitInitializationMode naming the FMI variable
// (values outside a declared range are already rejected when set).

fn assert_exit_rejects<M: FmuModel>(setup: impl FnOnce(&mut Component), name: &str) {
    let (mut c, log) = init::<M>();
    setup(&mut c);
    let _ = log.take();
    assert_eq!(c.exit_initialization_mode(), Status::Error, "{name}");
    assert_eq!(c.state(), FmiState::InitializationMode);
    let msgs = log.take();
    let needle = format!("'{name}'");
    assert!(
        msgs.iter().any(|(s, cat, m)| *s == Status::Error
            && cat == "logStatusError"
            && m.contains(&needle)),
        "{} {name}: {msgs:?}",
        M::INFO.name
    );
}

fn assert_set_rejects(status: Status, log: &CollectLog, name: &str) {
    assert_eq!(status, Status::Error, "{name}");
    let msgs = log.take();
    assert!(
        msgs.iter()
            .any(|(s, _, m)| *s == Status::Error && m.contains(&format!("'{name}'"))),
        "{name}: {msgs:?}"
    );
}

#[test]
fn invalid_parameters_are_rejected_with_their_name() {
    type M = MpptController;
    // negative period: outside the declared range, rejected when set
    let (mut c, log) = init::<M>();
    assert_set_rejects(
        set_r::<M>(&mut c, "hill_climb.period", -1.0),
        &log,
        "hill_climb.period",
    );
    // choices are Enumerations: an order or a sign that is no item is refused when set
    for (name, bad, item) in [
        (
            "band_pass.order",
            3,
            "BandPassOrder (2 = second, 4 = fourth)",
        ),
        (
            "hill_climb.initial_direction",
            0,
            "Sign (-1 = minus, 1 = plus)",
        ),
    ] {
        assert_set_rejects(set_i::<M>(&mut c, name, bad), &log, name);
        assert_eq!(set_i::<M>(&mut c, name, bad), Status::Error);
        let msgs = log.take();
        assert!(
            msgs.iter().any(
                |(_, _, m)| m.contains("is not an item of the enumeration") && m.contains(item)
            ),
            "{name}: {msgs:?}"
        );
    }
    assert_eq!(set_i::<M>(&mut c, "band_pass.order", 2), Status::Ok);
    assert_eq!(get_i::<M>(&mut c, "band_pass.order"), 2);
    assert_eq!(
        set_i::<M>(&mut c, "hill_climb.initial_direction", -1),
        Status::Ok
    );
    assert_eq!(get_i::<M>(&mut c, "hill_climb.initial_direction"), -1);
    // zero period / not a multiple of the sample time: rejected at initialisation
    assert_exit_rejects::<M>(
        |c| assert_eq!(set_r::<M>(c, "hill_climb.period", 0.0), Status::Ok),
        "hill_climb.period",
    );
    assert_exit_rejects::<M>(
        |c| assert_eq!(set_r::<M>(c, "hill_climb.period", 1.0005), Status::Ok),
        "hill_climb.period",
    );
    assert_exit_rejects::<M>(
        |c| assert_eq!(set_r::<M>(c, "band_pass.high", 1.0), Status::Ok),
        "band_pass.high",
    );
    assert_exit_rejects::<M>(
        |c| {
            assert_eq!(set_r::<M>(c, "valve.command_max", 5.0), Status::Ok);
            assert_eq!(set_r::<M>(c, "valve.initial_command", 8.0), Status::Ok);
        },
        "valve.initial_command",
    );
    assert_exit_rejects::<M>(
        |c| {
            assert_eq!(set_r::<M>(c, "cost.acceleration_weight", 0.0), Status::Ok);
            assert_eq!(set_r::<M>(c, "cost.force_weight", 0.0), Status::Ok);
        },
        "cost.acceleration_weight",
    );

    type S = SkyHookController;
    assert_exit_rejects::<S>(
        |c| assert_eq!(set_r::<S>(c, "damping.min", 500e3), Status::Ok),
        "damping.min",
    );
    // damping must fall with the opening
    assert_exit_rejects::<S>(
        |c| assert_eq!(set_r::<S>(c, "table.damping[4]", 500e3), Status::Ok),
        "table.damping[4]",
    );
    assert_exit_rejects::<S>(
        |c| assert_eq!(set_r::<S>(c, "table.opening[3]", 0.05), Status::Ok),
        "table.opening[3]",
    );
    assert_exit_rejects::<S>(
        |c| assert_eq!(set_r::<S>(c, "table.damping[9]", 0.0), Status::Ok),
        "table.damping[9]",
    );
    // below the declared minimum (1 us): refused when set (a few ulps made a step loop for ever)
    for bad in [0.0, 1e-310, 1e-9] {
        let (mut c, log) = init::<S>();
        assert_set_rejects(
            set_r::<S>(&mut c, "board.sample_time", bad),
            &log,
            "board.sample_time",
        );
    }
    let (mut c, log) = init::<S>();
    assert_set_rejects(set_i::<S>(&mut c, "sensor.sign", 0), &log, "sensor.sign");
    let (mut c, log) = init::<S>();
    assert_set_rejects(
        set_r::<S>(&mut c, "table.opening[2]", 1.5),
        &log,
        "table.opening[2]",
    );
    assert_set_rejects(set_i::<S>(&mut c, "control.mode", 2), &log, "control.mode");

    type I = IdealDamperForceController;
    let (mut c, log) = init::<I>();
    assert_set_rejects(
        set_i::<I>(&mut c, "force_loop.command_sign", 0),
        &log,
        "force_loop.command_sign",
    );
    assert_exit_rejects::<I>(
        |c| assert_eq!(set_r::<I>(c, "spool.command_limit", 0.0), Status::Ok),
        "spool.command_limit",
    );

    // a rejected initialisation can be repaired and completed
    let (mut c, _log) = init::<S>();
    assert_eq!(set_r::<S>(&mut c, "table.damping[4]", 500e3), Status::Ok);
    assert_eq!(c.exit_initialization_mode(), Status::Error);
    assert_eq!(set_r::<S>(&mut c, "table.damping[4]", 132.3e3), Status::Ok);
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    assert_eq!(c.do_step(0.0, 1e-3), Status::Ok);
}

#[test]
fn a_changed_table_is_used() {
    // Continuous mode with an ideal velocity demanding c = c_sky = 330 kN.s/m; a linear table
    // 0 -> 400 kN.s/m, 1 -> 10 kN.s/m (other points on the line) gives opening 70/390.
    type S = SkyHookController;
    let (mut c, _log) = init::<S>();
    assert_eq!(set_i::<S>(&mut c, "control.mode", 1), Status::Ok);
    assert_eq!(set_i::<S>(&mut c, "sensor.velocity_source", 1), Status::Ok);
    for i in 0..9 {
        let o = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.8, 1.0][i];
        let name = format!("table.damping[{}]", i + 1);
        assert_eq!(set_r::<S>(&mut c, &name, 400e3 - 390e3 * o), Status::Ok);
    }
    // c_min/c_max do not follow a changed table (documented): set them to its ends.
    assert_eq!(set_r::<S>(&mut c, "damping.max", 400e3), Status::Ok);
    assert_eq!(set_r::<S>(&mut c, "damping.min", 10e3), Status::Ok);
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    let ins = [
        vr::<S>("sensor.velocity"),
        vr::<S>("damper.elongation_velocity"),
    ];
    assert_eq!(c.set_real(&ins, &[0.05, 0.05]), Status::Ok);
    for k in 0..3 {
        assert_eq!(c.do_step(k as f64 * 1e-3, 1e-3), Status::Ok);
    }
    let cmd = get_r::<S>(&mut c, "valve.command");
    assert!((cmd - 10.0 * 70.0 / 390.0).abs() < 1e-12, "{cmd}");
    assert_eq!(get_r::<S>(&mut c, "damping.desired"), 330e3);
}

// ---------------------------------------------------------------------------------------------
// Step-size independence through the FMU path.

fn run_grid<M: FmuModel>(
    setup: &dyn Fn(&mut Component),
    inputs: &[&str],
    drive: &dyn Fn(f64) -> Vec<f64>,
    h: f64,
    t_end: f64,
) -> Vec<Vec<f64>> {
    let (mut c, _log) = init::<M>();
    setup(&mut c);
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    let vrs: Vec<u32> = inputs.iter().map(|n| vr::<M>(n)).collect();
    let n = (t_end / h).round() as usize;
    let per_ms = (1e-3 / h).round() as usize;
    let mut trace = Vec::new();
    for k in 0..n {
        let t = k as f64 * h;
        assert_eq!(c.set_real(&vrs, &drive(t)), Status::Ok);
        assert!(c.do_step(t, h) <= Status::Warning);
        if (k + 1) % per_ms == 0 {
            trace.push(all_real_outputs::<M>(&mut c));
        }
    }
    trace
}

fn assert_same_traces(a: &[Vec<f64>], b: &[Vec<f64>], what: &str) {
    assert_eq!(a.len(), b.len());
    let mut changes = 0;
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        for (j, (p, q)) in x.iter().zip(y).enumerate() {
            assert!(
                (p - q).abs() <= 1e-9 * (1.0 + p.abs().max(q.abs())),
                "{what}: output {j} at ms {i}: {p} vs {q}"
            );
        }
        if i > 0 && a[i - 1][0] != x[0] {
            changes += 1;
        }
    }
    assert!(changes > 0, "{what}: first output never changes");
}

#[test]
fn step_size_independence_through_the_fmu() {
    let none: &dyn Fn(&mut Component) = &|_| {};
    let md = |t: f64| {
        let (a, f) = mppt_drive(t);
        vec![a, f]
    };
    let ins = ["bogie.lateral_acceleration", "damper.force"];
    let a = run_grid::<MpptController>(
        &|c| {
            assert_eq!(
                set_r::<MpptController>(c, "valve.initial_command", 5.0),
                Status::Ok
            )
        },
        &ins,
        &md,
        1e-4,
        7.0,
    );
    let b = run_grid::<MpptController>(
        &|c| {
            assert_eq!(
                set_r::<MpptController>(c, "valve.initial_command", 5.0),
                Status::Ok
            )
        },
        &ins,
        &md,
        1e-3,
        7.0,
    );
    assert_same_traces(&a, &b, "MPPT");

    let sd = |t: f64| {
        let (a, xa, ve) = skyhook_drive(t);
        vec![a, xa, ve]
    };
    let ins = [
        "sensor.acceleration",
        "sensor.velocity",
        "damper.elongation_velocity",
    ];
    for mode in [0, 1] {
        let setup = move |c: &mut Component| {
            assert_eq!(
                set_i::<SkyHookController>(c, "control.mode", mode),
                Status::Ok
            )
        };
        let a = run_grid::<SkyHookController>(&setup, &ins, &sd, 1e-4, 2.0);
        let b = run_grid::<SkyHookController>(&setup, &ins, &sd, 1e-3, 2.0);
        assert_same_traces(&a, &b, "sky-hook");
    }

    let id = |t: f64| {
        vec![
            0.05 * (2.0 * PI * 4.0 * t).cos(),
            12e3 * (2.0 * PI * 4.0 * t + 0.5).sin(),
        ]
    };
    let ins = ["damper.elongation_velocity", "damper.force"];
    let a = run_grid::<IdealDamperForceController>(none, &ins, &id, 1e-4, 1.0);
    let b = run_grid::<IdealDamperForceController>(none, &ins, &id, 1e-3, 1.0);
    assert_same_traces(&a, &b, "IDF");
}

// ---------------------------------------------------------------------------------------------
// No direct feedthrough: declared and true.

fn check_no_feedthrough<M: FmuModel>(inputs: &[&str], a: &[f64], b: &[f64]) {
    let xml = model_description::xml::model_description::<M>()
        .unwrap()
        .xml;
    let outputs = &xml[xml.find("<Outputs>").unwrap()..xml.find("</Outputs>").unwrap()];
    let n = outputs.matches("<Unknown").count();
    assert!(n >= 3);
    assert_eq!(
        outputs.matches(r#"dependencies="""#).count(),
        n,
        "{outputs}"
    );

    let (mut c, _log) = init::<M>();
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    let vrs: Vec<u32> = inputs.iter().map(|n| vr::<M>(n)).collect();
    for k in 0..50 {
        assert_eq!(c.set_real(&vrs, a), Status::Ok);
        assert!(c.do_step(k as f64 * 1e-3, 1e-3) <= Status::Warning);
    }
    let before = all_real_outputs::<M>(&mut c);
    assert_eq!(c.set_real(&vrs, b), Status::Ok);
    let after = all_real_outputs::<M>(&mut c);
    assert_eq!(
        before,
        after,
        "{}: outputs moved without a step",
        M::INFO.name
    );
    // ... and the new inputs do act after a step
    assert!(c.do_step(0.05, 2e-3) <= Status::Warning);
    assert_ne!(all_real_outputs::<M>(&mut c), before, "{}", M::INFO.name);
}

#[test]
fn outputs_have_no_direct_feedthrough() {
    check_no_feedthrough::<MpptController>(
        &["bogie.lateral_acceleration", "damper.force"],
        &[1.0, 1e3],
        &[-3.0, 5e3],
    );
    check_no_feedthrough::<SkyHookController>(
        &[
            "sensor.acceleration",
            "sensor.velocity",
            "damper.elongation_velocity",
        ],
        &[1.0, 0.0, 0.01],
        &[-1.0, 0.0, -0.02],
    );
    check_no_feedthrough::<IdealDamperForceController>(
        &["damper.elongation_velocity", "damper.force"],
        &[0.01, 1e3],
        &[-0.02, 0.0],
    );
}

// ---------------------------------------------------------------------------------------------
// Inputs, initialisation preview, logging on change, FMU state.

#[test]
fn nan_input_rejected_at_set_time() {
    type I = IdealDamperForceController;
    let (mut c, log) = init::<I>();
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    assert_eq!(c.do_step(0.0, 1e-3), Status::Ok);
    assert_set_rejects(
        set_r::<I>(&mut c, "damper.force", f64::NAN),
        &log,
        "damper.force",
    );
    // the instance goes on with the previous input
    assert_eq!(c.state(), FmiState::StepComplete);
    assert_eq!(c.do_step(1e-3, 1e-3), Status::Ok);
    assert!(!get_b::<I>(&mut c, "board.input_fault"));
    // fixed parameters cannot change after initialisation
    assert_set_rejects(
        set_r::<I>(&mut c, "reference.damping", 1.0),
        &log,
        "reference.damping",
    );
}

#[test]
fn initialization_mode_previews_initial_outputs() {
    type M = MpptController;
    let (mut c, _log) = init::<M>();
    assert_eq!(get_r::<M>(&mut c, "valve.command"), 0.0);
    assert_eq!(set_r::<M>(&mut c, "valve.initial_command", 6.5), Status::Ok);
    assert_eq!(get_r::<M>(&mut c, "valve.command"), 6.5);
    assert_eq!(get_r::<M>(&mut c, "valve.opening"), 0.65);
    assert_eq!(
        set_i::<M>(&mut c, "hill_climb.initial_direction", -1),
        Status::Ok
    );
    assert_eq!(get_i::<M>(&mut c, "hill_climb.direction"), -1);
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    assert_eq!(get_r::<M>(&mut c, "valve.command"), 6.5);
    // the first board sample's command appears one sample later: still the initial command
    assert_eq!(c.do_step(0.0, 5e-4), Status::Ok);
    assert_eq!(get_r::<M>(&mut c, "valve.command"), 6.5);
}

#[test]
fn warnings_and_events_only_on_change() {
    // MPPT above the threshold: an override at every update, but one warning.
    type M = MpptController;
    let (mut c, log) = init::<M>();
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    let ins = [
        vr::<M>("bogie.lateral_acceleration"),
        vr::<M>("damper.force"),
    ];
    let mut warning_steps = 0;
    for k in 0..6000 {
        let t = k as f64 * 1e-3;
        let a = 10.0 * (2.0 * PI * 4.0 * t).sin();
        assert_eq!(c.set_real(&ins, &[a, 1e4 * a]), Status::Ok);
        let s = c.do_step(t, 1e-3);
        assert!(s <= Status::Warning);
        warning_steps += usize::from(s == Status::Warning);
    }
    assert!(get_b::<M>(&mut c, "override.active"));
    let msgs = log.take();
    let warnings: Vec<_> = msgs
        .iter()
        .filter(|(s, _, _)| *s == Status::Warning)
        .collect();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].2.contains("(3.5)"));
    assert_eq!(warning_steps, 1);
    let updates = msgs
        .iter()
        .filter(|(_, cat, m)| cat == "logEvents" && m.contains("valve update"))
        .count();
    assert_eq!(updates, 6);

    // IDF: saturation warned when it starts, not at every sample.
    type I = IdealDamperForceController;
    let (mut c, log) = init::<I>();
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    assert_eq!(set_r::<I>(&mut c, "damper.force", -20e3), Status::Ok);
    let mut statuses = Vec::new();
    for k in 0..100 {
        statuses.push(c.do_step(k as f64 * 1e-3, 1e-3));
    }
    assert!(get_b::<I>(&mut c, "spool.command_saturated"));
    assert_eq!(
        statuses.iter().filter(|s| **s == Status::Warning).count(),
        1
    );
    assert_eq!(set_r::<I>(&mut c, "damper.force", 0.0), Status::Ok);
    assert_eq!(c.do_step(0.1, 2e-3), Status::Ok);
    assert!(!get_b::<I>(&mut c, "spool.command_saturated"));
    let msgs = log.take();
    assert_eq!(
        msgs.iter()
            .filter(|(s, _, _)| *s == Status::Warning)
            .count(),
        1
    );
    assert!(msgs
        .iter()
        .any(|(_, cat, m)| cat == "logEvents" && m.contains("back within")));

    // Sky-hook: one event per switch, far fewer than samples.
    type S = SkyHookController;
    let (mut c, log) = init::<S>();
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    let ins = [
        vr::<S>("sensor.acceleration"),
        vr::<S>("sensor.velocity"),
        vr::<S>("damper.elongation_velocity"),
    ];
    let mut switches = 0;
    let mut last = get_b::<S>(&mut c, "control.on_state");
    for k in 0..2000 {
        let t = k as f64 * 1e-3;
        let (a, xa, ve) = skyhook_drive(t);
        assert_eq!(c.set_real(&ins, &[a, xa, ve]), Status::Ok);
        assert_eq!(c.do_step(t, 1e-3), Status::Ok);
        let on = get_b::<S>(&mut c, "control.on_state");
        switches += usize::from(on != last);
        last = on;
    }
    let events = log
        .take()
        .iter()
        .filter(|(_, cat, m)| cat == "logEvents" && m.contains("sky-hook"))
        .count();
    assert!(switches > 10);
    assert_eq!(events, switches);
}

fn state_round_trip<M: FmuModel>(inputs: &[&str], drive: &dyn Fn(f64) -> Vec<f64>) {
    let (mut c, _log) = init::<M>();
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    let vrs: Vec<u32> = inputs.iter().map(|n| vr::<M>(n)).collect();
    let h = 1e-3;
    for k in 0..1500 {
        let t = k as f64 * h;
        assert_eq!(c.set_real(&vrs, &drive(t)), Status::Ok);
        assert!(c.do_step(t, h) <= Status::Warning);
    }
    let snap = c.get_fmu_state().unwrap();
    let bytes = c.serialize_fmu_state(&snap).unwrap();
    let run = |c: &mut Component| {
        let mut tr = Vec::new();
        for k in 1500..2500 {
            let t = k as f64 * h;
            assert_eq!(c.set_real(&vrs, &drive(t)), Status::Ok);
            assert!(c.do_step(t, h) <= Status::Warning);
            tr.push(all_real_outputs::<M>(c));
        }
        tr
    };
    let first = run(&mut c);
    assert_eq!(c.set_fmu_state(&snap), Status::Ok);
    let second = run(&mut c);
    assert_eq!(first, second, "{}", M::INFO.name);
    let restored = c.deserialize_fmu_state(&bytes).unwrap();
    assert_eq!(c.set_fmu_state(&restored), Status::Ok);
    let third = run(&mut c);
    assert_eq!(first, third, "{}", M::INFO.name);
}

#[test]
fn fmu_state_save_restore_and_serialise() {
    state_round_trip::<MpptController>(&["bogie.lateral_acceleration", "damper.force"], &|t| {
        let (a, f) = mppt_drive(t);
        vec![a, f]
    });
    state_round_trip::<SkyHookController>(
        &[
            "sensor.acceleration",
            "sensor.velocity",
            "damper.elongation_velocity",
        ],
        &|t| {
            let (a, xa, ve) = skyhook_drive(t);
            vec![a, xa, ve]
        },
    );
    state_round_trip::<IdealDamperForceController>(
        &["damper.elongation_velocity", "damper.force"],
        &|t| vec![0.05 * (25.0 * t).cos(), 8e3 * (25.0 * t).sin()],
    );
}

/// Finite inputs whose products overflow (1e200 m/s from a broken sensor) end the run with the
/// output named as the FMU names it (`control.condition`), not as the physics field.
#[test]
fn an_overflowing_output_is_named_by_its_fmi_name() {
    type S = SkyHookController;
    let (mut c, log) = init::<S>();
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    assert_eq!(set_r::<S>(&mut c, "sensor.velocity", 1e200), Status::Ok);
    assert_eq!(set_r::<S>(&mut c, "sensor.acceleration", 1e200), Status::Ok);
    assert_eq!(
        set_r::<S>(&mut c, "damper.elongation_velocity", -1e200),
        Status::Ok
    );
    let mut status = Status::Ok;
    for k in 0..100 {
        status = c.do_step(k as f64 * 1e-3, 1e-3);
        if status != Status::Ok {
            break;
        }
    }
    assert_eq!(status, Status::Error);
    let text = format!("{:?}", log.take());
    assert!(text.contains("`control.condition`"), "{text}");
    assert!(!text.contains("`condition`"), "{text}");
}
