//! One declaration of a model variable: its FMI attributes (for modelDescription.xml) and its
//! accessors (for fmi2Get*/fmi2Set*). Value references are assigned by the glue in declaration
//! order, per type, so they cannot collide.

/// FMI 2.0 base type of a scalar variable.
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

/// Typed accessors of one variable. Plain function pointers: no allocation on the get/set path.
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
        set: Option<fn(&mut M, &str)>,
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
}

impl VarMeta {
    /// Whether the variable carries a start value in modelDescription.xml (FMI 2.0, 2.2.7:
    /// parameters and inputs must have one; calculated outputs and locals must not).
    pub fn has_start(&self) -> bool {
        matches!(self.causality, Causality::Parameter | Causality::Input)
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

impl<M> Variable<M> {
    /// The one constructor behind the typed ones: parameters (also calculated ones) are fixed,
    /// other Real variables continuous, other types discrete; `feedthrough` is for outputs only.
    fn new(
        name: &str,
        description: &str,
        causality: Causality,
        feedthrough: &[&'static str],
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
                description: description.to_string(),
                var_type,
                causality,
                variability,
                unit: None,
                display_unit: None,
                min: None,
                max: None,
                feedthrough: feedthrough.to_vec(),
            },
            access,
        }
    }

    /// A fixed Real parameter (settable before initialisation only).
    pub fn parameter(
        name: &str,
        description: &str,
        get: fn(&M) -> f64,
        set: fn(&mut M, f64),
    ) -> Self {
        let access = Access::Real {
            get,
            set: Some(set),
        };
        Self::new(name, description, Causality::Parameter, &[], access)
    }

    /// A fixed Integer parameter (enumerations are declared as Integer with min/max).
    pub fn integer_parameter(
        name: &str,
        description: &str,
        get: fn(&M) -> i32,
        set: fn(&mut M, i32),
    ) -> Self {
        let access = Access::Integer {
            get,
            set: Some(set),
        };
        Self::new(name, description, Causality::Parameter, &[], access)
    }

    /// A fixed Boolean parameter.
    pub fn boolean_parameter(
        name: &str,
        description: &str,
        get: fn(&M) -> bool,
        set: fn(&mut M, bool),
    ) -> Self {
        let access = Access::Boolean {
            get,
            set: Some(set),
        };
        Self::new(name, description, Causality::Parameter, &[], access)
    }

    /// A fixed String parameter (e.g. a file path).
    pub fn string_parameter(
        name: &str,
        description: &str,
        get: fn(&M) -> String,
        set: fn(&mut M, &str),
    ) -> Self {
        let access = Access::String {
            get,
            set: Some(set),
        };
        Self::new(name, description, Causality::Parameter, &[], access)
    }

    /// A continuous Real input.
    pub fn input(name: &str, description: &str, get: fn(&M) -> f64, set: fn(&mut M, f64)) -> Self {
        let access = Access::Real {
            get,
            set: Some(set),
        };
        Self::new(name, description, Causality::Input, &[], access)
    }

    /// A continuous Real output. `feedthrough` lists the inputs it depends on at the same
    /// instant; an output computed from states only passes `&[]`, which tells hosts there is
    /// no algebraic loop through this model.
    pub fn output(
        name: &str,
        description: &str,
        feedthrough: &[&'static str],
        get: fn(&M) -> f64,
    ) -> Self {
        let access = Access::Real { get, set: None };
        Self::new(name, description, Causality::Output, feedthrough, access)
    }

    /// A discrete Integer output.
    pub fn integer_output(
        name: &str,
        description: &str,
        feedthrough: &[&'static str],
        get: fn(&M) -> i32,
    ) -> Self {
        let access = Access::Integer { get, set: None };
        Self::new(name, description, Causality::Output, feedthrough, access)
    }

    /// A discrete Boolean output.
    pub fn boolean_output(
        name: &str,
        description: &str,
        feedthrough: &[&'static str],
        get: fn(&M) -> bool,
    ) -> Self {
        let access = Access::Boolean { get, set: None };
        Self::new(name, description, Causality::Output, feedthrough, access)
    }

    /// A Real parameter computed from others at initialisation (read-only).
    pub fn calculated_parameter(name: &str, description: &str, get: fn(&M) -> f64) -> Self {
        let access = Access::Real { get, set: None };
        Self::new(
            name,
            description,
            Causality::CalculatedParameter,
            &[],
            access,
        )
    }

    /// A Real local variable (observable, not settable).
    pub fn local(name: &str, description: &str, get: fn(&M) -> f64) -> Self {
        let access = Access::Real { get, set: None };
        Self::new(name, description, Causality::Local, &[], access)
    }

    /// Unit (must be one of [`crate::units::UNITS`]).
    pub fn unit(&mut self, unit: &'static str) -> &mut Self {
        self.meta.unit = Some(unit);
        self
    }

    /// Display unit (must be a display unit of the variable's unit, e.g. km/h of m/s).
    pub fn display_unit(&mut self, display_unit: &'static str) -> &mut Self {
        self.meta.display_unit = Some(display_unit);
        self
    }

    /// Inclusive bounds; a value set outside them is rejected with fmi2Error.
    pub fn range(&mut self, min: f64, max: f64) -> &mut Self {
        self.meta.min = Some(min);
        self.meta.max = Some(max);
        self
    }

    pub fn min(&mut self, min: f64) -> &mut Self {
        self.meta.min = Some(min);
        self
    }

    pub fn max(&mut self, max: f64) -> &mut Self {
        self.meta.max = Some(max);
        self
    }

    /// A parameter that may be changed between communication steps.
    pub fn tunable(&mut self) -> &mut Self {
        if self.meta.causality == Causality::Parameter {
            self.meta.variability = Variability::Tunable;
        }
        self
    }

    /// A discrete-time (sampled, piecewise constant) variable.
    pub fn discrete(&mut self) -> &mut Self {
        if matches!(
            self.meta.causality,
            Causality::Input | Causality::Output | Causality::Local
        ) {
            self.meta.variability = Variability::Discrete;
        }
        self
    }
}

/// The declaration of a model's variables, in order. Its methods fix the model type, so the
/// accessor closures need no type annotations:
///
/// ```ignore
/// let mut v = VariableList::<Self>::new();
/// v.parameter("mass", "Mass", |m| m.mass_kg, |m, x| m.mass_kg = x).unit("kg").min(0.0);
/// v.output("position", "Position", &[], |m| m.position_m).unit("m");
/// v.into_vec()
/// ```
pub struct VariableList<M> {
    vars: Vec<Variable<M>>,
}

impl<M> Default for VariableList<M> {
    fn default() -> Self {
        VariableList { vars: Vec::new() }
    }
}

macro_rules! push_fn {
    ($name:ident ( $($arg:ident : $ty:ty),* )) => {
        pub fn $name(&mut self, name: &str, description: &str, $($arg: $ty),*) -> &mut Variable<M> {
            self.vars.push(Variable::$name(name, description, $($arg),*));
            let last = self.vars.len() - 1;
            &mut self.vars[last]
        }
    };
}

impl<M> VariableList<M> {
    pub fn new() -> Self {
        Self::default()
    }

    push_fn!(parameter(get: fn(&M) -> f64, set: fn(&mut M, f64)));
    push_fn!(integer_parameter(get: fn(&M) -> i32, set: fn(&mut M, i32)));
    push_fn!(boolean_parameter(get: fn(&M) -> bool, set: fn(&mut M, bool)));
    push_fn!(string_parameter(get: fn(&M) -> String, set: fn(&mut M, &str)));
    push_fn!(input(get: fn(&M) -> f64, set: fn(&mut M, f64)));
    push_fn!(output(feedthrough: &[&'static str], get: fn(&M) -> f64));
    push_fn!(integer_output(feedthrough: &[&'static str], get: fn(&M) -> i32));
    push_fn!(boolean_output(feedthrough: &[&'static str], get: fn(&M) -> bool));
    push_fn!(calculated_parameter(get: fn(&M) -> f64));
    push_fn!(local(get: fn(&M) -> f64));

    pub fn into_vec(self) -> Vec<Variable<M>> {
        self.vars
    }
}
