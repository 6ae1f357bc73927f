//! The damper FMUs driven through the glue's state machine (same checks as the C API).

#![allow(clippy::unwrap_used, clippy::panic)] // test helpers outside #[test] fns

use std::f64::consts::PI;

use fmu_damper::fmu::{FullActiveActuator, PassiveYawDamper, SemiActiveDamper};
use fmu_damper::{
    Actuator, ActuatorInputs, ActuatorModel, SemiActiveDamper as Physics, SemiActiveInputs,
    SemiActiveOutputs, SemiActiveParams, ValveModel,
};
use model_description::{
    rust_component, value_reference, Causality, CollectLog, Component, FmuModel, InstanceContext,
    Status, VarType,
};

fn vr<M: FmuModel>(name: &str) -> u32 {
    value_reference::<M>(name).unwrap_or_else(|| panic!("no variable {name}"))
}

fn new<M: FmuModel>() -> (Component, CollectLog) {
    let (mut c, log) = rust_component::<M>(InstanceContext::default()).unwrap();
    assert_eq!(c.setup_experiment(0.0, None), Status::Ok);
    assert_eq!(c.enter_initialization_mode(), Status::Ok);
    (c, log)
}

fn set<M: FmuModel>(c: &mut Component, name: &str, x: f64) -> Status {
    c.set_real(&[vr::<M>(name)], &[x])
}

fn get<M: FmuModel>(c: &mut Component, name: &str) -> f64 {
    let mut out = [f64::NAN];
    let s = c.get_real(&[vr::<M>(name)], &mut out);
    assert!(s <= Status::Warning, "get {name}: {s:?}");
    out[0]
}

fn get_bool<M: FmuModel>(c: &mut Component, name: &str) -> bool {
    let mut out = [false];
    assert!(c.get_boolean(&[vr::<M>(name)], &mut out) <= Status::Warning);
    out[0]
}

/// Initialised component with the given parameters/inputs set in initialisation mode.
fn init<M: FmuModel>(values: &[(&str, f64)]) -> (Component, CollectLog) {
    let (mut c, log) = new::<M>();
    for (n, x) in values {
        assert_eq!(set::<M>(&mut c, n, *x), Status::Ok, "{n}");
    }
    let s = c.exit_initialization_mode();
    assert!(s <= Status::Warning, "{s:?}: {:?}", log.take());
    (c, log)
}

/// Steps of `h` from t = 0, one per call.
fn stepper(h: f64) -> impl FnMut(&mut Component) -> Status {
    let mut t = 0.0;
    move |c: &mut Component| {
        let s = c.do_step(t, h);
        t += h;
        s
    }
}

fn real_outputs<M: FmuModel>() -> Vec<String> {
    M::variables()
        .iter()
        .filter(|v| v.meta.causality == Causality::Output && v.meta.var_type == VarType::Real)
        .map(|v| v.meta.name.clone())
        .collect()
}

fn real_inputs<M: FmuModel>() -> Vec<String> {
    M::variables()
        .iter()
        .filter(|v| v.meta.causality == Causality::Input)
        .map(|v| v.meta.name.clone())
        .collect()
}

fn logged(log: &[(Status, String, String)], status: Status, needle: &str) -> bool {
    log.iter()
        .any(|(s, _, m)| *s == status && m.contains(needle))
}

/// Runs the default experiment with the start values; returns the final Real outputs.
fn run_default_experiment<M: FmuModel>() -> Vec<(String, f64)> {
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
    for k in 0..n {
        let target = e.start_time + (k + 1) as f64 * e.step_size;
        assert_eq!(c.do_step(t, target - t), Status::Ok, "{:?}", log.take());
        t = target;
        for name in &names {
            let x = get::<M>(&mut c, name);
            assert!(x.is_finite(), "{} {name} = {x} at t = {t}", M::INFO.name);
        }
    }
    assert!(log.take().is_empty());
    names
        .into_iter()
        .map(|n| {
            let x = get::<M>(&mut c, &n);
            (n, x)
        })
        .collect()
}

fn value(outs: &[(String, f64)], name: &str) -> f64 {
    outs.iter()
        .find(|(n, _)| n == name)
        .map(|(_, x)| *x)
        .unwrap()
}

/// Steady pressure difference of the damper at constant velocity: f(v) = C(x) g(dP).
fn steady_dp(p: &SemiActiveParams, v: f64, opening: f64) -> f64 {
    let q = p.velocity_flow(v);
    let c = p.total_flow_coeff(opening);
    let (mut lo, mut hi) = (0.0, 1e9);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if c * p.orifice_law(mid) < q {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn declarations_generate_a_model_description() {
    for xml in [
        model_description::xml::model_description::<SemiActiveDamper>().map(|d| d.xml),
        model_description::xml::model_description::<PassiveYawDamper>().map(|d| d.xml),
        model_description::xml::model_description::<FullActiveActuator>().map(|d| d.xml),
    ] {
        let xml = xml.unwrap();
        assert!(xml.contains("<DefaultExperiment"), "{xml}");
    }
}

/// Default experiments (constant extension at 0.05 m/s; actuator: blocked rod, u = 1 mm) run
/// with finite outputs and end where the physics says.
#[test]
fn default_experiments_run_with_finite_outputs() {
    let p = SemiActiveParams::default();
    let out = run_default_experiment::<SemiActiveDamper>();
    let f_ss = p.effective_area_m2 * steady_dp(&p, 0.05, 0.0);
    let f = value(&out, "damper.force");
    assert!((f / f_ss - 1.0).abs() < 0.01, "{f} vs steady {f_ss}");
    assert_eq!(value(&out, "valve.opening"), 0.0);
    assert!((value(&out, "damper.power") - f * 0.05).abs() < 1e-9 * f.abs());

    let out = run_default_experiment::<PassiveYawDamper>();
    let f_ss = p.effective_area_m2 * steady_dp(&p, 0.05, 0.3);
    let f = value(&out, "damper.force");
    assert!((f / f_ss - 1.0).abs() < 1e-3, "{f} vs steady {f_ss}");
    // Steady state: all the piston-driven flow goes through the orifices.
    let diss = value(&out, "damper.dissipated_power");
    let dp = value(&out, "damper.pressure_difference");
    assert!((diss / (dp * p.velocity_flow(0.05)) - 1.0).abs() < 1e-3);

    let out = run_default_experiment::<FullActiveActuator>();
    let pa = FullActiveActuator::default_params();
    assert!((value(&out, "spool.position") - 1e-3).abs() < 1e-8);
    // Blocked rod, valve open: chamber A at supply, B at tank, minus the leakage drop.
    let f = value(&out, "damper.force");
    let full = pa.supply_pressure_pa * pa.area_a_m2;
    assert!(f < -0.98 * full && f > -full, "{f} vs {full}");
    assert!(value(&out, "damper.hydraulic_power") > 0.0);
}

fn semi_inputs(t: f64) -> SemiActiveInputs {
    let w = 2.0 * PI * 4.0;
    SemiActiveInputs {
        elongation_m: 2e-3 * (w * t).sin(),
        elongation_velocity_mps: 2e-3 * w * (w * t).cos(),
        // Sweeps through 0..10 V and beyond (clamped).
        valve_command_v: 5.0 + 7.0 * (2.0 * PI * 1.5 * t).sin(),
    }
}

fn assert_same_semi<M: FmuModel>(c: &mut Component, o: &SemiActiveOutputs, passive: bool) {
    let pairs = [
        ("damper.force", o.force_n),
        ("damper.pressure_difference", o.pressure_difference_pa),
        ("damper.dissipated_power", o.dissipated_power_w),
        ("damper.power", o.mechanical_power_w),
    ];
    for (n, x) in pairs {
        assert_eq!(get::<M>(c, n).to_bits(), x.to_bits(), "{n}");
    }
    if !passive {
        assert_eq!(
            get::<M>(c, "valve.opening").to_bits(),
            o.valve_opening.to_bits()
        );
        assert_eq!(
            get::<M>(c, "valve.opening_command").to_bits(),
            o.valve_opening_command.to_bits()
        );
        assert_eq!(get_bool::<M>(c, "valve.command_clamped"), o.command_clamped);
    }
}

/// The glue steps from its own time to the host's target: the physics sees (t + h) - t.
fn run_semi_against_physics<M: FmuModel>(
    params: SemiActiveParams,
    fmu_values: &[(&str, f64)],
    passive: bool,
) {
    let i0 = semi_inputs(0.0);
    let mut values = fmu_values.to_vec();
    values.push(("damper.elongation", i0.elongation_m));
    values.push(("damper.elongation_velocity", i0.elongation_velocity_mps));
    if !passive {
        values.push(("valve.command", i0.valve_command_v));
    }
    let (mut c, _log) = init::<M>(&values);
    let mut d = Physics::new(params).unwrap();
    d.set_inputs(&i0).unwrap();
    assert_same_semi::<M>(&mut c, &d.outputs().unwrap(), passive);
    let h = 1e-3;
    let mut t = 0.0;
    for k in 0..600 {
        let i = semi_inputs(t);
        assert_eq!(
            set::<M>(&mut c, "damper.elongation", i.elongation_m),
            Status::Ok
        );
        assert_eq!(
            set::<M>(
                &mut c,
                "damper.elongation_velocity",
                i.elongation_velocity_mps
            ),
            Status::Ok
        );
        if !passive {
            assert_eq!(
                set::<M>(&mut c, "valve.command", i.valve_command_v),
                Status::Ok
            );
        }
        let target = t + h;
        let s = c.do_step(t, h);
        assert!(s <= Status::Warning, "step {k}: {s:?}");
        let o = d.step(target - t, &i).unwrap();
        t = target;
        assert_same_semi::<M>(&mut c, &o, passive);
    }
}

#[test]
fn fmu_equals_plain_physics_bit_for_bit() {
    run_semi_against_physics::<SemiActiveDamper>(SemiActiveParams::default(), &[], false);
    let real = SemiActiveParams {
        valve: fmu_damper::ValveParams::real(),
        ..SemiActiveParams::default()
    };
    assert_eq!(real.valve.model, ValveModel::Real);
    // Command at t = 0 is 5 V: the FMU starts the real valve at 50 %, so does the reference.
    let i0 = semi_inputs(0.0);
    let mut d = Physics::new(real).unwrap();
    d.set_opening(0.5).unwrap();
    d.set_inputs(&i0).unwrap();
    let (mut c, _) = new::<SemiActiveDamper>();
    assert_eq!(
        c.set_integer(&[vr::<SemiActiveDamper>("valve.model")], &[1]),
        Status::Ok
    );
    set::<SemiActiveDamper>(&mut c, "valve.command", i0.valve_command_v);
    set::<SemiActiveDamper>(
        &mut c,
        "damper.elongation_velocity",
        i0.elongation_velocity_mps,
    );
    set::<SemiActiveDamper>(&mut c, "damper.elongation", i0.elongation_m);
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    assert_same_semi::<SemiActiveDamper>(&mut c, &d.outputs().unwrap(), false);
    let (h, mut t) = (1e-3, 0.0);
    for _ in 0..600 {
        let i = semi_inputs(t);
        set::<SemiActiveDamper>(&mut c, "damper.elongation", i.elongation_m);
        set::<SemiActiveDamper>(
            &mut c,
            "damper.elongation_velocity",
            i.elongation_velocity_mps,
        );
        set::<SemiActiveDamper>(&mut c, "valve.command", i.valve_command_v);
        assert!(c.do_step(t, h) <= Status::Warning);
        let o = d.step((t + h) - t, &i).unwrap();
        t += h;
        assert_same_semi::<SemiActiveDamper>(&mut c, &o, false);
    }

    run_semi_against_physics::<PassiveYawDamper>(SemiActiveParams::passive_reference(), &[], true);
    // A non-default opening reaches the physics.
    run_semi_against_physics::<PassiveYawDamper>(
        SemiActiveParams::default().with_fixed_opening(0.55),
        &[("valve.opening", 0.55)],
        true,
    );

    for model in [ActuatorModel::FullOrder, ActuatorModel::ReducedOrder] {
        let params = fmu_damper::ActuatorParams {
            model,
            ..FullActiveActuator::default_params()
        };
        let inputs = |t: f64| {
            let w = 2.0 * PI * 4.0;
            ActuatorInputs {
                spool_command_m: 0.8e-3 * (2.0 * PI * 2.0 * t).sin(),
                load_force_n: 0.0,
                elongation_m: 3e-3 * (w * t).sin(),
                elongation_velocity_mps: 3e-3 * w * (w * t).cos(),
            }
        };
        type A = FullActiveActuator;
        let (mut c, _) = new::<A>();
        let code = i32::from(model == ActuatorModel::ReducedOrder);
        assert_eq!(
            c.set_integer(&[vr::<A>("actuator.model")], &[code]),
            Status::Ok
        );
        let set_inputs = |c: &mut Component, i: &ActuatorInputs| {
            assert_eq!(set::<A>(c, "spool.command", i.spool_command_m), Status::Ok);
            assert_eq!(set::<A>(c, "damper.elongation", i.elongation_m), Status::Ok);
            assert_eq!(
                set::<A>(c, "damper.elongation_velocity", i.elongation_velocity_mps),
                Status::Ok
            );
        };
        set_inputs(&mut c, &inputs(0.0));
        assert_eq!(c.exit_initialization_mode(), Status::Ok);
        let mut a = Actuator::new(params).unwrap();
        a.set_inputs(&inputs(0.0)).unwrap();
        let check = |c: &mut Component, o: &fmu_damper::ActuatorOutputs| {
            for (n, x) in [
                ("damper.force", o.force_n),
                ("damper.load_pressure", o.load_pressure_pa),
                ("chamber_a.pressure", o.pressure_a_pa),
                ("chamber_b.pressure", o.pressure_b_pa),
                ("spool.position", o.spool_position_m),
                ("damper.hydraulic_power", o.hydraulic_power_w),
                ("damper.friction_force", o.friction_force_n),
                ("damper.power", 0.0 - o.mechanical_power_w),
            ] {
                assert_eq!(get::<A>(c, n).to_bits(), x.to_bits(), "{model:?} {n}");
            }
        };
        check(&mut c, &a.outputs().unwrap());
        let (h, mut t) = (1e-3, 0.0);
        for _ in 0..300 {
            let i = inputs(t);
            set_inputs(&mut c, &i);
            assert_eq!(c.do_step(t, h), Status::Ok);
            let o = a.step((t + h) - t, &i).unwrap();
            t += h;
            check(&mut c, &o);
        }
    }
}

/// Negative values are rejected when set (declared min); zero and cross-parameter conditions at
/// fmi2ExitInitializationMode by the physics' validation; the FMI variable is named each time.
#[test]
fn invalid_parameters_are_rejected_by_name() {
    fn rejected_at_init<M: FmuModel>(name: &str, x: f64) {
        let (mut c, log) = new::<M>();
        assert_eq!(set::<M>(&mut c, name, x), Status::Ok, "{name} = {x}");
        assert_eq!(c.exit_initialization_mode(), Status::Error, "{name} = {x}");
        let msgs = log.take();
        assert!(
            logged(&msgs, Status::Error, &format!("'{name}'")),
            "{name}: {msgs:?}"
        );
    }
    fn rejected_at_set<M: FmuModel>(name: &str, x: f64) {
        let (mut c, log) = new::<M>();
        assert_eq!(set::<M>(&mut c, name, x), Status::Error, "{name} = {x}");
        let msgs = log.take();
        assert!(
            logged(&msgs, Status::Error, &format!("'{name}'")),
            "{name}: {msgs:?}"
        );
        // The rejected value was not applied: initialisation still succeeds.
        assert_eq!(c.exit_initialization_mode(), Status::Ok);
    }
    for name in [
        "damper.chamber_volume",
        "damper.bulk_modulus",
        "damper.effective_area",
        "damper.oil_density",
        "damper.laminar_pressure",
        "damper.velocity_reference",
    ] {
        rejected_at_set::<SemiActiveDamper>(name, -1e-3);
        rejected_at_init::<SemiActiveDamper>(name, 0.0);
        rejected_at_set::<PassiveYawDamper>(name, -1.0);
        rejected_at_init::<PassiveYawDamper>(name, 0.0);
    }
    rejected_at_init::<SemiActiveDamper>("valve.time_constant", 0.0);
    rejected_at_init::<SemiActiveDamper>("valve.full_scale_command", 0.0);
    rejected_at_set::<SemiActiveDamper>("valve.discharge_coefficient", 1.5);
    rejected_at_set::<PassiveYawDamper>("valve.opening", 1.2);
    rejected_at_set::<SemiActiveDamper>("damper.bulk_modulus", f64::NAN);
    {
        let (mut c, log) = new::<SemiActiveDamper>();
        let s = c.set_integer(&[vr::<SemiActiveDamper>("valve.model")], &[2]);
        assert_eq!(s, Status::Error);
        assert!(logged(&log.take(), Status::Error, "'valve.model'"));
    }

    type A = FullActiveActuator;
    for name in ["cylinder.volume_a0", "oil.bulk_modulus", "cylinder.area_a"] {
        rejected_at_set::<A>(name, -1e-3);
        rejected_at_init::<A>(name, 0.0);
    }
    rejected_at_set::<A>("cylinder.leakage_coefficient", -1e-13);
    // Cross-parameter conditions only the physics knows.
    rejected_at_init::<A>("cylinder.volume_b0", 1e-4); // < A_B h
    {
        // The reason speaks of FMI variables, not of the physics' field names.
        let (mut c, log) = new::<A>();
        set::<A>(&mut c, "cylinder.volume_b0", 1e-4);
        assert_eq!(c.exit_initialization_mode(), Status::Error);
        let msgs = log.take();
        assert!(
            logged(
                &msgs,
                Status::Error,
                "cylinder.area_b * cylinder.half_stroke"
            ),
            "{msgs:?}"
        );
        assert!(!logged(&msgs, Status::Error, "_m2"), "{msgs:?}");
    }
    rejected_at_init::<A>("tank.pressure", 2e7); // >= P_S
}

/// valve.command outside 0..10 V is clamped; the step entering the clamped state warns once.
#[test]
fn out_of_range_command_is_clamped_with_one_warning() {
    type S = SemiActiveDamper;
    let (mut c, log) = init::<S>(&[("damper.elongation_velocity", 0.02)]);
    let mut step = stepper(1e-3);
    assert_eq!(step(&mut c), Status::Ok);
    assert_eq!(set::<S>(&mut c, "valve.command", 12.0), Status::Ok);
    // Ideal valve: the clamped opening shows at once.
    assert_eq!(get::<S>(&mut c, "valve.opening"), 1.0);
    assert!(get_bool::<S>(&mut c, "valve.command_clamped"));
    assert_eq!(step(&mut c), Status::Warning);
    let msgs = log.take();
    assert_eq!(msgs.len(), 1, "{msgs:?}");
    assert!(
        logged(&msgs, Status::Warning, "valve.command = 12 V"),
        "{msgs:?}"
    );
    // Still clamped: no new warning.
    assert_eq!(set::<S>(&mut c, "valve.command", 15.0), Status::Ok);
    assert_eq!(step(&mut c), Status::Ok);
    assert_eq!(step(&mut c), Status::Ok);
    assert!(log.take().is_empty());
    assert_eq!(get::<S>(&mut c, "valve.opening"), 1.0);
    // Back in range, then out again below 0 V: warns again.
    assert_eq!(set::<S>(&mut c, "valve.command", 5.0), Status::Ok);
    assert_eq!(step(&mut c), Status::Ok);
    assert!(!get_bool::<S>(&mut c, "valve.command_clamped"));
    assert_eq!(get::<S>(&mut c, "valve.opening"), 0.5);
    assert_eq!(set::<S>(&mut c, "valve.command", -3.0), Status::Ok);
    assert_eq!(step(&mut c), Status::Warning);
    assert!(logged(&log.take(), Status::Warning, "valve.command = -3 V"));
    assert_eq!(get::<S>(&mut c, "valve.opening"), 0.0);

    // An out-of-range command at the start warns at initialisation.
    let (mut c, log) = new::<S>();
    set::<S>(&mut c, "valve.command", 11.0);
    assert_eq!(c.exit_initialization_mode(), Status::Warning);
    assert!(logged(&log.take(), Status::Warning, "valve.command = 11 V"));
    assert_eq!(c.do_step(0.0, 1e-3), Status::Ok);
}

/// An elongation velocity beyond what a yaw damper sees (100 m/s: mm/s given as m/s) warns on
/// the step entering it, once, and again after it returned into range; the model goes on.
#[test]
fn an_implausible_velocity_warns_once() {
    use fmu_damper::fmu::PLAUSIBLE_VELOCITY_MPS;
    type P = PassiveYawDamper;
    let (mut c, log) = init::<P>(&[]);
    let mut step = stepper(1e-3);
    assert_eq!(step(&mut c), Status::Ok);
    let v = "damper.elongation_velocity";
    assert_eq!(set::<P>(&mut c, v, PLAUSIBLE_VELOCITY_MPS), Status::Ok);
    assert_eq!(step(&mut c), Status::Ok);
    assert_eq!(set::<P>(&mut c, v, 100.0), Status::Ok);
    assert_eq!(step(&mut c), Status::Warning);
    let msgs = log.take();
    assert!(
        logged(
            &msgs,
            Status::Warning,
            "damper.elongation_velocity = 100 m/s"
        ),
        "{msgs:?}"
    );
    assert!(get::<P>(&mut c, "damper.force").is_finite());
    assert_eq!(set::<P>(&mut c, v, -100.0), Status::Ok);
    assert_eq!(step(&mut c), Status::Ok);
    assert!(log.take().is_empty());
    assert_eq!(set::<P>(&mut c, v, 0.1), Status::Ok);
    assert_eq!(step(&mut c), Status::Ok);
    assert_eq!(set::<P>(&mut c, v, -100.0), Status::Ok);
    assert_eq!(step(&mut c), Status::Warning);
}

/// 4 Hz, +-3 mm, 0 % opening (the stiffest case): communication steps 1e-4, 1e-3, 5e-3 s agree
/// within the physics crate's stated 0.5 % of the peak force (input sampled at mid-step), and
/// the steady peak with a plain zero-order hold within 0.5 %.
#[test]
fn communication_step_sizes_agree_at_4_hz() {
    type S = SemiActiveDamper;
    let run = |h: f64, midpoint: bool| -> Vec<f64> {
        let (mut c, _) = init::<S>(&[("damper.elongation_velocity", 0.0)]);
        let (amp, w) = (3e-3, 2.0 * PI * 4.0);
        let n = (1.0 / h).round() as usize;
        let mut f = Vec::with_capacity(n);
        for k in 0..n {
            let t = k as f64 * h;
            let ts = if midpoint { t + 0.5 * h } else { t };
            set::<S>(&mut c, "damper.elongation", amp * (w * ts).sin());
            set::<S>(
                &mut c,
                "damper.elongation_velocity",
                amp * w * (w * ts).cos(),
            );
            assert_eq!(c.do_step(t, h), Status::Ok);
            f.push(get::<S>(&mut c, "damper.force"));
        }
        f
    };
    let steady_peak = |f: &[f64]| f[f.len() / 2..].iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let fine = run(1e-4, true);
    let peak = steady_peak(&fine);
    assert!(peak > 12e3 && peak < 20e3, "R1: {peak}");
    for h in [1e-3, 5e-3] {
        let coarse = run(h, true);
        let ratio = (h / 1e-4).round() as usize;
        let worst = coarse
            .iter()
            .enumerate()
            .map(|(k, f)| (f - fine[(k + 1) * ratio - 1]).abs())
            .fold(0.0f64, f64::max);
        eprintln!(
            "FMU h = {h}: max |dF| = {worst:.2} N ({:.3} % of peak)",
            100.0 * worst / peak
        );
        assert!(worst < 0.005 * peak, "h = {h}: {worst} N vs peak {peak} N");
    }
    for h in [1e-4, 1e-3, 5e-3] {
        let p = steady_peak(&run(h, false));
        eprintln!("FMU ZOH h = {h}: peak {p:.1} N vs {peak:.1} N");
        assert!(
            ((p - peak) / peak).abs() < 0.005,
            "ZOH h = {h}: {p} vs {peak}"
        );
    }

    // Actuator: imposed 4 Hz, +-3 mm, closed valve: load pressure within the physics crate's
    // stated 1 % of its peak.
    type A = FullActiveActuator;
    let run = |h: f64| -> Vec<f64> {
        let (mut c, _) = init::<A>(&[("spool.command", 0.0)]);
        let (amp, w) = (3e-3, 2.0 * PI * 4.0);
        let n = (0.5 / h).round() as usize;
        let mut p = Vec::with_capacity(n);
        for k in 0..n {
            let ts = (k as f64 + 0.5) * h;
            set::<A>(&mut c, "damper.elongation", amp * (w * ts).sin());
            set::<A>(
                &mut c,
                "damper.elongation_velocity",
                amp * w * (w * ts).cos(),
            );
            assert_eq!(c.do_step(k as f64 * h, h), Status::Ok);
            p.push(get::<A>(&mut c, "damper.load_pressure"));
        }
        p
    };
    let fine = run(1e-4);
    let peak = fine.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(peak > 1e6, "{peak}");
    for h in [1e-3, 5e-3] {
        let coarse = run(h);
        let ratio = (h / 1e-4).round() as usize;
        let worst = coarse
            .iter()
            .enumerate()
            .map(|(k, p)| (p - fine[(k + 1) * ratio - 1]).abs())
            .fold(0.0f64, f64::max);
        eprintln!("actuator FMU h = {h}: max |dP_L| = {worst:.1} Pa of {peak:.0} Pa");
        assert!(worst < 0.01 * peak, "h = {h}: {worst} vs {peak}");
    }
}

/// Every output declared without feedthrough stays bit-identical when any input is set without
/// a step; the semi-active force in particular. Declared feedthrough is real for the defaults.
#[test]
fn no_direct_feedthrough_where_none_is_declared() {
    fn check<M: FmuModel>(new_inputs: &[(&str, f64)]) {
        let (mut c, _) = init::<M>(&[]);
        for k in 0..20 {
            assert_eq!(c.do_step(k as f64 * 1e-3, 1e-3), Status::Ok);
        }
        let vars = M::variables();
        let before: Vec<(String, f64)> = real_outputs::<M>()
            .into_iter()
            .map(|n| {
                let x = get::<M>(&mut c, &n);
                (n, x)
            })
            .collect();
        for (name, x) in new_inputs {
            assert!(real_inputs::<M>().iter().any(|n| n == name));
            assert_eq!(set::<M>(&mut c, name, *x), Status::Ok);
        }
        for (n, x) in &before {
            let meta = &vars.iter().find(|v| &v.meta.name == n).unwrap().meta;
            let now = get::<M>(&mut c, n);
            let touched = new_inputs.iter().any(|(i, _)| meta.feedthrough.contains(i));
            if touched {
                assert_ne!(now, *x, "{}: {n} declares feedthrough", M::INFO.name);
            } else {
                assert_eq!(now.to_bits(), x.to_bits(), "{}: {n} changed", M::INFO.name);
            }
        }
    }
    // Velocity only: force, pressure unchanged; power changes.
    check::<SemiActiveDamper>(&[("damper.elongation_velocity", -0.3)]);
    check::<SemiActiveDamper>(&[("damper.elongation", 0.01)]);
    check::<SemiActiveDamper>(&[("valve.command", 7.0)]);
    check::<PassiveYawDamper>(&[
        ("damper.elongation_velocity", -0.3),
        ("damper.elongation", 0.01),
    ]);
    check::<FullActiveActuator>(&[("damper.elongation", 0.01)]);
    check::<FullActiveActuator>(&[("damper.elongation_velocity", -0.05)]);
    // Full order: spool.command reaches outputs through the spool state only, so the declared
    // feedthrough is checked with the reduced-order model below.
    let (mut c, _) = init::<FullActiveActuator>(&[]);
    let before = get::<FullActiveActuator>(&mut c, "spool.position");
    assert_eq!(
        set::<FullActiveActuator>(&mut c, "spool.command", -0.7e-3),
        Status::Ok
    );
    assert_eq!(get::<FullActiveActuator>(&mut c, "spool.position"), before);
    let (mut c, _) = new::<FullActiveActuator>();
    assert_eq!(
        c.set_integer(&[vr::<FullActiveActuator>("actuator.model")], &[1]),
        Status::Ok
    );
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    let f = get::<FullActiveActuator>(&mut c, "damper.force");
    assert_eq!(
        set::<FullActiveActuator>(&mut c, "spool.command", -0.7e-3),
        Status::Ok
    );
    assert_eq!(get::<FullActiveActuator>(&mut c, "spool.position"), -0.7e-3);
    assert_eq!(get::<FullActiveActuator>(&mut c, "damper.force"), f);

    // The semi-active force, explicitly: set a new velocity, no step -> same force.
    let (mut c, _) = init::<SemiActiveDamper>(&[]);
    assert_eq!(c.do_step(0.0, 0.01), Status::Ok);
    let f = get::<SemiActiveDamper>(&mut c, "damper.force");
    assert!(f > 1e3);
    assert_eq!(
        set::<SemiActiveDamper>(&mut c, "damper.elongation_velocity", -0.5),
        Status::Ok
    );
    assert_eq!(get::<SemiActiveDamper>(&mut c, "damper.force"), f);
    assert_eq!(c.do_step(0.01, 1e-3), Status::Ok);
    assert!(get::<SemiActiveDamper>(&mut c, "damper.force") < f);
}

/// A positive spool command feeds chamber A and pushes the rod out: it decreases the tension.
/// A force loop u = s k_p (F_ref - F) on the actuator therefore converges with s = -1 and runs
/// away to the saturation with s = +1.
#[test]
fn positive_spool_command_decreases_tension() {
    type A = FullActiveActuator;
    for (u, sign) in [(0.6e-3, -1.0), (-0.6e-3, 1.0)] {
        let (mut c, _) = init::<A>(&[("spool.command", u)]);
        for k in 0..400 {
            assert_eq!(c.do_step(k as f64 * 1e-3, 1e-3), Status::Ok);
        }
        let f = get::<A>(&mut c, "damper.force");
        assert!(sign * f > 20e3, "u = {u}: force {f}");
    }
    let p = FullActiveActuator::default_params();
    let (k_p, f_ref) = (3e-7, 5e3);
    for (command_sign, converges) in [(-1.0, true), (1.0, false)] {
        let (mut c, _) = init::<A>(&[("spool.command", 0.0)]);
        let h = 1e-3;
        let mut f = get::<A>(&mut c, "damper.force");
        for k in 0..300 {
            let u = (command_sign * k_p * (f_ref - f)).clamp(-p.alpha_m, p.alpha_m);
            set::<A>(&mut c, "spool.command", u);
            assert_eq!(c.do_step(k as f64 * h, h), Status::Ok);
            f = get::<A>(&mut c, "damper.force");
        }
        // Inside the dead zone band |F_ref - F| < beta / k_p the loop stops correcting.
        let band = p.beta_m / k_p;
        if converges {
            assert!((f - f_ref).abs() <= 1.05 * band, "sign {command_sign}: {f}");
        } else {
            assert!(f < -20e3, "sign {command_sign}: {f}");
        }
    }
}

/// FMU state serialisation round trip continues bit for bit (Option<physics> inside).
#[test]
fn serialised_state_continues_identically() {
    let (mut c, _) = init::<SemiActiveDamper>(&[("valve.command", 3.0)]);
    for k in 0..10 {
        assert_eq!(c.do_step(k as f64 * 1e-3, 1e-3), Status::Ok);
    }
    let snap = c.get_fmu_state().unwrap();
    let bytes = c.serialize_fmu_state(&snap).unwrap();
    let run = |c: &mut Component| {
        let mut f = Vec::new();
        for k in 10..30 {
            assert_eq!(c.do_step(k as f64 * 1e-3, 1e-3), Status::Ok);
            f.push(get::<SemiActiveDamper>(c, "damper.force"));
        }
        f
    };
    let a = run(&mut c);
    let restored = c.deserialize_fmu_state(&bytes).unwrap();
    assert_eq!(c.set_fmu_state(&restored), Status::Ok);
    let b = run(&mut c);
    assert_eq!(a, b);
}

/// A serialised state is refused when the physics inside it was not built from its declared
/// parameters (bytes forged with a valid checksum): it would reach the physics otherwise.
#[test]
fn a_forged_state_whose_physics_disagrees_with_its_parameters_is_refused() {
    fn check<M: FmuModel>(parameter: &str, marker: f64) {
        let (mut c, log) = init::<M>(&[(parameter, marker)]);
        let state = c.get_fmu_state().unwrap();
        let bytes = c.serialize_fmu_state(&state).unwrap();
        assert!(c.deserialize_fmu_state(&bytes).is_ok());
        let at: Vec<usize> = bytes
            .windows(8)
            .enumerate()
            .filter(|(_, w)| *w == marker.to_le_bytes())
            .map(|(k, _)| k)
            .collect();
        // the declared value and the physics' copy
        assert_eq!(at.len(), 2, "{parameter}");
        let forge = |at: &[usize], value: f64| {
            let mut forged = bytes.clone();
            for &k in at {
                forged[k..k + 8].copy_from_slice(&value.to_le_bytes());
            }
            model_description::testing::reseal_state(&mut forged);
            forged
        };
        // one copy altered, or both set to 0 (in the declared range, which admits 0, but
        // not a value the physics takes)
        let cases = [
            (&at[..1], 1.5 * marker),
            (&at[1..], 1.5 * marker),
            (&at[..], 0.0),
        ];
        for (copies, value) in cases {
            let forged = forge(copies, value);
            assert!(
                c.deserialize_fmu_state(&forged).is_err(),
                "{parameter} {copies:?}"
            );
            assert!(
                logged(&log.take(), Status::Error, "does not hold together"),
                "{parameter}"
            );
        }
        // both altered alike to another valid value: a state the parameters can give
        assert!(c.deserialize_fmu_state(&forge(&at, 1.5 * marker)).is_ok());
    }
    check::<FullActiveActuator>("supply.pressure", 10.123_456_7e6);
    check::<SemiActiveDamper>("damper.bulk_modulus", 1.234_567_89e9);
    check::<PassiveYawDamper>("damper.bulk_modulus", 1.234_567_89e9);
}
