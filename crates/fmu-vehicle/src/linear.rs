//! Linear model: M q'' + C(V) q' + K(V) q = Q_dampers, without the yaw dampers (they enter
//! through [`crate::eigen::DamperRepresentation`] or as input forces).
//!
//! Wheel/rail forces of wheelset j in the linear model (per wheelset, the seed's (5.2)-(5.15)
//! with the wheelset's own lateral displacement y_j and yaw psi_j, relative to the track
//! y_rel = y_j - y_track):
//! * lateral F_y = -2 kappa f22 (y_j'/V + psi_j) - k_g y_rel,
//! * yaw M_z = 2 s F_LR with F_LR = -kappa f11 (s psi_j'/V - lambda y_rel / r0).
//!
//! k_g is the gravitational (contact-angle) stiffness, as in the 2-dof bogie's linear model.

use nalgebra::DMatrix;

use crate::layout::{mass_diagonal, wheelset_y, wheelset_yaw, Suspension, N_DOF, N_WHEELSETS};
use crate::params::VehicleParams;

/// Linear wheel/rail constants of one wheelset (already multiplied by the reduction factor).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearContact {
    /// kappa f11 \[N\].
    pub f11_n: f64,
    /// kappa f22 \[N\].
    pub f22_n: f64,
    /// s \[m\].
    pub s_m: f64,
    /// lambda / r0 [1/m].
    pub lambda_over_r0: f64,
    /// k_g [N/m].
    pub gravity_stiffness_n_per_m: f64,
}

impl LinearContact {
    /// From the parameters.
    pub fn new(p: &VehicleParams) -> Self {
        let r = &p.wheel_rail;
        Self {
            f11_n: r.creep_reduction * r.f11_n,
            f22_n: r.creep_reduction * r.f22_n,
            s_m: p.wheelset.half_contact_gauge_m,
            lambda_over_r0: r.conicity / p.wheelset.wheel_radius_m,
            gravity_stiffness_n_per_m: r.gravity_stiffness_n_per_m,
        }
    }

    /// (lateral force, yaw moment) on a wheelset.
    #[inline]
    pub fn forces(&self, v: f64, yd: f64, yaw: f64, yawd: f64, y_rel: f64) -> (f64, f64) {
        let lat = -2.0 * self.f22_n * (yd / v + yaw) - self.gravity_stiffness_n_per_m * y_rel;
        let f_lr = -self.f11_n * (self.s_m * yawd / v - self.lambda_over_r0 * y_rel);
        (lat, 2.0 * self.s_m * f_lr)
    }
}

/// Mass, damping and stiffness matrices of the linear model at speed `speed_mps` (dampers
/// excluded).
pub fn matrices(p: &VehicleParams, speed_mps: f64) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    let s = Suspension::new(p);
    let m = DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(&mass_diagonal(p)));
    let (mut c, mut k) = (s.c, s.k);
    let lc = LinearContact::new(p);
    let v = speed_mps;
    for j in 0..N_WHEELSETS {
        let (y, w) = (wheelset_y(j), wheelset_yaw(j));
        c[(y, y)] += 2.0 * lc.f22_n / v;
        k[(y, w)] += 2.0 * lc.f22_n;
        k[(y, y)] += lc.gravity_stiffness_n_per_m;
        c[(w, w)] += 2.0 * lc.f11_n * lc.s_m * lc.s_m / v;
        k[(w, y)] -= 2.0 * lc.f11_n * lc.s_m * lc.lambda_over_r0;
    }
    debug_assert_eq!(m.nrows(), N_DOF);
    (m, c, k)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matrices_match_the_force_law() {
        let p = VehicleParams::default();
        let v = 70.0;
        let (_, c, k) = matrices(&p, v);
        let s = Suspension::new(&p);
        let lc = LinearContact::new(&p);
        // unit lateral displacement of wheelset 2 relative to the track
        let (lat, mz) = lc.forces(v, 0.0, 0.0, 0.0, 1.0);
        let y = wheelset_y(2);
        assert!((k[(y, y)] - s.k[(y, y)] + lat).abs() < 1e-6);
        assert!((k[(wheelset_yaw(2), y)] - s.k[(wheelset_yaw(2), y)] + mz).abs() < 1e-6);
        let (lat, _) = lc.forces(v, 1.0, 0.0, 0.0, 0.0);
        assert!((c[(y, y)] - s.c[(y, y)] + lat).abs() < 1e-9);
    }
}
