//! FMI 2.0 co-simulation shell `RailVehicle` over the coach physics ([`crate::model::Vehicle`]).
//! Thin: parameters map onto [`VehicleParams`], inputs onto [`Inputs`], outputs come from
//! [`Outputs`]; the FMI machinery is in `model-description`.

use std::path::PathBuf;

use model_description::{
    field_error, DefaultExperiment, Diagnostics, FieldError, FmuModel, InstanceContext, ModelError,
    ModelInfo, StepError, Variable,
};
use serde::{Deserialize, Serialize};
use vehicle_elements::{resource_or_given, Shell, TooStiff, TrackSetting};

use crate::model::{Inputs, ModelError as PhysicsModelError, Outputs, StepError as PStep, Vehicle};
use crate::params::{ContactSource, Initial, VehicleParams};

/// Speed of the FMU's start values (default experiment: hunting into flange contact) [m/s].
pub const FMU_DEFAULT_SPEED_MPS: f64 = 300.0 / 3.6;
/// Initial lateral displacement of both bogies in the FMU's start values \[m\].
pub const FMU_DEFAULT_INITIAL_LATERAL_M: f64 = 3e-3;

// The FMI Enumeration `TrackSource`, with where this model applies the external input.
vehicle_elements::track_choice_enum!(
    "The input track.lateral_alignment under the leading wheelset (the others see it delayed by their distance over V)"
);

/// The physics fields the FMU calculates from the masses ([`VehicleParams::wheel_rail_from_masses`]).
const FROM_THE_MASSES: [&str; 4] = [
    "wheel_rail.wheel_load_n",
    "wheel_rail.f11_n",
    "wheel_rail.f22_n",
    "wheel_rail.gravity_stiffness_n_per_m",
];

/// Whether a too-stiff error is about a field calculated from the masses.
fn from_the_masses(e: &TooStiff) -> bool {
    e.parameter
        .as_deref()
        .is_some_and(|p| FROM_THE_MASSES.contains(&p))
}

impl FieldError for PhysicsModelError {
    fn field(&self) -> Option<&str> {
        match self {
            PhysicsModelError::Param(p) => p.field(),
            // The contact table is the shell's field `contact`.
            PhysicsModelError::Table(_) | PhysicsModelError::FlangeNotCovered(_) => Some("contact"),
            // the load and what follows it are calculated parameters of the masses
            PhysicsModelError::TooStiff(e) if from_the_masses(e) => Some("wheelset.wheel_load"),
            PhysicsModelError::TooStiff(e) => e.parameter.as_deref(),
            // the message names every parameter that holds the bodies upright
            PhysicsModelError::StaticallyUnstable { parameter, .. } => {
                Some(parameter.as_deref().unwrap_or("carbody.cg_height_m"))
            }
            PhysicsModelError::StartsDerailed { .. } => Some("initial.lateral_m"),
        }
    }

    fn reason(&self) -> String {
        match self {
            PhysicsModelError::Param(p) => p.reason(),
            PhysicsModelError::TooStiff(e) if from_the_masses(e) => {
                format!(
                    "{} (the wheel load and the creep coefficients follow carbody.mass, \
                     frame.mass and wheelset.mass)",
                    e.reason()
                )
            }
            PhysicsModelError::TooStiff(e) => e.reason(),
            other => other.to_string(),
        }
    }
}

// The physics as the shell core drives it.
vehicle_elements::shell_physics!(
    Vehicle: VehicleParams, Inputs, Outputs, PhysicsModelError, PStep, ContactSource
);

/// The coach FMU: parameters, current inputs, the physics (built at initialisation) and its
/// last outputs (the last three in [`Shell`]).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RailVehicle {
    params: VehicleParams,
    track: TrackSetting<TrackChoice>,
    /// The contact-table parameter as set: a keyword or a file (see [`Self::contact_source`]).
    contact: String,
    resource_dir: Option<PathBuf>,
    shell: Shell<Vehicle>,
}

impl RailVehicle {
    /// Outputs (read-only view, for tests and tools).
    pub fn outputs(&self) -> &Outputs {
        &self.shell.out
    }

    /// The contact-table parameter resolved: "" or "worn" is the built-in table, a relative
    /// file name is looked up under the FMU's resources/ folder first, then taken as given.
    fn contact_source(&self) -> ContactSource {
        match self.contact.trim() {
            "" | "worn" => ContactSource::WornSurrogate,
            p => ContactSource::File(resource_or_given(p, self.resource_dir.as_deref())),
        }
    }

    fn build_params(&self) -> VehicleParams {
        VehicleParams {
            track: self.track.source(),
            contact: self.contact_source(),
            wheel_rail: self.params.wheel_rail_from_masses(),
            ..self.params.clone()
        }
    }
}

const FT_DAMPERS: &[&str] = &[
    "damper_front_left.force",
    "damper_front_right.force",
    "damper_rear_left.force",
    "damper_rear_right.force",
];
const FT_TRACK: &[&str] = &["track.lateral_alignment"];

impl FmuModel for RailVehicle {
    const MAX_COMMUNICATION_STEP_S: f64 = vehicle_elements::MAX_HOST_STEP_S;

    const INFO: ModelInfo = ModelInfo {
        name: "RailVehicle",
        description: "Lateral dynamics of a bogie coach on straight track (car body, two bogie \
                      frames, four wheelsets; Manchester Benchmark data calibrated to the seed's \
                      coach): linear or non-linear wheel/rail forces; takes the four yaw damper \
                      forces, gives their elongations, the attachment points' motion, the \
                      EN 14363 frame accelerations and the car-body comfort accelerations",
        author: "rail-fmu project (fmu-vehicle)",
        version: "0.1.0",
        default_experiment: DefaultExperiment {
            start_time: 0.0,
            stop_time: 5.0,
            step_size: 1e-3,
        },
        documentation_html: DOC,
        resources: &[(
            "wheel_rail_worn_surrogate.csv",
            include_bytes!("../resources/wheel_rail_worn_surrogate.csv"),
        )],
    };

    fn variables() -> Vec<Variable<Self>> {
        let mut v: Vec<Variable<Self>> = Vec::new();
        model_description::declare! { v;
            /// Running speed V (> 0: the creepages divide by V)
            parameter "running.speed" [unit = "m/s", display_unit = "km/h", range = 1.0..=200.0] => params.speed_mps;
            /// Wheel/rail force law: linear (Kalker, constant conicity and gravitational stiffness, the
            /// seed's (5.1)-(5.18) per wheelset) or non-linear (contact table, Vermeulen-Johnson
            /// saturation, wheelset spin dofs, (5.19)-(5.27) per wheelset)
            parameter "contact.model" => params.model;
            /// Car-body mass (Manchester Benchmark: 32 t)
            parameter "carbody.mass" [unit = "kg", display_unit = "t", min = 0.0] => params.carbody.mass_kg;
            /// Car-body roll inertia about its centre of gravity (Manchester: 56 800 kg m2)
            parameter "carbody.roll_inertia" [unit = "kg.m2", min = 0.0] => params.carbody.roll_inertia_kgm2;
            /// Car-body yaw inertia (Manchester: 1 970 000 kg m2)
            parameter "carbody.yaw_inertia" [unit = "kg.m2", min = 0.0] => params.carbody.yaw_inertia_kgm2;
            /// Height of the car body's centre of gravity above the rail (Manchester: 1.8 m)
            parameter "carbody.cg_height" [unit = "m", range = 0.0..=6.0] => params.carbody.cg_height_m;
            /// Height of the comfort measuring points (floor) above the rail (chosen: 1.2 m)
            parameter "carbody.floor_height" [unit = "m", range = 0.0..=6.0] => params.carbody.floor_height_m;
            /// Mass of one bogie frame (2474 kg: 6.1 t bogie with its wheelsets, seed a_lim; Manchester
            /// 2615 kg)
            parameter "frame.mass" [unit = "kg", min = 0.0] => params.frame.mass_kg;
            /// Frame roll inertia (Manchester: 1722 kg m2)
            parameter "frame.roll_inertia" [unit = "kg.m2", min = 0.0] => params.frame.roll_inertia_kgm2;
            /// Frame yaw inertia (Manchester: 3067 kg m2)
            parameter "frame.yaw_inertia" [unit = "kg.m2", min = 0.0] => params.frame.yaw_inertia_kgm2;
            /// Height of the frame's centre of gravity above the rail (Manchester: 0.6 m)
            parameter "frame.cg_height" [unit = "m", range = 0.0..=3.0] => params.frame.cg_height_m;
            /// Wheelset mass (Manchester: 1813 kg)
            parameter "wheelset.mass" [unit = "kg", min = 0.0] => params.wheelset.mass_kg;
            /// Wheelset yaw inertia (Manchester: 1120 kg m2)
            parameter "wheelset.yaw_inertia" [unit = "kg.m2", min = 0.0] => params.wheelset.yaw_inertia_kgm2;
            /// Wheelset spin inertia about its axle (Manchester: 112 kg m2), non-linear model
            parameter "wheelset.spin_inertia" [unit = "kg.m2", min = 0.0] => params.wheelset.spin_inertia_kgm2;
            /// Nominal rolling radius r0; the axle and the primary springs are at this height (Manchester:
            /// 0.46 m)
            parameter "wheelset.wheel_radius" [unit = "m", range = 0.2..=0.8] => params.wheelset.wheel_radius_m;
            /// s: half distance between the contact points (MPE 2019: 0.7465 m)
            parameter "wheelset.half_contact_gauge" [unit = "m", range = 0.3..=1.0] => params.wheelset.half_contact_gauge_m;
            /// P: static vertical load per wheel, the coach's weight / 8 (from the masses: 54.2 kN with the
            /// defaults)
            calculated_parameter "wheelset.wheel_load" [unit = "N", display_unit = "kN"] => |m| m.params.wheel_rail_from_masses().wheel_load_n;
            /// a: half distance between the bogie centres (seed Table 4-1: 17.5 m between them)
            parameter "geometry.half_bogie_spacing" [unit = "m", min = 0.0] => params.geometry.half_bogie_spacing_m;
            /// p: half wheelbase (seed Table 4-1: wheelbase 2.5 m); at most half of a
            parameter "geometry.half_wheelbase" [unit = "m", min = 0.0] => params.geometry.half_wheelbase_m;
            /// Lateral semi-spacing of the primary springs (axle boxes) (Manchester: 1.0 m)
            parameter "primary.lateral_semi_spacing" [unit = "m", min = 0.0] => params.geometry.primary_half_spacing_m;
            /// Primary longitudinal stiffness per axle box (Manchester 31.4 MN/m times the calibrated
            /// factor 3.15)
            parameter "primary.longitudinal_stiffness" [unit = "N/m", display_unit = "MN/m", min = 0.0] => params.primary.kx_n_per_m;
            /// Primary lateral stiffness per axle box (Manchester 3.88 MN/m times the calibrated factor
            /// 3.15)
            parameter "primary.lateral_stiffness" [unit = "N/m", display_unit = "MN/m", min = 0.0] => params.primary.ky_n_per_m;
            /// Primary vertical stiffness per axle box (Manchester: 1.22 MN/m)
            parameter "primary.vertical_stiffness" [unit = "N/m", display_unit = "MN/m", min = 0.0] => params.primary.kz_n_per_m;
            /// Primary longitudinal damping per axle box (Manchester: 15 kNs/m)
            parameter "primary.longitudinal_damping" [unit = "N.s/m", display_unit = "kN.s/m", min = 0.0] => params.primary.cx_ns_per_m;
            /// Primary lateral damping per axle box (Manchester: 2 kNs/m)
            parameter "primary.lateral_damping" [unit = "N.s/m", display_unit = "kN.s/m", min = 0.0] => params.primary.cy_ns_per_m;
            /// Primary vertical damping per axle box (Manchester: 4 kNs/m)
            parameter "primary.vertical_damping" [unit = "N.s/m", display_unit = "kN.s/m", min = 0.0] => params.primary.cz_ns_per_m;
            /// Lateral semi-spacing of the air springs (Manchester: 1.0 m)
            parameter "secondary.lateral_semi_spacing" [unit = "m", min = 0.0] => params.geometry.secondary_half_spacing_m;
            /// Height of the air springs' force plane above the rail (Manchester: 0.8275 m)
            parameter "secondary.height" [unit = "m", range = 0.0..=3.0] => params.geometry.secondary_height_m;
            /// Height of the secondary lateral dampers above the rail (chosen: the air-spring height)
            parameter "secondary.lateral_damper_height" [unit = "m", range = 0.0..=3.0] => params.geometry.lateral_damper_height_m;
            /// Air-spring longitudinal stiffness per side (Manchester: 160 kN/m)
            parameter "secondary.longitudinal_stiffness" [unit = "N/m", display_unit = "kN/m", min = 0.0] => params.secondary.kx_n_per_m;
            /// Air-spring lateral stiffness per side (Manchester: 160 kN/m)
            parameter "secondary.lateral_stiffness" [unit = "N/m", display_unit = "kN/m", min = 0.0] => params.secondary.ky_n_per_m;
            /// Air-spring vertical stiffness per side (Manchester: 430 kN/m)
            parameter "secondary.vertical_stiffness" [unit = "N/m", display_unit = "kN/m", min = 0.0] => params.secondary.kz_n_per_m;
            /// Secondary vertical damping per side (Manchester: 20 kNs/m)
            parameter "secondary.vertical_damping" [unit = "N.s/m", display_unit = "kN.s/m", min = 0.0] => params.secondary.cz_ns_per_m;
            /// Secondary lateral damper per side (Manchester: 32 kNs/m)
            parameter "secondary.lateral_damping" [unit = "N.s/m", display_unit = "kN.s/m", min = 0.0] => params.secondary.lateral_damping_ns_per_m;
            /// Torsional (yaw) stiffness of one air spring (Manchester: 10.5 kN m/rad)
            parameter "secondary.yaw_stiffness" [unit = "N.m/rad", min = 0.0] => params.secondary.yaw_stiffness_nm_per_rad;
            /// Anti-roll bar per bogie on the car-body/frame relative roll (Manchester: 940 kN m/rad;
            /// 0 = none)
            parameter "secondary.anti_roll_stiffness" [unit = "N.m/rad", display_unit = "MN.m/rad", min = 0.0] => params.secondary.anti_roll_bar_nm_per_rad;
            /// b: lateral arm of the four yaw dampers (MPE 2019: 1.35 m, as the 2-dof bogie)
            parameter "damper.lateral_arm" [unit = "m", min = 0.0] => params.geometry.damper_arm_m;
            /// Equivalent conicity of the linear model (default: the default table at 1 mm)
            parameter "linear.conicity" [unit = "1", range = 0.0..=1.0] => params.wheel_rail.conicity;
            /// Lateral contact-angle (gravitational) stiffness per wheelset of the linear model: the
            /// default table's at 1 mm per newton of load, times the wheel load
            calculated_parameter "linear.gravitational_stiffness" [unit = "N/m", display_unit = "MN/m"] => |m| m.params.wheel_rail_from_masses().gravity_stiffness_n_per_m;
            /// f11: Kalker longitudinal creep coefficient per wheel (Hertz + Kalker, 11.5 MN at 70 kN,
            /// scaled as P^(2/3) to the wheel load)
            calculated_parameter "creep.f11" [unit = "N"] => |m| m.params.wheel_rail_from_masses().f11_n;
            /// f22: Kalker lateral creep coefficient per wheel (10.4 MN at 70 kN, scaled as P^(2/3))
            calculated_parameter "creep.f22" [unit = "N"] => |m| m.params.wheel_rail_from_masses().f22_n;
            /// kappa in (0, 1]: reduction of f11, f22 (Polach 2005), both models (0.6, as the 2-dof
            /// bogie)
            parameter "creep.reduction_factor" [unit = "1", range = 0.0..=1.0] => params.wheel_rail.creep_reduction;
            /// mu of the saturation (5.21)-(5.25), in (0, 1]; dry rail 0.3-0.4
            parameter "contact.friction_coefficient" [unit = "1", range = 0.0..=1.0] => params.wheel_rail.friction_coefficient;
            /// Wheel/rail contact table of the non-linear model: "" or "worn" = built-in worn-profile
            /// surrogate (the 2-dof bogie's default table), or a CSV file
            /// (y_m,delta_r_left_m,delta_r_right_m,tan_gamma_left,tan_gamma_right); a relative name is looked
            /// up in the FMU's resources/ first (shipped: wheel_rail_worn_surrogate.csv). The table must
            /// reach flange contact (tan gamma >= 1) on both sides; its range is the derailment limit
            parameter "contact.table" => contact;
            /// Gravity for the roll terms of the suspended bodies (0 switches them off)
            parameter "environment.gravity" [unit = "m/s2", range = 0.0..=30.0] => params.gravity_mps2;
            /// Initial lateral displacement of both bogies (frames and wheelsets), positive right
            parameter "initial.lateral_displacement" [unit = "m", display_unit = "mm", range = -0.03..=0.03] => params.initial.lateral_m;
            /// Initial yaw angle of both bogies, positive nose-left
            parameter "initial.yaw_angle" [unit = "rad", display_unit = "deg", range = -0.02..=0.02] => params.initial.yaw_rad;
            /// Lateral track alignment: none (ideal track), the external input track.lateral_alignment
            /// (under the leading wheelset; the others see it delayed by their distance behind it over V),
            /// or the internal ERRI B176 generator (track.level, track.seed)
            parameter "track.source" => track.source;
            /// ERRI B176 spectrum level of the internal generator
            parameter "track.level" => track.level;
            /// Random seed of the internal generator's phases (reproducible)
            parameter "track.seed" [range = 0.0..=2147483647.0] => track.seed;
            /// Largest internal RK4 sub-step (convergence study: 1 ms; lowered automatically where
            /// stability needs it)
            parameter "solver.max_substep" [unit = "s", display_unit = "ms", range = 1e-6..=1e-2] => params.solver_substep_s;

        }
        // Inputs and the yaw dampers' outputs (the macro recurses once per line: blocks keep
        // it within the compiler's recursion limit)
        model_description::declare! { v;
            /// Force of the front left yaw damper, positive in tension
            input "damper_front_left.force" [unit = "N", display_unit = "kN"] => shell.inputs.damper_force_n[0];
            /// Force of the front right yaw damper, positive in tension
            input "damper_front_right.force" [unit = "N", display_unit = "kN"] => shell.inputs.damper_force_n[1];
            /// Force of the rear left yaw damper, positive in tension
            input "damper_rear_left.force" [unit = "N", display_unit = "kN"] => shell.inputs.damper_force_n[2];
            /// Force of the rear right yaw damper, positive in tension
            input "damper_rear_right.force" [unit = "N", display_unit = "kN"] => shell.inputs.damper_force_n[3];
            /// Lateral track alignment under the leading wheelset, positive right (track.source = external)
            input "track.lateral_alignment" [unit = "m", display_unit = "mm"] => shell.inputs.track_lateral_m;

            /// Elongation of the front left yaw damper (extension positive), from the state
            output "damper_front_left.elongation" [unit = "m", display_unit = "mm"] => shell.out.damper[0].elongation_m;
            /// Elongation velocity of the front left yaw damper
            output "damper_front_left.elongation_velocity" [unit = "m/s", display_unit = "mm/s"] => shell.out.damper[0].elongation_velocity_mps;
            /// Absolute velocity of the car-body end of the front left damper along its axis, positive
            /// forward (towards the car-body end)
            output "damper_front_left.carbody_end_velocity" [unit = "m/s", display_unit = "mm/s"] => shell.out.damper[0].carbody_end_velocity_mps;
            /// Absolute acceleration of the car-body end of the front left damper along its axis
            output "damper_front_left.carbody_end_acceleration" [unit = "m/s2", depends_on = FT_DAMPERS] => shell.out.damper[0].carbody_end_acc_mps2;
            /// Absolute velocity of the frame end of the front left damper along its axis, positive forward
            /// (a textbook sky-hook's x', (3.6), with sensor.sign = -1)
            output "damper_front_left.frame_end_velocity" [unit = "m/s", display_unit = "mm/s"] => shell.out.damper[0].frame_end_velocity_mps;
            /// Absolute acceleration of the frame end of the front left damper along its axis
            output "damper_front_left.frame_end_acceleration" [unit = "m/s2", depends_on = FT_DAMPERS] => shell.out.damper[0].frame_end_acc_mps2;
            /// Elongation of the front right yaw damper (extension positive), from the state
            output "damper_front_right.elongation" [unit = "m", display_unit = "mm"] => shell.out.damper[1].elongation_m;
            /// Elongation velocity of the front right yaw damper
            output "damper_front_right.elongation_velocity" [unit = "m/s", display_unit = "mm/s"] => shell.out.damper[1].elongation_velocity_mps;
            /// Absolute velocity of the car-body end of the front right damper along its axis, positive
            /// forward (towards the car-body end)
            output "damper_front_right.carbody_end_velocity" [unit = "m/s", display_unit = "mm/s"] => shell.out.damper[1].carbody_end_velocity_mps;
            /// Absolute acceleration of the car-body end of the front right damper along its axis
            output "damper_front_right.carbody_end_acceleration" [unit = "m/s2", depends_on = FT_DAMPERS] => shell.out.damper[1].carbody_end_acc_mps2;
            /// Absolute velocity of the frame end of the front right damper along its axis, positive forward
            /// (a textbook sky-hook's x', (3.6), with sensor.sign = -1)
            output "damper_front_right.frame_end_velocity" [unit = "m/s", display_unit = "mm/s"] => shell.out.damper[1].frame_end_velocity_mps;
            /// Absolute acceleration of the frame end of the front right damper along its axis
            output "damper_front_right.frame_end_acceleration" [unit = "m/s2", depends_on = FT_DAMPERS] => shell.out.damper[1].frame_end_acc_mps2;
            /// Elongation of the rear left yaw damper (extension positive), from the state
            output "damper_rear_left.elongation" [unit = "m", display_unit = "mm"] => shell.out.damper[2].elongation_m;
            /// Elongation velocity of the rear left yaw damper
            output "damper_rear_left.elongation_velocity" [unit = "m/s", display_unit = "mm/s"] => shell.out.damper[2].elongation_velocity_mps;
            /// Absolute velocity of the car-body end of the rear left damper along its axis, positive
            /// forward (towards the car-body end)
            output "damper_rear_left.carbody_end_velocity" [unit = "m/s", display_unit = "mm/s"] => shell.out.damper[2].carbody_end_velocity_mps;
            /// Absolute acceleration of the car-body end of the rear left damper along its axis
            output "damper_rear_left.carbody_end_acceleration" [unit = "m/s2", depends_on = FT_DAMPERS] => shell.out.damper[2].carbody_end_acc_mps2;
            /// Absolute velocity of the frame end of the rear left damper along its axis, positive forward
            /// (a textbook sky-hook's x', (3.6), with sensor.sign = -1)
            output "damper_rear_left.frame_end_velocity" [unit = "m/s", display_unit = "mm/s"] => shell.out.damper[2].frame_end_velocity_mps;
            /// Absolute acceleration of the frame end of the rear left damper along its axis
            output "damper_rear_left.frame_end_acceleration" [unit = "m/s2", depends_on = FT_DAMPERS] => shell.out.damper[2].frame_end_acc_mps2;
            /// Elongation of the rear right yaw damper (extension positive), from the state
            output "damper_rear_right.elongation" [unit = "m", display_unit = "mm"] => shell.out.damper[3].elongation_m;
            /// Elongation velocity of the rear right yaw damper
            output "damper_rear_right.elongation_velocity" [unit = "m/s", display_unit = "mm/s"] => shell.out.damper[3].elongation_velocity_mps;
            /// Absolute velocity of the car-body end of the rear right damper along its axis, positive
            /// forward (towards the car-body end)
            output "damper_rear_right.carbody_end_velocity" [unit = "m/s", display_unit = "mm/s"] => shell.out.damper[3].carbody_end_velocity_mps;
            /// Absolute acceleration of the car-body end of the rear right damper along its axis
            output "damper_rear_right.carbody_end_acceleration" [unit = "m/s2", depends_on = FT_DAMPERS] => shell.out.damper[3].carbody_end_acc_mps2;
            /// Absolute velocity of the frame end of the rear right damper along its axis, positive forward
            /// (a textbook sky-hook's x', (3.6), with sensor.sign = -1)
            output "damper_rear_right.frame_end_velocity" [unit = "m/s", display_unit = "mm/s"] => shell.out.damper[3].frame_end_velocity_mps;
            /// Absolute acceleration of the frame end of the rear right damper along its axis
            output "damper_rear_right.frame_end_acceleration" [unit = "m/s2", depends_on = FT_DAMPERS] => shell.out.damper[3].frame_end_acc_mps2;
        }
        // Wheelsets, leading first
        model_description::declare! { v;
            /// Lateral displacement of wheelset 1 (leading wheelset of the front bogie), positive right
            output "wheelset_1.lateral_displacement" [unit = "m", display_unit = "mm"] => shell.out.wheelset[0].lateral_m;
            /// Lateral displacement of wheelset 1 relative to the track
            output "wheelset_1.lateral_displacement_relative" [unit = "m", display_unit = "mm", depends_on = FT_TRACK] => shell.out.wheelset[0].lateral_rel_track_m;
            /// Lateral velocity of wheelset 1
            output "wheelset_1.lateral_velocity" [unit = "m/s", display_unit = "mm/s"] => shell.out.wheelset[0].lateral_velocity_mps;
            /// Lateral acceleration of wheelset 1
            output "wheelset_1.lateral_acceleration" [unit = "m/s2", depends_on = FT_TRACK] => shell.out.wheelset[0].lateral_acc_mps2;
            /// Yaw angle of wheelset 1, positive nose-left
            output "wheelset_1.yaw_angle" [unit = "rad", display_unit = "deg"] => shell.out.wheelset[0].yaw_rad;
            /// Guiding force of wheelset 1: sum of the lateral forces of the rails on it, positive right
            output "wheelset_1.guiding_force" [unit = "N", display_unit = "kN", depends_on = FT_TRACK] => shell.out.wheelset[0].guiding_force_n;
            /// Y/Q of wheelset 1: larger lateral wheel force over the static wheel load
            output "wheelset_1.y_over_q" [unit = "1", depends_on = FT_TRACK] => shell.out.wheelset[0].y_over_q;
            /// Track lateral alignment under wheelset 1
            output "wheelset_1.track_alignment" [unit = "m", display_unit = "mm", depends_on = FT_TRACK] => shell.out.wheelset[0].track_m;
            /// Lateral displacement of wheelset 2 (trailing wheelset of the front bogie), positive right
            output "wheelset_2.lateral_displacement" [unit = "m", display_unit = "mm"] => shell.out.wheelset[1].lateral_m;
            /// Lateral displacement of wheelset 2 relative to the track
            output "wheelset_2.lateral_displacement_relative" [unit = "m", display_unit = "mm", depends_on = FT_TRACK] => shell.out.wheelset[1].lateral_rel_track_m;
            /// Lateral velocity of wheelset 2
            output "wheelset_2.lateral_velocity" [unit = "m/s", display_unit = "mm/s"] => shell.out.wheelset[1].lateral_velocity_mps;
            /// Lateral acceleration of wheelset 2
            output "wheelset_2.lateral_acceleration" [unit = "m/s2", depends_on = FT_TRACK] => shell.out.wheelset[1].lateral_acc_mps2;
            /// Yaw angle of wheelset 2, positive nose-left
            output "wheelset_2.yaw_angle" [unit = "rad", display_unit = "deg"] => shell.out.wheelset[1].yaw_rad;
            /// Guiding force of wheelset 2: sum of the lateral forces of the rails on it, positive right
            output "wheelset_2.guiding_force" [unit = "N", display_unit = "kN", depends_on = FT_TRACK] => shell.out.wheelset[1].guiding_force_n;
            /// Y/Q of wheelset 2: larger lateral wheel force over the static wheel load
            output "wheelset_2.y_over_q" [unit = "1", depends_on = FT_TRACK] => shell.out.wheelset[1].y_over_q;
            /// Track lateral alignment under wheelset 2
            output "wheelset_2.track_alignment" [unit = "m", display_unit = "mm", depends_on = FT_TRACK] => shell.out.wheelset[1].track_m;
            /// Lateral displacement of wheelset 3 (leading wheelset of the rear bogie), positive right
            output "wheelset_3.lateral_displacement" [unit = "m", display_unit = "mm"] => shell.out.wheelset[2].lateral_m;
            /// Lateral displacement of wheelset 3 relative to the track
            output "wheelset_3.lateral_displacement_relative" [unit = "m", display_unit = "mm", depends_on = FT_TRACK] => shell.out.wheelset[2].lateral_rel_track_m;
            /// Lateral velocity of wheelset 3
            output "wheelset_3.lateral_velocity" [unit = "m/s", display_unit = "mm/s"] => shell.out.wheelset[2].lateral_velocity_mps;
            /// Lateral acceleration of wheelset 3
            output "wheelset_3.lateral_acceleration" [unit = "m/s2", depends_on = FT_TRACK] => shell.out.wheelset[2].lateral_acc_mps2;
            /// Yaw angle of wheelset 3, positive nose-left
            output "wheelset_3.yaw_angle" [unit = "rad", display_unit = "deg"] => shell.out.wheelset[2].yaw_rad;
            /// Guiding force of wheelset 3: sum of the lateral forces of the rails on it, positive right
            output "wheelset_3.guiding_force" [unit = "N", display_unit = "kN", depends_on = FT_TRACK] => shell.out.wheelset[2].guiding_force_n;
            /// Y/Q of wheelset 3: larger lateral wheel force over the static wheel load
            output "wheelset_3.y_over_q" [unit = "1", depends_on = FT_TRACK] => shell.out.wheelset[2].y_over_q;
            /// Track lateral alignment under wheelset 3
            output "wheelset_3.track_alignment" [unit = "m", display_unit = "mm", depends_on = FT_TRACK] => shell.out.wheelset[2].track_m;
            /// Lateral displacement of wheelset 4 (trailing wheelset of the rear bogie), positive right
            output "wheelset_4.lateral_displacement" [unit = "m", display_unit = "mm"] => shell.out.wheelset[3].lateral_m;
            /// Lateral displacement of wheelset 4 relative to the track
            output "wheelset_4.lateral_displacement_relative" [unit = "m", display_unit = "mm", depends_on = FT_TRACK] => shell.out.wheelset[3].lateral_rel_track_m;
            /// Lateral velocity of wheelset 4
            output "wheelset_4.lateral_velocity" [unit = "m/s", display_unit = "mm/s"] => shell.out.wheelset[3].lateral_velocity_mps;
            /// Lateral acceleration of wheelset 4
            output "wheelset_4.lateral_acceleration" [unit = "m/s2", depends_on = FT_TRACK] => shell.out.wheelset[3].lateral_acc_mps2;
            /// Yaw angle of wheelset 4, positive nose-left
            output "wheelset_4.yaw_angle" [unit = "rad", display_unit = "deg"] => shell.out.wheelset[3].yaw_rad;
            /// Guiding force of wheelset 4: sum of the lateral forces of the rails on it, positive right
            output "wheelset_4.guiding_force" [unit = "N", display_unit = "kN", depends_on = FT_TRACK] => shell.out.wheelset[3].guiding_force_n;
            /// Y/Q of wheelset 4: larger lateral wheel force over the static wheel load
            output "wheelset_4.y_over_q" [unit = "1", depends_on = FT_TRACK] => shell.out.wheelset[3].y_over_q;
            /// Track lateral alignment under wheelset 4
            output "wheelset_4.track_alignment" [unit = "m", display_unit = "mm", depends_on = FT_TRACK] => shell.out.wheelset[3].track_m;
        }
        // Frames and car body
        model_description::declare! { v;
            /// Lateral acceleration of the front bogie frame over its leading axle boxes, at the frame's
            /// centre height (EN 14363 stability quantity)
            output "frame_front.lateral_acceleration_leading_axle" [unit = "m/s2", depends_on = FT_DAMPERS] => shell.out.frame[0].lateral_acc_leading_axle_mps2;
            /// Lateral acceleration of the front bogie frame over its trailing axle boxes
            output "frame_front.lateral_acceleration_trailing_axle" [unit = "m/s2", depends_on = FT_DAMPERS] => shell.out.frame[0].lateral_acc_trailing_axle_mps2;
            /// Lateral displacement of the front frame centre, positive right
            output "frame_front.lateral_displacement" [unit = "m", display_unit = "mm"] => shell.out.frame[0].lateral_m;
            /// Yaw angle of the front frame, positive nose-left
            output "frame_front.yaw_angle" [unit = "rad", display_unit = "deg"] => shell.out.frame[0].yaw_rad;
            /// Roll angle of the front frame, positive with the top moving right
            output "frame_front.roll_angle" [unit = "rad", display_unit = "deg"] => shell.out.frame[0].roll_rad;
            /// Lateral acceleration of the rear bogie frame over its leading axle boxes, at the frame's
            /// centre height (EN 14363 stability quantity)
            output "frame_rear.lateral_acceleration_leading_axle" [unit = "m/s2", depends_on = FT_DAMPERS] => shell.out.frame[1].lateral_acc_leading_axle_mps2;
            /// Lateral acceleration of the rear bogie frame over its trailing axle boxes
            output "frame_rear.lateral_acceleration_trailing_axle" [unit = "m/s2", depends_on = FT_DAMPERS] => shell.out.frame[1].lateral_acc_trailing_axle_mps2;
            /// Lateral displacement of the rear frame centre, positive right
            output "frame_rear.lateral_displacement" [unit = "m", display_unit = "mm"] => shell.out.frame[1].lateral_m;
            /// Yaw angle of the rear frame, positive nose-left
            output "frame_rear.yaw_angle" [unit = "rad", display_unit = "deg"] => shell.out.frame[1].yaw_rad;
            /// Roll angle of the rear frame, positive with the top moving right
            output "frame_rear.roll_angle" [unit = "rad", display_unit = "deg"] => shell.out.frame[1].roll_rad;
            /// Car-body lateral acceleration at floor height above the front bogie centre (ride comfort;
            /// kinematic, without the g roll component of a tilting accelerometer)
            output "carbody.lateral_acceleration_front" [unit = "m/s2", depends_on = FT_DAMPERS] => shell.out.carbody.lateral_acc_front_mps2;
            /// Car-body lateral acceleration at floor height at mid-length
            output "carbody.lateral_acceleration_mid" [unit = "m/s2", depends_on = FT_DAMPERS] => shell.out.carbody.lateral_acc_mid_mps2;
            /// Car-body lateral acceleration at floor height above the rear bogie centre
            output "carbody.lateral_acceleration_rear" [unit = "m/s2", depends_on = FT_DAMPERS] => shell.out.carbody.lateral_acc_rear_mps2;
            /// Lateral displacement of the car body's centre of gravity, positive right
            output "carbody.lateral_displacement" [unit = "m", display_unit = "mm"] => shell.out.carbody.lateral_m;
            /// Car-body yaw angle, positive nose-left
            output "carbody.yaw_angle" [unit = "rad", display_unit = "deg"] => shell.out.carbody.yaw_rad;
            /// Car-body roll angle, positive with the top moving right
            output "carbody.roll_angle" [unit = "rad", display_unit = "deg"] => shell.out.carbody.roll_rad;
        }
        v
    }

    fn instantiate(ctx: &InstanceContext) -> Result<Self, ModelError> {
        let params = VehicleParams {
            speed_mps: FMU_DEFAULT_SPEED_MPS,
            initial: Initial {
                lateral_m: FMU_DEFAULT_INITIAL_LATERAL_M,
                yaw_rad: 0.0,
            },
            ..VehicleParams::default()
        };
        Ok(Self {
            shell: Shell::new(&params),
            params,
            track: TrackSetting::external(),
            contact: String::new(),
            resource_dir: ctx.resource_dir.clone(),
        })
    }

    fn exit_initialization(&mut self, _diag: &mut Diagnostics) -> Result<(), ModelError> {
        let params = self.build_params();
        let v = Vehicle::new(params).map_err(|e| field_error::<Self>(&e))?;
        self.shell.initialize::<Self>(v)
    }

    fn update_outputs(&mut self, _diag: &mut Diagnostics) -> Result<(), ModelError> {
        self.shell.update_outputs::<Self>(&self.params)
    }

    fn do_step(&mut self, _time: f64, step: f64, _diag: &mut Diagnostics) -> Result<(), StepError> {
        self.shell.do_step::<Self>(step)
    }
}

const DOC: &str = include_str!("fmu_doc.html");

#[cfg(feature = "fmi-export")]
model_description::export_fmus!(RailVehicle);
