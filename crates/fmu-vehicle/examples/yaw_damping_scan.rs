//! Sensitivity of the coach's linear critical speed to yaw damping, over the candidate
//! parameters of the calibration: for each candidate value the common primary stiffness factor
//! is re-found for 285 km/h with the passive reference damper (where it can be), then the
//! critical speed with a closed semi-active valve (Maxwell, 16.9 MN/m in series with
//! 330 kNs/m) and with ideal 210 kNs/m dampers is computed.
//!
//! `cargo run --release -p fmu-vehicle --example yaw_damping_scan`
use fmu_vehicle::calibration::{self, calibrate_primary_stiffness_factor, passive_damper};
use fmu_vehicle::eigen::{critical_speed, DamperRepresentation, YawDamperModel};
use fmu_vehicle::VehicleParams;

const CLOSED_VALVE_C_NS_PER_M: f64 = 330e3;
const IDEAL_C_NS_PER_M: f64 = 210e3;

fn closed_valve() -> YawDamperModel {
    YawDamperModel::rigid(DamperRepresentation::Maxwell {
        k: calibration::PASSIVE_MAXWELL_K_N_PER_M,
        c: CLOSED_VALVE_C_NS_PER_M,
    })
}

fn ideal() -> YawDamperModel {
    YawDamperModel::rigid(DamperRepresentation::Viscous {
        c: IDEAL_C_NS_PER_M,
    })
}

fn vcr(p: &VehicleParams, d: &YawDamperModel) -> String {
    match critical_speed(p, d, 10.0, 250.0) {
        Ok(c) => format!("{:6.1}", c.speed_kmh),
        Err(_) => "   >900".to_string(),
    }
}

/// Prints one row: the candidate, the re-calibrated factor, passive / closed / ideal.
fn row(label: &str, base: &VehicleParams, recalibrate: bool) {
    let (p, f) = if recalibrate {
        match calibrate_primary_stiffness_factor(base, &passive_damper(), 285.0) {
            Ok((f, _)) => {
                let mut p = base.clone();
                p.primary.kx_n_per_m = f * calibration::MB_PRIMARY_KX_N_PER_M;
                p.primary.ky_n_per_m = f * calibration::MB_PRIMARY_KY_N_PER_M;
                (p, format!("{f:6.2}"))
            }
            Err(_) => (base.clone(), "  none".to_string()),
        }
    } else {
        (base.clone(), "     -".to_string())
    };
    println!(
        "{label:<40} {f}  {}  {}  {}",
        vcr(&p, &passive_damper()),
        vcr(&p, &closed_valve()),
        vcr(&p, &ideal())
    );
}

fn main() {
    println!("candidate                                factor  passive closed  ideal210 [km/h]");
    let d = VehicleParams::default();
    row("default", &d, false);
    // split of the primary stiffness factor: kx factor x ky factor
    for fx in [1.0, 2.0, 3.15, 5.0, 10.0, 30.0] {
        for fy in [1.0, 2.0, 3.15, 5.0, 10.0, 30.0] {
            let mut p = d.clone();
            p.primary.kx_n_per_m = fx * calibration::MB_PRIMARY_KX_N_PER_M;
            p.primary.ky_n_per_m = fy * calibration::MB_PRIMARY_KY_N_PER_M;
            row(&format!("primary kx x{fx} ky x{fy}"), &p, false);
        }
    }
    for lambda in [0.10, 0.15, 0.20, 0.25, 0.30, 0.35, 0.40] {
        let mut p = d.clone();
        p.wheel_rail.conicity = lambda;
        row(&format!("conicity {lambda}"), &p, true);
    }
    for b in [0.9, 1.0, 1.1, 1.2, 1.35] {
        let mut p = d.clone();
        p.geometry.damper_arm_m = b;
        row(&format!("damper arm {b} m"), &p, true);
    }
    for kx in [160e3, 300e3, 500e3, 1e6, 2e6] {
        let mut p = d.clone();
        p.secondary.kx_n_per_m = kx;
        row(&format!("secondary kx {} kN/m", kx / 1e3), &p, true);
    }
    for kappa in [0.3, 0.45, 0.6, 0.8, 1.0] {
        let mut p = d.clone();
        p.wheel_rail.creep_reduction = kappa;
        row(&format!("creep reduction {kappa}"), &p, true);
    }
    for (name, scale) in [
        ("gravity stiffness x0.5", 0.5),
        ("gravity stiffness x2", 2.0),
    ] {
        let mut p = d.clone();
        p.wheel_rail.gravity_stiffness_n_per_m *= scale;
        row(name, &p, true);
    }
    // combinations of the two candidates that lower the closed-valve speed most
    for (arm, kappa, lambda) in [
        (1.0, 1.0, 0.25),
        (1.0, 1.0, 0.30),
        (0.9, 1.0, 0.25),
        (1.0, 0.8, 0.30),
    ] {
        let mut p = d.clone();
        p.geometry.damper_arm_m = arm;
        p.wheel_rail.creep_reduction = kappa;
        p.wheel_rail.conicity = lambda;
        row(
            &format!("arm {arm} m, creep red. {kappa}, conicity {lambda}"),
            &p,
            true,
        );
    }
    // the series stiffness of the closed valve (mounting): 16.9 MN/m is the passive fit
    for k in [2e6, 5e6, 10e6, 16.9e6] {
        let m = YawDamperModel::rigid(DamperRepresentation::Maxwell {
            k,
            c: CLOSED_VALVE_C_NS_PER_M,
        });
        println!(
            "closed valve with series k {:>4.1} MN/m (default coach)          {}",
            k / 1e6,
            vcr(&d, &m)
        );
    }
    // the passive damper behind a mounting stiffness
    for km in [5e6, 10e6] {
        let m = YawDamperModel {
            mounting_stiffness_n_per_m: Some(km),
            ..passive_damper()
        };
        println!(
            "passive damper behind mounting {:>4.1} MN/m (default coach)      {}",
            km / 1e6,
            vcr(&d, &m)
        );
    }
    // yaw-damping sweep of the default coach (ideal dampers)
    for c in [60e3, 104e3, 150e3, 210e3, 330e3] {
        let m = YawDamperModel::rigid(DamperRepresentation::Viscous { c });
        println!(
            "ideal damper c {:>3.0} kNs/m (default coach)                     {}",
            c / 1e3,
            vcr(&d, &m)
        );
    }
    for cy in [0.0, 16e3, 32e3, 64e3] {
        let mut p = d.clone();
        p.secondary.lateral_damping_ns_per_m = cy;
        row(
            &format!("secondary lateral damper {} kNs/m", cy / 1e3),
            &p,
            true,
        );
    }
}
