//! The data exchange of a plan, arranged once per run for batched calls: every slave's
//! connected outputs are read with one call per type, every slave's connected inputs written
//! with one call per type, every slave's recorded variables read with one call per type.

use super::{CouplingPlan, UnitConversion};
use crate::slave::{VarBatch, VarRef};

/// The connected outputs of one instance and where they go.
#[derive(Debug, Default)]
pub(super) struct Source {
    /// One entry per connection from this instance, in plan order.
    pub outputs: VarBatch,
    /// The connection (index into the plan's) of each output.
    pub connections: Vec<usize>,
    /// The instances its outputs feed, in order of first connection.
    pub dests: Vec<Dest>,
    /// The instances among `dests` with an input from it that feeds directly through to one
    /// of their outputs (their outputs change when it sets them).
    pub feeds_through: Vec<usize>,
    /// Per output: it may change within a step when the instance's inputs are set
    /// (`PlanConnection::source_depends_on_inputs`).
    pub varies: Vec<bool>,
    /// The outputs passed on in another unit: (position in `outputs`, conversion), applied
    /// to the value as it is read (each connection has its own position).
    pub conversions: Vec<(usize, UnitConversion)>,
}

/// Inputs of one instance written together.
#[derive(Debug)]
pub(super) struct Dest {
    pub instance: usize,
    pub inputs: VarBatch,
    /// For each input: (source instance, position in that source's outputs).
    pub from: Vec<(usize, usize)>,
    /// When every input comes from one source's consecutive outputs: the first position
    /// (the inputs are that slice of the source's outputs, written without a copy).
    pub run: Option<usize>,
    /// One of its inputs comes from an output that may change within a step (see
    /// `Source::varies`; set by `Exchange::new` for a source's dests).
    pub varies: bool,
}

/// Recorded variables of one instance.
#[derive(Debug)]
pub(super) struct RecordGroup {
    pub instance: usize,
    pub vars: VarBatch,
    /// Result column (0-based, after time) of each variable.
    pub columns: Vec<usize>,
    /// The first column when `columns` are consecutive (then the slave writes into the row
    /// itself).
    pub first_column: Option<usize>,
    /// When every variable is also a connected output of the instance: its position in the
    /// instance's `Source::outputs` (the value read for the exchange is the value a second
    /// read gives while no call changed the instance since).
    pub from_outputs: Option<Vec<usize>>,
}

/// Real inputs of one instance gathered from one or more sources, written in one call.
#[derive(Debug)]
pub(super) struct MergedWrite {
    pub instance: usize,
    pub vrs: Vec<u32>,
    /// For each value: (source instance, position in that source's outputs).
    pub from: Vec<(usize, usize)>,
    /// When every value comes from one source's consecutive outputs: (source, first
    /// position), written from there without a copy.
    pub run: Option<(usize, usize)>,
    /// The source instances of `from` with an output that may change within a step (see
    /// `Source::varies`), each once: read again first if stale.
    pub sources: Vec<usize>,
}

/// The writes of a Gauss-Seidel macro step in the common case, arranged once. A write of
/// Reals to an instance whose outputs are never read again within a step (no input of it
/// feeds through) is deferred to that instance's next call: its step when the source comes
/// earlier in the order, else the end of the macro step. Writes deferred to the same point
/// are merged, so an instance fed by several sources gets one fmi2SetReal, and it sees the
/// same values at each of its calls as with one write per source. This holds for a single
/// source too, and an instance gets at most two merged writes per step (before its step, at
/// the end). Each input has one connection (`check_plan`), so merging cannot reorder two
/// writes of the same input.
#[derive(Debug, Default)]
pub(super) struct GaussSeidelWrites {
    /// Per position in the order: the write just before that instance steps.
    pub before_step: Vec<Option<MergedWrite>>,
    /// Per instance, per entry of its `Source::dests`: written at once after its outputs are
    /// read (a batch with other types than Real, or an instance read again within the step).
    pub immediate: Vec<Vec<bool>>,
    /// After the last instance stepped: the inputs from instances later in the order.
    pub at_end: Vec<MergedWrite>,
    /// Per instance: its position in the order (`usize::MAX`: not in it).
    pub position: Vec<usize>,
    /// Per instance: every write of its outputs is deferred (none is made at once), so an
    /// outputs read within the step can wait until a write uses them.
    pub deferred_only: Vec<bool>,
}

impl GaussSeidelWrites {
    fn new(sources: &[Source], order: &[usize]) -> Self {
        let n = sources.len();
        let mut position = vec![usize::MAX; n];
        for (p, &i) in order.iter().enumerate() {
            if i < n {
                position[i] = p;
            }
        }
        let read_again: Vec<bool> = (0..n)
            .map(|j| sources.iter().any(|s| s.feeds_through.contains(&j)))
            .collect();
        let mut before_step: Vec<Option<MergedWrite>> = order.iter().map(|_| None).collect();
        let mut at_end: Vec<MergedWrite> = Vec::new();
        let mut immediate: Vec<Vec<bool>> = vec![Vec::new(); n];
        for &i in order {
            let Some(src) = sources.get(i) else { continue };
            for d in &src.dests {
                let j = d.instance;
                let deferred = d.inputs.all_real() && !read_again[j] && position[j] != usize::MAX;
                immediate[i].push(!deferred);
                if !deferred {
                    continue;
                }
                let w = if position[i] < position[j] {
                    before_step[position[j]].get_or_insert_with(|| MergedWrite::empty(j))
                } else {
                    let k = at_end
                        .iter()
                        .position(|w| w.instance == j)
                        .unwrap_or_else(|| {
                            at_end.push(MergedWrite::empty(j));
                            at_end.len() - 1
                        });
                    &mut at_end[k]
                };
                w.vrs.extend(d.inputs.vars().iter().map(|v| v.vr));
                w.from.extend_from_slice(&d.from);
            }
        }
        for w in before_step.iter_mut().flatten().chain(at_end.iter_mut()) {
            w.sources = w
                .from
                .iter()
                .filter(|&&(s, k)| sources[s].varies.get(k).copied().unwrap_or(true))
                .map(|&(s, _)| s)
                .collect();
            w.sources.sort_unstable();
            w.sources.dedup();
            w.run = w
                .from
                .windows(2)
                .all(|p| p[1].0 == p[0].0 && p[1].1 == p[0].1 + 1)
                .then(|| w.from.first().copied())
                .flatten();
        }
        let deferred_only = (0..n)
            .map(|i| {
                position[i] != usize::MAX
                    && sources[i].feeds_through.is_empty()
                    && immediate[i].len() == sources[i].dests.len()
                    && immediate[i].iter().all(|&now| !now)
            })
            .collect();
        GaussSeidelWrites {
            before_step,
            immediate,
            at_end,
            position,
            deferred_only,
        }
    }
}

impl MergedWrite {
    fn empty(instance: usize) -> Self {
        MergedWrite {
            instance,
            vrs: Vec::new(),
            from: Vec::new(),
            run: None,
            sources: Vec::new(),
        }
    }
}

/// The whole exchange of a plan.
#[derive(Debug, Default)]
pub(super) struct Exchange {
    /// Indexed by instance.
    pub sources: Vec<Source>,
    /// Gauss-Seidel's writes in the common case.
    pub gauss_seidel: GaussSeidelWrites,
    /// Per plan connection: (source instance, position in its outputs).
    pub connection_at: Vec<(usize, usize)>,
    /// All connected inputs per destination instance (Jacobi writes them after all reads).
    pub jacobi: Vec<Dest>,
    pub record: Vec<RecordGroup>,
}

/// Variables of one instance with a value per variable.
struct Grouped<T> {
    instance: usize,
    vars: VarBatch,
    payload: Vec<T>,
}

/// Groups `(instance, variable, payload)` by instance, in order of first appearance.
fn group<T>(items: impl Iterator<Item = (usize, VarRef, T)>) -> Vec<Grouped<T>> {
    let mut groups: Vec<(usize, Vec<VarRef>, Vec<T>)> = Vec::new();
    for (instance, var, payload) in items {
        match groups.iter_mut().find(|g| g.0 == instance) {
            Some(g) => {
                g.1.push(var);
                g.2.push(payload);
            }
            None => groups.push((instance, vec![var], vec![payload])),
        }
    }
    groups
        .into_iter()
        .map(|(instance, vars, payload)| Grouped {
            instance,
            vars: VarBatch::new(vars),
            payload,
        })
        .collect()
}

fn dests(groups: Vec<Grouped<(usize, usize)>>) -> Vec<Dest> {
    groups
        .into_iter()
        .map(|g| Dest {
            instance: g.instance,
            inputs: g.vars,
            run: g
                .payload
                .windows(2)
                .all(|w| w[1].0 == w[0].0 && w[1].1 == w[0].1 + 1)
                .then(|| g.payload.first().map(|&(_, k)| k))
                .flatten(),
            from: g.payload,
            varies: true,
        })
        .collect()
}

impl Exchange {
    /// Arranges `plan`'s connections and records (instances assumed valid: see `check_plan`).
    pub fn new(plan: &CouplingPlan) -> Self {
        let n = plan.instances.len();
        // position of each connection in its source's outputs
        let mut count = vec![0usize; n];
        let connection_at: Vec<(usize, usize)> = plan
            .connections
            .iter()
            .map(|c| {
                let i = c.from_instance;
                count[i] += 1;
                (i, count[i] - 1)
            })
            .collect();
        let links = || plan.connections.iter().zip(connection_at.iter().copied());
        let mut sources: Vec<Source> = (0..n)
            .map(|i| {
                let mine = || {
                    links()
                        .enumerate()
                        .filter(move |(_, (c, _))| c.from_instance == i)
                };
                Source {
                    outputs: VarBatch::new(mine().map(|(_, (c, _))| c.from).collect()),
                    connections: mine().map(|(ci, _)| ci).collect(),
                    varies: mine()
                        .map(|(_, (c, _))| c.source_depends_on_inputs)
                        .collect(),
                    conversions: mine()
                        .enumerate()
                        .filter_map(|(k, (_, (c, _)))| c.conversion.map(|u| (k, u)))
                        .collect(),
                    dests: dests(group(mine().map(|(_, (c, at))| (c.to_instance, c.to, at)))),
                    feeds_through: {
                        let mut f: Vec<usize> = mine()
                            .filter(|(_, (c, _))| c.feedthrough)
                            .map(|(_, (c, _))| c.to_instance)
                            .collect();
                        f.dedup();
                        f.sort_unstable();
                        f.dedup();
                        f
                    },
                }
            })
            .collect();
        for src in &mut sources {
            let Source { dests, varies, .. } = src;
            for d in dests.iter_mut() {
                d.varies = d
                    .from
                    .iter()
                    .any(|&(_, k)| varies.get(k).copied().unwrap_or(true));
            }
        }
        let jacobi = dests(group(links().map(|(c, at)| (c.to_instance, c.to, at))));
        let record = group(
            plan.record
                .iter()
                .enumerate()
                .map(|(col, r)| (r.instance, r.var, col)),
        )
        .into_iter()
        .map(|g| RecordGroup {
            instance: g.instance,
            from_outputs: {
                // a value converted for its destination is not the variable's own
                let src = &sources[g.instance];
                let own = |k: usize| !src.conversions.iter().any(|&(c, _)| c == k);
                let outputs = src.outputs.vars();
                g.vars
                    .vars()
                    .iter()
                    .map(|v| (0..outputs.len()).find(|&k| outputs[k] == *v && own(k)))
                    .collect()
            },
            vars: g.vars,
            first_column: g
                .payload
                .windows(2)
                .all(|w| w[1] == w[0] + 1)
                .then(|| g.payload.first().copied())
                .flatten(),
            columns: g.payload,
        })
        .collect();
        Exchange {
            gauss_seidel: GaussSeidelWrites::new(&sources, &plan.order),
            sources,
            connection_at,
            jacobi,
            record,
        }
    }
}
