//! Bogie physics (no FMI): linear and non-linear 2-dof high-speed bogie of the seed's
//! section 5.3, eigen-analysis, track irregularity.
//!
//! Conventions (whole project): x forward (running direction), y lateral POSITIVE TO THE
//! RIGHT, yaw sigma POSITIVE NOSE-LEFT (the seed's (5.8)-(5.18) signs). Wheelset 1 (front,
//! leading) at +p: y1 = y - p sigma; wheelset 2 (rear) at -p: y2 = y + p sigma. Yaw dampers
//! at lateral arm b, car-body end ahead of the bogie end: elongations e_L = +b sigma,
//! e_R = -b sigma, tension positive, yaw moment -b F_L + b F_R (see [`eigen`]).
//!
//! Modules: [`params`] (Params, validation), [`linear`] (5.16) matrices, [`nonlinear`]
//! (right-hand sides), [`eigen`] (root
//! locus, critical speed, damper representations),
//! [`model`] (time-domain [`Bogie`] for the FMU), [`sim`] (closed loop with a simple
//! damper), [`calibration`], [`fmu`] (FMU shell `Bogie2Dof`, exported with feature `fmi-export`).
//! The contact-geometry table and the creep laws come from the `wheel-rail` crate
//! ([`wheel_rail::GeometryTable`], [`wheel_rail::creep`]), the ERRI B176 track generator and
//! the delay line from [`wheel_rail::track`].
pub mod calibration;
pub mod eigen;
pub mod fmu;
pub mod linear;
pub mod model;
pub mod nonlinear;
pub mod params;
pub mod perf;
pub mod sim;

pub use model::{Bogie, Inputs, ModelError, Outputs, StepError};
pub use params::{ContactSource, ModelKind, ParamError, Params, PsdLevel, TrackSource};
