//! The plan the coupling algorithm runs (validated by [`crate::system`]), its results and
//! errors, and the checks made before any call.

use crate::slave::{SlaveError, VarRef};

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
