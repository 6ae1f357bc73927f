//! Closed-loop helper: the bogie with the stand-in yaw damper law of `vehicle-elements`
//! evaluated in the loop (co-simulation style: damper forces from the outputs of the previous
//! step, held over the step). Used by the tests (R7) and handy for the master; the coupled-FMU
//! check with the hydraulic damper happens elsewhere.

pub use vehicle_elements::LoopDamper;
use vehicle_elements::{damper, ClosedLoopModel};

use crate::model::{Bogie, Inputs, Outputs, StepError};

/// The bogie's two yaw-damper ports (left, right) in the closed loop.
impl ClosedLoopModel<2> for Bogie {
    type Inputs = Inputs;
    type Outputs = Outputs;
    type Error = StepError;

    fn time_s(&self) -> f64 {
        Bogie::time_s(self)
    }

    fn outputs(&self, inputs: &Inputs) -> Result<Outputs, StepError> {
        Bogie::outputs(self, inputs)
    }

    fn step(&mut self, h_s: f64, inputs: &Inputs) -> Result<Outputs, StepError> {
        Bogie::step(self, h_s, inputs)
    }

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

/// Runs `t_end` seconds with communication step h; calls `record` with every output.
pub fn run_closed_loop(
    bogie: &mut Bogie,
    damper: LoopDamper,
    h: f64,
    t_end: f64,
    track_lateral_m: &dyn Fn(f64) -> f64,
    record: &mut dyn FnMut(&Outputs),
) -> Result<(), StepError> {
    damper::run_closed_loop(bogie, damper, h, t_end, track_lateral_m, record)
}
