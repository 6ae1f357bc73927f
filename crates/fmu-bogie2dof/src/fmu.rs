//! FMI 2.0 co-simulation shell `Bogie2Dof` over the bogie physics ([`crate::model::Bogie`]).
//! Thin: parameters map onto [`Params`], inputs onto [`Inputs`], outputs come from
//! [`Outputs`]; the FMI machinery is in `model-description`.

use std::path::PathBuf;

use model_description::{
    DefaultExperiment, Diagnostics, FmuModel, InstanceContext, ModelError, ModelInfo, StepError,
    Variable, VariableList,
};
use serde::{Deserialize, Serialize};

use crate::model::{Bogie, Inputs, ModelError as PhysicsModelError, Outputs, StepError as PStep};
use crate::params::{ContactSource, ModelKind, ParamError, Params, PsdLevel, TrackSource};

/// Speed of the FMU's start values (default experiment: hunting with flange contact) [m/s].
pub const FMU_DEFAULT_SPEED_MPS: f64 = 300.0 / 3.6;
/// Initial lateral displacement of the FMU's start values [m].
pub const FMU_DEFAULT_INITIAL_LATERAL_M: f64 = 3e-3;

/// Physics field -> FMI variable, for error messages.
const NAMES: &[(&str, &str)] = &[
    ("speed_mps", "vehicle.speed"),
    ("bogie_mass_kg", "bogie.mass"),
    ("bogie_yaw_inertia_kgm2", "bogie.yaw_inertia"),
    ("wheelset_spin_inertia_kgm2", "wheelset.spin_inertia"),
    ("half_wheelbase_m", "bogie.half_wheelbase"),
    ("half_contact_gauge_m", "wheelset.half_contact_gauge"),
    ("damper_arm_m", "damper.lateral_arm"),
    ("wheel_radius_m", "wheelset.wheel_radius"),
    ("k_ssy_n_per_m", "suspension.lateral_stiffness"),
    ("k_ssx_n_per_m", "suspension.longitudinal_stiffness"),
    ("conicity", "linear.conicity"),
    (
        "gravity_stiffness_n_per_m",
        "linear.gravitational_stiffness",
    ),
    ("f11_n", "creep.f11"),
    ("f22_n", "creep.f22"),
    ("creep_reduction", "creep.reduction_factor"),
    ("wheel_load_n", "wheelset.wheel_load"),
    ("friction_coefficient", "contact.friction_coefficient"),
    ("initial_lateral_m", "initial.lateral_displacement"),
    ("initial_yaw_rad", "initial.yaw_angle"),
    ("contact", "contact.table"),
];

fn fmi_name(field: &str) -> &'static str {
    NAMES
        .iter()
        .find(|(f, _)| *f == field)
        .map_or("parameter", |(_, n)| *n)
}

fn param_error(e: &ParamError) -> ModelError {
    ModelError::InvalidParameter {
        name: fmi_name(e.name).to_string(),
        reason: e.reason.clone(),
    }
}

fn physics_error(e: &PhysicsModelError) -> ModelError {
    match e {
        PhysicsModelError::Param(p) => param_error(p),
        PhysicsModelError::Contact(c) => ModelError::InvalidParameter {
            name: "contact.table".into(),
            reason: c.to_string(),
        },
    }
}

fn output_error(e: &PStep) -> ModelError {
    match e {
        PStep::NonFiniteInput { name, value } => ModelError::InvalidInput {
            name: match *name {
                "damper_left_force_n" => "damper_left.force",
                "damper_right_force_n" => "damper_right.force",
                _ => "track.lateral_alignment",
            }
            .into(),
            reason: format!("not finite ({value})"),
        },
        other => ModelError::Other(other.to_string()),
    }
}

/// The bogie FMU: parameters, current inputs, the physics (built at initialisation) and its
/// last outputs.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Bogie2Dof {
    params: Params,
    track_source: i32,
    track_level: i32,
    track_seed: i32,
    contact_table: String,
    resource_dir: Option<PathBuf>,
    inputs: Inputs,
    bogie: Option<Bogie>,
    out: Outputs,
}

impl Bogie2Dof {
    /// Outputs (read-only view, for tests and tools).
    pub fn outputs(&self) -> &Outputs {
        &self.out
    }

    /// The contact-table parameter resolved: keywords, then a file under the FMU's
    /// resources/ folder, then the path as given.
    fn contact_source(&self) -> ContactSource {
        match ContactSource::from_path_str(&self.contact_table) {
            ContactSource::File(p) => {
                let path = PathBuf::from(&p);
                if path.is_relative() {
                    if let Some(dir) = &self.resource_dir {
                        let candidate = dir.join(&path);
                        if candidate.is_file() {
                            return ContactSource::File(candidate.to_string_lossy().into_owned());
                        }
                    }
                }
                ContactSource::File(p)
            }
            other => other,
        }
    }

    /// Outputs before initialisation (state of the start values, built-in table, no track):
    /// indicative only; parameters are validated at fmi2ExitInitializationMode.
    fn preview_outputs(&mut self) {
        let p = Params {
            track: TrackSource::None,
            contact: ContactSource::WornSurrogate,
            ..self.params.clone()
        };
        if let Ok(b) = Bogie::new(p) {
            if let Ok(o) = b.outputs(&self.inputs) {
                self.out = o;
            }
        }
    }

    fn build_params(&self) -> Result<Params, ModelError> {
        let level = match self.track_level {
            0 => PsdLevel::Low,
            _ => PsdLevel::High,
        };
        let track = match self.track_source {
            0 => TrackSource::None,
            1 => TrackSource::External,
            _ => TrackSource::Internal {
                level,
                seed: u64::from(self.track_seed.unsigned_abs()),
            },
        };
        Ok(Params {
            track,
            contact: self.contact_source(),
            ..self.params.clone()
        })
    }
}

fn declare_parameters(v: &mut VariableList<Bogie2Dof>) {
    v.parameter(
        "vehicle.speed",
        "Running speed V (> 0: the creepages (5.8)-(5.11) divide by V)",
        |m| m.params.speed_mps,
        |m, x| m.params.speed_mps = x,
    )
    .unit("m/s")
    .display_unit("km/h")
    .range(0.0, 200.0);
    v.integer_parameter(
        "model",
        "Wheel/rail force law: 0 = linear (5.1)-(5.18) (Kalker, constant conicity and \
         gravitational stiffness), 1 = non-linear (5.19)-(5.27) (contact table, \
         Vermeulen-Johnson saturation, spin dofs)",
        |m| match m.params.model {
            ModelKind::Linear => 0,
            ModelKind::NonLinear => 1,
        },
        |m, x| {
            m.params.model = if x == 0 {
                ModelKind::Linear
            } else {
                ModelKind::NonLinear
            }
        },
    )
    .range(0.0, 1.0);
    v.parameter(
        "contact.friction_coefficient",
        "mu of the saturation (5.21)-(5.25), in (0, 1]; dry rail 0.3-0.4",
        |m| m.params.friction_coefficient,
        |m, x| m.params.friction_coefficient = x,
    )
    .unit("1")
    .range(0.0, 1.0);
    v.string_parameter(
        "contact.table",
        "Wheel/rail contact table of the non-linear model: \"\" = built-in default (worn-profile \
         surrogate), \"worn\", \"AA\" (EN 15302 profiles A/A), \"synthetic\" (cone + flange), or \
         a CSV file (y_m,delta_r_left_m,delta_r_right_m,tan_gamma_left,tan_gamma_right); a \
         relative name is looked up in the FMU's resources/ first (shipped: \
         wheel_rail_worn_surrogate.csv, wheel_rail_A_A.csv)",
        |m| m.contact_table.clone(),
        |m, x| m.contact_table = x,
    );
    v.parameter(
        "initial.lateral_displacement",
        "Initial lateral displacement y of the bogie centre (positive right)",
        |m| m.params.initial_lateral_m,
        |m, x| m.params.initial_lateral_m = x,
    )
    .unit("m")
    .display_unit("mm")
    .range(-0.05, 0.05);
    v.parameter(
        "initial.yaw_angle",
        "Initial yaw angle sigma (positive nose-left)",
        |m| m.params.initial_yaw_rad,
        |m, x| m.params.initial_yaw_rad = x,
    )
    .unit("rad")
    .display_unit("deg")
    .range(-0.05, 0.05);
    v.parameter(
        "bogie.mass",
        "m: bogie frame + two wheelsets (seed 4.2: 6.1 t from a_lim)",
        |m| m.params.bogie_mass_kg,
        |m, x| m.params.bogie_mass_kg = x,
    )
    .unit("kg")
    .display_unit("t")
    .min(0.0);
    v.parameter(
        "bogie.yaw_inertia",
        "J: yaw inertia of frame + wheelsets (Manchester Benchmark: 10 973 kg m2)",
        |m| m.params.bogie_yaw_inertia_kgm2,
        |m, x| m.params.bogie_yaw_inertia_kgm2 = x,
    )
    .unit("kg.m2")
    .min(0.0);
    v.parameter(
        "wheelset.spin_inertia",
        "J_w: spin inertia of one wheelset (Manchester: 112 kg m2), non-linear model",
        |m| m.params.wheelset_spin_inertia_kgm2,
        |m, x| m.params.wheelset_spin_inertia_kgm2 = x,
    )
    .unit("kg.m2")
    .min(0.0);
    v.parameter(
        "bogie.half_wheelbase",
        "p: half wheelbase (seed: wheelbase 2.5 m)",
        |m| m.params.half_wheelbase_m,
        |m, x| m.params.half_wheelbase_m = x,
    )
    .unit("m")
    .min(0.0);
    v.parameter(
        "wheelset.half_contact_gauge",
        "s: half distance between the contact points (MPE 2019: 0.7465 m)",
        |m| m.params.half_contact_gauge_m,
        |m, x| m.params.half_contact_gauge_m = x,
    )
    .unit("m")
    .min(0.0);
    v.parameter(
        "damper.lateral_arm",
        "b: lateral arm of the yaw dampers and of k_ssx (MPE 2019: 1.35 m)",
        |m| m.params.damper_arm_m,
        |m, x| m.params.damper_arm_m = x,
    )
    .unit("m")
    .min(0.0);
    v.parameter(
        "wheelset.wheel_radius",
        "R0: nominal rolling radius (Manchester: 0.46 m)",
        |m| m.params.wheel_radius_m,
        |m, x| m.params.wheel_radius_m = x,
    )
    .unit("m")
    .min(0.0);
    v.parameter(
        "wheelset.wheel_load",
        "P: static vertical load per wheel (70 kN; Table 4-1's 27.52 kN per wheelset is not \
         plausible)",
        |m| m.params.wheel_load_n,
        |m, x| m.params.wheel_load_n = x,
    )
    .unit("N")
    .display_unit("kN")
    .min(0.0);
    v.parameter(
        "suspension.lateral_stiffness",
        "k_ssy: secondary lateral stiffness per side (Manchester: 160 kN/m)",
        |m| m.params.k_ssy_n_per_m,
        |m, x| m.params.k_ssy_n_per_m = x,
    )
    .unit("N/m")
    .display_unit("kN/m")
    .min(0.0);
    v.parameter(
        "suspension.longitudinal_stiffness",
        "k_ssx: effective longitudinal secondary stiffness per side at arm b (air spring + \
         mountings, yaw damper excluded); calibrated for R5 with the passive damper",
        |m| m.params.k_ssx_n_per_m,
        |m, x| m.params.k_ssx_n_per_m = x,
    )
    .unit("N/m")
    .display_unit("kN/m")
    .min(0.0);
    v.parameter(
        "creep.f11",
        "f11: Kalker longitudinal creep coefficient per wheel (Hertz + Kalker at 70 kN)",
        |m| m.params.f11_n,
        |m, x| m.params.f11_n = x,
    )
    .unit("N")
    .min(0.0);
    v.parameter(
        "creep.f22",
        "f22: Kalker lateral creep coefficient per wheel (Hertz + Kalker at 70 kN)",
        |m| m.params.f22_n,
        |m, x| m.params.f22_n = x,
    )
    .unit("N")
    .min(0.0);
    v.parameter(
        "creep.reduction_factor",
        "kappa in (0, 1]: reduction of f11, f22 (Polach 2005), both models; calibrated 0.6",
        |m| m.params.creep_reduction,
        |m, x| m.params.creep_reduction = x,
    )
    .unit("1")
    .range(0.0, 1.0);
    v.parameter(
        "linear.conicity",
        "lambda: equivalent conicity of the linear model (default: the default table's \
         describing function at 1 mm)",
        |m| m.params.conicity,
        |m, x| m.params.conicity = x,
    )
    .unit("1")
    .range(0.0, 1.0);
    v.parameter(
        "linear.gravitational_stiffness",
        "k_g: lateral contact-angle stiffness per wheelset of the linear model (default: the \
         default table at 1 mm, P = 70 kN)",
        |m| m.params.gravity_stiffness_n_per_m,
        |m, x| m.params.gravity_stiffness_n_per_m = x,
    )
    .unit("N/m")
    .display_unit("MN/m")
    .min(0.0);
    v.integer_parameter(
        "track.source",
        "Lateral track alignment: 0 = none (ideal track), 1 = external input \
         track.lateral_alignment (at the front wheelset; the rear sees it 2p/V later), \
         2 = internal ERRI B176 generator (track.level, track.seed)",
        |m| m.track_source,
        |m, x| m.track_source = x,
    )
    .range(0.0, 2.0);
    v.integer_parameter(
        "track.level",
        "ERRI B176 spectrum level of the internal generator: 0 = low (A = 2.119e-7 m rad), \
         1 = high (A = 6.125e-7 m rad)",
        |m| m.track_level,
        |m, x| m.track_level = x,
    )
    .range(0.0, 1.0);
    v.integer_parameter(
        "track.seed",
        "Random seed of the internal generator's phases (reproducible)",
        |m| m.track_seed,
        |m, x| m.track_seed = x,
    )
    .range(0.0, f64::from(i32::MAX));
}

const FT_ACC: &[&str] = &[
    "damper_left.force",
    "damper_right.force",
    "track.lateral_alignment",
];
const FT_TRACK: &[&str] = &["track.lateral_alignment"];

fn declare_io(v: &mut VariableList<Bogie2Dof>) {
    v.input(
        "damper_left.force",
        "Left yaw damper force, positive in tension",
        |m| m.inputs.damper_left_force_n,
        |m, x| m.inputs.damper_left_force_n = x,
    )
    .unit("N")
    .display_unit("kN");
    v.input(
        "damper_right.force",
        "Right yaw damper force, positive in tension",
        |m| m.inputs.damper_right_force_n,
        |m, x| m.inputs.damper_right_force_n = x,
    )
    .unit("N")
    .display_unit("kN");
    v.input(
        "track.lateral_alignment",
        "Lateral track alignment at the front wheelset, positive right (track.source = 1)",
        |m| m.inputs.track_lateral_m,
        |m, x| m.inputs.track_lateral_m = x,
    )
    .unit("m")
    .display_unit("mm");

    v.output(
        "damper_left.elongation",
        "Left damper elongation e_L = +b sigma (extension positive), from the state",
        &[],
        |m| m.out.damper_left_elongation_m,
    )
    .unit("m")
    .display_unit("mm");
    v.output(
        "damper_left.elongation_velocity",
        "Left damper elongation velocity +b sigma'",
        &[],
        |m| m.out.damper_left_velocity_mps,
    )
    .unit("m/s")
    .display_unit("mm/s");
    v.output(
        "damper_right.elongation",
        "Right damper elongation e_R = -b sigma (extension positive), from the state",
        &[],
        |m| m.out.damper_right_elongation_m,
    )
    .unit("m")
    .display_unit("mm");
    v.output(
        "damper_right.elongation_velocity",
        "Right damper elongation velocity -b sigma'",
        &[],
        |m| m.out.damper_right_velocity_mps,
    )
    .unit("m/s")
    .display_unit("mm/s");
    v.output(
        "damper_left.end_absolute_velocity",
        "Absolute velocity of the bogie-side end of the left damper along its axis, positive \
         in the direction that extends the damper (+b sigma'; the car body does not move)",
        &[],
        |m| m.out.damper_left_velocity_mps,
    )
    .unit("m/s")
    .display_unit("mm/s");
    v.output(
        "damper_right.end_absolute_velocity",
        "Same for the right damper (-b sigma')",
        &[],
        |m| m.out.damper_right_velocity_mps,
    )
    .unit("m/s")
    .display_unit("mm/s");
    v.output(
        "damper_left.end_absolute_acceleration",
        "Absolute acceleration of the bogie-side end of the left damper along its axis, \
         positive towards extension (+b sigma''), for the sky-hook accelerometer",
        FT_ACC,
        |m| m.params.damper_arm_m * m.out.yaw_acc_radps2,
    )
    .unit("m/s2");
    v.output(
        "damper_right.end_absolute_acceleration",
        "Same for the right damper (-b sigma'')",
        FT_ACC,
        |m| -m.params.damper_arm_m * m.out.yaw_acc_radps2,
    )
    .unit("m/s2");
    v.output(
        "frame.lateral_acceleration_front",
        "Bogie frame lateral acceleration above the front wheelset y'' - p sigma'' (EN 14363 \
         stability quantity)",
        FT_ACC,
        |m| m.out.frame_acc_front_mps2,
    )
    .unit("m/s2");
    v.output(
        "frame.lateral_acceleration_rear",
        "Bogie frame lateral acceleration above the rear wheelset y'' + p sigma''",
        FT_ACC,
        |m| m.out.frame_acc_rear_mps2,
    )
    .unit("m/s2");
    for (front, name_d, name_r, name_a, name_g) in [
        (
            true,
            "wheelset_front.lateral_displacement",
            "wheelset_front.lateral_displacement_relative",
            "wheelset_front.lateral_acceleration",
            "wheelset_front.guiding_force",
        ),
        (
            false,
            "wheelset_rear.lateral_displacement",
            "wheelset_rear.lateral_displacement_relative",
            "wheelset_rear.lateral_acceleration",
            "wheelset_rear.guiding_force",
        ),
    ] {
        let which = if front {
            "front (leading, at +p)"
        } else {
            "rear (at -p)"
        };
        v.output(
            name_d,
            &format!("Lateral displacement of the {which} wheelset, y -+ p sigma"),
            &[],
            if front {
                |m: &Bogie2Dof| m.out.wheelset_front_lateral_m
            } else {
                |m: &Bogie2Dof| m.out.wheelset_rear_lateral_m
            },
        )
        .unit("m")
        .display_unit("mm");
        v.output(
            name_r,
            &format!("Lateral displacement of the {which} wheelset relative to the track"),
            FT_TRACK,
            if front {
                |m: &Bogie2Dof| m.out.wheelset_front_rel_track_m
            } else {
                |m: &Bogie2Dof| m.out.wheelset_rear_rel_track_m
            },
        )
        .unit("m")
        .display_unit("mm");
        v.output(
            name_a,
            &format!(
                "Lateral acceleration of the {which} wheelset (rigid primary suspension: \
                 that of the frame above it)"
            ),
            FT_ACC,
            if front {
                |m: &Bogie2Dof| m.out.wheelset_front_acc_mps2
            } else {
                |m: &Bogie2Dof| m.out.wheelset_rear_acc_mps2
            },
        )
        .unit("m/s2");
        v.output(
            name_g,
            &format!(
                "Sum Y of the lateral wheel/rail forces on the {which} wheelset (force of \
                 the rails on the wheelset, positive right)"
            ),
            FT_TRACK,
            if front {
                |m: &Bogie2Dof| m.out.guiding_force_front_n
            } else {
                |m: &Bogie2Dof| m.out.guiding_force_rear_n
            },
        )
        .unit("N")
        .display_unit("kN");
    }
    v.output(
        "bogie.yaw_angle",
        "Bogie yaw angle sigma (positive nose-left)",
        &[],
        |m| m.out.yaw_rad,
    )
    .unit("rad")
    .display_unit("deg");
    v.output("bogie.yaw_rate", "Bogie yaw rate sigma'", &[], |m| {
        m.out.yaw_rate_radps
    })
    .unit("rad/s")
    .display_unit("deg/s");
    v.output(
        "bogie.lateral_displacement",
        "Lateral displacement y of the bogie centre (positive right)",
        &[],
        |m| m.out.bogie_lateral_m,
    )
    .unit("m")
    .display_unit("mm");
    v.output(
        "bogie.lateral_velocity",
        "Lateral velocity y' of the bogie centre",
        &[],
        |m| m.out.bogie_lateral_velocity_mps,
    )
    .unit("m/s")
    .display_unit("mm/s");
    v.output(
        "track.alignment_front",
        "Track lateral alignment under the front wheelset (input or internal generator)",
        FT_TRACK,
        |m| m.out.track_front_m,
    )
    .unit("m")
    .display_unit("mm");
    v.output(
        "track.alignment_rear",
        "Track lateral alignment under the rear wheelset (delayed by 2p/V)",
        FT_TRACK,
        |m| m.out.track_rear_m,
    )
    .unit("m")
    .display_unit("mm");
}

impl FmuModel for Bogie2Dof {
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
        let mut v = VariableList::<Self>::new();
        declare_parameters(&mut v);
        declare_io(&mut v);
        v.into_vec()
    }

    fn instantiate(ctx: &InstanceContext) -> Result<Self, ModelError> {
        let params = Params {
            speed_mps: FMU_DEFAULT_SPEED_MPS,
            initial_lateral_m: FMU_DEFAULT_INITIAL_LATERAL_M,
            ..Params::default()
        };
        let mut me = Self {
            params,
            track_source: 1,
            track_level: 0,
            track_seed: 1,
            contact_table: String::new(),
            resource_dir: ctx.resource_dir.clone(),
            inputs: Inputs::default(),
            bogie: None,
            out: Outputs::default(),
        };
        me.preview_outputs();
        Ok(me)
    }

    fn exit_initialization(&mut self, _diag: &mut Diagnostics) -> Result<(), ModelError> {
        let params = self.build_params()?;
        params.validate().map_err(|e| param_error(&e))?;
        let b = Bogie::new(params).map_err(|e| physics_error(&e))?;
        self.out = b.outputs(&self.inputs).map_err(|e| output_error(&e))?;
        self.bogie = Some(b);
        Ok(())
    }

    fn update_outputs(&mut self, _diag: &mut Diagnostics) -> Result<(), ModelError> {
        match &self.bogie {
            Some(b) => self.out = b.outputs(&self.inputs).map_err(|e| output_error(&e))?,
            None => self.preview_outputs(),
        }
        Ok(())
    }

    fn do_step(&mut self, _time: f64, step: f64, _diag: &mut Diagnostics) -> Result<(), StepError> {
        let Some(b) = &mut self.bogie else {
            return Err(StepError::Error(ModelError::Other(
                "the physics is built in fmi2ExitInitializationMode; no step before it".into(),
            )));
        };
        let map = |e: PStep| match e {
            PStep::Diverged { .. } | PStep::InvalidStep { .. } => StepError::Discard(e.to_string()),
            other => StepError::Error(ModelError::Other(other.to_string())),
        };
        if step <= 1.0 {
            // The physics leaves itself unchanged when a step fails: step in place.
            self.out = b.step(step, &self.inputs).map_err(map)?;
        } else {
            // Longer host steps (the physics takes up to 1 s) on a copy, committed on success.
            let n = step.ceil() as usize;
            let h = step / n as f64;
            let mut next = b.clone();
            let mut out = self.out;
            for _ in 0..n {
                out = next.step(h, &self.inputs).map_err(map)?;
            }
            *b = next;
            self.out = out;
        }
        Ok(())
    }
}

const DOC: &str = include_str!("fmu_doc.html");

#[cfg(feature = "fmi-export")]
model_description::export_fmus!(Bogie2Dof);
