//! Type erasure: one non-generic view of any `FmuModel`, so the state machine and the C API
//! are written once.

use std::any::Any;
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::model::{Diagnostics, FmuModel, InstanceContext, ModelError, StepError};
use crate::variable::{Access, VarMeta, VarType, Variable};

/// What the component needs from a model, without knowing its type.
pub trait ErasedModel: Send {
    fn metas(&self) -> &[VarMeta];
    fn get_integer(&self, index: usize) -> Option<i32>;
    fn get_boolean(&self, index: usize) -> Option<bool>;
    fn get_string(&self, index: usize) -> Option<String>;
    /// Reads the Reals with value references `vrs` into `out` (as many): one call for a whole
    /// fmi2GetReal. `Err(vr)`: the first value reference that is no Real (nothing is written).
    fn get_reals(&self, vrs: &[u32], out: &mut [f64]) -> Result<(), u32>;
    /// Returns false if the variable has no setter of that type.
    fn set_integer(&mut self, index: usize, value: i32) -> bool;
    fn set_boolean(&mut self, index: usize, value: bool) -> bool;
    fn set_string(&mut self, index: usize, value: &str) -> bool;
    /// Writes the Reals with value references `vrs` (the caller checked every one): one call
    /// for a whole fmi2SetReal. `Err(vr)`: the first value reference with no Real setter
    /// (values before it are written).
    fn set_reals(&mut self, vrs: &[u32], values: &[f64]) -> Result<(), u32>;
    fn reset(&mut self, ctx: &InstanceContext) -> Result<(), ModelError>;
    /// A copy of this model and its variable table (for the outputs of Initialization Mode,
    /// computed on a copy so that the model itself is initialised once, at exit).
    fn duplicate(&self) -> Box<dyn ErasedModel>;
    fn exit_initialization(&mut self, diag: &mut Diagnostics) -> Result<(), ModelError>;
    fn update_outputs(&mut self, diag: &mut Diagnostics) -> Result<(), ModelError>;
    fn do_step(&mut self, time: f64, step: f64, diag: &mut Diagnostics) -> Result<(), StepError>;
    fn step_computes_outputs(&self) -> bool;
    /// [`FmuModel::MAX_COMMUNICATION_STEP_S`].
    fn max_communication_step_s(&self) -> f64;
    fn snapshot(&self) -> Box<dyn Any + Send>;
    /// Whether `snapshot` is a snapshot of this model.
    fn owns(&self, snapshot: &(dyn Any + Send)) -> bool;
    /// Restore from a snapshot taken from an instance of the same model.
    fn restore(&mut self, snapshot: &(dyn Any + Send)) -> bool;
    /// Overwrite an existing snapshot in place (fmi2GetFMUstate with a non-null state).
    fn update_snapshot(&self, snapshot: &mut (dyn Any + Send)) -> bool;
    fn serialize(&self, snapshot: &(dyn Any + Send)) -> Option<Vec<u8>>;
    /// A snapshot from serialised bytes: refused if they do not decode exactly (no trailing
    /// bytes), belong to another model, or hold a non-finite number.
    fn deserialize(&self, bytes: &[u8]) -> Result<Box<dyn Any + Send>, String>;
}

/// The setter of a Real variable (None: not settable).
type RealSetter<M> = Option<fn(&mut M, f64)>;

/// A model value plus its variable table.
pub struct Typed<M: FmuModel> {
    pub model: M,
    /// Shared with the instance's copies (the Initialization Mode view): it never changes.
    table: Arc<Table<M>>,
}

/// The variables of a model: what [`FmuModel::variables`] declares, indexed for the calls.
struct Table<M: FmuModel> {
    vars: Vec<Variable<M>>,
    metas: Vec<VarMeta>,
    /// The Real accessors by value reference (Real value references are 0, 1, ... in
    /// declaration order, see [`VrIndex`]): a read or write is one index and one call.
    real_get: Vec<fn(&M) -> f64>,
    real_set: Vec<RealSetter<M>>,
}

impl<M: FmuModel> Typed<M> {
    /// Every parameter and input of `model` holds what fmi2SetXXX would accept: a Real within
    /// its declared range, an Enumeration one of its items. A state decoded from bytes a host
    /// altered is refused here rather than reaching the physics (a negative stiffness, an
    /// unknown model choice).
    fn check_settable_values(&self, model: &M) -> Result<(), String> {
        for v in self
            .table
            .vars
            .iter()
            .filter(|v| v.meta.causality.is_settable())
        {
            let m = &v.meta;
            let bad = match &v.access {
                Access::Real { get, .. } => {
                    let x = get(model);
                    (m.min.is_some_and(|lo| x < lo) || m.max.is_some_and(|hi| x > hi))
                        .then(|| format!("{x:?} is outside its range"))
                }
                Access::Integer { get, .. } => {
                    let x = get(model);
                    let outside = m.min.is_some_and(|lo| f64::from(x) < lo)
                        || m.max.is_some_and(|hi| f64::from(x) > hi)
                        || m.enumeration.is_some_and(|e| e.item(x).is_none());
                    outside.then(|| format!("{x} is outside its range or items"))
                }
                Access::Boolean { .. } | Access::String { .. } => None,
            };
            if let Some(reason) = bad {
                return Err(format!(
                    "the serialised state holds '{}' = {reason}: not a state this FMU produced",
                    m.name
                ));
            }
        }
        Ok(())
    }

    pub fn new(ctx: &InstanceContext) -> Result<Self, ModelError> {
        let vars = M::variables();
        let metas = vars.iter().map(|v| v.meta.clone()).collect();
        let (mut real_get, mut real_set) = (Vec::new(), Vec::new());
        for v in &vars {
            if let Access::Real { get, set } = &v.access {
                real_get.push(*get);
                real_set.push(*set);
            }
        }
        Ok(Typed {
            model: M::instantiate(ctx)?,
            table: Arc::new(Table {
                vars,
                metas,
                real_get,
                real_set,
            }),
        })
    }
}

/// The serialised form of a model snapshot: tagged so that bytes from another model are
/// rejected rather than misread.
#[derive(Serialize, Deserialize)]
struct Tagged<M> {
    model_name: String,
    model: M,
}

impl<M: FmuModel> ErasedModel for Typed<M> {
    fn metas(&self) -> &[VarMeta] {
        &self.table.metas
    }

    fn get_integer(&self, index: usize) -> Option<i32> {
        match &self.table.vars.get(index)?.access {
            Access::Integer { get, .. } => Some(get(&self.model)),
            _ => None,
        }
    }

    fn get_boolean(&self, index: usize) -> Option<bool> {
        match &self.table.vars.get(index)?.access {
            Access::Boolean { get, .. } => Some(get(&self.model)),
            _ => None,
        }
    }

    fn get_string(&self, index: usize) -> Option<String> {
        match &self.table.vars.get(index)?.access {
            Access::String { get, .. } => Some(get(&self.model)),
            _ => None,
        }
    }

    fn get_reals(&self, vrs: &[u32], out: &mut [f64]) -> Result<(), u32> {
        // every value reference first: a refused call leaves the host's array as it was
        if let Some(&vr) = vrs
            .iter()
            .find(|&&vr| vr as usize >= self.table.real_get.len())
        {
            return Err(vr);
        }
        for (&vr, x) in vrs.iter().zip(out) {
            *x = self.table.real_get[vr as usize](&self.model);
        }
        Ok(())
    }

    fn set_reals(&mut self, vrs: &[u32], values: &[f64]) -> Result<(), u32> {
        for (&vr, &x) in vrs.iter().zip(values) {
            let set = self
                .table
                .real_set
                .get(vr as usize)
                .copied()
                .flatten()
                .ok_or(vr)?;
            set(&mut self.model, x);
        }
        Ok(())
    }

    fn set_integer(&mut self, index: usize, value: i32) -> bool {
        match self.table.vars.get(index).map(|v| &v.access) {
            Some(Access::Integer { set: Some(set), .. }) => {
                set(&mut self.model, value);
                true
            }
            _ => false,
        }
    }

    fn set_boolean(&mut self, index: usize, value: bool) -> bool {
        match self.table.vars.get(index).map(|v| &v.access) {
            Some(Access::Boolean { set: Some(set), .. }) => {
                set(&mut self.model, value);
                true
            }
            _ => false,
        }
    }

    fn set_string(&mut self, index: usize, value: &str) -> bool {
        match self.table.vars.get(index).map(|v| &v.access) {
            Some(Access::String { set: Some(set), .. }) => {
                set(&mut self.model, value.to_string());
                true
            }
            _ => false,
        }
    }

    fn reset(&mut self, ctx: &InstanceContext) -> Result<(), ModelError> {
        self.model = M::instantiate(ctx)?;
        Ok(())
    }

    fn duplicate(&self) -> Box<dyn ErasedModel> {
        Box::new(Typed {
            model: self.model.clone(),
            table: Arc::clone(&self.table),
        })
    }

    fn exit_initialization(&mut self, diag: &mut Diagnostics) -> Result<(), ModelError> {
        self.model.exit_initialization(diag)
    }

    fn update_outputs(&mut self, diag: &mut Diagnostics) -> Result<(), ModelError> {
        self.model.update_outputs(diag)
    }

    fn do_step(&mut self, time: f64, step: f64, diag: &mut Diagnostics) -> Result<(), StepError> {
        self.model.do_step(time, step, diag)
    }

    fn step_computes_outputs(&self) -> bool {
        self.model.step_computes_outputs()
    }

    fn max_communication_step_s(&self) -> f64 {
        M::MAX_COMMUNICATION_STEP_S
    }

    fn snapshot(&self) -> Box<dyn Any + Send> {
        Box::new(self.model.clone())
    }

    fn owns(&self, snapshot: &(dyn Any + Send)) -> bool {
        snapshot.is::<M>()
    }

    fn restore(&mut self, snapshot: &(dyn Any + Send)) -> bool {
        match snapshot.downcast_ref::<M>() {
            Some(m) => {
                self.model = m.clone();
                true
            }
            None => false,
        }
    }

    fn update_snapshot(&self, snapshot: &mut (dyn Any + Send)) -> bool {
        match snapshot.downcast_mut::<M>() {
            Some(m) => {
                m.clone_from(&self.model);
                true
            }
            None => false,
        }
    }

    fn serialize(&self, snapshot: &(dyn Any + Send)) -> Option<Vec<u8>> {
        let model = snapshot.downcast_ref::<M>()?;
        bincode::serialize(&Tagged {
            model_name: M::INFO.name.to_string(),
            model,
        })
        .ok()
    }

    fn deserialize(&self, bytes: &[u8]) -> Result<Box<dyn Any + Send>, String> {
        let tagged: Tagged<M> = crate::state_bytes::strict_bincode(bytes)
            .map_err(|e| format!("not a serialised state of model {}: {e}", M::INFO.name))?;
        if tagged.model_name != M::INFO.name {
            return Err(format!(
                "the serialised state belongs to model '{}', not {}",
                tagged.model_name,
                M::INFO.name
            ));
        }
        crate::finite::check_finite(&tagged.model).map_err(|e| e.to_string())?;
        self.check_settable_values(&tagged.model)?;
        tagged
            .model
            .check_restored()
            .map_err(|e| format!("the serialised state does not hold together: {e}"))?;
        Ok(Box::new(tagged.model))
    }
}

/// Index lookup from (type, value reference) to declaration index, built once per instance.
#[derive(Clone, Debug, Default)]
pub struct VrIndex {
    by_type: [Vec<usize>; 4],
}

const NONE: usize = usize::MAX;

impl VrIndex {
    pub fn new(metas: &[VarMeta]) -> Self {
        let mut index = VrIndex::default();
        let mut counters = [0usize; 4];
        for (i, m) in metas.iter().enumerate() {
            let t = type_slot(m.var_type);
            let vr = counters[t];
            counters[t] += 1;
            let table = &mut index.by_type[t];
            if table.len() <= vr {
                table.resize(vr + 1, NONE);
            }
            table[vr] = i;
        }
        index
    }

    pub fn lookup(&self, var_type: VarType, vr: u32) -> Option<usize> {
        let i = *self.by_type[type_slot(var_type)].get(vr as usize)?;
        (i != NONE).then_some(i)
    }
}

fn type_slot(t: VarType) -> usize {
    match t {
        VarType::Real => 0,
        VarType::Integer => 1,
        VarType::Boolean => 2,
        VarType::String => 3,
    }
}
