use super::*;

/// A MassSpring-like description: params m, k, d; input force; outputs position, velocity
/// (no direct feedthrough).
pub const MASS_SPRING: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="MassSpring" guid="{abc}" canHandleMultipleSetPerTimeInstant="true">
  <CoSimulation modelIdentifier="MassSpring" canGetAndSetFMUstate="true"/>
  <UnitDefinitions><Unit name="m"><BaseUnit m="1"/></Unit></UnitDefinitions>
  <TypeDefinitions>
<SimpleType name="Position"><Real quantity="Length" unit="m"/></SimpleType>
  </TypeDefinitions>
  <DefaultExperiment startTime="0" stopTime="1" stepSize="1e-3"/>
  <ModelVariables>
<ScalarVariable name="m" valueReference="0" causality="parameter" variability="fixed"><Real start="1" unit="kg"/></ScalarVariable>
<ScalarVariable name="k" valueReference="1" causality="parameter" variability="fixed"><Real start="100" unit="N/m"/></ScalarVariable>
<ScalarVariable name="d" valueReference="2" causality="parameter" variability="fixed"><Real start="1" unit="N.s/m"/></ScalarVariable>
<ScalarVariable name="force" valueReference="3" causality="input"><Real start="0" unit="N"/></ScalarVariable>
<ScalarVariable name="position" valueReference="4" causality="output" initial="exact"><Real declaredType="Position" start="0.1"/></ScalarVariable>
<ScalarVariable name="velocity" valueReference="5" causality="output" description="v &amp; co"><Real unit="m/s"/></ScalarVariable>
<ScalarVariable name="n_steps" valueReference="0" causality="local"><Integer/></ScalarVariable>
  </ModelVariables>
  <ModelStructure>
<Outputs>
  <Unknown index="5" dependencies=""/>
  <Unknown index="6" dependencies=""/>
</Outputs>
  </ModelStructure>
</fmiModelDescription>"#;

#[test]
fn parses_variables_units_and_structure() {
    let md = ModelDescription::parse(MASS_SPRING).unwrap();
    assert_eq!(md.fmi_version, "2.0");
    assert_eq!(md.guid, "{abc}");
    let cs = md.co_simulation.as_ref().unwrap();
    assert_eq!(cs.model_identifier, "MassSpring");
    assert!(cs.can_get_and_set_fmu_state);
    assert_eq!(md.variables.len(), 7);
    let (i, pos) = md.variable("position").unwrap();
    assert_eq!(i, 4);
    assert_eq!(pos.unit.as_deref(), Some("m")); // through declaredType
    assert_eq!(pos.causality, Causality::Output);
    assert_eq!(
        md.variable("velocity").unwrap().1.description.as_deref(),
        Some("v & co")
    );
    assert_eq!(md.variable("n_steps").unwrap().1.var_type, VarType::Integer);
    assert_eq!(
        md.variable("n_steps").unwrap().1.variability,
        Variability::Discrete
    );
    assert_eq!(md.outputs[0].depends_on, Some(vec![]));
    assert!(!md.has_direct_feedthrough(3));
    assert_eq!(
        md.default_experiment.as_ref().unwrap().step_size,
        Some(1e-3)
    );
    assert!(md.variable("m").unwrap().1.is_settable());
    assert!(!md.variable("velocity").unwrap().1.is_settable());
    assert!(md.variable("position").unwrap().1.is_settable()); // initial="exact"
}

#[test]
fn feedthrough_from_dependencies() {
    let xml = MASS_SPRING.replace(
        r#"<Unknown index="6" dependencies=""/>"#,
        r#"<Unknown index="6" dependencies="4"/>"#,
    );
    let md = ModelDescription::parse(&xml).unwrap();
    assert!(md.has_direct_feedthrough(3));
    // absent attribute: depends on everything
    let xml = MASS_SPRING.replace(
        r#"<Unknown index="6" dependencies=""/>"#,
        r#"<Unknown index="6"/>"#,
    );
    assert!(ModelDescription::parse(&xml)
        .unwrap()
        .has_direct_feedthrough(3));
}

#[test]
fn errors_name_line_and_attribute() {
    let xml = MASS_SPRING.replace(r#"name="k" valueReference="1""#, r#"name="k""#);
    let e = ModelDescription::parse(&xml).unwrap_err();
    assert_eq!(
        e,
        ModelDescriptionError::MissingAttribute {
            element: "ScalarVariable".into(),
            attribute: "valueReference".into(),
            line: 11
        }
    );
    let xml = MASS_SPRING.replace(r#"causality="input""#, r#"causality="inptu""#);
    let e = ModelDescription::parse(&xml).unwrap_err().to_string();
    assert!(e.contains("line 13") && e.contains("inptu"), "{e}");
    let e = ModelDescription::parse("<fmiModelDescription fmiVersion=\"2.0\"").unwrap_err();
    assert!(matches!(e, ModelDescriptionError::Xml(_)), "{e:?}");
    let e = ModelDescription::parse("not xml at all").unwrap_err();
    assert!(matches!(
        e,
        ModelDescriptionError::Xml(_) | ModelDescriptionError::NoRoot
    ));
    let xml = MASS_SPRING.replace(r#"<Unknown index="6""#, r#"<Unknown index="60""#);
    let e = ModelDescription::parse(&xml).unwrap_err();
    assert!(matches!(
        e,
        ModelDescriptionError::IndexOutOfRange {
            index: 60,
            count: 7,
            ..
        }
    ));
    let xml = MASS_SPRING.replace("declaredType=\"Position\"", "declaredType=\"Pos\"");
    assert!(matches!(
        ModelDescription::parse(&xml).unwrap_err(),
        ModelDescriptionError::UnknownDeclaredType { .. }
    ));
}

#[test]
fn suggestions() {
    let md = ModelDescription::parse(MASS_SPRING).unwrap();
    assert_eq!(md.suggest("forse"), Some("force"));
    assert_eq!(md.suggest("positon"), Some("position"));
    assert_eq!(md.suggest("completely_different"), None);
    assert_eq!(edit_distance("kitten", "sitting"), 3);
}
