//! Closed-loop helper: the bogie with a simple yaw damper law evaluated in the loop
//! (co-simulation style: damper forces from the outputs of the previous step, held over the
//! step). Used by the tests (R7) and handy for the master; the coupled-FMU check with the
//! hydraulic damper happens elsewhere.

use serde::{Deserialize, Serialize};

use crate::model::{Bogie, Inputs, Outputs, StepError};

/// A yaw damper law per damper (both dampers identical).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum LoopDamper {
    /// No damper.
    None,
    /// F = k e + c e'.
    KelvinVoigt {
        /// Stiffness [N/m].
        k: f64,
        /// Damping [N s/m].
        c: f64,
    },
    /// Spring k in series with dashpot c: F' = k (e' - F/c).
    Maxwell {
        /// Stiffness [N/m].
        k: f64,
        /// Damping [N s/m].
        c: f64,
    },
}

/// Damper state (forces of the Maxwell elements).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct LoopDamperState {
    /// Left force [N].
    pub left_n: f64,
    /// Right force [N].
    pub right_n: f64,
}

impl LoopDamper {
    /// Forces for the next step from the current outputs; Maxwell forces are advanced over
    /// h exactly for a constant elongation velocity.
    pub fn forces(&self, o: &Outputs, st: &mut LoopDamperState, h: f64) -> (f64, f64) {
        match *self {
            LoopDamper::None => (0.0, 0.0),
            LoopDamper::KelvinVoigt { k, c } => (
                k * o.damper_left_elongation_m + c * o.damper_left_velocity_mps,
                k * o.damper_right_elongation_m + c * o.damper_right_velocity_mps,
            ),
            LoopDamper::Maxwell { k, c } => {
                let f = (st.left_n, st.right_n);
                let a = (-k * h / c).exp();
                st.left_n = f.0 * a + c * o.damper_left_velocity_mps * (1.0 - a);
                st.right_n = f.1 * a + c * o.damper_right_velocity_mps * (1.0 - a);
                // force held over the step: midpoint of the exact solution
                (0.5 * (f.0 + st.left_n), 0.5 * (f.1 + st.right_n))
            }
        }
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
    let mut st = LoopDamperState::default();
    let mut inputs = Inputs {
        track_lateral_m: track_lateral_m(bogie.time_s()),
        ..Inputs::default()
    };
    let mut out = bogie.outputs(&inputs)?;
    record(&out);
    let n = (t_end / h).round() as usize;
    for _ in 0..n {
        let (fl, fr) = damper.forces(&out, &mut st, h);
        inputs.damper_left_force_n = fl;
        inputs.damper_right_force_n = fr;
        inputs.track_lateral_m = track_lateral_m(bogie.time_s());
        out = bogie.step(h, &inputs)?;
        record(&out);
    }
    Ok(())
}
