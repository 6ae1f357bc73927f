//! Full-active actuator against the seed (REFERENCE.md R3, R4) plus numerics and
//! interface checks.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] fns

use fmu_damper::characterise::{actuator_frf, linearised_actuator_frf};
use fmu_damper::full_active::dead_zone_describing_gain;
use fmu_damper::{
    Actuator, ActuatorInputs, ActuatorModel, ActuatorParams, Complex64, RodMode, StepError,
};
use std::f64::consts::PI;

/// R3: cylinder eigenfrequency (3.68) with Table 3-2 = 319.7 rad/s (+-1 %).
#[test]
fn r3_cylinder_eigenfrequency() {
    let p = ActuatorParams::default();
    let wc = p.cylinder_eigenfrequency_radps();
    assert!((wc - 319.7).abs() < 0.01 * 319.7, "{wc}");
    // The linear cylinder model (3.67) has its -90 deg phase at omega_c.
    let g = p.cylinder_tf(Complex64::new(0.0, wc));
    assert!((g.arg().to_degrees() + 90.0).abs() < 1e-9);
}

/// The dead zone (3.47) with the corrected condition: no flow for |v| < beta.
#[test]
fn dead_zone_and_saturation() {
    let p = ActuatorParams::default();
    assert_eq!(p.dead_zone(0.29e-3), 0.0);
    assert_eq!(p.dead_zone(-0.29e-3), 0.0);
    assert!((p.dead_zone(0.5e-3) - 0.2e-3).abs() < 1e-15);
    assert!((p.dead_zone(-0.5e-3) + 0.2e-3).abs() < 1e-15);
    assert_eq!(p.dead_zone(5e-3), 1e-3);
    assert_eq!(p.dead_zone(-5e-3), -1e-3);
    // Describing function: zero inside the dead zone, ->1 just before saturation
    // matters, and 0.624 at |u| = alpha (beta/A = 0.3).
    assert_eq!(dead_zone_describing_gain(&p, 0.3e-3), 0.0);
    assert!((dead_zone_describing_gain(&p, 1e-3) - 0.6239).abs() < 1e-3);
}

/// Rod free, |u| = 0.3 alpha = beta: the spool never leaves the dead zone at low
/// frequency, so the rod does not move (seed's Table 3-2 + corrected (3.47)).
#[test]
fn command_at_dead_zone_gives_no_motion() {
    let p = ActuatorParams::default();
    let r = actuator_frf(&p, ActuatorModel::FullOrder, 0.3 * p.alpha_m, &[5.0]).unwrap();
    assert!(r[0].modulus_per_s < 1e-6, "{:?}", r[0]);
}

/// R4: full- vs reduced-order FRF (u -> rod velocity, |u| = alpha, rod free) on a dense grid
/// up to 600 rad/s: within 1.5 dB wherever the modulus is above a tenth of its 1 Hz value,
/// within 4 dB in the steep fall, the fall within 2 % in frequency; more than 25 % apart above
/// the valve frequency (1200 rad/s), where the spool poles cut the full-order response.
#[test]
fn r4_full_vs_reduced_frf() {
    let p = ActuatorParams::default();
    // a dense grid from 1 Hz up to 600 rad/s, the grid of `master characterise actuator`: a
    // coarse one (1, 5, 20, 50, 80, 95 Hz) steps over the steep fall between 50 and 76 Hz,
    // where the modulus drops two decades and the two models differ most
    let n = 300;
    let top_hz = 600.0 / (2.0 * std::f64::consts::PI);
    let low: Vec<f64> = (0..n)
        .map(|i| 10f64.powf(top_hz.log10() * i as f64 / (n - 1) as f64))
        .collect();
    let full = actuator_frf(&p, ActuatorModel::FullOrder, p.alpha_m, &low).unwrap();
    let red = actuator_frf(&p, ActuatorModel::ReducedOrder, p.alpha_m, &low).unwrap();
    let reference = full[0].modulus_per_s;
    let (mut worst_db, mut worst_above_db) = (0.0f64, 0.0f64);
    for (f, r) in full.iter().zip(&red) {
        let db = (20.0 * (f.modulus_per_s / r.modulus_per_s).log10()).abs();
        worst_db = worst_db.max(db);
        if f.modulus_per_s > 0.1 * reference {
            worst_above_db = worst_above_db.max(db);
        }
    }
    // where each falls below a tenth of the low-frequency modulus
    let tenth = |pts: &[fmu_damper::characterise::ActuatorFrfPoint]| {
        pts.iter()
            .find(|x| x.modulus_per_s < 0.1 * reference)
            .map(|x| x.freq_hz)
            .unwrap()
    };
    let (f_full, f_red) = (tenth(&full), tenth(&red));
    eprintln!(
        "R4: {worst_db:.2} dB worst, {worst_above_db:.2} dB above a tenth; a tenth at {f_full:.2} / {f_red:.2} Hz"
    );
    // the seed's "close" on its Bode plot: within about 1 dB (1.05 measured) wherever the response
    // is above a tenth of its low-frequency value; in the steep fall the reduced model lies
    // about 1.5 % higher in frequency, which gives up to 4 dB there
    assert!(worst_above_db < 1.5, "{worst_above_db} dB");
    assert!(worst_db < 4.0, "{worst_db} dB");
    assert!(
        (f_red / f_full - 1.0).abs() < 0.02,
        "{f_full} vs {f_red} Hz"
    );
    // above the valve poles (1200-2010 rad/s) the two part
    let high = [191.0, 250.0, 320.0];
    let full = actuator_frf(&p, ActuatorModel::FullOrder, p.alpha_m, &high).unwrap();
    let red = actuator_frf(&p, ActuatorModel::ReducedOrder, p.alpha_m, &high).unwrap();
    for (f, r) in full.iter().zip(&red) {
        let rel = (f.modulus_per_s - r.modulus_per_s).abs() / r.modulus_per_s;
        assert!(
            rel > 0.25 && f.modulus_per_s < r.modulus_per_s,
            "{f:?} vs {r:?}"
        );
    }
}

/// Linearised model (3.73): at low frequency it tends to C_q N / (A + C_qp sigma / A)
/// and its phase tends to 0; its resonance sits near omega_c.
#[test]
fn linearised_model_limits() {
    let p = ActuatorParams::default();
    let pl = 0.75 * p.supply_pressure_pa;
    let r = linearised_actuator_frf(&p, p.alpha_m, pl, &[0.01]).unwrap();
    let z = p.dead_zone(p.alpha_m);
    let n = dead_zone_describing_gain(&p, p.alpha_m);
    let a = p.mean_area_m2();
    let expect =
        p.flow_gain(pl) * n / (a + p.flow_pressure_coeff(z, pl) * p.viscous_friction_nspm / a);
    assert!((r[0].modulus_per_s / expect - 1.0).abs() < 1e-4);
    assert!(r[0].phase_deg.abs() < 1.0);
    // Seed convention (3.70) without the 1/2: flow gain larger by sqrt(2).
    let seed = ActuatorParams {
        load_flow_half_factor: false,
        ..p
    };
    assert!((seed.flow_gain(pl) / p.flow_gain(pl) - 2f64.sqrt()).abs() < 1e-12);
}

fn imposed_sine(
    model: ActuatorModel,
    leakage: f64,
    freq: f64,
    amp: f64,
    h: f64,
    midpoint: bool,
) -> (Complex64, Vec<f64>) {
    let p = ActuatorParams {
        model,
        rod: RodMode::Imposed,
        leakage_coeff_m3ps_per_pa: leakage,
        ..ActuatorParams::default()
    };
    let mut a = Actuator::new(p).unwrap();
    let w = 2.0 * PI * freq;
    let n_per = (1.0 / (freq * h)).round() as usize;
    let periods = 6;
    let mut forces = Vec::new();
    let mut h1 = Complex64::default();
    for k in 0..n_per * periods {
        let ts = if midpoint {
            (k as f64 + 0.5) * h
        } else {
            k as f64 * h
        };
        let i = ActuatorInputs {
            elongation_m: amp * (w * ts).sin(),
            elongation_velocity_mps: amp * w * (w * ts).cos(),
            ..Default::default()
        };
        let o = a.step(h, &i).unwrap();
        // Pressure force (no friction): the friction term is algebraic in the held
        // input velocity and jumps at velocity reversals, whatever the integrator.
        forces.push(o.push_force_n + o.friction_force_n);
        if k >= n_per * (periods - 1) {
            let t = (k + 1) as f64 * h;
            h1 += Complex64::new((w * t).cos(), -(w * t).sin()).scale(o.force_n);
        }
    }
    let h1 = h1.scale(2.0 / n_per as f64) / Complex64::new(0.0, -amp);
    (h1, forces)
}

/// Imposed rod motion with a closed valve (u = 0) and no leakage: the actuator is a
/// hydraulic spring `k = E A_A^2 / V_A0 + E A_B^2 / V_B0` (1.266 MN/m), in tension
/// when extended; Coulomb friction adds damping (Im) only.
#[test]
fn imposed_motion_closed_valve_is_hydraulic_spring() {
    let p = ActuatorParams::default();
    let k_h = p.bulk_modulus_pa * p.area_a_m2.powi(2) / p.volume_a0_m3
        + p.bulk_modulus_pa * p.area_b_m2.powi(2) / p.volume_b0_m3;
    for model in [ActuatorModel::FullOrder, ActuatorModel::ReducedOrder] {
        let (h1, _) = imposed_sine(model, 0.0, 4.0, 1e-3, 1e-3, true);
        assert!(
            (h1.re / k_h - 1.0).abs() < 0.01,
            "{model:?}: {h1:?} vs {k_h}"
        );
        assert!(h1.im > 0.0, "friction must dissipate");
    }
    // Leakage (C_L = 7e-10) relaxes the spring at low frequency.
    let (h1, _) = imposed_sine(ActuatorModel::FullOrder, 7e-10, 4.0, 1e-3, 1e-3, true);
    assert!(h1.re < 0.5 * k_h, "{h1:?}");
}

/// Step-size study of the stiff actuator (imposed 4 Hz, 3 mm, closed valve, with
/// leakage, input sampled at mid-step): the pressure force with h = 1e-4, 1e-3, 5e-3
/// agrees within 1 % of its peak (measured: 0.03 % at 1e-3 s, 0.7 % at 5e-3 s; the
/// residual is the held input against the 7 ms leakage relaxation, not the solver).
#[test]
fn actuator_step_size_study() {
    let (_, fine) = imposed_sine(ActuatorModel::FullOrder, 7e-10, 4.0, 3e-3, 1e-4, true);
    let peak = fine.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    for h in [1e-3, 5e-3] {
        let (_, coarse) = imposed_sine(ActuatorModel::FullOrder, 7e-10, 4.0, 3e-3, h, true);
        let ratio = (h / 1e-4).round() as usize;
        let worst = coarse
            .iter()
            .enumerate()
            .map(|(k, f)| (f - fine[(k + 1) * ratio - 1]).abs())
            .fold(0.0f64, f64::max);
        eprintln!("actuator h = {h}: max |dF| = {worst:.3} N of peak {peak:.1} N");
        assert!(worst < 0.01 * peak, "h = {h}: {worst} vs {peak}");
    }
}

/// The internal error test's tolerances (`solver.rtol`, which scales the absolute ones): on
/// the benchmark's reference stroke (3 mm at 4 Hz plus a 17 Hz ripple, IDF-like spool command
/// of 0.6 mm), 5 s of 1 ms steps with the default rtol 1e-6 give the force within 2e-4 of its
/// amplitude of a run at rtol 1e-8 (measured 8.4e-5; with the spool's tolerances 10 times
/// tighter, as before they scaled with its travel, 1.7e-5 at 1.7 times the cost); 100 times
/// looser tolerances do not (measured 1.3e-3 at rtol 1e-4), so the test fails if the defaults
/// are made too loose.
#[test]
fn actuator_tolerances_study() {
    use fmu_damper::perf::stroke;
    let forces = |rtol: f64| -> Vec<f64> {
        let mut p = ActuatorParams::default();
        p.solver.rtol = rtol;
        let mut a = Actuator::new(p).unwrap();
        (0..5000u64)
            .map(|k| {
                let (x, v) = stroke(k);
                let i = ActuatorInputs {
                    spool_command_m: 0.6e-3 * v / (3e-3 * 2.0 * PI * 4.0),
                    elongation_m: x,
                    elongation_velocity_mps: v,
                    ..Default::default()
                };
                a.step(1e-3, &i).unwrap().force_n
            })
            .collect()
    };
    let reference = forces(1e-8);
    let amplitude = reference.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    let error = |f: &[f64]| {
        f.iter()
            .zip(&reference)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f64, f64::max)
            / amplitude
    };
    let default = error(&forces(ActuatorParams::default().solver.rtol));
    let loose = error(&forces(1e-4));
    eprintln!(
        "force error of the amplitude {amplitude:.0} N: rtol 1e-6 {default:.2e}, 1e-4 {loose:.2e}"
    );
    assert!(default < 2e-4, "{default:e}");
    assert!(loose > 2e-4, "{loose:e}");
}

/// Active mode, rod blocked (imposed at rest), u = alpha: chamber A fills until the
/// valve flow equals the leakage, K z sqrt(P_S - P_A) = C_L (P_A - P_B) with
/// P_A + P_B = P_S by symmetry; the actuator pushes (force_n < 0).
#[test]
fn blocked_rod_pressure_matches_leakage_balance() {
    let p = ActuatorParams::default();
    let mut a = Actuator::new(p).unwrap();
    let i = ActuatorInputs {
        spool_command_m: p.alpha_m,
        ..Default::default()
    };
    let mut o = a.outputs().unwrap();
    for _ in 0..200 {
        o = a.step(1e-3, &i).unwrap();
    }
    let z = p.dead_zone(p.alpha_m);
    let k = p.valve_gain();
    // Solve K z sqrt((P_S - P_L)/2) = C_L P_L by bisection.
    let (mut lo, mut hi) = (0.0, p_s());
    for _ in 0..100 {
        let m = 0.5 * (lo + hi);
        if k * z * ((p_s() - m) / 2.0).sqrt() > p.leakage_coeff_m3ps_per_pa * m {
            lo = m
        } else {
            hi = m
        }
    }
    assert!(
        (o.load_pressure_pa / lo - 1.0).abs() < 0.01,
        "{} vs {lo}",
        o.load_pressure_pa
    );
    assert!(o.force_n < 0.0 && o.push_force_n > 0.0 && o.hydraulic_power_w > 0.0);
}

/// Rod free, constant u = alpha, F_L = 0: the rod reaches the velocity where the load
/// flow feeds the piston and the leakage, K z sqrt((P_S - P_L)/2) = A v + C_L P_L,
/// with P_L A = f(v) (friction). Both model orders.
#[test]
fn free_rod_steady_velocity_matches_flow_balance() {
    for model in [ActuatorModel::FullOrder, ActuatorModel::ReducedOrder] {
        let p = ActuatorParams {
            model,
            rod: RodMode::Free,
            ..ActuatorParams::default()
        };
        let mut a = Actuator::new(p).unwrap();
        let i = ActuatorInputs {
            spool_command_m: p.alpha_m,
            ..Default::default()
        };
        let mut o = a.outputs().unwrap();
        for _ in 0..300 {
            o = a.step(1e-3, &i).unwrap();
        }
        let z = p.dead_zone(p.alpha_m);
        let ar = p.mean_area_m2();
        let excess = |v: f64| {
            let pl = p.friction(v) / ar;
            p.valve_gain() * z * ((p_s() - pl) / 2.0).sqrt()
                - ar * v
                - p.leakage_coeff_m3ps_per_pa * pl
        };
        let (mut lo, mut hi) = (0.01, 2.0);
        for _ in 0..100 {
            let m = 0.5 * (lo + hi);
            if excess(m) > 0.0 {
                lo = m
            } else {
                hi = m
            }
        }
        assert!(
            (o.rod_velocity_mps / lo - 1.0).abs() < 0.005,
            "{model:?}: {} vs {lo}",
            o.rod_velocity_mps
        );
    }
}

fn p_s() -> f64 {
    ActuatorParams::default().supply_pressure_pa
}

#[test]
fn bad_parameters_are_rejected_by_name() {
    let base = ActuatorParams::default();
    let cases: [(&str, ActuatorParams); 5] = [
        (
            "volume_a0_m3",
            ActuatorParams {
                volume_a0_m3: -1e-3,
                ..base
            },
        ),
        (
            "bulk_modulus_pa",
            ActuatorParams {
                bulk_modulus_pa: -1e8,
                ..base
            },
        ),
        (
            "area_b_m2",
            ActuatorParams {
                area_b_m2: -1.0,
                ..base
            },
        ),
        (
            "moving_mass_kg",
            ActuatorParams {
                moving_mass_kg: f64::NAN,
                ..base
            },
        ),
        (
            "volume_b0_m3",
            ActuatorParams {
                volume_b0_m3: 1e-4, // < A h: chamber would empty
                ..base
            },
        ),
    ];
    for (name, p) in cases {
        let e = Actuator::new(p).unwrap_err();
        assert!(e.to_string().contains(name), "{e}");
    }
}

#[test]
fn nan_inputs_are_rejected() {
    let mut a = Actuator::new(ActuatorParams::default()).unwrap();
    for bad in [
        ActuatorInputs {
            spool_command_m: f64::NAN,
            ..Default::default()
        },
        ActuatorInputs {
            elongation_velocity_mps: f64::NEG_INFINITY,
            ..Default::default()
        },
    ] {
        assert!(matches!(
            a.step(1e-3, &bad),
            Err(StepError::BadInput { .. })
        ));
    }
}

/// Violent imposed motion and bang-bang commands never produce NaN, nor a force the supply
/// could not hold.
#[test]
fn extreme_inputs_stay_finite() {
    for model in [ActuatorModel::FullOrder, ActuatorModel::ReducedOrder] {
        let mut a = Actuator::new(ActuatorParams {
            model,
            ..ActuatorParams::default()
        })
        .unwrap();
        let mut x = 0.0;
        for k in 0..1000 {
            // no drift: the rod stays within its stroke
            let v = if k % 5 < 2 { 0.6 } else { -0.4 };
            x += v * 5e-3;
            let i = ActuatorInputs {
                spool_command_m: if k % 3 == 0 { 5e-3 } else { -5e-3 },
                elongation_m: x,
                elongation_velocity_mps: v,
                ..Default::default()
            };
            // finite is checked by `step` itself (the unwrap); the force stays within what the
            // supply pressure can hold on the piston, plus friction (measured: 8.1 kN at most)
            let o = a.step(5e-3, &i).unwrap();
            let p = ActuatorParams::default();
            let bound_n =
                1.1 * p.supply_pressure_pa * p.area_a_m2.max(p.area_b_m2) + p.coulomb_friction_n;
            assert!(
                o.force_n.abs() <= bound_n,
                "{model:?}, step {k}: {} N over {bound_n} N",
                o.force_n
            );
        }
    }
}

/// The rod cannot leave its cylinder: an elongation beyond the half stroke (with a rigid or a
/// soft mounting) is an error naming it, and the model is unchanged. 100 m gave a force of
/// 1.6 kN with fmi2OK.
#[test]
fn an_elongation_beyond_the_stroke_is_refused() {
    for mounting in [None, Some(1e7)] {
        let mut a = Actuator::new(ActuatorParams {
            mounting_stiffness_n_per_m: mounting,
            ..ActuatorParams::default()
        })
        .unwrap();
        let within = ActuatorInputs {
            elongation_m: 0.1,
            elongation_velocity_mps: 0.1,
            ..Default::default()
        };
        assert!(a.step(1e-3, &within).is_ok(), "{mounting:?}");
        let before = a.clone();
        let beyond = ActuatorInputs {
            elongation_m: 100.0,
            ..within
        };
        let e = a.step(1e-3, &beyond).unwrap_err();
        assert!(matches!(e, StepError::BeyondStroke { .. }), "{e}");
        assert!(e.to_string().contains("half stroke of 180.0 mm"), "{e}");
        assert_eq!(a, before);
    }
    // a mounting of 1 N/m would carry the starting force stretched by 800 m: the rod starts
    // outside its cylinder (it gave 808 N through that spring after 1 cm)
    let mut soft = Actuator::new(ActuatorParams {
        mounting_stiffness_n_per_m: Some(1.0),
        ..ActuatorParams::default()
    })
    .unwrap();
    let start = ActuatorInputs {
        elongation_velocity_mps: 0.1,
        ..Default::default()
    };
    let e = soft.step(1e-3, &start).unwrap_err();
    assert!(matches!(e, StepError::BeyondStroke { .. }), "{e}");
}
