//! Yaw-damper control laws of the seed's section 3.2, as plain discrete-time Rust (no FMI).
//!
//! * [`mppt::Mppt`]: maximum power point tracking of the semi-active by-pass valve, (3.2)-(3.5).
//! * [`skyhook::SkyHook`]: continuous (3.11) and on/off (3.13) sky-hook of the semi-active damper,
//!   with the practical absolute-velocity estimate of section 2.3.2.
//! * [`idf::Idf`]: ideal damper force controller of the full-active actuator, (3.14)-(3.15).
//!
//! [`fmu`] wraps each law as an FMI 2.0 co-simulation model (`MpptController`,
//! `SkyHookController`, `IdealDamperForceController`), exported from this crate's one binary
//! with the `fmi-export` feature.
//!
//! # Timing (common to all laws)
//! Every controller is a sampled "board" with its own sample time `sample_time_s`. The host calls
//! `step(h, inputs)` for the communication interval `[t, t+h)`; the inputs are held constant (zero-order
//! hold) over that interval and the controller executes every sample instant `t_k = k * sample_time_s`
//! with `t <= t_k < t + h` (instants within 1e-6 sample times of `t + h` belong to the next call).
//! The command computed from the inputs sampled at `t_k` is applied (becomes the output) at
//! `t_{k+1}`: one board sample of computational delay, like a real controller, and held until
//! `t_{k+2}`. The output seen by the host at `t + h` is therefore the command applied at the last
//! sample instant `<= t + h`. As long as the host's grid contains the sample instants (h divides
//! the sample time, e.g. 1e-4 or 1e-3 s with a 1 ms board) the controller sees and produces exactly
//! the same sampled signals whatever h is, also in closed loop; with coarser host steps the inputs
//! are held over the host step (the only remaining dependence on h).
//!
//! # Sign conventions (shared with the damper and actuator models)
//! * damper elongation `x` positive = extension; elongation velocity `v = dx/dt`;
//! * damper/actuator force positive = tension (pulls the two ends together), so a passive viscous
//!   damper gives `F = +c v`;
//! * valve command in volts, 0 V = by-pass valve closed (maximum damping), 10 V = fully open
//!   (seed section 4.4.1); opening = command / 10 V.
//!
//! # Non-finite inputs
//! A real control board keeps running when a sensor reads garbage. With the default
//! [`NanPolicy::HoldAndWarn`] a sample with a NaN/inf input is dropped (filters and windows are not
//! fed), the last valid command is held and the outputs carry `input_fault = true` plus a running
//! count of dropped samples, which the shell can log. [`NanPolicy::Error`] makes `step` return
//! [`StepError::NonFiniteInput`] instead (the general project rule).

pub mod fmu;
pub mod idf;
pub mod mppt;
pub mod perf;
pub mod signal;
pub mod skyhook;

use serde::{Deserialize, Serialize};
use thiserror::Error;

pub use idf::{Idf, IdfInputs, IdfOutputs, IdfParams};
pub use mppt::{ForceNormaliser, Mppt, MpptInputs, MpptOutputs, MpptParams};
pub use skyhook::{
    DampingTable, SkyHook, SkyHookInputs, SkyHookMode, SkyHookOutputs, SkyHookParams,
    VelocitySource, DAMPING_TABLE_4HZ,
};

/// A parameter is invalid; names the parameter and the reason.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("invalid parameter `{name}`: {reason}")]
pub struct ParamError {
    /// Field name in the `*Params` struct.
    pub name: &'static str,
    /// Human readable reason.
    pub reason: String,
}

impl ParamError {
    pub(crate) fn new(name: &'static str, reason: impl Into<String>) -> Self {
        Self {
            name,
            reason: reason.into(),
        }
    }
}

/// Errors of `step`.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum StepError {
    /// The communication step is negative, NaN or infinite.
    #[error("invalid communication step h = {0}")]
    InvalidStep(f64),
    /// A used input is NaN/inf and the policy is [`NanPolicy::Error`].
    #[error("non-finite input `{name}` = {value}")]
    NonFiniteInput { name: &'static str, value: f64 },
    /// An output became NaN/inf (should not happen; guards the host against garbage).
    #[error("non-finite output `{name}` = {value}")]
    NonFiniteOutput { name: &'static str, value: f64 },
    /// The step holds more board samples than one step may compute (its cost is bounded).
    #[error(
        "the step holds {samples:e} board samples, more than {MAX_SAMPLES_PER_STEP} \
         (communication step / board.sample_time): use a shorter communication step"
    )]
    TooManySamples { samples: f64 },
}

/// Shortest board sample time \[s\] (a 1 MHz board): a shorter one would make every step cost
/// more samples than any board computes.
pub const MIN_SAMPLE_TIME_S: f64 = 1e-6;

/// Most board samples one communication step computes: 10 s of a 1 MHz board, about a second
/// of work; a longer step is refused before anything changes.
pub const MAX_SAMPLES_PER_STEP: u64 = 10_000_000;

/// The board sample time is finite and at least [`MIN_SAMPLE_TIME_S`].
pub(crate) fn check_sample_time(v: f64) -> Result<(), ParamError> {
    check_finite_pos("sample_time_s", v)?;
    if v < MIN_SAMPLE_TIME_S {
        return Err(ParamError::new(
            "sample_time_s",
            format!("must be at least {MIN_SAMPLE_TIME_S} s, got {v}"),
        ));
    }
    Ok(())
}

/// What to do with a NaN/inf sensor input.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum NanPolicy {
    /// Drop the sample, hold the last valid command and raise `input_fault` (board behaviour).
    #[default]
    HoldAndWarn,
    /// Return [`StepError::NonFiniteInput`].
    Error,
}

pub(crate) fn check_finite_pos(name: &'static str, v: f64) -> Result<(), ParamError> {
    if !v.is_finite() {
        return Err(ParamError::new(name, format!("must be finite, got {v}")));
    }
    if v <= 0.0 {
        return Err(ParamError::new(name, format!("must be > 0, got {v}")));
    }
    Ok(())
}

pub(crate) fn check_finite_nonneg(name: &'static str, v: f64) -> Result<(), ParamError> {
    if !v.is_finite() {
        return Err(ParamError::new(name, format!("must be finite, got {v}")));
    }
    if v < 0.0 {
        return Err(ParamError::new(name, format!("must be >= 0, got {v}")));
    }
    Ok(())
}

pub(crate) fn check_sign(name: &'static str, v: f64) -> Result<(), ParamError> {
    if v == 1.0 || v == -1.0 {
        Ok(())
    } else {
        Err(ParamError::new(name, format!("must be +1 or -1, got {v}")))
    }
}

/// The first check of every board step: the communication step `h` must be finite and
/// non-negative, and the inputs the law uses finite. `Ok(false)`: an input is not, and the
/// sample is dropped ([`NanPolicy::HoldAndWarn`]); with [`NanPolicy::Error`] that is an error
/// naming the input.
pub(crate) fn screen_step(
    h: f64,
    inputs: &[(&'static str, f64)],
    policy: NanPolicy,
) -> Result<bool, StepError> {
    if !h.is_finite() || h < 0.0 {
        return Err(StepError::InvalidStep(h));
    }
    match (inputs.iter().find(|(_, v)| !v.is_finite()), policy) {
        (None, _) => Ok(true),
        (Some(&(name, value)), NanPolicy::Error) => Err(StepError::NonFiniteInput { name, value }),
        (Some(_), NanPolicy::HoldAndWarn) => Ok(false),
    }
}

/// The last check of every board step: its real outputs are finite (guards the host).
pub(crate) fn check_outputs(outputs: &[(&'static str, f64)]) -> Result<(), StepError> {
    match outputs.iter().find(|(_, v)| !v.is_finite()) {
        None => Ok(()),
        Some(&(name, value)) => Err(StepError::NonFiniteOutput { name, value }),
    }
}

/// What the common end of a board step needs of a controller's outputs.
pub(crate) trait BoardOutputs: Copy {
    /// Records the screening of the step's inputs.
    fn set_input_status(&mut self, input_fault: bool, dropped_samples: u64);
    /// The last check of the step: the real outputs are finite ([`check_outputs`]).
    fn check_finite(&self) -> Result<(), StepError>;
}

/// Implements [`BoardOutputs`] for an outputs struct with the fields `input_fault` and
/// `dropped_samples`, checking the listed real outputs (named by their field) for finiteness.
macro_rules! board_outputs {
    ($outputs:ty: $($real:ident),+ $(,)?) => {
        impl $crate::BoardOutputs for $outputs {
            fn set_input_status(&mut self, input_fault: bool, dropped_samples: u64) {
                self.input_fault = input_fault;
                self.dropped_samples = dropped_samples;
            }

            fn check_finite(&self) -> Result<(), $crate::StepError> {
                $crate::check_outputs(&[$((stringify!($real), self.$real)),+])
            }
        }
    };
}
pub(crate) use board_outputs;

/// The common end of every board step: the command of the previous sample is applied if its
/// instant is now, the input screening is recorded, and the outputs are checked.
pub(crate) fn finish_step<O: BoardOutputs>(
    clock: &SampleClock,
    pending: &O,
    out: &mut O,
    valid: bool,
    dropped_samples: u64,
) -> Result<O, StepError> {
    if clock.at_sample_instant() {
        *out = *pending;
    }
    out.set_input_status(!valid, dropped_samples);
    out.check_finite()?;
    Ok(*out)
}

/// Relative tolerance (in sample times) on sample instants.
const TIME_TOL: f64 = 1e-6;

/// Sample scheduler of a discrete controller: which sample instants fall in `[t, t+h)`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SampleClock {
    /// Board sample time (s).
    pub sample_time_s: f64,
    /// Current time (s), the start of the next communication interval.
    pub time_s: f64,
    /// Index of the next sample instant not yet executed.
    pub next_sample: u64,
    /// Kahan compensation of `time_s` (a host doing 1e5 steps of 1e-4 s would otherwise drift by
    /// ~1e-10 s and move samples across step boundaries).
    #[serde(default)]
    time_comp: f64,
}

impl SampleClock {
    /// Clock starting at t = 0 whose first sample is at t = 0.
    pub fn new(sample_time_s: f64) -> Self {
        Self {
            sample_time_s,
            time_s: 0.0,
            next_sample: 0,
            time_comp: 0.0,
        }
    }

    /// Advance the clock by `h`; returns how many sample instants lie in `[t, t+h)`. More than
    /// [`MAX_SAMPLES_PER_STEP`] is an error that leaves the clock as it was.
    pub fn advance(&mut self, h: f64) -> Result<u64, StepError> {
        if !h.is_finite() || h < 0.0 {
            return Err(StepError::InvalidStep(h));
        }
        // Kahan-compensated t + h.
        let y = h - self.time_comp;
        let t_end = self.time_s + y;
        self.time_comp = (t_end - self.time_s) - y;
        // Tolerance so that residual round-off of t never moves a sample across a boundary.
        let eps = TIME_TOL * self.sample_time_s;
        // Largest k with k*Ts < t_end - eps, i.e. samples strictly before the end.
        let limit = (t_end - eps) / self.sample_time_s;
        let last_excl = if limit <= 0.0 {
            0
        } else {
            // ceil gives the first index not before the limit.
            limit.ceil() as u64
        };
        let n = last_excl.saturating_sub(self.next_sample);
        if n > MAX_SAMPLES_PER_STEP {
            // counted in floating point: the integer count saturates for a huge step
            let samples = limit.ceil() - self.next_sample as f64;
            return Err(StepError::TooManySamples { samples });
        }
        self.next_sample += n;
        self.time_s = t_end;
        Ok(n)
    }

    /// True when the current time is (within round-off) the next sample instant, i.e. the
    /// command computed at the previous sample is due now.
    pub fn at_sample_instant(&self) -> bool {
        let t_next = self.next_sample as f64 * self.sample_time_s;
        t_next <= self.time_s + TIME_TOL * self.sample_time_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A step's cost is bounded: a sample time of a few ulps (accepted once, it made one 1 ms
    /// step loop for ever) is refused, and a step holding more samples than the bound is an
    /// error that leaves the clock as it was, so a shorter step can follow.
    #[test]
    fn a_step_never_holds_more_samples_than_the_bound() {
        for bad in [1e-310, 1e-12, 0.99e-6] {
            let e = check_sample_time(bad).unwrap_err();
            assert_eq!(e.name, "sample_time_s", "{bad}");
        }
        check_sample_time(MIN_SAMPLE_TIME_S).unwrap();
        let mut c = SampleClock::new(MIN_SAMPLE_TIME_S);
        let before = c.clone();
        let e = c.advance(20.0).unwrap_err();
        assert!(
            matches!(e, StepError::TooManySamples { samples } if samples > MAX_SAMPLES_PER_STEP as f64)
        );
        assert!(e.to_string().contains("shorter communication step"), "{e}");
        assert!(
            e.to_string()
                .starts_with("the step holds 2e7 board samples"),
            "{e}"
        );
        assert_eq!(c, before);
        // a huge step is counted, not saturated to 2^64 - 1
        let e = c.advance(1e300).unwrap_err().to_string();
        assert!(e.contains("e306 board samples, more than 10000000"), "{e}");
        assert_eq!(c.advance(1e-3).unwrap(), 1000);
    }

    #[test]
    fn clock_counts_samples_independent_of_step() {
        let mut a = SampleClock::new(1e-3);
        let mut na = 0;
        for _ in 0..10_000 {
            na += a.advance(1e-4).unwrap();
        }
        let mut b = SampleClock::new(1e-3);
        let mut nb = 0;
        for _ in 0..1_000 {
            nb += b.advance(1e-3).unwrap();
        }
        let mut c = SampleClock::new(1e-3);
        let mut nc = 0;
        for _ in 0..200 {
            nc += c.advance(5e-3).unwrap();
        }
        // [0, 1 s) holds the samples 0..999.
        assert_eq!(na, 1000);
        assert_eq!(nb, 1000);
        assert_eq!(nc, 1000);
        // First call with h = 1e-4 runs the t = 0 sample, next nine run nothing.
        let mut d = SampleClock::new(1e-3);
        assert_eq!(d.advance(1e-4).unwrap(), 1);
        for _ in 0..9 {
            assert_eq!(d.advance(1e-4).unwrap(), 0);
        }
        assert_eq!(d.advance(1e-4).unwrap(), 1);
        // long runs: 1e6 steps of 1e-4 s still give exactly one sample per 10 steps
        let mut e = SampleClock::new(1e-3);
        for k in 0..1_000_000u64 {
            let n = e.advance(1e-4).unwrap();
            assert_eq!(n, u64::from(k % 10 == 0), "step {k}");
        }
        assert!(d.advance(-1.0).is_err());
        assert!(d.advance(f64::NAN).is_err());
    }

    /// FMU state save/restore: a serialised and restored controller continues identically.
    #[test]
    fn state_round_trips_through_serde() {
        let mut m = Mppt::new(MpptParams::mppt2()).unwrap();
        let mut s = SkyHook::new(SkyHookParams::default()).unwrap();
        let mut c = Idf::new(IdfParams::default()).unwrap();
        let drive = |k: usize| (k as f64 * 0.0237).sin();
        for k in 0..2500 {
            let a = 3.0 * drive(k);
            m.step(
                1e-3,
                &MpptInputs {
                    bogie_accel_mps2: a,
                    damper_force_n: 1e3 * a,
                },
            )
            .unwrap();
            s.step(
                1e-3,
                &SkyHookInputs {
                    sensor_accel_mps2: a,
                    abs_velocity_mps: 0.0,
                    elongation_velocity_mps: 0.01 * a,
                },
            )
            .unwrap();
            c.step(
                1e-3,
                &IdfInputs {
                    elongation_velocity_mps: 0.01 * a,
                    measured_force_n: 100.0,
                },
            )
            .unwrap();
        }
        let m2: Mppt = serde_json::from_str(&serde_json::to_string(&m).unwrap()).unwrap();
        let s2: SkyHook = serde_json::from_str(&serde_json::to_string(&s).unwrap()).unwrap();
        let c2: Idf = serde_json::from_str(&serde_json::to_string(&c).unwrap()).unwrap();
        let (mut m2, mut s2, mut c2) = (m2, s2, c2);
        for k in 2500..4000 {
            let a = 3.0 * drive(k);
            let mi = MpptInputs {
                bogie_accel_mps2: a,
                damper_force_n: 1e3 * a,
            };
            assert_eq!(m.step(1e-3, &mi).unwrap(), m2.step(1e-3, &mi).unwrap());
            let si = SkyHookInputs {
                sensor_accel_mps2: a,
                abs_velocity_mps: 0.0,
                elongation_velocity_mps: 0.01 * a,
            };
            assert_eq!(s.step(1e-3, &si).unwrap(), s2.step(1e-3, &si).unwrap());
            let ci = IdfInputs {
                elongation_velocity_mps: 0.01 * a,
                measured_force_n: 100.0,
            };
            assert_eq!(c.step(1e-3, &ci).unwrap(), c2.step(1e-3, &ci).unwrap());
        }
        assert_eq!(m.outputs().updates, 4);
    }
}
