//! One declaration of a model variable: its FMI attributes (for modelDescription.xml and the
//! documentation), the physics field it binds (for the accessors and for naming errors), and
//! its accessors (for fmi2Get*/fmi2Set*). Value references are assigned by the glue in
//! declaration order, per type, so they cannot collide.
//!
//! Models declare their variables with [`crate::declare!`]: one line per variable naming the
//! FMI variable and the field it binds, with the description as a doc comment. The field's Rust
//! type decides the FMI type ([`crate::FmiValue`]); a [`Codec`] converts fields whose FMI form
//! differs (a sign held as `f64` exposed as an Integer, an optional value).

use crate::codec::{Codec, Scalar};
use crate::enumeration::EnumType;

/// FMI 2.0 base type of a scalar variable (an Enumeration is an Integer with a declared type).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum VarType {
    Real,
    Integer,
    Boolean,
    String,
}

impl VarType {
    pub fn xml_name(self) -> &'static str {
        match self {
            VarType::Real => "Real",
            VarType::Integer => "Integer",
            VarType::Boolean => "Boolean",
            VarType::String => "String",
        }
    }
}

/// FMI 2.0 causality.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Causality {
    Parameter,
    CalculatedParameter,
    Input,
    Output,
    Local,
}

impl Causality {
    pub fn xml_name(self) -> &'static str {
        match self {
            Causality::Parameter => "parameter",
            Causality::CalculatedParameter => "calculatedParameter",
            Causality::Input => "input",
            Causality::Output => "output",
            Causality::Local => "local",
        }
    }

    /// Whether the host sets variables of this causality (parameters and inputs).
    pub fn is_settable(self) -> bool {
        matches!(self, Causality::Parameter | Causality::Input)
    }
}

/// The causality keywords of [`crate::declare!`] (`parameter "x" => field;`).
#[allow(non_upper_case_globals)]
pub mod kind {
    use super::Causality;
    pub const parameter: Causality = Causality::Parameter;
    pub const calculated_parameter: Causality = Causality::CalculatedParameter;
    pub const input: Causality = Causality::Input;
    pub const output: Causality = Causality::Output;
    pub const local: Causality = Causality::Local;
}

/// FMI 2.0 variability.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variability {
    Constant,
    Fixed,
    Tunable,
    Discrete,
    Continuous,
}

impl Variability {
    pub fn xml_name(self) -> &'static str {
        match self {
            Variability::Constant => "constant",
            Variability::Fixed => "fixed",
            Variability::Tunable => "tunable",
            Variability::Discrete => "discrete",
            Variability::Continuous => "continuous",
        }
    }
}

/// Typed accessors of one variable. Plain function pointers: no allocation on the get/set path
/// (strings excepted: they are copied).
pub enum Access<M> {
    Real {
        get: fn(&M) -> f64,
        set: Option<fn(&mut M, f64)>,
    },
    Integer {
        get: fn(&M) -> i32,
        set: Option<fn(&mut M, i32)>,
    },
    Boolean {
        get: fn(&M) -> bool,
        set: Option<fn(&mut M, bool)>,
    },
    String {
        get: fn(&M) -> String,
        set: Option<fn(&mut M, String)>,
    },
}

impl<M> Clone for Access<M> {
    fn clone(&self) -> Self {
        match self {
            Access::Real { get, set } => Access::Real {
                get: *get,
                set: *set,
            },
            Access::Integer { get, set } => Access::Integer {
                get: *get,
                set: *set,
            },
            Access::Boolean { get, set } => Access::Boolean {
                get: *get,
                set: *set,
            },
            Access::String { get, set } => Access::String {
                get: *get,
                set: *set,
            },
        }
    }
}

impl<M> Access<M> {
    pub fn var_type(&self) -> VarType {
        match self {
            Access::Real { .. } => VarType::Real,
            Access::Integer { .. } => VarType::Integer,
            Access::Boolean { .. } => VarType::Boolean,
            Access::String { .. } => VarType::String,
        }
    }

    pub fn is_settable(&self) -> bool {
        match self {
            Access::Real { set, .. } => set.is_some(),
            Access::Integer { set, .. } => set.is_some(),
            Access::Boolean { set, .. } => set.is_some(),
            Access::String { set, .. } => set.is_some(),
        }
    }
}

/// The FMI attributes of a variable, independent of the model type.
#[derive(Clone, Debug)]
pub struct VarMeta {
    pub name: String,
    pub description: String,
    pub var_type: VarType,
    pub causality: Causality,
    pub variability: Variability,
    pub unit: Option<&'static str>,
    pub display_unit: Option<&'static str>,
    pub min: Option<f64>,
    pub max: Option<f64>,
    /// For outputs: names of the inputs this output depends on at the same instant
    /// (direct feedthrough). Empty = none. Written to ModelStructure/Outputs.
    pub feedthrough: Vec<&'static str>,
    /// The model field the variable binds, as a path from the model value (e.g.
    /// `params.speed_mps`); `None` for a value computed from several fields. The glue names a
    /// physics error about field `speed_mps` by the variable bound to it.
    pub binding: Option<String>,
    /// The Enumeration type, for an Integer that is a choice.
    pub enumeration: Option<&'static EnumType>,
}

impl VarMeta {
    /// Whether the variable carries a start value in modelDescription.xml (FMI 2.0, 2.2.7:
    /// parameters and inputs must have one; calculated outputs and locals must not).
    pub fn has_start(&self) -> bool {
        self.causality.is_settable()
    }

    /// The `initial` attribute written to the XML (None = attribute omitted).
    pub fn initial(&self) -> Option<&'static str> {
        match self.causality {
            Causality::Parameter => Some("exact"),
            Causality::CalculatedParameter | Causality::Output | Causality::Local => {
                Some("calculated")
            }
            Causality::Input => None,
        }
    }

    /// The XML element of the value: Real, Integer, Boolean, String or Enumeration.
    pub fn type_element(&self) -> &'static str {
        match self.enumeration {
            Some(_) => "Enumeration",
            None => self.var_type.xml_name(),
        }
    }
}

/// A model variable: attributes plus accessors.
pub struct Variable<M> {
    pub meta: VarMeta,
    pub access: Access<M>,
}

impl<M> Clone for Variable<M> {
    fn clone(&self) -> Self {
        Variable {
            meta: self.meta.clone(),
            access: self.access.clone(),
        }
    }
}

/// A description from doc-comment lines: trimmed, joined by single spaces.
pub fn doc_text(lines: &[&str]) -> String {
    lines
        .iter()
        .map(|l| l.trim())
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join(" ")
}

impl<M> Variable<M> {
    /// The one constructor: parameters (also calculated ones) are fixed, other Real variables
    /// continuous, other types discrete; a setter is kept for parameters and inputs only.
    fn new(
        causality: Causality,
        name: &str,
        description: String,
        binding: Option<String>,
        enumeration: Option<&'static EnumType>,
        access: Access<M>,
    ) -> Self {
        let var_type = access.var_type();
        let variability = match causality {
            Causality::Parameter | Causality::CalculatedParameter => Variability::Fixed,
            _ if var_type == VarType::Real => Variability::Continuous,
            _ => Variability::Discrete,
        };
        Variable {
            meta: VarMeta {
                name: name.to_string(),
                description,
                var_type,
                causality,
                variability,
                unit: None,
                display_unit: None,
                min: None,
                max: None,
                feedthrough: Vec::new(),
                binding,
                enumeration,
            },
            access,
        }
    }

    /// Append a variable bound to a model field through codec `C` (what [`crate::declare!`]
    /// expands to). `vars` comes first so that its type fixes the model type before the
    /// accessor closures are checked. `_field` only names the field's type; `path` is the field
    /// path for error messages.
    #[doc(hidden)]
    #[allow(clippy::too_many_arguments)]
    pub fn bind_into<'a, F, C: Codec<F>>(
        vars: &'a mut Vec<Self>,
        causality: Causality,
        name: &str,
        doc: &[&str],
        path: &str,
        _field: fn(&M) -> &F,
        get: fn(&M) -> C::Fmi,
        set: fn(&mut M, C::Fmi),
    ) -> Attributes<'a, M> {
        let set = causality.is_settable().then_some(set);
        let path: String = path.chars().filter(|c| !c.is_whitespace()).collect();
        let access = <C::Fmi as Scalar>::access(get, set);
        vars.push(Self::new(
            causality,
            name,
            doc_text(doc),
            Some(path),
            C::ENUMERATION,
            access,
        ));
        let last = vars.len() - 1;
        Attributes(&mut vars[last])
    }

    /// Append a read-only variable computed from several fields (`output "x" => |m| expr;`).
    #[doc(hidden)]
    pub fn computed_into<'a, T: Scalar>(
        vars: &'a mut Vec<Self>,
        causality: Causality,
        name: &str,
        doc: &[&str],
        get: fn(&M) -> T,
    ) -> Attributes<'a, M> {
        vars.push(Self::new(
            causality,
            name,
            doc_text(doc),
            None,
            None,
            T::access(get, None),
        ));
        let last = vars.len() - 1;
        Attributes(&mut vars[last])
    }
}

/// The attributes of a variable being declared: the bracket of a [`crate::declare!`] line,
/// `[unit = "m", range = 0.0..=1.0]`, calls these methods.
pub struct Attributes<'a, M>(&'a mut Variable<M>);

impl<M> Attributes<'_, M> {
    /// Unit (must be one of [`crate::units::UNITS`]).
    pub fn unit(&mut self, unit: &'static str) -> &mut Self {
        self.0.meta.unit = Some(unit);
        self
    }

    /// Display unit (must be a display unit of the variable's unit, e.g. km/h of m/s).
    pub fn display_unit(&mut self, display_unit: &'static str) -> &mut Self {
        self.0.meta.display_unit = Some(display_unit);
        self
    }

    /// Inclusive bounds; a value set outside them is rejected with fmi2Error.
    pub fn range(&mut self, range: std::ops::RangeInclusive<f64>) -> &mut Self {
        self.0.meta.min = Some(*range.start());
        self.0.meta.max = Some(*range.end());
        self
    }

    pub fn min(&mut self, min: f64) -> &mut Self {
        self.0.meta.min = Some(min);
        self
    }

    pub fn max(&mut self, max: f64) -> &mut Self {
        self.0.meta.max = Some(max);
        self
    }

    /// For an output: the inputs it depends on at the same instant (direct feedthrough).
    /// Without it an output declares none, which tells hosts there is no algebraic loop through
    /// this model.
    pub fn depends_on(&mut self, inputs: &[&'static str]) -> &mut Self {
        self.0.meta.feedthrough = inputs.to_vec();
        self
    }

    /// A parameter that may be changed between communication steps.
    pub fn tunable(&mut self, tunable: bool) -> &mut Self {
        if tunable && self.0.meta.causality == Causality::Parameter {
            self.0.meta.variability = Variability::Tunable;
        }
        self
    }

    /// A discrete-time (sampled, piecewise constant) variable.
    pub fn discrete(&mut self, discrete: bool) -> &mut Self {
        if discrete
            && matches!(
                self.0.meta.causality,
                Causality::Input | Causality::Output | Causality::Local
            )
        {
            self.0.meta.variability = Variability::Discrete;
        }
        self
    }
}

/// Declare variables, one line each, appended to `vars` (a `Vec<Variable<Self>>` whose type is
/// known, so the accessors type-check) in order:
///
/// ```ignore
/// fn variables() -> Vec<Variable<Self>> {
///     let mut v: Vec<Variable<Self>> = Vec::new();
///     model_description::declare! { v;
///         /// Running speed V
///         parameter "vehicle.speed" [unit = "m/s", display_unit = "km/h", range = 0.0..=200.0] => params.speed_mps;
///         /// Wheel/rail force law
///         parameter "contact.model" => params.model;
///         /// Sign of the command
///         parameter "idf.command_sign" [range = -1.0..=1.0] => params.command_sign as Sign;
///         /// Damper force
///         output "damper.force" [unit = "N", depends_on = &["damper.elongation_velocity"]] => out.force_n;
///         /// A value computed from two fields (read-only)
///         output "damper.end_acceleration" [unit = "m/s2"] => |m| m.arm_m * m.out.yaw_acc_radps2;
///     }
///     v
/// }
/// ```
///
/// The doc comment is the description; the keyword is the causality (`parameter`,
/// `calculated_parameter`, `input`, `output`, `local`); the bracket holds the attributes, each
/// a method of [`Attributes`] (`unit`, `display_unit`, `range`, `min`, `max`, `depends_on`,
/// `tunable`, `discrete`); after `=>` comes the bound field path (the field's type gives the
/// FMI type, see [`crate::FmiValue`]; `as Codec` picks another [`Codec`]) or a closure for a read-only
/// value computed from several fields.
#[macro_export]
macro_rules! declare {
    ($vars:ident; $($rest:tt)*) => {
        $crate::declare!(@entry $vars; $($rest)*);
    };
    (@entry $vars:ident;) => {};
    // A read-only value computed by a closure.
    (@entry $vars:ident;
        $(#[doc = $doc:literal])*
        $kind:ident $name:literal $([ $($key:ident = $val:expr),* $(,)? ])?
        => |$m:ident| $get:expr;
        $($rest:tt)*
    ) => {
        {
            #[allow(unused_variables, unused_mut)]
            let mut var = $crate::variable::Variable::computed_into(
                &mut $vars,
                $crate::variable::kind::$kind,
                $name,
                &[$($doc),*],
                |$m| $get,
            );
            $($(var.$key($val);)*)?
        }
        $crate::declare!(@entry $vars; $($rest)*);
    };
    // A bound field, optionally through a codec.
    (@entry $vars:ident;
        $(#[doc = $doc:literal])*
        $kind:ident $name:literal $([ $($key:ident = $val:expr),* $(,)? ])?
        => $($seg:ident $([$idx:expr])?).+ $(as $codec:ty)?;
        $($rest:tt)*
    ) => {
        {
            #[allow(unused_variables, unused_mut)]
            let mut var = $crate::variable::Variable::bind_into::<_, $crate::declare!(@codec $($codec)?)>(
                &mut $vars,
                $crate::variable::kind::$kind,
                $name,
                &[$($doc),*],
                stringify!($($seg $([$idx])?).+),
                |m| &m $(.$seg $([$idx])?)+,
                |m| <$crate::declare!(@codec $($codec)?) as $crate::codec::Codec<_>>::get(
                    &m $(.$seg $([$idx])?)+
                ),
                |m, x| <$crate::declare!(@codec $($codec)?) as $crate::codec::Codec<_>>::set(
                    &mut m $(.$seg $([$idx])?)+,
                    x,
                ),
            );
            $($(var.$key($val);)*)?
        }
        $crate::declare!(@entry $vars; $($rest)*);
    };
    (@codec) => { $crate::codec::Native };
    (@codec $codec:ty) => { $codec };
}
