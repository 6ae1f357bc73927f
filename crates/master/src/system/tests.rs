use super::*;
use crate::coupling::CouplingPlan;
use crate::model_description::tests::MASS_SPRING;
use crate::slave::VarRef;

/// SpringDamperMass as the example FMU will declare it.
pub const SDM: &str = r#"<fmiModelDescription fmiVersion="2.0" modelName="SpringDamperMass" guid="g2">
  <CoSimulation modelIdentifier="SpringDamperMass" canGetAndSetFMUstate="true"/>
  <ModelVariables>
<ScalarVariable name="m" valueReference="0" causality="parameter" variability="fixed"><Real start="1" unit="kg"/></ScalarVariable>
<ScalarVariable name="k" valueReference="1" causality="parameter" variability="fixed"><Real start="1" unit="N/m"/></ScalarVariable>
<ScalarVariable name="d" valueReference="2" causality="parameter" variability="fixed"><Real start="1" unit="N.s/m"/></ScalarVariable>
<ScalarVariable name="input_position" valueReference="3" causality="input"><Real start="0" unit="m"/></ScalarVariable>
<ScalarVariable name="input_velocity" valueReference="4" causality="input"><Real start="0" unit="m/s"/></ScalarVariable>
<ScalarVariable name="coupling_force" valueReference="5" causality="output"><Real unit="N"/></ScalarVariable>
<ScalarVariable name="position" valueReference="6" causality="output"><Real unit="m"/></ScalarVariable>
<ScalarVariable name="velocity" valueReference="7" causality="output"><Real unit="m/s"/></ScalarVariable>
<ScalarVariable name="mode" valueReference="8" causality="parameter" variability="fixed"><Integer start="0"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs>
<Unknown index="6" dependencies="4 5"/>
<Unknown index="7" dependencies=""/>
<Unknown index="8" dependencies=""/>
  </Outputs></ModelStructure>
</fmiModelDescription>"#;

const SYS: &str = r#"{
  "instances": [
{"name": "sdm", "fmu": "SpringDamperMass.fmu", "parameters": {"k": 200.0, "mode": 1}},
{"name": "ms", "fmu": "MassSpring.fmu", "parameters": {"m": 1.0, "k": 100.0}}
  ],
  "connections": [
{"from": "ms.position", "to": "sdm.input_position"},
{"from": "ms.velocity", "to": "sdm.input_velocity"},
{"from": "sdm.coupling_force", "to": "ms.force"}
  ],
  "stop_time": 1.0,
  "step": 0.001
}"#;

fn models() -> (ModelDescription, ModelDescription) {
    (
        ModelDescription::parse(SDM).unwrap(),
        ModelDescription::parse(MASS_SPRING).unwrap(),
    )
}

fn plan_of(text: &str) -> Result<CouplingPlan, SystemError> {
    let (a, b) = models();
    let s = LoadedSystem::from_json_str(text, Path::new("/x"), "sys.json")?;
    s.plan(&[&a, &b])
}

fn err_of(text: &str) -> String {
    plan_of(text).unwrap_err().to_string()
}

#[test]
fn valid_system_gives_feedthrough_order_and_default_record() {
    let p = plan_of(SYS).unwrap();
    // sdm's coupling_force feeds through from its inputs: ms must step first
    assert_eq!(p.order, vec![1, 0]);
    assert_eq!(p.algorithm, Algorithm::GaussSeidel);
    assert_eq!(p.connections.len(), 3);
    assert_eq!(
        p.instances[0].parameters,
        vec![
            (
                VarRef {
                    vr: 1,
                    ty: ScalarType::Real
                },
                200.0
            ),
            (
                VarRef {
                    vr: 8,
                    ty: ScalarType::Integer
                },
                1.0
            ),
        ]
    );
    let labels: Vec<&str> = p.record.iter().map(|r| r.label.as_str()).collect();
    assert_eq!(
        labels,
        vec![
            "sdm.input_position [m]",
            "sdm.input_velocity [m/s]",
            "sdm.coupling_force [N]",
            "sdm.position [m]",
            "sdm.velocity [m/s]",
            "ms.force [N]",
            "ms.position [m]",
            "ms.velocity [m/s]",
        ]
    );
}

#[test]
fn outputs_read_again_only_where_a_connected_output_depends_on_the_input() {
    // sdm.coupling_force depends on both sdm inputs and drives ms.force: after the inputs are
    // set, it is read again (Gauss-Seidel)
    let p = plan_of(SYS).unwrap();
    let ft: Vec<bool> = p.connections.iter().map(|c| c.feedthrough).collect();
    assert_eq!(ft, [true, true, false]);
    // without that connection no connected output of sdm depends on its inputs, so nothing
    // is read again, while the order still puts ms first
    let t = SYS.replace(
        r#",
{"from": "sdm.coupling_force", "to": "ms.force"}"#,
        "",
    );
    let p = plan_of(&t).unwrap();
    assert!(p.connections.iter().all(|c| !c.feedthrough));
    assert_eq!(p.order, vec![1, 0]);
}

#[test]
fn explicit_order_and_record() {
    let t = SYS.replace("\"step\": 0.001", "\"step\": 0.001, \"order\": [\"sdm\", \"ms\"], \"record\": [\"ms.position\"], \"algorithm\": \"jacobi\"");
    let p = plan_of(&t).unwrap();
    assert_eq!(p.order, vec![0, 1]);
    assert_eq!(p.algorithm, Algorithm::Jacobi);
    assert_eq!(p.record.len(), 1);
    let t = SYS.replace("\"step\": 0.001", "\"step\": 0.001, \"order\": [\"sdm\"]");
    assert!(err_of(&t).contains("missing: ms"));
}

#[test]
fn unknown_variable_names_field_line_and_suggestion() {
    let t = SYS.replace("\"sdm.coupling_force\"", "\"sdm.coupling_forse\"");
    let e = err_of(&t);
    assert_eq!(
        e,
        "sys.json line 9: connections[2].from: unknown variable 'sdm.coupling_forse' in instance 'sdm' (model 'SpringDamperMass') (did you mean 'sdm.coupling_force'?)"
    );
    let t = SYS.replace("\"to\": \"ms.force\"", "\"to\": \"mss.force\"");
    assert!(err_of(&t).contains("connections[2].to: unknown instance 'mss' (did you mean 'ms'?)"));
    let t = SYS.replace("\"k\": 100.0", "\"kk\": 100.0");
    let e = err_of(&t);
    assert!(
        e.contains("instances[1].parameters.kk: unknown variable 'kk'")
            && e.contains("did you mean 'k'"),
        "{e}"
    );
}

#[test]
fn causality_type_and_unit_checks() {
    let t = SYS.replace("\"from\": \"ms.position\"", "\"from\": \"ms.force\"");
    assert!(err_of(&t).contains("connections[0].from: 'ms.force' has causality 'input'"));
    let t = SYS.replace("\"to\": \"ms.force\"", "\"to\": \"ms.velocity\"");
    assert!(err_of(&t).contains("only inputs can be connection targets"));
    // unit mismatch: position [m] -> input_velocity [m/s]
    let t = SYS.replace(
        "{\"from\": \"ms.velocity\", \"to\": \"sdm.input_velocity\"}",
        "{\"from\": \"ms.position\", \"to\": \"sdm.input_velocity\"}",
    );
    let e = err_of(&t);
    assert!(e.contains("connections[1]: unit mismatch: 'ms.position' is in [m] but 'sdm.input_velocity' is in [m/s]"), "{e}");
    // type mismatch needs an Integer output: make ms.velocity Integer
    let (a, _) = models();
    let ms_int = MASS_SPRING.replace("<Real unit=\"m/s\"/>", "<Integer/>");
    let b = ModelDescription::parse(&ms_int).unwrap();
    let s = LoadedSystem::from_json_str(SYS, Path::new("/x"), "sys.json").unwrap();
    let e = s.plan(&[&a, &b]).unwrap_err().to_string();
    assert!(
        e.contains("type mismatch: 'ms.velocity' is Integer but 'sdm.input_velocity' is Real"),
        "{e}"
    );
    // the same input twice
    let t = SYS.replace(
        "{\"from\": \"ms.velocity\", \"to\": \"sdm.input_velocity\"}",
        "{\"from\": \"ms.position\", \"to\": \"sdm.input_position\"}",
    );
    // the line is the second connection's, not the first holding the same text
    assert!(err_of(&t).contains(
        "line 8: connections[1].to: input 'sdm.input_position' is already driven by connections[0]"
    ), "{}", err_of(&t));
}

#[test]
fn connected_variables_of_different_units_are_converted_by_their_base_units() {
    let with_units = |units: &str, input_unit: &str| {
        SDM.replace(
            "  <ModelVariables>",
            &format!("  <UnitDefinitions>{units}</UnitDefinitions>\n  <ModelVariables>"),
        )
        .replace(
            r#"name="input_position" valueReference="3" causality="input"><Real start="0" unit="m"/>"#,
            &format!(
                r#"name="input_position" valueReference="3" causality="input"><Real start="0" unit="{input_unit}"/>"#
            ),
        )
    };
    let plan = |sdm: &str, text: &str| {
        let a = ModelDescription::parse(sdm).unwrap();
        let b = ModelDescription::parse(MASS_SPRING).unwrap();
        LoadedSystem::from_json_str(text, Path::new("/x"), "sys.json")?.plan(&[&a, &b])
    };
    // ms.position [m] -> sdm.input_position [mm]: x 1000
    let mm = with_units(
        r#"<Unit name="mm"><BaseUnit m="1" factor="0.001"/></Unit>"#,
        "mm",
    );
    let p = plan(&mm, SYS).unwrap();
    let c = p.connections[0].conversion.unwrap();
    assert_eq!((c.factor, c.offset), (1000.0, 0.0));
    assert_eq!(p.connections[1].conversion, None);
    // a unit of the same base units under another name converts by nothing
    let metre = with_units(r#"<Unit name="metre"><BaseUnit m="1"/></Unit>"#, "metre");
    assert_eq!(plan(&metre, SYS).unwrap().connections[0].conversion, None);
    // no BaseUnit for the target's unit: refused, saying how to pass the value unchanged
    let undefined = with_units("", "mm");
    let e = plan(&undefined, SYS).unwrap_err().to_string();
    assert!(
        e.contains(
            "connections[0]: unit mismatch: 'ms.position' is in [m] but 'sdm.input_position' is \
             in [mm]: model 'SpringDamperMass' gives [mm] no BaseUnit"
        ) && e.contains(r#""convert_units": false"#),
        "{e}"
    );
    // different quantities: refused with both units' base units
    let speed = with_units(r#"<Unit name="m/s"><BaseUnit m="1" s="-1"/></Unit>"#, "m/s");
    let e = plan(&speed, SYS).unwrap_err().to_string();
    assert!(
        e.contains("they measure different quantities ([m] = m, [m/s] = m s-1)"),
        "{e}"
    );
    // "convert_units": false passes the value unchanged whatever the units
    let unchanged = SYS.replace(
        r#""to": "sdm.input_position"}"#,
        r#""to": "sdm.input_position", "convert_units": false}"#,
    );
    assert_ne!(unchanged, SYS);
    for sdm in [&mm, &undefined, &speed] {
        assert_eq!(
            plan(sdm, &unchanged).unwrap().connections[0].conversion,
            None
        );
    }
}

#[test]
fn relative_quantities_convert_without_offsets_and_only_reals_convert() {
    // sdm.input_position in a unit of 1 mm whose zero lies 0.5 m off
    let sdm = |relative: &str| {
        SDM.replace(
            "  <ModelVariables>",
            r#"  <UnitDefinitions><Unit name="mm0"><BaseUnit m="1" factor="0.001" offset="0.5"/></Unit></UnitDefinitions>
  <ModelVariables>"#,
        )
        .replace(
            r#"name="input_position" valueReference="3" causality="input"><Real start="0" unit="m"/>"#,
            &format!(
                r#"name="input_position" valueReference="3" causality="input"><Real start="0" unit="mm0"{relative}/>"#
            ),
        )
    };
    // ms.position is a Position, a SimpleType: relative through its type
    let ms_relative = MASS_SPRING.replace(
        r#"<Real quantity="Length" unit="m"/>"#,
        r#"<Real quantity="Length" unit="m" relativeQuantity="true"/>"#,
    );
    assert_ne!(ms_relative, MASS_SPRING);
    let plan = |sdm: &str, ms: &str| {
        let a = ModelDescription::parse(sdm).unwrap();
        let b = ModelDescription::parse(ms).unwrap();
        LoadedSystem::from_json_str(SYS, Path::new("/x"), "sys.json")?.plan(&[&a, &b])
    };
    let conversion = |sdm: &str, ms: &str| plan(sdm, ms).unwrap().connections[0].conversion;
    // absolute: x [m] = 0.001 y + 0.5, so y = 1000 x - 500
    let c = conversion(&sdm(""), MASS_SPRING).unwrap();
    assert_eq!((c.factor, c.offset), (1000.0, -500.0));
    // two differences: the offsets do not apply (FMI 2.0, 2.2.7)
    let c = conversion(&sdm(r#" relativeQuantity="true""#), &ms_relative).unwrap();
    assert_eq!((c.factor, c.offset), (1000.0, 0.0));
    // a difference into an absolute value of a unit with an offset: refused
    for (s, m) in [
        (sdm(r#" relativeQuantity="true""#), MASS_SPRING.to_string()),
        (sdm(""), ms_relative.clone()),
    ] {
        let e = plan(&s, &m).unwrap_err().to_string();
        assert!(e.contains("one is a relative quantity"), "{e}");
    }
    // an Integer carrying units (FMI 2.0 gives it none) is never converted
    let int_units = |unit: &str| {
        SDM.replace(
            r#"name="mode" valueReference="8" causality="parameter" variability="fixed"><Integer start="0"/>"#,
            &format!(r#"name="mode" valueReference="8" causality="input"><Integer start="0" unit="{unit}"/>"#),
        )
    };
    let ms_count = MASS_SPRING
        .replace(
            r#"<ScalarVariable name="n_steps" valueReference="0" causality="local"><Integer/>"#,
            r#"<ScalarVariable name="n_steps" valueReference="0" causality="output"><Integer unit="m"/>"#,
        )
        .replace(
            r#"<Unknown index="6" dependencies=""/>"#,
            r#"<Unknown index="6" dependencies=""/><Unknown index="7" dependencies=""/>"#,
        );
    assert_ne!(ms_count, MASS_SPRING);
    let counting = SYS.replace(
        r#"{"from": "sdm.coupling_force", "to": "ms.force"}"#,
        r#"{"from": "sdm.coupling_force", "to": "ms.force"}, {"from": "ms.n_steps", "to": "sdm.mode"}"#,
    );
    let with_km = r#"<UnitDefinitions><Unit name="km"><BaseUnit m="1" factor="1000"/></Unit></UnitDefinitions>
  <ModelVariables>"#;
    let a =
        ModelDescription::parse(&int_units("km").replace("  <ModelVariables>", with_km)).unwrap();
    let b = ModelDescription::parse(&ms_count).unwrap();
    let sys = |t: &str| LoadedSystem::from_json_str(t, Path::new("/x"), "sys.json").unwrap();
    // mode is an input here: no start value of the description
    let counting = counting.replace(", \"mode\": 1", "");
    let e = sys(&counting).plan(&[&a, &b]).unwrap_err().to_string();
    assert!(
        e.contains("[m] but 'sdm.mode' is in [km]: Integer values are not converted"),
        "{e}"
    );
    let a = ModelDescription::parse(&int_units("m")).unwrap();
    let p = sys(&counting).plan(&[&a, &b]).unwrap();
    assert_eq!(p.connections[3].conversion, None);
}

#[test]
fn one_unit_name_defined_differently_by_two_fmus_is_converted() {
    // SpringDamperMass's "m" is a millimetre
    let sdm = SDM.replace(
        "  <ModelVariables>",
        r#"  <UnitDefinitions><Unit name="m"><BaseUnit m="1" factor="0.001"/></Unit></UnitDefinitions>
  <ModelVariables>"#,
    );
    let a = ModelDescription::parse(&sdm).unwrap();
    let b = ModelDescription::parse(MASS_SPRING).unwrap();
    let p = LoadedSystem::from_json_str(SYS, Path::new("/x"), "sys.json")
        .unwrap()
        .plan(&[&a, &b])
        .unwrap();
    let c = p.connections[0].conversion.unwrap();
    assert_eq!((c.factor, c.offset), (1000.0, 0.0));
}

#[test]
fn parameter_value_checks() {
    let t = SYS.replace("\"mode\": 1", "\"mode\": 1.5");
    assert!(err_of(&t).contains("instances[0].parameters.mode: 1.5 is not a 32-bit integer"));
    let t = SYS.replace("\"mode\": 1", "\"mode\": true");
    assert!(err_of(&t).contains("Integer variable cannot take the value true"));
    let t = SYS.replace("\"k\": 200.0", "\"coupling_force\": 2.0");
    assert!(err_of(&t).contains("causality 'output'"));
}

#[test]
fn malformed_json_and_timing() {
    let e = err_of("{\n  \"instances\": [\n  }");
    assert!(e.starts_with("sys.json: line 3, column 3:"), "{e}");
    let e = err_of(&SYS.replace("\"step\"", "\"stpe\""));
    assert!(e.contains("unknown field `stpe`"), "{e}");
    assert!(err_of(&SYS.replace("0.001", "-1")).contains("step: must be a positive number"));
    assert!(err_of(&SYS.replace("0.001", "0.3")).contains("not an integer multiple"));
    assert!(err_of(&SYS.replace("\"stop_time\": 1.0", "\"stop_time\": 0.0")).contains("stop_time"));
    let e = err_of(&SYS.replace("\"name\": \"ms\"", "\"name\": \"sdm\""));
    assert!(
        e.contains("line 4: instances[1].name: instance name 'sdm' is used twice"),
        "{e}"
    );
    let e = err_of(&SYS.replace("\"name\": \"ms\"", "\"name\": \"m.s\""));
    assert!(e.contains("not a valid instance name"), "{e}");
    let e = err_of(&SYS.replace("\"name\": \"ms\"", "\"name\": \"m\\u0001s\""));
    assert!(
        e.contains("not a valid instance name") && e.contains("no control character"),
        "{e}"
    );
}

#[test]
fn missing_fmu_names_the_field() {
    let s = LoadedSystem::from_json_str(SYS, Path::new("/nonexistent"), "sys.json").unwrap();
    let e = s.open_fmus().unwrap_err().to_string();
    assert!(
        e.contains("instances[0].fmu") && e.contains("/nonexistent/SpringDamperMass.fmu"),
        "{e}"
    );
    let r = s.resolved();
    assert_eq!(
        r.instances[1].fmu,
        PathBuf::from("/nonexistent/MassSpring.fmu")
    );
}

/// A start value given twice in one instance is refused with its name and line, as a field
/// given twice is (serde_json would keep the last silently); so is a parameter given twice in a
/// run set's product or run.
#[test]
fn a_start_value_given_twice_is_refused() {
    let twice = SYS.replace(
        r#""parameters": {"k": 200.0, "mode": 1}"#,
        r#""parameters": {"k": 500.0, "mode": 1, "k": 200.0}"#,
    );
    assert_ne!(twice, SYS);
    let e = LoadedSystem::from_json_str(&twice, Path::new("/d"), "sys.json").unwrap_err();
    let e = e.to_string();
    assert!(
        e.contains("`k` is given twice") && e.contains("line 3"),
        "{e}"
    );
    for set in [
        r#"{"product": {"ms.k": [1], "ms.k": [2]}}"#,
        r#"{"runs": [{"parameters": {"ms.k": 1, "ms.k": 2}}]}"#,
    ] {
        let e = serde_json::from_str::<crate::runset::RunSet>(set).unwrap_err();
        assert!(e.to_string().contains("`ms.k` is given twice"), "{e}");
    }
}
