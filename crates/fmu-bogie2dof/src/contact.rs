//! Wheel/rail contact: contact-geometry table, creep saturation, Kalker coefficients, Hertz.
//!
//! Table convention (CSV, header first, SI):
//! `y_m,delta_r_left_m,delta_r_right_m,tan_gamma_left,tan_gamma_right`
//! * `y_m`: wheelset lateral displacement RELATIVE TO THE TRACK, positive to the right;
//! * `delta_r_right_m` grows for y > 0 (r_R = r0 + delta_r_right), `delta_r_left_m` falls;
//! * `tan_gamma_*` are POSITIVE magnitudes (the cone angle on the tread, large on the flange).
//!
//! Lateral force of the normal load (5.20), with these signs: the rail pushes each wheel
//! towards the track centre, so F_BL = +P tan(gamma_L), F_BR = -P tan(gamma_R) (y to the
//! right); the net P (tan gamma_L - tan gamma_R) restores. Beyond the table range the last
//! segment is extrapolated linearly (a flange keeps getting steeper rather than letting go).

use serde::{Deserialize, Serialize};

/// Errors reading a contact table.
#[derive(Debug, thiserror::Error)]
pub enum ContactError {
    /// Could not read the file.
    #[error("cannot read contact table `{path}`: {source}")]
    Io {
        /// File path.
        path: String,
        /// OS error.
        source: std::io::Error,
    },
    /// Malformed content.
    #[error("contact table line {line}: {reason}")]
    Parse {
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        reason: String,
    },
}

/// Expected CSV header.
pub const TABLE_HEADER: &str = "y_m,delta_r_left_m,delta_r_right_m,tan_gamma_left,tan_gamma_right";

/// Contact geometry of one wheelset as functions of its lateral displacement.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactTable {
    y: Vec<f64>,
    dr_l: Vec<f64>,
    dr_r: Vec<f64>,
    tg_l: Vec<f64>,
    tg_r: Vec<f64>,
}

/// Interpolated contact geometry at one lateral displacement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPoint {
    /// r_L - r0 [m].
    pub delta_r_left_m: f64,
    /// r_R - r0 [m].
    pub delta_r_right_m: f64,
    /// tan(gamma_L) >= 0.
    pub tan_gamma_left: f64,
    /// tan(gamma_R) >= 0.
    pub tan_gamma_right: f64,
}

impl ContactTable {
    /// Builds a table from columns; checks lengths, finiteness and strictly increasing y.
    pub fn from_columns(
        y: Vec<f64>,
        dr_l: Vec<f64>,
        dr_r: Vec<f64>,
        tg_l: Vec<f64>,
        tg_r: Vec<f64>,
    ) -> Result<Self, ContactError> {
        let n = y.len();
        if n < 2 || dr_l.len() != n || dr_r.len() != n || tg_l.len() != n || tg_r.len() != n {
            return Err(ContactError::Parse {
                line: 0,
                reason: "need at least 2 rows and equal column lengths".into(),
            });
        }
        for i in 0..n {
            let row = [y[i], dr_l[i], dr_r[i], tg_l[i], tg_r[i]];
            if row.iter().any(|v| !v.is_finite()) {
                return Err(ContactError::Parse {
                    line: i + 2,
                    reason: "non-finite value".into(),
                });
            }
            if i > 0 && y[i] <= y[i - 1] {
                return Err(ContactError::Parse {
                    line: i + 2,
                    reason: "y_m must be strictly increasing".into(),
                });
            }
        }
        Ok(Self {
            y,
            dr_l,
            dr_r,
            tg_l,
            tg_r,
        })
    }

    /// Parses CSV text in the format of the module docs.
    pub fn parse_csv(text: &str) -> Result<Self, ContactError> {
        let mut cols: [Vec<f64>; 5] = Default::default();
        let mut header_seen = false;
        for (i, raw) in text.lines().enumerate() {
            let line = raw.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            if !header_seen {
                let h: String = line.chars().filter(|c| !c.is_whitespace()).collect();
                if h != TABLE_HEADER {
                    return Err(ContactError::Parse {
                        line: i + 1,
                        reason: format!("header must be `{TABLE_HEADER}`, got `{line}`"),
                    });
                }
                header_seen = true;
                continue;
            }
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            if fields.len() != 5 {
                return Err(ContactError::Parse {
                    line: i + 1,
                    reason: format!("expected 5 fields, got {}", fields.len()),
                });
            }
            for (c, f) in fields.iter().enumerate() {
                let v: f64 = f.parse().map_err(|_| ContactError::Parse {
                    line: i + 1,
                    reason: format!("not a number: `{f}`"),
                })?;
                cols[c].push(v);
            }
        }
        let [y, a, b, c, d] = cols;
        Self::from_columns(y, a, b, c, d)
    }

    /// Reads a CSV file.
    pub fn load(path: &str) -> Result<Self, ContactError> {
        let text = std::fs::read_to_string(path).map_err(|source| ContactError::Io {
            path: path.to_string(),
            source,
        })?;
        Self::parse_csv(&text)
    }

    /// Writes the table as CSV (same format as [`Self::parse_csv`]).
    pub fn to_csv(&self) -> String {
        let mut s = String::from(TABLE_HEADER);
        s.push('\n');
        for i in 0..self.y.len() {
            s.push_str(&format!(
                "{:.6e},{:.6e},{:.6e},{:.6e},{:.6e}\n",
                self.y[i], self.dr_l[i], self.dr_r[i], self.tg_l[i], self.tg_r[i]
            ));
        }
        s
    }

    /// Synthetic, symmetric profile for tests: a cone of conicity `conicity` (contact angle
    /// tan gamma = conicity on the tread) and a flange that starts at `flange_clearance_m`,
    /// where the radius difference and the contact angle rise over `ramp_m` to
    /// tan gamma = `flange_tan` (about 70 deg) and delta r grows with slope `flange_tan`.
    pub fn synthetic(
        conicity: f64,
        flange_clearance_m: f64,
        ramp_m: f64,
        flange_tan: f64,
    ) -> Result<Self, ContactError> {
        let step = 1e-4;
        let y_max = flange_clearance_m + ramp_m + 3e-3;
        let n = (2.0 * y_max / step).round() as i64;
        let (mut y, mut dl, mut dr, mut tl, mut tr) = (vec![], vec![], vec![], vec![], vec![]);
        // Flange side: tan gamma ramps smoothly (cosine) from the cone value to flange_tan;
        // delta r is the integral of that slope, so r and gamma stay consistent.
        let slope = |u: f64| -> f64 {
            // u = distance beyond flange clearance
            if u <= 0.0 {
                conicity
            } else if u >= ramp_m {
                flange_tan
            } else {
                let w = 0.5 - 0.5 * (std::f64::consts::PI * u / ramp_m).cos();
                conicity + (flange_tan - conicity) * w
            }
        };
        let dr_flange = |u: f64| -> f64 {
            // integral of (slope - conicity) over [0, u], trapezoid with fine steps
            if u <= 0.0 {
                return 0.0;
            }
            let k = 200;
            let du = u / k as f64;
            let mut acc = 0.0;
            for j in 0..k {
                let a = slope(j as f64 * du) - conicity;
                let b = slope((j + 1) as f64 * du) - conicity;
                acc += 0.5 * (a + b) * du;
            }
            acc
        };
        for i in 0..=n {
            let yi = -y_max + i as f64 * step;
            let ur = yi - flange_clearance_m; // right flange engages for y > 0
            let ul = -yi - flange_clearance_m;
            y.push(yi);
            dr.push(conicity * yi + dr_flange(ur));
            dl.push(-conicity * yi + dr_flange(ul));
            tr.push(slope(ur));
            tl.push(slope(ul));
        }
        Self::from_columns(y, dl, dr, tl, tr)
    }

    /// Copy whose tread is replaced by a cone: for |y| <= `y_flange_m` the rolling-radius
    /// difference is delta_r(0) +- `conicity` y; beyond, the table's own rise (flange) is
    /// appended continuously: delta_r_R(y) = delta_r(0) + conicity y_f + (dr_R(y) - dr_R(y_f))
    /// (left side mirrored the same way). Contact angles are kept. Used for the worn-profile
    /// surrogate (see [`crate::calibration`]).
    pub fn with_tread_cone(&self, conicity: f64, y_flange_m: f64) -> Self {
        let c0 = self.lookup(0.0);
        let yf = y_flange_m.abs();
        let (at_pos, at_neg) = (self.lookup(yf), self.lookup(-yf));
        let mut dr_l = Vec::with_capacity(self.y.len());
        let mut dr_r = Vec::with_capacity(self.y.len());
        for (i, &y) in self.y.iter().enumerate() {
            let r = if y <= yf {
                c0.delta_r_right_m + conicity * y
            } else {
                c0.delta_r_right_m + conicity * yf + (self.dr_r[i] - at_pos.delta_r_right_m)
            };
            let l = if y >= -yf {
                c0.delta_r_left_m - conicity * y
            } else {
                c0.delta_r_left_m + conicity * yf + (self.dr_l[i] - at_neg.delta_r_left_m)
            };
            dr_r.push(r);
            dr_l.push(l);
        }
        Self {
            y: self.y.clone(),
            dr_l,
            dr_r,
            tg_l: self.tg_l.clone(),
            tg_r: self.tg_r.clone(),
        }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.y.len()
    }

    /// True if the table has no rows (never for a constructed table).
    pub fn is_empty(&self) -> bool {
        self.y.is_empty()
    }

    /// Range of y covered by the table [m].
    pub fn y_range(&self) -> (f64, f64) {
        (self.y[0], self.y[self.y.len() - 1])
    }

    /// Linear interpolation (linear extrapolation of the end segments).
    #[inline]
    pub fn lookup(&self, y: f64) -> ContactPoint {
        let n = self.y.len();
        // index of the segment [i, i+1]
        let i = match self.y.partition_point(|&v| v <= y) {
            0 => 0,
            k if k >= n => n - 2,
            k => k - 1,
        };
        let y0 = self.y[i];
        let t = (y - y0) / (self.y[i + 1] - y0);
        let lerp = |c: &[f64]| c[i] + t * (c[i + 1] - c[i]);
        ContactPoint {
            delta_r_left_m: lerp(&self.dr_l),
            delta_r_right_m: lerp(&self.dr_r),
            tan_gamma_left: lerp(&self.tg_l),
            tan_gamma_right: lerp(&self.tg_r),
        }
    }

    /// Largest |d tan(gamma)/dy| in the table [1/m]: bounds the flange contact stiffness.
    pub fn max_tan_gamma_slope(&self) -> f64 {
        let mut m: f64 = 0.0;
        for i in 0..self.y.len() - 1 {
            let dy = self.y[i + 1] - self.y[i];
            m = m.max(((self.tg_l[i + 1] - self.tg_l[i]) / dy).abs());
            m = m.max(((self.tg_r[i + 1] - self.tg_r[i]) / dy).abs());
        }
        m
    }

    /// Equivalent linear parameters for a harmonic wheelset motion of amplitude `amp_m`
    /// (first-harmonic / describing-function fit):
    /// conicity = fundamental of (delta r_R - delta r_L)/2 divided by amp, and gravitational
    /// stiffness per wheelset = -P * fundamental of (tan g_L - tan g_R) / amp.
    /// Returns (conicity, gravity_stiffness_per_wheelset / P) so the caller multiplies by P.
    pub fn linearise(&self, amp_m: f64) -> (f64, f64) {
        let n = 256;
        let (mut a_r, mut a_g) = (0.0, 0.0);
        for k in 0..n {
            let th = 2.0 * std::f64::consts::PI * (k as f64 + 0.5) / n as f64;
            let y = amp_m * th.sin();
            let c = self.lookup(y);
            a_r += 0.5 * (c.delta_r_right_m - c.delta_r_left_m) * th.sin();
            a_g += (c.tan_gamma_left - c.tan_gamma_right) * th.sin();
        }
        let scale = 2.0 / n as f64 / amp_m;
        (a_r * scale, -a_g * scale)
    }
}

/// Vermeulen-Johnson saturation (5.21)-(5.25) as a scale factor F'/F_res applied to both
/// creep force components. With u = F_res/(mu P): F' = mu P (1 - (1 - u/3)^3)
/// = mu P (u - u^2/3 + u^3/27) for u <= 3, else mu P; the ratio F'/F_res is computed in
/// closed form so that F_res -> 0 gives 1 (no 0/0).
#[inline]
pub fn saturation_factor(f_res: f64, mu_p: f64) -> f64 {
    let u = f_res / mu_p;
    if u <= 3.0 {
        1.0 - u / 3.0 + u * u / 27.0
    } else {
        1.0 / u
    }
}

/// Kalker longitudinal coefficient C11 for Poisson 0.25 as a function of g = b/a
/// (a: semi-axis in rolling direction). The seed's (5.6)-(5.7) swap the labels: the fit the
/// seed calls "C22" reproduces Kalker's C11 (4.25 vs 4.12 at a = b), so it is used here.
pub fn kalker_c11(b_over_a: f64) -> f64 {
    3.2893 + 0.975 / b_over_a - 0.012 / (b_over_a * b_over_a)
}

/// Kalker lateral coefficient C22 for Poisson 0.25 (the seed's "C11" fit, see [`kalker_c11`]).
pub fn kalker_c22(b_over_a: f64) -> f64 {
    2.4014 + 1.3179 / b_over_a - 0.02 / (b_over_a * b_over_a)
}

/// Complete elliptic integrals K(k), E(k) by the arithmetic-geometric mean (modulus k < 1).
pub fn elliptic_ke(k: f64) -> (f64, f64) {
    let mut a = 1.0;
    let mut b = (1.0 - k * k).sqrt();
    let mut c_sum = 0.5 * k * k;
    let mut pow2 = 0.5;
    for _ in 0..40 {
        let an = 0.5 * (a + b);
        let bn = (a * b).sqrt();
        let cn = 0.5 * (a - b);
        pow2 *= 2.0;
        c_sum += pow2 * cn * cn;
        a = an;
        b = bn;
        if cn.abs() < 1e-16 {
            break;
        }
    }
    let kk = std::f64::consts::PI / (2.0 * a);
    (kk, kk * (1.0 - c_sum))
}

/// Result of [`hertz_kalker`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HertzKalker {
    /// Semi-axis in rolling direction [m].
    pub a_m: f64,
    /// Lateral semi-axis [m].
    pub b_m: f64,
    /// f11 = G a b C11 [N].
    pub f11_n: f64,
    /// f22 = G a b C22 [N].
    pub f22_n: f64,
}

/// Hertz contact ellipse of a wheel (rolling radius `wheel_radius_m`, flat across) on a
/// rail with crown radius `rail_crown_m`, both steel (`young_pa`, `poisson`), under normal
/// load `load_n`; then Kalker's f11, f22 (5.4)-(5.7) with the labels corrected.
/// Assumes the rail crown curvature exceeds the wheel curvature (a >= b).
pub fn hertz_kalker(
    load_n: f64,
    wheel_radius_m: f64,
    rail_crown_m: f64,
    young_pa: f64,
    poisson: f64,
) -> HertzKalker {
    let a_curv = 0.5 / wheel_radius_m; // rolling direction (rail straight)
    let b_curv = 0.5 / rail_crown_m; // lateral (wheel tread flat)
    let ratio = b_curv / a_curv;
    // ratio(e) = ((a/b)^2 E - K)/(K - E) grows with e: bisection on e.
    let ratio_of = |e: f64| {
        let (k, ee) = elliptic_ke(e);
        (ee / (1.0 - e * e) - k) / (k - ee)
    };
    let (mut lo, mut hi) = (1e-6, 1.0 - 1e-12);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if ratio_of(mid) < ratio {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let e = 0.5 * (lo + hi);
    let (k, ee) = elliptic_ke(e);
    let e_star = young_pa / (2.0 * (1.0 - poisson * poisson));
    // Johnson (1985) (4.39): A = p0 b (K - E)/(E* e^2 a^2), P = 2/3 pi a b p0
    let a3 = 3.0 * load_n * (k - ee) / (2.0 * std::f64::consts::PI * a_curv * e_star * e * e);
    let a = a3.cbrt();
    let b = a * (1.0 - e * e).sqrt();
    let g = young_pa / (2.0 * (1.0 + poisson));
    let g_ab = g * a * b;
    HertzKalker {
        a_m: a,
        b_m: b,
        f11_n: g_ab * kalker_c11(b / a),
        f22_n: g_ab * kalker_c22(b / a),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kalker_labels_match_kalker_table() {
        // Kalker (1967) Table, Poisson 0.25, a/b = 1: C11 = 4.12, C22 = 3.67
        assert!((kalker_c11(1.0) - 4.12).abs() / 4.12 < 0.04);
        assert!((kalker_c22(1.0) - 3.67).abs() / 3.67 < 0.02);
        // b/a = 0.5 (long ellipse): Kalker C11 = 5.10, C22 = 4.90
        assert!((kalker_c11(0.5) - 5.10).abs() / 5.10 < 0.05);
        assert!((kalker_c22(0.5) - 4.90).abs() / 4.90 < 0.05);
    }

    #[test]
    fn elliptic_integrals() {
        let (k, e) = elliptic_ke(0.0);
        assert!((k - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert!((e - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        // k = 0.5: K = 1.685750354812596, E = 1.467462209339427
        let (k, e) = elliptic_ke(0.5);
        assert!((k - 1.685_750_354_812_596).abs() < 1e-10);
        assert!((e - 1.467_462_209_339_427).abs() < 1e-10);
    }

    #[test]
    fn hertz_gives_creep_coefficients_of_order_10_mn() {
        let hk = hertz_kalker(70e3, 0.46, 0.3, 210e9, 0.28);
        // contact patch of a few mm, longer in rolling direction
        assert!(hk.a_m > hk.b_m && hk.a_m > 4e-3 && hk.a_m < 9e-3, "{hk:?}");
        assert!(hk.f11_n > 9e6 && hk.f11_n < 14e6, "{hk:?}");
        assert!(hk.f22_n > 8e6 && hk.f22_n < 13e6, "{hk:?}");
        // defaults in Params come from this calculation
        let p = crate::Params::default();
        assert!((p.f11_n - hk.f11_n).abs() / hk.f11_n < 0.02, "{hk:?}");
        assert!((p.f22_n - hk.f22_n).abs() / hk.f22_n < 0.02, "{hk:?}");
    }

    #[test]
    fn saturation_law() {
        // small force: unchanged; u = 3: fully saturated at mu P
        assert!((saturation_factor(1e-9, 1.0) - 1.0).abs() < 1e-8);
        assert!((saturation_factor(3.0, 1.0) * 3.0 - 1.0).abs() < 1e-12);
        assert!((saturation_factor(10.0, 1.0) * 10.0 - 1.0).abs() < 1e-12);
        // equals 1 - (1 - tau)^3 with tau = u/3 (5.24)
        for &u in &[0.3_f64, 1.0, 2.2] {
            let tau = u / 3.0;
            let f = 1.0 - (1.0 - tau).powi(3);
            assert!((saturation_factor(u, 1.0) * u - f).abs() < 1e-12);
        }
    }

    #[test]
    fn synthetic_table_and_roundtrip() {
        let t = ContactTable::synthetic(0.15, 7e-3, 0.5e-3, 2.7).unwrap();
        let c = t.lookup(3e-3);
        assert!((c.delta_r_right_m - 0.15 * 3e-3).abs() < 1e-9);
        assert!((c.delta_r_left_m + 0.15 * 3e-3).abs() < 1e-9);
        assert!((c.tan_gamma_right - 0.15).abs() < 1e-9);
        let f = t.lookup(8e-3);
        assert!(f.tan_gamma_right > 2.6 && f.delta_r_right_m > 2e-3);
        let (lam, g) = t.linearise(2e-3);
        assert!((lam - 0.15).abs() < 1e-6 && g.abs() < 1e-9);
        let t2 = ContactTable::parse_csv(&t.to_csv()).unwrap();
        let c2 = t2.lookup(7.3e-3);
        let c1 = t.lookup(7.3e-3);
        assert!((c2.tan_gamma_right - c1.tan_gamma_right).abs() < 1e-5);
    }

    #[test]
    fn bad_tables_rejected() {
        assert!(ContactTable::parse_csv("y,a\n1,2").is_err());
        let h = TABLE_HEADER;
        assert!(ContactTable::parse_csv(&format!("{h}\n0,0,0,0,0\n")).is_err());
        assert!(ContactTable::parse_csv(&format!("{h}\n0,0,0,0,0\n0,0,0,0,0\n")).is_err());
        assert!(ContactTable::parse_csv(&format!("{h}\n0,0,0,0,0\n1,0,x,0,0\n")).is_err());
        assert!(ContactTable::load("/nonexistent/table.csv").is_err());
    }
}
