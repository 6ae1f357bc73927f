//! Steps that cannot complete: the physics returns an error and leaves the model unchanged;
//! the FMUs return fmi2Discard with a logged message, never a non-finite output, and the run
//! continues after the host restores an FMU state (and retries with a smaller step or
//! corrected inputs).
//!
//! Two legitimate causes are exercised (no test-only switch):
//! * the integrator's work bound `solver.max_internal_steps` (a documented parameter for
//!   real-time hosts) reached by a normal 3 mm / 4 Hz stroke with 5 ms communication steps;
//! * an absurd but finite input (elongation velocity 1e10 or 1e300 m/s) that makes the
//!   integrator fail or a state/output overflow.

#![allow(clippy::unwrap_used, clippy::panic)] // test helpers outside #[test] fns

use std::f64::consts::PI;

use fmu_damper::fmu::{FullActiveActuator, PassiveYawDamper, SemiActiveDamper};
use fmu_damper::semi_active::orifice_law;
use fmu_damper::{
    Actuator, ActuatorInputs, ActuatorModel, ActuatorParams, SemiActiveDamper as Physics,
    SemiActiveInputs, SemiActiveParams, StepError,
};
use model_description::{
    rust_component, value_reference, Causality, CollectLog, Component, FmuModel, InstanceContext,
    Status, VarType,
};

const W: f64 = 2.0 * PI * 4.0;

/// 3 mm at 4 Hz: (elongation, velocity) at time t.
fn stroke(t: f64) -> (f64, f64) {
    (3e-3 * (W * t).sin(), 3e-3 * W * (W * t).cos())
}

fn semi_inputs(t: f64) -> SemiActiveInputs {
    let (x, v) = stroke(t);
    SemiActiveInputs {
        elongation_m: x,
        elongation_velocity_mps: v,
        valve_command_v: 0.0,
    }
}

fn act_inputs(t: f64) -> ActuatorInputs {
    let (x, v) = stroke(t);
    ActuatorInputs {
        spool_command_m: 0.6e-3 * (W * t).cos(),
        load_force_n: 0.0,
        elongation_m: x,
        elongation_velocity_mps: v,
    }
}

fn semi_with_limit(limit: u32) -> Physics {
    let mut p = SemiActiveParams::default();
    p.solver.max_internal_steps = limit;
    Physics::new(p).unwrap()
}

fn actuator_with_limit(model: ActuatorModel, limit: u32) -> Actuator {
    let mut p = ActuatorParams {
        model,
        ..FullActiveActuator::default_params()
    };
    p.solver.max_internal_steps = limit;
    Actuator::new(p).unwrap()
}

fn is_step_limit(e: &StepError) -> bool {
    matches!(e, StepError::Integration { reason, .. } if reason.contains("max_internal_steps"))
}

/// A master's policy: try `h_max`; on failure the model is unchanged, halve and retry.
/// Returns the accepted (t, h) schedule, the number of failed attempts and the forces.
fn run_with_retries<M: Clone + PartialEq + std::fmt::Debug, O>(
    model: &mut M,
    t_end: f64,
    h_max: f64,
    mut step: impl FnMut(&mut M, f64, f64) -> Result<O, StepError>,
    mut outputs: impl FnMut(&M) -> f64,
) -> (Vec<(f64, f64)>, usize, Vec<f64>) {
    let (mut t, mut schedule, mut failures, mut forces) = (0.0, Vec::new(), 0, Vec::new());
    while t < t_end - 1e-12 {
        let mut h = h_max;
        loop {
            let before = model.clone();
            let f_before = outputs(model);
            match step(model, t, h) {
                Ok(_) => break,
                Err(e) => {
                    assert!(is_step_limit(&e), "unexpected error {e}");
                    assert_eq!(*model, before, "a failed step changed the model");
                    let f = outputs(model);
                    assert!(f.is_finite());
                    assert_eq!(f.to_bits(), f_before.to_bits());
                    failures += 1;
                    h *= 0.5;
                    assert!(h > 1e-6, "no step size completes at t = {t}");
                }
            }
        }
        schedule.push((t, h));
        forces.push(outputs(model));
        t += h;
    }
    (schedule, failures, forces)
}

#[test]
fn semi_active_step_limit_fails_atomically_and_retry_matches_unlimited_run() {
    let mut d = semi_with_limit(10);
    let (schedule, failures, forces) = run_with_retries(
        &mut d,
        0.5,
        5e-3,
        |d, t, h| d.step(h, &semi_inputs(t)),
        |d| d.outputs().unwrap().force_n,
    );
    assert!(
        failures > 0,
        "the limit was never reached: the test shows nothing"
    );
    assert!(schedule.iter().any(|(_, h)| *h < 5e-3));
    // The completed steps are exactly those of a model without the (binding) limit.
    let mut r = Physics::new(SemiActiveParams::default()).unwrap();
    for ((t, h), f) in schedule.iter().zip(&forces) {
        let o = r.step(*h, &semi_inputs(*t)).unwrap();
        assert_eq!(o.force_n.to_bits(), f.to_bits(), "t = {t}");
    }
    // Sanity: it is the real 0 % damper (R1 band at 3 mm, 4 Hz; the retried steps are <= 5 ms).
    let peak = forces[forces.len() / 2..]
        .iter()
        .fold(0.0f64, |m, f| m.max(f.abs()));
    assert!((12e3..=20.5e3).contains(&peak), "peak {peak}");
}

#[test]
fn actuator_step_limit_fails_atomically_and_retry_matches_unlimited_run() {
    let mut a = actuator_with_limit(ActuatorModel::FullOrder, 30);
    let (schedule, failures, forces) = run_with_retries(
        &mut a,
        0.2,
        5e-3,
        |a, t, h| a.step(h, &act_inputs(t)),
        |a| a.outputs().unwrap().force_n,
    );
    assert!(
        failures > 0,
        "the limit was never reached: the test shows nothing"
    );
    let mut r = actuator_with_limit(ActuatorModel::FullOrder, 20_000);
    for ((t, h), f) in schedule.iter().zip(&forces) {
        let o = r.step(*h, &act_inputs(*t)).unwrap();
        assert_eq!(o.force_n.to_bits(), f.to_bits(), "t = {t}");
    }
}

#[test]
fn absurd_finite_velocity_is_an_error_not_a_number_and_leaves_the_model_unchanged() {
    // Semi-active: F v overflows at 1e300 m/s.
    let mut d = Physics::new(SemiActiveParams::default()).unwrap();
    let mut reference = d.clone();
    for k in 0..100 {
        let t = k as f64 * 1e-3;
        d.step(1e-3, &semi_inputs(t)).unwrap();
        reference.step(1e-3, &semi_inputs(t)).unwrap();
    }
    let before = d.clone();
    let bad = SemiActiveInputs {
        elongation_velocity_mps: 1e300,
        ..semi_inputs(0.1)
    };
    let e = d.step(1e-3, &bad).unwrap_err();
    assert!(
        matches!(
            e,
            StepError::NonFinite { .. } | StepError::Integration { .. }
        ),
        "{e}"
    );
    assert_eq!(d, before);
    assert!(d.outputs().unwrap().force_n.is_finite());
    for k in 100..200 {
        let t = k as f64 * 1e-3;
        let a = d.step(1e-3, &semi_inputs(t)).unwrap();
        let b = reference.step(1e-3, &semi_inputs(t)).unwrap();
        assert_eq!(a, b, "t = {t}");
    }

    // Actuator: at 1e10 m/s the full order's step size collapses; at 1e300 the derivative
    // overflows (both orders).
    for (model, v) in [
        (ActuatorModel::FullOrder, 1e10),
        (ActuatorModel::FullOrder, 1e300),
        (ActuatorModel::ReducedOrder, 1e300),
    ] {
        let mut a = actuator_with_limit(model, 20_000);
        let mut reference = a.clone();
        for k in 0..50 {
            let t = k as f64 * 1e-3;
            a.step(1e-3, &act_inputs(t)).unwrap();
            reference.step(1e-3, &act_inputs(t)).unwrap();
        }
        let before = a.clone();
        let bad = ActuatorInputs {
            elongation_velocity_mps: v,
            ..act_inputs(0.05)
        };
        let e = a.step(1e-3, &bad).unwrap_err();
        assert!(
            matches!(
                e,
                StepError::NonFinite { .. } | StepError::Integration { .. }
            ),
            "{model:?} {v}: {e}"
        );
        assert_eq!(a, before, "{model:?} {v}");
        let o = a.outputs().unwrap();
        assert!(o.force_n.is_finite() && o.load_pressure_pa.is_finite());
        for k in 50..100 {
            let t = k as f64 * 1e-3;
            assert_eq!(
                a.step(1e-3, &act_inputs(t)).unwrap(),
                reference.step(1e-3, &act_inputs(t)).unwrap(),
                "{model:?} {v}: t = {t}"
            );
        }
    }
}

#[test]
fn regularised_laws_do_not_collapse_to_zero_for_huge_arguments() {
    let p = SemiActiveParams::default();
    // Before the scaled branch, v^2 and dP^2 overflowed and both laws returned 0.
    let mut last = 0.0;
    for v in [1e100, 1e150, 1e200, 1e300, f64::MAX] {
        let f = p.velocity_flow(v);
        assert!(f.is_finite() && f > last, "f({v}) = {f}");
        assert_eq!(p.velocity_flow(-v), -f);
        // cube-root law: f(v) = Q_ref cbrt(v / v_ref) for v >> v_lin
        let expect = p.velocity_flow_ref_m3ps * (v.cbrt() / p.velocity_ref_mps.cbrt());
        assert!((f / expect - 1.0).abs() < 1e-12, "{v}: {f} vs {expect}");
        last = f;
    }
    for dp in [1e100, 1e150, 1e200, 1e300, f64::MAX] {
        let g = orifice_law(dp, 3e5);
        assert!((g / dp.sqrt() - 1.0).abs() < 1e-12, "g({dp}) = {g}");
        assert_eq!(orifice_law(-dp, 3e5), -g);
    }
    // Continuous across the switch between the plain and the scaled formulas.
    for x in [1e150 * (1.0 - 1e-15), 1e150, 1e150 * (1.0 + 1e-15)] {
        let f = p.velocity_flow(x);
        let expect = p.velocity_flow_ref_m3ps * (x / p.velocity_ref_mps).cbrt();
        assert!((f / expect - 1.0).abs() < 1e-12);
        assert!((orifice_law(x, 3e5) / x.sqrt() - 1.0).abs() < 1e-12);
    }
    // Tiny regularisations: a damper at rest gives 0, not 0/0 (v^2 + v_lin^2 underflowed)
    let tiny = SemiActiveParams {
        velocity_linear_mps: 1e-300,
        laminar_pressure_pa: 1e-300,
        ..p
    };
    assert_eq!(tiny.velocity_flow(0.0), 0.0);
    assert_eq!(tiny.orifice_law(0.0), 0.0);
    for x in [1e-300, 1e-200, 1e-151] {
        let f = tiny.velocity_flow(x);
        let expect = p.velocity_flow_ref_m3ps * (x / p.velocity_ref_mps).cbrt();
        assert!(f.is_finite() && f > 0.0 && f < 2.0 * expect, "f({x}) = {f}");
        let g = tiny.orifice_law(x);
        assert!(g.is_finite() && g > 0.0 && g <= x.sqrt(), "g({x}) = {g}");
        assert_eq!(tiny.orifice_law(-x), -g);
    }
    // Normal range unchanged: the plain formula, bit for bit.
    let v: f64 = 0.05;
    let vl = p.velocity_linear_mps;
    let plain =
        p.velocity_flow_ref_m3ps * v / (p.velocity_ref_mps.cbrt() * (v * v + vl * vl).cbrt());
    assert_eq!(p.velocity_flow(v).to_bits(), plain.to_bits());
}

// ---------------------------------------------------------------- FMU level

fn vr<M: FmuModel>(name: &str) -> u32 {
    value_reference::<M>(name).unwrap_or_else(|| panic!("no variable {name}"))
}

fn get<M: FmuModel>(c: &mut Component, name: &str) -> f64 {
    let mut out = [f64::NAN];
    let s = c.get_real(&[vr::<M>(name)], &mut out);
    assert!(s <= Status::Warning, "get {name}: {s:?}");
    out[0]
}

fn real_outputs<M: FmuModel>() -> Vec<String> {
    M::variables()
        .iter()
        .filter(|v| v.meta.causality == Causality::Output && v.meta.var_type == VarType::Real)
        .map(|v| v.meta.name.clone())
        .collect()
}

fn all_outputs_finite<M: FmuModel>(c: &mut Component) -> bool {
    real_outputs::<M>()
        .iter()
        .all(|n| get::<M>(c, n).is_finite())
}

/// Initialised instance with integer parameters set in initialisation mode.
fn init<M: FmuModel>(integers: &[(&str, i32)]) -> (Component, CollectLog) {
    let (mut c, log) = rust_component::<M>(InstanceContext::default()).unwrap();
    assert_eq!(c.setup_experiment(0.0, None), Status::Ok);
    assert_eq!(c.enter_initialization_mode(), Status::Ok);
    for (n, x) in integers {
        assert_eq!(c.set_integer(&[vr::<M>(n)], &[*x]), Status::Ok, "{n}");
    }
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    (c, log)
}

fn set_inputs<M: FmuModel>(c: &mut Component, values: &[(&str, f64)]) {
    for (n, x) in values {
        assert_eq!(c.set_real(&[vr::<M>(n)], &[*x]), Status::Ok, "{n}");
    }
}

fn discard_logged(log: &CollectLog, needle: &str) -> bool {
    log.take()
        .iter()
        .any(|(s, _, m)| *s == Status::Discard && m.contains(needle))
}

fn values<M: FmuModel>(c: &mut Component, names: &[&str]) -> Vec<u64> {
    names.iter().map(|n| get::<M>(c, n).to_bits()).collect()
}

/// Runs the stroke with the master policy "save state, try h_max, on Discard restore and halve".
/// `state_outputs` are outputs without direct feedthrough: a discarded step must leave them
/// bit for bit as they were. Returns the accepted schedule, the number of discards and the
/// forces after each step.
fn fmu_run_with_retries<M: FmuModel>(
    c: &mut Component,
    log: &CollectLog,
    inputs: impl Fn(f64) -> Vec<(&'static str, f64)>,
    state_outputs: &[&str],
    t_end: f64,
    h_max: f64,
) -> (Vec<(f64, f64)>, usize, Vec<f64>) {
    let (mut t, mut schedule, mut discards, mut forces) = (0.0, Vec::new(), 0, Vec::new());
    while t < t_end - 1e-12 {
        let mut h = h_max;
        loop {
            set_inputs::<M>(c, &inputs(t));
            let snapshot = c.get_fmu_state().unwrap();
            let before = values::<M>(c, state_outputs);
            match c.do_step(t, h) {
                Status::Ok => break,
                Status::Discard => {
                    assert!(
                        discard_logged(log, "solver.max_internal_steps"),
                        "no logged reason"
                    );
                    assert!(all_outputs_finite::<M>(c));
                    assert_eq!(values::<M>(c, state_outputs), before, "t = {t}");
                    assert_eq!(c.set_fmu_state(&snapshot), Status::Ok);
                    discards += 1;
                    h *= 0.5;
                    assert!(h > 1e-6, "no step size completes at t = {t}");
                }
                s => panic!("unexpected status {s:?}: {:?}", log.take()),
            }
        }
        schedule.push((t, h));
        forces.push(get::<M>(c, "damper.force"));
        t += h;
    }
    (schedule, discards, forces)
}

/// Replays an accepted schedule on a fresh instance with the default (non-binding) limit.
fn fmu_replay<M: FmuModel>(
    integers: &[(&str, i32)],
    inputs: impl Fn(f64) -> Vec<(&'static str, f64)>,
    schedule: &[(f64, f64)],
) -> Vec<f64> {
    let (mut c, log) = init::<M>(integers);
    schedule
        .iter()
        .map(|(t, h)| {
            set_inputs::<M>(&mut c, &inputs(*t));
            assert_eq!(c.do_step(*t, *h), Status::Ok, "{:?}", log.take());
            get::<M>(&mut c, "damper.force")
        })
        .collect()
}

fn semi_fmu_inputs(t: f64) -> Vec<(&'static str, f64)> {
    let (x, v) = stroke(t);
    vec![
        ("damper.elongation", x),
        ("damper.elongation_velocity", v),
        ("valve.command", 0.0),
    ]
}

fn act_fmu_inputs(t: f64) -> Vec<(&'static str, f64)> {
    let i = act_inputs(t);
    vec![
        ("spool.command", i.spool_command_m),
        ("damper.elongation", i.elongation_m),
        ("damper.elongation_velocity", i.elongation_velocity_mps),
    ]
}

const LIMIT: &str = "solver.max_internal_steps";

#[test]
fn fmu_step_limit_discards_with_message_and_restored_instance_continues() {
    // Semi-active damper, 0 % opening, limit 10 internal steps, 5 ms communication steps.
    let (mut c, log) = init::<SemiActiveDamper>(&[(LIMIT, 10)]);
    let state = ["damper.force", "damper.pressure_difference"];
    let (schedule, discards, forces) =
        fmu_run_with_retries::<SemiActiveDamper>(&mut c, &log, semi_fmu_inputs, &state, 0.3, 5e-3);
    assert!(
        discards > 0,
        "the limit was never reached: the test shows nothing"
    );
    let reference = fmu_replay::<SemiActiveDamper>(&[], semi_fmu_inputs, &schedule);
    assert_eq!(forces, reference);

    // Full-order actuator, limit 30.
    let (mut c, log) = init::<FullActiveActuator>(&[(LIMIT, 30), ("actuator.model", 0)]);
    let state = [
        "damper.load_pressure",
        "chamber_a.pressure",
        "chamber_b.pressure",
    ];
    let (schedule, discards, forces) =
        fmu_run_with_retries::<FullActiveActuator>(&mut c, &log, act_fmu_inputs, &state, 0.1, 5e-3);
    assert!(
        discards > 0,
        "the limit was never reached: the test shows nothing"
    );
    let reference =
        fmu_replay::<FullActiveActuator>(&[("actuator.model", 0)], act_fmu_inputs, &schedule);
    assert_eq!(forces, reference);
}

#[test]
fn fmu_step_limit_is_a_declared_parameter_with_a_range() {
    for (name, vars) in [
        ("SemiActiveDamper", var_meta::<SemiActiveDamper>()),
        ("PassiveYawDamper", var_meta::<PassiveYawDamper>()),
        ("FullActiveActuator", var_meta::<FullActiveActuator>()),
    ] {
        let Some((causality, min, start)) = vars else {
            panic!("{name}: no {LIMIT}");
        };
        assert_eq!(causality, Causality::Parameter, "{name}");
        assert_eq!(min, Some(1.0), "{name}");
        assert_eq!(start, 20_000, "{name}");
    }
    // Zero is rejected when it is set, naming the variable.
    let (mut c, log) = rust_component::<SemiActiveDamper>(InstanceContext::default()).unwrap();
    assert_eq!(c.setup_experiment(0.0, None), Status::Ok);
    assert_eq!(c.enter_initialization_mode(), Status::Ok);
    assert_eq!(
        c.set_integer(&[vr::<SemiActiveDamper>(LIMIT)], &[0]),
        Status::Error
    );
    assert!(log.take().iter().any(|(_, _, m)| m.contains(LIMIT)));
}

fn var_meta<M: FmuModel>() -> Option<(Causality, Option<f64>, i32)> {
    let (mut c, _) = rust_component::<M>(InstanceContext::default()).unwrap();
    assert_eq!(c.setup_experiment(0.0, None), Status::Ok);
    assert_eq!(c.enter_initialization_mode(), Status::Ok);
    let mut start = [0];
    assert_eq!(c.get_integer(&[vr::<M>(LIMIT)], &mut start), Status::Ok);
    M::variables()
        .iter()
        .find(|v| v.meta.name == LIMIT)
        .map(|v| (v.meta.causality, v.meta.min, start[0]))
}

#[test]
fn fmu_absurd_velocity_discards_and_restored_instance_continues_identically() {
    fn check<M: FmuModel>(
        integers: &[(&str, i32)],
        inputs: fn(f64) -> Vec<(&'static str, f64)>,
        state_outputs: &[&str],
        velocity: f64,
    ) {
        let (mut c, log) = init::<M>(integers);
        let (mut r, _) = init::<M>(integers);
        let h = 1e-3;
        for k in 0..50 {
            let t = k as f64 * h;
            for c in [&mut c, &mut r] {
                set_inputs::<M>(c, &inputs(t));
                assert_eq!(c.do_step(t, h), Status::Ok);
            }
        }
        let t = 50.0 * h;
        set_inputs::<M>(&mut c, &inputs(t));
        let snapshot = c.get_fmu_state().unwrap();
        let before = values::<M>(&mut c, state_outputs);
        set_inputs::<M>(&mut c, &[("damper.elongation_velocity", velocity)]);
        assert_eq!(c.do_step(t, h), Status::Discard, "{}", M::INFO.name);
        let log = log.take();
        assert!(
            log.iter().any(|(s, _, m)| *s == Status::Discard
                && m.contains("discarded")
                && (m.contains("integration failed") || m.contains("non-finite"))),
            "{}: {log:?}",
            M::INFO.name
        );
        assert!(all_outputs_finite::<M>(&mut c), "{}", M::INFO.name);
        assert_eq!(
            values::<M>(&mut c, state_outputs),
            before,
            "{}",
            M::INFO.name
        );
        // The host restores the state saved before the step and goes on with sane inputs:
        // bit for bit the run of an instance that never saw the absurd input.
        assert_eq!(c.set_fmu_state(&snapshot), Status::Ok);
        for k in 50..100 {
            let t = k as f64 * h;
            for c in [&mut c, &mut r] {
                set_inputs::<M>(c, &inputs(t));
                assert_eq!(c.do_step(t, h), Status::Ok);
            }
            assert_eq!(
                get::<M>(&mut c, "damper.force").to_bits(),
                get::<M>(&mut r, "damper.force").to_bits(),
                "{} t = {t}",
                M::INFO.name
            );
        }
    }
    let semi_state = ["damper.force", "damper.pressure_difference"];
    check::<SemiActiveDamper>(&[], semi_fmu_inputs, &semi_state, 1e300);
    check::<PassiveYawDamper>(
        &[],
        |t| semi_fmu_inputs(t)[..2].to_vec(),
        &semi_state,
        1e300,
    );
    let act_state = [
        "damper.load_pressure",
        "chamber_a.pressure",
        "chamber_b.pressure",
    ];
    check::<FullActiveActuator>(&[("actuator.model", 0)], act_fmu_inputs, &act_state, 1e10);
    check::<FullActiveActuator>(&[("actuator.model", 0)], act_fmu_inputs, &act_state, 1e300);
    check::<FullActiveActuator>(&[("actuator.model", 1)], act_fmu_inputs, &act_state, 1e300);
}
