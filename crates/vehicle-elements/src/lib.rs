//! Pieces the two rail-vehicle models (the 2-dof bogie and the coach) share without importing
//! each other:
//! * [`params`]: the parameter error that names the rejected physics field, and the range
//!   checks (finite, positive, non-negative, within bounds) that produce it;
//! * [`step`]: the checks of a step's size and inputs, the error that names the input, and a
//!   host step of any length on the physics;
//! * [`track`]: the FMI-facing choices of the track input (the ERRI B176 level, and the
//!   source through [`track_choice_enum!`]) and their mapping onto the physics'
//!   [`wheel_rail::track::TrackSource`];
//! * [`resources`]: file parameters looked up under the FMU's `resources/` folder first;
//! * [`shell`]: what both FMU shells do alike (inputs, physics built at initialisation and
//!   previewed before, outputs, host step, the physics' step errors under FMI names);
//! * [`substep`]: the shortest internal sub-step the models accept, and the parameter to blame
//!   when a parameter set needs a shorter one;
//! * [`stability`]: the search for a linear critical speed (scan, then bisection) that both
//!   eigen-analyses run;
//! * [`eigenvalues`]: the eigenvalues of a state matrix, balanced and with a bounded
//!   iteration, for both eigen-analyses;
//! * [`damper`]: the linear yaw damper law (none, viscous, Kelvin-Voigt, Maxwell) that the
//!   closed-loop runs evaluate beside a model, co-simulation style, and the coach's
//!   eigen-analysis takes; the loop itself.
//!
//! Wheel/rail contact and the track generator are physics of contact and live in `wheel-rail`.

pub mod damper;
pub mod eigenvalues;
pub mod params;
pub mod resources;
pub mod shell;
pub mod stability;
pub mod step;
pub mod substep;
pub mod track;

pub use damper::{run_closed_loop, ClosedLoopModel, LinearDamper};
pub use params::{finite, in_range, non_negative, positive, ParamError};
pub use resources::resource_or_given;
pub use shell::{Shell, ShellPhysics};
pub use stability::{first_unstable_speed, Crossing};
pub use step::{
    check_inputs, check_step, host_step, substep_count, InputError, MAX_HOST_STEP_S, MAX_STEP_S,
    MAX_SUBSTEPS,
};
pub use substep::{blame, blame_substep, check_substep, stable_substep, TooStiff, MIN_SUBSTEP_S};
pub use track::{TrackChoiceSource, TrackLevel, TrackSetting};
