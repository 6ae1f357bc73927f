//! Closed loop with a linear yaw-damper law evaluated beside the model, co-simulation style
//! (each damper's force from the outputs of the previous step, held over the step). Used by
//! the calibration and convergence tests; the coupled runs with the hydraulic damper FMUs
//! happen in the master.

use serde::{Deserialize, Serialize};

use crate::layout::N_DAMPERS;
use crate::model::{Inputs, Outputs, StepError, Vehicle};

/// A yaw damper law (all four identical).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum LoopDamper {
    /// No damper.
    None,
    /// Spring k in series with dashpot c: F' = k (e' - F / c), advanced exactly over a step
    /// for a constant elongation velocity; the force held over the step is the mean of its
    /// values at the step ends.
    Maxwell {
        /// Stiffness [N/m].
        k: f64,
        /// Damping [N s/m].
        c: f64,
    },
}

/// Forces of the Maxwell elements.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct LoopDamperState {
    /// Force of each damper [N].
    pub force_n: [f64; N_DAMPERS],
}

impl LoopDamper {
    /// Forces for the next step of length h from the current outputs.
    pub fn forces(&self, o: &Outputs, st: &mut LoopDamperState, h: f64) -> [f64; N_DAMPERS] {
        match *self {
            LoopDamper::None => [0.0; N_DAMPERS],
            LoopDamper::Maxwell { k, c } => {
                let a = (-k * h / c).exp();
                let mut held = [0.0; N_DAMPERS];
                for (d, f) in st.force_n.iter_mut().enumerate() {
                    let old = *f;
                    *f = old * a + c * o.damper[d].elongation_velocity_mps * (1.0 - a);
                    held[d] = 0.5 * (old + *f);
                }
                held
            }
        }
    }
}

/// Runs `t_end` seconds with communication step h, the track input from `track_lateral_m`
/// (time -> alignment under the leading wheelset); calls `record` with every output.
pub fn run_closed_loop(
    vehicle: &mut Vehicle,
    damper: LoopDamper,
    h: f64,
    t_end: f64,
    track_lateral_m: &dyn Fn(f64) -> f64,
    record: &mut dyn FnMut(&Outputs),
) -> Result<(), StepError> {
    let mut st = LoopDamperState::default();
    let mut inputs = Inputs {
        track_lateral_m: track_lateral_m(vehicle.time_s()),
        ..Inputs::default()
    };
    let mut out = vehicle.outputs(&inputs)?;
    record(&out);
    let n = (t_end / h).round() as usize;
    for _ in 0..n {
        inputs.damper_force_n = damper.forces(&out, &mut st, h);
        inputs.track_lateral_m = track_lateral_m(vehicle.time_s());
        out = vehicle.step(h, &inputs)?;
        record(&out);
    }
    Ok(())
}
