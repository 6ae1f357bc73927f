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

/// FMI 2.0 (2.2.8) on ModelStructure/Outputs and declared ranges, as fmpy validate checks
/// them: each was accepted before and is refused with the line and the cause.
#[test]
fn output_structure_and_ranges_follow_the_standard() {
    let refused = |from: &str, to: &str| {
        assert!(MASS_SPRING.contains(from), "{from}");
        ModelDescription::parse(&MASS_SPRING.replace(from, to))
            .unwrap_err()
            .to_string()
    };
    let outputs = r#"<Unknown index="6" dependencies=""/>"#;
    for (to, expected) in [
        // a parameter listed as an output
        (
            r#"<Unknown index="6" dependencies=""/><Unknown index="2"/>"#,
            "index 2 is 'k', whose causality is parameter, not output",
        ),
        // listed twice
        (
            r#"<Unknown index="6" dependencies=""/><Unknown index="6"/>"#,
            "output 'velocity' is listed twice",
        ),
        // depending on itself, on a parameter
        (
            r#"<Unknown index="6" dependencies="6"/>"#,
            "output 'velocity' depends on itself (index 6)",
        ),
        (
            r#"<Unknown index="6" dependencies="1"/>"#,
            "depends on 'm', a variable of causality parameter (index 1)",
        ),
        // kinds without dependencies, more kinds than dependencies, an unknown kind
        (
            r#"<Unknown index="6" dependenciesKind="dependent"/>"#,
            "1 kind(s) for absent dependencies",
        ),
        (
            r#"<Unknown index="6" dependencies="4" dependenciesKind="dependent fixed"/>"#,
            "2 kind(s) for 1 dependencies",
        ),
        (
            r#"<Unknown index="6" dependencies="4" dependenciesKind="linear"/>"#,
            "'linear' is not one of dependent",
        ),
        // an output not listed
        (
            "",
            "variable 'velocity' (line 15): an output not listed in ModelStructure/Outputs",
        ),
    ] {
        let e = refused(outputs, to);
        assert!(e.contains(expected), "{to}: {e}");
    }
    // an input, a state and kinds matching the dependencies are fine
    let xml = MASS_SPRING.replace(
        outputs,
        r#"<Unknown index="6" dependencies="4 7" dependenciesKind="dependent fixed"/>"#,
    );
    ModelDescription::parse(&xml).unwrap();
    // min above max, also through a declared type
    let e = refused(
        r#"<Real start="100" unit="N/m"/>"#,
        r#"<Real start="100" unit="N/m" min="10" max="1"/>"#,
    );
    assert!(
        e.contains("variable 'k' (line 11): min 10 is greater than max 1"),
        "{e}"
    );
    let e = refused(
        r#"<Real quantity="Length" unit="m"/>"#,
        r#"<Real quantity="Length" unit="m" min="1" max="0"/>"#,
    );
    assert!(
        e.contains("variable 'position' (line 14): min 1 is greater than max 0"),
        "{e}"
    );
}

#[test]
fn suggestions() {
    let md = ModelDescription::parse(MASS_SPRING).unwrap();
    assert_eq!(md.suggest("forse"), Some("force"));
    assert_eq!(md.suggest("positon"), Some("position"));
    assert_eq!(md.suggest("completely_different"), None);
    assert_eq!(edit_distance("kitten", "sitting"), 3);
}

/// MASS_SPRING with the attributes of variable `m` (a fixed parameter with start 1) replaced.
fn with_m(attrs: &str, real: &str) -> String {
    MASS_SPRING.replace(
        r#"name="m" valueReference="0" causality="parameter" variability="fixed"><Real start="1" unit="kg"/>"#,
        &format!(r#"name="m" valueReference="0" {attrs}>{real}"#),
    )
}

#[test]
fn fmi2_causality_variability_initial_table() {
    let ok = |attrs: &str, real: &str| {
        let mut xml = with_m(attrs, real);
        if attrs.contains("\"output\"") {
            // an output is listed in ModelStructure/Outputs
            xml = xml.replace(
                "<Outputs>",
                "<Outputs><Unknown index=\"1\" dependencies=\"\"/>",
            );
        }
        ModelDescription::parse(&xml).map_err(|e| e.to_string())
    };
    // allowed, each with the start value its case needs or forbids
    for (attrs, real) in [
        (
            r#"causality="parameter" variability="tunable""#,
            r#"<Real start="1"/>"#,
        ),
        (
            r#"causality="calculatedParameter" variability="fixed""#,
            "<Real/>",
        ),
        (
            r#"causality="calculatedParameter" variability="fixed" initial="approx""#,
            r#"<Real start="1"/>"#,
        ),
        (
            r#"causality="output" variability="constant""#,
            r#"<Real start="1"/>"#,
        ),
        (r#"causality="local" variability="tunable""#, "<Real/>"),
        (
            r#"causality="local" initial="exact""#,
            r#"<Real start="1"/>"#,
        ),
        (
            r#"causality="input" variability="discrete""#,
            r#"<Real start="1"/>"#,
        ),
        (r#"causality="independent""#, "<Real/>"),
    ] {
        ok(attrs, real).unwrap_or_else(|e| panic!("{attrs}: {e}"));
    }
    // refused, with the reason
    for (attrs, real, reason) in [
        (
            r#"causality="parameter" variability="continuous""#,
            r#"<Real start="1"/>"#,
            "causality 'parameter' with variability 'continuous' is not allowed",
        ),
        (
            r#"causality="input" variability="constant""#,
            r#"<Real start="1"/>"#,
            "is not allowed",
        ),
        (
            r#"causality="independent" variability="discrete""#,
            "<Real/>",
            "is not allowed",
        ),
        (
            r#"causality="parameter" variability="fixed" initial="approx""#,
            r#"<Real start="1"/>"#,
            "allows initial exact, got initial=\"approx\"",
        ),
        (
            r#"causality="input" initial="exact""#,
            r#"<Real start="1"/>"#,
            "takes no 'initial' attribute",
        ),
        (
            r#"causality="parameter" variability="fixed""#,
            "<Real/>",
            "requires a start value",
        ),
        (r#"causality="input""#, "<Real/>", "requires a start value"),
        (
            r#"causality="local" variability="fixed""#,
            r#"<Real start="2"/>"#,
            "initial 'calculated' must not have a start value",
        ),
        (
            r#"causality="independent""#,
            r#"<Real start="0"/>"#,
            "must not have a start value",
        ),
        (
            r#"causality="local" variability="continuous""#,
            "<Integer/>",
            "a Integer variable cannot be continuous",
        ),
        (
            r#"causality="local" initial="bogus""#,
            "<Real/>",
            "got initial=\"bogus\"",
        ),
    ] {
        let e = ok(attrs, real).unwrap_err();
        assert!(
            e.contains(reason) && e.contains("variable 'm' (line 10)"),
            "{attrs}: {e}"
        );
    }
}

#[test]
fn value_references_shared_only_by_aliases() {
    // a local alias of an output (same vr, no start of its own) is fine
    let alias = MASS_SPRING.replace(
        r#"<ScalarVariable name="n_steps" valueReference="0" causality="local"><Integer/></ScalarVariable>"#,
        r#"<ScalarVariable name="n_steps" valueReference="0" causality="local"><Integer/></ScalarVariable>
<ScalarVariable name="pos_alias" valueReference="4" causality="local"><Real/></ScalarVariable>"#,
    );
    ModelDescription::parse(&alias).unwrap();
    // two parameters on one vr: not aliases of one value
    let e = ModelDescription::parse(&MASS_SPRING.replace(
        r#"name="k" valueReference="1""#,
        r#"name="k" valueReference="0""#,
    ))
    .unwrap_err();
    assert!(
        matches!(&e, ModelDescriptionError::ValueReference { name, other, value_reference: 0, .. }
            if name == "k" && other == "m"),
        "{e}"
    );
    // two start values on one vr
    let e = ModelDescription::parse(&MASS_SPRING.replace(
        r#"<ScalarVariable name="velocity" valueReference="5" causality="output" description="v &amp; co"><Real unit="m/s"/>"#,
        r#"<ScalarVariable name="velocity" valueReference="4" causality="local" initial="exact"><Real unit="m/s" start="0"/>"#,
    ))
    .unwrap_err()
    .to_string();
    assert!(e.contains("both have a start value"), "{e}");
}

#[test]
fn names_and_identifiers() {
    let structured = MASS_SPRING.replace(
        "guid=\"{abc}\"",
        "guid=\"{abc}\" variableNamingConvention=\"structured\"",
    );
    let named = |n: &str| {
        ModelDescription::parse(&structured.replace("name=\"n_steps\"", &format!("name=\"{n}\"")))
            .map(|_| ())
            .map_err(|e| e.to_string())
    };
    for good in [
        "a",
        "_a1.b_2",
        "x[1]",
        "x[1,2].y[3]",
        "der(x)",
        "der(body.x,2)",
        "'quoted name'",
        "'it\\'s'",
        "a.'b c'[2]",
    ] {
        named(good).unwrap_or_else(|e| panic!("{good}: {e}"));
    }
    for bad in [
        "", "1a", "a.", ".a", "a..b", "x[]", "x[1,]", "x[1, 2]", "a b", "der(x", "''",
    ] {
        let e = named(bad).unwrap_err();
        assert!(e.contains("invalid name"), "{bad}: {e}");
    }
    // flat names: anything but control characters
    let flat = |n: &str| {
        ModelDescription::parse(&MASS_SPRING.replace("name=\"n_steps\"", &format!("name=\"{n}\"")))
            .map_err(|e| e.to_string())
    };
    flat("any name [with] stuff").unwrap();
    assert!(flat("tab&#9;here").unwrap_err().contains("U+0009"));
    assert!(flat("nul&#0;here")
        .unwrap_err()
        .contains("control character"));
    let e = ModelDescription::parse(&MASS_SPRING.replace(
        "modelIdentifier=\"MassSpring\"",
        "modelIdentifier=\"../lib/evil\"",
    ))
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("modelIdentifier") && e.contains("C identifier"),
        "{e}"
    );
    let e = ModelDescription::parse(&MASS_SPRING.replace("guid=\"{abc}\"", "guid=\"{a&#x0;}\""))
        .unwrap_err()
        .to_string();
    assert!(e.contains("guid") && e.contains("control character"), "{e}");
}

#[test]
fn stray_ampersands_and_line_numbers_stay_linear() {
    // 200 000 '&' without ';' used to cost a scan to the end of the value each
    let desc = "&".repeat(200_000);
    let md = ModelDescription::parse(&MASS_SPRING.replace("v &amp; co", &desc)).unwrap();
    assert_eq!(
        md.variable("velocity").unwrap().1.description.as_deref(),
        Some(desc.as_str())
    );
    // line numbers after many lines are right
    let padded = MASS_SPRING.replace(
        "<ModelVariables>",
        &format!("{}<ModelVariables>", "\n".repeat(5000)),
    );
    let e = ModelDescription::parse(&padded.replace(r#"causality="input""#, r#"causality="x""#))
        .unwrap_err()
        .to_string();
    assert!(e.contains("line 5013"), "{e}");
}

#[test]
fn ranges_come_from_the_variable_else_from_its_declared_type() {
    let xml = MASS_SPRING
        .replace(
            r#"<Real quantity="Length" unit="m"/>"#,
            r#"<Real quantity="Length" unit="m" min="-1" max="1"/>"#,
        )
        .replace(
            r#"<Real start="100" unit="N/m"/>"#,
            r#"<Real start="100" unit="N/m" min="0"/>"#,
        )
        .replace(
            r#"<Real declaredType="Position" start="0.1"/>"#,
            r#"<Real declaredType="Position" start="0.1" max="0.5"/>"#,
        );
    let md = ModelDescription::parse(&xml).unwrap();
    let range = |n: &str| {
        let v = md.variable(n).unwrap().1;
        (v.min, v.max)
    };
    assert_eq!(range("k"), (Some(0.0), None));
    // the type's min, the variable's own max
    assert_eq!(range("position"), (Some(-1.0), Some(0.5)));
    assert_eq!(range("m"), (None, None));
}

/// A start value or bound that does not read as its variable's type (the FMI 2.0 schema's
/// xs:double, xs:int, xs:boolean) is refused with the attribute, the value and the line.
#[test]
fn start_values_and_bounds_must_read_as_their_type() {
    let parse = |from: &str, to: &str| {
        assert!(MASS_SPRING.contains(from), "fixture lacks {from}");
        ModelDescription::parse(&MASS_SPRING.replace(from, to)).map_err(|e| e.to_string())
    };
    for (from, to, attribute) in [
        (
            r#"<Real start="1" unit="kg"/>"#,
            r#"<Real start="one" unit="kg"/>"#,
            "start",
        ),
        (
            r#"<Real start="100" unit="N/m"/>"#,
            r#"<Real start="100" min="low" unit="N/m"/>"#,
            "min",
        ),
        ("<Integer/>", r#"<Integer start="1.5"/>"#, "start"),
        ("<Integer/>", r#"<Integer start="4294967296"/>"#, "start"),
        (
            r#"<Real quantity="Length" unit="m"/>"#,
            r#"<Real quantity="Length" unit="m" max="far"/>"#,
            "max",
        ),
    ] {
        let e = parse(from, to).unwrap_err();
        assert!(
            e.contains(attribute) && e.contains("expected a"),
            "{to}: {e}"
        );
        assert!(e.contains("line"), "{to}: {e}");
    }
    // the forms the XML schema types allow
    parse(
        r#"<Real start="1" unit="kg"/>"#,
        r#"<Real start=" 1e-3 " unit="kg"/>"#,
    )
    .unwrap();
    parse(
        r#"<Real start="1" unit="kg"/>"#,
        r#"<Real start="INF" unit="kg"/>"#,
    )
    .unwrap();
    parse("<Integer/>", r#"<Integer max="+7" min="-2147483648"/>"#).unwrap();
}
