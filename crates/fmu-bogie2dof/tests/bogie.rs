//! Reference results R5-R7 of REFERENCE.md and numerical checks of the time-domain model.
//! Damper values in these tests are the PLACEHOLDER passive damper
//! (`calibration::placeholder_damper`, k_eq = 2.0 MN/m, c_eq = 120 kNs/m per damper) until
//! the damper helper's equivalent values at 30 % opening are known.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use fmu_bogie2dof::calibration::*;
use fmu_bogie2dof::contact::ContactTable;
use fmu_bogie2dof::eigen::*;
use fmu_bogie2dof::sim::{run_closed_loop, LoopDamper};
use fmu_bogie2dof::*;

fn placeholder_loop() -> LoopDamper {
    LoopDamper::KelvinVoigt {
        k: PLACEHOLDER_DAMPER_K_N_PER_M,
        c: PLACEHOLDER_DAMPER_C_NS_PER_M,
    }
}

/// Synthetic cone (calibrated conicity) + steep flange at 7 mm, until the A/A table exists.
fn synthetic_table() -> ContactTable {
    ContactTable::synthetic(CALIBRATED_CONICITY, 7e-3, 5e-4, 2.7).unwrap()
}

/// Runs the closed loop; returns (time, front wheelset displacement) samples.
fn run(
    kmh: f64,
    model: ModelKind,
    y0: f64,
    h: f64,
    t_end: f64,
    damper: LoopDamper,
) -> Vec<(f64, f64, f64)> {
    let p = Params {
        speed_mps: kmh / 3.6,
        model,
        initial_lateral_m: y0,
        ..Params::default()
    };
    let mut b = Bogie::with_table(p, synthetic_table()).unwrap();
    let mut v = Vec::new();
    run_closed_loop(&mut b, damper, h, t_end, &|_| 0.0, &mut |o| {
        v.push((
            o.time_s,
            o.wheelset_front_lateral_m,
            o.wheelset_rear_lateral_m,
        ))
    })
    .unwrap();
    v
}

fn peak_between(tr: &[(f64, f64, f64)], t0: f64, t1: f64) -> f64 {
    tr.iter()
        .filter(|s| s.0 >= t0 && s.0 <= t1)
        .map(|s| s.1.abs().max(s.2.abs()))
        .fold(0.0, f64::max)
}

#[test]
fn r5_r6_linear_critical_speed_and_hunting_frequency_placeholder_damper() {
    let p = Params::default();
    let c = critical_speed(&p, &placeholder_damper(), 5.0, 200.0).unwrap();
    println!(
        "V_cr = {:.1} km/h, hunting {:.2} Hz, Im {:.2} rad/s",
        c.speed_kmh, c.hunting.freq_hz, c.hunting.im
    );
    // R5: 270 km/h (+-10)
    assert!((c.speed_kmh - 270.0).abs() <= 10.0, "{c:?}");
    // R6: 3-4.5 Hz at onset, imaginary part about 21 rad/s
    assert!(
        c.hunting.freq_hz >= 3.0 && c.hunting.freq_hz <= 4.5,
        "{c:?}"
    );
    assert!((c.hunting.im - 21.0).abs() < 3.0, "{c:?}");
    assert!(c.hunting.re.abs() < 1e-3);
    // stable below, unstable above
    let below = analyse(&p, 250.0 / 3.6, &placeholder_damper()).unwrap();
    let above = analyse(&p, 290.0 / 3.6, &placeholder_damper()).unwrap();
    assert!(below.max_re < 0.0 && above.max_re > 0.0);
}

#[test]
fn calibration_function_reproduces_constant() {
    let p = Params::default();
    let (k, c) = calibrate_k_ssx(&p, &placeholder_damper(), TARGET_CRITICAL_SPEED_KMH).unwrap();
    assert!((c.speed_kmh - 270.0).abs() < 0.01);
    assert!((k - CALIBRATED_K_SSX_N_PER_M).abs() / k < 0.01, "k_ssx {k}");
    // total effective yaw stiffness per side in REFERENCE's 3-5 MN/m window
    let total = k + PLACEHOLDER_DAMPER_K_N_PER_M;
    assert!(total > 3e6 && total < 5e6);
}

#[test]
fn stiffness_not_damping_sets_critical_speed() {
    // REFERENCE: with air-spring stiffness alone the onset is far below 270 km/h,
    // whatever the damping.
    let p = Params {
        k_ssx_n_per_m: 160e3,
        ..Params::default()
    };
    for c0 in [60e3, 120e3, 300e3] {
        let c = critical_speed(&p, &DamperRepresentation::Viscous { c0 }, 5.0, 200.0).unwrap();
        assert!(c.speed_kmh < 230.0, "c0 {c0}: {c:?}");
        assert!(c.hunting.freq_hz < 2.5, "c0 {c0}: {c:?}");
    }
}

#[test]
fn maxwell_and_frequency_dependent_representations_work() {
    let p = Params::default();
    // A Maxwell damper (series stiffness ~10 MN/m, MPE 2019) gives a critical speed too.
    let m = critical_speed(
        &p,
        &DamperRepresentation::Maxwell { k: 10e6, c: 300e3 },
        5.0,
        200.0,
    )
    .unwrap();
    assert!(m.speed_kmh > 150.0 && m.speed_kmh < 400.0, "{m:?}");
    // Kelvin-Voigt equivalent of that Maxwell element at the mode frequency, as a table:
    // k_eq = k (wc)^2/(k^2+(wc)^2), c_eq = c k^2/(k^2+(wc)^2): same critical speed.
    let (k, c) = (10e6, 300e3);
    let table: Vec<DamperPoint> = (1..=80)
        .map(|i| {
            let f = 0.1 * i as f64;
            let w = 2.0 * std::f64::consts::PI * f;
            let d = k * k + (w * c) * (w * c);
            DamperPoint {
                freq_hz: f,
                k_n_per_m: k * (w * c) * (w * c) / d,
                c_ns_per_m: c * k * k / d,
            }
        })
        .collect();
    let fd = critical_speed(
        &p,
        &DamperRepresentation::FrequencyDependent(table),
        5.0,
        200.0,
    )
    .unwrap();
    assert!((fd.speed_kmh - m.speed_kmh).abs() < 1.0, "{fd:?} vs {m:?}");
}

/// The time-domain model with a Kelvin-Voigt damper fed back through the inputs decays at
/// the rate of the eigen-analysis: checks the damper sign convention end to end.
#[test]
fn time_domain_linear_decay_matches_eigenvalue() {
    let kmh = 240.0;
    let p = Params::default();
    let e = analyse(&p, kmh / 3.6, &placeholder_damper()).unwrap();
    let h = e.hunting.unwrap();
    let tr = run(kmh, ModelKind::Linear, 2e-3, 1e-4, 6.0, placeholder_loop());
    // decay of the envelope between 2 s and 5 s (hunting dominates by then)
    let a1 = peak_between(&tr, 2.0, 2.0 + 1.0 / h.freq_hz);
    let a2 = peak_between(&tr, 5.0, 5.0 + 1.0 / h.freq_hz);
    let rate = (a2 / a1).ln() / 3.0;
    println!("decay rate {rate:.4} vs eigen {:.4}", h.re);
    assert!((rate - h.re).abs() < 0.1 * h.re.abs(), "{rate} vs {}", h.re);
}

#[test]
fn r7_nonlinear_decays_at_220_kmh() {
    let tr = run(
        220.0,
        ModelKind::NonLinear,
        3e-3,
        1e-3,
        6.0,
        placeholder_loop(),
    );
    let early = peak_between(&tr, 0.0, 0.5);
    let late = peak_between(&tr, 5.0, 6.0);
    println!("220 km/h: peak {early:e} -> {late:e}");
    assert!(early > 2e-3 && late < 0.05 * early, "{early} -> {late}");
}

#[test]
fn r7_nonlinear_flange_limit_cycle_at_320_kmh() {
    let tr = run(
        320.0,
        ModelKind::NonLinear,
        3e-3,
        1e-3,
        8.0,
        placeholder_loop(),
    );
    let a = peak_between(&tr, 5.0, 8.0);
    let b = peak_between(&tr, 3.0, 5.0);
    println!(
        "320 km/h: limit cycle peak wheelset displacement {:.2} mm",
        a * 1e3
    );
    // seed: +-6 mm with flange contact; accepted 5-8 mm, and a steady cycle (not growing)
    assert!(a > 5e-3 && a < 8e-3, "{a}");
    assert!((a - b).abs() < 0.05 * a);
    // the same with a Maxwell damper (spring in series with the dashpot, as the hydraulic
    // element) that equals the placeholder at the hunting frequency (22 rad/s):
    // 1/(k_eq + i w c_eq) = 1/k + 1/(i w c)
    let w = 22.0;
    let (ke, ce) = (PLACEHOLDER_DAMPER_K_N_PER_M, PLACEHOLDER_DAMPER_C_NS_PER_M);
    let d = ke * ke + (w * ce) * (w * ce);
    let (k, c) = (d / ke, d / (w * w * ce));
    let trm = run(
        320.0,
        ModelKind::NonLinear,
        3e-3,
        1e-3,
        8.0,
        LoopDamper::Maxwell { k, c },
    );
    let am = peak_between(&trm, 5.0, 8.0);
    println!(
        "320 km/h, Maxwell k {k:.3e} c {c:.3e}: peak {:.2} mm",
        am * 1e3
    );
    assert!(am > 5e-3 && am < 8e-3, "{am}");
}

#[test]
fn linear_and_nonlinear_agree_at_small_amplitude_below_critical_speed() {
    let a = run(
        220.0,
        ModelKind::Linear,
        0.5e-3,
        1e-3,
        3.0,
        placeholder_loop(),
    );
    let b = run(
        220.0,
        ModelKind::NonLinear,
        0.5e-3,
        1e-3,
        3.0,
        placeholder_loop(),
    );
    let max_diff = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x.1 - y.1).abs())
        .fold(0.0, f64::max);
    println!("max |lin - nonlin| = {max_diff:e} m of 5e-4 m");
    assert!(max_diff < 0.05 * 0.5e-3, "{max_diff}");
}

/// Integrator accuracy: the model alone (no damper in the loop; the damper's stiffness is put
/// into k_ssx so it is stable) must not depend on the communication step.
#[test]
fn communication_step_independence_model_alone() {
    let mk2 = |h: f64| {
        let p = Params {
            speed_mps: 320.0 / 3.6,
            initial_lateral_m: 6e-3,
            ..Params::default()
        };
        let mut b = Bogie::with_table(p, synthetic_table()).unwrap();
        let mut v = Vec::new();
        run_closed_loop(&mut b, LoopDamper::None, h, 1.55, &|_| 0.0, &mut |o| {
            v.push((o.time_s, o.wheelset_front_lateral_m))
        })
        .unwrap();
        v
    };
    let mk = |h: f64, t_end: f64| {
        let p = Params {
            speed_mps: 250.0 / 3.6,
            initial_lateral_m: 3e-3,
            k_ssx_n_per_m: CALIBRATED_K_SSX_N_PER_M + 2.0 * PLACEHOLDER_DAMPER_K_N_PER_M,
            ..Params::default()
        };
        let mut b = Bogie::with_table(p, synthetic_table()).unwrap();
        let mut v = Vec::new();
        run_closed_loop(&mut b, LoopDamper::None, h, t_end, &|_| 0.0, &mut |o| {
            v.push((o.time_s, o.wheelset_front_lateral_m))
        })
        .unwrap();
        v
    };
    // 1e-4 s (sub-step 1e-4) vs 1.55e-3 s (16 sub-steps of 0.97e-4): different internal
    // grids, compared at t = 3.1 s (common end) and on the envelope.
    let (a, b) = (mk(1e-4, 3.1), mk(1.55e-3, 3.1));
    let (ea, eb) = (a.last().unwrap(), b.last().unwrap());
    assert!((ea.0 - eb.0).abs() < 1e-9);
    let diff = (ea.1 - eb.1).abs();
    let env = |v: &[(f64, f64)]| {
        v.iter()
            .filter(|s| s.0 > 2.0)
            .map(|s| s.1.abs())
            .fold(0.0, f64::max)
    };
    println!(
        "model alone: |y(3.1 s)| diff {diff:e} m, envelope {:e} vs {:e}",
        env(&a),
        env(&b)
    );
    assert!(diff < 1e-6 * 3e-3, "{diff}");
    assert!((env(&a) - env(&b)).abs() < 1e-3 * env(&a));
    // and a flange-contact case (320 km/h, no damper): the stiff part is resolved too
    let (a, b) = (mk2(1e-4), mk2(1.55e-3));
    let (ea, eb) = (a.last().unwrap(), b.last().unwrap());
    let diff = (ea.1 - eb.1).abs();
    println!("flange contact: |y(1.55 s)| diff {diff:e} m");
    assert!(diff < 1e-3 * 7e-3, "{diff}");
}

/// Closed loop with the zero-order-hold damper force: the coupling delay (h/2) shifts the
/// damper phase by about w h / 2, a few % of the decay rate at h = 2 ms. Bounded here.
#[test]
fn communication_step_independence_closed_loop() {
    let a = run(
        250.0,
        ModelKind::NonLinear,
        3e-3,
        1e-4,
        3.0,
        placeholder_loop(),
    );
    let b = run(
        250.0,
        ModelKind::NonLinear,
        3e-3,
        2e-3,
        3.0,
        placeholder_loop(),
    );
    let mut max_diff: f64 = 0.0;
    for s in &b {
        let k = (s.0 / 1e-4).round() as usize;
        max_diff = max_diff.max((a[k].1 - s.1).abs());
    }
    println!("closed loop: max |h=1e-4 - h=2e-3| = {max_diff:e} m (initial 3e-3)");
    assert!(max_diff < 0.08 * 3e-3, "{max_diff}");
}

#[test]
fn outputs_without_stepping_and_feedthrough() {
    let p = Params {
        initial_lateral_m: 2e-3,
        initial_yaw_rad: 1e-3,
        ..Params::default()
    };
    let b = Bogie::with_table(p.clone(), synthetic_table()).unwrap();
    let i0 = Inputs::default();
    let o0 = b.outputs(&i0).unwrap();
    assert_eq!(o0.time_s, 0.0);
    assert!((o0.damper_left_elongation_m - p.damper_arm_m * 1e-3).abs() < 1e-15);
    assert!((o0.damper_right_elongation_m + p.damper_arm_m * 1e-3).abs() < 1e-15);
    assert!((o0.wheelset_front_lateral_m - (2e-3 - 1.25e-3)).abs() < 1e-12);
    // left damper in tension -> yaw moment -b F_L -> nose-right acceleration: the front
    // end accelerates to the right, the rear to the left
    let i1 = Inputs {
        damper_left_force_n: 10e3,
        ..Inputs::default()
    };
    let o1 = b.outputs(&i1).unwrap();
    let dsdd = -p.damper_arm_m * 10e3 / p.bogie_yaw_inertia_kgm2;
    assert!(
        ((o1.frame_acc_front_mps2 - o0.frame_acc_front_mps2) - (-p.half_wheelbase_m * dsdd)).abs()
            < 1e-9
    );
    assert!(
        ((o1.frame_acc_rear_mps2 - o0.frame_acc_rear_mps2) - (p.half_wheelbase_m * dsdd)).abs()
            < 1e-9
    );
    assert!(o1.frame_acc_front_mps2 > o0.frame_acc_front_mps2);
}

#[test]
fn external_track_reaches_rear_wheelset_after_2p_over_v() {
    let p = Params {
        speed_mps: 50.0,
        model: ModelKind::NonLinear,
        ..Params::default()
    };
    let mut b = Bogie::with_table(p, synthetic_table()).unwrap();
    let step_in = |t: f64| if t >= 0.1 { 1e-3 } else { 0.0 };
    let mut rec = Vec::new();
    run_closed_loop(&mut b, placeholder_loop(), 1e-3, 0.3, &step_in, &mut |o| {
        rec.push((o.time_s, o.track_front_m, o.track_rear_m))
    })
    .unwrap();
    // rear sees the step 2p/V = 0.05 s later
    let rear_at = |t: f64| rec.iter().find(|r| (r.0 - t).abs() < 5e-4).unwrap().2;
    assert!(rear_at(0.14) < 1e-9);
    assert!((rear_at(0.16) - 1e-3).abs() < 1e-9);
    // the bogie follows the shifted track
    assert!(b.state()[0] > 0.3e-3);
}

#[test]
fn internal_track_generator_drives_the_bogie() {
    let p = Params {
        speed_mps: 200.0 / 3.6,
        track: TrackSource::Internal {
            level: PsdLevel::High,
            seed: 11,
        },
        ..Params::default()
    };
    let mut b = Bogie::with_table(p, synthetic_table()).unwrap();
    let mut max_t: f64 = 0.0;
    let mut max_acc: f64 = 0.0;
    run_closed_loop(&mut b, placeholder_loop(), 1e-3, 2.0, &|_| 0.0, &mut |o| {
        max_t = max_t.max(o.track_front_m.abs());
        max_acc = max_acc.max(o.frame_acc_front_mps2.abs());
    })
    .unwrap();
    assert!(max_t > 5e-4 && max_acc > 0.05, "{max_t} {max_acc}");
}

#[test]
fn bad_params_and_inputs_rejected() {
    let cases: Vec<(&str, Params)> = vec![
        (
            "bogie_mass_kg",
            Params {
                bogie_mass_kg: -1.0,
                ..Params::default()
            },
        ),
        (
            "k_ssy_n_per_m",
            Params {
                k_ssy_n_per_m: -5.0,
                ..Params::default()
            },
        ),
        (
            "k_ssx_n_per_m",
            Params {
                k_ssx_n_per_m: f64::NAN,
                ..Params::default()
            },
        ),
        (
            "speed_mps",
            Params {
                speed_mps: 0.0,
                ..Params::default()
            },
        ),
        (
            "friction_coefficient",
            Params {
                friction_coefficient: 1.5,
                ..Params::default()
            },
        ),
        (
            "friction_coefficient",
            Params {
                friction_coefficient: -0.1,
                ..Params::default()
            },
        ),
        (
            "wheel_load_n",
            Params {
                wheel_load_n: 0.0,
                ..Params::default()
            },
        ),
    ];
    for (name, p) in cases {
        let e = p.validate().unwrap_err();
        assert_eq!(e.name, name);
        assert!(e.to_string().contains(name));
        assert!(Bogie::new(p).is_err());
    }
    assert!(Params::default().validate().is_ok());
    let p = Params {
        contact: ContactSource::File("/nonexistent/x.csv".into()),
        ..Params::default()
    };
    assert!(Bogie::new(p).is_err());

    let mut b = Bogie::with_table(Params::default(), synthetic_table()).unwrap();
    let bad = Inputs {
        damper_left_force_n: f64::NAN,
        ..Inputs::default()
    };
    match b.step(1e-3, &bad) {
        Err(StepError::NonFiniteInput { name, .. }) => assert_eq!(name, "damper_left_force_n"),
        r => panic!("{r:?}"),
    }
    assert!(b.outputs(&bad).is_err());
    let bad = Inputs {
        track_lateral_m: f64::INFINITY,
        ..Inputs::default()
    };
    assert!(b.step(1e-3, &bad).is_err());
    assert!(b.step(0.0, &Inputs::default()).is_err());
    assert!(b.step(f64::NAN, &Inputs::default()).is_err());
    // huge forces: an error, never NaN
    let huge = Inputs {
        damper_left_force_n: 1e12,
        ..Inputs::default()
    };
    let mut res = Ok(b.outputs(&Inputs::default()).unwrap());
    for _ in 0..1000 {
        res = b.step(1e-3, &huge);
        if res.is_err() {
            break;
        }
    }
    assert!(matches!(res, Err(StepError::Diverged { .. })), "{res:?}");
}

#[test]
fn state_save_restore_by_clone_and_serde() {
    let p = Params {
        initial_lateral_m: 3e-3,
        ..Params::default()
    };
    let mut a = Bogie::with_table(p, synthetic_table()).unwrap();
    let i = Inputs::default();
    for _ in 0..100 {
        a.step(1e-3, &i).unwrap();
    }
    let mut b = a.clone();
    let oa = a.step(1e-3, &i).unwrap();
    let ob = b.step(1e-3, &i).unwrap();
    assert_eq!(oa, ob);
    let json = serde_json::to_string(&a).unwrap();
    let mut c: Bogie = serde_json::from_str(&json).unwrap();
    assert_eq!(a.step(1e-3, &i).unwrap(), c.step(1e-3, &i).unwrap());
}

/// The built-in A/A table (EN 15302 profiles, from the wheel-rail crate): conventions and the
/// non-linear response. KNOWN DEVIATION (open): with this table the large gravitational
/// stiffness (P * d(tan g_R - tan g_L)/dy ~ 1.9 MN/m per wheelset) and the low
/// small-amplitude conicity make the bogie stable up to at least 320 km/h with the
/// placeholder damper, so R7's limit cycles are reproduced only with the synthetic cone
/// (tests above). Printed here; only the conventions and the 220 km/h decay are asserted.
#[test]
fn profiles_aa_table_conventions_and_response() {
    let t = fmu_bogie2dof::model::default_contact_table().unwrap();
    let (a, b) = (t.lookup(3e-3), t.lookup(-3e-3));
    // right wheel radius grows and its contact angle steepens to the right
    assert!(a.delta_r_right_m > b.delta_r_right_m && a.delta_r_left_m < b.delta_r_left_m);
    assert!(a.tan_gamma_right > a.tan_gamma_left && b.tan_gamma_left > b.tan_gamma_right);
    assert!(t.lookup(7.5e-3).tan_gamma_right > 2.0);
    let (lam, g) = t.linearise(3e-3);
    println!(
        "A/A: equivalent conicity(3 mm) {lam:.3}, gravity stiffness {:.2} MN/m per wheelset",
        g * 70e3 / 1e6
    );
    assert!(lam > 0.1 && lam < 0.3);
    for kmh in [220.0, 320.0] {
        let p = Params {
            speed_mps: kmh / 3.6,
            initial_lateral_m: 3e-3,
            ..Params::default()
        };
        let mut m = Bogie::new(p).unwrap();
        let mut peak_late: f64 = 0.0;
        run_closed_loop(&mut m, placeholder_loop(), 1e-3, 4.0, &|_| 0.0, &mut |o| {
            if o.time_s > 3.0 {
                peak_late = peak_late.max(o.wheelset_front_lateral_m.abs());
            }
        })
        .unwrap();
        println!(
            "A/A table, {kmh} km/h: peak wheelset displacement after 3 s {:.4} mm",
            peak_late * 1e3
        );
        if kmh < 250.0 {
            assert!(peak_late < 0.3e-3);
        }
    }
}
