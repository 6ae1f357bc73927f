//! Time-domain model: consistency with the linear matrices, sign conventions of the outputs,
//! direct feedthrough, track delays, bad input, derailment, state save/restore.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use fmu_vehicle::dynamics::{rhs, Consts, N_STATES, RATES};
use fmu_vehicle::eigen::{state_matrix, DamperRepresentation, YawDamperModel};
use fmu_vehicle::layout::{frame_yaw, wheelset_y, Positions, CARBODY_YAW, N_DOF};
use fmu_vehicle::model::{worn_surrogate_table, InputError};
use fmu_vehicle::params::Initial;
use fmu_vehicle::{
    Inputs, ModelError, ModelKind, PsdLevel, StepError, TrackSource, Vehicle, VehicleParams,
};
use wheel_rail::{GeometryTable, SegmentHint};

#[test]
fn linear_rhs_equals_the_state_matrix() {
    let p = VehicleParams {
        model: ModelKind::Linear,
        ..VehicleParams::default()
    };
    let table = worn_surrogate_table().unwrap();
    let c = Consts::new(&p, &table);
    let a = state_matrix(
        &p,
        p.speed_mps,
        &YawDamperModel::rigid(DamperRepresentation::None),
    )
    .unwrap();
    // z = (q', q) ; x = (q, q', spin)
    let to_x = |z: usize| if z < N_DOF { RATES + z } else { z - N_DOF };
    let mut hints = [SegmentHint::default(); 4];
    for col in 0..2 * N_DOF {
        let mut x = [0.0; N_STATES];
        x[to_x(col)] = 1e-6;
        let d = rhs(&c, &table, &mut hints, &x, &[0.0; 4], &[0.0; 4]).dx;
        for row in 0..2 * N_DOF {
            let num = d[to_x(row)] / 1e-6;
            let ex = a[(row, col)];
            assert!(
                (num - ex).abs() <= 1e-6 * ex.abs().max(1.0),
                "A[{row},{col}] {num} vs {ex}"
            );
        }
    }
}

#[test]
fn nonlinear_forces_equal_linear_ones_at_small_amplitude_on_a_cone() {
    // a pure cone (no contact-angle change): the non-linear wheelset forces reduce to the linear
    // ones with the same conicity and no gravitational stiffness
    let cone = GeometryTable::synthetic(0.2, 7e-3, 5e-4, 2.7).unwrap();
    let mut p = VehicleParams::default();
    p.wheel_rail.conicity = 0.2;
    p.wheel_rail.gravity_stiffness_n_per_m = 0.0;
    let nl = Consts::new(&p, &cone);
    p.model = ModelKind::Linear;
    let li = Consts::new(&p, &cone);
    let mut x = [0.0; N_STATES];
    x[wheelset_y(1)] = 2e-5;
    x[wheelset_y(1) + 1] = -1e-6;
    x[RATES + wheelset_y(1)] = 1e-4;
    let mut hints = [SegmentHint::default(); 4];
    let a = rhs(&nl, &cone, &mut hints, &x, &[0.0; 4], &[0.0; 4]);
    let b = rhs(&li, &cone, &mut hints, &x, &[0.0; 4], &[0.0; 4]);
    let (fa, fb) = (a.wheelsets[1], b.wheelsets[1]);
    assert!(
        (fa.lateral_n - fb.lateral_n).abs() < 2e-3 * fb.lateral_n.abs(),
        "{fa:?} {fb:?}"
    );
    assert!((fa.yaw_moment_nm - fb.yaw_moment_nm).abs() < 2e-3 * fb.yaw_moment_nm.abs());
}

fn yawed_front_bogie() -> Vehicle {
    let mut v = Vehicle::new(VehicleParams::default()).unwrap();
    let mut s = *v.state();
    s[frame_yaw(0)] = 1e-3;
    s[RATES + frame_yaw(0)] = 2e-3;
    s[RATES + CARBODY_YAW] = 5e-4;
    v.set_state(s).unwrap();
    v
}

#[test]
fn damper_outputs_follow_the_conventions() {
    let v = yawed_front_bogie();
    let b = v.params().geometry.damper_arm_m;
    let o = v.outputs(&Inputs::default()).unwrap();
    // nose-left frame yaw: left damper extends by b psi, right one shortens
    assert!((o.damper[0].elongation_m - b * 1e-3).abs() < 1e-15);
    assert!((o.damper[1].elongation_m + b * 1e-3).abs() < 1e-15);
    assert_eq!(o.damper[2].elongation_m, 0.0);
    // attachment velocities along the damper axis (forward positive): left points move
    // backwards under nose-left yaw rate
    assert!((o.damper[0].frame_end_velocity_mps + b * 2e-3).abs() < 1e-15);
    assert!((o.damper[0].carbody_end_velocity_mps + b * 5e-4).abs() < 1e-15);
    assert!(
        (o.damper[0].elongation_velocity_mps
            - (o.damper[0].carbody_end_velocity_mps - o.damper[0].frame_end_velocity_mps))
            .abs()
            < 1e-15
    );
    assert!((o.damper[3].carbody_end_velocity_mps - b * 5e-4).abs() < 1e-15);
}

#[test]
fn damper_forces_feed_through_to_frame_and_carbody_accelerations() {
    let v = Vehicle::new(VehicleParams::default()).unwrap();
    let o0 = v.outputs(&Inputs::default()).unwrap();
    let inputs = Inputs {
        damper_force_n: [1e4, 0.0, 0.0, 0.0],
        ..Inputs::default()
    };
    let o1 = v.outputs(&inputs).unwrap();
    // tension in the front-left damper: yaw moment -b F on the frame (nose right), so the
    // frame's leading end accelerates to the right and the trailing end to the left
    assert!(o1.frame[0].lateral_acc_leading_axle_mps2 > o0.frame[0].lateral_acc_leading_axle_mps2);
    assert!(o1.frame[0].lateral_acc_trailing_axle_mps2 < 0.0);
    assert!(o1.damper[0].frame_end_acc_mps2 > 0.0);
    // the car body gets +b F: nose-left, its front end moves left
    assert!(o1.carbody.lateral_acc_front_mps2 < 0.0 && o1.carbody.lateral_acc_rear_mps2 > 0.0);
    // the wheelsets see nothing at the same instant
    assert_eq!(
        o1.wheelset[0].lateral_acc_mps2,
        o0.wheelset[0].lateral_acc_mps2
    );
    assert_eq!(o1.frame[1], o0.frame[1]);
}

#[test]
fn external_track_reaches_each_wheelset_after_its_delay() {
    let p = VehicleParams {
        speed_mps: 50.0,
        track: TrackSource::External,
        ..VehicleParams::default()
    };
    let pos = Positions::new(&p);
    let mut v = Vehicle::new(p).unwrap();
    let h = 1e-3;
    // straight track first (the track before the first sample is taken as that sample)
    v.step(h, &Inputs::default()).unwrap();
    let inputs = Inputs {
        track_lateral_m: 1e-3,
        ..Inputs::default()
    };
    let mut arrival = [f64::NAN; 4];
    for _ in 0..500 {
        let o = v.step(h, &inputs).unwrap();
        for (a, w) in arrival.iter_mut().zip(&o.wheelset) {
            if a.is_nan() && w.track_m > 0.5e-3 {
                *a = o.time_s;
            }
        }
    }
    for j in 0..4 {
        let expected = h + pos.wheelset_delay_m[j] / 50.0;
        assert!(
            (arrival[j] - expected).abs() <= 2.0 * h,
            "wheelset {j}: {arrival:?}"
        );
    }
}

#[test]
fn internal_track_is_the_same_track_under_every_wheelset() {
    let p = VehicleParams {
        speed_mps: 70.0,
        track: TrackSource::Internal {
            level: PsdLevel::High,
            seed: 4,
        },
        ..VehicleParams::default()
    };
    let d = Positions::new(&p).wheelset_delay_m;
    let mut v = Vehicle::new(p).unwrap();
    let mut rec = Vec::new();
    for _ in 0..2000 {
        let o = v.step(1e-3, &Inputs::default()).unwrap();
        rec.push(o.wheelset.map(|w| w.track_m));
    }
    let max = rec.iter().map(|r| r[0].abs()).fold(0.0, f64::max);
    assert!(max > 5e-4, "{max}");
    // the last wheelset at step k sees what the leading one saw (2a + 2p)/V earlier
    let lag = (d[3] / 70.0 / 1e-3).round() as usize;
    for k in lag + 1..rec.len() {
        let (now, then) = (rec[k][3], rec[k - lag][0]);
        assert!((now - then).abs() < 0.02 * max, "{k}: {now} vs {then}");
    }
}

#[test]
fn bad_inputs_are_refused_and_change_nothing() {
    let mut v = yawed_front_bogie();
    let before = v.clone();
    let bad = Inputs {
        damper_force_n: [0.0, f64::NAN, 0.0, 0.0],
        ..Inputs::default()
    };
    assert!(matches!(
        v.step(1e-3, &bad),
        Err(StepError::Input(InputError::NonFiniteInput { .. }))
    ));
    assert!(matches!(
        v.step(0.0, &Inputs::default()),
        Err(StepError::Input(InputError::InvalidStep { .. }))
    ));
    assert!(matches!(
        v.step(f64::INFINITY, &Inputs::default()),
        Err(StepError::Input(InputError::InvalidStep { .. }))
    ));
    assert_eq!(v, before);
}

#[test]
fn derailment_is_reported_and_the_model_is_unchanged() {
    // linear model far above its critical speed without dampers: grows until a wheelset
    // leaves the table's range
    let p = VehicleParams {
        speed_mps: 90.0,
        model: ModelKind::Linear,
        track: TrackSource::External,
        initial: Initial {
            lateral_m: 5e-3,
            yaw_rad: 0.0,
        },
        ..VehicleParams::default()
    };
    let mut v = Vehicle::new(p).unwrap();
    let mut err = None;
    for _ in 0..20_000 {
        let before = v.clone();
        match v.step(1e-3, &Inputs::default()) {
            Ok(o) => assert!(o.wheelset.iter().all(|w| w.lateral_m.is_finite())),
            Err(e) => {
                assert_eq!(v, before, "a failed step must leave the model unchanged");
                err = Some(e);
                break;
            }
        }
    }
    let e = err.expect("the linear model must grow to derailment");
    assert!(matches!(e, StepError::Derailed { .. }), "{e}");
    let msg = e.to_string();
    assert!(
        msg.contains("derailment") && msg.contains("wheelset"),
        "{msg}"
    );
}

/// Tables the vehicle cannot run on are refused by name at initialisation: a flange on the
/// wrong side, a reach beyond any rail, a rolling radius no wheel has.
#[test]
fn tables_that_do_not_fit_a_wheelset_are_refused() {
    let table = worn_surrogate_table().unwrap();
    let rows: Vec<[f64; 5]> = table.rows().collect();
    let columns = |rows: &[[f64; 5]]| {
        let col = |k: usize| rows.iter().map(|r| r[k]).collect::<Vec<f64>>();
        GeometryTable::from_columns(col(0), col(1), col(2), col(3), col(4)).unwrap()
    };
    let refused = |t: GeometryTable| {
        Vehicle::with_table(VehicleParams::default(), t)
            .unwrap_err()
            .to_string()
    };
    // the shipped table passes
    assert!(Vehicle::with_table(VehicleParams::default(), table.clone()).is_ok());
    // the left wheel without its flange on the left (capped where y <= 0): only its field
    // side reaches tan gamma 1.2, which used to pass
    let mut left_missing = rows.clone();
    for r in left_missing.iter_mut() {
        if r[0] <= 0.0 {
            r[3] = r[3].min(0.5);
        } else if r[0] > 9e-3 {
            r[3] = 1.2;
        }
    }
    let e = refused(columns(&left_missing));
    assert!(
        e.contains("on the left wheel tan(gamma) reaches only 0.500"),
        "{e}"
    );
    // the two wheels' columns swapped: both flanges on the wrong side
    let mirrored: Vec<[f64; 5]> = rows
        .iter()
        .map(|r| [r[0], r[2], r[1], r[4], r[3]])
        .collect();
    assert!(refused(columns(&mirrored)).contains("does not cover the flange"));
    // reaching 1 m from the track centre
    let mut wide = rows.clone();
    wide.insert(0, [-1.0, rows[0][1], rows[0][2], rows[0][3], rows[0][4]]);
    let e = refused(columns(&wide));
    assert!(
        e.contains("reaches 1000.0 mm from the track centre, beyond 50 mm"),
        "{e}"
    );
    // delta r in mm taken as m: a rolling radius far below the wheel's
    let mm: Vec<[f64; 5]> = rows
        .iter()
        .map(|r| [r[0], r[1] * 1e3, r[2] * 1e3, r[3], r[4]])
        .collect();
    let e = refused(columns(&mm));
    assert!(
        e.contains("rolling radius of") && e.contains("below half the nominal"),
        "{e}"
    );
}

#[test]
fn a_table_without_flange_is_refused() {
    let tread_only = GeometryTable::synthetic(0.2, 7e-3, 5e-4, 0.5).unwrap();
    let e = Vehicle::with_table(VehicleParams::default(), tread_only).unwrap_err();
    assert!(matches!(e, ModelError::FlangeNotCovered(_)), "{e}");
    assert!(e.to_string().contains("flange"), "{e}");
    let e = Vehicle::new(VehicleParams {
        contact: fmu_vehicle::params::ContactSource::File("/nonexistent/table.csv".into()),
        ..VehicleParams::default()
    })
    .unwrap_err();
    assert!(e.to_string().contains("/nonexistent/table.csv"), "{e}");
}

#[test]
fn state_save_restore_continues_bit_for_bit() {
    let p = VehicleParams {
        speed_mps: 300.0 / 3.6,
        track: TrackSource::Internal {
            level: PsdLevel::Low,
            seed: 2,
        },
        initial: Initial {
            lateral_m: 3e-3,
            yaw_rad: 0.0,
        },
        ..VehicleParams::default()
    };
    let mut a = Vehicle::new(p).unwrap();
    let inputs = Inputs {
        damper_force_n: [1e3, -1e3, 5e2, -5e2],
        ..Inputs::default()
    };
    for _ in 0..500 {
        a.step(1e-3, &inputs).unwrap();
    }
    let json = serde_json::to_string(&a).unwrap();
    let mut b: Vehicle = serde_json::from_str(&json).unwrap();
    assert_eq!(a, b);
    for _ in 0..500 {
        let (oa, ob) = (
            a.step(1e-3, &inputs).unwrap(),
            b.step(1e-3, &inputs).unwrap(),
        );
        assert_eq!(oa, ob);
    }
}

#[test]
fn step_size_independence_of_the_model_alone() {
    // no co-simulated element: 1 ms and 0.5 ms communication steps (one RK4 sub-step each)
    // give the same motion, within the integrator's error (0.5 % of the perturbation over 2 s
    // of transient; the limit cycles converge far better, see tests/convergence.rs)
    let p = VehicleParams {
        speed_mps: 250.0 / 3.6,
        initial: Initial {
            lateral_m: 3e-3,
            yaw_rad: 1e-3,
        },
        ..VehicleParams::default()
    };
    let mut a = Vehicle::new(p.clone()).unwrap();
    let mut b = Vehicle::new(p).unwrap();
    let mut diff: f64 = 0.0;
    for _ in 0..2000 {
        let oa = a.step(1e-3, &Inputs::default()).unwrap();
        b.step(5e-4, &Inputs::default()).unwrap();
        let ob = b.step(5e-4, &Inputs::default()).unwrap();
        diff = diff.max((oa.wheelset[0].lateral_m - ob.wheelset[0].lateral_m).abs());
    }
    assert!(diff < 5e-3 * 3e-3, "{diff}");
}

/// A saved state whose damper rows index past the dofs (a tampered one) is refused when read,
/// instead of panicking in the next step's force assembly.
#[test]
fn restored_damper_rows_must_index_the_dofs() {
    let table = worn_surrogate_table().unwrap();
    let c = Consts::new(&VehicleParams::default(), &table);
    let good = serde_json::to_value(&c).unwrap();
    assert_eq!(serde_json::from_value::<Consts>(good.clone()).unwrap(), c);
    let mut bad = good;
    bad["dampers"][2][1][0] = serde_json::json!(N_DOF);
    let e = serde_json::from_value::<Consts>(bad).unwrap_err();
    assert!(e.to_string().contains("beyond the"), "{e}");
}

#[test]
fn a_car_body_the_suspension_cannot_hold_upright_is_refused() {
    // a centre of gravity 6 m high without anti-roll bar: gravity's overturning moment beats
    // the air springs' roll stiffness (it tipped over to 127 degrees in 30 s, every step OK)
    let mut p = VehicleParams::default();
    p.carbody.cg_height_m = 6.0;
    p.secondary.anti_roll_bar_nm_per_rad = 0.0;
    let e = Vehicle::new(p).unwrap_err();
    assert!(matches!(e, ModelError::StaticallyUnstable { .. }), "{e}");
    let msg = e.to_string();
    assert!(
        msg.contains("upright") && msg.contains("car-body") && msg.contains("cg_height"),
        "{msg}"
    );
    // the calibrated coach, and the same centre of gravity with its anti-roll bar, stand
    assert!(Vehicle::new(VehicleParams::default()).is_ok());
    let mut p = VehicleParams::default();
    p.carbody.cg_height_m = 2.5;
    assert!(Vehicle::new(p).is_ok());
}

#[test]
fn a_start_beyond_the_contact_table_is_refused_before_the_first_step() {
    let e = Vehicle::new(VehicleParams {
        initial: Initial {
            lateral_m: 12e-3,
            yaw_rad: 0.0,
        },
        ..VehicleParams::default()
    })
    .unwrap_err();
    assert!(
        matches!(e, ModelError::StartsDerailed { wheelset: 1, .. }),
        "{e}"
    );
    assert!(
        e.to_string().contains("initial.lateral_displacement"),
        "{e}"
    );
    // a yaw angle that puts the leading wheelset past the table's end
    let e = Vehicle::new(VehicleParams {
        initial: Initial {
            lateral_m: 0.0,
            yaw_rad: 0.009,
        },
        ..VehicleParams::default()
    })
    .unwrap_err();
    assert!(matches!(e, ModelError::StartsDerailed { .. }), "{e}");
}

#[test]
fn a_large_suspension_damping_shortens_the_internal_step_instead_of_diverging() {
    // 3 MN s/m of lateral secondary damping: the explicit step of the default sub-step
    // diverged (frame acceleration -1.2e8 m/s^2 with every step OK, then a "derailment")
    let mut p = VehicleParams {
        track: TrackSource::None,
        ..VehicleParams::default()
    };
    p.secondary.lateral_damping_ns_per_m = 3e6;
    let default_substep = Vehicle::new(VehicleParams::default()).unwrap().substep_s();
    let mut v = Vehicle::new(p).unwrap();
    assert!(v.substep_s() < default_substep, "{}", v.substep_s());
    let mut peak: f64 = 0.0;
    for _ in 0..500 {
        let o = v.step(1e-3, &Inputs::default()).unwrap();
        for f in &o.frame {
            peak = peak.max(f.lateral_acc_leading_axle_mps2.abs());
        }
    }
    // measured with a 0.1 ms sub-step: 9.2 m/s^2 at most
    assert!(peak < 50.0, "{peak}");
}
