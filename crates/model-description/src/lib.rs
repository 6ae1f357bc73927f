//! FMI 2.0 co-simulation export glue, written once for every model of the project.
//!
//! A model crate implements [`FmuModel`] (its variables, defaults, initialisation and step) and
//! invokes [`export_fmus!`]. Each variable is one line of [`declare!`]: FMI name, the model field
//! it binds, causality, unit, range, description; choices are Rust enums made FMI Enumerations
//! by [`fmi_enum!`]. From that one declaration come
//! - `modelDescription.xml` ([`xml::model_description`]): units, enumeration types,
//!   ModelStructure with explicit dependencies, capability flags, a GUID derived from the
//!   interface;
//! - the accessors behind fmi2Get*/fmi2Set* (plain function pointers, no allocation);
//! - the documentation's variable table ([`doc::documentation_html`]);
//! - physics errors under the FMI name of the field they name ([`fields::field_error`]);
//! - the C API ([`capi`]) with the FMI state machine ([`component::Component`]), value checks,
//!   logging through the host's callback, FMU state save/restore/serialisation;
//! - the packaged `.fmu` ([`package`], binary `package-fmus`).
//!
//! Beside the glue, [`timing`] times the FMU crates' benchmark workloads per step.

pub mod capi;
pub mod codec;
pub mod component;
pub mod doc;
pub mod enumeration;
pub mod erased;
pub mod fields;
pub mod files;
pub mod finite;
pub mod model;
pub mod package;
mod state_bytes;
#[cfg(feature = "testing")]
pub mod testing;
pub mod timing;
pub mod units;
pub mod variable;
pub mod xml;

pub use codec::{AlwaysSome, Codec, FmiValue, Native, Sign, ZeroIsNone};
pub use component::{CollectLog, Component, FmiState, Status};
pub use enumeration::{EnumItem, EnumType, FmiEnum};
pub use fields::{field_error, rename_fields_of, FieldError};
pub use files::{read_parameter_file, ParameterFileError, MAX_PARAMETER_FILE_BYTES};
pub use model::{
    DefaultExperiment, Diagnostics, FmuModel, InstanceContext, ModelError, ModelInfo, StepError,
};
pub use variable::{Causality, VarType, Variability, Variable};

/// Create a component for `M` driven from Rust (tests, tools): the same state machine and
/// checks as through the C API, with log messages collected in the returned [`CollectLog`].
pub fn rust_component<M: FmuModel>(
    ctx: InstanceContext,
) -> Result<(Component, CollectLog), ModelError> {
    let model = erased::Typed::<M>::new(&ctx)?;
    let log = CollectLog::default();
    let component = Component::new(Box::new(model), ctx, Box::new(log.clone()), true);
    Ok((component, log))
}

/// Value reference of the variable `name` of `M` (declaration order per type).
pub fn value_reference<M: FmuModel>(name: &str) -> Option<u32> {
    let vars = M::variables();
    let vrs = xml::value_references(&vars);
    vars.iter()
        .position(|v| v.meta.name == name)
        .map(|i| vrs[i])
}
