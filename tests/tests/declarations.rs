//! Every FMU's declaration, checked the same way for all ten models (driven from Rust through
//! the glue's state machine, the same path as the C API):
//! - the default experiment is a whole number of steps in floating point (strict hosts refuse
//!   0.3 s / 1e-4 s);
//! - every declared variable round-trips through set/get (parameters, inputs) or can be read
//!   (outputs), so each declaration line binds a real field in both directions;
//! - every parameter error the physics raises is reported under a declared FMI variable, and
//!   a single bad parameter is reported under its own name.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use model_description::xml::{check_declaration, value_references, StartValue};
use model_description::{
    rust_component, Causality, Component, FmuModel, InstanceContext, Status, VarType,
};

fn metas<M: FmuModel>() -> Vec<model_description::variable::VarMeta> {
    M::variables().into_iter().map(|v| v.meta).collect()
}

/// Runs `f` for each of the ten models.
macro_rules! for_each_model {
    ($f:ident) => {
        $f::<fmu_examples::MassSpring>();
        $f::<fmu_examples::SpringDamperMass>();
        $f::<fmu_damper::fmu::SemiActiveDamper>();
        $f::<fmu_damper::fmu::PassiveYawDamper>();
        $f::<fmu_damper::fmu::FullActiveActuator>();
        $f::<fmu_controller::fmu::MpptController>();
        $f::<fmu_controller::fmu::SkyHookController>();
        $f::<fmu_controller::fmu::IdealDamperForceController>();
        $f::<fmu_bogie2dof::fmu::Bogie2Dof>();
        $f::<fmu_vehicle::fmu::RailVehicle>();
    };
}

fn exact_default_experiment<M: FmuModel>() {
    let de = M::INFO.default_experiment;
    let (duration, step) = (de.stop_time - de.start_time, de.step_size);
    let n = (duration / step).round();
    assert_eq!(de.start_time, 0.0, "{}", M::INFO.name);
    assert!(
        de.stop_time / step == n && n * step == de.stop_time,
        "{}: stop {} is not a whole number of {} s steps ({})",
        M::INFO.name,
        de.stop_time,
        step,
        de.stop_time / step
    );
}

#[test]
fn default_experiments_are_whole_numbers_of_steps() {
    for_each_model!(exact_default_experiment);
}

/// A value other than the start value that the declaration accepts.
fn other_real(start: f64, min: Option<f64>, max: Option<f64>) -> f64 {
    let candidates = [
        start * 0.5,
        start * 1.5,
        start + 0.25,
        start - 0.25,
        0.5 * (min.unwrap_or(0.0) + max.unwrap_or(1.0)),
        0.5 * (start + max.unwrap_or(start + 1.0)),
    ];
    candidates
        .into_iter()
        .find(|x| *x != start && min.is_none_or(|lo| *x >= lo) && max.is_none_or(|hi| *x <= hi))
        .unwrap_or_else(|| panic!("no test value for start {start} in [{min:?}, {max:?}]"))
}

fn round_trip<M: FmuModel>() {
    let name = M::INFO.name;
    let vars = M::variables();
    let starts = check_declaration::<M>(&vars).unwrap();
    let vrs = value_references(&vars);
    let (mut c, log) = rust_component::<M>(InstanceContext::default()).unwrap();
    let mut expected: Vec<Option<StartValue>> = Vec::new();
    for ((v, start), &vr) in vars.iter().zip(&starts).zip(&vrs) {
        let m = &v.meta;
        if !m.causality.is_settable() {
            expected.push(None);
            continue;
        }
        let value = match start.clone().unwrap() {
            StartValue::Real(x) => {
                let y = other_real(x, m.min, m.max);
                assert_eq!(c.set_real(&[vr], &[y]), Status::Ok, "{name}: {}", m.name);
                StartValue::Real(y)
            }
            StartValue::Integer(n) => {
                let y = match m.enumeration {
                    Some(e) => e.items.iter().map(|i| i.value).find(|&i| i != n).unwrap(),
                    None => {
                        let (lo, hi) = (m.min.unwrap_or(-1e9), m.max.unwrap_or(1e9));
                        [n - 1, n + 1]
                            .into_iter()
                            .find(|&y| f64::from(y) >= lo && f64::from(y) <= hi)
                            .unwrap()
                    }
                };
                assert_eq!(c.set_integer(&[vr], &[y]), Status::Ok, "{name}: {}", m.name);
                StartValue::Integer(y)
            }
            StartValue::Boolean(b) => {
                assert_eq!(
                    c.set_boolean(&[vr], &[!b]),
                    Status::Ok,
                    "{name}: {}",
                    m.name
                );
                StartValue::Boolean(!b)
            }
            StartValue::String(_) => {
                assert_eq!(
                    c.set_string(&[vr], &["round-trip value"]),
                    Status::Ok,
                    "{name}: {}",
                    m.name
                );
                StartValue::String("round-trip value".into())
            }
        };
        expected.push(Some(value));
    }
    assert_eq!(c.enter_initialization_mode(), Status::Ok, "{name}");
    let mut read = 0;
    for ((v, want), &vr) in vars.iter().zip(&expected).zip(&vrs) {
        let m = &v.meta;
        let got = match m.var_type {
            VarType::Real => {
                let mut x = [f64::NAN];
                assert!(
                    c.get_real(&[vr], &mut x) <= Status::Warning,
                    "{name}: {}",
                    m.name
                );
                assert!(x[0].is_finite(), "{name}: {} = {}", m.name, x[0]);
                StartValue::Real(x[0])
            }
            VarType::Integer => {
                let mut x = [0];
                assert!(c.get_integer(&[vr], &mut x) <= Status::Warning);
                StartValue::Integer(x[0])
            }
            VarType::Boolean => {
                let mut x = [false];
                assert!(c.get_boolean(&[vr], &mut x) <= Status::Warning);
                StartValue::Boolean(x[0])
            }
            VarType::String => {
                let mut x = [String::new()];
                assert!(c.get_string(&[vr], &mut x) <= Status::Warning);
                StartValue::String(x[0].clone())
            }
        };
        if let Some(want) = want {
            assert_eq!(&got, want, "{name}: {} did not round-trip", m.name);
        }
        read += 1;
    }
    assert_eq!(read, vars.len());
    assert!(
        !log.take().iter().any(|(s, _, _)| *s >= Status::Error),
        "{name}: a set or get failed"
    );
}

#[test]
fn every_declared_variable_round_trips() {
    for_each_model!(round_trip);
}

/// The variable named by the first "invalid parameter '...'" / "invalid input '...'" message.
fn named_variable(log: &[(Status, String, String)]) -> Option<String> {
    log.iter().find_map(|(_, _, m)| {
        ["invalid parameter '", "invalid input '"]
            .iter()
            .find_map(|p| {
                let start = m.find(p)? + p.len();
                let len = m[start..].find('\'')?;
                Some(m[start..start + len].to_string())
            })
    })
}

/// Initialise with `set` applied; `Some((named variable, message))` if initialisation was
/// refused.
fn refused_by<M: FmuModel>(set: impl FnOnce(&mut Component) -> Status) -> Option<(String, String)> {
    let (mut c, log) = rust_component::<M>(InstanceContext::default()).unwrap();
    if set(&mut c) != Status::Ok {
        // The glue refused the value itself (range, enumeration): not a physics check.
        return None;
    }
    assert_eq!(c.enter_initialization_mode(), Status::Ok);
    if c.exit_initialization_mode() <= Status::Warning {
        return None;
    }
    let log = log.take();
    let named = named_variable(&log);
    assert!(
        named.is_some(),
        "{}: refused without naming a variable: {log:?}",
        M::INFO.name
    );
    let text = log
        .iter()
        .map(|(_, _, m)| m.as_str())
        .collect::<Vec<_>>()
        .join(" | ");
    named.map(|n| (n, text))
}

/// Values that pass the declared bounds but may fail the physics' own checks.
fn suspicious_reals(start: f64, min: Option<f64>, max: Option<f64>) -> Vec<f64> {
    let mut v = vec![0.0, start * 1e6, start * 1e-6, -start, 1e12, -1e12];
    v.extend(min);
    v.extend(max);
    v.retain(|x| min.is_none_or(|lo| *x >= lo) && max.is_none_or(|hi| *x <= hi) && *x != start);
    v
}

/// Every single-parameter rejection names the parameter that was set; returns how many
/// parameters have a reachable validation path.
fn single_parameter_errors<M: FmuModel>() -> usize {
    let name = M::INFO.name;
    let vars = M::variables();
    let starts = check_declaration::<M>(&vars).unwrap();
    let vrs = value_references(&vars);
    let declared: Vec<String> = metas::<M>().into_iter().map(|m| m.name).collect();
    let mut checked = 0;
    for ((v, start), &vr) in vars.iter().zip(&starts).zip(&vrs) {
        let m = &v.meta;
        if m.causality != Causality::Parameter {
            continue;
        }
        let mut named = Vec::new();
        match start.clone().unwrap() {
            StartValue::Real(x) => {
                for y in suspicious_reals(x, m.min, m.max) {
                    named.extend(refused_by::<M>(|c| c.set_real(&[vr], &[y])));
                }
            }
            StartValue::Integer(_) if m.enumeration.is_none() => {
                for y in [0, -1, 1, i32::MAX] {
                    named.extend(refused_by::<M>(|c| c.set_integer(&[vr], &[y])));
                }
            }
            StartValue::String(_) => {
                named.extend(refused_by::<M>(|c| {
                    c.set_string(&[vr], &["/nonexistent/table.csv"])
                }));
            }
            _ => {}
        }
        for (n, text) in &named {
            assert!(
                declared.contains(n),
                "{name}: error names '{n}', not a variable"
            );
            // Either under its own name, or a cross-parameter condition that says it is
            // about this parameter too ("must exceed cylinder.area_a * cylinder.half_stroke").
            assert!(
                n == &m.name || text.contains(&m.name),
                "{name}: a bad {} is reported as '{n}': {text}",
                m.name
            );
        }
        if !named.is_empty() {
            checked += 1;
        }
    }
    checked
}

/// Cross-parameter checks: each is reported under one of the parameters involved.
fn cross_parameter_error<M: FmuModel>(sets: &[(&str, f64)], expected: &[&str]) {
    let named = refused_by::<M>(|c| {
        let mut s = Status::Ok;
        for (n, x) in sets {
            let vr = model_description::value_reference::<M>(n).unwrap();
            let meta = metas::<M>().into_iter().find(|m| m.name == *n).unwrap();
            s = s.max(match meta.var_type {
                VarType::Integer => c.set_integer(&[vr], &[*x as i32]),
                _ => c.set_real(&[vr], &[*x]),
            });
        }
        s
    });
    let (named, _) = named.unwrap_or_else(|| panic!("{}: {sets:?} was accepted", M::INFO.name));
    assert!(
        expected.contains(&named.as_str()),
        "{}: {sets:?} reported as '{named}'",
        M::INFO.name
    );
}

#[test]
fn every_parameter_error_names_a_declared_variable() {
    use fmu_bogie2dof::fmu::Bogie2Dof;
    use fmu_controller::fmu::{IdealDamperForceController, MpptController, SkyHookController};
    use fmu_damper::fmu::{FullActiveActuator, PassiveYawDamper, SemiActiveDamper};
    use fmu_examples::{MassSpring, SpringDamperMass};
    use fmu_vehicle::fmu::RailVehicle;
    // The examples' declared bounds refuse every bad value when it is set: no value within
    // them reaches a validation error at initialisation.
    assert_eq!(single_parameter_errors::<MassSpring>(), 0, "MassSpring");
    assert_eq!(
        single_parameter_errors::<SpringDamperMass>(),
        0,
        "SpringDamperMass"
    );
    // How many parameters have a validation path reachable with one value (at least).
    let counts = [
        (
            "SemiActiveDamper",
            single_parameter_errors::<SemiActiveDamper>(),
            10,
        ),
        (
            "PassiveYawDamper",
            single_parameter_errors::<PassiveYawDamper>(),
            7,
        ),
        (
            "FullActiveActuator",
            single_parameter_errors::<FullActiveActuator>(),
            18,
        ),
        // band_pass.order and hill_climb.initial_direction are Enumerations: refused when set
        (
            "MpptController",
            single_parameter_errors::<MpptController>(),
            10,
        ),
        // sensor.sign is an Enumeration: 0 is refused when set
        (
            "SkyHookController",
            single_parameter_errors::<SkyHookController>(),
            22,
        ),
        // board.sample_time is refused when set (declared minimum), not at initialisation, and
        // force_loop.command_sign is an Enumeration
        (
            "IdealDamperForceController",
            single_parameter_errors::<IdealDamperForceController>(),
            1,
        ),
        ("Bogie2Dof", single_parameter_errors::<Bogie2Dof>(), 14),
        ("RailVehicle", single_parameter_errors::<RailVehicle>(), 20),
    ];
    for (model, n, at_least) in counts {
        eprintln!("{model}: {n} parameters with a reachable validation error");
        assert!(n >= at_least, "{model}: only {n} validation paths reached");
    }
    // Checks that involve two parameters (or a parameter and a table element).
    cross_parameter_error::<FullActiveActuator>(
        &[("tank.pressure", 2e7)],
        &["tank.pressure", "supply.pressure"],
    );
    cross_parameter_error::<FullActiveActuator>(
        &[("cylinder.volume_a0", 1e-4)],
        &["cylinder.volume_a0"],
    );
    cross_parameter_error::<SemiActiveDamper>(
        &[("damper.piston_flow_coefficient", 0.0), ("valve.area", 0.0)],
        &["damper.piston_flow_coefficient", "valve.area"],
    );
    cross_parameter_error::<MpptController>(
        &[("valve.command_min", 8.0), ("valve.command_max", 2.0)],
        &["valve.command_min", "valve.command_max"],
    );
    cross_parameter_error::<MpptController>(
        &[("band_pass.low", 9.0), ("band_pass.high", 3.0)],
        &["band_pass.low", "band_pass.high"],
    );
    cross_parameter_error::<MpptController>(
        &[("hill_climb.period", 0.0015)],
        &["hill_climb.period", "board.sample_time"],
    );
    cross_parameter_error::<SkyHookController>(
        &[("damping.min", 4e5), ("damping.max", 1e5)],
        &["damping.min", "damping.max"],
    );
    cross_parameter_error::<SkyHookController>(
        &[("table.opening[3]", 0.05)],
        &["table.opening[3]"],
    );
    cross_parameter_error::<SkyHookController>(&[("table.damping[4]", 5e5)], &["table.damping[4]"]);
    cross_parameter_error::<RailVehicle>(
        &[("geometry.half_wheelbase", 5.0)],
        &["geometry.half_wheelbase"],
    );
}

fn state_round_trip<M: FmuModel>() {
    let name = M::INFO.name;
    let de = M::INFO.default_experiment;
    let (mut c, log) = rust_component::<M>(InstanceContext::default()).unwrap();
    let check = |c: &mut Component, when: &str| {
        let snap = c.get_fmu_state().ok().unwrap();
        let bytes = c.serialize_fmu_state(&snap).ok().unwrap();
        assert!(
            c.deserialize_fmu_state(&bytes).is_ok(),
            "{name}: the state {when} does not deserialise: {:?}",
            log.take()
        );
    };
    check(&mut c, "after instantiation");
    assert_eq!(
        c.setup_experiment(de.start_time, Some(de.stop_time)),
        Status::Ok
    );
    assert_eq!(c.enter_initialization_mode(), Status::Ok);
    assert!(c.exit_initialization_mode() <= Status::Warning);
    check(&mut c, "after initialisation");
    for k in 0..200 {
        let t = de.start_time + k as f64 * de.step_size;
        assert!(c.do_step(t, de.step_size) <= Status::Warning, "{name}");
    }
    check(&mut c, "after 200 steps");
}

/// The deserialiser refuses non-finite numbers: no model may hold one in a legitimate state.
#[test]
fn every_model_state_passes_the_deserialisation_checks() {
    for_each_model!(state_round_trip);
}

fn passes_the_masters_checks<M: FmuModel>() {
    let d = model_description::xml::model_description::<M>().unwrap();
    let md = master::model_description::ModelDescription::parse(&d.xml)
        .unwrap_or_else(|e| panic!("{}: {e}", M::INFO.name));
    assert_eq!(md.guid, d.guid);
    assert_eq!(md.variables.len(), metas::<M>().len());
}

#[test]
fn every_model_description_passes_the_masters_fmi2_checks() {
    // the master refuses what FMI 2.0 forbids (causality/variability/initial table, start
    // values, aliases, structured names): our own FMUs must pass it
    for_each_model!(passes_the_masters_checks);
}
