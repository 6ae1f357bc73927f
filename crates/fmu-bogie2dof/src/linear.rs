//! Linear 2-dof bogie (5.1)-(5.18): mass, damping and stiffness matrices without the yaw
//! dampers (they are added by [`crate::eigen::DamperRepresentation`] or enter the time
//! domain as input forces).
//!
//! Coordinates: x = (y, sigma); y lateral, positive to the right; sigma yaw, positive
//! nose-left. Front wheelset 1 at +p: y1 = y - p sigma; rear wheelset 2: y2 = y + p sigma.
//! Creepages (5.8)-(5.15) per wheelset i: lateral (y_i' + V sigma)/V, longitudinal right
//! s sigma'/V - lambda y_i/R0, left the opposite; forces F = -f eps (5.2)-(5.3).
//! The sum over both wheelsets equals the seed's (5.14)-(5.15) written with y (y1 + y2 = 2y).

use nalgebra::Matrix2;

use crate::params::Params;

/// (M, C, K) of (5.18) at speed V, dampers excluded: M x'' + C x' + K x = Q.
/// Includes the optional gravitational stiffness per wheelset k_g (0 in the seed):
/// lateral -2 k_g y, yaw -2 k_g p^2 sigma.
pub fn matrices(p: &Params, speed_mps: f64) -> (Matrix2<f64>, Matrix2<f64>, Matrix2<f64>) {
    let v = speed_mps;
    let (s, pp, b) = (p.half_contact_gauge_m, p.half_wheelbase_m, p.damper_arm_m);
    // Kalker coefficients with the reduction factor kappa (see Params::creep_reduction)
    let (f11, f22) = (p.creep_reduction * p.f11_n, p.creep_reduction * p.f22_n);
    let kg = p.gravity_stiffness_n_per_m;
    let m = Matrix2::new(p.bogie_mass_kg, 0.0, 0.0, p.bogie_yaw_inertia_kgm2);
    let c = Matrix2::new(
        4.0 * f22 / v,
        0.0,
        0.0,
        4.0 * f11 * s * s / v + 4.0 * f22 * pp * pp / v,
    );
    let k = Matrix2::new(
        2.0 * p.k_ssy_n_per_m + 2.0 * kg,
        4.0 * f22,
        -4.0 * f11 * s * p.conicity / p.wheel_radius_m,
        2.0 * p.k_ssx_n_per_m * b * b + 2.0 * kg * pp * pp,
    );
    (m, c, k)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_seed_5_18_structure() {
        let p = Params::default();
        let v = 70.0;
        let (m, c, k) = matrices(&p, v);
        assert_eq!(m[(0, 1)], 0.0);
        assert_eq!(c[(0, 1)], 0.0);
        let f22 = p.creep_reduction * p.f22_n;
        assert!((c[(0, 0)] - 4.0 * f22 / v).abs() < 1e-6);
        assert!((k[(0, 1)] - 4.0 * f22).abs() < 1e-6);
        // kinematic coupling: yaw moment pushes a right-displaced bogie nose-left
        assert!(k[(1, 0)] < 0.0);
    }
}
