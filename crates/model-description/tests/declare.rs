//! The declaration style on a small model: one `declare!` line per variable gives the accessors,
//! the XML entry (with Enumeration types), the documentation row and FMI-named errors.

use model_description::{
    field_error, fmi_enum, rust_component, value_reference, xml, DefaultExperiment, Diagnostics,
    FieldError, FmuModel, InstanceContext, ModelError, ModelInfo, Sign, Status, StepError,
    Variable, ZeroIsNone,
};
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
enum Law {
    Linear,
    Cubic,
}

fmi_enum! {
    Law as "SpringLaw", "Force law of the spring" {
        Linear = 0, "linear", "F = k x";
        Cubic = 1, "cubic", "F = k x^3 / (1 m^2)";
    }
}

#[derive(Clone, Debug, Default, Serialize, Deserialize)]
struct Params {
    stiffness_n_per_m: f64,
    sign: f64,
    mounting_stiffness_n_per_m: Option<f64>,
    steps: u32,
    label: String,
    enabled: bool,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
struct Demo {
    params: Params,
    law: Law,
    table: [f64; 2],
    x_m: f64,
    force_n: f64,
}

/// A physics error naming a field.
struct Bad(&'static str);

impl std::fmt::Display for Bad {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "`{}` must be > 0 (and below table[1])", self.0)
    }
}

impl FieldError for Bad {
    fn field(&self) -> Option<&str> {
        Some(self.0)
    }
}

impl FmuModel for Demo {
    const INFO: ModelInfo = ModelInfo {
        name: "Demo",
        description: "declaration test",
        author: "test",
        version: "0",
        default_experiment: DefaultExperiment {
            start_time: 0.0,
            stop_time: 1.0,
            step_size: 0.5,
        },
        documentation_html: "",
        resources: &[],
    };

    fn variables() -> Vec<Variable<Self>> {
        let mut v: Vec<Variable<Self>> = Vec::new();
        model_description::declare! { v;
            /// Spring stiffness,
            /// second line of the description
            parameter "spring.stiffness" [unit = "N/m", display_unit = "kN/m", min = 0.0] => params.stiffness_n_per_m;
            /// Force law
            parameter "spring.law" => law;
            /// Sign
            parameter "spring.sign" => params.sign as Sign;
            /// Optional mounting stiffness, 0 = rigid
            parameter "spring.mounting_stiffness" [unit = "N/m", min = 0.0] => params.mounting_stiffness_n_per_m as ZeroIsNone;
            /// Work bound
            parameter "solver.steps" [range = 1.0..=100.0] => params.steps;
            /// A label
            parameter "spring.label" => params.label;
            /// A switch
            parameter "spring.enabled" => params.enabled;
            /// Table point 1
            parameter "table.x[1]" [unit = "m"] => table[0];
            /// Table point 2
            parameter "table.x[2]" [unit = "m"] => table[1];
            /// Elongation
            input "spring.elongation" [unit = "m"] => x_m;
            /// Force
            output "spring.force" [unit = "N", depends_on = &["spring.elongation"]] => force_n;
            /// Twice the force (computed)
            output "spring.double_force" [unit = "N", depends_on = &["spring.elongation"]] => |m| 2.0 * m.force_n;
        }
        v
    }

    fn instantiate(_ctx: &InstanceContext) -> Result<Self, ModelError> {
        Ok(Demo {
            params: Params {
                stiffness_n_per_m: 1e3,
                sign: -1.0,
                steps: 10,
                label: "a".into(),
                ..Params::default()
            },
            law: Law::Cubic,
            table: [0.0, 1.0],
            x_m: 0.0,
            force_n: 0.0,
        })
    }

    fn exit_initialization(&mut self, _diag: &mut Diagnostics) -> Result<(), ModelError> {
        if self.params.stiffness_n_per_m <= 0.0 {
            return Err(field_error::<Self>(&Bad("stiffness_n_per_m")));
        }
        if self.x_m > 1.0 {
            return Err(field_error::<Self>(&Bad("x_m")));
        }
        Ok(())
    }

    fn update_outputs(&mut self, _diag: &mut Diagnostics) -> Result<(), ModelError> {
        self.force_n = self.params.stiffness_n_per_m * self.x_m;
        Ok(())
    }

    fn do_step(&mut self, _t: f64, _h: f64, _diag: &mut Diagnostics) -> Result<(), StepError> {
        Ok(())
    }
}

#[test]
fn one_line_gives_the_xml_entry() {
    let d = xml::model_description::<Demo>().unwrap();
    let x = &d.xml;
    assert!(x.contains(r#"<SimpleType name="SpringLaw" description="Force law of the spring">"#));
    assert!(x.contains(r#"<Item name="cubic" value="1" description="F = k x^3 / (1 m^2)"/>"#));
    assert!(x.contains(r#"<Enumeration declaredType="SpringLaw" start="1"/>"#));
    assert!(x.contains(
        r#"description="Spring stiffness, second line of the description" causality="parameter""#
    ));
    assert!(x.contains(r#"<Real start="1000.0" unit="N/m" displayUnit="kN/m" min="0.0"/>"#));
    // a sign is the Enumeration Sign (-1 = minus, 1 = plus)
    assert!(
        x.contains(r#"<Enumeration declaredType="Sign" start="-1"/>"#),
        "{x}"
    );
    assert!(x.contains(r#"<Item name="minus" value="-1" description="-1"/>"#));
    assert!(x.contains(r#"<Real start="0.0" unit="N/m" min="0.0"/>"#));
    assert!(x.contains(r#"<String start="a"/>"#));
    assert!(x.contains(r#"<Boolean start="false"/>"#));
    // TypeDefinitions come between UnitDefinitions and LogCategories (FMI 2.0 schema order).
    let (u, t, l) = (
        x.find("<UnitDefinitions>").unwrap(),
        x.find("<TypeDefinitions>").unwrap(),
        x.find("<LogCategories>").unwrap(),
    );
    assert!(u < t && t < l);
    // Value references per type in declaration order: the enumeration shares Integer's.
    assert_eq!(value_reference::<Demo>("spring.law"), Some(0));
    assert_eq!(value_reference::<Demo>("spring.sign"), Some(1));
    assert_eq!(value_reference::<Demo>("solver.steps"), Some(2));
    assert_eq!(value_reference::<Demo>("table.x[2]"), Some(3));
    // Feedthrough of the computed output.
    assert!(
        x.contains(r#"<Unknown index="12" dependencies="10"/>"#),
        "{x}"
    );
    let html = model_description::doc::documentation_html::<Demo>().unwrap();
    assert!(html.contains("<td>Enumeration <code>SpringLaw</code></td>"));
    assert!(html.contains("<td>1 (cubic)</td>"));
    assert!(html.contains("<h2>Enumerations</h2>"));
}

#[test]
fn every_variable_round_trips_through_its_accessors() {
    let (mut c, _log) = rust_component::<Demo>(InstanceContext::default()).unwrap();
    let vr = |n| value_reference::<Demo>(n).unwrap();
    assert_eq!(c.set_real(&[vr("spring.stiffness")], &[2e3]), Status::Ok);
    assert_eq!(
        c.set_real(&[vr("spring.mounting_stiffness")], &[1e7]),
        Status::Ok
    );
    assert_eq!(
        c.set_integer(
            &[vr("spring.law"), vr("spring.sign"), vr("solver.steps")],
            &[0, 1, 7]
        ),
        Status::Ok
    );
    assert_eq!(c.set_string(&[vr("spring.label")], &["b"]), Status::Ok);
    assert_eq!(c.set_boolean(&[vr("spring.enabled")], &[true]), Status::Ok);
    assert_eq!(c.set_real(&[vr("table.x[2]")], &[3.0]), Status::Ok);
    assert_eq!(c.enter_initialization_mode(), Status::Ok);
    let mut r = [0.0; 3];
    c.get_real(
        &[
            vr("spring.stiffness"),
            vr("spring.mounting_stiffness"),
            vr("table.x[2]"),
        ],
        &mut r,
    );
    assert_eq!(r, [2e3, 1e7, 3.0]);
    let mut i = [0; 3];
    c.get_integer(
        &[vr("spring.law"), vr("spring.sign"), vr("solver.steps")],
        &mut i,
    );
    assert_eq!(i, [0, 1, 7]);
    let mut s = [String::new()];
    c.get_string(&[vr("spring.label")], &mut s);
    assert_eq!(s[0], "b");
    let mut b = [false];
    c.get_boolean(&[vr("spring.enabled")], &mut b);
    assert!(b[0]);
    // 0 means "none" for the optional stiffness.
    assert_eq!(
        c.set_real(&[vr("spring.mounting_stiffness")], &[0.0]),
        Status::Ok
    );
    c.get_real(&[vr("spring.mounting_stiffness")], &mut r[..1]);
    assert_eq!(r[0], 0.0);
    // Outputs are read-only.
    assert_eq!(c.set_real(&[vr("spring.force")], &[1.0]), Status::Error);
}

#[test]
fn an_integer_that_is_no_item_is_refused_and_changes_nothing() {
    let (mut c, log) = rust_component::<Demo>(InstanceContext::default()).unwrap();
    let law = value_reference::<Demo>("spring.law").unwrap();
    assert_eq!(c.set_integer(&[law], &[2]), Status::Error);
    let msgs = log.take();
    assert!(
        msgs.iter().any(|(_, _, m)| m.contains(
            "'spring.law' = 2 is not an item of the enumeration SpringLaw (0 = linear, 1 = cubic)"
        )),
        "{msgs:?}"
    );
    assert_eq!(c.enter_initialization_mode(), Status::Ok);
    let mut i = [0];
    c.get_integer(&[law], &mut i);
    assert_eq!(i[0], 1);
}

#[test]
fn physics_errors_are_named_by_the_bound_variable() {
    let (mut c, log) = rust_component::<Demo>(InstanceContext::default()).unwrap();
    let vr = |n| value_reference::<Demo>(n).unwrap();
    assert_eq!(c.set_real(&[vr("spring.stiffness")], &[0.0]), Status::Ok);
    assert_eq!(c.enter_initialization_mode(), Status::Ok);
    assert_eq!(c.exit_initialization_mode(), Status::Error);
    let msgs = log.take();
    assert!(
        msgs.iter().any(|(_, _, m)| m
            .contains("invalid parameter 'spring.stiffness': `spring.stiffness` must be > 0")),
        "{msgs:?}"
    );
    // An input is reported as an input.
    let e = field_error::<Demo>(&Bad("x_m"));
    assert!(matches!(e, ModelError::InvalidInput { ref name, .. } if name == "spring.elongation"));
}
