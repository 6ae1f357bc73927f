//! What defines a contact-geometry computation: the four profiles, the nominal radii, how wheels
//! and rails are placed, where `y` is measured, the contact-zone depth and how a difference of the
//! nominal radii enters ([`RadiusConvention`]).

use serde::{Deserialize, Serialize};

use super::ContactError;
use crate::profile::Profile;

/// How the wheels are placed laterally on the axle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum WheelPlacement {
    /// Lateral distance between the origins of the two wheel profiles (nominal rolling circles),
    /// e.g. 1.500 m for the EN 15302 benchmark profiles.
    RollingCircleDistance {
        /// Distance \[m\].
        distance_m: f64,
    },
    /// Back-to-back distance of the wheels plus the lateral distance from each wheel's back face
    /// to its profile origin (S1002: 70 mm): origin distance = B + 2 * offset.
    BackToBack {
        /// Back-to-back distance \[m\] (1.360 m nominal for standard gauge).
        back_to_back_m: f64,
        /// Back face to profile origin (taping line) \[m\].
        back_face_to_origin_m: f64,
    },
    /// Distance between the active flange faces, each measured `measuring_depth_m` below the
    /// profile origin (e.g. 10 mm below the tread datum).
    FlangeFaces {
        /// Distance \[m\].
        distance_m: f64,
        /// Measuring depth below the profile origin \[m\].
        measuring_depth_m: f64,
    },
}

/// How the rails are placed laterally.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum RailPlacement {
    /// Track gauge between the gauge faces, measured `measuring_depth_m` (14 mm) below the highest
    /// point of each (inclined) rail head. The gauge point is the first crossing of that level
    /// coming from the gauge side of the rail profile.
    Gauge {
        /// Gauge \[m\].
        gauge_m: f64,
        /// Measuring depth below the top of rail \[m\].
        measuring_depth_m: f64,
    },
    /// Lateral distance between the origins of the two rail profiles \[m\].
    OriginDistance {
        /// Distance \[m\].
        distance_m: f64,
    },
}

/// Where the wheelset lateral displacement `y` is measured (only differs by `h * sin(roll)`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum LateralReference {
    /// Centre plane of the wheelset at the level of the nominal rolling circles (rail level).
    /// This is the convention that reproduces the EN 15302 E1 reference.
    RailLevel,
    /// Axle centre.
    AxleCentre,
}

/// Everything that defines a contact-geometry computation.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactSetup {
    /// Left wheel profile (in its own frame: lateral towards the field side, vertical up).
    pub wheel_left: Profile,
    /// Right wheel profile.
    pub wheel_right: Profile,
    /// Left rail profile.
    pub rail_left: Profile,
    /// Right rail profile.
    pub rail_right: Profile,
    /// Nominal rolling radius of the left wheel at its profile origin \[m\] (diameter / 2).
    pub nominal_radius_left_m: f64,
    /// Nominal rolling radius of the right wheel \[m\].
    pub nominal_radius_right_m: f64,
    /// Lateral placement of the wheels on the axle.
    pub wheel_placement: WheelPlacement,
    /// Lateral placement of the rails.
    pub rail_placement: RailPlacement,
    /// Rail inclination to APPLY to the rail profiles as read, as a tangent (e.g. 1/40), positive
    /// = rail head tilted towards the track centre. 0 for profiles already given in track
    /// orientation, such as the EN 15302 rail A (which already contains its inclination).
    pub rail_inclination: f64,
    /// Where `y` is measured.
    pub lateral_reference: LateralReference,
    /// Depth of the contact zone \[m\] ("virtual penetration"): the contact point of each wheel is
    /// the penetration-weighted centroid of the zone where the wheel/rail gap lies within this
    /// depth of its minimum (see the module docs). 0 gives the bare minimum-distance point.
    /// [`CONTACT_ZONE_DEPTH_M`] by default.
    pub contact_zone_depth_m: f64,
    /// How a difference between `nominal_radius_left_m` and `nominal_radius_right_m` enters
    /// (no effect when they are equal).
    pub radius_convention: RadiusConvention,
}

/// How a difference of the nominal wheel radii enters the contact geometry. Both give the same
/// result when the two nominal radii are equal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum RadiusConvention {
    /// EN 15302's convention, the default of the equivalent conicity: the radius difference is an
    /// offset of Δr. The contact search runs with both wheels at the mean nominal radius; each
    /// wheel's rolling radius is then its own nominal radius plus the deviation found there, so
    /// Δr(y) = Δr_equal(y) + (r_R0 - r_L0). Roll angle and axle height are those of the
    /// equal-radius wheelset. Interpretation: the EN 15302 benchmark gives, for the same profiles
    /// (cases E1 and E5, 920/920 and 920/918 mm), conicities that follow from the equal-diameter
    /// Δr plus the radius difference; with this convention our E5 conicity matches the Annex E
    /// values better than with [`RadiusConvention::RigidRoll`] (tests/radius_convention.rs).
    En15302Offset,
    /// The rigid wheelset with its real radii: the smaller wheel rolls the axle by about
    /// (r_R0 - r_L0) / (2 e0), which moves both contact points on crowned rails (Δr shifts by
    /// 2 tanγ R_rail φ, about 0.04-0.1 mm for E5). This is the geometry the time-domain models
    /// feel, so it is the convention of the bogie tables.
    RigidRoll,
}

impl RadiusConvention {
    /// Short name used in CSV headers and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            RadiusConvention::En15302Offset => "en15302-offset",
            RadiusConvention::RigidRoll => "rigid-roll",
        }
    }
}

/// Default [`ContactSetup::contact_zone_depth_m`]: 7.5 µm. Every depth from 5 to 10 µm puts all
/// E1 points with |y| <= 6 mm within 0.1 mm of the EN 15302 reference (tests/e1_benchmark.rs);
/// the default is the middle of that range. It is far below the elastic approach of a loaded
/// wheel (~0.05-0.1 mm), so it only spreads the contact over zones that are conformal to within
/// a few micrometres, where the bare minimum-distance point is ill-conditioned.
pub const CONTACT_ZONE_DEPTH_M: f64 = 7.5e-6;

impl ContactSetup {
    /// Same wheel profile on both sides, same rail on both sides, EN 15302 benchmark placement:
    /// profile origins 1.500 m apart, gauge measured 14 mm below the top of rail, no additional
    /// rail inclination, `y` measured at rail level, the radius difference (if the right radius is
    /// changed afterwards) as an EN 15302 offset of Δr.
    pub fn symmetric(wheel: Profile, rail: Profile, nominal_radius_m: f64, gauge_m: f64) -> Self {
        Self {
            wheel_left: wheel.clone(),
            wheel_right: wheel,
            rail_left: rail.clone(),
            rail_right: rail,
            nominal_radius_left_m: nominal_radius_m,
            nominal_radius_right_m: nominal_radius_m,
            wheel_placement: WheelPlacement::RollingCircleDistance { distance_m: 1.5 },
            rail_placement: RailPlacement::Gauge {
                gauge_m,
                measuring_depth_m: 0.014,
            },
            rail_inclination: 0.0,
            lateral_reference: LateralReference::RailLevel,
            contact_zone_depth_m: CONTACT_ZONE_DEPTH_M,
            radius_convention: RadiusConvention::En15302Offset,
        }
    }

    /// Checks the numeric parameters; the error names the parameter.
    pub fn validate(&self) -> Result<(), ContactError> {
        let check = |name: &'static str, v: f64, lo: f64, hi: f64, reason: &'static str| {
            if v.is_finite() && v > lo && v < hi {
                Ok(())
            } else {
                Err(ContactError::Param {
                    name,
                    value: v,
                    reason,
                })
            }
        };
        check(
            "nominal_radius_left_m",
            self.nominal_radius_left_m,
            0.1,
            2.0,
            "must be a finite radius in (0.1, 2) m",
        )?;
        check(
            "nominal_radius_right_m",
            self.nominal_radius_right_m,
            0.1,
            2.0,
            "must be a finite radius in (0.1, 2) m",
        )?;
        if !(self.contact_zone_depth_m.is_finite()
            && (0.0..1e-3).contains(&self.contact_zone_depth_m))
        {
            return Err(ContactError::Param {
                name: "contact_zone_depth_m",
                value: self.contact_zone_depth_m,
                reason: "must be a finite depth in [0, 1e-3) m",
            });
        }
        check(
            "rail_inclination",
            self.rail_inclination,
            -0.2,
            0.2,
            "must be a finite tangent in (-0.2, 0.2)",
        )?;
        match self.wheel_placement {
            WheelPlacement::RollingCircleDistance { distance_m } => check(
                "wheel_placement.distance_m",
                distance_m,
                0.3,
                3.0,
                "must be in (0.3, 3) m",
            )?,
            WheelPlacement::BackToBack {
                back_to_back_m,
                back_face_to_origin_m,
            } => {
                check(
                    "wheel_placement.back_to_back_m",
                    back_to_back_m,
                    0.3,
                    3.0,
                    "must be in (0.3, 3) m",
                )?;
                check(
                    "wheel_placement.back_face_to_origin_m",
                    back_face_to_origin_m,
                    0.0,
                    0.3,
                    "must be in (0, 0.3) m",
                )?;
            }
            WheelPlacement::FlangeFaces {
                distance_m,
                measuring_depth_m,
            } => {
                check(
                    "wheel_placement.distance_m",
                    distance_m,
                    0.3,
                    3.0,
                    "must be in (0.3, 3) m",
                )?;
                check(
                    "wheel_placement.measuring_depth_m",
                    measuring_depth_m,
                    0.0,
                    0.05,
                    "must be in (0, 0.05) m",
                )?;
            }
        }
        match self.rail_placement {
            RailPlacement::Gauge {
                gauge_m,
                measuring_depth_m,
            } => {
                check(
                    "rail_placement.gauge_m",
                    gauge_m,
                    0.3,
                    3.0,
                    "must be in (0.3, 3) m",
                )?;
                check(
                    "rail_placement.measuring_depth_m",
                    measuring_depth_m,
                    0.0,
                    0.05,
                    "must be in (0, 0.05) m",
                )?;
            }
            RailPlacement::OriginDistance { distance_m } => check(
                "rail_placement.distance_m",
                distance_m,
                0.3,
                3.0,
                "must be in (0.3, 3) m",
            )?,
        }
        Ok(())
    }
}
