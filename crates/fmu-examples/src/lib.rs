//! Two linear test models that split a two-mass oscillator into two FMUs:
//!
//! ```text
//!   ground --k1,d1-- [m1] --kc,dc-- [m2] --k2,d2-- ground
//!   MassSpring: m1 x1'' = -k1 x1 - d1 v1 + force          (force = coupling force from m2)
//!   SpringDamperMass: m2 x2'' = kc (x1 - x2) + dc (v1 - v2) - k2 x2 - d2 v2
//!                     coupling_force = kc (x2 - x1) + dc (v2 - v1)   (force on m1)
//! ```
//! The monolithic system is linear, so the coupled result can be checked against the exact
//! solution; the internal integrator (RK4 at <= 1e-4 s) is far more accurate than any coupling
//! step, so the remaining error is the coupling error.

use model_description::{
    field_error, DefaultExperiment, Diagnostics, FieldError, FmuModel, InstanceContext, ModelError,
    ModelInfo, StepError, Variable,
};
use serde::{Deserialize, Serialize};

const MAX_SUBSTEP_S: f64 = 1.0e-4;

/// One communication step of x'' = accel(x, v) from (x, v) with RK4 sub-steps; `accel` closes
/// over parameters and inputs. A state that is no longer finite discards the step (the caller
/// keeps its state).
fn rk4_step(
    mut x: f64,
    mut v: f64,
    h: f64,
    accel: impl Fn(f64, f64) -> f64,
) -> Result<(f64, f64), StepError> {
    let n = (h / MAX_SUBSTEP_S).ceil().max(1.0);
    let dt = h / n;
    for _ in 0..n as usize {
        let (x0, v0) = (x, v);
        let k1x = v0;
        let k1v = accel(x0, v0);
        let k2x = v0 + 0.5 * dt * k1v;
        let k2v = accel(x0 + 0.5 * dt * k1x, v0 + 0.5 * dt * k1v);
        let k3x = v0 + 0.5 * dt * k2v;
        let k3v = accel(x0 + 0.5 * dt * k2x, v0 + 0.5 * dt * k2v);
        let k4x = v0 + dt * k3v;
        let k4v = accel(x0 + dt * k3x, v0 + dt * k3v);
        x = x0 + dt / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
        v = v0 + dt / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    }
    if x.is_finite() && v.is_finite() {
        Ok((x, v))
    } else {
        Err(StepError::Discard("state is no longer finite".into()))
    }
}

/// A parameter out of range, naming the model field (the glue reports it under the FMI name of
/// the variable bound to that field).
#[derive(Debug)]
struct Invalid {
    field: &'static str,
    reason: String,
}

impl std::fmt::Display for Invalid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.reason)
    }
}

impl FieldError for Invalid {
    fn field(&self) -> Option<&str> {
        Some(self.field)
    }
}

fn positive(field: &'static str, value: f64) -> Result<(), Invalid> {
    if value > 0.0 && value.is_finite() {
        Ok(())
    } else {
        Err(Invalid {
            field,
            reason: format!("must be positive, got {value}"),
        })
    }
}

fn non_negative(field: &'static str, value: f64) -> Result<(), Invalid> {
    if value >= 0.0 && value.is_finite() {
        Ok(())
    } else {
        Err(Invalid {
            field,
            reason: format!("must be >= 0, got {value}"),
        })
    }
}

/// A mass on a spring-damper to ground, driven by an external force.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MassSpring {
    pub mass_kg: f64,
    pub stiffness_n_per_m: f64,
    pub damping_ns_per_m: f64,
    pub initial_position_m: f64,
    pub initial_velocity_mps: f64,
    pub force_n: f64,
    pub position_m: f64,
    pub velocity_mps: f64,
}

impl MassSpring {
    fn accel(&self, x: f64, v: f64) -> f64 {
        (self.force_n - self.stiffness_n_per_m * x - self.damping_ns_per_m * v) / self.mass_kg
    }
}

impl FmuModel for MassSpring {
    /// 1e7 sub-steps of 0.1 ms.
    const MAX_COMMUNICATION_STEP_S: f64 = 1000.0;

    const INFO: ModelInfo = ModelInfo {
        name: "MassSpring",
        description: "Mass on a spring-damper to ground, driven by an input force",
        author: "rail-fmu project",
        version: "0.1.0",
        default_experiment: DefaultExperiment {
            start_time: 0.0,
            stop_time: 5.0,
            step_size: 1.0e-3,
        },
        documentation_html:
            "<p>m x'' = -k x - d x' + force. RK4 with sub-steps of at most 1e-4 s; \
            the input force is held constant over a communication step.</p>",
        resources: &[],
    };

    fn variables() -> Vec<Variable<Self>> {
        let mut v: Vec<Variable<Self>> = Vec::new();
        model_description::declare! { v;
            /// Mass
            parameter "mass" [unit = "kg", min = 1e-9] => mass_kg;
            /// Spring stiffness to ground
            parameter "stiffness" [unit = "N/m", min = 0.0] => stiffness_n_per_m;
            /// Damping to ground
            parameter "damping" [unit = "N.s/m", min = 0.0] => damping_ns_per_m;
            /// Position at the start time
            parameter "initial_position" [unit = "m"] => initial_position_m;
            /// Velocity at the start time
            parameter "initial_velocity" [unit = "m/s"] => initial_velocity_mps;
            /// External force on the mass
            input "force" [unit = "N"] => force_n;
            /// Position
            output "position" [unit = "m"] => position_m;
            /// Velocity
            output "velocity" [unit = "m/s"] => velocity_mps;
        }
        v
    }

    fn instantiate(_ctx: &InstanceContext) -> Result<Self, ModelError> {
        Ok(MassSpring {
            mass_kg: 1.0,
            stiffness_n_per_m: 100.0,
            damping_ns_per_m: 0.5,
            initial_position_m: 0.1,
            initial_velocity_mps: 0.0,
            force_n: 0.0,
            position_m: 0.1,
            velocity_mps: 0.0,
        })
    }

    fn exit_initialization(&mut self, _diag: &mut Diagnostics) -> Result<(), ModelError> {
        let check = || {
            positive("mass_kg", self.mass_kg)?;
            non_negative("stiffness_n_per_m", self.stiffness_n_per_m)?;
            non_negative("damping_ns_per_m", self.damping_ns_per_m)
        };
        check().map_err(|e| field_error::<Self>(&e))?;
        self.position_m = self.initial_position_m;
        self.velocity_mps = self.initial_velocity_mps;
        Ok(())
    }

    fn do_step(&mut self, _t: f64, h: f64, _diag: &mut Diagnostics) -> Result<(), StepError> {
        (self.position_m, self.velocity_mps) =
            rk4_step(self.position_m, self.velocity_mps, h, |x, v| {
                self.accel(x, v)
            })?;
        Ok(())
    }
}

/// A mass joined to a moving point (the input) by a spring-damper, and to ground.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SpringDamperMass {
    pub mass_kg: f64,
    pub coupling_stiffness_n_per_m: f64,
    pub coupling_damping_ns_per_m: f64,
    pub ground_stiffness_n_per_m: f64,
    pub ground_damping_ns_per_m: f64,
    pub initial_position_m: f64,
    pub initial_velocity_mps: f64,
    pub input_position_m: f64,
    pub input_velocity_mps: f64,
    pub position_m: f64,
    pub velocity_mps: f64,
}

impl SpringDamperMass {
    /// Force of the coupling spring-damper on the input body.
    pub fn coupling_force(&self) -> f64 {
        self.coupling_stiffness_n_per_m * (self.position_m - self.input_position_m)
            + self.coupling_damping_ns_per_m * (self.velocity_mps - self.input_velocity_mps)
    }

    fn accel(&self, x: f64, v: f64) -> f64 {
        (self.coupling_stiffness_n_per_m * (self.input_position_m - x)
            + self.coupling_damping_ns_per_m * (self.input_velocity_mps - v)
            - self.ground_stiffness_n_per_m * x
            - self.ground_damping_ns_per_m * v)
            / self.mass_kg
    }
}

impl FmuModel for SpringDamperMass {
    /// 1e7 sub-steps of 0.1 ms.
    const MAX_COMMUNICATION_STEP_S: f64 = 1000.0;

    const INFO: ModelInfo = ModelInfo {
        name: "SpringDamperMass",
        description: "Mass coupled through a spring-damper to an input motion, and to ground",
        author: "rail-fmu project",
        version: "0.1.0",
        default_experiment: DefaultExperiment {
            start_time: 0.0,
            stop_time: 5.0,
            step_size: 1.0e-3,
        },
        documentation_html: "<p>m x'' = kc (x_in - x) + dc (v_in - v) - k2 x - d2 v; \
            coupling_force = kc (x - x_in) + dc (v - v_in) is the force on the input body and \
            depends directly on the inputs (direct feedthrough).</p>",
        resources: &[],
    };

    fn variables() -> Vec<Variable<Self>> {
        let mut v: Vec<Variable<Self>> = Vec::new();
        model_description::declare! { v;
            /// Mass
            parameter "mass" [unit = "kg", min = 1e-9] => mass_kg;
            /// Stiffness of the coupling spring
            parameter "coupling_stiffness" [unit = "N/m", min = 0.0] => coupling_stiffness_n_per_m;
            /// Damping of the coupling damper
            parameter "coupling_damping" [unit = "N.s/m", min = 0.0] => coupling_damping_ns_per_m;
            /// Stiffness to ground
            parameter "ground_stiffness" [unit = "N/m", min = 0.0] => ground_stiffness_n_per_m;
            /// Damping to ground
            parameter "ground_damping" [unit = "N.s/m", min = 0.0] => ground_damping_ns_per_m;
            /// Position at the start time
            parameter "initial_position" [unit = "m"] => initial_position_m;
            /// Velocity at the start time
            parameter "initial_velocity" [unit = "m/s"] => initial_velocity_mps;
            /// Position of the other end of the coupling
            input "input_position" [unit = "m"] => input_position_m;
            /// Velocity of the other end of the coupling
            input "input_velocity" [unit = "m/s"] => input_velocity_mps;
            /// Force of the coupling on the input body
            output "coupling_force" [unit = "N", depends_on = &["input_position", "input_velocity"]]
                => |m| m.coupling_force();
            /// Position
            output "position" [unit = "m"] => position_m;
            /// Velocity
            output "velocity" [unit = "m/s"] => velocity_mps;
        }
        v
    }

    fn instantiate(_ctx: &InstanceContext) -> Result<Self, ModelError> {
        Ok(SpringDamperMass {
            mass_kg: 1.0,
            coupling_stiffness_n_per_m: 50.0,
            coupling_damping_ns_per_m: 0.2,
            ground_stiffness_n_per_m: 100.0,
            ground_damping_ns_per_m: 0.5,
            initial_position_m: 0.0,
            initial_velocity_mps: 0.0,
            input_position_m: 0.0,
            input_velocity_mps: 0.0,
            position_m: 0.0,
            velocity_mps: 0.0,
        })
    }

    fn exit_initialization(&mut self, _diag: &mut Diagnostics) -> Result<(), ModelError> {
        let check = || {
            positive("mass_kg", self.mass_kg)?;
            non_negative(
                "coupling_stiffness_n_per_m",
                self.coupling_stiffness_n_per_m,
            )?;
            non_negative("coupling_damping_ns_per_m", self.coupling_damping_ns_per_m)?;
            non_negative("ground_stiffness_n_per_m", self.ground_stiffness_n_per_m)?;
            non_negative("ground_damping_ns_per_m", self.ground_damping_ns_per_m)
        };
        check().map_err(|e| field_error::<Self>(&e))?;
        self.position_m = self.initial_position_m;
        self.velocity_mps = self.initial_velocity_mps;
        Ok(())
    }

    fn do_step(&mut self, _t: f64, h: f64, _diag: &mut Diagnostics) -> Result<(), StepError> {
        (self.position_m, self.velocity_mps) =
            rk4_step(self.position_m, self.velocity_mps, h, |x, v| {
                self.accel(x, v)
            })?;
        Ok(())
    }
}

#[cfg(feature = "fmi-export")]
model_description::export_fmus!(MassSpring, SpringDamperMass);
