//! Reference workloads of the bogie for benchmarks (no timing in tests: the figures come from
//! `cargo bench -p fmu-bogie2dof --bench realtime_factor` or from any bench command that calls
//! [`realtime_factor`]).
//!
//! The reference run: non-linear model, default contact table (worn-profile surrogate),
//! 320 km/h, 3 mm initial lateral displacement (flange-root limit cycle), the passive damper's
//! Maxwell stand-in fed back through the damper-force inputs ([`crate::sim`]), 1 ms
//! communication steps, on the ideal track or on the internal ERRI B176 high-level track
//! (seed 1). The Maxwell element costs a few floating-point operations per step, so the figure
//! is the bogie's own cost.

use std::time::Instant;

use crate::calibration::{PASSIVE_MAXWELL_C_NS_PER_M, PASSIVE_MAXWELL_K_N_PER_M};
use crate::model::{Bogie, ModelError, StepError};
use crate::params::{Params, PsdLevel, TrackSource};
use crate::sim::{run_closed_loop, LinearDamper};

/// Communication step of the reference run \[s\].
pub const REFERENCE_STEP_S: f64 = 1e-3;

/// Track of the reference run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReferenceTrack {
    /// Ideal straight track.
    Ideal,
    /// Internal ERRI B176 generator, high level, seed 1.
    InternalIrregular,
}

/// Parameters of the reference run on `track`.
pub fn reference_params(track: ReferenceTrack) -> Params {
    Params {
        speed_mps: 320.0 / 3.6,
        initial_lateral_m: 3e-3,
        track: match track {
            ReferenceTrack::Ideal => TrackSource::None,
            ReferenceTrack::InternalIrregular => TrackSource::Internal {
                level: PsdLevel::High,
                seed: 1,
            },
        },
        ..Params::default()
    }
}

/// Errors of a reference run.
#[derive(Debug, thiserror::Error)]
pub enum PerfError {
    /// The model could not be built.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// A step failed.
    #[error(transparent)]
    Step(#[from] StepError),
}

/// Builds the reference bogie (table parsing and track synthesis included).
pub fn reference_bogie(track: ReferenceTrack) -> Result<Bogie, PerfError> {
    Ok(Bogie::new(reference_params(track))?)
}

/// Runs `bogie` for `sim_seconds` with the reference damper and step; returns the final lateral
/// displacement (so the work cannot be optimised away). Never inlined, so a profiler can
/// select it by name (`valgrind --tool=callgrind --toggle-collect='*simulate_reference*'`).
#[inline(never)]
pub fn simulate_reference(bogie: &mut Bogie, sim_seconds: f64) -> Result<f64, PerfError> {
    let damper = LinearDamper::Maxwell {
        k: PASSIVE_MAXWELL_K_N_PER_M,
        c: PASSIVE_MAXWELL_C_NS_PER_M,
    };
    run_closed_loop(
        bogie,
        damper,
        REFERENCE_STEP_S,
        sim_seconds,
        &|_| 0.0,
        &mut |_| {},
    )?;
    Ok(bogie.state()[0])
}

/// Real-time factor (simulated seconds per wall-clock second) of the reference run on one
/// core: the median of `repeats` runs of `sim_seconds` each, every run on a freshly built
/// model (construction not timed).
pub fn realtime_factor(
    track: ReferenceTrack,
    sim_seconds: f64,
    repeats: usize,
) -> Result<f64, PerfError> {
    let mut factors = Vec::with_capacity(repeats.max(1));
    for _ in 0..repeats.max(1) {
        let mut bogie = reference_bogie(track)?;
        let start = Instant::now();
        std::hint::black_box(simulate_reference(&mut bogie, sim_seconds)?);
        let wall = start.elapsed().as_secs_f64();
        factors.push(sim_seconds / wall.max(1e-12));
    }
    factors.sort_by(f64::total_cmp);
    Ok(factors[factors.len() / 2])
}
