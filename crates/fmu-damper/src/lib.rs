//! Yaw damper physics (plain Rust, no FMI): the semi-active damper with a by-pass
//! proportional valve (seed 3.3), the passive reference damper (semi-active at a fixed
//! 30 % opening, seed 4.3) and the full-active hydraulic actuator (seed 3.4), with
//! characterisation helpers (seed 3.3.4, 3.4.4).
//!
//! Entry points for an FMU shell:
//! * [`SemiActiveDamper`] (`new`, `step`, `outputs`, `set_inputs`) with
//!   [`SemiActiveParams`] (`default`, `passive_reference`, `validate`);
//! * [`Actuator`] with [`ActuatorParams`] (Table 3-2 defaults, model and rod mode);
//! * [`characterise`] for loops, FRFs and [`characterise::equivalent_stiffness_damping`].
//!
//! Sign convention of every `force_n`: positive in tension (opposing extension).

pub mod characterise;
pub mod complex;
pub mod error;
pub mod full_active;
pub mod ode;
pub mod semi_active;
pub mod valve;

pub use characterise::equivalent_stiffness_damping;
pub use complex::Complex;
pub use error::{ParamError, StepError};
pub use full_active::{
    Actuator, ActuatorInputs, ActuatorModel, ActuatorOutputs, ActuatorParams, RodMode,
};
pub use ode::SolverSettings;
pub use semi_active::{SemiActiveDamper, SemiActiveInputs, SemiActiveOutputs, SemiActiveParams};
pub use valve::{ValveCommand, ValveModel, ValveParams};
