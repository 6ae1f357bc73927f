//! Convergence study of the internal RK4 sub-step (`calibration::SOLVER_SUBSTEP_S`): the
//! time-domain critical speed and a flange-contact limit cycle with the default sub-step must
//! agree with a run at a 10 times smaller sub-step within 1 km/h and 0.1 mm (and Y/Q within
//! 5 %). Run at the 1 ms communication step of the studies, and at a 10 ms communication step,
//! where the sub-step constant itself is what limits the internal step (so raising it fails
//! here).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use fmu_vehicle::calibration::{PASSIVE_MAXWELL_C_NS_PER_M, PASSIVE_MAXWELL_K_N_PER_M};
use fmu_vehicle::params::Initial;
use fmu_vehicle::sim::{run_closed_loop, LinearDamper};
use fmu_vehicle::{ModelKind, Vehicle, VehicleParams};

fn params(kmh: f64, model: ModelKind, substep_s: f64, y0: f64) -> VehicleParams {
    VehicleParams {
        speed_mps: kmh / 3.6,
        model,
        solver_substep_s: substep_s,
        initial: Initial {
            lateral_m: y0,
            yaw_rad: 0.0,
        },
        ..VehicleParams::default()
    }
}

/// Flange-contact limit cycle: 320 km/h, yaw dampers at 30 % of the passive damping
/// (Y/Q about 2 on the flange). Returns (amplitude of the leading wheelset over the last 2 s,
/// largest Y/Q there).
fn flange_limit_cycle(substep_s: f64, h: f64) -> (f64, f64) {
    let mut v = Vehicle::new(params(320.0, ModelKind::NonLinear, substep_s, 3e-3)).unwrap();
    let d = LinearDamper::Maxwell {
        k: PASSIVE_MAXWELL_K_N_PER_M,
        c: 0.3 * PASSIVE_MAXWELL_C_NS_PER_M,
    };
    let (mut a, mut yq) = (0.0_f64, 0.0_f64);
    run_closed_loop(&mut v, d, h, 15.0, &|_| 0.0, &mut |o| {
        if o.time_s > 13.0 {
            a = a.max(o.wheelset[0].lateral_rel_track_m.abs());
            yq = yq.max(o.wheelset[0].y_over_q);
        }
    })
    .unwrap();
    (a, yq)
}

/// Envelope growth rate [1/s] of the linear model with the passive Maxwell dampers.
fn growth_rate(kmh: f64, substep_s: f64, h: f64) -> f64 {
    let mut v = Vehicle::new(params(kmh, ModelKind::Linear, substep_s, 1e-5)).unwrap();
    let d = LinearDamper::Maxwell {
        k: PASSIVE_MAXWELL_K_N_PER_M,
        c: PASSIVE_MAXWELL_C_NS_PER_M,
    };
    let (mut a1, mut a2) = (0.0_f64, 0.0_f64);
    run_closed_loop(&mut v, d, h, 8.0, &|_| 0.0, &mut |o| {
        let y = o.wheelset[0].lateral_m.abs();
        if o.time_s > 2.0 && o.time_s < 4.0 {
            a1 = a1.max(y);
        }
        if o.time_s > 6.0 {
            a2 = a2.max(y);
        }
    })
    .unwrap();
    (a2 / a1).ln() / 4.0
}

/// Speed where the growth rate changes sign (bisection to 0.05 km/h) [km/h].
fn time_domain_critical_speed(substep_s: f64, h: f64) -> f64 {
    let (mut lo, mut hi) = (260.0, 310.0);
    assert!(growth_rate(lo, substep_s, h) < 0.0 && growth_rate(hi, substep_s, h) > 0.0);
    while hi - lo > 0.05 {
        let mid = 0.5 * (lo + hi);
        if growth_rate(mid, substep_s, h) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

fn check(h: f64) {
    let coarse = VehicleParams::default().solver_substep_s;
    let fine = coarse / 10.0;
    let (a, yq) = flange_limit_cycle(coarse, h);
    let (a_ref, yq_ref) = flange_limit_cycle(fine, h);
    eprintln!(
        "h = {h} s: limit cycle {:.4} / {:.4} mm, Y/Q {yq:.3} / {yq_ref:.3}",
        a * 1e3,
        a_ref * 1e3
    );
    assert!(yq_ref > 0.6, "flange contact expected, Y/Q {yq_ref}");
    assert!((a - a_ref).abs() < 1e-4, "{a} vs {a_ref}");
    assert!((yq - yq_ref).abs() < 0.05 * yq_ref, "Y/Q {yq} vs {yq_ref}");
    let v = time_domain_critical_speed(coarse, h);
    let v_ref = time_domain_critical_speed(fine, h);
    eprintln!("h = {h} s: critical speed {v:.2} / {v_ref:.2} km/h");
    assert!((v - v_ref).abs() < 1.0, "{v} vs {v_ref}");
}

#[test]
fn convergence_at_the_1ms_communication_step() {
    check(1e-3);
}

#[test]
fn convergence_at_a_10ms_communication_step() {
    check(1e-2);
}
