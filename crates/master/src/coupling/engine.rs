//! The fixed-step co-simulation engine: initialisation, macro steps with retry, data exchange
//! in batches, recording, termination (see [`super`] for the semantics).

use std::sync::atomic::Ordering;

use super::exchange::{Dest, Exchange, MergedWrite};
use super::{Algorithm, CouplingPlan, RunOptions, SimError};
use crate::show;
use crate::slave::{FailStatus, ScalarType, Slave, SlaveError, StepStatus, StringTable, VarBatch};

pub(super) struct Engine<'p, 's, 'd, 'o> {
    plan: &'p CouplingPlan,
    exchange: &'p Exchange,
    slaves: &'s mut [&'d mut dyn Slave],
    opts: &'o RunOptions<'o>,
    n_steps: u64,
    rejected: u64,
    initialised: Vec<bool>,
    /// Instances that returned fmi2Error or fmi2Fatal: FMI 2.0 allows only fmi2Reset,
    /// fmi2SetFMUstate or fmi2FreeInstance after an error (only the last after a fatal one),
    /// so they get no fmi2Terminate.
    failed: Vec<bool>,
    /// Latest connected outputs of each instance (in its `Source::outputs` order).
    outputs: Vec<Vec<f64>>,
    /// Per instance: how many calls that may change its values (set, step, state restore,
    /// mode change) it has had, and that count when `outputs` was last read (`u64::MAX`:
    /// not read yet). Equal counts: a read now returns `outputs` again (FMI 2.0: values
    /// change only through such calls).
    changes: Vec<u64>,
    read_at: Vec<u64>,
    /// Scratch: the inputs of one destination, and their previous values.
    inputs: Vec<f64>,
    previous: Vec<f64>,
    /// Scratch: the recorded variables of one instance.
    recorded: Vec<f64>,
    /// The texts of String values (the plan's start values first).
    strings: StringTable,
    /// Scratch: texts read from a slave.
    texts: Vec<String>,
    /// Set when a slave asked to end the run: (instance, last completed point).
    terminated: Option<(usize, f64)>,
    /// Gauss-Seidel: the slaves at the current communication point (stepped to it), whose
    /// direct-feedthrough outputs are read again when their inputs change; and scratch for
    /// the instances refreshed after one step.
    current: Vec<bool>,
    refreshed: Vec<bool>,
    pending: Vec<usize>,
    /// Scratch: each instance's window of the current macro step.
    windows: Vec<Option<(f64, f64)>>,
    /// The first slave without canGetAndSetFMUstate, and the first without
    /// canHandleVariableCommunicationStepSize (capabilities do not change during a run).
    lacking_state: Option<usize>,
    fixed_step: Option<usize>,
    /// Every instance steps at every point (step multiple 1).
    every_point: bool,
    /// [`Self::fast_step`]: the deferred writes (source, entry of its `Source::dests`) that an
    /// instance read again within the step owes to a destination that has stepped already
    /// this step, made once at the end of the step.
    late: Vec<(usize, usize)>,
    /// [`Self::fast_step`]: instances whose inputs changed after their outputs were last read
    /// within the step and whose outputs only go to deferred writes: read when a write uses
    /// them, or at the end of the step ([`Self::propagate_refreshed`]).
    stale: Vec<bool>,
    any_stale: bool,
    /// The common case runs [`Self::fast_step`]: Gauss-Seidel, every instance stepping at
    /// every point, no step retry (so no split steps) and no String among the exchanged or
    /// recorded variables. The calls of [`Self::step_windows`] in the same order, except that
    /// the Real inputs of an instance whose outputs are not read again within the step are
    /// written just before its next call (its step, or the end of the macro step), those from
    /// several sources in one call: each instance holds the same values at each of its calls,
    /// so a run gives the same results bit for bit. When a step is discarded or ends the
    /// simulation early, the pending writes to the other instances are made at once. When a
    /// call fails, the error may name a later call than with one write per source: both end
    /// the run without results.
    fast: bool,
}

/// How a macro step ended.
enum StepEnd {
    Done,
    /// A slave discarded the step (and did not ask to end the simulation).
    Discarded(usize),
    /// A slave asked to end the simulation; `completed`: it got to the end of the step (its
    /// fmi2LastSuccessfulTime), and so did the others, so the point is recorded.
    Terminated {
        instance: usize,
        completed: bool,
    },
}

/// How a single slave's step ended.
enum SlaveStep {
    Ok,
    Discarded,
    /// The slave ends the simulation; whether it completed this step.
    Terminating {
        completed: bool,
    },
}

impl<'p, 's, 'd, 'o> Engine<'p, 's, 'd, 'o> {
    pub(super) fn new(
        plan: &'p CouplingPlan,
        exchange: &'p Exchange,
        slaves: &'s mut [&'d mut dyn Slave],
        opts: &'o RunOptions<'o>,
        n_steps: u64,
        fast: bool,
    ) -> Self {
        let n = slaves.len();
        let lacking_state = slaves.iter().position(|s| !s.can_save_state());
        let fixed_step = slaves.iter().position(|s| !s.can_vary_step());
        Engine {
            plan,
            exchange,
            slaves,
            opts,
            n_steps,
            rejected: 0,
            initialised: vec![false; n],
            failed: vec![false; n],
            outputs: vec![Vec::new(); n],
            changes: vec![0; n],
            read_at: vec![u64::MAX; n],
            inputs: Vec::new(),
            previous: Vec::new(),
            recorded: Vec::new(),
            strings: StringTable::from_texts(&plan.strings),
            texts: Vec::new(),
            terminated: None,
            current: vec![false; n],
            refreshed: vec![false; n],
            pending: Vec::new(),
            windows: Vec::with_capacity(n),
            lacking_state,
            fixed_step,
            every_point: plan.instances.iter().all(|i| i.step_multiple <= 1),
            late: Vec::new(),
            stale: vec![false; n],
            any_stale: false,
            fast: fast && Self::fast_applies(plan, exchange),
        }
    }

    /// Whether [`Self::fast_step`] does what [`Self::step_windows`] does for this plan.
    fn fast_applies(plan: &CouplingPlan, exchange: &Exchange) -> bool {
        let no_strings = |b: &VarBatch| b.group(ScalarType::String).vrs.is_empty();
        plan.algorithm == Algorithm::GaussSeidel
            && plan.max_step_halvings == 0
            && plan.instances.iter().all(|i| i.step_multiple <= 1)
            && exchange
                .sources
                .iter()
                .all(|s| no_strings(&s.outputs) && s.dests.iter().all(|d| no_strings(&d.inputs)))
            && exchange.record.iter().all(|g| no_strings(&g.vars))
    }

    /// The instance that ended the run and the time of the last result row, if one did.
    pub(super) fn terminated(&self) -> Option<(usize, f64)> {
        self.terminated
    }

    /// The texts of the run's String values.
    pub(super) fn take_strings(&mut self) -> Vec<String> {
        std::mem::take(&mut self.strings).into_texts()
    }

    /// Reads a batch of slave `i` (numbers in one call per type, then the Strings, whose texts
    /// are interned into values).
    fn get_batch(&mut self, i: usize, batch: &VarBatch, out: &mut [f64]) -> Result<(), SlaveError> {
        self.slaves[i].get(batch, out)?;
        let g = batch.group(ScalarType::String);
        if !g.vrs.is_empty() {
            let mut texts = std::mem::take(&mut self.texts);
            let r = self.slaves[i].get_strings(&g.vrs, &mut texts);
            if r.is_ok() {
                for (&k, t) in g.positions.iter().zip(&texts) {
                    out[k] = self.strings.intern(t);
                }
            }
            self.texts = texts;
            r?;
        }
        Ok(())
    }

    /// Counts a call on slave `i` that may change its values.
    fn touch(&mut self, i: usize) {
        self.changes[i] = self.changes[i].wrapping_add(1);
    }

    /// Writes a batch to slave `i` (numbers, then the Strings by their texts).
    fn set_batch(&mut self, i: usize, batch: &VarBatch, values: &[f64]) -> Result<(), SlaveError> {
        self.touch(i);
        self.slaves[i].set(batch, values)?;
        let g = batch.group(ScalarType::String);
        if !g.vrs.is_empty() {
            let texts: Vec<&str> = g
                .positions
                .iter()
                .map(|&k| self.strings.text(values[k]).unwrap_or(""))
                .collect();
            self.slaves[i].set_strings(&g.vrs, &texts)?;
        }
        Ok(())
    }

    /// Macro steps redone with sub-steps after a discard.
    pub(super) fn rejected(&self) -> u64 {
        self.rejected
    }

    fn t(&self, k: u64) -> f64 {
        if k >= self.n_steps {
            self.plan.stop_time
        } else {
            self.plan.start_time + k as f64 * self.plan.step
        }
    }

    fn slave_err(&mut self, time: f64, i: usize, e: SlaveError) -> SimError {
        if matches!(e.status, FailStatus::Error | FailStatus::Fatal) {
            self.failed[i] = true;
        }
        SimError::Slave {
            time,
            source: Box::new(e),
        }
    }

    /// Reads the connected outputs of instance `i` (one call per type).
    fn read_outputs(&mut self, time: f64, i: usize) -> Result<(), SimError> {
        let src = &self.exchange.sources[i];
        if src.outputs.is_empty() {
            return Ok(());
        }
        let mut values = std::mem::take(&mut self.outputs[i]);
        values.resize(src.outputs.len(), 0.0);
        let r = self.get_batch(i, &src.outputs, &mut values);
        self.outputs[i] = values;
        if !src.conversions.is_empty() {
            self.convert_units(i);
        }
        self.read_at[i] = if r.is_ok() { self.changes[i] } else { u64::MAX };
        r.map_err(|e| self.slave_err(time, i, e))
    }

    /// The outputs of instance `i` just read, in their destinations' units where those differ
    /// (out of line: most systems convert nothing).
    #[inline(never)]
    fn convert_units(&mut self, i: usize) {
        let conversions = &self.exchange.sources[i].conversions;
        let out = &mut self.outputs[i];
        for &(k, u) in conversions {
            if let Some(x) = out.get_mut(k) {
                *x = u.apply(*x);
            }
        }
    }

    /// The connected outputs of instance `i` must be finite (first offender in plan order).
    #[inline]
    fn check_outputs(&self, time: f64, i: usize) -> Result<(), SimError> {
        if self.outputs[i].iter().all(|x| x.is_finite()) {
            return Ok(());
        }
        self.non_finite_output(time, i)
    }

    #[cold]
    #[inline(never)]
    fn non_finite_output(&self, time: f64, i: usize) -> Result<(), SimError> {
        let src = &self.exchange.sources[i];
        for (&x, &ci) in self.outputs[i].iter().zip(&src.connections) {
            if !x.is_finite() {
                return Err(self.non_finite(time, ci, x));
            }
        }
        Ok(())
    }

    fn non_finite(&self, time: f64, connection: usize, value: f64) -> SimError {
        let c = &self.plan.connections[connection];
        SimError::NonFinite {
            time,
            label: match c.conversion {
                // the FMU's own value may be finite: the conversion overflowed
                Some(u) => format!(
                    "{} (converted to its input's unit: x {} + {})",
                    c.label,
                    crate::show::num(u.factor),
                    crate::show::num(u.offset)
                ),
                None => c.label.clone(),
            },
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
            let before = self.get_batch(j, &dest.inputs, &mut old).is_ok();
            for (&o, &x) in old.iter().zip(&inputs) {
                if !before || (o - x).abs() > 0.0 || o.is_nan() {
                    change = change.max(if before { (o - x).abs() } else { f64::INFINITY });
                }
            }
            self.previous = old;
        }
        let r = self.set_batch(j, &dest.inputs, &inputs);
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

    /// Gauss-Seidel, after instance `from` passed on its outputs: every instance at the
    /// current point whose outputs depend directly on the inputs just set (ModelStructure) is
    /// read again and passes its fresh outputs on, and so on down the chain (FMI 2.0 allows
    /// reading outputs again after setting inputs at the same instant). Each instance is read
    /// again at most once per call, so an algebraic loop ends. `fast_at`: in
    /// [`Self::fast_step`], the position in the order being stepped (see
    /// [`Self::propagate_refreshed`]).
    fn refresh_feedthrough(
        &mut self,
        time: f64,
        from: usize,
        fast_at: Option<usize>,
    ) -> Result<(), SimError> {
        let exchange = self.exchange;
        // a source ahead of the others (a longer step) does not refresh them
        if exchange.sources[from].feeds_through.is_empty() || !self.current[from] {
            return Ok(());
        }
        self.refreshed.iter_mut().for_each(|r| *r = false);
        self.refreshed[from] = true;
        let mut pending = std::mem::take(&mut self.pending);
        pending.clear();
        pending.push(from);
        let mut result = Ok(());
        while let Some(s) = pending.pop() {
            for &j in &exchange.sources[s].feeds_through {
                if self.current[j] && !self.refreshed[j] {
                    self.refreshed[j] = true;
                    if let Err(e) = self.propagate_refreshed(time, j, fast_at) {
                        result = Err(e);
                        break;
                    }
                    pending.push(j);
                }
            }
            if result.is_err() {
                break;
            }
        }
        self.pending = pending;
        result
    }

    /// Passes on the outputs of instance `from`, read again within the step. In
    /// [`Self::fast_step`] (`fast_at`: the position in the order being stepped) a write that
    /// is deferred there (see [`GaussSeidelWrites`](super::exchange::GaussSeidelWrites)) is
    /// not made now: the destination's merged write still to come in this step (before its
    /// step, or at the end) takes the fresh values; if that write has been made already (the
    /// destination stepped after `from` and before this point), the write is made once at the
    /// end of the step ([`Self::late_writes`]). Nothing reads such a destination in between
    /// (its outputs are not read again within a step), so it holds the same values at each
    /// of its calls as with every write made at once. When every write of `from` is deferred,
    /// its outputs are not read now either: it is marked stale and read once, before the
    /// first write that uses one of its outputs that depend on its inputs (ModelStructure), or
    /// at the end of the step ([`Self::fresh`]); that read gives the values the last read
    /// here would give (only its inputs changed since, and each such change brings it here
    /// again), and its other outputs have not changed since its step. Its outputs are then
    /// checked once per step, not after each change of its inputs.
    fn propagate_refreshed(
        &mut self,
        time: f64,
        from: usize,
        fast_at: Option<usize>,
    ) -> Result<(), SimError> {
        let Some(p) = fast_at else {
            return self.propagate_from(time, from, false).map(|_| ());
        };
        let exchange = self.exchange;
        let writes = &exchange.gauss_seidel;
        if writes.deferred_only[from] {
            self.stale[from] = true;
            self.any_stale = true;
        } else {
            self.read_outputs(time, from)?;
            self.check_outputs(time, from)?;
        }
        for (d, dest) in exchange.sources[from].dests.iter().enumerate() {
            let immediate = writes.immediate[from].get(d).copied().unwrap_or(true);
            if immediate {
                self.write_inputs(time, dest, false)?;
                continue;
            }
            let (source_at, dest_at) = (writes.position[from], writes.position[dest.instance]);
            if source_at < dest_at && dest_at <= p && !self.late.contains(&(from, d)) {
                self.late.push((from, d));
            }
        }
        Ok(())
    }

    /// The writes [`Self::propagate_refreshed`] left for the end of the step, from the latest
    /// outputs.
    #[inline(never)]
    fn late_writes(&mut self, time: f64) -> Result<(), SimError> {
        let exchange = self.exchange;
        let mut late = std::mem::take(&mut self.late);
        let mut result = Ok(());
        for &(from, d) in &late {
            let dest = &exchange.sources[from].dests[d];
            if dest.varies {
                result = self.fresh(time, from);
                if result.is_err() {
                    break;
                }
            }
            result = self.write_inputs(time, dest, false).map(|_| ());
            if result.is_err() {
                break;
            }
        }
        late.clear();
        self.late = late;
        result
    }

    /// Reads the outputs of instance `i` if they are stale (see [`Self::propagate_refreshed`]).
    #[inline]
    fn fresh(&mut self, time: f64, i: usize) -> Result<(), SimError> {
        if self.stale[i] {
            self.stale[i] = false;
            self.read_outputs(time, i)?;
            self.check_outputs(time, i)?;
        }
        Ok(())
    }

    /// Reads every stale instance (the end of a step).
    #[inline(never)]
    fn fresh_all(&mut self, time: f64) -> Result<(), SimError> {
        self.any_stale = false;
        for i in 0..self.stale.len() {
            self.fresh(time, i)?;
        }
        Ok(())
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
                // every slave is at this point
                self.current.iter_mut().for_each(|c| *c = true);
                for idx in 0..self.plan.order.len() {
                    let i = self.plan.order[idx];
                    self.propagate_from(time, i, false)?;
                    self.refresh_feedthrough(time, i, None)?;
                }
                Ok(())
            }
        }
    }

    /// Appends one result row: time, then the recorded variables (one call per instance and
    /// type), which must be finite.
    fn record(&mut self, time: f64, out: &mut Vec<f64>) -> Result<(), SimError> {
        let row = out.len();
        out.try_reserve(1 + self.plan.record.len())
            .map_err(|_| SimError::OutOfMemory { time, values: row })?;
        out.push(time);
        out.resize(row + 1 + self.plan.record.len(), f64::NAN);
        let exchange = self.exchange;
        let mut values = std::mem::take(&mut self.recorded);
        for g in &exchange.record {
            let i = g.instance;
            if let (Some(at), true) = (&g.from_outputs, self.read_at[i] == self.changes[i]) {
                // connected outputs read since the instance's last change: the same values
                for (&c, &k) in g.columns.iter().zip(at) {
                    out[row + 1 + c] = self.outputs[i][k];
                }
                continue;
            }
            let read = match g.first_column {
                // the common case (no String recorded): consecutive columns in one call
                Some(c) if self.fast => {
                    let at = row + 1 + c;
                    self.slaves[i].get(&g.vars, &mut out[at..at + g.vars.len()])
                }
                // consecutive columns: read straight into the row
                Some(c) => {
                    let at = row + 1 + c;
                    self.get_batch(g.instance, &g.vars, &mut out[at..at + g.vars.len()])
                }
                None => {
                    values.resize(g.vars.len(), 0.0);
                    let r = self.get_batch(g.instance, &g.vars, &mut values);
                    for (&c, &x) in g.columns.iter().zip(&values) {
                        out[row + 1 + c] = x;
                    }
                    r
                }
            };
            if let Err(e) = read {
                self.recorded = values;
                // the rows before stay a history; this one is not complete
                out.truncate(row);
                return Err(self.slave_err(time, g.instance, e));
            }
        }
        self.recorded = values;
        if out[row + 1..].iter().all(|x| x.is_finite()) {
            return Ok(());
        }
        if let Some(k) = out[row + 1..].iter().position(|x| !x.is_finite()) {
            let value = out[row + 1 + k];
            out.truncate(row);
            return Err(SimError::NonFinite {
                time,
                label: self.plan.record[k].label.clone(),
                value,
            });
        }
        Ok(())
    }

    fn initialise(&mut self) -> Result<(), SimError> {
        let plan = self.plan;
        let t0 = plan.start_time;
        for i in 0..self.slaves.len() {
            self.touch(i);
            self.slaves[i]
                .setup_experiment(t0, plan.stop_time)
                .map_err(|e| self.slave_err(t0, i, e))?;
            let inst = &plan.instances[i];
            // one call per start value, so that a refused one is named
            for (k, &(v, x)) in inst.parameters.iter().enumerate() {
                self.set_batch(i, &VarBatch::new(vec![v]), &[x])
                    .map_err(|source| SimError::StartValue {
                        instance: inst.name.clone(),
                        assignment: format!(
                            "'{}' = {}",
                            inst.parameter_names.get(k).map_or_else(
                                || format!("vr {}", v.vr),
                                |n| show::text(n).to_string()
                            ),
                            match v.ty {
                                ScalarType::String => {
                                    format!("{:?}", show::text(self.strings.text(x).unwrap_or("")))
                                }
                                _ => show::num(x).to_string(),
                            }
                        ),
                        source: Box::new(source),
                    })?;
            }
            self.touch(i);
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
            self.touch(i);
            self.slaves[i]
                .exit_initialization_mode()
                .map_err(|e| self.slave_err(t0, i, e))?;
            // fmi2Terminate is allowed only from step mode (FMI 2.0 CS state machine); a slave
            // stopped earlier is only freed
            self.initialised[i] = true;
        }
        self.exchange_all(t0)
    }

    /// Steps slave `i` over `[ts, ts + h]`; a discard asks the slave whether it ends the
    /// simulation, and how far it got (fmi2LastSuccessfulTime).
    fn step_slave(&mut self, i: usize, ts: f64, h: f64) -> Result<SlaveStep, SimError> {
        self.touch(i);
        match self.slaves[i].do_step(ts, h) {
            Ok(StepStatus::Ok) => Ok(SlaveStep::Ok),
            Ok(StepStatus::Discard) => {
                if !self.slaves[i].terminate_requested() {
                    return Ok(SlaveStep::Discarded);
                }
                let end = ts + h;
                let completed = self.slaves[i]
                    .last_successful_time()
                    .is_some_and(|t| (t - end).abs() <= 1e-9 * end.abs().max(h));
                Ok(SlaveStep::Terminating { completed })
            }
            Err(e) => Err(self.slave_err(ts, i, e)),
        }
    }

    /// Tries macro step `k` split into `parts` sub-steps. A slave that ends the simulation
    /// after completing the last sub-step lets the others complete it too.
    fn try_macro_step(&mut self, k: u64, parts: u64) -> Result<StepEnd, SimError> {
        if self.fast && parts == 1 {
            return self.fast_step(k);
        }
        let plan = self.plan;
        let t = self.t(k);
        // (start, end) of each active slave's window (a scratch vector: no allocation per step)
        let mut windows = std::mem::take(&mut self.windows);
        windows.clear();
        if self.every_point {
            let w = Some((t, self.t(k + 1)));
            windows.extend(plan.instances.iter().map(|_| w));
        } else {
            for inst in &plan.instances {
                let m = u64::from(inst.step_multiple.max(1));
                windows.push(
                    k.is_multiple_of(m)
                        .then(|| (t, self.t((k + m).min(self.n_steps)))),
                );
            }
        }
        let result = self.step_windows(k, parts, &windows);
        self.windows = windows;
        result
    }

    /// Macro step `k` in the common case (see `fast`): each instance in order steps over
    /// `[t_k, t_k+1]`, then its connected outputs are read in one call and passed on to their
    /// inputs: at once when the destination is read again within the step or the batch holds
    /// other types than Real, else merged per destination and written before the
    /// destination's next call (see [`GaussSeidelWrites`](super::exchange::GaussSeidelWrites));
    /// no windows, no sub-step arithmetic and no String handling.
    fn fast_step(&mut self, k: u64) -> Result<StepEnd, SimError> {
        let plan = self.plan;
        let exchange = self.exchange;
        let t = self.t(k);
        let h = self.t(k + 1) - t;
        let te = t + h;
        self.current.iter_mut().for_each(|c| *c = false);
        self.late.clear();
        if self.any_stale {
            self.stale.iter_mut().for_each(|s| *s = false);
            self.any_stale = false;
        }
        let mut ending: Option<usize> = None;
        let writes = &exchange.gauss_seidel;
        for (p, &i) in plan.order.iter().enumerate() {
            if let Some(w) = &writes.before_step[p] {
                self.write_merged(te, w)?;
            }
            match self.step_slave(i, t, h)? {
                SlaveStep::Ok => {}
                SlaveStep::Discarded => return self.stopped(te, p, StepEnd::Discarded(i)),
                SlaveStep::Terminating { completed: true } => {
                    ending.get_or_insert(i);
                }
                SlaveStep::Terminating { completed: false } => {
                    let end = StepEnd::Terminated {
                        instance: i,
                        completed: false,
                    };
                    return self.stopped(te, p, end);
                }
            }
            self.current[i] = true;
            let src = &exchange.sources[i];
            if !src.outputs.is_empty() {
                let out = &mut self.outputs[i];
                if out.len() != src.outputs.len() {
                    out.resize(src.outputs.len(), 0.0);
                }
                let r = self.slaves[i].get(&src.outputs, out);
                self.read_at[i] = if r.is_ok() { self.changes[i] } else { u64::MAX };
                r.map_err(|e| self.slave_err(te, i, e))?;
                if !src.conversions.is_empty() {
                    self.convert_units(i);
                }
                self.check_outputs(te, i)?;
            }
            for (dest, _) in src
                .dests
                .iter()
                .zip(&writes.immediate[i])
                .filter(|(_, &now)| now)
            {
                let j = dest.instance;
                self.touch(j);
                let r = match dest.run {
                    // the inputs are consecutive outputs of this source: written from there
                    Some(k) => {
                        self.slaves[j].set(&dest.inputs, &self.outputs[i][k..k + dest.from.len()])
                    }
                    None => {
                        self.inputs.clear();
                        let outputs = &self.outputs;
                        self.inputs
                            .extend(dest.from.iter().map(|&(s, k)| outputs[s][k]));
                        self.slaves[j].set(&dest.inputs, &self.inputs)
                    }
                };
                r.map_err(|e| self.slave_err(te, j, e))?;
            }
            if !src.feeds_through.is_empty() {
                self.refresh_feedthrough(te, i, Some(p))?;
            }
        }
        if !self.late.is_empty() {
            self.late_writes(te)?;
        }
        for w in &writes.at_end {
            self.write_merged(te, w)?;
        }
        if self.any_stale {
            self.fresh_all(te)?;
        }
        Ok(match ending {
            Some(instance) => StepEnd::Terminated {
                instance,
                completed: true,
            },
            None => StepEnd::Done,
        })
    }

    /// [`Self::fast_step`] stops at position `p` of the order: the others get the writes still
    /// pending, so that each holds the inputs it would hold with one write per source (what it
    /// gets before fmi2Terminate); not the instance at `p`, whose step failed.
    #[cold]
    fn stopped(&mut self, time: f64, p: usize, end: StepEnd) -> Result<StepEnd, SimError> {
        self.late_writes(time)?;
        let writes = &self.exchange.gauss_seidel;
        let i = self.plan.order[p];
        for w in writes.before_step[p + 1..].iter().flatten() {
            self.write_merged(time, w)?;
        }
        for w in writes.at_end.iter().filter(|w| w.instance != i) {
            self.write_merged(time, w)?;
        }
        Ok(end)
    }

    /// One merged write of [`Self::fast_step`] from the latest outputs.
    #[inline(always)]
    fn write_merged(&mut self, time: f64, w: &MergedWrite) -> Result<(), SimError> {
        if self.any_stale {
            for &s in &w.sources {
                self.fresh(time, s)?;
            }
        }
        let j = w.instance;
        self.touch(j);
        let r = match w.run {
            Some((s, k)) => self.slaves[j].set_reals(&w.vrs, &self.outputs[s][k..k + w.vrs.len()]),
            None => {
                // in place (an extend from an iterator took about 35 instructions per value)
                self.inputs.resize(w.from.len(), 0.0);
                for (x, &(s, k)) in self.inputs.iter_mut().zip(&w.from) {
                    *x = self.outputs[s][k];
                }
                self.slaves[j].set_reals(&w.vrs, &self.inputs)
            }
        };
        r.map_err(|e| self.slave_err(time, j, e))
    }

    /// [`Self::try_macro_step`] over the given windows.
    fn step_windows(
        &mut self,
        k: u64,
        parts: u64,
        windows: &[Option<(f64, f64)>],
    ) -> Result<StepEnd, SimError> {
        let plan = self.plan;
        let n = self.slaves.len();
        let t = self.t(k);
        let sub = |(a, b): (f64, f64), j: u64| -> (f64, f64) {
            if parts == 1 {
                return (a, b - a);
            }
            let s = a + (b - a) * (j as f64) / (parts as f64);
            let e = if j + 1 == parts {
                b
            } else {
                a + (b - a) * ((j + 1) as f64) / (parts as f64)
            };
            (s, e - s)
        };
        let mut ending: Option<usize> = None;
        for j in 0..parts {
            let last_part = j + 1 == parts;
            // the outcome of one slave's step: Some(end) stops the macro step
            let mut outcome = |i: usize, step: SlaveStep| -> Option<StepEnd> {
                match step {
                    SlaveStep::Ok => None,
                    SlaveStep::Discarded => Some(StepEnd::Discarded(i)),
                    SlaveStep::Terminating { completed } if completed && last_part => {
                        ending.get_or_insert(i);
                        None
                    }
                    SlaveStep::Terminating { .. } => Some(StepEnd::Terminated {
                        instance: i,
                        completed: false,
                    }),
                }
            };
            match plan.algorithm {
                Algorithm::Jacobi => {
                    for (i, w) in windows.iter().enumerate().take(n) {
                        if let Some(w) = *w {
                            let (ts, h) = sub(w, j);
                            let step = self.step_slave(i, ts, h)?;
                            if let Some(end) = outcome(i, step) {
                                return Ok(end);
                            }
                        }
                    }
                    let te = sub((t, self.t(k + 1)), j);
                    self.exchange_all_jacobi(te.0 + te.1)?;
                }
                Algorithm::GaussSeidel => {
                    self.current.iter_mut().for_each(|c| *c = false);
                    for idx in 0..plan.order.len() {
                        let i = plan.order[idx];
                        if let Some(w) = windows[i] {
                            let (ts, h) = sub(w, j);
                            let step = self.step_slave(i, ts, h)?;
                            if let Some(end) = outcome(i, step) {
                                return Ok(end);
                            }
                            // at the same point as the others stepping every point
                            self.current[i] = plan.instances[i].step_multiple <= 1;
                            self.propagate_from(ts + h, i, false)?;
                            self.refresh_feedthrough(ts + h, i, None)?;
                        }
                    }
                }
            }
        }
        Ok(match ending {
            Some(instance) => StepEnd::Terminated {
                instance,
                completed: true,
            },
            None => StepEnd::Done,
        })
    }

    /// Macro step `k` with retry; `Ok(Some((i, completed)))` when slave `i` asked to end the
    /// simulation (`completed`: at the end of this step, else at its start).
    fn macro_step(&mut self, k: u64) -> Result<Option<(usize, bool)>, SimError> {
        let t = self.t(k);
        let h = self.t(k + 1) - t;
        let retry = self.plan.max_step_halvings > 0;
        let lacking = self.lacking_state;
        // sub-steps change every active slave's step size
        let fixed = self.fixed_step;
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
            let i = match self.try_macro_step(k, parts)? {
                StepEnd::Done => return Ok(None),
                StepEnd::Terminated {
                    instance,
                    completed,
                } => return Ok(Some((instance, completed))),
                StepEnd::Discarded(instance) => instance,
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
                self.touch(j);
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

    /// Runs the plan, recording into `data` (which keeps the rows recorded before a failure).
    pub(super) fn run(&mut self, data: &mut Vec<f64>) -> Result<(), SimError> {
        // Reserved up to 32 MiB at first, then grown (fallibly, see `record`): the limits of
        // check_plan bound the total, the memory actually free is only known while growing.
        let total = (self.n_steps as usize)
            .saturating_add(1)
            .saturating_mul(self.plan.record.len() + 1);
        data.clear();
        data.reserve(total.min(1 << 22));
        self.initialise()?;
        self.record(self.plan.start_time, data)?;
        for k in 0..self.n_steps {
            if let Some(c) = self.opts.cancel {
                if c.load(Ordering::Relaxed) {
                    return Err(SimError::Cancelled { time: self.t(k) });
                }
            }
            if let Some((i, completed)) = self.macro_step(k)? {
                // the FMU ends the run: the results stop at the last completed point
                let t = if completed { self.t(k + 1) } else { self.t(k) };
                if completed {
                    self.record(t, data)?;
                }
                log::info!(target: "master", "instance '{}' asked to end the simulation at t = {t} s", self.slaves[i].name());
                self.terminated = Some((i, t));
                break;
            }
            let t = self.t(k + 1);
            self.record(t, data)?;
            if let Some(p) = self.opts.progress {
                p(k + 1, self.n_steps);
            }
        }
        Ok(())
    }

    /// fmi2Terminate on every slave that reached step mode and did not return fmi2Error or
    /// fmi2Fatal; `time` is where the run ended (the last recorded point), for the message.
    pub(super) fn terminate_all(&mut self, time: f64) -> Result<(), SimError> {
        let mut first = None;
        for i in 0..self.slaves.len() {
            if self.initialised[i] && !self.failed[i] {
                self.initialised[i] = false;
                if let Err(e) = self.slaves[i].terminate() {
                    first.get_or_insert(SimError::Slave {
                        time,
                        source: Box::new(e),
                    });
                }
            }
        }
        first.map_or(Ok(()), Err)
    }
}
