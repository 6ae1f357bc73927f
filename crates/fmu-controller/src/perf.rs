//! Reference workloads of the control boards for benchmarks (the figures come from
//! `cargo bench -p fmu-controller --bench per_step` or from any bench command that calls
//! [`ns_per_step`]; tests never time anything).
//!
//! Each case steps one board with 1 ms communication steps (one board sample per step) on the
//! signals of a hunting bogie: lateral acceleration 4 m/s^2 at 4 Hz plus a 0.5 m/s^2 ripple at
//! 17 Hz, damper elongation velocity 75 mm/s at 4 Hz (3 mm stroke) in quadrature, damper force
//! 10 kN in phase with the velocity.

use std::f64::consts::PI;

use model_description::timing::median_ns_per_step;

use crate::idf::{Idf, IdfInputs, IdfParams};
use crate::mppt::{Mppt, MpptInputs, MpptParams};
use crate::skyhook::{SkyHook, SkyHookInputs, SkyHookMode, SkyHookParams};
use crate::{ParamError, StepError};

/// Communication step of the reference cases \[s\].
pub const REFERENCE_STEP_S: f64 = 1e-3;

/// One reference case.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ControllerCase {
    /// MPPT2 (k_acc = 1, k_F = 4).
    Mppt2,
    /// Sky-hook on/off, velocity estimated from the acceleration.
    SkyHookOnOff,
    /// Sky-hook continuous, velocity estimated from the acceleration.
    SkyHookContinuous,
    /// Ideal damper force controller.
    Idf,
}

impl ControllerCase {
    /// Every case, in report order.
    pub const ALL: [ControllerCase; 4] = [
        ControllerCase::Mppt2,
        ControllerCase::SkyHookOnOff,
        ControllerCase::SkyHookContinuous,
        ControllerCase::Idf,
    ];

    /// Short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            ControllerCase::Mppt2 => "MPPT2",
            ControllerCase::SkyHookOnOff => "sky-hook on/off",
            ControllerCase::SkyHookContinuous => "sky-hook continuous",
            ControllerCase::Idf => "ideal damper force",
        }
    }
}

/// (lateral acceleration [m/s^2], elongation velocity [m/s], damper force \[N\]) at step `k`.
pub fn signals(k: u64) -> (f64, f64, f64) {
    let t = k as f64 * REFERENCE_STEP_S;
    let (w1, w2) = (2.0 * PI * 4.0, 2.0 * PI * 17.0);
    let acc = 4.0 * (w1 * t).sin() + 0.5 * (w2 * t).sin();
    let vel = 0.075 * (w1 * t).cos();
    (acc, vel, 10e3 * (w1 * t).cos())
}

/// Length of the precomputed input sequence (5 s; it repeats after that) \[steps\].
pub const INPUT_STEPS: usize = 5000;

/// The board of one case, ready to step, and its precomputed input signals (so the measured
/// loop holds no trigonometry).
#[derive(Debug, Clone)]
pub struct ControllerWorkload {
    board: Board,
    signals: Vec<(f64, f64, f64)>,
}

// Held inline, as an FMU instance holds its board (no indirection in the measured loop).
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone)]
enum Board {
    Mppt(Mppt),
    SkyHook(SkyHook),
    Idf(Idf),
}

/// Errors of a reference run.
#[derive(Debug, thiserror::Error)]
pub enum PerfError {
    /// The board could not be built.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// A step failed.
    #[error(transparent)]
    Step(#[from] StepError),
}

impl ControllerWorkload {
    /// Board of `case` with its default parameters.
    pub fn new(case: ControllerCase) -> Result<Self, PerfError> {
        let sky = |mode| {
            SkyHook::new(SkyHookParams {
                mode,
                ..SkyHookParams::default()
            })
        };
        let board = match case {
            ControllerCase::Mppt2 => Board::Mppt(Mppt::new(MpptParams::mppt2())?),
            ControllerCase::SkyHookOnOff => Board::SkyHook(sky(SkyHookMode::OnOff)?),
            ControllerCase::SkyHookContinuous => Board::SkyHook(sky(SkyHookMode::Continuous)?),
            ControllerCase::Idf => Board::Idf(Idf::new(IdfParams::default())?),
        };
        Ok(Self {
            board,
            signals: (0..INPUT_STEPS as u64).map(signals).collect(),
        })
    }

    /// Steps `k0..k0 + steps` (signals of step k: entry k mod [`INPUT_STEPS`]); returns the
    /// sum of the commands (keeps the work observable).
    #[inline(never)]
    pub fn run_steps(&mut self, k0: u64, steps: u64) -> Result<f64, PerfError> {
        let mut sum = 0.0;
        for k in k0..k0 + steps {
            let (acc, vel, force) = self.signals[(k % INPUT_STEPS as u64) as usize];
            sum += match &mut self.board {
                Board::Mppt(m) => {
                    let i = MpptInputs {
                        bogie_accel_mps2: acc,
                        damper_force_n: force,
                    };
                    m.step(REFERENCE_STEP_S, &i)?.command_v
                }
                Board::SkyHook(s) => {
                    let i = SkyHookInputs {
                        sensor_accel_mps2: acc,
                        abs_velocity_mps: 0.0,
                        elongation_velocity_mps: vel,
                    };
                    s.step(REFERENCE_STEP_S, &i)?.command_v
                }
                Board::Idf(c) => {
                    let i = IdfInputs {
                        elongation_velocity_mps: vel,
                        measured_force_n: 0.9 * force,
                    };
                    c.step(REFERENCE_STEP_S, &i)?.spool_command_m
                }
            };
        }
        Ok(sum)
    }
}

/// Warm-up before timing: 2 s (two MPPT updates).
pub const WARM_UP_STEPS: u64 = 2000;

/// Wall-clock nanoseconds per 1 ms step of `case` on one core: the median of `repeats` runs of
/// `steps` steps each, after [`WARM_UP_STEPS`] untimed steps on the same board.
pub fn ns_per_step(case: ControllerCase, steps: u64, repeats: usize) -> Result<f64, PerfError> {
    let mut board = ControllerWorkload::new(case)?;
    board.run_steps(0, WARM_UP_STEPS)?;
    median_ns_per_step(WARM_UP_STEPS, steps, repeats, |k0, n| {
        board.run_steps(k0, n)
    })
}
