//! Calibration of the coach against the seed's full-vehicle results R15 (linear critical speed
//! 280-290 km/h with the passive reference damper) and R16 (non-linear, from an initial
//! perturbation: stable at 240 km/h, small limit cycle without continuous flange contact at
//! 280 km/h, 6-7 mm flange-contact limit cycle at 300 km/h).
//!
//! Constants carried over from the 2-dof bogie's calibration (fmu-bogie2dof `calibration`,
//! numbers copied, no dependency): the worn-profile surrogate table, its linearisation at
//! 1 mm, the creep reduction factor, the friction coefficient and the Maxwell fit of the
//! passive reference damper (semi-active damper at 30 % opening, 1 mm stroke, 3-4 Hz).

use crate::eigen::{DamperRepresentation, YawDamperModel};

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

/// The passive reference damper as the eigen-analysis sees it (rigid mounting).
pub fn passive_damper() -> YawDamperModel {
    YawDamperModel::rigid(DamperRepresentation::Maxwell {
        k: PASSIVE_MAXWELL_K_N_PER_M,
        c: PASSIVE_MAXWELL_C_NS_PER_M,
    })
}
