//! A system prepared once for many runs: FMUs opened, checked, unpacked and loaded once, the
//! coupling plan built once; a run is then typed start values plus a stop time.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::PathBuf;
use std::sync::Arc;

use serde_json::Value;

use super::plan::start_value;
use super::{split_ref, LoadedSystem, RunError, SystemError};
use crate::coupling::{simulate_keeping_history, CouplingPlan, FailedRun, RunOptions, SimOutput};
use crate::fmu::{FmuSlave, PreparedFmu};
use crate::model_description::ModelDescription;
use crate::show::text;
use crate::slave::{Slave, VarRef};

/// What one run of a [`PreparedSystem`] changes: validated, typed start values (replacing the
/// system's or added to them) and the stop time.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RunChanges {
    /// (instance index, variable name, variable, value as f64; a String's indexes `strings`)
    start_values: Vec<(usize, String, VarRef, f64)>,
    stop_time: Option<f64>,
    strings: Vec<String>,
}

impl RunChanges {
    /// Number of start values the run sets beyond the system's.
    pub fn len(&self) -> usize {
        self.start_values.len()
    }
    pub fn is_empty(&self) -> bool {
        self.start_values.is_empty() && self.stop_time.is_none()
    }
}

/// A system description with its FMUs prepared ([`PreparedFmu`], shared by instances of the
/// same file) and its plan. `Sync`: the workers of a run set share one and each run
/// instantiates its own slaves.
#[derive(Debug)]
pub struct PreparedSystem {
    system: LoadedSystem,
    /// Absolute FMU path of each instance.
    fmu_paths: Vec<PathBuf>,
    /// The prepared FMU of each instance.
    fmus: Vec<Arc<PreparedFmu>>,
    plan: CouplingPlan,
    /// The SHA-1 of each FMU file when it was loaded, by its absolute path.
    fmu_digests: BTreeMap<String, String>,
}

impl PreparedSystem {
    /// Opens and checks the FMUs (each file once), validates the system into its plan, then
    /// unpacks and loads each FMU file once.
    pub fn prepare(system: &LoadedSystem) -> Result<Self, RunError> {
        let archives = system.open_fmus()?;
        let models: Vec<_> = archives.iter().map(|a| &a.model).collect();
        let plan = system.plan(&models)?;
        let mut by_path: HashMap<PathBuf, Arc<PreparedFmu>> = HashMap::new();
        let mut fmus = Vec::with_capacity(archives.len());
        let mut fmu_paths = Vec::with_capacity(archives.len());
        // by the absolute paths the runs' descriptions give
        let fmu_digests = system.resolved().fmu_digests();
        for (i, archive) in archives.into_iter().enumerate() {
            let path = system.fmu_path(i);
            let path = std::path::absolute(&path).unwrap_or(path);
            let fmu = match by_path.get(&path) {
                Some(f) => Arc::clone(f),
                None => {
                    let name = &system.desc.instances[i].name;
                    let f = Arc::new(PreparedFmu::prepare(archive, name)?);
                    by_path.insert(path.clone(), Arc::clone(&f));
                    f
                }
            };
            fmus.push(fmu);
            fmu_paths.push(path);
        }
        Ok(PreparedSystem {
            system: system.clone(),
            fmu_paths,
            fmus,
            plan,
            fmu_digests,
        })
    }

    pub fn system(&self) -> &LoadedSystem {
        &self.system
    }

    /// The plan of a run without changes.
    pub fn plan(&self) -> &CouplingPlan {
        &self.plan
    }

    /// Absolute FMU path of each instance.
    pub fn fmu_paths(&self) -> &[PathBuf] {
        &self.fmu_paths
    }

    /// The SHA-1 of each FMU file as it was when loaded, by its absolute path.
    pub fn fmu_digests(&self) -> &BTreeMap<String, String> {
        &self.fmu_digests
    }

    /// Of the parameter names `keys` (`instance.variable`), those that are Integers or
    /// Enumerations in their FMUs (the others, and names that are not the system's, are left
    /// out: [`Self::changes`] refuses the latter).
    pub fn integer_parameters<'a>(
        &self,
        keys: impl IntoIterator<Item = &'a String>,
    ) -> BTreeSet<String> {
        let models: Vec<&ModelDescription> = self.fmus.iter().map(|f| f.model()).collect();
        self.system.integer_parameters(&models, keys)
    }

    /// Validates the start values of one run (`instance.variable` -> value, as in a run set)
    /// and its stop time (`None`: the system's). `run` names the run in messages.
    pub fn changes(
        &self,
        parameters: &BTreeMap<String, Value>,
        stop_time: Option<f64>,
        run: &str,
    ) -> Result<RunChanges, SystemError> {
        let invalid = |field: String, _: &str, reason: String| SystemError::Invalid {
            file: run.to_string(),
            line: None,
            field,
            reason,
        };
        let mut start_values = Vec::with_capacity(parameters.len());
        let mut strings = Vec::new();
        for (key, value) in parameters {
            // named as given ("bogie.vehicle.speed"), not by the description's field
            let invalid_key = |_: String, _: &str, reason: String| SystemError::Invalid {
                file: run.to_string(),
                line: None,
                field: key.clone(),
                reason,
            };
            let Some((inst, var)) = split_ref(key) else {
                return Err(invalid(
                    key.clone(),
                    key,
                    format!("'{}' is not of the form 'instance.variable'", text(key)),
                ));
            };
            let instances = &self.system.desc.instances;
            let Some(i) = instances.iter().position(|s| s.name == inst) else {
                return Err(invalid(
                    key.clone(),
                    key,
                    format!("unknown instance '{}'", text(inst)),
                ));
            };
            let (v, x) = start_value(
                i,
                self.fmus[i].model(),
                var,
                value,
                &mut strings,
                &invalid_key,
            )?;
            start_values.push((i, var.to_string(), v, x));
        }
        if let Some(t) = stop_time {
            if t != self.system.desc.stop_time {
                // said of this run's stop time, not at the line of the description's
                self.system
                    .stop_time_problem(t)
                    .map_err(|(field, reason)| invalid(field.into(), "", reason))?;
                // the recorded values of the longer run, refused now as a description's are,
                // not when the run starts
                let limits = crate::coupling::RunLimits::from_env()
                    .map_err(|r| invalid("step".into(), "", r))?;
                let steps = limits
                    .steps(t - self.plan.start_time, self.plan.step)
                    .map_err(|r| invalid("step".into(), "", r))?;
                limits
                    .recorded(steps, self.plan.record.len() + 1)
                    .map_err(|r| invalid("stop_time".into(), "", r))?;
            }
        }
        Ok(RunChanges {
            start_values,
            stop_time,
            strings,
        })
    }

    /// The plan of one run: the system's start values with the run's merged in and its stop
    /// time.
    pub fn plan_for(&self, changes: &RunChanges) -> CouplingPlan {
        apply(&self.plan, changes)
    }

    /// One run: instantiates every instance (sharing the prepared FMUs), simulates, frees the
    /// instances (also on error).
    pub fn run(&self, changes: &RunChanges, opts: &RunOptions) -> Result<SimOutput, RunError> {
        self.run_keeping_history(changes, opts).map_err(|f| f.error)
    }

    /// [`Self::run`], keeping the history of a run that fails (see [`FailedRun`]).
    pub fn run_keeping_history(
        &self,
        changes: &RunChanges,
        opts: &RunOptions,
    ) -> Result<SimOutput, FailedRun<RunError>> {
        let plan = self.plan_for(changes);
        let mut slaves: Vec<FmuSlave> = Vec::with_capacity(self.fmus.len());
        for (fmu, inst) in self.fmus.iter().zip(&self.system.desc.instances) {
            let slave = fmu
                .instantiate(&inst.name, inst.logging)
                .map_err(RunError::from)?;
            slaves.push(slave);
        }
        let mut refs: Vec<&mut dyn Slave> =
            slaves.iter_mut().map(|s| s as &mut dyn Slave).collect();
        simulate_keeping_history(&plan, &mut refs, opts).map_err(|f| f.map(RunError::from))
    }
}

/// `plan` with the run's stop time and start values: each instance's start values in name
/// order with the run's replacing or joining the system's, as a system description holding
/// those values would give (so a prepared run sets the same values in the same order). A plan
/// without names keeps its values and gets the run's appended (set later, so they win).
fn apply(plan: &CouplingPlan, changes: &RunChanges) -> CouplingPlan {
    let mut plan = plan.clone();
    if let Some(t) = changes.stop_time {
        plan.stop_time = t;
    }
    // the run's texts follow the system's
    let offset = plan.strings.len() as f64;
    plan.strings.extend(changes.strings.iter().cloned());
    let shifted: Vec<(usize, String, VarRef, f64)> = changes
        .start_values
        .iter()
        .map(|(i, n, v, x)| {
            let x = if v.ty == crate::slave::ScalarType::String {
                x + offset
            } else {
                *x
            };
            (*i, n.clone(), *v, x)
        })
        .collect();
    for (i, inst) in plan.instances.iter_mut().enumerate() {
        let mut run = shifted.iter().filter(|c| c.0 == i).peekable();
        if run.peek().is_none() {
            continue;
        }
        if inst.parameter_names.len() != inst.parameters.len() {
            for (_, name, v, x) in run {
                inst.parameters.push((*v, *x));
                inst.parameter_names.push(name.clone());
            }
            continue;
        }
        let mut merged: BTreeMap<String, (VarRef, f64)> = std::mem::take(&mut inst.parameter_names)
            .into_iter()
            .zip(inst.parameters.iter().copied())
            .collect();
        for (_, name, v, x) in run {
            merged.insert(name.clone(), (*v, *x));
        }
        (inst.parameter_names, inst.parameters) = merged.into_iter().unzip();
    }
    plan
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coupling::tests::two_mass_plan;
    use crate::coupling::Algorithm;

    #[test]
    fn run_changes_merge_by_name_and_set_the_stop_time() {
        let plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 1e-3, 1.0);
        let changes = RunChanges {
            start_values: vec![
                (1, "k".into(), VarRef::real(1), 300.0),
                (1, "a_new".into(), VarRef::real(7), 2.0),
                (0, "x0".into(), VarRef::real(4), 0.2),
            ],
            stop_time: Some(2.0),
            strings: vec![],
        };
        let p = apply(&plan, &changes);
        assert_eq!(p.stop_time, 2.0);
        // sdm has names: merged in name order, k replaced
        assert_eq!(p.instances[1].parameter_names, ["a_new", "d", "k", "m"]);
        assert_eq!(
            p.instances[1].parameters,
            vec![
                (VarRef::real(7), 2.0),
                (VarRef::real(2), 1.0),
                (VarRef::real(1), 300.0),
                (VarRef::real(0), 0.5)
            ]
        );
        // ms has none: the run's value is set after the system's
        assert_eq!(p.instances[0].parameters.len(), 5);
        assert_eq!(p.instances[0].parameters[4], (VarRef::real(4), 0.2));
        // no changes: the plan itself
        assert_eq!(apply(&plan, &RunChanges::default()), plan);
    }
}
