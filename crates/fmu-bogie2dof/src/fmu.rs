//! FMI 2.0 co-simulation shell `Bogie2Dof` over the bogie physics ([`crate::model::Bogie`]).
//! Thin: parameters map onto [`Params`], inputs onto [`Inputs`], outputs come from
//! [`Outputs`]; the FMI machinery is in `model-description`.

use std::path::{Path, PathBuf};

use model_description::{
    field_error, read_parameter_file, DefaultExperiment, Diagnostics, FieldError, FmuModel,
    InstanceContext, ModelError, ModelInfo, StepError, Variable, MAX_PARAMETER_FILE_BYTES,
};
use serde::{Deserialize, Serialize};
use vehicle_elements::{resource_or_given, Shell, TrackSetting};
use wheel_rail::GeometryTable;

use crate::model::{Bogie, Inputs, ModelError as PhysicsModelError, Outputs, StepError as PStep};
use crate::params::{ContactSource, Params, TrackSource};

/// Speed of the FMU's start values (default experiment: hunting with flange contact) [m/s].
pub const FMU_DEFAULT_SPEED_MPS: f64 = 300.0 / 3.6;
/// Initial lateral displacement of the FMU's start values \[m\].
pub const FMU_DEFAULT_INITIAL_LATERAL_M: f64 = 3e-3;

// The FMI Enumeration `TrackSource`, with where this model applies the external input.
vehicle_elements::track_choice_enum!(
    "The input track.lateral_alignment at the front wheelset (the rear sees it 2p/V later)"
);

impl FieldError for PhysicsModelError {
    fn field(&self) -> Option<&str> {
        match self {
            PhysicsModelError::Param(p) => p.field(),
            // The contact table is the shell's field `contact`.
            PhysicsModelError::Contact(_) | PhysicsModelError::FlangeNotCovered(_) => {
                Some("contact")
            }
            PhysicsModelError::TooStiff(e) => e.parameter.as_deref(),
            PhysicsModelError::StartsDerailed { .. } => Some("initial_lateral_m"),
        }
    }

    fn reason(&self) -> String {
        match self {
            PhysicsModelError::Param(p) => p.reason(),
            PhysicsModelError::Contact(c) => c.to_string(),
            PhysicsModelError::TooStiff(e) => e.reason(),
            other => other.to_string(),
        }
    }
}

/// A contact-table file refused or unreadable: about the shell's field `contact`.
struct ContactFileError(String);

impl std::fmt::Display for ContactFileError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl FieldError for ContactFileError {
    fn field(&self) -> Option<&str> {
        Some("contact")
    }
}

// The physics as the shell core drives it.
vehicle_elements::shell_physics!(
    Bogie: Params, Inputs, Outputs, PhysicsModelError, PStep, ContactSource
);

/// The bogie FMU: parameters, current inputs, the physics (built at initialisation) and its
/// last outputs (the last three in [`Shell`]).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Bogie2Dof {
    params: Params,
    track: TrackSetting<TrackChoice>,
    /// The contact-table parameter as set: a keyword or a file (see [`Self::contact_source`]).
    contact: String,
    resource_dir: Option<PathBuf>,
    shell: Shell<Bogie>,
}

impl Bogie2Dof {
    /// Outputs (read-only view, for tests and tools).
    pub fn outputs(&self) -> &Outputs {
        &self.shell.out
    }

    /// The contact-table parameter resolved: keywords, then a file under the FMU's
    /// resources/ folder, then the path as given.
    fn contact_source(&self) -> ContactSource {
        match ContactSource::from_path_str(&self.contact) {
            ContactSource::File(p) => {
                ContactSource::File(resource_or_given(&p, self.resource_dir.as_deref()))
            }
            other => other,
        }
    }

    fn build_params(&self) -> Params {
        Params {
            track: self.track.source(),
            contact: self.contact_source(),
            ..self.params.clone()
        }
    }
}

const FT_ACC: &[&str] = &[
    "damper_left.force",
    "damper_right.force",
    "track.lateral_alignment",
];
const FT_TRACK: &[&str] = &["track.lateral_alignment"];

impl FmuModel for Bogie2Dof {
    const MAX_COMMUNICATION_STEP_S: f64 = vehicle_elements::MAX_HOST_STEP_S;

    const INFO: ModelInfo = ModelInfo {
        name: "Bogie2Dof",
        description: "High-speed bogie hunting model (seed 5.3): 2-dof (lateral + yaw) with \
                      linear (5.1)-(5.18) or non-linear (5.19)-(5.27) wheel/rail forces; takes \
                      the yaw damper forces, gives their elongations and the EN 14363 frame \
                      accelerations",
        author: "rail-fmu project (fmu-bogie2dof)",
        version: "0.1.0",
        default_experiment: DefaultExperiment {
            start_time: 0.0,
            stop_time: 5.0,
            step_size: 1e-3,
        },
        documentation_html: DOC,
        resources: &[
            (
                "wheel_rail_worn_surrogate.csv",
                include_bytes!("../resources/wheel_rail_worn_surrogate.csv"),
            ),
            (
                "wheel_rail_A_A.csv",
                include_bytes!("../resources/wheel_rail_A_A.csv"),
            ),
        ],
    };

    fn variables() -> Vec<Variable<Self>> {
        let mut v: Vec<Variable<Self>> = Vec::new();
        model_description::declare! { v;
            /// Running speed V (> 0: the creepages (5.8)-(5.11) divide by V)
            parameter "vehicle.speed" [unit = "m/s", display_unit = "km/h", range = 0.0..=200.0] => params.speed_mps;
            /// Wheel/rail force law: linear (5.1)-(5.18) (Kalker, constant conicity and
            /// gravitational stiffness) or non-linear (5.19)-(5.27) (contact table,
            /// Vermeulen-Johnson saturation, spin dofs)
            parameter "contact.model" => params.model;
            /// mu of the saturation (5.21)-(5.25), in (0, 1]; dry rail 0.3-0.4
            parameter "contact.friction_coefficient" [unit = "1", range = 0.0..=1.0] => params.friction_coefficient;
            /// Wheel/rail contact table of the non-linear model: "" = built-in default
            /// (worn-profile surrogate), "worn", "AA" (EN 15302 profiles A/A), "synthetic" (cone +
            /// flange), or a CSV file (y_m,delta_r_left_m,delta_r_right_m,tan_gamma_left,tan_gamma_right);
            /// a relative name is looked up in the FMU's resources/ first (shipped:
            /// wheel_rail_worn_surrogate.csv, wheel_rail_A_A.csv); a regular file of at most
            /// 64 MiB (a FIFO, device or directory is refused without being opened)
            parameter "contact.table" => contact;
            /// Initial lateral displacement y of the bogie centre (positive right)
            parameter "initial.lateral_displacement" [unit = "m", display_unit = "mm", range = -0.05..=0.05] => params.initial_lateral_m;
            /// Initial yaw angle sigma (positive nose-left)
            parameter "initial.yaw_angle" [unit = "rad", display_unit = "deg", range = -0.05..=0.05] => params.initial_yaw_rad;
            /// m: bogie frame + two wheelsets (seed 4.2: 6.1 t from a_lim)
            parameter "inertia.mass" [unit = "kg", display_unit = "t", min = 0.0] => params.bogie_mass_kg;
            /// J: yaw inertia of frame + wheelsets (Manchester Benchmark: 10 973 kg m2)
            parameter "inertia.yaw" [unit = "kg.m2", min = 0.0] => params.bogie_yaw_inertia_kgm2;
            /// J_w: spin inertia of one wheelset (Manchester: 112 kg m2), non-linear model
            parameter "wheelset.spin_inertia" [unit = "kg.m2", min = 0.0] => params.wheelset_spin_inertia_kgm2;
            /// p: half wheelbase (seed: wheelbase 2.5 m)
            parameter "geometry.half_wheelbase" [unit = "m", min = 0.0] => params.half_wheelbase_m;
            /// s: half distance between the contact points (MPE 2019: 0.7465 m)
            parameter "wheelset.half_contact_gauge" [unit = "m", range = 0.3..=1.0] => params.half_contact_gauge_m;
            /// b: lateral arm of the yaw dampers and of k_ssx (MPE 2019: 1.35 m)
            parameter "damper.lateral_arm" [unit = "m", min = 0.0] => params.damper_arm_m;
            /// R0: nominal rolling radius (Manchester: 0.46 m)
            parameter "wheelset.wheel_radius" [unit = "m", range = 0.2..=0.8] => params.wheel_radius_m;
            /// P: static vertical load per wheel (70 kN; Table 4-1's 27.52 kN per wheelset is not
            /// plausible)
            parameter "wheelset.wheel_load" [unit = "N", display_unit = "kN", min = 0.0] => params.wheel_load_n;
            /// k_ssy: secondary lateral stiffness per side (Manchester: 160 kN/m)
            parameter "suspension.lateral_stiffness" [unit = "N/m", display_unit = "kN/m", min = 0.0] => params.k_ssy_n_per_m;
            /// k_ssx: effective longitudinal secondary stiffness per side at arm b (air spring +
            /// mountings, yaw damper excluded); calibrated for R5 with the passive damper
            parameter "suspension.longitudinal_stiffness" [unit = "N/m", display_unit = "kN/m", min = 0.0] => params.k_ssx_n_per_m;
            /// f11: Kalker longitudinal creep coefficient per wheel (Hertz + Kalker at 70 kN)
            parameter "creep.f11" [unit = "N", min = 0.0] => params.f11_n;
            /// f22: Kalker lateral creep coefficient per wheel (Hertz + Kalker at 70 kN)
            parameter "creep.f22" [unit = "N", min = 0.0] => params.f22_n;
            /// kappa in (0, 1]: reduction of f11, f22 (Polach 2005), both models; calibrated 0.6
            parameter "creep.reduction_factor" [unit = "1", range = 0.0..=1.0] => params.creep_reduction;
            /// lambda: equivalent conicity of the linear model (default: the default table's
            /// describing function at 1 mm)
            parameter "linear.conicity" [unit = "1", range = 0.0..=1.0] => params.conicity;
            /// k_g: lateral contact-angle stiffness per wheelset of the linear model (default: the
            /// default table at 1 mm, P = 70 kN)
            parameter "linear.gravitational_stiffness" [unit = "N/m", display_unit = "MN/m", min = 0.0] => params.gravity_stiffness_n_per_m;
            /// Lateral track alignment: none (ideal track), external input
            /// track.lateral_alignment (at the front wheelset; the rear sees it 2p/V later), or
            /// the internal ERRI B176 generator (track.level, track.seed)
            parameter "track.source" => track.source;
            /// ERRI B176 spectrum level of the internal generator: low (A = 2.119e-7 m rad) or
            /// high (A = 6.125e-7 m rad)
            parameter "track.level" => track.level;
            /// Random seed of the internal generator's phases (reproducible)
            parameter "track.seed" [range = 0.0..=2147483647.0] => track.seed;

            /// Left yaw damper force, positive in tension
            input "damper_left.force" [unit = "N", display_unit = "kN"] => shell.inputs.damper_left_force_n;
            /// Right yaw damper force, positive in tension
            input "damper_right.force" [unit = "N", display_unit = "kN"] => shell.inputs.damper_right_force_n;
            /// Lateral track alignment at the front wheelset, positive right (track.source = external)
            input "track.lateral_alignment" [unit = "m", display_unit = "mm"] => shell.inputs.track_lateral_m;

            /// Left damper elongation e_L = +b sigma (extension positive), from the state
            output "damper_left.elongation" [unit = "m", display_unit = "mm"] => shell.out.damper_left_elongation_m;
            /// Left damper elongation velocity +b sigma'
            output "damper_left.elongation_velocity" [unit = "m/s", display_unit = "mm/s"] => shell.out.damper_left_velocity_mps;
            /// Right damper elongation e_R = -b sigma (extension positive), from the state
            output "damper_right.elongation" [unit = "m", display_unit = "mm"] => shell.out.damper_right_elongation_m;
            /// Right damper elongation velocity -b sigma'
            output "damper_right.elongation_velocity" [unit = "m/s", display_unit = "mm/s"] => shell.out.damper_right_velocity_mps;
            /// Absolute velocity of the bogie-side end of the left damper along its axis, positive
            /// in the direction that extends the damper (+b sigma'; the car body does not move)
            output "damper_left.end_absolute_velocity" [unit = "m/s", display_unit = "mm/s"] => shell.out.damper_left_velocity_mps;
            /// Same for the right damper (-b sigma')
            output "damper_right.end_absolute_velocity" [unit = "m/s", display_unit = "mm/s"] => shell.out.damper_right_velocity_mps;
            /// Absolute acceleration of the bogie-side end of the left damper along its axis,
            /// positive towards extension (+b sigma''), for the sky-hook accelerometer
            output "damper_left.end_absolute_acceleration" [unit = "m/s2", depends_on = FT_ACC]
                => |m| m.params.damper_arm_m * m.shell.out.yaw_acc_radps2;
            /// Same for the right damper (-b sigma'')
            output "damper_right.end_absolute_acceleration" [unit = "m/s2", depends_on = FT_ACC]
                => |m| -m.params.damper_arm_m * m.shell.out.yaw_acc_radps2;
            /// Bogie frame lateral acceleration above the front wheelset y'' - p sigma'' (EN 14363
            /// stability quantity)
            output "frame.lateral_acceleration_front" [unit = "m/s2", depends_on = FT_ACC] => shell.out.frame_acc_front_mps2;
            /// Bogie frame lateral acceleration above the rear wheelset y'' + p sigma''
            output "frame.lateral_acceleration_rear" [unit = "m/s2", depends_on = FT_ACC] => shell.out.frame_acc_rear_mps2;
            /// Lateral displacement of the front (leading, at +p) wheelset, y - p sigma
            output "wheelset_front.lateral_displacement" [unit = "m", display_unit = "mm"] => shell.out.wheelset_front_lateral_m;
            /// Lateral displacement of the front (leading, at +p) wheelset relative to the track
            output "wheelset_front.lateral_displacement_relative" [unit = "m", display_unit = "mm", depends_on = FT_TRACK] => shell.out.wheelset_front_rel_track_m;
            /// Lateral acceleration of the front (leading, at +p) wheelset (rigid primary
            /// suspension: that of the frame above it)
            output "wheelset_front.lateral_acceleration" [unit = "m/s2", depends_on = FT_ACC] => shell.out.wheelset_front_acc_mps2;
            /// Sum Y of the lateral wheel/rail forces on the front (leading, at +p) wheelset
            /// (force of the rails on the wheelset, positive right)
            output "wheelset_front.guiding_force" [unit = "N", display_unit = "kN", depends_on = FT_TRACK] => shell.out.guiding_force_front_n;
            /// Lateral displacement of the rear (at -p) wheelset, y + p sigma
            output "wheelset_rear.lateral_displacement" [unit = "m", display_unit = "mm"] => shell.out.wheelset_rear_lateral_m;
            /// Lateral displacement of the rear (at -p) wheelset relative to the track
            output "wheelset_rear.lateral_displacement_relative" [unit = "m", display_unit = "mm", depends_on = FT_TRACK] => shell.out.wheelset_rear_rel_track_m;
            /// Lateral acceleration of the rear (at -p) wheelset (rigid primary suspension: that
            /// of the frame above it)
            output "wheelset_rear.lateral_acceleration" [unit = "m/s2", depends_on = FT_ACC] => shell.out.wheelset_rear_acc_mps2;
            /// Sum Y of the lateral wheel/rail forces on the rear (at -p) wheelset (force of the
            /// rails on the wheelset, positive right)
            output "wheelset_rear.guiding_force" [unit = "N", display_unit = "kN", depends_on = FT_TRACK] => shell.out.guiding_force_rear_n;
            /// Bogie yaw angle sigma (positive nose-left)
            output "bogie.yaw_angle" [unit = "rad", display_unit = "deg"] => shell.out.yaw_rad;
            /// Bogie yaw rate sigma'
            output "bogie.yaw_rate" [unit = "rad/s", display_unit = "deg/s"] => shell.out.yaw_rate_radps;
            /// Lateral displacement y of the bogie centre (positive right)
            output "bogie.lateral_displacement" [unit = "m", display_unit = "mm"] => shell.out.bogie_lateral_m;
            /// Lateral velocity y' of the bogie centre
            output "bogie.lateral_velocity" [unit = "m/s", display_unit = "mm/s"] => shell.out.bogie_lateral_velocity_mps;
            /// Track lateral alignment under the front wheelset (input or internal generator)
            output "track.alignment_front" [unit = "m", display_unit = "mm", depends_on = FT_TRACK] => shell.out.track_front_m;
            /// Track lateral alignment under the rear wheelset (delayed by 2p/V)
            output "track.alignment_rear" [unit = "m", display_unit = "mm", depends_on = FT_TRACK] => shell.out.track_rear_m;
        }
        v
    }

    fn instantiate(ctx: &InstanceContext) -> Result<Self, ModelError> {
        let params = Params {
            speed_mps: FMU_DEFAULT_SPEED_MPS,
            initial_lateral_m: FMU_DEFAULT_INITIAL_LATERAL_M,
            ..Params::default()
        };
        Ok(Self {
            shell: Shell::new(&params),
            params,
            track: TrackSetting::external(),
            contact: String::new(),
            resource_dir: ctx.resource_dir.clone(),
        })
    }

    fn exit_initialization(&mut self, diag: &mut Diagnostics) -> Result<(), ModelError> {
        let params = self.build_params();
        params.validate().map_err(|e| field_error::<Self>(&e))?;
        // the creep coefficients and the linear gravitational stiffness are parameters of
        // their own, given for the default load: a new load alone leaves them as they were
        let defaults = Params::default();
        let load_changed =
            (params.wheel_load_n - defaults.wheel_load_n).abs() > 1e-6 * defaults.wheel_load_n;
        let kept: Vec<&str> = [
            ("'creep.f11'", params.f11_n == defaults.f11_n),
            ("'creep.f22'", params.f22_n == defaults.f22_n),
            (
                "'linear.gravitational_stiffness'",
                params.gravity_stiffness_n_per_m == defaults.gravity_stiffness_n_per_m,
            ),
        ]
        .into_iter()
        .filter_map(|(name, at_default)| at_default.then_some(name))
        .collect();
        if load_changed && !kept.is_empty() {
            diag.warn(format!(
                "'wheelset.wheel_load' = {} kN, but {} keep the values given for {} kN: they \
                 are not derived from the load (Hertz-Kalker: f11, f22 grow with P^(2/3); the \
                 gravitational stiffness with P); set them for this load",
                params.wheel_load_n / 1e3,
                kept.join(", "),
                defaults.wheel_load_n / 1e3
            ));
        }
        let b = match &params.contact {
            // A file named by the host: a regular file of sane size only, checked before it is
            // opened (a FIFO must not block the host, /dev/zero must not fill its memory).
            ContactSource::File(path) => {
                let text = read_parameter_file(Path::new(path), MAX_PARAMETER_FILE_BYTES)
                    .map_err(|e| field_error::<Self>(&ContactFileError(e.to_string())))?;
                let table = GeometryTable::parse_csv(&text, path)
                    .map_err(|e| field_error::<Self>(&PhysicsModelError::from(e)))?;
                Bogie::with_table(params, table)
            }
            _ => Bogie::new(params),
        }
        .map_err(|e| field_error::<Self>(&e))?;
        self.shell.initialize::<Self>(b)
    }

    fn update_outputs(&mut self, _diag: &mut Diagnostics) -> Result<(), ModelError> {
        self.shell.update_outputs::<Self>(&self.params)
    }

    fn do_step(&mut self, _time: f64, step: f64, _diag: &mut Diagnostics) -> Result<(), StepError> {
        self.shell.do_step::<Self>(step)
    }

    /// The physics' step returns the outputs at its end with the held inputs, as
    /// `update_outputs` would compute them, except on the external track: there the rear
    /// wheelset's alignment of a step is the delayed input at the step's start.
    fn step_computes_outputs(&self) -> bool {
        self.shell
            .physics
            .as_ref()
            .is_some_and(|b| b.params().track != TrackSource::External)
    }
}

const DOC: &str = include_str!("fmu_doc.html");

#[cfg(feature = "fmi-export")]
model_description::export_fmus!(Bogie2Dof);
