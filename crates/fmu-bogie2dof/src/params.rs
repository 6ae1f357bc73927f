//! Parameters of the 2-dof bogie (SI units), their sources and validation.
//!
//! Sources (numbers carried over, see `/work/shared/REFERENCE.md`):
//! * seed thesis, section 5.3 and 4.2: wheelbase 2.5 m, bogie mass 6.1 t including the
//!   wheelsets (EN 14363 limit a_lim = 5.39 m/s^2 = (12 - m/5)/2  =>  m = 6.1 t);
//! * Manchester Benchmark passenger vehicle (Iwnicki 1998, VSD suppl. 31): wheel radius 0.46 m,
//!   wheelset mass 1813 kg, wheelset yaw inertia 1120 kg m^2, spin inertia 112 kg m^2,
//!   frame yaw inertia 3067 kg m^2, secondary lateral stiffness 160 kN/m per side;
//! * Mathematical Problems in Engineering 2019 ("Numerical investigation into the critical
//!   speed and frequency of the hunting motion ...", Table 2): half contact gauge 0.7465 m,
//!   half wheelbase 1.25 m, yaw damper lateral arm 1.35 m;
//! * Hertz + Kalker (see [`wheel_rail::creep::hertz_kalker`]) at 70 kN per wheel on a 0.46 m wheel
//!   and a 0.30 m rail crown: f11 = 11.5 MN, f22 = 10.4 MN.
//!
//! Calibrated (free) parameters, see [`crate::calibration`]: `k_ssx_n_per_m` (effective
//! longitudinal secondary stiffness per side at arm b: air spring + mountings, WITHOUT the yaw
//! damper, whose elastic part comes with the damper representation), `creep_reduction`
//! (Kalker reduction factor, Polach 2005), and the contact geometry: the default table is the
//! worn-profile surrogate (the A/A table with a 0.25 cone on the central +-3.5 mm of the
//! tread); `conicity` and `gravity_stiffness_n_per_m` of the linear model are its
//! describing-function values at 1 mm amplitude, so both models see the same contact at small
//! amplitude. The calibrated values are the `CALIBRATED_*` / `WORN_SURROGATE_*` constants
//! below (this module imports no other module of the crate).

use serde::{Deserialize, Serialize};
use vehicle_elements::{finite, in_range, non_negative, positive};

pub use vehicle_elements::ParamError;

// Calibrated values: the defaults below use them; the procedure that produced them and its
// reasoning are in the calibration module.

/// Tread conicity of the worn-profile surrogate [-] (see [`crate::calibration`]).
pub const WORN_SURROGATE_CONICITY: f64 = 0.25;
/// Half-width of the coned tread of the surrogate; the A/A flange rise is kept beyond \[m\].
pub const WORN_SURROGATE_TREAD_HALF_WIDTH_M: f64 = 3.5e-3;
/// Amplitude at which the linear model's conicity and gravity stiffness are taken \[m\].
pub const LINEARISATION_AMPLITUDE_M: f64 = 1e-3;
/// Equivalent conicity of the default table at 1 mm (describing function) [-].
pub const CALIBRATED_CONICITY: f64 = 0.25;
/// Gravitational stiffness per wheelset of the default table at 1 mm, P = 70 kN [N/m].
pub const CALIBRATED_GRAVITY_STIFFNESS_N_PER_M: f64 = 2.022e6;
/// Kalker creep-coefficient reduction factor [-].
pub const CALIBRATED_CREEP_REDUCTION: f64 = 0.6;
/// k_ssx calibrated for 270 km/h with the Maxwell passive damper [N/m per side].
pub const CALIBRATED_K_SSX_N_PER_M: f64 = 0.390e6;
/// Wheel/rail friction coefficient [-] (dry rail 0.3-0.4).
pub const CALIBRATED_FRICTION: f64 = 0.35;

vehicle_elements::force_law_enum!(
    "(5.1)-(5.18): Kalker linear creep, constant conicity and gravitational stiffness",
    "(5.19)-(5.27): contact table, Vermeulen-Johnson saturation, wheelset spin dofs"
);

pub use wheel_rail::track::{PsdLevel, TrackSource};

/// Which wheel/rail contact table the non-linear model uses.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum ContactSource {
    /// DEFAULT: worn-profile surrogate, the A/A table with a 0.25 cone on the central
    /// +-3.5 mm of the tread and the A/A rise beyond (equivalent conicity 0.25 up to 3.5 mm,
    /// 0.38 at 6 mm), contact angles kept; `resources/wheel_rail_worn_surrogate.csv`. See
    /// [`crate::calibration`] for why.
    #[default]
    WornSurrogate,
    /// Built-in table of EN 15302 profiles A/A (wheel A on rail A, 1435 mm gauge),
    /// `resources/wheel_rail_A_A.csv`, computed by the `wheel-rail` crate.
    ProfilesAA,
    /// Synthetic cone of `conicity` with a steep flange at 7 mm (the profile with which R7
    /// is reproduced, see `calibration`).
    SyntheticCone,
    /// CSV file at run time (format in [`wheel_rail::table`]).
    File(String),
}

impl ContactSource {
    /// Mapping of an FMU string parameter: "" or "worn" -> WornSurrogate, "AA" ->
    /// ProfilesAA, "synthetic" -> SyntheticCone, anything else is a file path.
    pub fn from_path_str(s: &str) -> Self {
        match s.trim() {
            "" | "worn" => ContactSource::WornSurrogate,
            "AA" => ContactSource::ProfilesAA,
            "synthetic" => ContactSource::SyntheticCone,
            p => ContactSource::File(p.to_string()),
        }
    }
}

/// All parameters of the bogie model (SI units).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Params {
    /// Running speed V [m/s].
    pub speed_mps: f64,
    /// Linear or non-linear wheel/rail forces.
    pub model: ModelKind,
    /// m: bogie frame + two wheelsets \[kg\]. Seed 4.2: a_lim = 5.39 m/s^2 -> 6.1 t.
    pub bogie_mass_kg: f64,
    /// J: yaw inertia of frame + wheelsets about the bogie centre [kg m^2].
    /// Manchester Benchmark: 3067 + 2*(1120 + 1813*1.25^2) = 10 973 kg m^2.
    pub bogie_yaw_inertia_kgm2: f64,
    /// J_w: spin inertia of one wheelset about its axle [kg m^2] (Manchester: 112).
    pub wheelset_spin_inertia_kgm2: f64,
    /// p: half wheelbase \[m\] (seed Table 4-1: wheelbase 2.5 m).
    pub half_wheelbase_m: f64,
    /// s: half distance between the contact points \[m\] (MPE 2019: 0.7465 m).
    pub half_contact_gauge_m: f64,
    /// b: lateral arm of the yaw dampers and of k_ssx \[m\] (MPE 2019: 1.35 m).
    pub damper_arm_m: f64,
    /// R0: nominal rolling radius \[m\] (Manchester: 0.46 m).
    pub wheel_radius_m: f64,
    /// k_ssy: secondary lateral stiffness per side [N/m] (Manchester: 160 kN/m).
    pub k_ssy_n_per_m: f64,
    /// k_ssx: effective longitudinal secondary stiffness per side at arm b [N/m]
    /// (air spring + traction/damper mountings, without the yaw damper). CALIBRATED, see
    /// [`crate::calibration`].
    pub k_ssx_n_per_m: f64,
    /// lambda: equivalent conicity of the linear model [-]. CALIBRATED.
    pub conicity: f64,
    /// Lateral gravitational (contact-angle) stiffness per wheelset used by the LINEAR model
    /// [N/m]: P d(tan g_R - tan g_L)/dy of the table (describing function at 1 mm, see
    /// [`wheel_rail::GeometryTable::linearise`]). Not in the seed's (5.18); included here
    /// because the non-linear model (5.20) has it through the contact angles.
    pub gravity_stiffness_n_per_m: f64,
    /// f11: Kalker longitudinal creep coefficient per wheel \[N\] (Hertz+Kalker: 11.5 MN).
    pub f11_n: f64,
    /// f22: Kalker lateral creep coefficient per wheel \[N\] (Hertz+Kalker: 10.4 MN).
    pub f22_n: f64,
    /// kappa: reduction factor applied to f11 and f22 in both models (0, 1]. Measured initial
    /// creep slopes are lower than Kalker's theory; Polach (2005, Wear 258) uses reduction
    /// factors of about 0.3-1 (0.5-1 for dry rail). CALIBRATED: 0.6.
    pub creep_reduction: f64,
    /// P: vertical load per wheel \[N\] (~140 kN per wheelset; Table 4-1's 27.52 kN is
    /// implausible, see REFERENCE.md).
    pub wheel_load_n: f64,
    /// mu: wheel/rail friction coefficient (0..1], dry rail 0.3-0.4.
    pub friction_coefficient: f64,
    /// Initial lateral displacement of the bogie centre \[m\].
    pub initial_lateral_m: f64,
    /// Initial yaw angle sigma (positive nose-left) \[rad\].
    pub initial_yaw_rad: f64,
    /// Track alignment source.
    pub track: TrackSource,
    /// Wheel/rail contact table of the non-linear model.
    pub contact: ContactSource,
}

impl Default for Params {
    fn default() -> Self {
        Self {
            speed_mps: 250.0 / 3.6,
            model: ModelKind::NonLinear,
            bogie_mass_kg: 6100.0,
            bogie_yaw_inertia_kgm2: 11_000.0, // Manchester: 10 973, rounded
            wheelset_spin_inertia_kgm2: 112.0,
            half_wheelbase_m: 1.25,
            half_contact_gauge_m: 0.7465,
            damper_arm_m: 1.35,
            wheel_radius_m: 0.46,
            k_ssy_n_per_m: 160e3,
            k_ssx_n_per_m: CALIBRATED_K_SSX_N_PER_M,
            conicity: CALIBRATED_CONICITY,
            gravity_stiffness_n_per_m: CALIBRATED_GRAVITY_STIFFNESS_N_PER_M,
            f11_n: 11.5e6,
            f22_n: 10.4e6,
            creep_reduction: CALIBRATED_CREEP_REDUCTION,
            wheel_load_n: 70e3,
            friction_coefficient: CALIBRATED_FRICTION,
            initial_lateral_m: 0.0,
            initial_yaw_rad: 0.0,
            track: TrackSource::External,
            contact: ContactSource::WornSurrogate,
        }
    }
}

impl Params {
    /// Checks every field; the error names the first offending parameter.
    pub fn validate(&self) -> Result<(), ParamError> {
        // Creepages are divided by V: a standing vehicle has no creep model.
        positive("speed_mps", self.speed_mps)?;
        if self.speed_mps > 200.0 {
            return Err(ParamError::new(
                "speed_mps",
                format!(
                    "{} m/s is beyond any rail vehicle (max 200)",
                    self.speed_mps
                ),
            ));
        }
        positive("bogie_mass_kg", self.bogie_mass_kg)?;
        positive("bogie_yaw_inertia_kgm2", self.bogie_yaw_inertia_kgm2)?;
        positive(
            "wheelset_spin_inertia_kgm2",
            self.wheelset_spin_inertia_kgm2,
        )?;
        positive("half_wheelbase_m", self.half_wheelbase_m)?;
        // the coach's ranges (fmu-vehicle): a rail wheel, a standard or broad gauge
        in_range(
            "half_contact_gauge_m",
            self.half_contact_gauge_m,
            0.3,
            1.0,
            "rail gauges",
        )?;
        positive("damper_arm_m", self.damper_arm_m)?;
        in_range(
            "wheel_radius_m",
            self.wheel_radius_m,
            0.2,
            0.8,
            "rail wheels",
        )?;
        non_negative("k_ssy_n_per_m", self.k_ssy_n_per_m)?;
        non_negative("k_ssx_n_per_m", self.k_ssx_n_per_m)?;
        non_negative("conicity", self.conicity)?;
        if self.conicity > 1.0 {
            return Err(ParamError::new("conicity", "must be <= 1"));
        }
        non_negative("gravity_stiffness_n_per_m", self.gravity_stiffness_n_per_m)?;
        positive("f11_n", self.f11_n)?;
        positive("f22_n", self.f22_n)?;
        positive("creep_reduction", self.creep_reduction)?;
        if self.creep_reduction > 1.0 {
            return Err(ParamError::new(
                "creep_reduction",
                format!("must be in (0, 1], got {}", self.creep_reduction),
            ));
        }
        positive("wheel_load_n", self.wheel_load_n)?;
        finite("friction_coefficient", self.friction_coefficient)?;
        if !(self.friction_coefficient > 0.0 && self.friction_coefficient <= 1.0) {
            return Err(ParamError::new(
                "friction_coefficient",
                format!("must be in (0, 1], got {}", self.friction_coefficient),
            ));
        }
        finite("initial_lateral_m", self.initial_lateral_m)?;
        if self.initial_lateral_m.abs() > 0.05 {
            return Err(ParamError::new(
                "initial_lateral_m",
                "must be within +-0.05 m (wheelset would be off the rails)",
            ));
        }
        finite("initial_yaw_rad", self.initial_yaw_rad)?;
        if self.initial_yaw_rad.abs() > 0.05 {
            return Err(ParamError::new(
                "initial_yaw_rad",
                "must be within +-0.05 rad (small-angle model)",
            ));
        }
        if let ContactSource::File(p) = &self.contact {
            if p.trim().is_empty() {
                return Err(ParamError::new("contact", "empty contact table path"));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The default creep coefficients are the Hertz + Kalker values of the module docs.
    #[test]
    fn default_creep_coefficients_come_from_hertz_kalker() {
        let p = Params::default();
        let hk = wheel_rail::hertz_kalker(p.wheel_load_n, p.wheel_radius_m, 0.3, 210e9, 0.28);
        assert!((p.f11_n - hk.f11_n).abs() / hk.f11_n < 0.02, "{hk:?}");
        assert!((p.f22_n - hk.f22_n).abs() / hk.f22_n < 0.02, "{hk:?}");
    }
}
