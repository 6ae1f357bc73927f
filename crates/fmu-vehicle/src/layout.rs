//! Bodies, degrees of freedom and the linear suspension, assembled from force elements.
//!
//! Degrees of freedom (17): car body lateral y, yaw psi, roll phi; each bogie frame y, psi,
//! phi; each wheelset y, psi (its roll follows the rails and is not a dof). Every body's
//! coordinates are taken at its centre of gravity. Small-angle kinematics of a point with
//! absolute position (X, Y, Z) (Z = height above the rail) on a body at (x_b, 0, h_b):
//! * lateral u_y = y - psi (X - x_b) + phi (Z - h_b)   (psi nose-left, phi top to the right),
//! * longitudinal u_x = psi Y,
//! * vertical u_z = -phi Y.
//!
//! A spring/damper between two bodies acts on the relative displacement of its two ends along
//! one direction; its stiffness matrix is k a a^T with a the row that maps the dofs onto that
//! relative displacement. The primary suspension (per axle box, three directions), the air
//! springs (per side, three directions), the secondary lateral dampers, the air springs'
//! torsional yaw stiffness and the anti-roll bars are assembled that way, so every coupling of
//! roll with lateral motion through the heights of the elements follows from the geometry.
//!
//! Gravitational roll terms: a body resting on preloaded vertical springs below its centre of
//! gravity, or loaded from above, gets the destabilising roll stiffness -W dh (W the vertical
//! preload, dh the height between the centre of gravity and the loaded plane): car body
//! -W_c (h_c - h_s); frame -(W_c/2)(h_s - h_f) - (W_c/2 + W_f)(h_f - h_p). Summed over a
//! rigidly locked car body and frame this gives the familiar -W (H - h_p) of the whole mass.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use crate::params::VehicleParams;

/// Number of mechanical degrees of freedom.
pub const N_DOF: usize = 17;
/// Number of bogies.
pub const N_BOGIES: usize = 2;
/// Number of wheelsets.
pub const N_WHEELSETS: usize = 4;
/// Number of yaw dampers.
pub const N_DAMPERS: usize = 4;

/// Car body lateral displacement.
pub const CARBODY_Y: usize = 0;
/// Car body yaw (nose-left).
pub const CARBODY_YAW: usize = 1;
/// Car body roll (top to the right).
pub const CARBODY_ROLL: usize = 2;

/// Lateral dof of frame `i` (0 = front, 1 = rear).
pub const fn frame_y(i: usize) -> usize {
    3 + 3 * i
}
/// Yaw dof of frame `i`.
pub const fn frame_yaw(i: usize) -> usize {
    4 + 3 * i
}
/// Roll dof of frame `i`.
pub const fn frame_roll(i: usize) -> usize {
    5 + 3 * i
}
/// Lateral dof of wheelset `j` (0 = leading ... 3 = last).
pub const fn wheelset_y(j: usize) -> usize {
    9 + 2 * j
}
/// Yaw dof of wheelset `j`.
pub const fn wheelset_yaw(j: usize) -> usize {
    10 + 2 * j
}

/// Bogie of wheelset `j`.
pub const fn bogie_of_wheelset(j: usize) -> usize {
    j / 2
}

/// Yaw damper `d`: 0 front left, 1 front right, 2 rear left, 3 rear right.
pub const fn damper_bogie(d: usize) -> usize {
    d / 2
}
/// Side of damper `d`: -1 left, +1 right (its lateral coordinate is side * b).
pub fn damper_side(d: usize) -> f64 {
    if d.is_multiple_of(2) {
        -1.0
    } else {
        1.0
    }
}

/// Longitudinal positions (from the car-body centre, forward positive) and distances.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Positions {
    /// Bogie centres \[m\]: +a, -a.
    pub bogie_x_m: [f64; N_BOGIES],
    /// Wheelsets \[m\]: a + p, a - p, -a + p, -a - p.
    pub wheelset_x_m: [f64; N_WHEELSETS],
    /// Distance of each wheelset behind the leading one \[m\]: 0, 2p, 2a, 2a + 2p.
    pub wheelset_delay_m: [f64; N_WHEELSETS],
}

impl Positions {
    /// From the geometry.
    pub fn new(p: &VehicleParams) -> Self {
        let a = p.geometry.half_bogie_spacing_m;
        let h = p.geometry.half_wheelbase_m;
        let wx = [a + h, a - h, -a + h, -a - h];
        Self {
            bogie_x_m: [a, -a],
            wheelset_x_m: wx,
            wheelset_delay_m: wx.map(|x| wx[0] - x),
        }
    }
}

/// One body's dofs and the position of its centre of gravity.
#[derive(Debug, Clone, Copy)]
struct Body {
    y: usize,
    yaw: usize,
    /// `None` for a wheelset (roll follows the rails).
    roll: Option<usize>,
    x_m: f64,
    h_m: f64,
}

/// Direction of a translational element.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Dir {
    X,
    Y,
    Z,
}

/// Sparse row a: relative coordinate = sum coeff * q[dof].
#[derive(Debug, Clone, Default)]
struct Row(Vec<(usize, f64)>);

impl Row {
    fn add(&mut self, dof: usize, coeff: f64) {
        if coeff != 0.0 {
            self.0.push((dof, coeff));
        }
    }

    /// Adds (sign = +1) or subtracts the displacement of point (X, Y, Z) of `body` along `dir`.
    fn point(&mut self, body: &Body, point: [f64; 3], dir: Dir, sign: f64) {
        let [x, y, z] = point;
        match dir {
            Dir::X => self.add(body.yaw, sign * y),
            Dir::Y => {
                self.add(body.y, sign);
                self.add(body.yaw, -sign * (x - body.x_m));
                if let Some(r) = body.roll {
                    self.add(r, sign * (z - body.h_m));
                }
            }
            Dir::Z => {
                if let Some(r) = body.roll {
                    self.add(r, -sign * y);
                }
            }
        }
    }
}

/// Linear suspension matrices: K_s, C_s (including the gravitational roll terms in K_s).
#[derive(Debug, Clone)]
pub struct Suspension {
    /// Stiffness matrix [N/m, N, N m/rad].
    pub k: DMatrix<f64>,
    /// Damping matrix.
    pub c: DMatrix<f64>,
}

fn bodies(p: &VehicleParams, pos: &Positions) -> (Body, [Body; N_BOGIES], [Body; N_WHEELSETS]) {
    let carbody = Body {
        y: CARBODY_Y,
        yaw: CARBODY_YAW,
        roll: Some(CARBODY_ROLL),
        x_m: 0.0,
        h_m: p.carbody.cg_height_m,
    };
    let frames = [0, 1].map(|i| Body {
        y: frame_y(i),
        yaw: frame_yaw(i),
        roll: Some(frame_roll(i)),
        x_m: pos.bogie_x_m[i],
        h_m: p.frame.cg_height_m,
    });
    let wheelsets = [0, 1, 2, 3].map(|j| Body {
        y: wheelset_y(j),
        yaw: wheelset_yaw(j),
        roll: None,
        x_m: pos.wheelset_x_m[j],
        h_m: p.wheelset.wheel_radius_m,
    });
    (carbody, frames, wheelsets)
}

impl Suspension {
    /// Assembles the primary and secondary suspension of `p`.
    pub fn new(p: &VehicleParams) -> Self {
        let pos = Positions::new(p);
        let (carbody, frames, wheelsets) = bodies(p, &pos);
        let mut k = DMatrix::<f64>::zeros(N_DOF, N_DOF);
        let mut c = DMatrix::<f64>::zeros(N_DOF, N_DOF);
        let mut element = |row: &Row, stiffness: f64, damping: f64| {
            for &(i, ai) in &row.0 {
                for &(j, aj) in &row.0 {
                    k[(i, j)] += stiffness * ai * aj;
                    c[(i, j)] += damping * ai * aj;
                }
            }
        };
        let translational = |lower: &Body, upper: &Body, point: [f64; 3], dir: Dir| {
            let mut r = Row::default();
            r.point(upper, point, dir, 1.0);
            r.point(lower, point, dir, -1.0);
            r
        };
        let g = &p.geometry;
        let pr = &p.primary;
        // Primary: per axle box, at axle height, between wheelset and frame.
        for (j, ws) in wheelsets.iter().enumerate() {
            let frame = &frames[bogie_of_wheelset(j)];
            for side in [-1.0, 1.0] {
                let point = [
                    ws.x_m,
                    side * g.primary_half_spacing_m,
                    p.wheelset.wheel_radius_m,
                ];
                for (dir, kk, cc) in [
                    (Dir::X, pr.kx_n_per_m, pr.cx_ns_per_m),
                    (Dir::Y, pr.ky_n_per_m, pr.cy_ns_per_m),
                    (Dir::Z, pr.kz_n_per_m, pr.cz_ns_per_m),
                ] {
                    element(&translational(ws, frame, point, dir), kk, cc);
                }
            }
        }
        // Secondary: per side, between frame and car body.
        let s = &p.secondary;
        for frame in &frames {
            for side in [-1.0, 1.0] {
                let spring = [
                    frame.x_m,
                    side * g.secondary_half_spacing_m,
                    g.secondary_height_m,
                ];
                for (dir, kk, cc) in [
                    (Dir::X, s.kx_n_per_m, 0.0),
                    (Dir::Y, s.ky_n_per_m, 0.0),
                    (Dir::Z, s.kz_n_per_m, s.cz_ns_per_m),
                ] {
                    element(&translational(frame, &carbody, spring, dir), kk, cc);
                }
                let damper = [
                    frame.x_m,
                    side * g.secondary_half_spacing_m,
                    g.lateral_damper_height_m,
                ];
                element(
                    &translational(frame, &carbody, damper, Dir::Y),
                    0.0,
                    s.lateral_damping_ns_per_m,
                );
            }
            // Torsional yaw stiffness of the two air springs and the anti-roll bar.
            let mut yaw = Row::default();
            yaw.add(carbody.yaw, 1.0);
            yaw.add(frame.yaw, -1.0);
            element(&yaw, 2.0 * s.yaw_stiffness_nm_per_rad, 0.0);
            let mut roll = Row::default();
            roll.add(CARBODY_ROLL, 1.0);
            if let Some(r) = frame.roll {
                roll.add(r, -1.0);
            }
            element(&roll, s.anti_roll_bar_nm_per_rad, 0.0);
        }
        // Gravitational roll terms (module docs).
        let grav = p.gravity_mps2;
        let w_c = p.carbody.mass_kg * grav;
        let w_f = p.frame.mass_kg * grav;
        let (h_c, h_f) = (p.carbody.cg_height_m, p.frame.cg_height_m);
        let (h_s, h_p) = (g.secondary_height_m, p.wheelset.wheel_radius_m);
        k[(CARBODY_ROLL, CARBODY_ROLL)] -= w_c * (h_c - h_s);
        for i in 0..N_BOGIES {
            k[(frame_roll(i), frame_roll(i))] -=
                0.5 * w_c * (h_s - h_f) + (0.5 * w_c + w_f) * (h_f - h_p);
        }
        Self { k, c }
    }
}

/// Diagonal of the mass matrix.
pub fn mass_diagonal(p: &VehicleParams) -> [f64; N_DOF] {
    let mut m = [0.0; N_DOF];
    m[CARBODY_Y] = p.carbody.mass_kg;
    m[CARBODY_YAW] = p.carbody.yaw_inertia_kgm2;
    m[CARBODY_ROLL] = p.carbody.roll_inertia_kgm2;
    for i in 0..N_BOGIES {
        m[frame_y(i)] = p.frame.mass_kg;
        m[frame_yaw(i)] = p.frame.yaw_inertia_kgm2;
        m[frame_roll(i)] = p.frame.roll_inertia_kgm2;
    }
    for j in 0..N_WHEELSETS {
        m[wheelset_y(j)] = p.wheelset.mass_kg;
        m[wheelset_yaw(j)] = p.wheelset.yaw_inertia_kgm2;
    }
    m
}

/// Rows of the yaw-damper elongations e = E q \[m\]: e_left = b (psi_frame - psi_carbody),
/// e_right = -b (psi_frame - psi_carbody) (car-body end ahead of the frame end, extension
/// positive). A tension force F does the virtual work -F de, so its generalised force is
/// -E^T F.
pub fn damper_rows(p: &VehicleParams) -> [[(usize, f64); 2]; N_DAMPERS] {
    let b = p.geometry.damper_arm_m;
    [0, 1, 2, 3].map(|d| {
        let s = -damper_side(d); // +1 left, -1 right
        [(frame_yaw(damper_bogie(d)), s * b), (CARBODY_YAW, -s * b)]
    })
}

/// The suspension matrices for the time domain, dense and by column: the forces are
/// accumulated column by column (f -= K[:, j] q_j + C[:, j] q'_j), which vectorises over the rows
/// without a floating-point reduction (a sparse loop over the 83 non-zeros is four times slower:
/// every entry waits for the previous update of its row).
/// A deserialised one (a saved FMU state, say) must hold N_DOF x N_DOF of each.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "SuspensionColumns")]
pub struct SparseSuspension {
    /// K by column, column j at [j * N_DOF ..].
    k: Vec<f64>,
    /// C by column.
    c: Vec<f64>,
}

/// max_i sum_j |A_ij| / M_i of a matrix stored by column.
fn row_sum_bound(a: &[f64], minv: &[f64; N_DOF]) -> f64 {
    let mut rows = [0.0; N_DOF];
    for col in a.chunks_exact(N_DOF) {
        for (r, x) in rows.iter_mut().zip(col) {
            *r += x.abs();
        }
    }
    rows.iter()
        .zip(minv)
        .map(|(r, m)| r * m)
        .fold(0.0, f64::max)
}

/// The serialised form of [`SparseSuspension`] before its check.
#[derive(Deserialize)]
struct SuspensionColumns {
    k: Vec<f64>,
    c: Vec<f64>,
}

impl TryFrom<SuspensionColumns> for SparseSuspension {
    type Error = String;
    fn try_from(s: SuspensionColumns) -> Result<Self, String> {
        if s.k.len() != N_DOF * N_DOF || s.c.len() != N_DOF * N_DOF {
            return Err(format!(
                "suspension matrices of {} and {} entries, {} expected",
                s.k.len(),
                s.c.len(),
                N_DOF * N_DOF
            ));
        }
        Ok(SparseSuspension { k: s.k, c: s.c })
    }
}

impl SparseSuspension {
    /// From the dense matrices.
    pub fn from_dense(s: &Suspension) -> Self {
        let mut k = vec![0.0; N_DOF * N_DOF];
        let mut c = vec![0.0; N_DOF * N_DOF];
        for j in 0..N_DOF {
            for i in 0..N_DOF {
                k[j * N_DOF + i] = s.k[(i, j)];
                c[j * N_DOF + i] = s.c[(i, j)];
            }
        }
        Self { k, c }
    }

    /// Adds -K q - C q' to `f`.
    #[inline]
    pub fn add_forces(&self, q: &[f64], qd: &[f64], f: &mut [f64; N_DOF]) {
        for (j, (kc, cc)) in self
            .k
            .chunks_exact(N_DOF)
            .zip(self.c.chunks_exact(N_DOF))
            .enumerate()
        {
            let (qj, qdj) = (q[j], qd[j]);
            for i in 0..N_DOF {
                f[i] -= kc[i] * qj + cc[i] * qdj;
            }
        }
    }

    /// Gershgorin bound of the largest eigenvalue of M^-1 K: max_i sum_j |K_ij| / M_i.
    pub fn gershgorin_bound(&self, minv: &[f64; N_DOF]) -> f64 {
        row_sum_bound(&self.k, minv)
    }

    /// The same bound for M^-1 C [1/s]: the fastest decay rate the suspension's damping gives.
    pub fn damping_gershgorin_bound(&self, minv: &[f64; N_DOF]) -> f64 {
        row_sum_bound(&self.c, minv)
    }

    /// Number of non-zero entries of K or C.
    pub fn non_zeros(&self) -> usize {
        self.k
            .iter()
            .zip(&self.c)
            .filter(|(k, c)| **k != 0.0 || **c != 0.0)
            .count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deserialised_suspension_matrices_must_be_n_dof_square() {
        let s = SparseSuspension::from_dense(&Suspension::new(&VehicleParams::default()));
        let good = serde_json::to_value(&s).unwrap();
        assert_eq!(
            serde_json::from_value::<SparseSuspension>(good.clone()).unwrap(),
            s
        );
        let mut bad = good;
        bad["k"]
            .as_array_mut()
            .unwrap()
            .push(serde_json::json!(0.0));
        let e = serde_json::from_value::<SparseSuspension>(bad).unwrap_err();
        assert!(e.to_string().contains("expected"), "{e}");
    }

    #[test]
    fn suspension_is_symmetric_and_rigid_motion_is_free() {
        let p = VehicleParams {
            gravity_mps2: 0.0,
            ..VehicleParams::default()
        };
        let s = Suspension::new(&p);
        for i in 0..N_DOF {
            for j in 0..N_DOF {
                assert!((s.k[(i, j)] - s.k[(j, i)]).abs() <= 1e-6 * s.k[(i, i)].abs().max(1.0));
            }
        }
        // Whole vehicle displaced laterally by 1: no suspension force.
        let mut q = [0.0; N_DOF];
        for i in [CARBODY_Y, frame_y(0), frame_y(1)] {
            q[i] = 1.0;
        }
        for j in 0..N_WHEELSETS {
            q[wheelset_y(j)] = 1.0;
        }
        let f = &s.k * nalgebra::DVector::from_column_slice(&q);
        assert!(f.amax() < 1e-6, "{f}");
        // Whole vehicle yawed rigidly: lateral displacement -x psi at each body.
        let pos = Positions::new(&p);
        let mut q = [0.0; N_DOF];
        q[CARBODY_YAW] = 1e-3;
        for i in 0..N_BOGIES {
            q[frame_yaw(i)] = 1e-3;
            q[frame_y(i)] = -pos.bogie_x_m[i] * 1e-3;
        }
        for j in 0..N_WHEELSETS {
            q[wheelset_yaw(j)] = 1e-3;
            q[wheelset_y(j)] = -pos.wheelset_x_m[j] * 1e-3;
        }
        let f = &s.k * nalgebra::DVector::from_column_slice(&q);
        assert!(f.amax() < 1e-6, "{f}");
    }

    #[test]
    fn primary_yaw_stiffness_of_a_wheelset() {
        let p = VehicleParams::default();
        let s = Suspension::new(&p);
        let d = p.geometry.primary_half_spacing_m;
        let k = s.k[(wheelset_yaw(0), wheelset_yaw(0))];
        assert!((k - 2.0 * p.primary.kx_n_per_m * d * d).abs() < 1e-3);
        assert!((s.k[(wheelset_y(0), wheelset_y(0))] - 2.0 * p.primary.ky_n_per_m).abs() < 1e-6);
    }

    #[test]
    fn gravity_roll_terms_of_a_locked_vehicle() {
        // Car body and frames locked together and rolled about the axle plane: the gravity
        // terms must sum to -W_suspended (H - h_p).
        let mut p = VehicleParams::default();
        let with = Suspension::new(&p);
        p.gravity_mps2 = 0.0;
        let without = Suspension::new(&p);
        let g = 9.81;
        let hp = p.wheelset.wheel_radius_m;
        let mut q = [0.0; N_DOF];
        q[CARBODY_ROLL] = 1.0;
        q[CARBODY_Y] = p.carbody.cg_height_m - hp;
        for i in 0..N_BOGIES {
            q[frame_roll(i)] = 1.0;
            q[frame_y(i)] = p.frame.cg_height_m - hp;
        }
        let v = nalgebra::DVector::from_column_slice(&q);
        let e = |k: &DMatrix<f64>| (v.transpose() * k * &v)[(0, 0)];
        let grav = e(&with.k) - e(&without.k);
        let w = g * (p.carbody.mass_kg + 2.0 * p.frame.mass_kg);
        let h = (p.carbody.mass_kg * p.carbody.cg_height_m
            + 2.0 * p.frame.mass_kg * p.frame.cg_height_m)
            / (p.carbody.mass_kg + 2.0 * p.frame.mass_kg);
        assert!((grav + w * (h - hp)).abs() < 1e-6 * w, "{grav}");
    }

    #[test]
    fn damper_elongation_convention() {
        let p = VehicleParams::default();
        let rows = damper_rows(&p);
        // Front frame yawed nose-left: left damper extends by b psi.
        let b = p.geometry.damper_arm_m;
        assert_eq!(rows[0][0], (frame_yaw(0), b));
        assert_eq!(rows[1][0], (frame_yaw(0), -b));
        assert_eq!(rows[2][1], (CARBODY_YAW, -b));
    }
}
