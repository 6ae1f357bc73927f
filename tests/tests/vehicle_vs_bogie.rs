//! The coach and the 2-dof bogie are one model family: with the car body made very heavy and
//! the primary suspension very stiff, the coach's linear critical speed and hunting frequency
//! reduce to the 2-dof bogie's with the same parameters (within 1 %); and both ship the same
//! default contact table and passive-damper fit.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use fmu_bogie2dof::{calibration as bogie_cal, eigen as bogie_eigen, Params};
use fmu_vehicle::{calibration as vehicle_cal, eigen, VehicleParams};

/// The coach with the bogie's parameters: car body 1000 times heavier (fixed at the hunting
/// frequency), primary suspension 1e10 N/m in all directions (rigid), no gravitational roll
/// terms (they act on the car body, which no longer moves, and the frames, which the rigid
/// primary holds), the secondary longitudinal stiffness k_ssx at the yaw-damper arm b, no
/// secondary lateral dampers, torsional air-spring stiffness or anti-roll bar (the bogie has
/// none), the frame carrying the bogie's mass and yaw inertia minus the wheelsets'.
fn coach_like_bogie(b: &Params) -> VehicleParams {
    let mut v = VehicleParams::default();
    let scale = 1e3;
    v.carbody.mass_kg *= scale;
    v.carbody.yaw_inertia_kgm2 *= scale;
    v.carbody.roll_inertia_kgm2 *= scale;
    v.gravity_mps2 = 0.0;
    v.primary.kx_n_per_m = 1e10;
    v.primary.ky_n_per_m = 1e10;
    v.primary.kz_n_per_m = 1e10;
    let w = &v.wheelset;
    let p = b.half_wheelbase_m;
    v.frame.mass_kg = b.bogie_mass_kg - 2.0 * w.mass_kg;
    v.frame.yaw_inertia_kgm2 =
        b.bogie_yaw_inertia_kgm2 - 2.0 * (w.yaw_inertia_kgm2 + w.mass_kg * p * p);
    v.geometry.half_wheelbase_m = p;
    v.geometry.damper_arm_m = b.damper_arm_m;
    v.geometry.secondary_half_spacing_m = b.damper_arm_m;
    v.wheelset.half_contact_gauge_m = b.half_contact_gauge_m;
    v.wheelset.wheel_radius_m = b.wheel_radius_m;
    v.wheelset.spin_inertia_kgm2 = b.wheelset_spin_inertia_kgm2;
    v.secondary.ky_n_per_m = b.k_ssy_n_per_m;
    v.secondary.kx_n_per_m = b.k_ssx_n_per_m;
    v.secondary.yaw_stiffness_nm_per_rad = 0.0;
    v.secondary.lateral_damping_ns_per_m = 0.0;
    v.secondary.anti_roll_bar_nm_per_rad = 0.0;
    let r = &mut v.wheel_rail;
    r.conicity = b.conicity;
    r.gravity_stiffness_n_per_m = b.gravity_stiffness_n_per_m;
    r.f11_n = b.f11_n;
    r.f22_n = b.f22_n;
    r.creep_reduction = b.creep_reduction;
    r.wheel_load_n = b.wheel_load_n;
    r.friction_coefficient = b.friction_coefficient;
    v
}

#[test]
fn heavy_car_body_and_rigid_primary_reduce_the_coach_to_the_bogie() {
    let b = Params::default();
    let bc = bogie_eigen::critical_speed(&b, &bogie_cal::passive_damper(), 5.0, 199.0).unwrap();
    let v = coach_like_bogie(&b);
    let vc = eigen::critical_speed(&v, &vehicle_cal::passive_damper(), 10.0, 160.0).unwrap();
    eprintln!(
        "bogie {:.2} km/h {:.3} Hz; coach reduced {:.2} km/h {:.3} Hz ({})",
        bc.speed_kmh,
        bc.hunting.freq_hz,
        vc.speed_kmh,
        vc.mode.freq_hz,
        vc.mode.kind.label()
    );
    assert!((vc.speed_kmh - bc.speed_kmh).abs() < 0.01 * bc.speed_kmh);
    assert!((vc.mode.freq_hz - bc.hunting.freq_hz).abs() < 0.01 * bc.hunting.freq_hz);
    assert!(vc.mode.shares.carbody < 1e-3, "{:?}", vc.mode.shares);
    // and the reduction is not trivially met: with the real car body and primary suspension
    // (same bogie data otherwise) the coach differs by far more than 1 %
    let mut real = v.clone();
    let d = VehicleParams::default();
    real.carbody = d.carbody;
    real.primary = d.primary;
    real.gravity_mps2 = d.gravity_mps2;
    let rc = eigen::critical_speed(&real, &vehicle_cal::passive_damper(), 10.0, 160.0).unwrap();
    eprintln!(
        "with the real car body and primary: {:.2} km/h",
        rc.speed_kmh
    );
    assert!((rc.speed_kmh - bc.speed_kmh).abs() > 0.03 * bc.speed_kmh);
}

#[test]
fn both_models_share_the_contact_table_and_the_damper_fit() {
    let bogie_file = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../crates/fmu-bogie2dof/resources/wheel_rail_worn_surrogate.csv");
    let bogie_csv = std::fs::read_to_string(bogie_file).unwrap();
    assert_eq!(fmu_vehicle::model::WORN_SURROGATE_CSV, bogie_csv);
    assert_eq!(
        vehicle_cal::PASSIVE_MAXWELL_K_N_PER_M,
        bogie_cal::PASSIVE_MAXWELL_K_N_PER_M
    );
    assert_eq!(
        vehicle_cal::PASSIVE_MAXWELL_C_NS_PER_M,
        bogie_cal::PASSIVE_MAXWELL_C_NS_PER_M
    );
    let b = Params::default();
    let v = VehicleParams::default();
    assert_eq!(v.wheel_rail.conicity, b.conicity);
    assert_eq!(v.wheel_rail.creep_reduction, b.creep_reduction);
    assert_eq!(v.wheel_rail.friction_coefficient, b.friction_coefficient);
    assert_eq!(v.geometry.damper_arm_m, b.damper_arm_m);
    assert_eq!(v.wheelset.half_contact_gauge_m, b.half_contact_gauge_m);
    // the vehicle's gravitational stiffness is the bogie's per newton of wheel load
    let per_load = |k: f64, p: f64| k / p;
    assert!(
        (per_load(
            v.wheel_rail.gravity_stiffness_n_per_m,
            v.wheel_rail.wheel_load_n
        ) - per_load(b.gravity_stiffness_n_per_m, b.wheel_load_n))
        .abs()
            < 1e-9
    );
    // Kalker coefficients at the bogie's load, scaled by (P/P_bogie)^(2/3)
    let s = (v.wheel_rail.wheel_load_n / b.wheel_load_n).powf(2.0 / 3.0);
    assert!((v.wheel_rail.f11_n - s * b.f11_n).abs() < 1e-6 * b.f11_n);
    assert!((v.wheel_rail.f22_n - s * b.f22_n).abs() < 1e-6 * b.f22_n);
}
