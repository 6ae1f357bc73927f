//! Calibration of the free parameters against R5 (linear critical speed 270 km/h with the
//! passive reference damper) and R6 (hunting frequency about 3-4 Hz, Im ~ 21 rad/s).
//!
//! Interpretation (REFERENCE.md, "Checked against the seed"): in this model the critical
//! speed is set by the effective longitudinal (yaw) stiffness, not by damping. The yaw
//! stiffness here is k_ssx (air spring + mountings, per side, at arm b) PLUS the elastic part
//! of the yaw damper, which comes with the damper representation (k_eq of the passive
//! damper at 30 % opening, calibrated by the damper helper). Until those numbers exist, the
//! calibration uses a clearly named PLACEHOLDER Kelvin-Voigt damper (k_eq = 2.0 MN/m,
//! c_eq = 120 kNs/m per damper). Re-run [`calibrate_k_ssx`] with the real representation
//! (e.g. `DamperRepresentation::FrequencyDependent(table)`) once it is known.
//!
//! Fixed choices: conicity 0.15 (a new S1002/UIC60 pairing; the real A/A table's
//! equivalent conicity can be taken from `ContactTable::linearise`), f11/f22 from Hertz and
//! Kalker at 70 kN per wheel, friction 0.35 (dry rail 0.3-0.4).
//! Result with the placeholder: k_ssx = 1.645 MN/m per side (total effective yaw stiffness
//! 3.6 MN/m per side, in the 3-5 MN/m window of REFERENCE.md), V_cr = 270 km/h,
//! hunting frequency 3.5 Hz (Im = 22.1 rad/s).

use crate::eigen::{critical_speed, CriticalSpeed, DamperRepresentation, EigenError};
use crate::params::Params;

/// PLACEHOLDER equivalent stiffness of one passive yaw damper at the hunting frequency
/// [N/m] (to be replaced by the damper helper's k_eq at 30 % opening).
pub const PLACEHOLDER_DAMPER_K_N_PER_M: f64 = 2.0e6;
/// PLACEHOLDER equivalent damping of one passive yaw damper [N s/m].
pub const PLACEHOLDER_DAMPER_C_NS_PER_M: f64 = 1.2e5;
/// k_ssx calibrated with the placeholder damper for 270 km/h [N/m per side].
pub const CALIBRATED_K_SSX_N_PER_M: f64 = 1.645e6;
/// Equivalent conicity of the linear model [-].
pub const CALIBRATED_CONICITY: f64 = 0.15;
/// Wheel/rail friction coefficient [-].
pub const CALIBRATED_FRICTION: f64 = 0.35;
/// R5 target [km/h].
pub const TARGET_CRITICAL_SPEED_KMH: f64 = 270.0;

/// The placeholder passive damper as a Kelvin-Voigt representation.
pub fn placeholder_damper() -> DamperRepresentation {
    DamperRepresentation::KelvinVoigt {
        k: PLACEHOLDER_DAMPER_K_N_PER_M,
        c: PLACEHOLDER_DAMPER_C_NS_PER_M,
    }
}

/// Finds k_ssx in [0, 20 MN/m] (bisection; V_cr grows with k_ssx) such that the linear
/// critical speed with `damper` equals `target_kmh`. Returns (k_ssx, critical speed).
pub fn calibrate_k_ssx(
    base: &Params,
    damper: &DamperRepresentation,
    target_kmh: f64,
) -> Result<(f64, CriticalSpeed), EigenError> {
    let vcr = |k: f64| -> Result<f64, EigenError> {
        let mut p = base.clone();
        p.k_ssx_n_per_m = k;
        match critical_speed(&p, damper, 5.0, 199.0) {
            Ok(c) => Ok(c.speed_kmh),
            // stable over the whole range: above any target
            Err(EigenError::NoCrossing { .. }) => Ok(f64::INFINITY),
            Err(e) => Err(e),
        }
    };
    let (mut lo, mut hi) = (0.0, 20e6);
    if vcr(lo)? > target_kmh || vcr(hi)? < target_kmh {
        return Err(EigenError::NoCrossing {
            lo_mps: target_kmh / 3.6,
            hi_mps: target_kmh / 3.6,
        });
    }
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if vcr(mid)? < target_kmh {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let k = 0.5 * (lo + hi);
    let mut p = base.clone();
    p.k_ssx_n_per_m = k;
    Ok((k, critical_speed(&p, damper, 5.0, 199.0)?))
}
