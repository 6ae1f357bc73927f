//! The RailVehicle FMU driven through the glue's state machine (the same checks as the C API).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use fmu_vehicle::fmu::{RailVehicle, FMU_DEFAULT_INITIAL_LATERAL_M, FMU_DEFAULT_SPEED_MPS};
use fmu_vehicle::params::Initial;
use fmu_vehicle::{Inputs, PsdLevel, TrackSource, Vehicle, VehicleParams};
use model_description::testing::{get, initialising, logged, real_outputs, set, vr};
use model_description::{rust_component, FmuModel, InstanceContext, Status};

type M = RailVehicle;

#[test]
fn names_are_structured() {
    for v in M::variables() {
        let n = &v.meta.name;
        assert!(n.contains('.'), "bare name {n}");
        assert!(!n.starts_with("model"), "{n}");
        // OMSimulator does not find a parameter whose first segment is the instance's name: keep
        // the natural instance names of this FMU free
        assert!(
            !n.starts_with("vehicle.") && !n.starts_with("coach."),
            "{n}"
        );
    }
    // the physics names its fields; the glue finds the FMI variable bound to each
    let metas: Vec<_> = M::variables().into_iter().map(|v| v.meta).collect();
    for (field, fmi) in [
        ("damper_force_n[1]", "damper_front_right.force"),
        ("carbody.mass_kg", "carbody.mass"),
        ("geometry.half_wheelbase_m", "geometry.half_wheelbase"),
        ("primary.kx_n_per_m", "primary.longitudinal_stiffness"),
        ("secondary.kx_n_per_m", "secondary.longitudinal_stiffness"),
        ("speed_mps", "running.speed"),
        ("contact", "contact.table"),
    ] {
        let m = model_description::fields::variable_for_field(&metas, field)
            .unwrap_or_else(|| panic!("no variable bound to {field}"));
        assert_eq!(m.name, fmi);
    }
    for name in [
        "damper_front_left.force",
        "damper_rear_right.carbody_end_velocity",
        "carbody.lateral_acceleration_mid",
        "frame_rear.lateral_acceleration_trailing_axle",
        "wheelset_4.y_over_q",
    ] {
        vr::<M>(name);
    }
}

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
    let (mut peak, mut yq): (f64, f64) = (0.0, 0.0);
    for k in 0..n {
        let target = e.start_time + (k + 1) as f64 * e.step_size;
        assert_eq!(c.do_step(t, target - t), Status::Ok, "{:?}", log.take());
        t = target;
        if k % 10 == 0 {
            for name in &names {
                let x = get::<M>(&mut c, name);
                assert!(x.is_finite(), "{name} = {x} at t = {t}");
            }
        }
        if t > 2.0 {
            peak = peak.max(get::<M>(&mut c, "wheelset_1.lateral_displacement").abs());
            yq = yq.max(get::<M>(&mut c, "wheelset_1.y_over_q"));
        }
    }
    assert!(log.take().is_empty());
    // hunting into flange contact without yaw dampers
    assert!(peak > 6e-3 && peak < 8e-3, "{peak}");
    assert!(yq > 1.0, "{yq}");
}

/// Same parameters, same inputs: the FMU outputs equal the physics bit for bit.
#[test]
fn fmu_equals_plain_physics_bit_for_bit() {
    let (mut c, log) = initialising::<M>();
    assert_eq!(set::<M>(&mut c, "running.speed", 280.0 / 3.6), Status::Ok);
    assert_eq!(
        c.set_integer(&[vr::<M>("track.source")], &[2]),
        Status::Ok,
        "{:?}",
        log.take()
    );
    assert_eq!(c.set_integer(&[vr::<M>("track.level")], &[1]), Status::Ok);
    assert_eq!(c.set_integer(&[vr::<M>("track.seed")], &[7]), Status::Ok);
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    let p = VehicleParams {
        speed_mps: 280.0 / 3.6,
        initial: Initial {
            lateral_m: FMU_DEFAULT_INITIAL_LATERAL_M,
            yaw_rad: 0.0,
        },
        track: TrackSource::Internal {
            level: PsdLevel::High,
            seed: 7,
        },
        ..VehicleParams::default()
    };
    let mut v = Vehicle::new(p).unwrap();
    let forces = [
        "damper_front_left.force",
        "damper_front_right.force",
        "damper_rear_left.force",
        "damper_rear_right.force",
    ]
    .map(vr::<M>);
    let h = 1e-3;
    let mut t = 0.0;
    for k in 0..1000 {
        let f = 3e3 * ((k as f64) * 0.05).sin();
        let i = Inputs {
            damper_force_n: [f, -0.5 * f, 0.3 * f, -f],
            track_lateral_m: 0.0,
        };
        assert_eq!(c.set_real(&forces, &i.damper_force_n), Status::Ok);
        assert_eq!(c.do_step(t, h), Status::Ok);
        // the glue steps from its own time to t + h: the same effective step here
        let o = v.step((t + h) - t, &i).unwrap();
        t += h;
        assert_eq!(
            get::<M>(&mut c, "wheelset_3.lateral_displacement"),
            o.wheelset[2].lateral_m
        );
        assert_eq!(
            get::<M>(&mut c, "frame_rear.lateral_acceleration_leading_axle"),
            o.frame[1].lateral_acc_leading_axle_mps2
        );
        assert_eq!(
            get::<M>(&mut c, "carbody.lateral_acceleration_mid"),
            o.carbody.lateral_acc_mid_mps2
        );
        assert_eq!(
            get::<M>(&mut c, "damper_rear_right.carbody_end_acceleration"),
            o.damper[3].carbody_end_acc_mps2
        );
        assert_eq!(
            get::<M>(&mut c, "wheelset_4.track_alignment"),
            o.wheelset[3].track_m
        );
    }
}

#[test]
fn impossible_parameters_are_named() {
    // the glue refuses values outside the declared range at once
    let (mut c, log) = initialising::<M>();
    assert_eq!(set::<M>(&mut c, "carbody.mass", -1.0), Status::Error);
    assert!(logged(&log.take(), Status::Error, "carbody.mass"));
    // the physics' own checks at fmi2ExitInitializationMode, under the FMI names
    for (name, value, needle) in [
        ("geometry.half_wheelbase", 5.0, "do not fit"),
        ("primary.longitudinal_stiffness", 0.0, "> 0"),
        ("frame.yaw_inertia", 0.0, "> 0"),
    ] {
        let (mut c, log) = initialising::<M>();
        assert_eq!(set::<M>(&mut c, name, value), Status::Ok);
        assert_eq!(c.exit_initialization_mode(), Status::Error, "{name}");
        let l = log.take();
        assert!(logged(&l, Status::Error, name), "{name}: {l:?}");
        assert!(logged(&l, Status::Error, needle), "{name}: {l:?}");
    }
}

/// The wheel load, the Kalker coefficients and the linear model's gravitational stiffness are
/// calculated from the masses: a laden coach loads its wheels without four more parameters to
/// keep in step (and they cannot be set apart from the masses).
#[test]
fn the_wheel_load_and_what_follows_it_come_from_the_masses() {
    let laden = VehicleParams {
        speed_mps: FMU_DEFAULT_SPEED_MPS,
        initial: Initial {
            lateral_m: FMU_DEFAULT_INITIAL_LATERAL_M,
            yaw_rad: 0.0,
        },
        carbody: fmu_vehicle::params::CarBody {
            mass_kg: 40_000.0,
            ..VehicleParams::default().carbody
        },
        ..VehicleParams::default()
    };
    let expected = laden.wheel_rail_from_masses();
    let tare = VehicleParams::default().wheel_rail;
    // g m_total / 8: 64.0 kN against 54.2 kN
    assert_eq!(expected.wheel_load_n, 9.81 * laden.total_mass_kg() / 8.0);
    assert!(
        (expected.wheel_load_n - 64.0e3).abs() < 0.1e3,
        "{expected:?}"
    );
    let (mut c, log) = initialising::<M>();
    let names = [
        "wheelset.wheel_load",
        "creep.f11",
        "creep.f22",
        "linear.gravitational_stiffness",
    ];
    let read = |c: &mut model_description::Component| names.map(|n| get::<M>(c, n));
    assert_eq!(
        read(&mut c),
        [
            tare.wheel_load_n,
            tare.f11_n,
            tare.f22_n,
            tare.gravity_stiffness_n_per_m
        ]
    );
    assert_eq!(set::<M>(&mut c, "carbody.mass", 40_000.0), Status::Ok);
    let values = [
        expected.wheel_load_n,
        expected.f11_n,
        expected.f22_n,
        expected.gravity_stiffness_n_per_m,
    ];
    assert_eq!(read(&mut c), values);
    // 11.5 MN at 70 kN, scaled as P^(2/3)
    let f11 = 11.5e6 * (expected.wheel_load_n / 70e3).powf(2.0 / 3.0);
    assert!((expected.f11_n - f11).abs() < 1e-6 * f11);
    for name in names {
        assert_eq!(set::<M>(&mut c, name, 1e6), Status::Error, "{name}");
        assert!(logged(&log.take(), Status::Error, "calculatedParameter"));
    }
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    assert_eq!(read(&mut c), values);
    // the physics runs on them: the FMU's step equals the laden vehicle's
    let mut v = Vehicle::new(VehicleParams {
        wheel_rail: expected,
        ..laden
    })
    .unwrap();
    let h = 1e-3;
    let mut t = 0.0;
    for k in 0..200 {
        assert_eq!(c.do_step(t, h), Status::Ok);
        // the glue steps from its own time to t + h: the same effective step here
        let o = v.step((t + h) - t, &Inputs::default()).unwrap();
        t += h;
        assert_eq!(
            get::<M>(&mut c, "wheelset_1.y_over_q"),
            o.wheelset[0].y_over_q,
            "step {k}"
        );
    }
    assert!(get::<M>(&mut c, "wheelset_1.y_over_q").abs() > 0.0);
}

/// A parameter that passes its range but leaves the dynamics faster than any step can follow
/// (a wheelset of 1e-300 kg) is refused at initialisation, naming it and saying why, instead of
/// making every later step loop for ever.
#[test]
fn parameters_too_stiff_to_integrate_are_refused() {
    for (name, value) in [
        ("wheelset.mass", 1e-300),
        ("primary.lateral_stiffness", 1e300),
    ] {
        let (mut c, log) = initialising::<M>();
        assert_eq!(set::<M>(&mut c, name, value), Status::Ok, "{name}");
        assert_eq!(c.exit_initialization_mode(), Status::Error, "{name}");
        let l = log.take();
        assert!(
            logged(&l, Status::Error, &format!("'{name}'")),
            "{name}: {l:?}"
        );
        assert!(
            logged(&l, Status::Error, "internal steps of"),
            "{name}: {l:?}"
        );
        assert!(
            logged(&l, Status::Error, "outside any vehicle's range"),
            "{name}: {l:?}"
        );
    }
}

#[test]
fn a_contact_table_without_flange_is_refused() {
    let dir = std::env::temp_dir().join(format!("rail_vehicle_table_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("tread_only.csv");
    let t = wheel_rail::GeometryTable::synthetic(0.2, 7e-3, 5e-4, 0.5).unwrap();
    std::fs::write(&file, t.to_csv(wheel_rail::CsvNumbers::Scientific)).unwrap();
    let (mut c, log) = initialising::<M>();
    let path = file.to_string_lossy().into_owned();
    assert_eq!(
        c.set_string(&[vr::<M>("contact.table")], &[path.as_str()]),
        Status::Ok
    );
    assert_eq!(c.exit_initialization_mode(), Status::Error);
    let l = log.take();
    assert!(logged(&l, Status::Error, "contact.table"), "{l:?}");
    assert!(logged(&l, Status::Error, "flange"), "{l:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_input_and_derailment_are_errors_naming_the_cause() {
    let (mut c, log) = initialising::<M>();
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    // NaN is refused by the glue at fmi2SetReal
    assert_eq!(
        set::<M>(&mut c, "damper_front_right.force", f64::NAN),
        Status::Error
    );
    assert!(logged(
        &log.take(),
        Status::Error,
        "damper_front_right.force"
    ));
    // linear model far above its critical speed without dampers: derails
    let (mut c, log) = initialising::<M>();
    assert_eq!(c.set_integer(&[vr::<M>("contact.model")], &[0]), Status::Ok);
    assert_eq!(set::<M>(&mut c, "running.speed", 90.0), Status::Ok);
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    let mut t = 0.0;
    let mut status = Status::Ok;
    for _ in 0..20_000 {
        status = c.do_step(t, 1e-3);
        if status != Status::Ok {
            break;
        }
        t += 1e-3;
        assert!(get::<M>(&mut c, "wheelset_1.lateral_displacement").is_finite());
    }
    assert_eq!(status, Status::Error);
    let l = log.take();
    assert!(logged(&l, Status::Error, "derailment"), "{l:?}");
}

#[test]
fn start_values_are_the_fmu_defaults() {
    let (mut c, _log) = initialising::<M>();
    assert_eq!(get::<M>(&mut c, "running.speed"), FMU_DEFAULT_SPEED_MPS);
    assert_eq!(
        get::<M>(&mut c, "initial.lateral_displacement"),
        FMU_DEFAULT_INITIAL_LATERAL_M
    );
    assert_eq!(
        get::<M>(&mut c, "primary.longitudinal_stiffness"),
        VehicleParams::default().primary.kx_n_per_m
    );
}

#[test]
fn serialised_fmu_state_continues_bit_for_bit_in_another_instance() {
    let (mut a, _la) = initialising::<M>();
    assert_eq!(a.set_integer(&[vr::<M>("track.source")], &[2]), Status::Ok);
    assert_eq!(a.exit_initialization_mode(), Status::Ok);
    let mut t = 0.0;
    for _ in 0..300 {
        assert_eq!(a.do_step(t, 1e-3), Status::Ok);
        t += 1e-3;
    }
    let snap = a.get_fmu_state().unwrap();
    let bytes = a.serialize_fmu_state(&snap).unwrap();
    let (mut b, _lb) = initialising::<M>();
    assert_eq!(b.exit_initialization_mode(), Status::Ok);
    let restored = b.deserialize_fmu_state(&bytes).unwrap();
    assert_eq!(b.set_fmu_state(&restored), Status::Ok);
    let outs: Vec<u32> = real_outputs::<M>().iter().map(|n| vr::<M>(n)).collect();
    let (mut va, mut vb) = (vec![0.0; outs.len()], vec![0.0; outs.len()]);
    for _ in 0..300 {
        assert_eq!(a.do_step(t, 1e-3), Status::Ok);
        assert_eq!(b.do_step(t, 1e-3), Status::Ok);
        t += 1e-3;
        assert_eq!(a.get_real(&outs, &mut va), Status::Ok);
        assert_eq!(b.get_real(&outs, &mut vb), Status::Ok);
        assert_eq!(va, vb);
    }
}

/// A host step longer than the physics takes (1 s) runs as equal sub-steps: 2.5 s gives what
/// three steps of 2.5/3 s give, bit for bit.
#[test]
fn a_long_host_step_equals_its_sub_steps() {
    let run = |steps: &[f64]| {
        let (mut c, log) = initialising::<M>();
        assert_eq!(c.exit_initialization_mode(), Status::Ok);
        let mut t = 0.0;
        for &h in steps {
            assert_eq!(c.do_step(t, h), Status::Ok, "{:?}", log.take());
            t += h;
        }
        real_outputs::<M>()
            .iter()
            .map(|n| get::<M>(&mut c, n))
            .collect::<Vec<f64>>()
    };
    let h = 2.5 / 3.0;
    let sub = run(&[h, h, h]);
    assert_eq!(run(&[2.5]), sub);
    assert!(sub.iter().any(|x| *x != 0.0));
}

/// One call computes a bounded number of internal sub-steps: a light wheelset (0.01 kg) needs
/// a sub-step of about a microsecond, and a 30 s step took 284 s of one host call. Such a step
/// is discarded at once with the reason; shorter steps run.
#[test]
fn a_step_needing_too_many_internal_sub_steps_is_discarded_at_once() {
    let (mut c, log) = initialising::<M>();
    assert_eq!(set::<M>(&mut c, "wheelset.mass", 0.01), Status::Ok);
    assert_eq!(c.exit_initialization_mode(), Status::Ok, "{:?}", log.take());
    let started = std::time::Instant::now();
    assert_eq!(c.do_step(0.0, 30.0), Status::Discard);
    let l = log.take();
    assert!(
        logged(&l, Status::Discard, "take shorter communication steps"),
        "{l:?}"
    );
    // measured 0.1 ms: refused before computing (the test does not time anything else)
    assert!(started.elapsed().as_secs_f64() < 5.0);
    let (mut c, _log) = initialising::<M>();
    assert_eq!(set::<M>(&mut c, "wheelset.mass", 0.01), Status::Ok);
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    assert_eq!(c.do_step(0.0, 1e-3), Status::Ok);
}
