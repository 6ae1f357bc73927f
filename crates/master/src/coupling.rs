//! Fixed-step co-simulation of several slaves (FMI 2.0 co-simulation semantics).
//!
//! * Communication points are `t_k = t0 + k*h` computed from `k` each time (no accumulated
//!   drift); the last point is exactly the stop time. A slave with step multiple `m` steps at
//!   every `m`-th point over `[t_k, t_min(k+m, N)]`. The master always passes its own `t_k`
//!   to fmi2DoStep, so an FMU whose internal clock drifts by round-off is not rejected here.
//! * Jacobi: all slaves step from the same inputs, then all outputs are exchanged.
//!   Gauss-Seidel: slaves step in `order`; the outputs of each step reach the connected
//!   inputs before their instance's next call, so later slaves see them (sample and hold
//!   between points). Inputs that feed through to a connected output are written at once and
//!   that output read again; the Real inputs of other instances may be written later, just
//!   before the instance's next call, merged into one call per instance (same values at
//!   every call, so the same results).
//! * Initialisation (FMI 2.0 section 4.2.4): setupExperiment, parameters, enterInitializationMode,
//!   `init_sweeps` fixed-point sweeps that copy connected outputs to inputs (stops early when
//!   nothing changes), exitInitializationMode, one more exchange, first record at `t0`.
//! * Step rejection: when a slave returns fmi2Discard and `max_step_halvings > 0` and every
//!   slave can get/set its FMU state, all slaves are reset to the state saved before the macro
//!   step and the step is redone as 2, 4, ... sub-steps (each active slave's step split into
//!   equal parts, data exchanged after every part), up to `max_step_halvings` times; not when a
//!   slave lacks canHandleVariableCommunicationStepSize (its step must stay constant).
//! * A slave without canHandleVariableCommunicationStepSize is only accepted when its
//!   `step_multiple` divides the number of steps (no shortened last window).
//! * Termination requested by a slave: a step that returns fmi2Discard while
//!   fmi2GetBooleanStatus(fmi2Terminated) is true ends the run normally (FMI 2.0 section
//!   4.2.3), never retried: every slave is terminated, the results stop at the last
//!   communication point all completed, and the summary names the slave and that time.
//! * Recording reads every recorded variable at each point, except a connected output whose
//!   slave has had no call that can change a value (set, step, FMU state restore, mode change)
//!   since it was read for the exchange: the row takes that value (what a second read returns).
//! * Every exit path (success, error, cancellation) calls fmi2Terminate on each slave that
//!   reached step mode (exitInitializationMode) and did not report fmi2Fatal; freeing
//!   (fmi2FreeInstance, allowed in every state) is the slaves' `Drop`.

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use crate::slave::Slave;

use engine::Engine;
use exchange::Exchange;

mod engine;
mod exchange;
mod plan;

pub use plan::{
    check_plan, step_below_resolution, topological_order, Algorithm, ColumnInfo, CouplingPlan,
    Failure, PlanConnection, PlanInstance, Recorded, RunLimits, SimError, SimOutput, Summary,
    Terminated, UnitConversion, MAX_RECORDED_VALUES_VAR, MAX_STEPS_VAR,
};

/// Options of one run.
#[derive(Default)]
pub struct RunOptions<'a> {
    /// Checked at every communication point (e.g. set by a Ctrl-C handler).
    pub cancel: Option<&'a AtomicBool>,
    /// Called after every macro step with (steps done, total steps).
    pub progress: Option<&'a dyn Fn(u64, u64)>,
    /// Run every macro step through the general engine, never the precompiled one of the
    /// common case (Gauss-Seidel, every instance stepping at every point, no step retry, no
    /// String exchanged): the same results bit for bit, for comparing the two.
    pub general_engine: bool,
}

/// FMI 2.0 (4.3.1): a slave without canHandleVariableCommunicationStepSize must always be
/// stepped with the same step. Its window is `step_multiple` steps, so the last window is
/// shorter unless the multiple divides the number of steps: refused before any call.
fn check_step_sizes(
    plan: &CouplingPlan,
    slaves: &[&mut dyn Slave],
    n_steps: u64,
) -> Result<(), SimError> {
    for (inst, s) in plan.instances.iter().zip(slaves.iter()) {
        let m = u64::from(inst.step_multiple.max(1));
        if !s.can_vary_step() && !n_steps.is_multiple_of(m) {
            return Err(SimError::Plan(format!(
                "instance '{}' does not support canHandleVariableCommunicationStepSize, but its \
                 step_multiple {m} does not divide the {n_steps} communication steps, so its last \
                 step would be shorter; choose a step_multiple that divides {n_steps}",
                s.name()
            )));
        }
    }
    Ok(())
}

/// Runs the plan on the given slaves (same order as `plan.instances`). The slaves are
/// terminated on every path; freeing them is left to their owner (drop).
pub fn simulate(
    plan: &CouplingPlan,
    slaves: &mut [&mut dyn Slave],
    opts: &RunOptions,
) -> Result<SimOutput, SimError> {
    simulate_with(plan, slaves, opts, !opts.general_engine).map_err(|f| f.error)
}

/// A run that failed: its error, and the history recorded before the failure (up to the last
/// communication point every instance completed, its summary's `failed` set); `None` when
/// the run failed before its first row, or was cancelled (stopped, not failed: Ctrl-C
/// replaces no result with a history).
#[derive(Debug)]
pub struct FailedRun<E> {
    pub error: E,
    pub history: Option<Box<SimOutput>>,
}

impl<E> FailedRun<E> {
    /// The same failure with the error converted.
    pub fn map<F>(self, f: impl FnOnce(E) -> F) -> FailedRun<F> {
        FailedRun {
            error: f(self.error),
            history: self.history,
        }
    }
}

impl<E> From<E> for FailedRun<E> {
    fn from(error: E) -> Self {
        FailedRun {
            error,
            history: None,
        }
    }
}

/// [`simulate`], keeping the history of a run that fails.
pub fn simulate_keeping_history(
    plan: &CouplingPlan,
    slaves: &mut [&mut dyn Slave],
    opts: &RunOptions,
) -> Result<SimOutput, FailedRun<SimError>> {
    simulate_with(plan, slaves, opts, !opts.general_engine)
}

fn simulate_with(
    plan: &CouplingPlan,
    slaves: &mut [&mut dyn Slave],
    opts: &RunOptions,
    fast: bool,
) -> Result<SimOutput, FailedRun<SimError>> {
    let n_steps = check_plan(plan, slaves.len())?;
    check_step_sizes(plan, slaves, n_steps)?;
    let started = Instant::now();
    let exchange = Exchange::new(plan);
    let mut eng = Engine::new(plan, &exchange, slaves, opts, n_steps, fast);
    let mut data = Vec::new();
    let res = eng.run(&mut data);
    let width = plan.record.len() + 1;
    let last_row_time = |data: &[f64]| data.len().checked_sub(width).map(|k| data[k]);
    let term = eng.terminate_all(last_row_time(&data).unwrap_or(plan.start_time));
    let error = match (res, term) {
        (Err(e), Err(t)) => {
            // the run's error is the one reported; the other is not lost
            log::warn!(target: "master", "after the run failed, {t}");
            e
        }
        (Err(e), Ok(())) | (Ok(()), Err(e)) => e,
        (Ok(()), Ok(())) => {
            let terminated = eng.terminated().map(|(i, t)| Terminated {
                instance: plan.instances[i].name.clone(),
                time_s: t,
            });
            let end = terminated.as_ref().map_or(plan.stop_time, |t| t.time_s);
            let strings = eng.take_strings();
            let rejected = eng.rejected();
            let summary = summary(plan, n_steps, end, started, rejected, terminated, None);
            return Ok(output(plan, data, strings, summary));
        }
    };
    let cancelled = matches!(error, SimError::Cancelled { .. });
    let history = last_row_time(&data).filter(|_| !cancelled).map(|end| {
        let failure = Failure {
            time_s: end,
            error: error.to_string(),
        };
        let strings = eng.take_strings();
        let summary = summary(
            plan,
            n_steps,
            end,
            started,
            eng.rejected(),
            // an FMU that ended the run before fmi2Terminate failed: said too
            eng.terminated().map(|(i, t)| Terminated {
                instance: plan.instances[i].name.clone(),
                time_s: t,
            }),
            Some(failure),
        );
        Box::new(output(plan, data, strings, summary))
    });
    Err(FailedRun { error, history })
}

/// The statistics of a run that ended at `end` \[s\].
fn summary(
    plan: &CouplingPlan,
    n_steps: u64,
    end: f64,
    started: Instant,
    rejected_steps: u64,
    terminated: Option<Terminated>,
    failed: Option<Failure>,
) -> Summary {
    let wall = started.elapsed().as_secs_f64();
    let sim = end - plan.start_time;
    let steps = (sim / plan.step).round() as u64;
    Summary {
        terminated,
        failed,
        steps: steps.min(n_steps),
        rejected_steps,
        simulated_time_s: sim,
        wall_time_s: wall,
        realtime_ratio: if wall > 0.0 {
            sim / wall
        } else {
            f64::INFINITY
        },
    }
}

fn output(
    plan: &CouplingPlan,
    data: Vec<f64>,
    strings: Vec<String>,
    summary: Summary,
) -> SimOutput {
    let mut header = vec!["time [s]".to_string()];
    header.extend(plan.record.iter().map(|r| r.label.clone()));
    SimOutput {
        header,
        data,
        columns: plan.record.iter().map(|r| r.info.clone()).collect(),
        strings,
        decimation: None,
        summary,
    }
}

#[cfg(test)]
pub(crate) mod tests;
