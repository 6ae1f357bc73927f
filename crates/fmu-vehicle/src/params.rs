//! Parameters of the coach (SI units), their sources and validation.
//!
//! # Sources
//! * **Manchester Benchmark passenger vehicle** (S. Iwnicki (ed.), "The Manchester Benchmarks for
//!   Rail Vehicle Simulation", Vehicle System Dynamics 30 (3-4), 1998, 295-313,
//!   doi:10.1080/00423119808969454; values as transcribed in public parameter sets of the
//!   benchmark): masses and inertias of car body, frames and wheelsets, heights of the centres of
//!   gravity, primary suspension per axle box, secondary suspension per side, anti-roll bar,
//!   lateral semi-spacings of the suspensions, wheel radius. Marked `[MB]` below.
//! * **The seed** (Table 4-1, 4.2): wheelbase 2.5 m (MB: 2.56 m), 17.5 m between bogie centres
//!   (MB: 19 m), bogie mass 6.1 t with its wheelsets (from a_lim = 5.39 m/s^2), so the frame mass
//!   is 6100 - 2 x 1813 = 2474 kg (MB: 2615 kg). Marked `[seed]`.
//! * **The same physical things as the 2-dof bogie** (fmu-bogie2dof, numbers carried over, not
//!   imported): half contact gauge 0.7465 m and yaw-damper lateral arm 1.35 m (Mathematical
//!   Problems in Engineering 2019, Table 2), Kalker coefficients from Hertz contact of the
//!   0.46 m wheel on a 0.30 m rail crown, creep reduction factor 0.6 (Polach 2005), friction
//!   0.35, the worn-profile surrogate contact table and its 1 mm linearisation. Marked `[bogie]`.
//! * **Calibrated** (the one parameter the seed says its coach has differently, see
//!   [`crate::calibration`]): a common factor on the benchmark's primary longitudinal and
//!   lateral stiffness, for R15.
//! * **Not in any data set, chosen here**: the comfort measuring height (car-body floor), the
//!   height of the secondary lateral damper (taken at the air-spring height). Marked `[chosen]`.
//!
//! The static wheel load follows from the masses (P = g m_total / 8 = 54.2 kN; the bogie uses
//! 70 kN for its own, heavier, axle load), and the Kalker coefficients scale with it as
//! P^(2/3) (Hertz: a, b ~ P^(1/3) at fixed curvatures, C11, C22 depend on b/a only), so the
//! vehicle carries the bogie's wheel/rail contact at its own load.

use serde::{Deserialize, Serialize};
use vehicle_elements::{finite, in_range, non_negative, positive};

pub use vehicle_elements::ParamError;

// Calibrated values the defaults below take; the procedure that produced them and its reasoning
// are in the calibration module.

/// Equivalent conicity of the worn-profile surrogate at 1 mm amplitude [-].
pub const TABLE_CONICITY_1MM: f64 = 0.25;
/// Gravitational stiffness per wheelset of the surrogate at 1 mm divided by the wheel load
/// [1/m] (the bogie: 2.022 MN/m at 70 kN).
pub const TABLE_GRAVITY_STIFFNESS_PER_LOAD_1MM: f64 = 2.022e6 / 70e3;
/// Kalker reduction factor kappa [-].
pub const CREEP_REDUCTION: f64 = 0.6;
/// Wheel/rail friction coefficient [-].
pub const FRICTION_COEFFICIENT: f64 = 0.35;
/// Manchester Benchmark primary longitudinal stiffness per axle box [N/m].
pub const MB_PRIMARY_KX_N_PER_M: f64 = 31.391e6;
/// Manchester Benchmark primary lateral stiffness per axle box [N/m].
pub const MB_PRIMARY_KY_N_PER_M: f64 = 3.884e6;
/// Factor on the benchmark's primary longitudinal and lateral stiffness, calibrated for R15.
pub const PRIMARY_STIFFNESS_FACTOR: f64 = 3.15;
/// Largest RK4 sub-step of the time-domain model \[s\].
pub const SOLVER_SUBSTEP_S: f64 = 1e-3;

/// Standard gravity [m/s^2].
pub const STANDARD_GRAVITY_MPS2: f64 = 9.81;

/// Static wheel load of the 2-dof bogie's calibration \[N\] (its Kalker coefficients are taken
/// there).
pub const BOGIE_WHEEL_LOAD_N: f64 = 70e3;
/// Kalker f11 at [`BOGIE_WHEEL_LOAD_N`] (Hertz + Kalker, as the bogie) \[N\].
pub const BOGIE_F11_N: f64 = 11.5e6;
/// Kalker f22 at [`BOGIE_WHEEL_LOAD_N`] \[N\].
pub const BOGIE_F22_N: f64 = 10.4e6;

vehicle_elements::force_law_enum!(
    "Kalker linear creep, constant conicity and gravitational stiffness, no spin dofs",
    "Contact table, Vermeulen-Johnson saturation, flange contact, wheelset spin dofs"
);

pub use wheel_rail::track::{PsdLevel, TrackSource};

/// Car body \[MB\].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CarBody {
    /// Mass \[kg\] (MB 32 000).
    pub mass_kg: f64,
    /// Roll inertia about the centre of gravity [kg m^2] (MB 56 800).
    pub roll_inertia_kgm2: f64,
    /// Yaw inertia [kg m^2] (MB 1 970 000).
    pub yaw_inertia_kgm2: f64,
    /// Height of the centre of gravity above the rail \[m\] (MB 1.8).
    pub cg_height_m: f64,
    /// Height above the rail of the comfort measuring points (floor) \[m\] \[chosen\] 1.2.
    pub floor_height_m: f64,
}

/// One bogie frame (both identical).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Frame {
    /// Mass \[kg\] \[seed\] 2474 (6.1 t bogie; MB 2615).
    pub mass_kg: f64,
    /// Roll inertia [kg m^2] (MB 1722).
    pub roll_inertia_kgm2: f64,
    /// Yaw inertia [kg m^2] (MB 3067).
    pub yaw_inertia_kgm2: f64,
    /// Height of the centre of gravity above the rail \[m\] (MB 0.6).
    pub cg_height_m: f64,
}

/// One wheelset (all four identical).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Wheelset {
    /// Mass \[kg\] (MB 1813).
    pub mass_kg: f64,
    /// Yaw inertia [kg m^2] (MB 1120).
    pub yaw_inertia_kgm2: f64,
    /// Spin inertia about the axle [kg m^2] (MB 112).
    pub spin_inertia_kgm2: f64,
    /// Nominal rolling radius r0 \[m\] (MB 0.46); the axle is at this height.
    pub wheel_radius_m: f64,
    /// Half distance between the contact points s \[m\] \[bogie\] 0.7465.
    pub half_contact_gauge_m: f64,
}

/// Longitudinal geometry and lateral arms.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Geometry {
    /// a: half distance between the bogie centres \[m\] \[seed\] 8.75.
    pub half_bogie_spacing_m: f64,
    /// p: half wheelbase \[m\] \[seed\] 1.25.
    pub half_wheelbase_m: f64,
    /// Lateral semi-spacing of the primary springs (axle boxes) \[m\] (MB 1.0).
    pub primary_half_spacing_m: f64,
    /// Lateral semi-spacing of the air springs \[m\] (MB 1.0).
    pub secondary_half_spacing_m: f64,
    /// b: lateral arm of the yaw dampers \[m\] \[bogie\] 1.35.
    pub damper_arm_m: f64,
    /// Height of the air springs' force plane above the rail \[m\] (MB 0.8275).
    pub secondary_height_m: f64,
    /// Height of the secondary lateral dampers \[m\] \[chosen\] = air-spring height.
    pub lateral_damper_height_m: f64,
}

/// Primary suspension, per axle box (between wheelset and frame, at axle height).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Primary {
    /// Longitudinal stiffness [N/m] (MB 31.391e6 times the calibrated factor, see
    /// [`crate::calibration`]).
    pub kx_n_per_m: f64,
    /// Lateral stiffness [N/m] (MB 3.884e6 times the same factor).
    pub ky_n_per_m: f64,
    /// Vertical stiffness [N/m] (MB 1.22e6).
    pub kz_n_per_m: f64,
    /// Longitudinal damping [N s/m] (MB 15e3).
    pub cx_ns_per_m: f64,
    /// Lateral damping [N s/m] (MB 2e3).
    pub cy_ns_per_m: f64,
    /// Vertical damping [N s/m] (MB 4e3).
    pub cz_ns_per_m: f64,
}

/// Secondary suspension, per side of a bogie (air spring, lateral damper) and per bogie
/// (anti-roll bar).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Secondary {
    /// Air-spring longitudinal stiffness [N/m] (MB 160e3).
    pub kx_n_per_m: f64,
    /// Air-spring lateral stiffness [N/m] (MB 160e3).
    pub ky_n_per_m: f64,
    /// Air-spring vertical stiffness [N/m] (MB 430e3).
    pub kz_n_per_m: f64,
    /// Vertical damping [N s/m] (MB 20e3).
    pub cz_ns_per_m: f64,
    /// Lateral damper [N s/m] (MB 32e3).
    pub lateral_damping_ns_per_m: f64,
    /// Air-spring torsional (yaw) stiffness [N m/rad] (MB 10.5e3).
    pub yaw_stiffness_nm_per_rad: f64,
    /// Anti-roll bar per bogie, on the car-body/frame relative roll [N m/rad] (MB 940e3);
    /// 0 = none.
    pub anti_roll_bar_nm_per_rad: f64,
}

/// Wheel/rail contact \[bogie\].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WheelRail {
    /// lambda: equivalent conicity of the linear model [-] (the default table at 1 mm).
    pub conicity: f64,
    /// Lateral gravitational (contact-angle) stiffness per wheelset of the linear model [N/m]
    /// (the default table at 1 mm, times the wheel load).
    pub gravity_stiffness_n_per_m: f64,
    /// f11 per wheel \[N\] (Hertz + Kalker, scaled to the wheel load).
    pub f11_n: f64,
    /// f22 per wheel \[N\].
    pub f22_n: f64,
    /// kappa: reduction factor on f11, f22 in (0, 1] [-] (0.6, Polach 2005).
    pub creep_reduction: f64,
    /// P: static vertical load per wheel \[N\] (weight of the coach / 8).
    pub wheel_load_n: f64,
    /// mu: friction coefficient in (0, 1] (0.35).
    pub friction_coefficient: f64,
}

/// Initial condition: both bogies (frames and wheelsets) displaced and yawed, car body at rest.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Initial {
    /// Lateral displacement of both bogies \[m\].
    pub lateral_m: f64,
    /// Yaw angle of both bogies, positive nose-left \[rad\].
    pub yaw_rad: f64,
}

/// Which wheel/rail contact table the non-linear model uses.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum ContactSource {
    /// Worn-profile surrogate shipped with the crate (the 2-dof bogie's default table).
    #[default]
    WornSurrogate,
    /// CSV file in the wheel-rail table format, read at construction.
    File(String),
}

/// All parameters of the coach (SI units).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VehicleParams {
    /// Running speed V [m/s].
    pub speed_mps: f64,
    /// Linear or non-linear wheel/rail forces.
    pub model: ModelKind,
    /// Car body.
    pub carbody: CarBody,
    /// Bogie frames.
    pub frame: Frame,
    /// Wheelsets.
    pub wheelset: Wheelset,
    /// Geometry.
    pub geometry: Geometry,
    /// Primary suspension per axle box.
    pub primary: Primary,
    /// Secondary suspension per side.
    pub secondary: Secondary,
    /// Wheel/rail contact.
    pub wheel_rail: WheelRail,
    /// g [m/s^2]: gravitational roll terms of the suspended bodies (0 switches them off).
    pub gravity_mps2: f64,
    /// Initial condition.
    pub initial: Initial,
    /// Track alignment source.
    pub track: TrackSource,
    /// Contact table of the non-linear model.
    pub contact: ContactSource,
    /// Largest internal integration sub-step \[s\] (RK4; see the convergence study in
    /// [`crate::calibration`]).
    pub solver_substep_s: f64,
}

impl VehicleParams {
    /// Total mass of the coach \[kg\].
    pub fn total_mass_kg(&self) -> f64 {
        self.carbody.mass_kg + 2.0 * self.frame.mass_kg + 4.0 * self.wheelset.mass_kg
    }

    /// Mass of one bogie with its two wheelsets \[kg\] (the EN 14363 a_lim mass).
    pub fn bogie_mass_kg(&self) -> f64 {
        self.frame.mass_kg + 2.0 * self.wheelset.mass_kg
    }

    /// Static wheel load the masses give, g m_total / 8 \[N\].
    pub fn wheel_load_from_masses_n(&self) -> f64 {
        STANDARD_GRAVITY_MPS2 * self.total_mass_kg() / 8.0
    }

    /// The wheel/rail quantities that follow the wheel load, from the masses: the load
    /// g m_total / 8, the Kalker coefficients scaled to it from the bogie's (P^(2/3)) and the
    /// linear model's gravitational stiffness (the default table's at 1 mm, per newton of
    /// load); conicity, creep reduction and friction as they stand.
    pub fn wheel_rail_from_masses(&self) -> WheelRail {
        let load = self.wheel_load_from_masses_n();
        WheelRail {
            gravity_stiffness_n_per_m: TABLE_GRAVITY_STIFFNESS_PER_LOAD_1MM * load,
            f11_n: scale_creep_coefficient(BOGIE_F11_N, BOGIE_WHEEL_LOAD_N, load),
            f22_n: scale_creep_coefficient(BOGIE_F22_N, BOGIE_WHEEL_LOAD_N, load),
            wheel_load_n: load,
            ..self.wheel_rail.clone()
        }
    }
}

/// Kalker coefficient at wheel load `load_n` from its value `f_ref` at `load_ref_n` (Hertz
/// scaling P^(2/3)).
pub fn scale_creep_coefficient(f_ref: f64, load_ref_n: f64, load_n: f64) -> f64 {
    f_ref * (load_n / load_ref_n).powf(2.0 / 3.0)
}

impl Default for VehicleParams {
    fn default() -> Self {
        let carbody = CarBody {
            mass_kg: 32_000.0,
            roll_inertia_kgm2: 56_800.0,
            yaw_inertia_kgm2: 1.97e6,
            cg_height_m: 1.8,
            floor_height_m: 1.2,
        };
        let frame = Frame {
            mass_kg: 2474.0,
            roll_inertia_kgm2: 1722.0,
            yaw_inertia_kgm2: 3067.0,
            cg_height_m: 0.6,
        };
        let wheelset = Wheelset {
            mass_kg: 1813.0,
            yaw_inertia_kgm2: 1120.0,
            spin_inertia_kgm2: 112.0,
            wheel_radius_m: 0.46,
            half_contact_gauge_m: 0.7465,
        };
        let params = Self {
            speed_mps: 250.0 / 3.6,
            model: ModelKind::NonLinear,
            carbody,
            frame,
            wheelset,
            geometry: Geometry {
                half_bogie_spacing_m: 8.75,
                half_wheelbase_m: 1.25,
                primary_half_spacing_m: 1.0,
                secondary_half_spacing_m: 1.0,
                damper_arm_m: 1.35,
                secondary_height_m: 0.8275,
                lateral_damper_height_m: 0.8275,
            },
            primary: Primary {
                kx_n_per_m: PRIMARY_STIFFNESS_FACTOR * MB_PRIMARY_KX_N_PER_M,
                ky_n_per_m: PRIMARY_STIFFNESS_FACTOR * MB_PRIMARY_KY_N_PER_M,
                kz_n_per_m: 1.22e6,
                cx_ns_per_m: 15e3,
                cy_ns_per_m: 2e3,
                cz_ns_per_m: 4e3,
            },
            secondary: Secondary {
                kx_n_per_m: 160e3,
                ky_n_per_m: 160e3,
                kz_n_per_m: 430e3,
                cz_ns_per_m: 20e3,
                lateral_damping_ns_per_m: 32e3,
                yaw_stiffness_nm_per_rad: 10.5e3,
                anti_roll_bar_nm_per_rad: 940e3,
            },
            wheel_rail: WheelRail {
                conicity: TABLE_CONICITY_1MM,
                creep_reduction: CREEP_REDUCTION,
                friction_coefficient: FRICTION_COEFFICIENT,
                // the load and what follows it: from the masses, below
                gravity_stiffness_n_per_m: 0.0,
                f11_n: 0.0,
                f22_n: 0.0,
                wheel_load_n: 0.0,
            },
            gravity_mps2: STANDARD_GRAVITY_MPS2,
            initial: Initial::default(),
            track: TrackSource::None,
            contact: ContactSource::WornSurrogate,
            solver_substep_s: SOLVER_SUBSTEP_S,
        };
        Self {
            wheel_rail: params.wheel_rail_from_masses(),
            ..params
        }
    }
}

impl VehicleParams {
    /// Checks every field; the error names the first offending parameter.
    pub fn validate(&self) -> Result<(), ParamError> {
        // Creepages divide by V: a standing vehicle has no creep model.
        in_range(
            "speed_mps",
            self.speed_mps,
            1.0,
            200.0,
            "creepages divide by V; 200 m/s is beyond any rail vehicle",
        )?;
        let c = &self.carbody;
        positive("carbody.mass_kg", c.mass_kg)?;
        positive("carbody.roll_inertia_kgm2", c.roll_inertia_kgm2)?;
        positive("carbody.yaw_inertia_kgm2", c.yaw_inertia_kgm2)?;
        in_range(
            "carbody.cg_height_m",
            c.cg_height_m,
            0.0,
            6.0,
            "above the rail",
        )?;
        in_range(
            "carbody.floor_height_m",
            c.floor_height_m,
            0.0,
            6.0,
            "above the rail",
        )?;
        let f = &self.frame;
        positive("frame.mass_kg", f.mass_kg)?;
        positive("frame.roll_inertia_kgm2", f.roll_inertia_kgm2)?;
        positive("frame.yaw_inertia_kgm2", f.yaw_inertia_kgm2)?;
        in_range(
            "frame.cg_height_m",
            f.cg_height_m,
            0.0,
            3.0,
            "above the rail",
        )?;
        let w = &self.wheelset;
        positive("wheelset.mass_kg", w.mass_kg)?;
        positive("wheelset.yaw_inertia_kgm2", w.yaw_inertia_kgm2)?;
        positive("wheelset.spin_inertia_kgm2", w.spin_inertia_kgm2)?;
        in_range(
            "wheelset.wheel_radius_m",
            w.wheel_radius_m,
            0.2,
            0.8,
            "rail wheels",
        )?;
        in_range(
            "wheelset.half_contact_gauge_m",
            w.half_contact_gauge_m,
            0.3,
            1.0,
            "half the distance between the contact points of a wheelset",
        )?;
        let g = &self.geometry;
        positive("geometry.half_wheelbase_m", g.half_wheelbase_m)?;
        positive("geometry.half_bogie_spacing_m", g.half_bogie_spacing_m)?;
        if g.half_wheelbase_m > 0.5 * g.half_bogie_spacing_m {
            return Err(ParamError::new(
                "geometry.half_wheelbase_m",
                format!(
                    "the wheelsets do not fit the bogies: {} m must be at most half of \
                     geometry.half_bogie_spacing_m = {} m (the bogies would overlap)",
                    g.half_wheelbase_m, g.half_bogie_spacing_m
                ),
            ));
        }
        positive("geometry.primary_half_spacing_m", g.primary_half_spacing_m)?;
        positive(
            "geometry.secondary_half_spacing_m",
            g.secondary_half_spacing_m,
        )?;
        positive("geometry.damper_arm_m", g.damper_arm_m)?;
        in_range(
            "geometry.secondary_height_m",
            g.secondary_height_m,
            0.0,
            3.0,
            "above the rail",
        )?;
        in_range(
            "geometry.lateral_damper_height_m",
            g.lateral_damper_height_m,
            0.0,
            3.0,
            "above the rail",
        )?;
        let p = &self.primary;
        non_negative("primary.cx_ns_per_m", p.cx_ns_per_m)?;
        non_negative("primary.cy_ns_per_m", p.cy_ns_per_m)?;
        non_negative("primary.cz_ns_per_m", p.cz_ns_per_m)?;
        // Without longitudinal/lateral/vertical primary stiffness a wheelset (or the frame's
        // roll) is not held: the model would have a free body.
        positive("primary.kx_n_per_m", p.kx_n_per_m)?;
        positive("primary.ky_n_per_m", p.ky_n_per_m)?;
        positive("primary.kz_n_per_m", p.kz_n_per_m)?;
        let s = &self.secondary;
        non_negative("secondary.kx_n_per_m", s.kx_n_per_m)?;
        non_negative("secondary.ky_n_per_m", s.ky_n_per_m)?;
        positive("secondary.kz_n_per_m", s.kz_n_per_m)?;
        non_negative("secondary.cz_ns_per_m", s.cz_ns_per_m)?;
        non_negative(
            "secondary.lateral_damping_ns_per_m",
            s.lateral_damping_ns_per_m,
        )?;
        non_negative(
            "secondary.yaw_stiffness_nm_per_rad",
            s.yaw_stiffness_nm_per_rad,
        )?;
        non_negative(
            "secondary.anti_roll_bar_nm_per_rad",
            s.anti_roll_bar_nm_per_rad,
        )?;
        if s.ky_n_per_m == 0.0 {
            return Err(ParamError::new(
                "secondary.ky_n_per_m",
                "must be > 0: without lateral air-spring stiffness the car body is laterally free",
            ));
        }
        if s.kx_n_per_m == 0.0 && s.yaw_stiffness_nm_per_rad == 0.0 {
            return Err(ParamError::new(
                "secondary.kx_n_per_m",
                "must be > 0 (or secondary.yaw_stiffness_nm_per_rad): otherwise the car body yaw is free",
            ));
        }
        let r = &self.wheel_rail;
        in_range(
            "wheel_rail.conicity",
            r.conicity,
            0.0,
            1.0,
            "equivalent conicity",
        )?;
        non_negative(
            "wheel_rail.gravity_stiffness_n_per_m",
            r.gravity_stiffness_n_per_m,
        )?;
        positive("wheel_rail.f11_n", r.f11_n)?;
        positive("wheel_rail.f22_n", r.f22_n)?;
        finite("wheel_rail.creep_reduction", r.creep_reduction)?;
        if !(r.creep_reduction > 0.0 && r.creep_reduction <= 1.0) {
            return Err(ParamError::new(
                "wheel_rail.creep_reduction",
                format!("must be in (0, 1], got {}", r.creep_reduction),
            ));
        }
        positive("wheel_rail.wheel_load_n", r.wheel_load_n)?;
        finite("wheel_rail.friction_coefficient", r.friction_coefficient)?;
        if !(r.friction_coefficient > 0.0 && r.friction_coefficient <= 1.0) {
            return Err(ParamError::new(
                "wheel_rail.friction_coefficient",
                format!("must be in (0, 1], got {}", r.friction_coefficient),
            ));
        }
        in_range("gravity_mps2", self.gravity_mps2, 0.0, 30.0, "gravity")?;
        in_range(
            "initial.lateral_m",
            self.initial.lateral_m,
            -0.03,
            0.03,
            "beyond 30 mm the wheelsets are off the rails",
        )?;
        in_range(
            "initial.yaw_rad",
            self.initial.yaw_rad,
            -0.02,
            0.02,
            "small-angle model",
        )?;
        in_range(
            "solver_substep_s",
            self.solver_substep_s,
            1e-6,
            1e-2,
            "RK4 sub-step",
        )?;
        if let ContactSource::File(path) = &self.contact {
            if path.trim().is_empty() {
                return Err(ParamError::new("contact", "empty contact table path"));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_consistent() {
        let p = VehicleParams::default();
        p.validate().unwrap();
        // 6.1 t bogie (seed a_lim = (12 - m/5)/2 = 5.39 m/s^2)
        assert!((p.bogie_mass_kg() - 6100.0).abs() < 1e-9);
        let a_lim = (12.0 - p.bogie_mass_kg() / 1000.0 / 5.0) / 2.0;
        assert!((a_lim - 5.39).abs() < 0.005, "{a_lim}");
        assert!((p.wheel_rail.wheel_load_n - p.wheel_load_from_masses_n()).abs() < 1e-6);
        assert!((p.wheel_rail.wheel_load_n - 54.2e3).abs() < 0.1e3);
        // Hertz scaling
        let f = scale_creep_coefficient(BOGIE_F11_N, BOGIE_WHEEL_LOAD_N, BOGIE_WHEEL_LOAD_N);
        assert_eq!(f, BOGIE_F11_N);
        assert!(p.wheel_rail.f11_n < BOGIE_F11_N && p.wheel_rail.f11_n > 9e6);
    }

    #[test]
    fn impossible_parameters_name_the_field() {
        type Setter = Box<dyn Fn(&mut VehicleParams)>;
        let cases: Vec<(&str, Setter)> = vec![
            ("carbody.mass_kg", Box::new(|p| p.carbody.mass_kg = -1.0)),
            (
                "frame.yaw_inertia_kgm2",
                Box::new(|p| p.frame.yaw_inertia_kgm2 = 0.0),
            ),
            (
                "primary.kx_n_per_m",
                Box::new(|p| p.primary.kx_n_per_m = -5.0),
            ),
            (
                "secondary.ky_n_per_m",
                Box::new(|p| p.secondary.ky_n_per_m = f64::NAN),
            ),
            (
                "geometry.half_wheelbase_m",
                Box::new(|p| p.geometry.half_wheelbase_m = 5.0),
            ),
            ("speed_mps", Box::new(|p| p.speed_mps = 0.0)),
            (
                "wheel_rail.creep_reduction",
                Box::new(|p| p.wheel_rail.creep_reduction = 1.5),
            ),
            ("initial.lateral_m", Box::new(|p| p.initial.lateral_m = 0.1)),
        ];
        for (name, set) in cases {
            let mut p = VehicleParams::default();
            set(&mut p);
            let e = p.validate().unwrap_err();
            assert_eq!(e.name, name, "{e}");
            assert!(e.to_string().contains(name));
        }
    }
}
