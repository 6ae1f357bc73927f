//! Closed-loop helper: the bogie with the stand-in yaw damper law of `vehicle-elements`
//! evaluated in the loop (co-simulation style: damper forces from the outputs of the previous
//! step, held over the step). Used by the tests (R7) and handy for the master; the coupled-FMU
//! check with the hydraulic damper happens elsewhere.

use vehicle_elements::ClosedLoopModel;
pub use vehicle_elements::{run_closed_loop, LinearDamper};

use crate::model::{Bogie, Inputs, Outputs, StepError};

/// The bogie's two yaw-damper ports (left, right) in the closed loop.
impl ClosedLoopModel<2> for Bogie {
    vehicle_elements::forward_stepping!(Bogie, Inputs, Outputs, StepError);

    fn set_track_lateral_m(inputs: &mut Inputs, track_lateral_m: f64) {
        inputs.track_lateral_m = track_lateral_m;
    }

    fn damper_motion(o: &Outputs) -> [(f64, f64); 2] {
        [
            (o.damper_left_elongation_m, o.damper_left_velocity_mps),
            (o.damper_right_elongation_m, o.damper_right_velocity_mps),
        ]
    }

    fn set_damper_force_n(inputs: &mut Inputs, [left_n, right_n]: [f64; 2]) {
        inputs.damper_left_force_n = left_n;
        inputs.damper_right_force_n = right_n;
    }
}
