//! Closed loop with the stand-in yaw damper law of `vehicle-elements` evaluated beside the
//! model, co-simulation style (each damper's force from the outputs of the previous step,
//! held over the step). Used by the calibration and convergence tests; the coupled runs with
//! the hydraulic damper FMUs happen in the master.

use vehicle_elements::ClosedLoopModel;
pub use vehicle_elements::{run_closed_loop, LinearDamper};

use crate::layout::N_DAMPERS;
use crate::model::{Inputs, Outputs, StepError, Vehicle};

/// The coach's four yaw-damper ports (front left, front right, rear left, rear right).
impl ClosedLoopModel<N_DAMPERS> for Vehicle {
    vehicle_elements::forward_stepping!(Vehicle, Inputs, Outputs, StepError);

    fn set_track_lateral_m(inputs: &mut Inputs, track_lateral_m: f64) {
        inputs.track_lateral_m = track_lateral_m;
    }

    fn damper_motion(o: &Outputs) -> [(f64, f64); N_DAMPERS] {
        o.damper
            .map(|d| (d.elongation_m, d.elongation_velocity_mps))
    }

    fn set_damper_force_n(inputs: &mut Inputs, force_n: [f64; N_DAMPERS]) {
        inputs.damper_force_n = force_n;
    }
}
