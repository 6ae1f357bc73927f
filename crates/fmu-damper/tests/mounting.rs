//! The optional mounting (series) stiffness k_m of the damper installation: a spring in series
//! with the damper, so the damper's own elongation is the imposed one less F/k_m.
//! - a very stiff mounting converges to the rigid damper;
//! - at 10 MN/m (MPE 2019) the equivalent damping at 4 Hz falls by what the series-spring
//!   formula Z = Z_d k_m / (Z_d + k_m) predicts from the rigid damper's k_eq, c_eq;
//! - the actuator's mounted mode converges to its rigid one;
//! - through the FMU, `damper.mounting_stiffness` = 0 is the rigid default.

#![allow(clippy::unwrap_used, clippy::panic)]

use std::f64::consts::PI;

use fmu_damper::characterise::damper_frf_point;
use fmu_damper::{
    Actuator, ActuatorInputs, ActuatorParams, Complex64, ParamError, RodMode, SemiActiveDamper,
    SemiActiveInputs, SemiActiveParams,
};
use model_description::{rust_component, value_reference, FmuModel, InstanceContext, Status};

/// Force history of the passive damper (30 %) under a 3 mm, 4 Hz stroke for 0.5 s.
fn semi_force(k_m: Option<f64>) -> Vec<f64> {
    let p = SemiActiveParams {
        mounting_stiffness_n_per_m: k_m,
        ..SemiActiveParams::passive_reference()
    };
    let mut d = SemiActiveDamper::new(p).unwrap();
    let (amp, w, h) = (3e-3, 2.0 * PI * 4.0, 1e-3);
    (0..500)
        .map(|k| {
            let t = (k as f64 + 0.5) * h;
            let inputs = SemiActiveInputs {
                elongation_m: amp * (w * t).sin(),
                elongation_velocity_mps: amp * w * (w * t).cos(),
                valve_command_v: 0.0,
            };
            d.step(h, &inputs).unwrap().force_n
        })
        .collect()
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn a_stiff_mounting_converges_to_the_rigid_damper() {
    let rigid = semi_force(None);
    let peak = rigid.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    let errors: Vec<f64> = [1e8, 1e10, 1e12]
        .iter()
        .map(|&k| max_diff(&semi_force(Some(k)), &rigid) / peak)
        .collect();
    eprintln!("max |F - F_rigid| / F_peak for k_m = 1e8, 1e10, 1e12 N/m: {errors:?}");
    assert!(errors[0] > errors[1] && errors[1] > errors[2], "{errors:?}");
    assert!(
        errors[0] > 1e-3,
        "1e8 N/m must make a difference: {errors:?}"
    );
    // The difference falls like 1/k_m (the spring's deflection F/k_m).
    assert!(errors[1] / errors[2] > 30.0, "{errors:?}");
    assert!(errors[2] < 1e-4, "{errors:?}");
}

/// The series-spring prediction of the mounted damper's c_eq from the rigid damper's
/// k_eq, c_eq at the same stroke.
fn series_c_eq(k_eq: f64, c_eq: f64, k_m: f64, omega: f64) -> f64 {
    let zd = Complex64::new(k_eq, omega * c_eq);
    let km = Complex64::from(k_m);
    (zd * km / (zd + km)).im / omega
}

#[test]
fn at_10_mn_per_m_the_damping_falls_as_the_series_spring_formula_predicts() {
    let (f, amp, k_m) = (4.0, 1e-3, 10e6);
    let omega = 2.0 * PI * f;
    for opening in [0.0, 0.3] {
        let rigid = SemiActiveParams::default();
        let mounted = SemiActiveParams {
            mounting_stiffness_n_per_m: Some(k_m),
            ..rigid
        };
        let r = damper_frf_point(&rigid, opening, f, amp).unwrap();
        let m = damper_frf_point(&mounted, opening, f, amp).unwrap();
        let predicted = series_c_eq(r.k_eq_n_per_m, r.c_eq_ns_per_m, k_m, omega);
        let fall = r.c_eq_ns_per_m - m.c_eq_ns_per_m;
        let fall_predicted = r.c_eq_ns_per_m - predicted;
        eprintln!(
            "opening {opening}: rigid k_eq {:.0} N/m, c_eq {:.0} N.s/m; mounted c_eq {:.0}; \
             series formula {predicted:.0}; fall {fall:.0} vs {fall_predicted:.0} predicted",
            r.k_eq_n_per_m, r.c_eq_ns_per_m, m.c_eq_ns_per_m
        );
        assert!(fall > 0.1 * r.c_eq_ns_per_m, "opening {opening}: {fall}");
        assert!(
            (fall - fall_predicted).abs() < 0.05 * fall_predicted,
            "opening {opening}: fall {fall} vs {fall_predicted} predicted"
        );
    }
}

#[test]
fn a_mounting_stiffness_must_be_positive() {
    for k in [0.0, -1.0, f64::NAN] {
        let p = SemiActiveParams {
            mounting_stiffness_n_per_m: Some(k),
            ..SemiActiveParams::default()
        };
        let e = SemiActiveDamper::new(p).err().unwrap();
        assert!(matches!(
            e,
            ParamError::NotPositive {
                name: "mounting_stiffness_n_per_m",
                ..
            } | ParamError::NotFinite {
                name: "mounting_stiffness_n_per_m",
                ..
            }
        ));
        let a = ActuatorParams {
            mounting_stiffness_n_per_m: Some(k),
            ..ActuatorParams::default()
        };
        assert!(Actuator::new(a).is_err());
    }
}

/// Force history of the imposed-rod actuator under a 1 mm, 4 Hz stroke with a 0.6 mm spool
/// command, for 0.25 s in 0.1 ms steps; `stribeck_n` is the static friction F_s.
fn actuator_force(k_m: Option<f64>, stribeck_n: f64) -> Vec<f64> {
    let p = ActuatorParams {
        rod: RodMode::Imposed,
        mounting_stiffness_n_per_m: k_m,
        leakage_coeff_m3ps_per_pa: 7e-13,
        stribeck_friction_n: stribeck_n,
        ..ActuatorParams::default()
    };
    let mut a = Actuator::new(p).unwrap();
    let (amp, w, h) = (1e-3, 2.0 * PI * 4.0, 1e-4);
    (0..2500)
        .map(|k| {
            let t = (k as f64 + 0.5) * h;
            let inputs = ActuatorInputs {
                spool_command_m: 0.6e-3,
                load_force_n: 0.0,
                elongation_m: amp * (w * t).sin(),
                elongation_velocity_mps: amp * w * (w * t).cos(),
            };
            a.step(h, &inputs).unwrap().force_n
        })
        .collect()
}

fn peak(f: &[f64]) -> f64 {
    f.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Without Table 3-2's Stribeck drop (F_s = F_c: friction never falls with speed) the rod mode
/// behind the spring is damped and a stiff mounting converges to the rigid, imposed rod.
#[test]
fn the_mounted_actuator_converges_to_the_rigid_one() {
    let f_c = ActuatorParams::default().coulomb_friction_n;
    let rigid = actuator_force(None, f_c);
    let errors: Vec<f64> = [1e8, 1e9, 1e10]
        .iter()
        .map(|&k| max_diff(&actuator_force(Some(k), f_c), &rigid) / peak(&rigid))
        .collect();
    eprintln!("actuator: max |F - F_rigid| / F_peak for k_m = 1e8, 1e9, 1e10 N/m: {errors:?}");
    assert!(errors[0] > errors[1] && errors[1] > errors[2], "{errors:?}");
    assert!(errors[2] < 1e-3, "{errors:?}");
}

/// With Table 3-2's friction (F_s = 900 N > F_c = 600 N) the friction slope is negative at
/// a few mm/s; behind the 10 MN/m of MPE 2019 the rod mode (about 900 rad/s) stays smooth.
#[test]
fn with_table_3_2_friction_a_10_mn_per_m_mounting_runs_smoothly() {
    let f_s = ActuatorParams::default().stribeck_friction_n;
    let f = actuator_force(Some(10e6), f_s);
    let rigid = actuator_force(None, f_s);
    let second_difference = f
        .windows(3)
        .map(|w| (w[0] - 2.0 * w[1] + w[2]).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "actuator at 10 MN/m: peak {:.0} N (rigid {:.0} N), max second difference {second_difference:.1} N",
        peak(&f),
        peak(&rigid)
    );
    assert!(second_difference < 1e-3 * peak(&f), "{second_difference}");
    assert!((peak(&f) - peak(&rigid)).abs() < 0.1 * peak(&rigid));
}

#[test]
fn through_the_fmu_zero_is_rigid_and_a_stiffness_changes_the_force() {
    use fmu_damper::fmu::PassiveYawDamper as M;
    let run = |k_m: f64| {
        let (mut c, _log) = rust_component::<M>(InstanceContext::default()).unwrap();
        let vr = value_reference::<M>("damper.mounting_stiffness").unwrap();
        assert_eq!(c.set_real(&[vr], &[k_m]), Status::Ok);
        assert_eq!(c.setup_experiment(0.0, None), Status::Ok);
        assert_eq!(c.enter_initialization_mode(), Status::Ok);
        assert!(c.exit_initialization_mode() <= Status::Warning);
        let de = M::INFO.default_experiment;
        for k in 0..200 {
            assert!(c.do_step(k as f64 * de.step_size, de.step_size) <= Status::Warning);
        }
        let mut f = [0.0];
        assert_eq!(
            c.get_real(&[value_reference::<M>("damper.force").unwrap()], &mut f),
            Status::Ok
        );
        f[0]
    };
    let (rigid, zero, soft) = (run_default(), run(0.0), run(1e5));
    assert_eq!(
        zero.to_bits(),
        rigid.to_bits(),
        "0 must be the rigid default"
    );
    assert!(
        (soft - rigid).abs() > 1e-3 * rigid.abs(),
        "{soft} vs {rigid}"
    );

    fn run_default() -> f64 {
        let (mut c, _log) = rust_component::<M>(InstanceContext::default()).unwrap();
        assert_eq!(c.setup_experiment(0.0, None), Status::Ok);
        assert_eq!(c.enter_initialization_mode(), Status::Ok);
        assert!(c.exit_initialization_mode() <= Status::Warning);
        let de = M::INFO.default_experiment;
        for k in 0..200 {
            assert!(c.do_step(k as f64 * de.step_size, de.step_size) <= Status::Warning);
        }
        let mut f = [0.0];
        assert_eq!(
            c.get_real(&[value_reference::<M>("damper.force").unwrap()], &mut f),
            Status::Ok
        );
        f[0]
    }
}

/// The largest second difference of a force history relative to its peak: a smooth 4 Hz force
/// in 0.1 ms steps stays far below 1e-3, a chattering one does not.
fn roughness(f: &[f64]) -> f64 {
    f.windows(3)
        .map(|w| (w[0] - 2.0 * w[1] + w[2]).abs())
        .fold(0.0, f64::max)
        / peak(f)
}

/// Behind a mounting stiffer than the smooth limit, Table 3-2's friction makes the rod chatter
/// and the FMU says so at initialisation (fmi2Warning naming the parameter); at or below the
/// limit, or without the Stribeck drop, it is silent.
#[test]
fn a_mounting_stiffer_than_the_smooth_limit_chatters_and_the_fmu_warns() {
    use fmu_damper::fmu::FullActiveActuator as A;
    use fmu_damper::full_active::SMOOTH_MOUNTING_LIMIT_N_PER_M;
    let f_s = ActuatorParams::default().stribeck_friction_n;
    let f_c = ActuatorParams::default().coulomb_friction_n;
    let rough: Vec<f64> = [1e7, SMOOTH_MOUNTING_LIMIT_N_PER_M, 1e10]
        .iter()
        .map(|&k| roughness(&actuator_force(Some(k), f_s)))
        .collect();
    eprintln!("roughness at 1e7, limit, 1e10 N/m: {rough:?}");
    assert!(rough[0] < 1e-3 && rough[1] < 1e-2, "{rough:?}");
    assert!(rough[2] > 10.0 * rough[1], "{rough:?}");

    let exit = |k_m: f64, stribeck: f64| {
        let (mut c, log) = rust_component::<A>(InstanceContext::default()).unwrap();
        let set = |c: &mut model_description::Component, name: &str, x: f64| {
            c.set_real(&[value_reference::<A>(name).unwrap()], &[x])
        };
        assert_eq!(set(&mut c, "damper.mounting_stiffness", k_m), Status::Ok);
        assert_eq!(set(&mut c, "friction.stribeck", stribeck), Status::Ok);
        assert_eq!(c.setup_experiment(0.0, None), Status::Ok);
        assert_eq!(c.enter_initialization_mode(), Status::Ok);
        let status = c.exit_initialization_mode();
        (status, format!("{:?}", log.take()))
    };
    let (status, log) = exit(1e10, f_s);
    assert_eq!(status, Status::Warning, "{log}");
    assert!(
        log.contains("damper.mounting_stiffness = 1e10 N/m"),
        "{log}"
    );
    for (k_m, stribeck) in [(1e7, f_s), (0.0, f_s), (1e10, f_c)] {
        let (status, log) = exit(k_m, stribeck);
        assert_eq!(status, Status::Ok, "k_m {k_m}, F_s {stribeck}: {log}");
    }
}
