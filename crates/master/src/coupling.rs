//! Fixed-step co-simulation of several slaves (FMI 2.0 co-simulation semantics).
//!
//! * Communication points are `t_k = t0 + k*h` computed from `k` each time (no accumulated
//!   drift); the last point is exactly the stop time. A slave with step multiple `m` steps at
//!   every `m`-th point over `[t_k, t_min(k+m, N)]`. The master always passes its own `t_k`
//!   to fmi2DoStep, so an FMU whose internal clock drifts by round-off is not rejected here.
//! * Jacobi: all slaves step from the same inputs, then all outputs are exchanged.
//!   Gauss-Seidel: slaves step in `order`; after each step its outputs go to the connected
//!   inputs at once, so later slaves see them (sample and hold between points).
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
//! * Every exit path (success, error, cancellation) calls fmi2Terminate on each slave that
//!   reached step mode (exitInitializationMode) and did not report fmi2Fatal; freeing
//!   (fmi2FreeInstance, allowed in every state) is the slaves' `Drop`.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use crate::slave::{FailStatus, Slave, SlaveError, StepStatus, VarBatch, VarRef};

use exchange::{Dest, Exchange};

mod exchange;

/// Coupling algorithm.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Algorithm {
    Jacobi,
    GaussSeidel,
}

#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PlanInstance {
    pub name: String,
    pub step_multiple: u32,
    /// Start values set before initialisation (value reference, value as f64).
    pub parameters: Vec<(VarRef, f64)>,
    /// Names of `parameters` (same order) for messages; may be empty.
    pub parameter_names: Vec<String>,
}

#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PlanConnection {
    pub from_instance: usize,
    pub from: VarRef,
    pub to_instance: usize,
    pub to: VarRef,
    /// "instance.variable" of the source, for messages.
    pub label: String,
}

#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Recorded {
    pub instance: usize,
    pub var: VarRef,
    /// CSV header, e.g. `bogie.wheelset_front.y [m]`.
    pub label: String,
}

/// Everything the coupling algorithm needs, already validated (see [`crate::system`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CouplingPlan {
    pub start_time: f64,
    pub stop_time: f64,
    pub step: f64,
    pub instances: Vec<PlanInstance>,
    pub connections: Vec<PlanConnection>,
    pub algorithm: Algorithm,
    /// Stepping order for Gauss-Seidel (a permutation of the instance indices); also the order
    /// of exchange during initialisation.
    pub order: Vec<usize>,
    pub record: Vec<Recorded>,
    pub init_sweeps: usize,
    pub max_step_halvings: u32,
}

/// Run statistics.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Summary {
    pub steps: u64,
    pub rejected_steps: u64,
    pub simulated_time_s: f64,
    pub wall_time_s: f64,
    /// simulated time / wall time.
    pub realtime_ratio: f64,
}

impl std::fmt::Display for Summary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} steps ({} rejected), {:.3} s simulated in {:.3} s wall time ({:.1}x real time)",
            self.steps,
            self.rejected_steps,
            self.simulated_time_s,
            self.wall_time_s,
            self.realtime_ratio
        )
    }
}

/// Recorded results: `header[0]` is `time [s]`, each row has `header.len()` values.
#[derive(Debug, Clone, PartialEq)]
pub struct SimOutput {
    pub header: Vec<String>,
    pub data: Vec<f64>,
    pub summary: Summary,
}

impl SimOutput {
    pub fn rows(&self) -> impl Iterator<Item = &[f64]> {
        self.data.chunks(self.header.len().max(1))
    }
    /// Column by exact header label or by its name without the unit suffix.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let c = self
            .header
            .iter()
            .position(|h| h == name || h.split(" [").next() == Some(name))?;
        Some(self.rows().map(|r| r[c]).collect())
    }
}

/// Why a simulation stopped.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    #[error("invalid plan: {0}")]
    Plan(String),
    #[error("instance '{instance}': setting start value '{name}' = {value} failed: {source}")]
    StartValue {
        instance: String,
        name: String,
        value: f64,
        #[source]
        source: SlaveError,
    },
    #[error("at t = {time} s: {source}")]
    Slave {
        time: f64,
        #[source]
        source: SlaveError,
    },
    #[error("at t = {time} s: instance '{instance}' discarded the step of {step} s: {reason}")]
    Discarded {
        time: f64,
        instance: String,
        step: f64,
        reason: String,
    },
    #[error("at t = {time} s: '{label}' is not finite ({value})")]
    NonFinite {
        time: f64,
        label: String,
        value: f64,
    },
    #[error("cancelled at t = {time} s")]
    Cancelled { time: f64 },
}

/// Stable topological order of `n` nodes under edges `a -> b` ("a before b"). Cycles are broken
/// by taking the lowest-index remaining node; the returned list names the nodes so taken.
pub fn topological_order(n: usize, edges: &[(usize, usize)]) -> (Vec<usize>, Vec<usize>) {
    let mut indeg = vec![0usize; n];
    for &(a, b) in edges {
        if a != b && a < n && b < n {
            indeg[b] += 1;
        }
    }
    let mut done = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut broken = Vec::new();
    while order.len() < n {
        let next = (0..n).find(|&i| !done[i] && indeg[i] == 0);
        let i = match next {
            Some(i) => i,
            None => {
                let Some(i) = (0..n).find(|&i| !done[i]) else {
                    break;
                };
                broken.push(i);
                i
            }
        };
        done[i] = true;
        order.push(i);
        for &(a, b) in edges {
            if a == i && a != b && b < n && !done[b] {
                indeg[b] = indeg[b].saturating_sub(1);
            }
        }
    }
    (order, broken)
}

/// Options of one run.
#[derive(Default)]
pub struct RunOptions<'a> {
    /// Checked at every communication point (e.g. set by a Ctrl-C handler).
    pub cancel: Option<&'a AtomicBool>,
    /// Called after every macro step with (steps done, total steps).
    pub progress: Option<&'a dyn Fn(u64, u64)>,
}

struct Engine<'p, 's, 'd, 'o> {
    plan: &'p CouplingPlan,
    exchange: &'p Exchange,
    slaves: &'s mut [&'d mut dyn Slave],
    opts: &'o RunOptions<'o>,
    n_steps: u64,
    rejected: u64,
    initialised: Vec<bool>,
    fatal: Vec<bool>,
    /// Latest connected outputs of each instance (in its `Source::outputs` order).
    outputs: Vec<Vec<f64>>,
    /// Scratch: the inputs of one destination, and their previous values.
    inputs: Vec<f64>,
    previous: Vec<f64>,
    /// Scratch: the recorded variables of one instance.
    recorded: Vec<f64>,
}

impl Engine<'_, '_, '_, '_> {
    fn t(&self, k: u64) -> f64 {
        if k >= self.n_steps {
            self.plan.stop_time
        } else {
            self.plan.start_time + k as f64 * self.plan.step
        }
    }

    fn slave_err(&mut self, time: f64, i: usize, e: SlaveError) -> SimError {
        if e.status == FailStatus::Fatal {
            self.fatal[i] = true;
        }
        SimError::Slave { time, source: e }
    }

    /// Reads the connected outputs of instance `i` (one call per type).
    fn read_outputs(&mut self, time: f64, i: usize) -> Result<(), SimError> {
        let src = &self.exchange.sources[i];
        if src.outputs.is_empty() {
            return Ok(());
        }
        let mut values = std::mem::take(&mut self.outputs[i]);
        values.resize(src.outputs.len(), 0.0);
        let r = self.slaves[i].get(&src.outputs, &mut values);
        self.outputs[i] = values;
        r.map_err(|e| self.slave_err(time, i, e))
    }

    /// The connected outputs of instance `i` must be finite (first offender in plan order).
    fn check_outputs(&self, time: f64, i: usize) -> Result<(), SimError> {
        let src = &self.exchange.sources[i];
        for (&x, &ci) in self.outputs[i].iter().zip(&src.connections) {
            if !x.is_finite() {
                return Err(self.non_finite(time, ci, x));
            }
        }
        Ok(())
    }

    fn non_finite(&self, time: f64, connection: usize, value: f64) -> SimError {
        SimError::NonFinite {
            time,
            label: self.plan.connections[connection].label.clone(),
            value,
        }
    }

    /// Writes the inputs of one destination from the latest outputs (one call per type). With
    /// `compare`, first reads the inputs back and returns the largest change (initialisation
    /// fixed point; reading an input is allowed in FMI 2.0, a failed read counts as changed).
    fn write_inputs(&mut self, time: f64, dest: &Dest, compare: bool) -> Result<f64, SimError> {
        let j = dest.instance;
        let mut inputs = std::mem::take(&mut self.inputs);
        inputs.clear();
        inputs.extend(dest.from.iter().map(|&(i, k)| self.outputs[i][k]));
        let mut change: f64 = 0.0;
        if compare {
            let mut old = std::mem::take(&mut self.previous);
            old.clear();
            old.resize(inputs.len(), f64::NAN);
            let before = self.slaves[j].get(&dest.inputs, &mut old).is_ok();
            for (&o, &x) in old.iter().zip(&inputs) {
                if !before || (o - x).abs() > 0.0 || o.is_nan() {
                    change = change.max(if before { (o - x).abs() } else { f64::INFINITY });
                }
            }
            self.previous = old;
        }
        let r = self.slaves[j].set(&dest.inputs, &inputs);
        self.inputs = inputs;
        r.map_err(|e| self.slave_err(time, j, e))?;
        Ok(change)
    }

    /// Copies the outputs of instance `from` to their connected inputs; with `compare`, returns
    /// the largest change of an input value (for the initialisation fixed point).
    fn propagate_from(&mut self, time: f64, from: usize, compare: bool) -> Result<f64, SimError> {
        self.read_outputs(time, from)?;
        self.check_outputs(time, from)?;
        let exchange = self.exchange;
        let mut change: f64 = 0.0;
        for dest in &exchange.sources[from].dests {
            change = change.max(self.write_inputs(time, dest, compare)?);
        }
        Ok(change)
    }

    /// Jacobi exchange: read all connected outputs first, then set all inputs.
    fn exchange_all_jacobi(&mut self, time: f64) -> Result<(), SimError> {
        for i in 0..self.slaves.len() {
            self.read_outputs(time, i)?;
        }
        for (ci, &(i, k)) in self.exchange.connection_at.iter().enumerate() {
            let x = self.outputs[i][k];
            if !x.is_finite() {
                return Err(self.non_finite(time, ci, x));
            }
        }
        let exchange = self.exchange;
        for dest in &exchange.jacobi {
            self.write_inputs(time, dest, false)?;
        }
        Ok(())
    }

    fn exchange_all(&mut self, time: f64) -> Result<(), SimError> {
        match self.plan.algorithm {
            Algorithm::Jacobi => self.exchange_all_jacobi(time),
            Algorithm::GaussSeidel => {
                for idx in 0..self.plan.order.len() {
                    let i = self.plan.order[idx];
                    self.propagate_from(time, i, false)?;
                }
                Ok(())
            }
        }
    }

    /// Appends one result row: time, then the recorded variables (one call per instance and
    /// type), which must be finite.
    fn record(&mut self, time: f64, out: &mut Vec<f64>) -> Result<(), SimError> {
        let row = out.len();
        out.push(time);
        out.resize(row + 1 + self.plan.record.len(), f64::NAN);
        let exchange = self.exchange;
        let mut values = std::mem::take(&mut self.recorded);
        for g in &exchange.record {
            values.resize(g.vars.len(), 0.0);
            if let Err(e) = self.slaves[g.instance].get(&g.vars, &mut values) {
                self.recorded = values;
                return Err(self.slave_err(time, g.instance, e));
            }
            for (&c, &x) in g.columns.iter().zip(&values) {
                out[row + 1 + c] = x;
            }
        }
        self.recorded = values;
        for (r, &x) in self.plan.record.iter().zip(&out[row + 1..]) {
            if !x.is_finite() {
                return Err(SimError::NonFinite {
                    time,
                    label: r.label.clone(),
                    value: x,
                });
            }
        }
        Ok(())
    }

    fn initialise(&mut self) -> Result<(), SimError> {
        let plan = self.plan;
        let t0 = plan.start_time;
        for i in 0..self.slaves.len() {
            self.slaves[i]
                .setup_experiment(t0, plan.stop_time)
                .map_err(|e| self.slave_err(t0, i, e))?;
            let inst = &plan.instances[i];
            // one call per start value, so that a refused one is named
            for (k, &(v, x)) in inst.parameters.iter().enumerate() {
                self.slaves[i]
                    .set(&VarBatch::new(vec![v]), &[x])
                    .map_err(|source| SimError::StartValue {
                        instance: inst.name.clone(),
                        name: inst
                            .parameter_names
                            .get(k)
                            .cloned()
                            .unwrap_or_else(|| format!("vr {}", v.vr)),
                        value: x,
                        source,
                    })?;
            }
            self.slaves[i]
                .enter_initialization_mode()
                .map_err(|e| self.slave_err(t0, i, e))?;
        }
        for _ in 0..plan.init_sweeps.max(1) {
            let mut change: f64 = 0.0;
            for idx in 0..plan.order.len() {
                let i = plan.order[idx];
                change = change.max(self.propagate_from(t0, i, true)?);
            }
            if change == 0.0 {
                break;
            }
        }
        for i in 0..self.slaves.len() {
            self.slaves[i]
                .exit_initialization_mode()
                .map_err(|e| self.slave_err(t0, i, e))?;
            // fmi2Terminate is allowed only from step mode (FMI 2.0 CS state machine); a slave
            // stopped earlier is only freed
            self.initialised[i] = true;
        }
        self.exchange_all(t0)
    }

    /// Tries macro step `k` split into `parts` sub-steps; returns the index of a slave that
    /// discarded, if any.
    fn try_macro_step(&mut self, k: u64, parts: u64) -> Result<Option<usize>, SimError> {
        let plan = self.plan;
        let n = self.slaves.len();
        let t = self.t(k);
        // (start, end) of each active slave's window
        let windows: Vec<Option<(f64, f64)>> = plan
            .instances
            .iter()
            .map(|inst| {
                let m = u64::from(inst.step_multiple.max(1));
                k.is_multiple_of(m)
                    .then(|| (t, self.t((k + m).min(self.n_steps))))
            })
            .collect();
        let sub = |(a, b): (f64, f64), j: u64| -> (f64, f64) {
            let s = a + (b - a) * (j as f64) / (parts as f64);
            let e = if j + 1 == parts {
                b
            } else {
                a + (b - a) * ((j + 1) as f64) / (parts as f64)
            };
            (s, e - s)
        };
        for j in 0..parts {
            match plan.algorithm {
                Algorithm::Jacobi => {
                    for (i, w) in windows.iter().enumerate().take(n) {
                        if let Some(w) = *w {
                            let (ts, h) = sub(w, j);
                            match self.slaves[i].do_step(ts, h) {
                                Ok(StepStatus::Ok) => {}
                                Ok(StepStatus::Discard) => return Ok(Some(i)),
                                Err(e) => return Err(self.slave_err(ts, i, e)),
                            }
                        }
                    }
                    let te = sub((t, self.t(k + 1)), j);
                    self.exchange_all_jacobi(te.0 + te.1)?;
                }
                Algorithm::GaussSeidel => {
                    for idx in 0..plan.order.len() {
                        let i = plan.order[idx];
                        if let Some(w) = windows[i] {
                            let (ts, h) = sub(w, j);
                            match self.slaves[i].do_step(ts, h) {
                                Ok(StepStatus::Ok) => {}
                                Ok(StepStatus::Discard) => return Ok(Some(i)),
                                Err(e) => return Err(self.slave_err(ts, i, e)),
                            }
                            self.propagate_from(ts + h, i, false)?;
                        }
                    }
                }
            }
        }
        Ok(None)
    }

    fn macro_step(&mut self, k: u64) -> Result<(), SimError> {
        let t = self.t(k);
        let h = self.t(k + 1) - t;
        let retry = self.plan.max_step_halvings > 0;
        let lacking = self.slaves.iter().position(|s| !s.can_save_state());
        // sub-steps change every active slave's step size
        let fixed = self.slaves.iter().position(|s| !s.can_vary_step());
        let can_retry = retry && lacking.is_none() && fixed.is_none();
        if can_retry {
            for i in 0..self.slaves.len() {
                self.slaves[i]
                    .save_state()
                    .map_err(|e| self.slave_err(t, i, e))?;
            }
        }
        let mut parts = 1u64;
        let mut halvings = 0u32;
        loop {
            let Some(i) = self.try_macro_step(k, parts)? else {
                return Ok(());
            };
            let name = self.slaves[i].name().to_string();
            let refusal = if !retry {
                Some("step retry is off (max_step_halvings = 0)".to_string())
            } else if let Some(l) = lacking {
                Some(format!(
                    "cannot retry: instance '{}' does not support canGetAndSetFMUstate",
                    self.slaves[l].name()
                ))
            } else if let Some(l) = fixed {
                Some(format!(
                    "cannot retry with smaller steps: instance '{}' does not support \
                     canHandleVariableCommunicationStepSize",
                    self.slaves[l].name()
                ))
            } else if halvings >= self.plan.max_step_halvings {
                Some(format!("still discarded after {halvings} halvings"))
            } else {
                None
            };
            if let Some(reason) = refusal {
                return Err(SimError::Discarded {
                    time: t,
                    instance: name,
                    step: h / parts as f64,
                    reason,
                });
            }
            for j in 0..self.slaves.len() {
                self.slaves[j]
                    .restore_state()
                    .map_err(|e| self.slave_err(t, j, e))?;
            }
            self.rejected += 1;
            halvings += 1;
            parts *= 2;
            log::debug!(target: "master", "t = {t}: '{name}' discarded, retrying with {parts} sub-steps");
        }
    }

    fn run(&mut self) -> Result<Vec<f64>, SimError> {
        let mut data =
            Vec::with_capacity((self.n_steps as usize + 1) * (self.plan.record.len() + 1));
        self.initialise()?;
        self.record(self.plan.start_time, &mut data)?;
        for k in 0..self.n_steps {
            if let Some(c) = self.opts.cancel {
                if c.load(Ordering::Relaxed) {
                    return Err(SimError::Cancelled { time: self.t(k) });
                }
            }
            self.macro_step(k)?;
            let t = self.t(k + 1);
            self.record(t, &mut data)?;
            if let Some(p) = self.opts.progress {
                p(k + 1, self.n_steps);
            }
        }
        Ok(data)
    }

    fn terminate_all(&mut self) -> Result<(), SimError> {
        let mut first = None;
        for i in 0..self.slaves.len() {
            if self.initialised[i] && !self.fatal[i] {
                self.initialised[i] = false;
                if let Err(e) = self.slaves[i].terminate() {
                    first.get_or_insert(SimError::Slave {
                        time: self.plan.stop_time,
                        source: e,
                    });
                }
            }
        }
        first.map_or(Ok(()), Err)
    }
}

/// Checks a plan against the slaves and returns the number of macro steps.
pub fn check_plan(plan: &CouplingPlan, n_slaves: usize) -> Result<u64, SimError> {
    let bad = |s: String| Err(SimError::Plan(s));
    if plan.instances.len() != n_slaves {
        return bad(format!(
            "{} instances in the plan but {} slaves",
            plan.instances.len(),
            n_slaves
        ));
    }
    if !(plan.step.is_finite() && plan.step > 0.0) {
        return bad(format!("step must be > 0, got {}", plan.step));
    }
    if !(plan.start_time.is_finite() && plan.stop_time.is_finite())
        || plan.stop_time <= plan.start_time
    {
        return bad(format!(
            "stop_time ({}) must be finite and greater than start_time ({})",
            plan.stop_time, plan.start_time
        ));
    }
    let span = plan.stop_time - plan.start_time;
    let n = (span / plan.step).round();
    if n < 1.0 || (n * plan.step - span).abs() > 1e-9 * span.max(plan.step) {
        return bad(format!(
            "stop_time - start_time ({span}) is not an integer multiple of step ({})",
            plan.step
        ));
    }
    let mut seen = vec![false; n_slaves];
    for &i in &plan.order {
        if i >= n_slaves || seen[i] {
            return bad(format!("order {:?} is not a permutation", plan.order));
        }
        seen[i] = true;
    }
    if seen.iter().any(|s| !s) {
        return bad(format!("order {:?} misses instances", plan.order));
    }
    let ok_ref = |i: usize| i < n_slaves;
    if plan
        .connections
        .iter()
        .any(|c| !ok_ref(c.from_instance) || !ok_ref(c.to_instance))
        || plan.record.iter().any(|r| !ok_ref(r.instance))
    {
        return bad("connection or record refers to a missing instance".into());
    }
    if plan.instances.iter().any(|i| i.step_multiple == 0) {
        return bad("step_multiple must be >= 1".into());
    }
    Ok(n as u64)
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
    let n_steps = check_plan(plan, slaves.len())?;
    check_step_sizes(plan, slaves, n_steps)?;
    let started = Instant::now();
    let n = slaves.len();
    let exchange = Exchange::new(plan);
    let mut eng = Engine {
        plan,
        exchange: &exchange,
        slaves,
        opts,
        n_steps,
        rejected: 0,
        initialised: vec![false; n],
        fatal: vec![false; n],
        outputs: vec![Vec::new(); n],
        inputs: Vec::new(),
        previous: Vec::new(),
        recorded: Vec::new(),
    };
    let res = eng.run();
    let term = eng.terminate_all();
    let data = res?;
    term?;
    let wall = started.elapsed().as_secs_f64();
    let sim = plan.stop_time - plan.start_time;
    let mut header = vec!["time [s]".to_string()];
    header.extend(plan.record.iter().map(|r| r.label.clone()));
    Ok(SimOutput {
        header,
        data,
        summary: Summary {
            steps: n_steps,
            rejected_steps: eng.rejected,
            simulated_time_s: sim,
            wall_time_s: wall,
            realtime_ratio: if wall > 0.0 {
                sim / wall
            } else {
                f64::INFINITY
            },
        },
    })
}

#[cfg(test)]
pub(crate) mod tests;
