//! Calibration against R15 (linear critical speed of the coach with the passive reference
//! damper, 280-290 km/h) and the numbers `calibration` documents. R16 with the hydraulic
//! passive damper itself is tested in the workspace's `tests/tests/vehicle_nonlinear.rs`
//! (this crate cannot depend on the damper crate); here R16's set-up runs with the linear
//! Maxwell stand-in.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use fmu_vehicle::calibration::*;
use fmu_vehicle::eigen::{analyse, critical_speed, DamperRepresentation, ModeKind, YawDamperModel};
use fmu_vehicle::model::worn_surrogate_table;
use fmu_vehicle::sim::{run_closed_loop, LinearDamper};
use fmu_vehicle::{ModelKind, Vehicle, VehicleParams};

fn maxwell() -> LinearDamper {
    LinearDamper::Maxwell {
        k: PASSIVE_MAXWELL_K_N_PER_M,
        c: PASSIVE_MAXWELL_C_NS_PER_M,
    }
}

#[test]
fn r15_linear_critical_speed_with_the_passive_damper() {
    let p = VehicleParams::default();
    let c = critical_speed(&p, &passive_damper(), 10.0, 160.0).unwrap();
    assert!(
        c.speed_kmh >= 280.0 && c.speed_kmh <= 290.0,
        "R15: {:.2} km/h",
        c.speed_kmh
    );
    assert!(
        (c.speed_kmh - TARGET_CRITICAL_SPEED_KMH).abs() < 0.5,
        "{c:?}"
    );
    // bogie hunting (not the car body), at a hunting frequency of 3-5 Hz
    assert_ne!(c.mode.kind, ModeKind::CarBody, "{c:?}");
    assert!(c.mode.shares.carbody < 0.2, "{c:?}");
    assert!(c.mode.freq_hz > 3.0 && c.mode.freq_hz < 5.0, "{c:?}");
    assert!(c.mode.re.abs() < 1e-3);
    // stable below, unstable above
    let d = passive_damper();
    assert!(analyse(&p, 275.0 / 3.6, &d).unwrap().max_re < 0.0);
    assert!(analyse(&p, 295.0 / 3.6, &d).unwrap().max_re > 0.0);
}

#[test]
fn calibration_function_reproduces_the_constant() {
    let (f, c) =
        calibrate_primary_stiffness_factor(&VehicleParams::default(), &passive_damper(), 285.0)
            .unwrap();
    assert!((c.speed_kmh - 285.0).abs() < 0.01, "{c:?}");
    assert!(
        (f - PRIMARY_STIFFNESS_FACTOR).abs() < 0.01 * f,
        "factor {f}"
    );
    // the published primary suspension alone is too stable for R15
    let mut p = VehicleParams::default();
    p.primary.kx_n_per_m = MB_PRIMARY_KX_N_PER_M;
    p.primary.ky_n_per_m = MB_PRIMARY_KY_N_PER_M;
    let c = critical_speed(&p, &passive_damper(), 10.0, 160.0).unwrap();
    assert!(c.speed_kmh > 320.0, "{c:?}");
}

#[test]
fn linear_contact_parameters_are_the_tables_at_1mm() {
    let t = worn_surrogate_table().unwrap();
    let (lambda, g_per_load) = t.linearise(1e-3);
    let p = VehicleParams::default();
    assert!((lambda - p.wheel_rail.conicity).abs() < 1e-3, "{lambda}");
    let kg = g_per_load * p.wheel_rail.wheel_load_n;
    assert!(
        (kg - p.wheel_rail.gravity_stiffness_n_per_m).abs() < 0.01 * kg,
        "{kg} vs {}",
        p.wheel_rail.gravity_stiffness_n_per_m
    );
}

/// Peak |y_rel| of the leading wheelset over [t_end - 2, t_end] and over [1, 3] s, and the
/// largest Y/Q over the last 2 s, from 3 mm initial lateral displacement of both bogies.
fn perturbation_run(kmh: f64, t_end: f64) -> (f64, f64, f64) {
    let p = VehicleParams {
        speed_mps: kmh / 3.6,
        initial: fmu_vehicle::params::Initial {
            lateral_m: 3e-3,
            yaw_rad: 0.0,
        },
        ..VehicleParams::default()
    };
    let mut v = Vehicle::new(p).unwrap();
    let (mut early, mut late, mut yq) = (0.0_f64, 0.0_f64, 0.0_f64);
    run_closed_loop(&mut v, maxwell(), 1e-3, t_end, &|_| 0.0, &mut |o| {
        let y = o.wheelset[0].lateral_rel_track_m.abs();
        if o.time_s > 1.0 && o.time_s < 3.0 {
            early = early.max(y);
        }
        if o.time_s > t_end - 2.0 {
            late = late.max(y);
            yq = yq.max(o.wheelset[0].y_over_q);
        }
    })
    .unwrap();
    (early, late, yq)
}

#[test]
fn r16_setup_with_the_maxwell_stand_in() {
    // 240 km/h: decays
    let (early, late, _) = perturbation_run(240.0, 12.0);
    assert!(early > 3e-4 && late < 0.05 * early, "{early} -> {late}");
    // 300 km/h: a tread limit cycle of 3-4.5 mm, no flange contact (the documented
    // difference to R16's 6-7 mm, which the hydraulic damper reaches)
    let (_, a, yq) = perturbation_run(300.0, 20.0);
    assert!(a > 3e-3 && a < 4.5e-3, "{a}");
    assert!(yq < 0.3, "Y/Q {yq}");
    // 320 km/h: larger, still on the tread
    let (_, b, _) = perturbation_run(320.0, 20.0);
    assert!(b > a && b < 6.0e-3, "{b}");
}

#[test]
fn time_domain_linear_growth_matches_the_eigenvalue() {
    // Without yaw dampers (nothing co-simulated beside the model), 15 km/h above the critical
    // speed: the envelope grows at the least stable eigenvalue's rate (two close bogie modes
    // beat, so peaks are taken over whole seconds six seconds apart).
    let none = YawDamperModel::rigid(DamperRepresentation::None);
    let base = VehicleParams::default();
    let vcr = critical_speed(&base, &none, 10.0, 160.0).unwrap();
    let p = VehicleParams {
        speed_mps: (vcr.speed_kmh + 15.0) / 3.6,
        model: ModelKind::Linear,
        initial: fmu_vehicle::params::Initial {
            lateral_m: 1e-7,
            yaw_rad: 0.0,
        },
        ..base
    };
    let re = analyse(&p, p.speed_mps, &none)
        .unwrap()
        .least_stable
        .unwrap()
        .re;
    let mut v = Vehicle::new(p).unwrap();
    let mut peaks = [0.0_f64; 11];
    run_closed_loop(&mut v, LinearDamper::None, 1e-3, 11.0, &|_| 0.0, &mut |o| {
        let k = (o.time_s as usize).min(10);
        peaks[k] = peaks[k].max(o.wheelset[0].lateral_m.abs());
    })
    .unwrap();
    let rate = (peaks[10] / peaks[4]).ln() / 6.0;
    assert!(re > 0.3);
    assert!((rate - re).abs() < 0.03 * re, "{rate} vs {re}");
}

#[test]
fn root_locus_names_the_modes() {
    let p = VehicleParams::default();
    let speeds: Vec<f64> = [100.0, 200.0, 285.0].iter().map(|k| k / 3.6).collect();
    let rl = fmu_vehicle::eigen::root_locus(&p, &passive_damper(), &speeds).unwrap();
    assert_eq!(rl.len(), 3);
    // at 100 km/h the slowest-decaying oscillation is the car body's (about 0.6 Hz; by damping
    // ratio a wheelset mode near 90 Hz is the least damped one)
    let low = rl[0].least_stable.unwrap();
    assert_eq!(low.kind, ModeKind::CarBody, "{low:?}");
    assert!(low.shares.carbody > 0.9 && low.freq_hz < 1.5, "{low:?}");
    // at the critical speed it is the bogies' hunting at about 4 Hz
    let hunt = rl[2].least_stable.unwrap();
    assert_ne!(hunt.kind, ModeKind::CarBody);
    assert!(hunt.freq_hz > 3.0 && hunt.freq_hz < 5.0, "{hunt:?}");
    for r in &rl {
        assert_eq!(r.eigenvalues.len(), 2 * 17 + 4);
        let s = r.least_damped.unwrap().shares;
        assert!((s.carbody + s.front_bogie + s.rear_bogie - 1.0).abs() < 1e-9);
    }
    // the naming rule
    use fmu_vehicle::eigen::EnergyShares;
    let k = |c: f64, f: f64, r: f64| {
        ModeKind::from_shares(&EnergyShares {
            carbody: c,
            front_bogie: f,
            rear_bogie: r,
        })
    };
    assert_eq!(k(0.6, 0.2, 0.2), ModeKind::CarBody);
    assert_eq!(k(0.1, 0.7, 0.2), ModeKind::FrontBogie);
    assert_eq!(k(0.1, 0.2, 0.7), ModeKind::RearBogie);
    assert_eq!(k(0.1, 0.5, 0.4), ModeKind::BothBogies);
}

/// The sensitivity to yaw damping the calibration module documents: the calibrated coach's
/// closed valve (Maxwell, 16.9 MN/m in series with 330 kNs/m) lies far above the target shape
/// (350-385 km/h); a shorter arm with full Kalker coefficients would reach it (not adopted:
/// neither value has a source).
#[test]
fn sensitivity_to_yaw_damping() {
    let closed = YawDamperModel::rigid(DamperRepresentation::Maxwell {
        k: PASSIVE_MAXWELL_K_N_PER_M,
        c: 330e3,
    });
    let ideal = YawDamperModel::rigid(DamperRepresentation::Viscous { c: 210e3 });
    let p = VehicleParams::default();
    let c = critical_speed(&p, &closed, 10.0, 250.0).unwrap();
    assert!((c.speed_kmh - 695.8).abs() < 1.0, "{c:?}");
    let i = critical_speed(&p, &ideal, 10.0, 250.0).unwrap();
    assert!((i.speed_kmh - 335.9).abs() < 1.0, "{i:?}");
    let mut q = VehicleParams::default();
    q.geometry.damper_arm_m = 0.9;
    q.wheel_rail.creep_reduction = 1.0;
    let (f, pass) = calibrate_primary_stiffness_factor(&q, &passive_damper(), 285.0).unwrap();
    assert!((f - 2.25).abs() < 0.01, "{f}");
    assert!((pass.speed_kmh - 285.0).abs() < 0.01);
    q.primary.kx_n_per_m = f * MB_PRIMARY_KX_N_PER_M;
    q.primary.ky_n_per_m = f * MB_PRIMARY_KY_N_PER_M;
    let c = critical_speed(&q, &closed, 10.0, 250.0).unwrap();
    assert!(c.speed_kmh > 350.0 && c.speed_kmh < 385.0, "{c:?}");
    let i = critical_speed(&q, &ideal, 10.0, 250.0).unwrap();
    assert!(i.speed_kmh < 380.0, "{i:?}");
}
