//! The plan the coupling algorithm runs (validated by [`crate::system`]), its results and
//! errors, and the checks made before any call.

use crate::show::{num, text};
use crate::slave::{ScalarType, SlaveError, VarRef};

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
    /// Start values set before initialisation (value reference, value as f64; a String's
    /// value indexes [`CouplingPlan::strings`]).
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
    /// Whether the target input feeds directly through (ModelStructure/Outputs) to an output
    /// of the target instance that is itself the source of a connection: after setting it,
    /// that output is read again and passed on (Gauss-Seidel).
    pub feedthrough: bool,
    /// Whether the source output depends directly (ModelStructure/Outputs; an output without
    /// declared dependencies: yes) on a connected input of its own instance: setting that
    /// input within a Gauss-Seidel step may change it.
    pub source_depends_on_inputs: bool,
    /// The source's value in the target's unit, when the two units differ (None: passed
    /// unchanged).
    pub conversion: Option<UnitConversion>,
}

/// A Real value in one unit expressed in another of the same base units (FMI 2.0, 2.2.2:
/// value in SI = BaseUnit factor * value + BaseUnit offset, for either unit):
/// `target = factor * source + offset`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct UnitConversion {
    pub factor: f64,
    pub offset: f64,
}

impl UnitConversion {
    /// From a unit with BaseUnit (`factor`, `offset`) `from` to one with `to` (both in the
    /// same SI base units); None when the two are the same unit under two names.
    pub fn between(from: (f64, f64), to: (f64, f64)) -> Option<Self> {
        let c = UnitConversion {
            factor: from.0 / to.0,
            offset: (from.1 - to.1) / to.0,
        };
        (c.factor != 1.0 || c.offset != 0.0).then_some(c)
    }

    #[inline]
    pub fn apply(&self, x: f64) -> f64 {
        self.factor * x + self.offset
    }
}

#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Recorded {
    pub instance: usize,
    pub var: VarRef,
    /// CSV header, e.g. `bogie.wheelset_front.y [m]`.
    pub label: String,
    /// What a reader of the results needs to know of the variable.
    pub info: ColumnInfo,
}

/// A recorded variable as a reader of the results sees it: type (with the items of an
/// Enumeration), unit and the FMU variable it comes from.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ColumnInfo {
    pub ty: Option<ScalarType>,
    /// `instance.variable`.
    pub name: String,
    pub unit: Option<String>,
    pub causality: String,
    pub description: Option<String>,
    pub instance: String,
    pub fmu_guid: String,
    /// Enumeration items (value, name).
    pub items: Vec<(i32, String)>,
}

impl ColumnInfo {
    /// The type, Real when unknown.
    pub fn scalar_type(&self) -> ScalarType {
        self.ty.unwrap_or(ScalarType::Real)
    }
    /// The item name of an Enumeration value.
    pub fn item(&self, value: f64) -> Option<&str> {
        self.items
            .iter()
            .find(|(v, _)| f64::from(*v) == value)
            .map(|(_, n)| n.as_str())
    }
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
    /// Texts of the String start values (their values index this list).
    pub strings: Vec<String>,
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
    /// Set when an FMU asked to end the simulation before the stop time.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub terminated: Option<Terminated>,
    /// Set on the history of a run that failed: the results stop at the last communication
    /// point every instance completed, before the failure.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub failed: Option<Failure>,
}

/// The run failed after its history up to `time_s` was recorded.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Failure {
    /// The last recorded communication point \[s\].
    pub time_s: f64,
    /// What failed (the run's error).
    pub error: String,
}

/// An FMU ended the run: its step returned fmi2Discard with fmi2Terminated true (FMI 2.0
/// section 4.2.3). The results stop at the last communication point every instance completed.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Terminated {
    /// The instance that asked.
    pub instance: String,
    /// The last completed communication point (the last result row) \[s\].
    pub time_s: f64,
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
        )?;
        if let Some(t) = &self.terminated {
            write!(
                f,
                "; terminated by instance '{}' at t = {} s",
                t.instance, t.time_s
            )?;
        }
        if let Some(x) = &self.failed {
            write!(f, "; failed after t = {} s", x.time_s)?;
        }
        Ok(())
    }
}

/// Recorded results: `header[0]` is `time [s]`, each row has `header.len()` values.
#[derive(Debug, Clone, PartialEq)]
pub struct SimOutput {
    pub header: Vec<String>,
    pub data: Vec<f64>,
    pub summary: Summary,
    /// What each column after time holds (may be empty: all Real).
    pub columns: Vec<ColumnInfo>,
    /// Texts of the String values (a String column's values index this list).
    pub strings: Vec<String>,
    /// How the rows were decimated from the record at every communication point; `None`:
    /// every communication point is here ([`crate::decimation`]).
    pub decimation: Option<crate::decimation::Decimation>,
}

impl SimOutput {
    /// The description of column `c` (0 is time), Real when not described.
    pub fn column_info(&self, c: usize) -> ColumnInfo {
        c.checked_sub(1)
            .and_then(|k| self.columns.get(k))
            .cloned()
            .unwrap_or_default()
    }
    /// The text of a String value.
    pub fn text(&self, value: f64) -> Option<&str> {
        if value >= 0.0 && value.fract() == 0.0 {
            self.strings.get(value as usize).map(String::as_str)
        } else {
            None
        }
    }
    /// The strings of a String column, by label as in [`SimOutput::column`].
    pub fn text_column(&self, name: &str) -> Option<Vec<String>> {
        let x = self.column(name)?;
        x.into_iter()
            .map(|v| self.text(v).map(str::to_string))
            .collect()
    }
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
    #[error("instance '{instance}': setting start value {assignment} failed: {source}")]
    StartValue {
        instance: String,
        /// `'name' = value`.
        assignment: String,
        #[source]
        source: Box<SlaveError>,
    },
    #[error("at t = {} s: {source}", num(*.time))]
    Slave {
        time: f64,
        #[source]
        source: Box<SlaveError>,
    },
    #[error(
        "at t = {} s: instance '{instance}' discarded the step of {} s: {reason}",
        num(*.time),
        num(*.step)
    )]
    Discarded {
        time: f64,
        instance: String,
        step: f64,
        reason: String,
    },
    #[error("at t = {} s: '{label}' is not finite ({value})", num(*.time))]
    NonFinite {
        time: f64,
        label: String,
        value: f64,
    },
    #[error("cancelled at t = {} s", num(*.time))]
    Cancelled { time: f64 },
    #[error(
        "at t = {} s: out of memory for the recorded results ({values} values so far)",
        num(*.time)
    )]
    OutOfMemory { time: f64, values: usize },
}

/// Environment variable raising [`RunLimits::max_steps`].
pub const MAX_STEPS_VAR: &str = "MASTER_MAX_STEPS";

/// Environment variable raising [`RunLimits::max_recorded_values`].
pub const MAX_RECORDED_VALUES_VAR: &str = "MASTER_MAX_RECORDED_VALUES";

/// Why `step` is too short for the times it steps through, if it is: near the largest time
/// of the run a step of `step` would not advance time (1e16 + 1e-3 == 1e16) or would be off
/// by half of it, so communication points would repeat or jump.
pub fn step_below_resolution(start: f64, stop: f64, step: f64) -> Option<String> {
    let largest = start.abs().max(stop.abs());
    let advance = (largest + step) - largest;
    (advance < 0.5 * step || advance > 1.5 * step).then(|| {
        format!(
            "step {} s is below the time resolution at t = {} s (a step there advances time by \
             {} s): shift the start time towards 0",
            num(step),
            num(largest),
            num(advance)
        )
    })
}

/// How large one run may be, checked before any FMU is called: a stop time of 1e9 s at a 1 s
/// step, or a step of 1e-300 s, is refused up front instead of running for days or running out
/// of memory for its results.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RunLimits {
    /// Communication steps of one run (default 1e8: 28 h of simulated time at 1 ms).
    pub max_steps: u64,
    /// Recorded values of one run, time included: (steps + 1) x (recorded variables + 1)
    /// (default 5e8 = 4 GB of results).
    pub max_recorded_values: u64,
}

impl Default for RunLimits {
    fn default() -> Self {
        RunLimits {
            max_steps: 100_000_000,
            max_recorded_values: 500_000_000,
        }
    }
}

impl RunLimits {
    /// The defaults, each replaced by its environment variable when set ([`MAX_STEPS_VAR`],
    /// [`MAX_RECORDED_VALUES_VAR`]: a plain integer); one set to anything else is an error.
    pub fn from_env() -> Result<Self, String> {
        let mut limits = RunLimits::default();
        for (var, field) in [
            (MAX_STEPS_VAR, &mut limits.max_steps),
            (MAX_RECORDED_VALUES_VAR, &mut limits.max_recorded_values),
        ] {
            if let Some(v) = std::env::var_os(var) {
                let s = v.to_string_lossy();
                *field = s.trim().parse::<u64>().map_err(|_| {
                    format!(
                        "environment variable {var}='{}' is not a non-negative integer",
                        text(&s)
                    )
                })?;
            }
        }
        Ok(limits)
    }

    /// The number of communication steps over `span_s` at `step_s` (both finite, positive),
    /// refused when above the limit. The count is compared as a float, so 1e300 steps cannot
    /// overflow anything.
    pub fn steps(&self, span_s: f64, step_s: f64) -> Result<u64, String> {
        let n = (span_s / step_s).round();
        if n.is_nan() || n > self.max_steps as f64 {
            return Err(format!(
                "{} s at a step of {} s is {n:e} communication steps, more than the {} \
                 allowed (a larger step, or raise the limit with the environment variable \
                 {MAX_STEPS_VAR})",
                num(span_s),
                num(step_s),
                self.max_steps
            ));
        }
        Ok(n as u64)
    }

    /// Refuses a run whose recorded results, `steps + 1` rows of `columns` values (time
    /// included), would be more values than the limit.
    pub fn recorded(&self, steps: u64, columns: usize) -> Result<(), String> {
        let values = (steps as f64 + 1.0) * columns as f64;
        if values > self.max_recorded_values as f64 {
            return Err(format!(
                "recording {columns} columns (time included) at {} communication points is \
                 {values:e} values ({:.1} GB), more than the {} allowed (record fewer \
                 variables, take a larger step, or raise the limit with the environment \
                 variable {MAX_RECORDED_VALUES_VAR})",
                steps + 1,
                values * 8e-9,
                self.max_recorded_values
            ));
        }
        Ok(())
    }
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
        return bad(format!("step must be > 0, got {}", num(plan.step)));
    }
    if !(plan.start_time.is_finite() && plan.stop_time.is_finite())
        || plan.stop_time <= plan.start_time
    {
        return bad(format!(
            "stop_time ({}) must be finite and greater than start_time ({})",
            num(plan.stop_time),
            num(plan.start_time)
        ));
    }
    let span = plan.stop_time - plan.start_time;
    let limits = RunLimits::from_env().map_err(SimError::Plan)?;
    limits.steps(span, plan.step).map_err(SimError::Plan)?;
    if let Some(why) = step_below_resolution(plan.start_time, plan.stop_time, plan.step) {
        return bad(why);
    }
    let n = (span / plan.step).round();
    if n < 1.0 || (n * plan.step - span).abs() > 1e-9 * span.max(plan.step) {
        return bad(format!(
            "stop_time - start_time ({}) is not an integer multiple of step ({})",
            num(span),
            num(plan.step)
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
    // an input takes one value per point: with two connections the last write would win,
    // and which write comes last depends on the algorithm and on how writes are batched
    // an Enumeration is written with fmi2SetInteger: same value reference, same variable
    let base = |ty: ScalarType| match ty {
        ScalarType::Enumeration => ScalarType::Integer,
        t => t,
    } as u8;
    let mut inputs: Vec<(usize, u8, u32, usize)> = plan
        .connections
        .iter()
        .enumerate()
        .map(|(k, c)| (c.to_instance, base(c.to.ty), c.to.vr, k))
        .collect();
    inputs.sort_unstable();
    if let Some(w) = inputs
        .windows(2)
        .find(|w| (w[0].0, w[0].1, w[0].2) == (w[1].0, w[1].1, w[1].2))
    {
        let (a, b) = (&plan.connections[w[0].3], &plan.connections[w[1].3]);
        return bad(format!(
            "input {:?} {} of instance '{}' is driven by two connections (from {} and from {})",
            b.to.ty, b.to.vr, plan.instances[b.to_instance].name, a.label, b.label
        ));
    }
    limits
        .recorded(n as u64, plan.record.len() + 1)
        .map_err(SimError::Plan)?;
    Ok(n as u64)
}
