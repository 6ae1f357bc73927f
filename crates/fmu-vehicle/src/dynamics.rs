//! Right-hand side of the time-domain model: x' = f(x, track, damper forces).
//!
//! State x = (q (17), q' (17), beta_j' (4)): the dofs of [`crate::layout`], their rates, and the
//! spin perturbations of the four wheelsets (non-linear model; zero in the linear one).
//!
//! Wheel/rail forces of wheelset j (non-linear model), the seed's (5.19)-(5.27) written for one
//! wheelset with its own lateral displacement y_j and yaw psi_j, relative to the track
//! y_rel = y_j - y_track,j:
//! * creepages (5.8)-(5.11) with the absolute lateral velocity and yaw, rolling radii
//!   r_{L,R} = r0 + delta_r_{L,R}(y_rel) from the contact table (5.19), wheel speed
//!   Omega + beta_j' (5.26), Omega = V / r_c with r_c the table's centred rolling radius;
//! * Kalker forces (5.2)-(5.3) with kappa f11, kappa f22, saturated per wheel by
//!   Vermeulen-Johnson (5.21)-(5.25) (`wheel_rail::saturated_wheelset_creep`), static load P;
//! * normal-force lateral components (5.20) F_BL = +P tan g_L, F_BR = -P tan g_R (contact
//!   angles from the table; flange contact is the steep part of the table);
//! * wheelset yaw moment s (F_LR - F_LL), spin equation J_w beta'' = -(F_LL R_L + F_LR R_R).
//!
//! The linear model uses [`crate::linear::LinearContact`] instead. Suspension forces come from
//! the assembled sparse matrices, the yaw dampers enter as -E^T F.

use serde::{Deserialize, Serialize};
use wheel_rail::{saturated_wheelset_creep, GeometryTable, SegmentHint};

use crate::layout::{
    damper_rows, mass_diagonal, wheelset_y, wheelset_yaw, SparseSuspension, Suspension, N_DAMPERS,
    N_DOF, N_WHEELSETS,
};
use crate::linear::LinearContact;
use crate::params::{ModelKind, VehicleParams};

/// Number of states.
pub const N_STATES: usize = 2 * N_DOF + N_WHEELSETS;
/// Index of q' in the state.
pub const RATES: usize = N_DOF;
/// Index of the first spin perturbation rate.
pub const SPIN: usize = 2 * N_DOF;

/// Constants of the right-hand side, derived from the parameters once.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Consts {
    /// V [m/s].
    pub v: f64,
    /// 1 / V [s/m].
    pub v_inv: f64,
    /// 1 / M_ii.
    pub minv: [f64; N_DOF],
    /// Suspension.
    pub suspension: SparseSuspension,
    /// Damper elongation rows (dof index, coefficient); a restored state's indices are
    /// checked against the dofs.
    #[serde(deserialize_with = "damper_rows_within_the_dofs")]
    pub dampers: [[(usize, f64); 2]; N_DAMPERS],
    /// Linear contact (linear model).
    pub linear: LinearContactConsts,
    /// Non-linear contact.
    pub nonlinear: bool,
    /// kappa f11 \[N\].
    pub f11: f64,
    /// kappa f22 \[N\].
    pub f22: f64,
    /// s \[m\].
    pub s: f64,
    /// r0 \[m\].
    pub r0: f64,
    /// Nominal wheel speed Omega [rad/s].
    pub omega: f64,
    /// 1 / J_w.
    pub jw_inv: f64,
    /// P \[N\].
    pub load: f64,
    /// mu P \[N\].
    pub mu_p: f64,
}

/// The damper rows of a deserialised [`Consts`] (a saved FMU state): every index names a dof,
/// so that the force assembly cannot index past the force vector.
fn damper_rows_within_the_dofs<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> Result<[[(usize, f64); 2]; N_DAMPERS], D::Error> {
    let rows = <[[(usize, f64); 2]; N_DAMPERS]>::deserialize(d)?;
    if let Some(&(i, _)) = rows.iter().flatten().find(|(i, _)| *i >= N_DOF) {
        return Err(serde::de::Error::custom(format!(
            "damper row index {i} beyond the {N_DOF} degrees of freedom"
        )));
    }
    Ok(rows)
}

/// Serialisable copy of [`LinearContact`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LinearContactConsts {
    f11_n: f64,
    f22_n: f64,
    s_m: f64,
    lambda_over_r0: f64,
    gravity_stiffness_n_per_m: f64,
}

impl LinearContactConsts {
    fn get(&self) -> LinearContact {
        LinearContact {
            f11_n: self.f11_n,
            f22_n: self.f22_n,
            s_m: self.s_m,
            lambda_over_r0: self.lambda_over_r0,
            gravity_stiffness_n_per_m: self.gravity_stiffness_n_per_m,
        }
    }
}

impl Consts {
    /// Largest internal step the explicit RK4 needs for stability and accuracy \[s\]: 1.5 over
    /// the fastest creep-damping rate (lateral 2 kappa f22/(V m_w), yaw 2 kappa f11 s^2/(V I_w),
    /// spin 2 kappa f11 r0^2/(V J_w); the suspension's damping, Gershgorin bound of M^-1 C),
    /// and 1 over the highest frequency bound (Gershgorin bound
    /// of M^-1 K of the suspension, and the contact-angle stiffness P d tan(gamma)/dy of the
    /// table or k_g of the linear model, on one wheelset).
    pub fn stable_substep_s(&self, p: &VehicleParams, table: &GeometryTable) -> f64 {
        let w = &p.wheelset;
        // creep damping, and the suspension's own (a large damping of a light body decays
        // faster than an explicit step can follow)
        let mut rate = (2.0 * self.f22 / (self.v * w.mass_kg))
            .max(2.0 * self.f11 * self.s * self.s / (self.v * w.yaw_inertia_kgm2))
            .max(self.suspension.damping_gershgorin_bound(&self.minv));
        let k_contact = if self.nonlinear {
            rate = rate.max(2.0 * self.f11 * self.r0 * self.r0 * self.jw_inv / self.v);
            self.load * table.max_tan_gamma_slope()
        } else {
            self.linear.gravity_stiffness_n_per_m
        };
        let omega2 = self
            .suspension
            .gershgorin_bound(&self.minv)
            .max(k_contact / w.mass_kg);
        (1.5 / rate).min(1.0 / omega2.sqrt().max(1e-9))
    }

    /// From validated parameters and the contact table (its centred rolling radius sets Omega).
    pub fn new(p: &VehicleParams, table: &GeometryTable) -> Self {
        let lc = LinearContact::new(p);
        let r = &p.wheel_rail;
        let r0 = p.wheelset.wheel_radius_m;
        let nonlinear = p.model == ModelKind::NonLinear;
        let omega = if nonlinear {
            // No longitudinal creep in the centred position.
            let c0 = table.lookup(0.0);
            p.speed_mps / (r0 + 0.5 * (c0.delta_r_left_m + c0.delta_r_right_m))
        } else {
            p.speed_mps / r0
        };
        Self {
            v: p.speed_mps,
            v_inv: 1.0 / p.speed_mps,
            minv: mass_diagonal(p).map(|m| 1.0 / m),
            suspension: SparseSuspension::from_dense(&Suspension::new(p)),
            dampers: damper_rows(p),
            linear: LinearContactConsts {
                f11_n: lc.f11_n,
                f22_n: lc.f22_n,
                s_m: lc.s_m,
                lambda_over_r0: lc.lambda_over_r0,
                gravity_stiffness_n_per_m: lc.gravity_stiffness_n_per_m,
            },
            nonlinear,
            f11: r.creep_reduction * r.f11_n,
            f22: r.creep_reduction * r.f22_n,
            s: p.wheelset.half_contact_gauge_m,
            r0,
            omega,
            jw_inv: 1.0 / p.wheelset.spin_inertia_kgm2,
            load: r.wheel_load_n,
            mu_p: r.friction_coefficient * r.wheel_load_n,
        }
    }
}

/// Wheel/rail forces on one wheelset.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct WheelsetForces {
    /// Sum of the lateral forces of the rails on the wheelset (guiding force), positive right \[N\].
    pub lateral_n: f64,
    /// Yaw moment [N m].
    pub yaw_moment_nm: f64,
    /// Lateral force on the left wheel \[N\].
    pub left_n: f64,
    /// Lateral force on the right wheel \[N\].
    pub right_n: f64,
    /// beta'' [rad/s^2].
    pub spin_acc: f64,
}

/// Non-linear contact of one wheelset.
#[inline]
#[allow(clippy::too_many_arguments)]
fn nonlinear_wheelset(
    c: &Consts,
    table: &GeometryTable,
    hint: &mut SegmentHint,
    y_rel: f64,
    vy: f64,
    yaw: f64,
    yaw_rate: f64,
    spin_rate: f64,
) -> WheelsetForces {
    let (v, v_inv) = (c.v, c.v_inv);
    let g = table.lookup_with_hint(hint, y_rel);
    let rr = c.r0 + g.delta_r_right_m;
    let rl = c.r0 + g.delta_r_left_m;
    let w = c.omega + spin_rate;
    // (5.8)-(5.11)
    let eps_t = (vy + v * yaw) * v_inv;
    let eps_lr = (v - vy * yaw + c.s * yaw_rate - w * rr) * v_inv;
    let eps_ll = (v - vy * yaw - c.s * yaw_rate - w * rl) * v_inv;
    // (5.2)-(5.3), saturated (5.21)-(5.25)
    let creep = saturated_wheelset_creep(c.f11, c.f22, c.mu_p, eps_t, eps_ll, eps_lr);
    let (ftr, flr) = (creep.lateral_right_n, creep.longitudinal_right_n);
    let (ftl, fll) = (creep.lateral_left_n, creep.longitudinal_left_n);
    // (5.20)
    let fbl = c.load * g.tan_gamma_left;
    let fbr = -c.load * g.tan_gamma_right;
    let (left, right) = (ftl + fbl, ftr + fbr);
    WheelsetForces {
        lateral_n: left + right,
        yaw_moment_nm: c.s * (flr - fll),
        left_n: left,
        right_n: right,
        // (5.27)
        spin_acc: -(fll * rl + flr * rr) * c.jw_inv,
    }
}

/// One evaluation: the state derivative and the wheel/rail forces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Eval {
    /// x'.
    pub dx: [f64; N_STATES],
    /// Wheel/rail forces per wheelset.
    pub wheelsets: [WheelsetForces; N_WHEELSETS],
}

/// x' = f(x) for the track alignment `track_m` under each wheelset and the yaw-damper forces
/// (tension positive); `hints` speed up the table lookups (one per wheelset, results do not
/// depend on them).
#[inline]
pub fn rhs(
    c: &Consts,
    table: &GeometryTable,
    hints: &mut [SegmentHint; N_WHEELSETS],
    x: &[f64; N_STATES],
    track_m: &[f64; N_WHEELSETS],
    damper_force_n: &[f64; N_DAMPERS],
) -> Eval {
    let (q, rest) = x.split_at(N_DOF);
    let qd = &rest[..N_DOF];
    let mut f = [0.0; N_DOF];
    c.suspension.add_forces(q, qd, &mut f);
    for (row, &force) in c.dampers.iter().zip(damper_force_n) {
        for &(i, a) in row {
            f[i] -= a * force;
        }
    }
    let mut dx = [0.0; N_STATES];
    let mut forces = [WheelsetForces::default(); N_WHEELSETS];
    let lin = c.linear.get();
    for j in 0..N_WHEELSETS {
        let (iy, ip) = (wheelset_y(j), wheelset_yaw(j));
        let y_rel = q[iy] - track_m[j];
        let w = if c.nonlinear {
            nonlinear_wheelset(
                c,
                table,
                &mut hints[j],
                y_rel,
                qd[iy],
                q[ip],
                qd[ip],
                x[SPIN + j],
            )
        } else {
            let (lat, mz) = lin.forces(c.v, qd[iy], q[ip], qd[ip], y_rel);
            WheelsetForces {
                lateral_n: lat,
                yaw_moment_nm: mz,
                left_n: 0.5 * lat,
                right_n: 0.5 * lat,
                spin_acc: 0.0,
            }
        };
        f[iy] += w.lateral_n;
        f[ip] += w.yaw_moment_nm;
        dx[SPIN + j] = w.spin_acc;
        forces[j] = w;
    }
    for i in 0..N_DOF {
        dx[i] = qd[i];
        dx[RATES + i] = f[i] * c.minv[i];
    }
    Eval {
        dx,
        wheelsets: forces,
    }
}
