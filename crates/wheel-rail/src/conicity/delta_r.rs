//! The rolling-radius difference Δr(y) as a piecewise-linear function, its exact integral
//! S(y) = ∫ Δr dy (the potential of the kinematic oscillation, (K2) of the module docs), the
//! equilibrium position and the turning points of an oscillation of given amplitude.

use super::ConicityError;
use crate::contact::ContactTable;

/// Relative tolerance on S for "equal levels" (plateaus of a flat Δr = 0 tread are exact).
const LEVEL_REL_TOL: f64 = 1e-9;

/// Δr a contact search resolves \[m\]: below it a computed Δr is taken as 0. On a wide gauge
/// both wheels run on the flat of the tread over several millimetres, where the search gives
/// |Δr| of 0.01-0.2 µm of either sign (the profiles' own resolution, far below the contact
/// zone's 7.5 µm); that noise put the equilibrium of a wheelset without restoring force
/// millimetres off centre and left no oscillation of 1 mm (1445 mm gauge).
pub const DELTA_R_RESOLUTION_M: f64 = 1e-6;

/// Piecewise-linear Δr(y) = r_right - r_left and its exact integral.
#[derive(Debug, Clone, PartialEq)]
pub struct DeltaR {
    y: Vec<f64>,
    dr: Vec<f64>,
    s: Vec<f64>,
    e0_m: f64,
    r0_m: f64,
    flange_limits_m: Option<(f64, f64)>,
}

/// Turning points of a kinematic oscillation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Oscillation {
    pub(crate) y1: f64,
    pub(crate) y2: f64,
    /// S(y1) = S(y2).
    pub(crate) level: f64,
    /// Smallest S between the turning points (the bottom of the potential well).
    pub(crate) bottom: f64,
}

impl DeltaR {
    /// From a contact table (|Δr| below `DELTA_R_RESOLUTION_M`, 1 µm, taken as 0): every solved state ([`ContactTable::solved_states`]: reachable rows,
    /// flange-climbing rows beyond the flange limit, and the states on both sides of each located
    /// contact-point jump), with e0 and the mean nominal radius of the table.
    pub fn from_table(table: &ContactTable) -> Self {
        let (y, dr): (Vec<f64>, Vec<f64>) = table
            .solved_states()
            .iter()
            .map(|r| {
                let resolved = r.delta_r_m.abs() >= DELTA_R_RESOLUTION_M;
                (r.y_m, if resolved { r.delta_r_m } else { 0.0 })
            })
            .unzip();
        let mut d = Self::build(y, dr, table.e0_m, table.nominal_radius_mean_m());
        d.flange_limits_m = Some((table.y_reachable_min_m, table.y_reachable_max_m));
        d
    }

    /// From sampled values (e.g. a reference Δr function): `y_m` strictly increasing, same length
    /// as `delta_r_m`, at least 3 points; `e0_m`, `r0_m` only scale the reported wavelength.
    pub fn from_samples(
        y_m: &[f64],
        delta_r_m: &[f64],
        e0_m: f64,
        r0_m: f64,
    ) -> Result<Self, ConicityError> {
        let ok = y_m.len() == delta_r_m.len()
            && y_m.len() >= 3
            && y_m.windows(2).all(|w| w[1] > w[0])
            && y_m.iter().chain(delta_r_m).all(|v| v.is_finite())
            && e0_m.is_finite()
            && e0_m > 0.0
            && r0_m.is_finite()
            && r0_m > 0.0;
        if !ok {
            return Err(ConicityError::Samples);
        }
        Ok(Self::build(y_m.to_vec(), delta_r_m.to_vec(), e0_m, r0_m))
    }

    fn build(y: Vec<f64>, dr: Vec<f64>, e0_m: f64, r0_m: f64) -> Self {
        let mut s = vec![0.0; y.len()];
        for i in 1..y.len() {
            s[i] = s[i - 1] + 0.5 * (dr[i] + dr[i - 1]) * (y[i] - y[i - 1]);
        }
        Self {
            y,
            dr,
            s,
            e0_m,
            r0_m,
            flange_limits_m: None,
        }
    }

    /// Half distance between the contact points used for the wavelength \[m\].
    pub fn e0_m(&self) -> f64 {
        self.e0_m
    }

    /// Mean nominal rolling radius used for the wavelength \[m\].
    pub fn r0_m(&self) -> f64 {
        self.r0_m
    }

    /// The y of the samples \[m\].
    pub fn samples_y(&self) -> &[f64] {
        &self.y
    }

    /// Range of y where Δr is known \[m\].
    pub fn range_m(&self) -> (f64, f64) {
        (
            self.y.first().copied().unwrap_or(f64::NAN),
            self.y.last().copied().unwrap_or(f64::NAN),
        )
    }

    /// The flange limits of the table (reachable range), if built from one; Δr beyond them is
    /// the wheel climbing its flange.
    pub fn flange_limits_m(&self) -> Option<(f64, f64)> {
        self.flange_limits_m
    }

    /// Δr at `y` (linear interpolation, constant extrapolation) \[m\].
    pub fn delta_r_at(&self, y: f64) -> f64 {
        if y <= self.y[0] {
            return self.dr[0];
        }
        if y >= self.y[self.y.len() - 1] {
            return self.dr[self.dr.len() - 1];
        }
        let i = self.seg(y);
        let t = (y - self.y[i]) / (self.y[i + 1] - self.y[i]);
        self.dr[i] + t * (self.dr[i + 1] - self.dr[i])
    }

    fn seg(&self, y: f64) -> usize {
        self.y
            .partition_point(|&v| v <= y)
            .clamp(1, self.y.len() - 1)
            - 1
    }

    /// S(y) = ∫ Δr dy from the first sample (exact for the piecewise-linear Δr).
    pub(crate) fn s_at(&self, y: f64) -> f64 {
        let i = self.seg(y);
        let u = y - self.y[i];
        let k = (self.dr[i + 1] - self.dr[i]) / (self.y[i + 1] - self.y[i]);
        self.s[i] + self.dr[i] * u + 0.5 * k * u * u
    }

    /// The points where S can have an extremum inside [lo, hi]: the samples and the zero
    /// crossings of Δr, plus lo and hi; sorted.
    fn extremum_candidates(&self, lo: f64, hi: f64) -> Vec<f64> {
        let mut pts = vec![lo, hi];
        for i in 0..self.y.len() {
            if self.y[i] > lo && self.y[i] < hi {
                pts.push(self.y[i]);
            }
            if i + 1 < self.y.len() && self.dr[i] * self.dr[i + 1] < 0.0 {
                let t = self.dr[i] / (self.dr[i] - self.dr[i + 1]);
                let yz = self.y[i] + t * (self.y[i + 1] - self.y[i]);
                if yz > lo && yz < hi {
                    pts.push(yz);
                }
            }
        }
        pts.sort_by(f64::total_cmp);
        pts
    }

    /// (min, max) of S over [lo, hi].
    pub(crate) fn s_extremes(&self, lo: f64, hi: f64) -> (f64, f64) {
        self.extremum_candidates(lo, hi)
            .into_iter()
            .map(|y| self.s_at(y))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            })
    }

    /// Largest |Δr| over [lo, hi] (at samples or ends).
    fn max_abs_dr(&self, lo: f64, hi: f64) -> f64 {
        self.y
            .iter()
            .zip(&self.dr)
            .filter(|(y, _)| **y > lo && **y < hi)
            .map(|(_, d)| d.abs())
            .chain([self.delta_r_at(lo).abs(), self.delta_r_at(hi).abs()])
            .fold(0.0, f64::max)
    }

    /// Equilibrium position of the wheelset \[m\]: the minimiser of S over the whole range, i.e.
    /// where Δr crosses zero from negative to positive (the bottom of the potential well). A
    /// stretch with Δr = 0 at the bottom (a flat tread) gives its middle; several separate
    /// minimisers of equal depth (a symmetric hollow tread) give the one nearest to y = 0.
    pub fn equilibrium_m(&self) -> Result<f64, ConicityError> {
        let (lo, hi) = self.range_m();
        let pts = self.extremum_candidates(lo, hi);
        let vals: Vec<f64> = pts.iter().map(|&y| self.s_at(y)).collect();
        let s_min = vals.iter().copied().fold(f64::INFINITY, f64::min);
        let scale = self.max_abs_dr(lo, hi) * (hi - lo);
        let tol = LEVEL_REL_TOL * 1e-3 * scale;
        // runs of consecutive candidates at the minimum level
        let mut best: Option<f64> = None;
        let mut k = 0;
        while k < pts.len() {
            if vals[k] > s_min + tol {
                k += 1;
                continue;
            }
            let start = k;
            while k + 1 < pts.len() && vals[k + 1] <= s_min + tol {
                k += 1;
            }
            let mid = 0.5 * (pts[start] + pts[k]);
            if best.is_none_or(|b| mid.abs() < b.abs()) {
                best = Some(mid);
            }
            k += 1;
        }
        let y_eq = best.ok_or(ConicityError::Samples)?;
        let restoring_left = self.delta_r_at(lo) < 0.0;
        let restoring_right = self.delta_r_at(hi) > 0.0;
        if (y_eq <= lo && !restoring_left) || (y_eq >= hi && !restoring_right) {
            return Err(ConicityError::NoEquilibrium {
                y_min_m: lo,
                y_max_m: hi,
                delta_r_min_m: self.delta_r_at(lo),
                delta_r_max_m: self.delta_r_at(hi),
            });
        }
        Ok(y_eq)
    }

    /// Turning points y1 < y2 = y1 + 2 amplitude of the kinematic oscillation around the
    /// equilibrium: S(y1) = S(y2) and S <= S(y1) in between (the wheelset stays inside the
    /// potential well), with the equilibrium between them. H(y1) = S(y1 + 2a) - S(y1) is sampled
    /// at its breakpoints (the samples and the samples - 2a) and at its extrema inside each piece,
    /// so it is monotonic between samples; every sign change is refined by bisection, and a
    /// stretch where H = 0 (a flat tread, Δr = 0) gives its middle. Among the candidates that
    /// satisfy the conditions, the one centred nearest to the equilibrium is taken.
    pub(crate) fn oscillation(&self, a: f64) -> Result<Oscillation, ConicityError> {
        let (lo, hi) = self.range_m();
        let no = |reason: String| ConicityError::NoOscillation {
            amplitude_m: a,
            y_min_m: lo,
            y_max_m: hi,
            reason,
        };
        if hi - lo < 2.0 * a {
            return Err(no(format!(
                "Δr is known over {:.3} mm only, less than twice the amplitude",
                (hi - lo) * 1e3
            )));
        }
        let y_eq = self.equilibrium_m()?;
        let h = |y1: f64| self.s_at(y1 + 2.0 * a) - self.s_at(y1);
        let (xlo, xhi) = (lo, hi - 2.0 * a);
        let mut xs = vec![xlo, xhi];
        for &yi in &self.y {
            for x in [yi, yi - 2.0 * a] {
                if x > xlo && x < xhi {
                    xs.push(x);
                }
            }
        }
        xs.sort_by(f64::total_cmp);
        xs.dedup();
        // extremum of H inside each piece: H' = Δr(x + 2a) - Δr(x) is linear there
        let mut extra = Vec::new();
        for w in xs.windows(2) {
            let d0 = self.delta_r_at(w[0] + 2.0 * a) - self.delta_r_at(w[0]);
            let d1 = self.delta_r_at(w[1] + 2.0 * a) - self.delta_r_at(w[1]);
            if d0 * d1 < 0.0 {
                extra.push(w[0] + d0 / (d0 - d1) * (w[1] - w[0]));
            }
        }
        xs.extend(extra);
        xs.sort_by(f64::total_cmp);
        let hs: Vec<f64> = xs.iter().map(|&x| h(x)).collect();
        let scale = 2.0 * a * self.max_abs_dr(lo, hi);
        let tol_h = 1e-13 * scale;
        let sign = |v: f64| {
            if v.abs() <= tol_h {
                0
            } else if v > 0.0 {
                1
            } else {
                -1
            }
        };
        let mut roots = Vec::new();
        let mut k = 0;
        while k < xs.len() {
            if sign(hs[k]) == 0 {
                let start = k;
                while k + 1 < xs.len() && sign(hs[k + 1]) == 0 {
                    k += 1;
                }
                roots.push(0.5 * (xs[start] + xs[k]));
            } else if k + 1 < xs.len() && sign(hs[k]) * sign(hs[k + 1]) < 0 {
                let (mut l, mut r) = (xs[k], xs[k + 1]);
                let left_sign = sign(hs[k]);
                for _ in 0..200 {
                    let m = 0.5 * (l + r);
                    if sign(h(m)) == left_sign {
                        l = m;
                    } else {
                        r = m;
                    }
                    if r - l < 1e-15 {
                        break;
                    }
                }
                roots.push(0.5 * (l + r));
            }
            k += 1;
        }
        if roots.is_empty() {
            let side = if hs[0] > 0.0 {
                format!("the wheelset would have to go below y = {:.3} mm", lo * 1e3)
            } else {
                format!(
                    "the wheelset would have to go beyond y = {:.3} mm",
                    hi * 1e3
                )
            };
            return Err(no(format!(
                "no turning points with S(y1) = S(y1 + 2 amplitude) inside the range where Δr \
                 is known: {side}, where the contact search ended{}",
                self.limit_note()
            )));
        }
        let mut best: Option<Oscillation> = None;
        let mut blocked: Option<f64> = None;
        for y1 in roots {
            let y2 = y1 + 2.0 * a;
            if y_eq < y1 || y_eq > y2 {
                continue;
            }
            let level = 0.5 * (self.s_at(y1) + self.s_at(y2));
            let (bottom, top) = self.s_extremes(y1, y2);
            let tol = LEVEL_REL_TOL * a * self.max_abs_dr(y1, y2);
            if top > level + tol {
                blocked = Some(y1);
                continue;
            }
            let cand = Oscillation {
                y1,
                y2,
                level,
                bottom,
            };
            let centre = |o: &Oscillation| (0.5 * (o.y1 + o.y2) - y_eq).abs();
            if best.is_none_or(|b| centre(&cand) < centre(&b)) {
                best = Some(cand);
            }
        }
        best.ok_or_else(|| {
            no(match blocked {
                Some(y1) => format!(
                    "Δr does not restore the wheelset between the turning points {:.3} and \
                     {:.3} mm (S rises above the turning-point level in between): no kinematic \
                     oscillation of this amplitude around the equilibrium y = {:.3} mm",
                    y1 * 1e3,
                    (y1 + 2.0 * a) * 1e3,
                    y_eq * 1e3
                ),
                None => format!(
                    "no turning points around the equilibrium y = {:.3} mm",
                    y_eq * 1e3
                ),
            })
        })
    }

    fn limit_note(&self) -> String {
        match self.flange_limits_m {
            Some((l, r)) => format!(
                " (flange limits {:.3} / {:.3} mm; a table over a wider y range lets the search \
                 follow the flange further)",
                l * 1e3,
                r * 1e3
            ),
            None => String::new(),
        }
    }
}
