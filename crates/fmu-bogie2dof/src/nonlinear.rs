//! Right-hand sides of the time-domain models.
//!
//! Non-linear model (5.19)-(5.27), per wheelset i (1 = front at +p, 2 = rear at -p;
//! y_i = y -+ p sigma, same yaw sigma, positive nose-left):
//! * creepages (5.8)-(5.11) with the ABSOLUTE wheelset lateral velocity and yaw, and rolling
//!   radii r_{L,R} = r0 + delta_r_{L,R}(y_i - y_track,i) (5.19); wheel angular speed
//!   Omega + beta_i' (5.26) with Omega = V/r0;
//! * Kalker linear forces (5.2)-(5.3) (coefficients times the reduction factor kappa), saturated per wheel with Vermeulen-Johnson
//!   (5.21)-(5.25) using the static wheel load P;
//! * normal-force lateral components (5.20): F_BL = +P tan g_L, F_BR = -P tan g_R (the table
//!   holds positive tan g; signs so the net force restores, see [`wheel_rail::table`]);
//! * equations (5.27) with the damper moment -b F_L + b F_R (see [`crate::eigen`]).
//!
//! Linear model: the same structure with unsaturated forces, rolling radii r0 +- lambda
//! (y_i - y_track,i), no normal-force term except the optional gravitational stiffness, and
//! no spin dofs; it equals (5.16) exactly (checked against the state matrix in tests).

use wheel_rail::{saturated_wheelset_creep, GeometryTable, SegmentHint};

use crate::params::{ModelKind, Params};

/// State indices: y, sigma, y', sigma', beta1', beta2'.
pub const N_STATES: usize = 6;

/// Constants derived from the parameters once.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Consts {
    pub v: f64,
    pub m: f64,
    pub j: f64,
    pub jw: f64,
    pub p: f64,
    pub s: f64,
    pub b: f64,
    pub r0: f64,
    pub omega: f64,
    pub k_ssy: f64,
    pub k_ssx: f64,
    pub lambda: f64,
    pub kg: f64,
    pub f11: f64,
    pub f22: f64,
    pub load: f64,
    pub mu_p: f64,
    pub nonlinear: bool,
    /// 1/V, 1/m, 1/J, 1/J_w: the right-hand side multiplies instead of dividing.
    pub inv_v: f64,
    pub inv_m: f64,
    pub inv_j: f64,
    pub inv_jw: f64,
}

impl Consts {
    /// From validated parameters.
    pub fn new(p: &Params) -> Self {
        Self {
            v: p.speed_mps,
            m: p.bogie_mass_kg,
            j: p.bogie_yaw_inertia_kgm2,
            jw: p.wheelset_spin_inertia_kgm2,
            p: p.half_wheelbase_m,
            s: p.half_contact_gauge_m,
            b: p.damper_arm_m,
            r0: p.wheel_radius_m,
            omega: p.speed_mps / p.wheel_radius_m,
            k_ssy: p.k_ssy_n_per_m,
            k_ssx: p.k_ssx_n_per_m,
            lambda: p.conicity,
            kg: p.gravity_stiffness_n_per_m,
            f11: p.creep_reduction * p.f11_n,
            f22: p.creep_reduction * p.f22_n,
            load: p.wheel_load_n,
            mu_p: p.friction_coefficient * p.wheel_load_n,
            nonlinear: p.model == ModelKind::NonLinear,
            inv_v: 1.0 / p.speed_mps,
            inv_m: 1.0 / p.bogie_mass_kg,
            inv_j: 1.0 / p.bogie_yaw_inertia_kgm2,
            inv_jw: 1.0 / p.wheelset_spin_inertia_kgm2,
        }
    }
}

/// Result of one right-hand-side evaluation.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Eval {
    /// Time derivative of the state.
    pub dx: [f64; N_STATES],
    /// Sum of lateral wheel/rail forces on each wheelset (front, rear) \[N\], positive right.
    pub guiding: [f64; 2],
    /// Yaw moment of everything but the yaw dampers [N m]: the damper forces enter only
    /// `dx[3] = (yaw_moment_without_dampers_nm - b F_L + b F_R) / J`.
    pub yaw_moment_without_dampers_nm: f64,
}

impl Eval {
    /// Yaw acceleration for other damper forces at the same state and track (bit for bit what
    /// a new evaluation would give).
    #[inline]
    pub fn yaw_acc_with_dampers(&self, c: &Consts, f_left: f64, f_right: f64) -> f64 {
        (self.yaw_moment_without_dampers_nm + (-c.b * f_left + c.b * f_right)) * c.inv_j
    }
}

/// x' = f(x) with track alignment `yt` = (front, rear) and damper forces (tension positive).
#[inline]
pub fn rhs(
    c: &Consts,
    table: &GeometryTable,
    x: &[f64; N_STATES],
    yt: [f64; 2],
    f_left: f64,
    f_right: f64,
) -> Eval {
    rhs_with_hints(
        c,
        table,
        &mut [SegmentHint::default(); 2],
        x,
        yt,
        f_left,
        f_right,
    )
}

/// As [`rhs`], with one contact-table segment hint per wheelset (front, rear) that the caller
/// keeps from one evaluation to the next (the lookup result is the same for any hint).
#[inline]
pub fn rhs_with_hints(
    c: &Consts,
    table: &GeometryTable,
    hints: &mut [SegmentHint; 2],
    x: &[f64; N_STATES],
    yt: [f64; 2],
    f_left: f64,
    f_right: f64,
) -> Eval {
    let (y, sig, yd, sigd) = (x[0], x[1], x[2], x[3]);
    let v = c.v;
    let mut lat_sum = 0.0;
    let mut yaw = 0.0;
    let mut out = Eval::default();
    for i in 0..2 {
        let sgn = if i == 0 { -1.0 } else { 1.0 };
        let yi = y + sgn * c.p * sig;
        let vi = yd + sgn * c.p * sigd;
        let yrel = yi - yt[i];
        let eps_t = (vi + v * sig) * c.inv_v;
        let lat;
        let long_moment;
        if c.nonlinear {
            let g = table.lookup_with_hint(&mut hints[i], yrel);
            let rr = c.r0 + g.delta_r_right_m;
            let rl = c.r0 + g.delta_r_left_m;
            let w = c.omega + x[4 + i];
            let eps_lr = (v - vi * sig + c.s * sigd - w * rr) * c.inv_v;
            let eps_ll = (v - vi * sig - c.s * sigd - w * rl) * c.inv_v;
            let creep = saturated_wheelset_creep(c.f11, c.f22, c.mu_p, eps_t, eps_ll, eps_lr);
            let (ftr, flr) = (creep.lateral_right_n, creep.longitudinal_right_n);
            let (ftl, fll) = (creep.lateral_left_n, creep.longitudinal_left_n);
            let fbl = c.load * g.tan_gamma_left;
            let fbr = -c.load * g.tan_gamma_right;
            lat = ftr + ftl + fbl + fbr;
            long_moment = c.s * (flr - fll);
            // (5.27) J_w beta'' + F_LL R_L + F_LR R_R = 0
            out.dx[4 + i] = -(fll * rl + flr * rr) * c.inv_jw;
        } else {
            let ft = -c.f22 * eps_t;
            let flr = -c.f11 * (c.s * sigd * c.inv_v - c.lambda * yrel / c.r0);
            lat = 2.0 * ft - c.kg * yrel;
            long_moment = 2.0 * c.s * flr; // F_LL = -F_LR
            out.dx[4 + i] = 0.0;
        }
        out.guiding[i] = lat;
        lat_sum += lat;
        yaw += long_moment + sgn * c.p * lat;
    }
    out.dx[0] = yd;
    out.dx[1] = sigd;
    out.dx[2] = (lat_sum - 2.0 * c.k_ssy * y) * c.inv_m;
    out.yaw_moment_without_dampers_nm = yaw - 2.0 * c.k_ssx * c.b * c.b * sig;
    out.dx[3] = out.yaw_acc_with_dampers(c, f_left, f_right);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eigen::{state_matrix, DamperRepresentation, LinearDamper};

    /// Finite-difference Jacobian of the linear RHS equals the state matrix (5.30).
    #[test]
    fn linear_rhs_equals_state_matrix() {
        let p = Params {
            model: ModelKind::Linear,
            gravity_stiffness_n_per_m: 3e5,
            ..Params::default()
        };
        let c = Consts::new(&p);
        let table = GeometryTable::synthetic(0.15, 7e-3, 5e-4, 2.7).unwrap();
        let (kd, cd) = (2e6, 1.2e5);
        let a = state_matrix(
            &p,
            p.speed_mps,
            &DamperRepresentation::Linear(LinearDamper::KelvinVoigt { k: kd, c: cd }),
            0.0,
        )
        .unwrap();
        // z = (y', sigma', y, sigma) ; x = (y, sigma, y', sigma', ..)
        let map = [2usize, 3, 0, 1];
        let f = |x: &[f64; N_STATES]| {
            let b = p.damper_arm_m;
            let fl = kd * b * x[1] + cd * b * x[3];
            rhs(&c, &table, x, [0.0, 0.0], fl, -fl).dx
        };
        for col in 0..4 {
            let mut x = [0.0; N_STATES];
            let h = 1e-6;
            x[map[col]] = h;
            let d = f(&x);
            for row in 0..4 {
                let num = d[map[row]] / h;
                let ex = a[(row, col)];
                assert!(
                    (num - ex).abs() <= 1e-6 * ex.abs().max(1.0),
                    "A[{row},{col}] {num} vs {ex}"
                );
            }
        }
    }

    /// At small amplitude on a cone the non-linear forces equal the linear ones.
    #[test]
    fn nonlinear_reduces_to_linear_at_small_amplitude() {
        // synthetic cone: no contact-angle change, so no gravitational stiffness
        let mut p = Params {
            gravity_stiffness_n_per_m: 0.0,
            ..Params::default()
        };
        let table = GeometryTable::synthetic(p.conicity, 7e-3, 5e-4, 2.7).unwrap();
        p.model = ModelKind::NonLinear;
        let cn = Consts::new(&p);
        p.model = ModelKind::Linear;
        let cl = Consts::new(&p);
        let x = [1e-5, 2e-6, 1e-4, -3e-5, 0.0, 0.0];
        let a = rhs(&cn, &table, &x, [0.0, 0.0], 10.0, -10.0);
        let b = rhs(&cl, &table, &x, [0.0, 0.0], 10.0, -10.0);
        for k in 2..4 {
            assert!(
                (a.dx[k] - b.dx[k]).abs() < 2e-3 * b.dx[k].abs().max(1e-6),
                "{k}: {} {}",
                a.dx[k],
                b.dx[k]
            );
        }
    }

    #[test]
    fn flange_force_restores() {
        let p = Params::default();
        let table = GeometryTable::synthetic(0.15, 7e-3, 5e-4, 2.7).unwrap();
        let c = Consts::new(&p);
        // wheelsets 8 mm right, no motion: strong force to the left
        let x = [8e-3, 0.0, 0.0, 0.0, 0.0, 0.0];
        let e = rhs(&c, &table, &x, [0.0, 0.0], 0.0, 0.0);
        assert!(
            e.guiding[0] < -1e5 && e.guiding[1] < -1e5,
            "{:?}",
            e.guiding
        );
        // the same relative to a track shifted by 8 mm: no flange force
        let e2 = rhs(&c, &table, &x, [8e-3, 8e-3], 0.0, 0.0);
        assert!(e2.guiding[0].abs() < 1.0);
    }
}
