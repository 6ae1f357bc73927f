//! Rigid wheel/rail contact search over the wheelset lateral displacement.
//!
//! Track frame: lateral `Y` positive to the RIGHT (looking in the direction of travel), vertical `Z`
//! positive UP, origin on the track centre line at the height of the rail-profile origins.
//! The right rail lies at `Y > 0`. A profile point `(s, z)` (lateral towards the field side, up) of
//! the right side maps to `Y = offset + s`, of the left side to `Y = -(offset + s)` (mirror image).
//!
//! Wheelset: wheel profile point `(s, z)` is at `Ŷ = ±(d + s)`, `Ẑ = z - r0` relative to the axle
//! centre (`d` = half distance of the profile origins, `r0` = nominal radius of that wheel), so the
//! rolling radius at `s` is `r0 - z(s)`. The wheelset is displaced by `y` laterally and rolled by
//! `φ` (positive = right wheel up) about a pivot on its centre plane, at rail level (default,
//! [`LateralReference::RailLevel`]) or at the axle centre. For each `y` the roll angle and the
//! vertical position are solved so that the minimum VERTICAL gap between the wheel and rail
//! polylines is zero on both sides (rigid, single-point contact per side; the global minimum is
//! taken, so the jump from tread to flange contact appears as a jump of the contact point).
//! The reported contact point of each side is the penetration-weighted centroid of the connected
//! zone around that minimum where the gap is below `min + contact_zone_depth_m` (integrated on a
//! 0.01 mm lateral grid): in nearly conformal zones the bare minimum is ill-conditioned (see the
//! crate docs), the centroid is not; where the gap is sharply curved it equals the minimum.
//!
//! Unequal nominal radii enter as [`ContactSetup::radius_convention`] says: the EN 15302 offset
//! of Δr (search with equal radii) or the rigid wheelset's roll ([`RadiusConvention`]).
//!
//! The set-up types live in `setup`, the table over `y` (flange-climbing rows beyond the flange
//! limit, contact-point jumps located by bisection) in `sweep`; both are re-exported here.

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::profile::{Profile, ProfileError};

mod setup;
mod sweep;

pub use setup::{
    ContactSetup, LateralReference, RadiusConvention, RailPlacement, WheelPlacement,
    CONTACT_ZONE_DEPTH_M,
};
pub use sweep::{compute_table, compute_table_until, ContactJump, ContactTable, MAX_TABLE_ROWS};

/// Half width of the central difference used for the contact-angle slope [m].
const SLOPE_HALF_WINDOW_M: f64 = 0.25e-3;
/// A wheel whose steepest rising segment exceeds this slope is considered flanged; its flange limit
/// is the steepest point of the active flange face.
const FLANGE_MIN_SLOPE: f64 = 1.0;
/// A flange-steep rise this near the origin on the field side \[m\] is a mirrored profile's
/// flange (a flange's face lies 25-45 mm from the taping line), not an outer chamfer or rim
/// face (S1002's chamfer: +60.7 mm).
const MIRRORED_FLANGE_MAX_M: f64 = 0.050;
/// Lateral grid step of the contact-zone integration [m].
const ZONE_STEP_M: f64 = 0.01e-3;
/// Largest half width of a contact zone, in grid steps (30 mm).
const ZONE_MAX_STEPS: f64 = 3000.0;

/// A number for a message: as written below 1e16 (and above 1e-4), in scientific notation
/// beyond (a gauge of 1e300 m printed 300 digits).
pub(crate) fn short(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e16).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// Errors of the contact geometry.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ContactError {
    /// A setup parameter is invalid.
    #[error("invalid parameter `{name}` = {}: {reason}", short(*.value))]
    Param {
        /// Parameter name.
        name: &'static str,
        /// Its value.
        value: f64,
        /// Why it is invalid.
        reason: &'static str,
    },
    /// A profile problem (e.g. rail not single-valued after applying the inclination).
    #[error(transparent)]
    Profile(#[from] ProfileError),
    /// A reference point (gauge point, flange face point) was not found on a profile.
    #[error("{profile}: {what} not found")]
    ReferencePoint {
        /// Profile name.
        profile: String,
        /// What was searched.
        what: String,
    },
    /// The wheel and rail do not overlap laterally, or the rolled wheel is not single-valued.
    #[error("no contact on {side} at y = {} mm: {reason}", short(*.y_m * 1e3))]
    NoContact {
        /// "the left side", "the right side" or "either side".
        side: &'static str,
        /// Lateral displacement.
        y_m: f64,
        /// Reason.
        reason: &'static str,
    },
    /// A wheel profile without a flange on its flange side but as steep a rise near its origin
    /// on the field side: its flange is there, the profile mirrored.
    #[error(
        "{profile}: no flange at negative lateral values, but a rise as steep as a flange at \
         +{} mm: is the wheel profile mirrored? (lateral positive towards the field side, the \
         flange at negative values)",
        (*.at_m * 1e4).round() / 10.0
    )]
    MirroredWheel {
        /// Profile name.
        profile: String,
        /// Where the flange-steep rise lies \[m\].
        at_m: f64,
    },
    /// The caller asked the computation to stop.
    #[error("stopped before the table was complete")]
    Stopped,
    /// The roll angle equation could not be solved.
    #[error(
        "roll angle not found at y = {} mm (searched up to |phi| = {limit_rad} rad)",
        short(*.y_m * 1e3)
    )]
    RollNotFound {
        /// Lateral displacement.
        y_m: f64,
        /// Search limit.
        limit_rad: f64,
    },
}

/// Contact point of one wheel.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WheelContact {
    /// Contact position on the wheel profile, in the wheel profile's own lateral coordinate \[m\].
    pub wheel_lateral_m: f64,
    /// Contact position on the rail profile, in the rail file's own lateral coordinate \[m\].
    pub rail_lateral_m: f64,
    /// Contact point in the track frame: lateral \[m\] (positive right).
    pub track_lateral_m: f64,
    /// Contact point in the track frame: vertical \[m\] (rail surface height).
    pub track_vertical_m: f64,
    /// Rolling radius \[m\].
    pub rolling_radius_m: f64,
    /// Rolling radius minus the nominal radius of this wheel \[m\].
    pub delta_radius_m: f64,
    /// Tangent of the contact angle in the track frame, positive when the surface rises towards
    /// the field side (conical tread), large on the flange.
    pub tan_gamma: f64,
}

/// Contact state at one lateral displacement.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ContactRow {
    /// Wheelset lateral displacement \[m\], positive to the right.
    pub y_m: f64,
    /// Left wheel contact.
    pub left: WheelContact,
    /// Right wheel contact.
    pub right: WheelContact,
    /// Roll angle \[rad\], positive = right wheel up.
    pub roll_rad: f64,
    /// Height of the axle centre above the rail-profile origin level \[m\].
    pub axle_centre_height_m: f64,
    /// Rolling radius difference r_right - r_left \[m\].
    pub delta_r_m: f64,
    /// True if this row lies beyond the flange limit (or the profiles' extent) and repeats the
    /// last reachable row.
    pub beyond_flange_limit: bool,
}

/// One wheel of the wheelset.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum WheelSide {
    /// Left wheel (track lateral Y < 0).
    Left,
    /// Right wheel (track lateral Y > 0).
    Right,
}

impl WheelSide {
    fn sign(self) -> f64 {
        match self {
            WheelSide::Left => -1.0,
            WheelSide::Right => 1.0,
        }
    }
    /// "left" or "right".
    pub fn name(self) -> &'static str {
        match self {
            WheelSide::Left => "left",
            WheelSide::Right => "right",
        }
    }
}

impl ContactRow {
    /// The contact of one wheel.
    pub fn wheel(&self, side: WheelSide) -> &WheelContact {
        match side {
            WheelSide::Left => &self.left,
            WheelSide::Right => &self.right,
        }
    }

    /// The same state with the wheels' nominal radii `r_left0`, `r_right0` applied as EN 15302
    /// offsets ([`RadiusConvention::En15302Offset`]): each rolling radius becomes its own
    /// nominal radius plus the deviation of this (equal-radius) row.
    fn with_nominal_radii(mut self, r_left0: f64, r_right0: f64) -> Self {
        self.left.rolling_radius_m = r_left0 + self.left.delta_radius_m;
        self.right.rolling_radius_m = r_right0 + self.right.delta_radius_m;
        self.delta_r_m = self.right.rolling_radius_m - self.left.rolling_radius_m;
        self
    }
}

/// One side, prepared for the search.
#[derive(Debug, Clone)]
struct PreparedSide {
    side: WheelSide,
    wheel: Profile,
    r0: f64,
    /// Half distance of the wheel profile origin from the wheelset centre plane.
    d: f64,
    /// Rail in the track frame, increasing Y: (Y, Z, lateral in the rail file frame).
    rail: Vec<(f64, f64, f64)>,
    /// Flange limit on the wheel profile (steepest point of the flange), if flanged.
    flange_s: Option<f64>,
}

#[derive(Debug, Clone)]
pub(crate) struct Prepared {
    left: PreparedSide,
    right: PreparedSide,
    pivot_depth: f64,
    zone_depth: f64,
    /// (left, right) nominal radii to apply to each solved row as EN 15302 offsets, when the
    /// search runs with their mean.
    nominal_offsets: Option<(f64, f64)>,
}

#[derive(Debug, Clone, Copy)]
struct SideGap {
    gap: f64,
    s_wheel: f64,
    s_rail: f64,
    y_track: f64,
    z_rail: f64,
    at_end: bool,
}

/// Gauge point: first crossing of (top - depth) coming from the low-lateral (gauge) side.
fn gauge_point(rail: &Profile, depth: f64) -> Result<f64, ContactError> {
    let top = rail
        .vertical_m
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    let level = top - depth;
    let xs = &rail.lateral_m;
    let zs = &rail.vertical_m;
    for i in 1..xs.len() {
        if (zs[i - 1] - level) * (zs[i] - level) <= 0.0 && zs[i] != zs[i - 1] {
            let t = (level - zs[i - 1]) / (zs[i] - zs[i - 1]);
            return Ok(xs[i - 1] + t * (xs[i] - xs[i - 1]));
        }
    }
    Err(ContactError::ReferencePoint {
        profile: rail.name.clone(),
        what: format!("gauge point {depth} m below the top of rail"),
    })
}

/// Active flange face point: first crossing of z = -depth going from the origin towards the flange.
fn flange_face_point(wheel: &Profile, depth: f64) -> Result<f64, ContactError> {
    let xs = &wheel.lateral_m;
    let zs = &wheel.vertical_m;
    let level = -depth;
    let start = xs.partition_point(|&x| x <= 0.0).min(xs.len() - 1);
    for i in (1..=start).rev() {
        if (zs[i - 1] - level) * (zs[i] - level) <= 0.0 && zs[i] != zs[i - 1] {
            let t = (level - zs[i - 1]) / (zs[i] - zs[i - 1]);
            return Ok(xs[i - 1] + t * (xs[i] - xs[i - 1]));
        }
    }
    Err(ContactError::ReferencePoint {
        profile: wheel.name.clone(),
        what: format!("active flange face {depth} m below the profile origin"),
    })
}

pub(crate) fn prepare(setup: &ContactSetup) -> Result<Prepared, ContactError> {
    setup.validate()?;
    let (r_left0, r_right0) = (setup.nominal_radius_left_m, setup.nominal_radius_right_m);
    // EN 15302 offset: search with the mean radius on both wheels, apply the real ones after.
    let nominal_offsets = (setup.radius_convention == RadiusConvention::En15302Offset
        && r_left0 != r_right0)
        .then_some((r_left0, r_right0));
    let (r_left, r_right) = match nominal_offsets {
        Some(_) => (0.5 * (r_left0 + r_right0), 0.5 * (r_left0 + r_right0)),
        None => (r_left0, r_right0),
    };
    let incl = setup.rail_inclination.atan();
    let mk = |side: WheelSide| -> Result<PreparedSide, ContactError> {
        let (wheel, rail_file, r0) = match side {
            WheelSide::Left => (&setup.wheel_left, &setup.rail_left, r_left),
            WheelSide::Right => (&setup.wheel_right, &setup.rail_right, r_right),
        };
        let rail = if incl != 0.0 {
            rail_file.rotated(incl)?
        } else {
            rail_file.clone()
        };
        let d = match setup.wheel_placement {
            WheelPlacement::RollingCircleDistance { distance_m } => 0.5 * distance_m,
            WheelPlacement::BackToBack {
                back_to_back_m,
                back_face_to_origin_m,
            } => 0.5 * back_to_back_m + back_face_to_origin_m,
            WheelPlacement::FlangeFaces {
                distance_m,
                measuring_depth_m,
            } => 0.5 * distance_m - flange_face_point(wheel, measuring_depth_m)?,
        };
        let offset = match setup.rail_placement {
            RailPlacement::Gauge {
                gauge_m,
                measuring_depth_m,
            } => 0.5 * gauge_m - gauge_point(&rail, measuring_depth_m)?,
            RailPlacement::OriginDistance { distance_m } => 0.5 * distance_m,
        };
        // Rail lateral coordinate in the file frame for reporting: undo the inclination.
        let (sn, cs) = incl.sin_cos();
        let sg = side.sign();
        let mut pts: Vec<(f64, f64, f64)> = rail
            .lateral_m
            .iter()
            .zip(&rail.vertical_m)
            .map(|(&s, &z)| (sg * (offset + s), z, s * cs + z * sn))
            .collect();
        if side == WheelSide::Left {
            pts.reverse();
        }
        // the flange on the flange side only (negative lateral values): a measured profile's
        // outer rim face or chamfer, on the field side, is steeper than its tread and was taken
        // for the flange (the central row then lay "beyond the flange limit")
        let (fs, fm) = wheel.max_slope_within(f64::NEG_INFINITY, 0.0);
        if fm <= FLANGE_MIN_SLOPE {
            // mirrored, the flange lies on the field side and falls as steeply as it rose
            let (ms, mm) = wheel.steepest_fall_within(0.0, MIRRORED_FLANGE_MAX_M);
            if mm > FLANGE_MIN_SLOPE {
                return Err(ContactError::MirroredWheel {
                    profile: wheel.name.clone(),
                    at_m: ms,
                });
            }
        }
        Ok(PreparedSide {
            side,
            wheel: wheel.clone(),
            r0,
            d,
            rail: pts,
            flange_s: (fm > FLANGE_MIN_SLOPE).then_some(fs),
        })
    };
    let left = mk(WheelSide::Left)?;
    let right = mk(WheelSide::Right)?;
    let pivot_depth = match setup.lateral_reference {
        LateralReference::RailLevel => 0.5 * (left.r0 + right.r0),
        LateralReference::AxleCentre => 0.0,
    };
    Ok(Prepared {
        left,
        right,
        pivot_depth,
        zone_depth: setup.contact_zone_depth_m,
        nominal_offsets,
    })
}

impl PreparedSide {
    /// Minimum vertical gap for the wheelset at (y, roll), axle reference height 0.
    fn min_gap(
        &self,
        y: f64,
        phi: f64,
        h: f64,
        buf: &mut Vec<(f64, f64, f64)>,
    ) -> Result<SideGap, ContactError> {
        let (sn, cs) = phi.sin_cos();
        let sg = self.side.sign();
        buf.clear();
        let n = self.wheel.len();
        for k in 0..n {
            // ascending Y: right side in profile order, left side reversed
            let i = if sg > 0.0 { k } else { n - 1 - k };
            let s = self.wheel.lateral_m[i];
            let yh = sg * (self.d + s);
            let zh = self.wheel.vertical_m[i] - self.r0 + h;
            buf.push((y + yh * cs - zh * sn, yh * sn + zh * cs - h, s));
        }
        let no_contact = |reason| ContactError::NoContact {
            side: match self.side {
                WheelSide::Left => "the left side",
                WheelSide::Right => "the right side",
            },
            y_m: y,
            reason,
        };
        let rail = &self.rail;
        // only the part of the wheel over the rail can touch it: a back face or rim beyond the
        // rail head that folds over when the wheelset rolls does not matter (it cut a table
        // short, taken for the flange limit)
        let (rail_lo, rail_hi) = (rail[0].0, rail[rail.len() - 1].0);
        let over = |p: &(f64, f64, f64)| p.0 >= rail_lo && p.0 <= rail_hi;
        if let (Some(a), Some(b)) = (buf.iter().position(over), buf.iter().rposition(over)) {
            buf.truncate((b + 1).min(n - 1) + 1);
            buf.drain(..a.saturating_sub(1));
        }
        if buf.windows(2).any(|w| w[1].0 <= w[0].0) {
            return Err(no_contact("rolled wheel profile is not single-valued"));
        }
        let lo = buf[0].0.max(rail[0].0);
        let hi = buf[buf.len() - 1].0.min(rail[rail.len() - 1].0);
        if hi <= lo {
            return Err(no_contact(
                "wheel and rail profiles do not overlap laterally",
            ));
        }
        let mut best: Option<SideGap> = None;
        let consider = |best: &mut Option<SideGap>, g: SideGap| match best {
            Some(b) if b.gap <= g.gap => {}
            _ => *best = Some(g),
        };
        // wheel vertices against the rail polyline
        let mut j = 1;
        for &(yw, zw, sw) in buf.iter() {
            if yw < lo || yw > hi {
                continue;
            }
            while j < rail.len() - 1 && rail[j].0 < yw {
                j += 1;
            }
            let (a, b) = (rail[j - 1], rail[j]);
            let t = ((yw - a.0) / (b.0 - a.0)).clamp(0.0, 1.0);
            let zr = a.1 + t * (b.1 - a.1);
            consider(
                &mut best,
                SideGap {
                    gap: zw - zr,
                    s_wheel: sw,
                    s_rail: a.2 + t * (b.2 - a.2),
                    y_track: yw,
                    z_rail: zr,
                    at_end: false,
                },
            );
        }
        // rail vertices against the wheel polyline
        let mut i = 1;
        for &(yr, zr, sr) in rail.iter() {
            if yr < lo || yr > hi {
                continue;
            }
            while i < buf.len() - 1 && buf[i].0 < yr {
                i += 1;
            }
            let (a, b) = (buf[i - 1], buf[i]);
            let t = ((yr - a.0) / (b.0 - a.0)).clamp(0.0, 1.0);
            consider(
                &mut best,
                SideGap {
                    gap: a.1 + t * (b.1 - a.1) - zr,
                    s_wheel: a.2 + t * (b.2 - a.2),
                    s_rail: sr,
                    y_track: yr,
                    z_rail: zr,
                    at_end: false,
                },
            );
        }
        let mut g = best.ok_or_else(|| no_contact("no overlapping points"))?;
        // contact at the edge of the overlap: the profiles are exhausted there
        let tol = 1e-9;
        g.at_end = g.y_track <= lo + tol || g.y_track >= hi - tol;
        Ok(g)
    }

    /// Contact point as the penetration-weighted centroid of the contact zone: the connected
    /// stretch around the minimum `g` where the gap is below `g.gap + depth`, integrated on a
    /// uniform lateral grid (weights `g.gap + depth - gap`). `buf` must hold this side's rolled
    /// wheel from the `min_gap` call that produced `g`.
    fn zone_centroid(&self, g: SideGap, depth: f64, buf: &[(f64, f64, f64)]) -> SideGap {
        if depth <= 0.0 || g.at_end {
            return g;
        }
        let rail = &self.rail;
        let lo = buf[0].0.max(rail[0].0);
        let hi = buf[buf.len() - 1].0.min(rail[rail.len() - 1].0);
        // (vertical, lateral in the profile's own frame) at track lateral `yq`
        let at = |poly: &[(f64, f64, f64)], yq: f64| -> (f64, f64) {
            let k = poly.partition_point(|q| q.0 <= yq).clamp(1, poly.len() - 1);
            let (a, b) = (poly[k - 1], poly[k]);
            let t = ((yq - a.0) / (b.0 - a.0)).clamp(0.0, 1.0);
            (a.1 + t * (b.1 - a.1), a.2 + t * (b.2 - a.2))
        };
        let level = g.gap + depth;
        let weight = |yq: f64| level - (at(buf, yq).0 - at(rail, yq).0);
        let (mut sw, mut swy) = (0.0, 0.0);
        for dir in [-1.0, 1.0] {
            let mut k = if dir < 0.0 { 0.0 } else { 1.0 };
            loop {
                let yq = g.y_track + dir * k * ZONE_STEP_M;
                if yq < lo || yq > hi || k > ZONE_MAX_STEPS {
                    break;
                }
                let w = weight(yq);
                if w <= 0.0 {
                    break;
                }
                sw += w;
                swy += w * yq;
                k += 1.0;
            }
        }
        if sw <= 0.0 {
            return g;
        }
        let yc = swy / sw;
        let (_, s_wheel) = at(buf, yc);
        let (z_rail, s_rail) = at(rail, yc);
        SideGap {
            s_wheel,
            s_rail,
            y_track: yc,
            z_rail,
            ..g
        }
    }

    fn contact(&self, g: &SideGap, phi: f64) -> Result<WheelContact, ContactError> {
        let z = self.wheel.vertical_at(g.s_wheel).unwrap_or(0.0);
        let slope = self
            .wheel
            .slope_at(g.s_wheel, SLOPE_HALF_WINDOW_M)
            .ok_or_else(|| ContactError::ReferencePoint {
                profile: self.wheel.name.clone(),
                what: "slope at the contact point".to_string(),
            })?;
        // right: angle = atan(slope) + phi; left (mirrored): atan(slope) - phi
        let tan_gamma = (slope.atan() + self.side.sign() * phi).tan();
        Ok(WheelContact {
            wheel_lateral_m: g.s_wheel,
            rail_lateral_m: g.s_rail,
            track_lateral_m: g.y_track,
            track_vertical_m: g.z_rail,
            rolling_radius_m: self.r0 - z,
            delta_radius_m: -z,
            tan_gamma,
        })
    }

    fn beyond_limit(&self, g: &SideGap) -> bool {
        g.at_end || self.flange_s.is_some_and(|fs| g.s_wheel < fs)
    }
}

/// One solved row and where it lies.
pub(crate) struct Solved {
    pub(crate) row: ContactRow,
    /// Beyond the flange limit or at a profile end.
    pub(crate) beyond: bool,
    /// A contact at the end of a profile's overlap (the profiles are exhausted there).
    pub(crate) at_end: bool,
}

pub(crate) fn solve_at(p: &Prepared, y: f64, phi_guess: f64) -> Result<Solved, ContactError> {
    let h = p.pivot_depth;
    let mut buf = Vec::with_capacity(p.left.wheel.len().max(p.right.wheel.len()));
    let mut f = |phi: f64| -> Result<(f64, SideGap, SideGap), ContactError> {
        let gl = p.left.min_gap(y, phi, h, &mut buf)?;
        let gr = p.right.min_gap(y, phi, h, &mut buf)?;
        Ok((gr.gap - gl.gap, gl, gr))
    };
    // bracket the root of F(phi) = gap_right - gap_left (increasing in phi)
    let limit = 0.1;
    let mut w = 1e-3;
    let (mut a, mut b);
    let (mut fa, mut fb);
    loop {
        a = phi_guess - w;
        b = phi_guess + w;
        fa = f(a)?.0;
        fb = f(b)?.0;
        if fa <= 0.0 && fb >= 0.0 {
            break;
        }
        w *= 2.0;
        if w > limit {
            return Err(ContactError::RollNotFound {
                y_m: y,
                limit_rad: limit,
            });
        }
    }
    // Illinois (modified regula falsi); `phi` is the latest iterate, the bracket always holds
    // the root.
    let mut retained = 0i8;
    let mut phi = 0.5 * (a + b);
    for _ in 0..200 {
        if b - a < 1e-13 {
            phi = 0.5 * (a + b);
            break;
        }
        let c = if fb != fa {
            (a * fb - b * fa) / (fb - fa)
        } else {
            0.5 * (a + b)
        };
        phi = if c > a && c < b { c } else { 0.5 * (a + b) };
        let fc = f(phi)?.0;
        if fc.abs() < 1e-14 {
            break;
        }
        if fc < 0.0 {
            a = phi;
            fa = fc;
            if retained == 1 {
                fb *= 0.5;
            }
            retained = 1; // b retained
        } else {
            b = phi;
            fb = fc;
            if retained == -1 {
                fa *= 0.5;
            }
            retained = -1; // a retained
        }
        phi = 0.5 * (a + b);
    }
    let gl = p.left.min_gap(y, phi, h, &mut buf)?;
    let gl = p.left.zone_centroid(gl, p.zone_depth, &buf);
    let gr = p.right.min_gap(y, phi, h, &mut buf)?;
    let gr = p.right.zone_centroid(gr, p.zone_depth, &buf);
    let zc = -0.5 * (gl.gap + gr.gap);
    let left = p.left.contact(&gl, phi)?;
    let right = p.right.contact(&gr, phi)?;
    let beyond = p.left.beyond_limit(&gl) || p.right.beyond_limit(&gr);
    let row = ContactRow {
        y_m: y,
        left,
        right,
        roll_rad: phi,
        axle_centre_height_m: zc + h * phi.cos() - h,
        delta_r_m: right.rolling_radius_m - left.rolling_radius_m,
        beyond_flange_limit: beyond,
    };
    let row = match p.nominal_offsets {
        Some((r_left0, r_right0)) => row.with_nominal_radii(r_left0, r_right0),
        None => row,
    };
    Ok(Solved {
        row,
        beyond,
        at_end: gl.at_end || gr.at_end,
    })
}

/// Contact state at a single lateral displacement `y_m` (no flange-limit clamping; check
/// `beyond_flange_limit`).
pub fn solve_contact(setup: &ContactSetup, y_m: f64) -> Result<ContactRow, ContactError> {
    if !y_m.is_finite() {
        return Err(ContactError::Param {
            name: "y_m",
            value: y_m,
            reason: "must be finite",
        });
    }
    let p = prepare(setup)?;
    Ok(solve_at(&p, y_m, 0.0)?.row)
}
