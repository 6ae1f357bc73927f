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
//! [`PRIMARY_STIFFNESS_FACTOR`] = 3.15, i.e. 98.9 MN/m longitudinal and 12.2 MN/m lateral per
//! axle box (high-speed bogies: 10-150 MN/m and 5-20 MN/m). Sensitivities measured on the way
//! (linear critical speed, km/h, other values as published): factor 1 / 1.5 / 2 / 3 / 5 / 10 /
//! 100: 334 / 314 / 301 / 287 / 273 / 262 / 252; rigid primary in all directions: 250;
//! conicity 0.30 / 0.35 at factor 1: 305 / 284; without the secondary lateral dampers: 275;
//! yaw-damper c 60 / 104 / 200 kNs/m: 282 / 334 / 528; creep reduction 0.5 / 0.6 / 1.0: 341 /
//! 334 / 348. In the coach, unlike the 2-dof bogie, the yaw dampers' damping matters more than
//! their stiffness (a mounting stiffness in series makes the Maxwell element stiffer at 4-5 Hz
//! and RAISES the critical speed here: 5 MN/m: 366 km/h). Vertical primary stiffness, secondary
//! suspension, masses and heights stay as published.
//!
//! # Sensitivity to yaw damping: why MPPT gains more here than in the seed (not calibrated)
//! The study's MPPT gain (+105 to +140 km/h against the seed's about +70) follows from how
//! steeply this coach's critical speed rises with yaw damping. Scan
//! (`examples/yaw_damping_scan.rs`; for each candidate value the common primary factor is
//! re-found for 285 km/h with the passive damper where [1, 100] allows it; then the linear
//! critical speed, km/h, with a closed valve as a Maxwell element of 16.9 MN/m in series with
//! 330 kNs/m and with ideal 210 kNs/m dampers; target shape: closed 350-385, ideal below 380):
//! * calibrated coach: passive 285.0, closed 695.8, ideal 335.9; ideal dampers of 60 / 104 /
//!   150 / 210 / 330 kNs/m: 244.0 / 267.7 / 295.3 / 335.9 / 434.1. The closed valve's series
//!   spring counts as much as its damping: 330 kNs/m behind 2 / 5 / 10 / 16.9 MN/m gives
//!   292.3 / 447.2 / > 900 / 695.8, and the passive damper behind a 5 / 10 MN/m mounting
//!   309.6 / 306.4. Four yaw dampers of 16.9 MN/m at 1.35 m put 2 k b^2 = 61.6 MN m/rad of yaw
//!   stiffness between each frame and the car body (the air springs: about 0.3 MN m/rad): the
//!   elastic yaw coupling to the car body is a strong stabiliser of bogie hunting.
//! * split of the primary factor (longitudinal x lateral, no re-calibration): every split with
//!   passive 280-290 km/h keeps the closed valve at 662-711 and the ideal damper at 318-350
//!   (kx x2 ky x10: 287.3 / 710.8 / 349.8; x3.15 x3.15: 285.0 / 695.8 / 335.9; x5 x2: 285.1 /
//!   690.3 / 328.2; x10 x2: 279.6 / 662.3 / 318.2).
//! * equivalent conicity 0.20 / 0.30 (re-calibrated where possible): 0.20 cannot reach 285
//!   (325.5 at factor 100), 0.30 at factor 1.54: closed > 900. 0.35: 238.1 already at 3.15.
//! * yaw-damper arm 1.0 / 1.1 / 1.2 m (factor 1.01 / 1.41 / 1.89): closed 525.2 / 555.3 /
//!   605.0, ideal 316.1 / 320.4 / 326.3.
//! * air-spring longitudinal stiffness 0.3 / 0.5 / 1 MN/m (factor 3.61 / 4.49 / 10.35): closed
//!   690.3 / 683.7 / 671.6.
//! * creep reduction 0.8 / 1.0 (factor 3.03 / 3.77): closed 582.7 / 524.4, ideal 312.2 / 299.9;
//!   0.45 cannot reach 285. Secondary lateral damper 16 / 64 kNs/m: closed 599.1 / > 900.
//! * combinations: arm 1.0 m with creep reduction 1.0 (factor 2.50): closed 401.8, ideal
//!   292.8; arm 0.9 m with creep reduction 1.0 (factor 2.25): closed 377.5, ideal 291.0.
//!
//! No single candidate brings the closed valve below 520 km/h. What lowers the sensitivity is
//! what lowers the yaw dampers' torque against the creep forces' (a shorter arm, full Kalker
//! coefficients); only the combination of both reaches the target shape, and neither value has
//! a source: the seed gives no yaw-damper arm (1.35 m is the published arm of the bogie data
//! both models use), and the creep reduction 0.6 is the shared contact's value on which the
//! bogie's R1-R7 rest. Choosing them for the target would be tuning, so the model stays as it
//! is. It would also break R16: with those values (factor 2.25) the hydraulic passive damper's
//! run at 280 km/h ends in a 6.71 mm flange-contact limit cycle (Y/Q 2.18, on the flange 6 %
//! of the time) instead of a small one on the tread (240: decays; 300: 6.81 mm, Y/Q 2.36).
//! The proxy also overstates the study: its closed-valve gain (+411 km/h) is far above the
//! study's MPPT gain, so the hydraulic valve at hunting amplitudes is not a 330 kNs/m Maxwell
//! element (which part of the damper model limits it is not measured here).
//!
//! # Results (tests: `tests/calibration.rs` in this crate, `tests/tests/vehicle_*.rs`)
//! * R15: 285.0 km/h at 4.03 Hz (Im 25.3 rad/s), both bogies hunting (kinetic-energy shares:
//!   front bogie 0.50, rear bogie 0.40, car body 0.10). Seed R6 (2-dof bogie): about 3-4 Hz.
//! * R16 with the passive reference damper itself (the hydraulic model of fmu-damper at 30 %,
//!   the seed's passive damper, coupled co-simulation style at 1 ms), 3 mm initial lateral
//!   displacement of both bogies: decays at 240 km/h (and 260); 280 km/h: a 4.3 mm limit cycle
//!   on the tread, Y/Q 0.23, never on the flange; 300 km/h: a 6.57 mm limit cycle up the flange
//!   root (tan gamma 0.8; the flank starts at 6.65 mm), Y/Q 0.80; 320 km/h: 6.60 mm, Y/Q 0.88.
//!   With the linear Maxwell stand-in instead the damping does not fall with the stroke and the
//!   limit cycles stay smaller (280: 0.6 mm, 300: 3.55 mm, 320: 4.69 mm, all on the tread):
//!   R16's flange contact at 300 km/h needs the real damper's falling equivalent damping at
//!   large strokes (1 mm: 96 kNs/m, 3 mm: 61 kNs/m at 4 Hz).
//! * Reduction (tests/tests/vehicle_vs_bogie.rs): car body 1000 times heavier, rigid primary,
//!   the bogie's data: 270.22 km/h at 4.411 Hz against the 2-dof bogie's 270.03 km/h at
//!   4.409 Hz.
//!
//! # Integrator sub-step (convergence study, `tests/convergence.rs`)
//! RK4 with one sub-step per 1 ms communication step: the limit cycle at 320 km/h with the
//! yaw dampers at 30 % of the passive damping (hard flange contact, Y/Q 2.05) is 6.6944 mm
//! against 6.6937 mm with a 0.1 ms sub-step, Y/Q 2.053 against 2.039, and the time-domain
//! critical speed of the linear model 287.27 km/h for both. With a 10 ms communication step
//! (where the sub-step constant itself limits the internal step): 1 ms sub-step 6.5912 mm /
//! Y/Q 0.841 / 302.26 km/h against 6.5836 mm / 0.828 / 302.31 km/h at 0.1 ms; a 2 ms sub-step
//! gives Y/Q 0.879 (6 % off, the test fails), 5 ms 1.16, 10 ms diverges. Hence
//! [`SOLVER_SUBSTEP_S`] = 1 ms. Below that bound the model lowers the sub-step where the
//! creep damping (growing as 1/V: at 10 km/h the non-linear model takes 0.19 ms) or the
//! stiffest contact or suspension frequency needs it (`dynamics::Consts::stable_substep_s`).

use crate::eigen::{
    critical_speed, CriticalSpeed, DamperRepresentation, EigenError, YawDamperModel,
};
use crate::params::VehicleParams;
// The calibrated values the default parameters take live with the parameters (so that module
// imports no other of the crate); they are named here too, where they are explained.
pub use crate::params::{
    CREEP_REDUCTION, FRICTION_COEFFICIENT, MB_PRIMARY_KX_N_PER_M, MB_PRIMARY_KY_N_PER_M,
    PRIMARY_STIFFNESS_FACTOR, SOLVER_SUBSTEP_S, TABLE_CONICITY_1MM,
    TABLE_GRAVITY_STIFFNESS_PER_LOAD_1MM,
};

/// Maxwell series stiffness of the passive reference damper [N/m].
pub const PASSIVE_MAXWELL_K_N_PER_M: f64 = 16.9e6;
/// Maxwell damping of the passive reference damper [N s/m].
pub const PASSIVE_MAXWELL_C_NS_PER_M: f64 = 104e3;
/// R15 target [km/h] (middle of 280-290).
pub const TARGET_CRITICAL_SPEED_KMH: f64 = 285.0;

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
