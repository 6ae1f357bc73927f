//! Calibration of the coach against the seed's full-vehicle results R15 (linear critical speed
//! 280-290 km/h with the passive reference damper) and R16 (non-linear, from an initial
//! perturbation: stable at 240 km/h, small limit cycle without continuous flange contact at
//! 280 km/h, 6-7 mm flange-contact limit cycle at 300 km/h), and the integrator's sub-step.
//!
//! # Carried over from the 2-dof bogie (numbers copied, no dependency)
//! The worn-profile surrogate table and its linearisation at 1 mm (conicity 0.25, gravitational
//! stiffness 2.022 MN/m per wheelset at 70 kN, i.e. 28.9 N/m per newton of wheel load), the
//! creep reduction factor 0.6, the friction coefficient 0.35, and the Maxwell fit of the
//! passive reference damper (semi-active damper at 30 % opening, 1 mm stroke, 3-4 Hz:
//! k = 16.9 MN/m in series with c = 104 kNs/m).
//!
//! # The one calibrated parameter: primary longitudinal and lateral stiffness
//! With every value as published (Manchester Benchmark suspension, seed geometry, the bogie's
//! wheel/rail contact and damper) the coach's linear critical speed is 334 km/h at 4.6 Hz
//! (both bogies hunting), above R15. The seed itself says where its coach differs from the
//! benchmark: its 2-dof reduction (5.3, assumption 3) rests on "completely rigid primary
//! suspensions, since the longitudinal and transversal stiffness values of the multibody model
//! are very large", while the benchmark's primary (31.4 MN/m longitudinal, 3.9 MN/m lateral
//! per axle box) belongs to a conventional passenger bogie. The primary longitudinal and
//! lateral stiffnesses are therefore scaled together by one factor, found by
//! [`calibrate_primary_stiffness_factor`] for 285 km/h (the middle of R15):
//! [`PRIMARY_STIFFNESS_FACTOR`] = 3.08, i.e. 96.7 MN/m longitudinal and 12.0 MN/m lateral per
//! axle box (high-speed bogies: 10-150 MN/m and 5-20 MN/m). Sensitivities measured on the way
//! (linear critical speed, km/h): factor 1 / 1.5 / 2 / 3 / 5 / 10 / 100: 334 / 314 / 301 / 287 /
//! 273 / 262 / 252; rigid primary: 250; conicity 0.30 / 0.35 at factor 1: 305 / 284; without the
//! secondary lateral dampers: 275; yaw-damper c 60 / 104 / 200 kNs/m: 282 / 334 / 528. In the
//! coach, unlike the 2-dof bogie, the yaw dampers' damping matters more than their stiffness.
//! Vertical primary stiffness, secondary suspension, masses and heights stay as published.
//!
//! # Results (tests: `tests/calibration.rs` in this crate, `tests/tests/vehicle_*.rs`)
//! * R15: 285.0 km/h at 4.0 Hz, both bogies hunting (kinetic-energy shares front/rear
//!   bogie about 0.5/0.4, car body 0.1).
//! * R16 with the passive reference damper itself (the hydraulic model of fmu-damper at 30 %,
//!   the seed's passive damper, coupled co-simulation style at 1 ms), 3 mm initial lateral
//!   displacement of both bogies: decays at 240 and 260 km/h; 280 km/h: a 3.9 mm limit cycle on
//!   the tread, Y/Q 0.2 (no flange contact); 300 km/h: 6.6 mm flange-contact limit cycle
//!   (Y/Q 0.8). With the linear Maxwell stand-in instead the damping does not fall with the
//!   stroke, and the limit cycles stay smaller (280: 0.6 mm, 300: 3.5 mm, 320: 4.6 mm): R16's
//!   flange contact at 300 km/h needs the real damper's falling equivalent damping at large
//!   strokes (1 mm: 96 kNs/m, 3 mm: 61 kNs/m at 4 Hz).
//!
//! # Integrator sub-step (convergence study, tests `convergence_*`)
//! RK4 with one sub-step per 1 ms communication step: the limit-cycle amplitude at 320 km/h
//! with hard flange contact (Y/Q 2.1) differs from a 0.1 ms sub-step by 0.001 mm, the
//! time-domain critical speed of the linear model by less than 0.01 km/h. With a 10 ms
//! communication step, sub-steps of 1 / 2 / 5 / 10 ms give 6.573 / 6.544 / 6.650 mm / unstable
//! against 6.567 mm at 0.1 ms, and Y/Q 0.78 / 0.73 / 1.16 against 0.77, so [`SOLVER_SUBSTEP_S`]
//! = 1 ms. Below that bound the model lowers the sub-step where creep damping (which grows as
//! 1/V) or the stiffest contact or suspension frequency would need it.

use crate::eigen::{
    critical_speed, CriticalSpeed, DamperRepresentation, EigenError, YawDamperModel,
};
use crate::params::VehicleParams;

/// Equivalent conicity of the worn-profile surrogate at 1 mm amplitude [-].
pub const TABLE_CONICITY_1MM: f64 = 0.25;
/// Gravitational stiffness per wheelset of the surrogate at 1 mm divided by the wheel load
/// [1/m] (the bogie: 2.022 MN/m at 70 kN).
pub const TABLE_GRAVITY_STIFFNESS_PER_LOAD_1MM: f64 = 2.022e6 / 70e3;
/// Kalker reduction factor kappa [-].
pub const CREEP_REDUCTION: f64 = 0.6;
/// Wheel/rail friction coefficient [-].
pub const FRICTION_COEFFICIENT: f64 = 0.35;
/// Maxwell series stiffness of the passive reference damper [N/m].
pub const PASSIVE_MAXWELL_K_N_PER_M: f64 = 16.9e6;
/// Maxwell damping of the passive reference damper [N s/m].
pub const PASSIVE_MAXWELL_C_NS_PER_M: f64 = 104e3;
/// Manchester Benchmark primary longitudinal stiffness per axle box [N/m].
pub const MB_PRIMARY_KX_N_PER_M: f64 = 31.391e6;
/// Manchester Benchmark primary lateral stiffness per axle box [N/m].
pub const MB_PRIMARY_KY_N_PER_M: f64 = 3.884e6;
/// Factor on the benchmark's primary longitudinal and lateral stiffness, calibrated for R15.
pub const PRIMARY_STIFFNESS_FACTOR: f64 = 3.15;
/// R15 target [km/h] (middle of 280-290).
pub const TARGET_CRITICAL_SPEED_KMH: f64 = 285.0;
/// Largest RK4 sub-step of the time-domain model [s].
pub const SOLVER_SUBSTEP_S: f64 = 1e-3;

/// The passive reference damper as the eigen-analysis sees it (rigid mounting).
pub fn passive_damper() -> YawDamperModel {
    YawDamperModel::rigid(DamperRepresentation::Maxwell {
        k: PASSIVE_MAXWELL_K_N_PER_M,
        c: PASSIVE_MAXWELL_C_NS_PER_M,
    })
}

/// Finds the factor on the benchmark's primary longitudinal and lateral stiffness (bisection
/// over [1, 100]; the critical speed falls as the factor grows) for which the linear critical
/// speed with `damper` is `target_kmh`. Returns (factor, critical speed).
pub fn calibrate_primary_stiffness_factor(
    base: &VehicleParams,
    damper: &YawDamperModel,
    target_kmh: f64,
) -> Result<(f64, CriticalSpeed), EigenError> {
    let with = |f: f64| {
        let mut p = base.clone();
        p.primary.kx_n_per_m = f * MB_PRIMARY_KX_N_PER_M;
        p.primary.ky_n_per_m = f * MB_PRIMARY_KY_N_PER_M;
        p
    };
    let vcr = |f: f64| critical_speed(&with(f), damper, 10.0, 160.0).map(|c| c.speed_kmh);
    let (mut lo, mut hi) = (1.0_f64, 100.0_f64);
    if vcr(lo)? < target_kmh || vcr(hi)? > target_kmh {
        return Err(EigenError::NoCrossing {
            lo_mps: target_kmh / 3.6,
            hi_mps: target_kmh / 3.6,
        });
    }
    // bisection on log(factor)
    for _ in 0..40 {
        let mid = (lo * hi).sqrt();
        if vcr(mid)? > target_kmh {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let f = (lo * hi).sqrt();
    Ok((f, critical_speed(&with(f), damper, 10.0, 160.0)?))
}
