//! The FMI 2.0 glue through the real C ABI of a packaged FMU (dist/MassSpring.fmu and
//! dist/SpringDamperMass.fmu), as any third-party host drives it.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tests::*;

fn fmu() -> TestFmu {
    TestFmu::open_dist("MassSpring").expect("dist/MassSpring.fmu")
}

fn run(inst: &Instance, t0: f64, n: usize, h: f64) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        let t = t0 + k as f64 * h;
        // A force that depends on time, set every step like a coupled host would.
        assert_eq!(inst.set_real("force", (3.0 * t).sin()), OK);
        assert_eq!(inst.do_step(t, h), OK);
        let (s1, x) = inst.get_real("position");
        let (s2, v) = inst.get_real("velocity");
        assert_eq!((s1, s2), (OK, OK));
        out.push((x, v));
    }
    out
}

#[test]
fn wrong_call_order_is_an_error_with_a_message() {
    let f = fmu();
    let inst = f.instantiate("a").unwrap();
    assert_eq!(inst.do_step(0.0, 0.01), ERROR);
    assert!(
        inst.messages()
            .iter()
            .any(|m| m.contains("fmi2DoStep is not allowed in state Instantiated")),
        "{:?}",
        inst.messages()
    );
    // Getting before initialisation is not allowed either.
    assert_eq!(inst.get_real("position").0, ERROR);
    assert_eq!(inst.exit_init(), ERROR);
    assert_eq!(inst.initialize(0.0), OK);
    // A fixed parameter cannot change after initialisation.
    assert_eq!(inst.set_real("mass", 2.0), ERROR);
    assert!(inst
        .messages()
        .iter()
        .any(|m| m.contains("'mass' is a fixed parameter")));
    assert_eq!(inst.get_real("mass"), (OK, 1.0));
    // An output cannot be set.
    assert_eq!(inst.set_real("position", 1.0), ERROR);
    // Unknown value reference.
    assert_eq!(inst.get_real_vr(999).0, ERROR);
    assert!(inst
        .messages()
        .iter()
        .any(|m| m.contains("unknown value reference 999")));
    // The instance is still usable after rejected calls: they changed nothing.
    assert_eq!(inst.do_step(0.0, 0.01), OK);
}

#[test]
fn bad_values_are_rejected_and_change_nothing() {
    let f = fmu();
    let inst = f.instantiate("a").unwrap();
    assert_eq!(inst.setup(0.0, None), OK);
    assert_eq!(inst.enter_init(), OK);
    assert_eq!(inst.set_real("mass", -1.0), ERROR, "below min");
    assert!(inst
        .messages()
        .iter()
        .any(|m| m.contains("outside its range")));
    assert_eq!(inst.set_real("force", f64::NAN), ERROR);
    assert!(inst
        .messages()
        .iter()
        .any(|m| m.contains("'force' = NaN is not a finite number")));
    assert_eq!(inst.set_real("force", f64::INFINITY), ERROR);
    // Several values in one call: one bad value rejects the whole call.
    let vrs = [inst.vr("force"), inst.vr("mass")];
    let vals = [5.0, -3.0];
    let s = unsafe {
        inst.b()
            .fmi2SetReal(inst.component, vrs.as_ptr(), 2, vals.as_ptr())
    };
    assert_eq!(s, ERROR);
    assert_eq!(inst.get_real("force"), (OK, 0.0));
    assert_eq!(inst.get_real("mass"), (OK, 1.0));
    // Null pointers.
    let s = unsafe {
        inst.b()
            .fmi2SetReal(inst.component, std::ptr::null(), 1, vals.as_ptr())
    };
    assert_eq!(s, ERROR);
    let s = unsafe { inst.b().fmi2DoStep(std::ptr::null_mut(), 0.0, 0.1, 1) };
    assert_eq!(s, ERROR);
}

/// Whatever fmi2GetReal returns with fmi2OK is finite: an output that overflows (here a
/// coupling force of 1e300 N/m times 1e300 m) is an error naming it, and the instance goes on
/// once the input is sane again.
#[test]
fn an_output_that_is_not_finite_is_an_error_naming_it() {
    let f = TestFmu::open_dist("SpringDamperMass").expect("dist/SpringDamperMass.fmu");
    let inst = f.instantiate("overflow").unwrap();
    assert_eq!(inst.set_real("coupling_stiffness", 1e300), OK);
    assert_eq!(inst.initialize(0.0), OK);
    assert_eq!(inst.set_real("input_position", 1e300), OK);
    let (status, value) = inst.get_real("coupling_force");
    assert_eq!(status, ERROR, "{value}");
    assert!(
        inst.messages()
            .iter()
            .any(|m| m.contains("'coupling_force' is -inf") && m.contains("cannot compute")),
        "{:?}",
        inst.messages()
    );
    assert_eq!(inst.set_real("input_position", 1e-3), OK);
    let (status, value) = inst.get_real("coupling_force");
    assert_eq!(status, OK);
    assert!((value.abs() - 1e297).abs() < 1e285, "{value}");
    assert_eq!(inst.set_real("input_position", 0.0), OK);
    assert_eq!(inst.get_real("coupling_force"), (OK, 0.0));
    assert_eq!(inst.do_step(0.0, 1e-3), OK);
}

#[test]
fn invalid_parameter_is_reported_at_initialisation() {
    let f = TestFmu::open_dist("SpringDamperMass").unwrap();
    let inst = f.instantiate("p").unwrap();
    assert_eq!(inst.setup(0.0, None), OK);
    assert_eq!(inst.enter_init(), OK);
    // mass has min 1e-9 in the XML; zero is caught by the range check.
    assert_eq!(inst.set_real("mass", 0.0), ERROR);
    assert!(inst.messages().iter().any(|m| m.contains("'mass'")));
}

#[test]
fn logger_gets_environment_category_and_percent_s() {
    let f = fmu();
    let inst = f.instantiate("logging instance").unwrap();
    assert_eq!(inst.do_step(0.0, 0.01), ERROR);
    let records = inst.records();
    assert!(!records.is_empty());
    for r in &records {
        assert_eq!(r.env, inst.env_ptr(), "componentEnvironment passed back");
        assert_eq!(r.instance, "logging instance");
        assert_eq!(r.format.as_deref(), Some("%s"), "message as a %s argument");
        let cat = r.category.as_deref().expect("non-null category");
        assert!(f
            .model_description
            .contains(&format!("Category name=\"{cat}\"")));
    }
}

#[test]
fn unknown_guid_is_refused_with_a_message() {
    let f = fmu();
    let wrong = "{00000000-0000-0000-0000-000000000000}";
    let err = f
        .instantiate_with_guid("g", wrong)
        .err()
        .expect("must fail");
    assert!(err.contains("matches none of the models"), "{err}");
    // the binary works its GUIDs out once: a right one after a wrong one is accepted, and a
    // wrong one after a right one is still refused
    let right = f.instantiate("r").expect("the model's own GUID");
    assert!(f.instantiate_with_guid("g2", wrong).is_err());
    drop(right);
}

#[test]
fn fmu_state_restores_a_run_bit_for_bit() {
    let f = fmu();
    let inst = f.instantiate("s").unwrap();
    assert_eq!(inst.initialize(0.0), OK);
    let h = 1.0e-3;
    run(&inst, 0.0, 500, h);
    let mut state: ffi::fmi2FMUstate = std::ptr::null_mut();
    assert_eq!(
        unsafe { inst.b().fmi2GetFMUstate(inst.component, &mut state) },
        OK
    );
    let first = run(&inst, 0.5, 500, h);
    assert_eq!(
        unsafe { inst.b().fmi2SetFMUstate(inst.component, state) },
        OK
    );
    let second = run(&inst, 0.5, 500, h);
    assert_eq!(first, second, "restored run continues bit for bit");

    // Serialise, continue elsewhere, deserialise into a new state and restore.
    let mut size = 0usize;
    assert_eq!(
        unsafe {
            inst.b()
                .fmi2SerializedFMUstateSize(inst.component, state, &mut size)
        },
        OK
    );
    let mut bytes = vec![0 as std::os::raw::c_char; size];
    assert_eq!(
        unsafe {
            inst.b()
                .fmi2SerializeFMUstate(inst.component, state, bytes.as_mut_ptr(), size)
        },
        OK
    );
    // A second instance restores the serialised state and continues identically.
    let other = f.instantiate("t").unwrap();
    assert_eq!(other.initialize(0.0), OK);
    let mut state2: ffi::fmi2FMUstate = std::ptr::null_mut();
    assert_eq!(
        unsafe {
            other
                .b()
                .fmi2DeSerializeFMUstate(other.component, bytes.as_ptr(), size, &mut state2)
        },
        OK
    );
    assert_eq!(
        unsafe { other.b().fmi2SetFMUstate(other.component, state2) },
        OK
    );
    let third = run(&other, 0.5, 500, h);
    assert_eq!(first, third, "deserialised state continues bit for bit");
    // Garbage is refused with a message.
    let garbage = [1 as std::os::raw::c_char; 7];
    let mut state3: ffi::fmi2FMUstate = std::ptr::null_mut();
    assert_eq!(
        unsafe {
            other
                .b()
                .fmi2DeSerializeFMUstate(other.component, garbage.as_ptr(), 7, &mut state3)
        },
        ERROR
    );
    unsafe {
        assert_eq!(inst.b().fmi2FreeFMUstate(inst.component, &mut state), OK);
        assert_eq!(other.b().fmi2FreeFMUstate(other.component, &mut state2), OK);
    }
    assert!(state.is_null());
}

#[test]
fn two_instances_in_two_threads_match_sequential_runs() {
    let f = fmu();
    let go = |mass: f64| {
        let inst = f.instantiate(&format!("m{mass}")).unwrap();
        assert_eq!(inst.setup(0.0, None), OK);
        assert_eq!(inst.enter_init(), OK);
        assert_eq!(inst.set_real("mass", mass), OK);
        assert_eq!(inst.exit_init(), OK);
        run(&inst, 0.0, 3000, 1.0e-3)
    };
    let seq_a = go(1.0);
    let seq_b = go(2.5);
    let (par_a, par_b) = std::thread::scope(|s| {
        let a = s.spawn(|| go(1.0));
        let b = s.spawn(|| go(2.5));
        (a.join().unwrap(), b.join().unwrap())
    });
    assert_eq!(seq_a, par_a);
    assert_eq!(seq_b, par_b);
    assert_ne!(seq_a, seq_b);
}

#[test]
fn reset_returns_to_the_just_instantiated_state() {
    let f = fmu();
    let fresh = {
        let inst = f.instantiate("fresh").unwrap();
        assert_eq!(inst.initialize(0.0), OK);
        run(&inst, 0.0, 300, 1.0e-3)
    };
    let inst = f.instantiate("reused").unwrap();
    assert_eq!(inst.setup(0.0, None), OK);
    assert_eq!(inst.enter_init(), OK);
    assert_eq!(inst.set_real("mass", 3.0), OK);
    assert_eq!(inst.set_real("initial_position", 0.5), OK);
    assert_eq!(inst.exit_init(), OK);
    run(&inst, 0.0, 100, 1.0e-3);
    assert_eq!(inst.reset(), OK);
    // Just instantiated again: stepping is a state error, getters are not allowed yet.
    assert_eq!(inst.do_step(0.1, 1.0e-3), ERROR);
    assert_eq!(inst.initialize(0.0), OK);
    assert_eq!(inst.get_real("mass"), (OK, 1.0), "defaults restored");
    assert_eq!(run(&inst, 0.0, 300, 1.0e-3), fresh);
}

#[test]
fn drifting_communication_points_and_tiny_final_steps_are_accepted() {
    let f = fmu();
    let inst = f.instantiate("drift").unwrap();
    assert_eq!(inst.setup(0.0, Some(1.0)), OK);
    assert_eq!(inst.enter_init(), OK);
    assert_eq!(inst.exit_init(), OK);
    let mut t = 0.0;
    let h = 0.1;
    for _ in 0..10 {
        assert_eq!(inst.do_step(t, h), OK, "t = {t:.17}");
        t += h; // accumulates rounding error, as many hosts do
    }
    // A tiny extra step close to the stop time.
    assert_eq!(inst.do_step(t, 1.0e-11), OK);
    // A step far from the instance time is refused.
    assert_eq!(inst.do_step(0.5, 0.1), ERROR);
    // Past the stop time is refused.
    assert_eq!(inst.do_step(t + 1.0e-11, 0.5), ERROR);
    let mut last = 0.0;
    assert_eq!(
        unsafe {
            inst.b().fmi2GetRealStatus(
                inst.component,
                ffi::fmi2StatusKind_fmi2LastSuccessfulTime,
                &mut last,
            )
        },
        OK
    );
    assert!((last - 1.0).abs() < 1e-9, "{last}");
    assert_eq!(inst.terminate(), OK);
    assert_eq!(inst.do_step(last, 0.1), ERROR);
}

#[test]
fn direct_feedthrough_is_declared_and_others_are_empty() {
    let f = TestFmu::open_dist("SpringDamperMass").unwrap();
    let md = &f.model_description;
    // coupling_force (index 10) depends on the two inputs (indices 8, 9); position does not.
    assert!(
        md.contains(r#"<Unknown index="10" dependencies="8 9"/>"#),
        "{md}"
    );
    assert!(md.contains(r#"<Unknown index="11" dependencies=""/>"#));
    // Feedthrough is real: setting the input changes the output without a step.
    let inst = f.instantiate("ft").unwrap();
    assert_eq!(inst.initialize(0.0), OK);
    let (_, f0) = inst.get_real("coupling_force");
    assert_eq!(inst.set_real("input_position", 0.01), OK);
    let (_, f1) = inst.get_real("coupling_force");
    assert!((f1 - f0 + 50.0 * 0.01).abs() < 1e-12, "{f0} {f1}");
}

#[test]
fn unsupported_functions_return_error_with_message() {
    let f = fmu();
    let inst = f.instantiate("u").unwrap();
    assert_eq!(inst.initialize(0.0), OK);
    assert_eq!(unsafe { inst.b().fmi2CancelStep(inst.component) }, ERROR);
    let vr = [inst.vr("force")];
    let order = [1];
    let val = [1.0];
    assert_eq!(
        unsafe {
            inst.b().fmi2SetRealInputDerivatives(
                inst.component,
                vr.as_ptr(),
                1,
                order.as_ptr(),
                val.as_ptr(),
            )
        },
        ERROR
    );
    assert!(inst
        .messages()
        .iter()
        .any(|m| m.contains("canInterpolateInputs = false")));
    let platform = unsafe { std::ffi::CStr::from_ptr(inst.b().fmi2GetTypesPlatform()) };
    assert_eq!(platform.to_str(), Ok("default"));
    let version = unsafe { std::ffi::CStr::from_ptr(inst.b().fmi2GetVersion()) };
    assert_eq!(version.to_str(), Ok("2.0"));
}

#[test]
fn a_literal_hash_reaches_the_host_logger_doubled() {
    // FMI 2.0 reserves '#' in log messages for variable references (#r12#); the MPPT logs
    // "valve update #1", which a strict logger (fmuCheck) would misread.
    let f = TestFmu::open_dist("MpptController").unwrap();
    let inst = f.instantiate("hash").unwrap();
    let on = unsafe {
        inst.b()
            .fmi2SetDebugLogging(inst.component, 1, 0, std::ptr::null())
    };
    assert_eq!(on, OK);
    assert_eq!(inst.initialize(0.0), OK);
    let h = 1.0e-3;
    for k in 0..1100 {
        assert!(inst.do_step(k as f64 * h, h) <= WARNING);
    }
    let msgs = inst.messages();
    let update = msgs
        .iter()
        .find(|m| m.contains("valve update"))
        .unwrap_or_else(|| panic!("no valve update logged: {msgs:?}"));
    assert!(update.contains("valve update ##1:"), "{update}");
    for m in &msgs {
        assert!(!m.replace("##", "").contains('#'), "a bare '#' in: {m}");
    }
}

#[test]
fn a_step_longer_than_1000_s_is_discarded_and_the_instance_keeps_its_time() {
    for name in ["MassSpring", "SpringDamperMass", "Bogie2Dof", "RailVehicle"] {
        let f = TestFmu::open_dist(name).expect(name);
        for h in [2000.0, 1.0e300] {
            let inst = f.instantiate("long").unwrap();
            assert_eq!(inst.initialize(0.0), OK, "{name}");
            assert_eq!(inst.do_step(0.0, h), DISCARD, "{name}: h = {h}");
            assert!(
                inst.messages()
                    .iter()
                    .any(|m| m.contains("longer than 1000 s: take several shorter steps")),
                "{name}: {:?}",
                inst.messages()
            );
            // numbers in messages are short: 1e300, not 301 digits
            let short = format!("step from 0.0 over {h:?} s discarded");
            assert!(
                inst.messages().iter().any(|m| m.contains(&short)),
                "{name}: {:?}",
                inst.messages()
            );
            let mut last = f64::NAN;
            let status = unsafe {
                inst.b().fmi2GetRealStatus(
                    inst.component,
                    ffi::fmi2StatusKind_fmi2LastSuccessfulTime,
                    &mut last,
                )
            };
            assert_eq!((status, last), (OK, 0.0), "{name}");
            assert_eq!(inst.terminate(), OK, "{name}");
        }
    }
}

#[test]
fn a_communication_point_off_by_more_than_a_billionth_of_the_step_is_refused() {
    let f = fmu();
    let inst = f.instantiate("off").unwrap();
    assert_eq!(inst.initialize(0.0), OK);
    // 0.9 ms off the instance time: a long step does not widen the tolerance to that
    assert_eq!(inst.do_step(9.0e-4, 1000.0), ERROR);
    assert!(
        inst.messages()
            .iter()
            .any(|m| m.contains("communication point 0.0009 does not match")),
        "{:?}",
        inst.messages()
    );
    // refused, nothing changed: the step from the instance time goes on
    assert_eq!(inst.do_step(0.0, 1.0e-3), OK);
    // a point a few ulps off a long step's end is still accepted
    let end = 1.0e-3 + 500.0;
    assert_eq!(inst.do_step(1.0e-3, 500.0), OK);
    assert_eq!(inst.do_step(end * (1.0 + 4.0 * f64::EPSILON), 1.0e-3), OK);
}

#[test]
fn the_shortest_sub_step_parameters_allow_still_takes_a_one_second_step() {
    // at 0.02 m/s the creep damping sets a sub-step of about 0.77 µs: 1.3 million sub-steps
    // in one 1 s step, a valid run (a bound of a million sub-steps refused it as corrupted)
    let f = TestFmu::open_dist("Bogie2Dof").unwrap();
    let inst = f.instantiate("slow").unwrap();
    assert_eq!(inst.setup(0.0, None), OK);
    assert_eq!(inst.enter_init(), OK);
    assert_eq!(inst.set_real("vehicle.speed", 0.02), OK);
    assert_eq!(inst.exit_init(), OK);
    assert_eq!(inst.do_step(0.0, 1.0), OK, "{:?}", inst.messages());
}

/// Every packaged FMU names its copyright and licence in modelDescription.xml and carries the
/// licence texts it names, linked from its documentation.
#[test]
fn every_fmu_names_its_licence_and_ships_its_texts() {
    let dist = workspace_root().join("dist");
    let mut fmus: Vec<_> = std::fs::read_dir(&dist)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "fmu"))
        .collect();
    fmus.sort();
    assert!(fmus.len() >= 10, "{fmus:?}");
    for path in fmus {
        let f = TestFmu::open(&path).unwrap();
        let md = &f.model_description;
        assert!(
            md.contains(r#" copyright="Copyright (c) 2026 the rail-fmu authors""#),
            "{}",
            path.display()
        );
        assert!(
            md.contains(r#" license="MIT OR Apache-2.0 (documentation/LICENSE-MIT.txt"#),
            "{}",
            path.display()
        );
        let mit =
            std::fs::read_to_string(f.dir.path().join("documentation/LICENSE-MIT.txt")).unwrap();
        assert!(
            mit.contains("Permission is hereby granted"),
            "{}",
            path.display()
        );
        let apache =
            std::fs::read_to_string(f.dir.path().join("documentation/LICENSE-APACHE.txt")).unwrap();
        assert!(apache.contains("Apache License"), "{}", path.display());
        let html = std::fs::read_to_string(f.dir.path().join("documentation/index.html")).unwrap();
        assert!(
            html.contains(r#"<a href="LICENSE-MIT.txt">"#)
                && html.contains("<h2>Initialization Mode</h2>"),
            "{}",
            path.display()
        );
    }
}
