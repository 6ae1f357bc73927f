//! Lateral dynamics of a bogie coach on straight track at constant speed (plain Rust, no FMI):
//! car body (lateral, yaw, roll), two bogie frames (lateral, yaw, roll), four wheelsets
//! (lateral, yaw, and in the non-linear model their spin perturbations), primary suspension
//! per axle box, secondary suspension per side, four yaw dampers as force inputs.
//!
//! Conventions (whole project, as the 2-dof bogie): x forward (running direction), y lateral
//! POSITIVE TO THE RIGHT, yaw POSITIVE NOSE-LEFT, roll positive with the top moving right;
//! heights above the rail. Bogie 0 is the front (leading) one, wheelsets 0..3 from the front.
//! Yaw dampers are longitudinal at lateral arm b between frame and car body, the car-body end
//! ahead of the frame end; elongation positive = extension, force positive = tension
//! (left damper e = b (psi_frame - psi_carbody)).
//!
//! Modules: [`params`] (data set, sources, validation), [`layout`] (dofs, suspension assembly),
//! [`linear`] (linear matrices), [`eigen`] (state matrix, modes, critical speed, root locus),
//! [`calibration`], [`dynamics`] (right-hand side), [`model`] (time-domain [`Vehicle`]),
//! [`sim`] (closed loop with linear dampers), [`fmu`] (FMU shell `RailVehicle`,
//! exported with feature `fmi-export`).
pub mod calibration;
pub mod dynamics;
pub mod eigen;
pub mod fmu;
pub mod layout;
pub mod linear;
pub mod model;
pub mod params;
pub mod sim;

pub use model::{Inputs, ModelError, Outputs, StepError, Vehicle};
pub use params::{ModelKind, ParamError, PsdLevel, TrackSource, VehicleParams};
