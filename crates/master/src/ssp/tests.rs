//! SSP import on hand-written archives in the styles of OMSimulator (system-level .ssv with
//! hierarchical names, oms:FixedStepMaster), libcosim (component bindings, osp annotations)
//! and SSP 2.0 (Float64/Int32, prefix, .ssm mapping); and the refusals.

use std::io::Write;
use std::path::{Path, PathBuf};

use serde_json::json;

use super::*;
use crate::fmu::platform_binary_dir;
use crate::model_description::tests::MASS_SPRING;

const HEAD: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription" xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" xmlns:ssm="http://ssp-standard.org/SSP1/SystemStructureParameterMapping" xmlns:oms="https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd" xmlns:osp="http://opensimulationplatform.com/SSP/OSPAnnotations""#;

fn fmu_bytes() -> Vec<u8> {
    let (dir, suf) = platform_binary_dir().unwrap();
    let mut z = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let o = zip::write::SimpleFileOptions::default();
    z.start_file("modelDescription.xml", o).unwrap();
    z.write_all(MASS_SPRING.as_bytes()).unwrap();
    z.start_file(format!("binaries/{dir}/MassSpring{suf}"), o)
        .unwrap();
    z.finish().unwrap().into_inner()
}

/// Writes `x.ssp` with these members (FMU members get the test FMU's bytes when empty).
fn ssp(dir: &Path, files: &[(&str, &str)]) -> PathBuf {
    let p = dir.join("x.ssp");
    let mut z = zip::ZipWriter::new(std::fs::File::create(&p).unwrap());
    let o = zip::write::SimpleFileOptions::default();
    for (name, text) in files {
        z.start_file(*name, o).unwrap();
        if name.ends_with(".fmu") && text.is_empty() {
            z.write_all(&fmu_bytes()).unwrap();
        } else {
            z.write_all(text.as_bytes()).unwrap();
        }
    }
    z.finish().unwrap();
    p
}

fn import_ok(files: &[(&str, &str)]) -> ImportedSsp {
    let d = tempfile::tempdir().unwrap();
    let p = ssp(d.path(), files);
    import(&p, &ImportOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn import_err(files: &[(&str, &str)]) -> String {
    let d = tempfile::tempdir().unwrap();
    let p = ssp(d.path(), files);
    match import(&p, &ImportOptions::default()) {
        Ok(_) => panic!("imported although it should not"),
        Err(e) => e.to_string(),
    }
}

const OMS_SSD: &str = r#" name="oms" version="1.0">
  <ssd:System name="root">
    <ssd:ParameterBindings>
      <ssd:ParameterBinding source="resources/oms.ssv"/>
    </ssd:ParameterBindings>
    <ssd:Elements>
      <ssd:Component name="ms1" type="application/x-fmu-sharedlibrary" source="resources/0001_ms1.fmu">
        <ssd:Connectors>
          <ssd:Connector name="force" kind="input"><ssc:Real unit="N"/><ssd:ConnectorGeometry x="0" y="0.5"/></ssd:Connector>
          <ssd:Connector name="position" kind="output"><ssc:Real unit="m"/><ssd:ConnectorGeometry x="1" y="0.5"/></ssd:Connector>
          <ssd:Connector name="k" kind="parameter"><ssc:Real unit="N/m"/></ssd:Connector>
        </ssd:Connectors>
        <ssd:ElementGeometry x1="10" y1="10" x2="30" y2="30"/>
      </ssd:Component>
      <ssd:Component name="ms2" type="application/x-fmu-sharedlibrary" source="resources/0002_ms2.fmu">
        <ssd:Connectors>
          <ssd:Connector name="force" kind="input"><ssc:Real unit="N"/></ssd:Connector>
          <ssd:Connector name="velocity" kind="output"><ssc:Real unit="m/s"/></ssd:Connector>
        </ssd:Connectors>
      </ssd:Component>
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="ms1" startConnector="position" endElement="ms2" endConnector="force" suppressUnitConversion="true"/>
      <ssd:Connection startElement="ms2" startConnector="velocity" endElement="ms1" endConnector="force" suppressUnitConversion="1"/>
    </ssd:Connections>
    <ssd:Annotations>
      <ssc:Annotation type="org.openmodelica">
        <oms:Annotations>
          <oms:SimulationInformation>
            <oms:FixedStepMaster description="oms-ma" stepSize="0.002000" absoluteTolerance="0.000100" relativeTolerance="0.000100"/>
          </oms:SimulationInformation>
        </oms:Annotations>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:System>
  <ssd:Units>
    <ssc:Unit name="N"><ssc:BaseUnit kg="1" m="1" s="-2"/></ssc:Unit>
    <ssc:Unit name="m"><ssc:BaseUnit m="1"/></ssc:Unit>
  </ssd:Units>
  <ssd:DefaultExperiment startTime="0.000000" stopTime="2.000000">
    <ssd:Annotations>
      <ssc:Annotation type="org.openmodelica">
        <oms:Annotations><oms:SimulationInformation resultFile="oms_res.mat" loggingInterval="0.000000" bufferSize="10" signalFilter="resources/signalFilter.xml"/></oms:Annotations>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:DefaultExperiment>
</ssd:SystemStructureDescription>"#;

const OMS_SSV: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<ssv:ParameterSet xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" version="1.0" name="parameters">
  <ssv:Parameters>
    <ssv:Parameter name="ms1.k"><ssv:Real value="250" unit="N/m"/></ssv:Parameter>
    <ssv:Parameter name="ms2.m"><ssv:Real value="2.5"/></ssv:Parameter>
    <ssv:Parameter name="ms2.position"><ssv:Real value="-0.05" unit="m"/></ssv:Parameter>
  </ssv:Parameters>
  <ssv:Units>
    <ssc:Unit name="N/m"><ssc:BaseUnit kg="1" s="-2"/></ssc:Unit>
    <ssc:Unit name="m"><ssc:BaseUnit m="1"/></ssc:Unit>
  </ssv:Units>
</ssv:ParameterSet>"#;

fn oms_files() -> Vec<(&'static str, String)> {
    vec![
        ("SystemStructure.ssd", format!("{HEAD}{OMS_SSD}")),
        ("resources/0001_ms1.fmu", String::new()),
        ("resources/0002_ms2.fmu", String::new()),
        ("resources/oms.ssv", OMS_SSV.to_string()),
    ]
}

fn refs<'a>(v: &'a [(&'static str, String)]) -> Vec<(&'static str, &'a str)> {
    v.iter().map(|(a, b)| (*a, b.as_str())).collect()
}

#[test]
fn omsimulator_style_system_binding_with_hierarchical_names() {
    let files = oms_files();
    let imp = import_ok(&refs(&files));
    let d = &imp.system.desc;
    assert_eq!(imp.version, "1.0");
    assert_eq!(d.instances.len(), 2);
    assert_eq!(d.instances[0].name, "ms1");
    assert_eq!(d.instances[0].parameters.get("k"), Some(&json!(250.0)));
    assert_eq!(d.instances[1].parameters.get("m"), Some(&json!(2.5)));
    assert_eq!(
        d.instances[1].parameters.get("position"),
        Some(&json!(-0.05))
    );
    assert_eq!(d.instances[1].parameters.len(), 2);
    assert_eq!(d.connections.len(), 2);
    assert_eq!(d.connections[0].from, "ms1.position");
    assert_eq!(d.connections[0].to, "ms2.force");
    // suppressUnitConversion="true" (and "1"): the value passes unchanged
    assert!(d.connections.iter().all(|c| !c.convert_units));
    let mut files = oms_files();
    files[0].1 = files[0].1.replace(r#" suppressUnitConversion="1""#, "");
    let d = import_ok(&refs(&files)).system.desc;
    assert!(!d.connections[0].convert_units && d.connections[1].convert_units);
    assert_eq!(d.step, 0.002);
    assert_eq!(d.stop_time, 2.0);
    assert_eq!(d.start_time, 0.0);
    assert_eq!(d.algorithm, crate::coupling::Algorithm::Jacobi);
    // the FMUs are unpacked and open
    let fmus = imp.system.open_fmus().unwrap();
    assert_eq!(fmus[1].model.model_name, "MassSpring");
}

#[test]
fn options_override_the_ssp() {
    let files = oms_files();
    let d = tempfile::tempdir().unwrap();
    let p = ssp(d.path(), &refs(&files));
    let opts = ImportOptions {
        step: Some(0.01),
        stop_time: Some(0.5),
        algorithm: Some(crate::coupling::Algorithm::GaussSeidel),
    };
    let imp = import(&p, &opts).unwrap();
    assert_eq!(imp.system.desc.step, 0.01);
    assert_eq!(imp.system.desc.stop_time, 0.5);
    assert_eq!(
        imp.system.desc.algorithm,
        crate::coupling::Algorithm::GaussSeidel
    );
}

const OSP_SSD: &str = r#" name="osp" version="1.0">
  <ssd:System name="sys" description="libcosim style">
    <ssd:Elements>
      <ssd:Component name="a" source="resources/ms.fmu">
        <ssd:Connectors>
          <ssd:Connector name="position" kind="output"><ssc:Real/></ssd:Connector>
          <ssd:Connector name="force" kind="input"><ssc:Real/></ssd:Connector>
        </ssd:Connectors>
        <ssd:ParameterBindings>
          <ssd:ParameterBinding source="a_params.ssv"/>
          <ssd:ParameterBinding>
            <ssd:ParameterValues>
              <ssv:ParameterSet version="1.0" name="later">
                <ssv:Parameters>
                  <ssv:Parameter name="d"><ssv:Real value="0.5"/></ssv:Parameter>
                </ssv:Parameters>
              </ssv:ParameterSet>
            </ssd:ParameterValues>
          </ssd:ParameterBinding>
        </ssd:ParameterBindings>
        <ssd:Annotations>
          <ssc:Annotation type="com.opensimulationplatform"><osp:StepSizeHint value="0.004"/></ssc:Annotation>
        </ssd:Annotations>
      </ssd:Component>
      <ssd:Component name="b" source="resources/ms.fmu">
        <ssd:Connectors>
          <ssd:Connector name="position" kind="output"><ssc:Real/></ssd:Connector>
          <ssd:Connector name="force" kind="input"><ssc:Real/></ssd:Connector>
        </ssd:Connectors>
      </ssd:Component>
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="b" startConnector="force" endElement="a" endConnector="position" suppressUnitConversion="true"/>
    </ssd:Connections>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0.5" stopTime="1.5">
    <ssd:Annotations>
      <ssc:Annotation type="com.opensimulationplatform">
        <osp:Algorithm><osp:FixedStepAlgorithm baseStepSize="0.001"/></osp:Algorithm>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:DefaultExperiment>
</ssd:SystemStructureDescription>"#;

const A_SSV: &str = r#"<ssv:ParameterSet xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" version="1.0" name="initial">
  <ssv:Parameters>
    <ssv:Parameter name="d"><ssv:Real value="9"/></ssv:Parameter>
    <ssv:Parameter name="m"><ssv:Real value="3"/></ssv:Parameter>
  </ssv:Parameters>
</ssv:ParameterSet>"#;

#[test]
fn libcosim_style_component_bindings_and_annotations() {
    let ssd = format!("{HEAD}{OSP_SSD}");
    let imp = import_ok(&[
        ("SystemStructure.ssd", &ssd),
        ("resources/ms.fmu", ""),
        ("a_params.ssv", A_SSV),
    ]);
    let d = &imp.system.desc;
    // every binding is applied, the later one winning for 'd'
    assert_eq!(d.instances[0].parameters.get("m"), Some(&json!(3.0)));
    assert_eq!(d.instances[0].parameters.get("d"), Some(&json!(0.5)));
    assert_eq!(d.step, 0.001);
    assert_eq!(d.start_time, 0.5);
    assert_eq!(d.stop_time, 1.5);
    assert_eq!(d.instances[0].step_multiple, 4);
    assert_eq!(d.instances[1].step_multiple, 1);
    // written input -> output: read as output -> input
    assert_eq!(d.connections[0].from, "a.position");
    assert_eq!(d.connections[0].to, "b.force");
    // both instances share one FMU source, unpacked once from the archive (and loaded as the
    // instances of one FMU file of a JSON system are)
    assert_eq!(imp.system.fmu_path(0), imp.system.fmu_path(1));
}

const V2_SSD: &str = r#" name="v2" version="2.0">
  <ssd:System name="top">
    <ssd:ParameterBindings>
      <ssd:ParameterBinding source="resources/bare.ssv" prefix="ms.">
        <ssd:ParameterMapping source="resources/map.ssm"/>
      </ssd:ParameterBinding>
    </ssd:ParameterBindings>
    <ssd:Elements>
      <ssd:Component name="ms" source="resources/ms.fmu" implementation="CoSimulation">
        <ssd:ParameterBindings>
          <ssd:ParameterBinding>
            <ssd:ParameterValues>
              <ssv:ParameterSet version="2.0" name="component">
                <ssv:Parameters>
                  <ssv:Parameter name="k"><ssv:Float64 value="1"/></ssv:Parameter>
                  <ssv:Parameter name="m"><ssv:Float64 value="7"/></ssv:Parameter>
                </ssv:Parameters>
              </ssv:ParameterSet>
            </ssd:ParameterValues>
          </ssd:ParameterBinding>
        </ssd:ParameterBindings>
      </ssd:Component>
    </ssd:Elements>
  </ssd:System>
  <ssd:DefaultExperiment stopTime="1"/>
</ssd:SystemStructureDescription>"#;

const BARE_SSV: &str = r#"<ssv:ParameterSet xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" version="2.0" name="bare">
  <ssv:Parameters>
    <ssv:Parameter name="stiffness"><ssv:Float64 value="2"/></ssv:Parameter>
    <ssv:Parameter name="unused"><ssv:Int32 value="4"/></ssv:Parameter>
  </ssv:Parameters>
</ssv:ParameterSet>"#;

const MAP_SSM: &str = r#"<ssm:ParameterMapping xmlns:ssm="http://ssp-standard.org/SSP1/SystemStructureParameterMapping" xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" version="2.0">
  <ssm:MappingEntry source="ms.stiffness" target="ms.k"><ssc:LinearTransformation factor="100" offset="5"/></ssm:MappingEntry>
</ssm:ParameterMapping>"#;

/// The SSP 2.0 archive (V2_SSD) in `dir` with these parameter set and mapping members.
fn v2_archive(dir: &Path, ssv: &str, ssm: &str) -> PathBuf {
    let ssd = format!("{HEAD}{V2_SSD}");
    ssp(
        dir,
        &[
            ("SystemStructure.ssd", &ssd),
            ("resources/ms.fmu", ""),
            ("resources/bare.ssv", ssv),
            ("resources/map.ssm", ssm),
        ],
    )
}

/// Import options giving the 1 ms step the V2 archive lacks.
fn stepped() -> ImportOptions {
    ImportOptions {
        step: Some(0.001),
        ..Default::default()
    }
}

#[test]
fn ssp2_prefix_mapping_and_precedence() {
    let d = tempfile::tempdir().unwrap();
    let p = v2_archive(d.path(), BARE_SSV, MAP_SSM);
    let imp = import(&p, &stepped()).unwrap();
    assert_eq!(imp.version, "2.0");
    let params = &imp.system.desc.instances[0].parameters;
    // the system binding (mapped: 100 * 2 + 5) wins over the component's k = 1; only mapped
    // parameters are applied ('unused' is not)
    assert_eq!(params.get("k"), Some(&json!(205.0)));
    assert_eq!(params.get("m"), Some(&json!(7.0)));
    assert_eq!(params.len(), 2);
    // a mapping whose result overflows is named as such, not as a value that is "null"
    let huge = BARE_SSV.replace(
        r#"<ssv:Float64 value="2"/>"#,
        r#"<ssv:Float64 value="1e307"/>"#,
    );
    let other = tempfile::tempdir().unwrap();
    let e = import(&v2_archive(other.path(), &huge, MAP_SSM), &stepped())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("not a finite number") && !e.contains("null"),
        "{e}"
    );
    // without a step the SSP is refused, naming what is missing
    let e = import(&p, &ImportOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("no communication step") && e.contains("--step"),
        "{e}"
    );
}

/// The master's own annotation (as `master export-ssp` writes it) sets the coupling of an
/// import: algorithm, order, sweeps; an option overrides the algorithm, an order that does
/// not name the SSD's components is not used, a bad algorithm is named.
#[test]
fn the_masters_coupling_annotation_is_read_and_checked() {
    let with_coupling = |coupling: &str| {
        let mut files = oms_files();
        let annotation = format!(
            r#"<ssd:Annotations>
      <ssc:Annotation type="org.rail-fmu.master"><rfm:Coupling xmlns:rfm="urn:rail-fmu:master:coupling" {coupling}</rfm:Coupling></ssc:Annotation>"#
        );
        let ssd = &mut files[0].1;
        let at = ssd
            .find("    <ssd:Annotations>\n      <ssc:Annotation")
            .unwrap();
        ssd.replace_range(at + 4..at + 4 + "<ssd:Annotations>".len(), &annotation);
        files
    };
    let opts = |algorithm| ImportOptions {
        algorithm,
        ..ImportOptions::default()
    };
    let desc = |coupling: &str, algorithm| {
        let files = with_coupling(coupling);
        let d = tempfile::tempdir().unwrap();
        let p = ssp(d.path(), &refs(&files));
        import(&p, &opts(algorithm)).map(|i| i.system.desc.clone())
    };
    let kept = r#"algorithm="gauss-seidel" initSweeps="4" maxStepHalvings="1"><rfm:Instance name="ms2"/><rfm:Instance name="ms1"/>"#;
    let d = desc(kept, None).unwrap();
    assert_eq!(d.algorithm, Algorithm::GaussSeidel);
    assert_eq!(d.order, Some(vec!["ms2".to_string(), "ms1".to_string()]));
    assert_eq!((d.init_sweeps, d.max_step_halvings), (4, 1));
    // the command line's algorithm wins; Jacobi has no order
    let d = desc(kept, Some(Algorithm::Jacobi)).unwrap();
    assert_eq!((d.algorithm, d.order), (Algorithm::Jacobi, None));
    // an order of components renamed since: derived from the FMUs instead
    let stale = kept.replace(r#"name="ms1""#, r#"name="renamed""#);
    let d = desc(&stale, None).unwrap();
    assert_eq!((d.algorithm, d.order), (Algorithm::GaussSeidel, None));
    let e = desc(r#"algorithm="seidel">"#, None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("coupling algorithm 'seidel': expected 'jacobi' or 'gauss-seidel'"),
        "{e}"
    );
    let e = desc(r#"initSweeps="-1">"#, None).unwrap_err().to_string();
    assert!(e.contains("initSweeps = '-1': not a whole number"), "{e}");
}

/// Names SSP says are unique: a parameter set's parameters, a mapping's targets. Given twice
/// they are refused (the last one won).
#[test]
fn a_parameter_or_mapping_target_given_twice_is_refused() {
    let import_with = |ssv: &str, ssm: &str| {
        let d = tempfile::tempdir().unwrap();
        import(&v2_archive(d.path(), ssv, ssm), &stepped())
            .map(|_| ())
            .map_err(|e| e.to_string())
    };
    assert!(import_with(BARE_SSV, MAP_SSM).is_ok());
    let twice = BARE_SSV.replace(r#"name="unused""#, r#"name="stiffness""#);
    let e = import_with(&twice, MAP_SSM).unwrap_err();
    assert!(
        e.contains("parameter 'stiffness' is given twice in set 'bare' (first at line 3)"),
        "{e}"
    );
    let entry = r#"<ssm:MappingEntry source="ms.stiffness" target="ms.k">"#;
    let two_targets = MAP_SSM.replace(
        "</ssm:ParameterMapping>",
        r#"  <ssm:MappingEntry source="ms.unused" target="ms.k"/>
</ssm:ParameterMapping>"#,
    );
    assert!(MAP_SSM.contains(entry));
    let e = import_with(BARE_SSV, &two_targets).unwrap_err();
    assert!(
        e.contains("mapping target 'ms.k' is mapped to twice (first at line 2)"),
        "{e}"
    );
}

#[test]
fn a_bare_ssd_next_to_its_fmus() {
    let d = tempfile::tempdir().unwrap();
    std::fs::create_dir(d.path().join("resources")).unwrap();
    std::fs::write(d.path().join("resources/ms.fmu"), fmu_bytes()).unwrap();
    std::fs::write(d.path().join("a_params.ssv"), A_SSV).unwrap();
    let ssd = d.path().join("SystemStructure.ssd");
    std::fs::write(&ssd, format!("{HEAD}{OSP_SSD}")).unwrap();
    let imp = import(&ssd, &ImportOptions::default()).unwrap();
    assert_eq!(imp.system.desc.instances[0].parameters.len(), 2);
    assert!(imp.system.fmu_path(0).exists());
    // the parameter file is an input of a run, as the .ssd and the FMUs are
    assert_eq!(imp.files_read, vec![d.path().join("a_params.ssv")]);
    assert!(is_ssp_path(&ssd) && !is_ssp_path(Path::new("x.json")));
}

/// The OMSimulator archive with `from` replaced by `to` in member `member`.
fn oms_with(member: &str, from: &str, to: &str) -> String {
    let mut files = oms_files();
    for (n, t) in files.iter_mut() {
        if *n == member {
            assert!(t.contains(from), "fixture lacks {from}");
            *t = t.replace(from, to);
        }
    }
    import_err(&refs(&files))
}

#[test]
fn unsupported_content_is_refused_by_name() {
    let ssd = "SystemStructure.ssd";
    let ssv = "resources/oms.ssv";
    let cases: Vec<(String, &str)> = vec![
        (
            oms_with(ssv, r#""ms2.m""#, r#""ms2.mass""#),
            "'ms2.mass' matches no 'component.variable'",
        ),
        (oms_with(ssv, r#""ms1.k""#, r#""ms3.k""#), "ms3.k"),
        (
            oms_with(
                ssv,
                r#"<ssv:Real value="2.5"/>"#,
                r#"<ssv:Binary value="00"/>"#,
            ),
            "type Binary",
        ),
        (
            oms_with(
                ssv,
                r#"<ssv:Real value="2.5"/>"#,
                r#"<ssv:Boolean value="true"/>"#,
            ),
            "a Boolean value cannot set 'ms2.m', which is Real",
        ),
        (
            oms_with(
                ssv,
                r#"value="250" unit="N/m""#,
                r#"value="250" unit="N/mm""#,
            ),
            "unit conversion",
        ),
        (
            oms_with(
                ssd,
                r#"<ssd:Connection startElement="ms1""#,
                r#"<ssd:Connection startElement="ms1" startIndices="1""#,
            ),
            "startIndices",
        ),
        (
            oms_with(
                ssd,
                r#"endConnector="force" suppressUnitConversion="1"/>"#,
                r#"endConnector="force"><ssc:LinearTransformation factor="2"/></ssd:Connection>"#,
            ),
            "connection transformation",
        ),
        (
            oms_with(
                ssd,
                r#"startElement="ms1" startConnector="position""#,
                r#"startConnector="position""#,
            ),
            "system connector 'root.position'",
        ),
        (
            oms_with(
                ssd,
                r#"<ssc:Real unit="m"/><ssd:ConnectorGeometry"#,
                r#"<ssc:Real unit="mm"/><ssd:ConnectorGeometry"#,
            ),
            "unit conversion: connector 'ms1.position' is in [mm]",
        ),
        (
            oms_with(
                ssd,
                r#"name="k" kind="parameter"><ssc:Real unit="N/m"/>"#,
                r#"name="k" kind="parameter"><ssc:Integer/>"#,
            ),
            "connector 'ms1.k' is Integer but the FMU's variable is Real",
        ),
        (
            oms_with(
                ssd,
                r#"name="velocity" kind="output""#,
                r#"name="velocity" kind="input""#,
            ),
            "kind 'input'",
        ),
        (
            oms_with(
                ssd,
                r#"name="force" kind="input"><ssc:Real unit="N"/></ssd:Connector>"#,
                r#"name="forc" kind="input"><ssc:Real unit="N"/></ssd:Connector>"#,
            ),
            "did you mean 'force'",
        ),
        (
            oms_with(
                ssd,
                r#"<ssd:Component name="ms2" type="application/x-fmu-sharedlibrary" source="resources/0002_ms2.fmu">"#,
                r#"<ssd:System name="sub"/><ssd:Component name="ms2" type="application/x-fmu-sharedlibrary" source="resources/0002_ms2.fmu">"#,
            ),
            "nested system 'sub'",
        ),
        (
            oms_with(
                ssd,
                r#"source="resources/0002_ms2.fmu""#,
                r#"source="resources/0002_ms2.fmu" implementation="ModelExchange""#,
            ),
            "implementation 'ModelExchange'",
        ),
        (
            oms_with(
                ssd,
                r#"source="resources/0002_ms2.fmu""#,
                r#"source="../0002_ms2.fmu""#,
            ),
            "outside the archive",
        ),
        (
            oms_with(
                ssd,
                r#"source="resources/0002_ms2.fmu""#,
                r#"source="file:///etc/passwd""#,
            ),
            "absolute URI",
        ),
        (
            oms_with(
                ssd,
                r#"source="resources/0002_ms2.fmu""#,
                r#"source="resources/other.ssp#sub.ssd""#,
            ),
            "fragment",
        ),
        (
            oms_with(ssd, r#"name="ms2" type"#, r#"name="ms.2" type"#),
            "component name 'ms.2'",
        ),
        (
            oms_with(ssd, r#"name="ms2" type"#, r#"name="ms1" type"#),
            "'ms1' is used twice",
        ),
        (
            oms_with(ssd, r#"<oms:FixedStepMaster"#, r#"<oms:VariableStepMaster"#),
            "variable-step master",
        ),
        (
            oms_with(ssd, r#"version="1.0""#, r#"version="3.0""#),
            "SSP version '3.0'",
        ),
        (
            oms_with(ssd, r#"<ssd:Units>"#, r#"<ssd:Bogus/><ssd:Units>"#),
            "<ssd:Bogus>",
        ),
        (
            oms_with(ssd, r#"stopTime="2.000000""#, r#"stopTime="soon""#),
            "stopTime=\"soon\"",
        ),
        (
            oms_with(
                ssd,
                r#"<ssd:ParameterBinding source="resources/oms.ssv"/>"#,
                r#"<ssd:ParameterBinding source="resources/oms.ssv" type="application/x-cdf"/>"#,
            ),
            "x-cdf",
        ),
        (
            oms_with(
                ssd,
                r#"<ssd:ParameterBinding source="resources/oms.ssv"/>"#,
                r#"<ssd:ParameterBinding source="resources/missing.ssv"/>"#,
            ),
            "missing.ssv",
        ),
        (
            oms_with(ssd, "<ssd:Elements>", "<ssd:Elements <"),
            "XML syntax error",
        ),
    ];
    for (msg, want) in cases {
        assert!(msg.contains(want), "expected '{want}' in: {msg}");
    }
    // a member of the archive is named as archive:member with a line
    let e = oms_with(ssv, r#""ms2.m""#, r#""ms2.mass""#);
    assert!(e.contains("x.ssp:resources/oms.ssv line 5"), "{e}");
    let e = oms_with(
        ssd,
        r#"name="velocity" kind="output""#,
        r#"name="velocity" kind="input""#,
    );
    assert!(e.contains("x.ssp:SystemStructure.ssd line 19"), "{e}");
}

#[test]
fn broken_archives_are_refused() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("bad.ssp");
    std::fs::write(&p, b"not a zip").unwrap();
    let e = import(&p, &ImportOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("not a zip"), "{e}");
    let e = import_err(&[("readme.txt", "hi")]);
    assert!(
        e.contains("SystemStructure.ssd") && e.contains("no such file"),
        "{e}"
    );
    let e = import(Path::new("/no/such.ssd"), &ImportOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("/no/such.ssd"), "{e}");
    let e = import(&d.path().join("x.txt"), &ImportOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains(".ssp archive or a .ssd file"), "{e}");
    // a DTD (entity expansion) is refused by the XML reader
    let e = import_err(&[(
        "SystemStructure.ssd",
        "<?xml version=\"1.0\"?><!DOCTYPE x [<!ENTITY a \"aaaa\">]><x>&a;</x>",
    )]);
    assert!(e.contains("XML syntax error") || e.contains("DTD"), "{e}");
}

/// `import(path)` on another thread, its message; a call that blocks (on a FIFO) fails the
/// test instead of hanging it.
#[cfg(unix)]
fn import_message_within_seconds(path: &Path) -> String {
    let path = path.to_path_buf();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(
            import(&path, &ImportOptions::default())
                .map(|_| ())
                .map_err(|e| e.to_string()),
        );
    });
    match rx.recv_timeout(std::time::Duration::from_secs(20)) {
        Ok(r) => r.expect_err("imported although it should not"),
        Err(_) => panic!("import blocks"),
    }
}

#[cfg(unix)]
#[test]
fn a_fifo_or_folder_is_refused_as_not_a_regular_file() {
    let d = tempfile::tempdir().unwrap();
    let mkfifo = |p: &Path| {
        let made = std::process::Command::new("mkfifo").arg(p).status();
        assert!(made.is_ok_and(|s| s.success()), "mkfifo");
    };
    for name in ["fifo.ssd", "fifo.ssp"] {
        let p = d.path().join(name);
        mkfifo(&p);
        let e = import_message_within_seconds(&p);
        assert!(
            e.contains(name) && e.contains("not a regular file") && !e.contains("no such file"),
            "{e}"
        );
    }
    let folder = d.path().join("folder.ssd");
    std::fs::create_dir(&folder).unwrap();
    let e = import_message_within_seconds(&folder);
    assert!(e.contains("not a regular file"), "{e}");
    // a parameter set next to a bare .ssd that is a FIFO
    std::fs::create_dir(d.path().join("resources")).unwrap();
    std::fs::write(d.path().join("resources/ms.fmu"), fmu_bytes()).unwrap();
    mkfifo(&d.path().join("a_params.ssv"));
    let ssd = d.path().join("SystemStructure.ssd");
    std::fs::write(&ssd, format!("{HEAD}{OSP_SSD}")).unwrap();
    let e = import_message_within_seconds(&ssd);
    assert!(
        e.contains("a_params.ssv") && e.contains("not a regular file"),
        "{e}"
    );
    // a missing one is still named as missing
    let e = import_message_within_seconds(&d.path().join("none.ssd"));
    assert!(e.contains("No such file"), "{e}");
}

/// A large parameter set names the line of a duplicate far down (each element's line comes
/// from an index of the line starts, not a scan from the file's start per element, which was
/// quadratic in the file's size); a tag crowded with attributes is refused before the XML
/// parser, which compares each attribute with the element's others.
#[test]
fn large_parameter_sets_keep_their_line_numbers_and_crowded_tags_are_refused() {
    let n = 30_000;
    let mut ssv = String::from(
        "<ssv:ParameterSet xmlns:ssv=\"http://ssp-standard.org/SSP1/SystemStructureParameterValues\" version=\"2.0\" name=\"big\">\n  <ssv:Parameters>\n",
    );
    for k in 0..n {
        ssv.push_str(&format!(
            "    <ssv:Parameter name=\"p{k}\"><ssv:Float64 value=\"{k}.5\"/></ssv:Parameter>\n"
        ));
    }
    // line 3 holds p0; the copy of p7 below lands on line 3 + n
    ssv.push_str("    <ssv:Parameter name=\"p7\"><ssv:Float64 value=\"1\"/></ssv:Parameter>\n");
    ssv.push_str("  </ssv:Parameters>\n</ssv:ParameterSet>");
    let e = super::ssv::parse_ssv("big.ssv", &ssv)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(&format!("line {}", 3 + n))
            && e.contains("parameter 'p7' is given twice in set 'big' (first at line 10)"),
        "{e}"
    );
    // a value may hold '>' and '=': the count goes on past them
    let attributes: String = (0..10_001).map(|k| format!(" a{k}=\">=\"")).collect();
    let crowded = format!("<?xml version=\"1.0\"?>\n\n<x{attributes}/>");
    let e = super::ssv::parse_ssv("crowded.ssv", &crowded)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("line 3") && e.contains("more than 10000 attributes"),
        "{e}"
    );
}

/// SSP 1.0 5.3.5: a binding with inline values has an empty source, which some tools write as
/// `source=""`; a component's FMU member that is no zip archive is refused before it is written
/// out (a member of gigabytes of zeros would fill the disk first).
#[test]
fn an_empty_binding_source_is_none_and_a_member_that_is_no_fmu_is_refused_at_once() {
    let ssd = format!(
        "{HEAD}{}",
        OSP_SSD.replace(
            "<ssd:ParameterBinding>\n            <ssd:ParameterValues>",
            "<ssd:ParameterBinding source=\"\">\n            <ssd:ParameterValues>"
        )
    );
    assert!(ssd.contains("source=\"\""));
    let imp = import_ok(&[
        ("SystemStructure.ssd", &ssd),
        ("resources/ms.fmu", ""),
        ("a_params.ssv", A_SSV),
    ]);
    let d = &imp.system.desc;
    assert_eq!(d.instances[0].parameters.get("d"), Some(&json!(0.5)));
    let e = import_err(&[
        ("SystemStructure.ssd", &ssd),
        ("resources/ms.fmu", "\0\0\0\0 zeros, not a zip"),
        ("a_params.ssv", A_SSV),
    ]);
    assert!(
        e.contains("resources/ms.fmu") && e.contains("not an FMU: it does not begin as a zip"),
        "{e}"
    );
}

/// A connector's kind is one the schema allows, and its name is declared once per component.
#[test]
fn a_connector_of_an_unknown_kind_or_declared_twice_is_refused() {
    let files = |ssd: String| {
        vec![
            ("SystemStructure.ssd", ssd),
            ("resources/ms.fmu", String::new()),
            ("a_params.ssv", A_SSV.to_string()),
        ]
    };
    let output = r#"<ssd:Connector name="position" kind="output"><ssc:Real/></ssd:Connector>"#;
    assert!(OSP_SSD.contains(output));
    // a kind SSP 2.0 adds is one the schema allows
    let unspecified = format!(
        "{HEAD}{}",
        OSP_SSD.replacen(r#"kind="output""#, r#"kind="unspecified""#, 1)
    );
    import_ok(&refs(&files(unspecified)));
    let bogus = format!(
        "{HEAD}{}",
        OSP_SSD.replacen(r#"kind="output""#, r#"kind="bogus""#, 1)
    );
    let e = import_err(&refs(&files(bogus)));
    assert!(
        e.contains("connector 'position' has kind 'bogus': one of input, output"),
        "{e}"
    );
    let twice = format!(
        "{HEAD}{}",
        OSP_SSD.replacen(output, &format!("{output}\n{output}"), 1)
    );
    let e = import_err(&refs(&files(twice)));
    assert!(
        e.contains("connector 'position' is declared twice (first at line"),
        "{e}"
    );
}

/// A connector's unit named otherwise than its FMU variable's is that unit when both define
/// the same SI unit, the FMU's through its own UnitDefinitions (`metre` in the SSP, `m` in the
/// FMU); a different factor is a conversion the master does not make.
#[test]
fn a_unit_of_another_name_is_the_fmus_when_their_definitions_agree() {
    let with_metre = |factor: &str| {
        let units = format!(
            r#"<ssd:Units><ssc:Unit name="metre"><ssc:BaseUnit m="1"{factor}/></ssc:Unit></ssd:Units>
  <ssd:DefaultExperiment"#
        );
        let ssd = OSP_SSD
            .replacen(
                r#"<ssd:Connector name="position" kind="output"><ssc:Real/></ssd:Connector>"#,
                r#"<ssd:Connector name="position" kind="output"><ssc:Real unit="metre"/></ssd:Connector>"#,
                1,
            )
            .replacen("<ssd:DefaultExperiment", &units, 1);
        assert!(ssd.contains(r#"unit="metre""#) && ssd.contains("<ssd:Units>"));
        vec![
            ("SystemStructure.ssd", format!("{HEAD}{ssd}")),
            ("resources/ms.fmu", String::new()),
            ("a_params.ssv", A_SSV.to_string()),
        ]
    };
    import_ok(&refs(&with_metre("")));
    let e = import_err(&refs(&with_metre(r#" factor="0.001""#)));
    assert!(
        e.contains("unit conversion: connector 'a.position' is in [metre]"),
        "{e}"
    );
    let md = crate::model_description::ModelDescription::parse(MASS_SPRING).unwrap();
    assert_eq!(md.units["m"].exponents, [0, 1, 0, 0, 0, 0, 0, 0]);
}

/// An element the schemas allow once is refused when given twice (the reader kept the last:
/// a second `<ssd:ParameterBindings>` dropped the first's parameters without a word, a second
/// `<ssd:System>` replaced the first); SSP 2.0's meta data (`ssc:MetaData`, several allowed)
/// is skipped wherever it may stand, and its array dimension is refused as an array.
#[test]
fn an_element_given_twice_is_refused_and_ssp2_meta_data_is_skipped() {
    let files = |ssd: String| {
        vec![
            ("SystemStructure.ssd", ssd),
            ("resources/ms.fmu", String::new()),
            ("a_params.ssv", A_SSV.to_string()),
        ]
    };
    let with = |from: &str, to: &str| {
        assert!(OSP_SSD.contains(from), "fixture lacks {from}");
        format!("{HEAD}{}", OSP_SSD.replacen(from, to, 1))
    };
    let bindings_end = "</ssd:ParameterBindings>";
    let second_bindings = r#"</ssd:ParameterBindings>
        <ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues>
          <ssv:ParameterSet version="1.0" name="other"><ssv:Parameters>
            <ssv:Parameter name="d"><ssv:Real value="1"/></ssv:Parameter>
          </ssv:Parameters></ssv:ParameterSet>
        </ssd:ParameterValues></ssd:ParameterBinding></ssd:ParameterBindings>"#;
    let e = import_err(&refs(&files(with(bindings_end, second_bindings))));
    assert!(
        e.contains("<ssd:ParameterBindings> is given twice in <ssd:Component> (first at line"),
        "{e}"
    );
    let e = import_err(&refs(&files(with(
        "</ssd:System>",
        r#"</ssd:System><ssd:System name="second"><ssd:Elements/></ssd:System>"#,
    ))));
    assert!(
        e.contains("<ssd:System> is given twice in <ssd:SystemStructureDescription>"),
        "{e}"
    );
    let connectors_end = "</ssd:Connectors>";
    let e = import_err(&refs(&files(with(
        connectors_end,
        r#"</ssd:Connectors><ssd:Connectors><ssd:Connector name="x" kind="input"><ssc:Real unit="furlong"/></ssd:Connector></ssd:Connectors>"#,
    ))));
    assert!(e.contains("<ssd:Connectors> is given twice"), "{e}");
    // SSP 2.0 meta data, twice in the root and once in a component: skipped
    let meta = r#"<ssc:MetaData kind="general" type="text/plain" source="readme.txt"/>"#;
    let v2 = with(r#"version="1.0""#, r#"version="2.0""#)
        .replacen(
            "</ssd:SystemStructureDescription>",
            &format!("{meta}{meta}</ssd:SystemStructureDescription>"),
            1,
        )
        .replacen("</ssd:Component>", &format!("{meta}</ssd:Component>"), 1);
    import_ok(&refs(&files(v2)));
    // an SSP 2.0 array connector is refused as one, and a connector of two types
    let e = import_err(&refs(&files(with(
        r#"<ssc:Real/></ssd:Connector>"#,
        r#"<ssc:Real/><ssc:Dimension size="1"/></ssd:Connector>"#,
    ))));
    assert!(e.contains("array connector 'position'"), "{e}");
    let e = import_err(&refs(&files(with(
        r#"<ssc:Real/></ssd:Connector>"#,
        r#"<ssc:Integer/><ssc:Real/></ssd:Connector>"#,
    ))));
    assert!(
        e.contains("connector 'position' has more than one type"),
        "{e}"
    );
    // and in a parameter mapping's root (SSP 2.0 allows meta data there too)
    let d = tempfile::tempdir().unwrap();
    let mapped = MAP_SSM.replacen(
        "<ssm:MappingEntry",
        &format!("{meta}\n  <ssm:MappingEntry"),
        1,
    );
    import(&v2_archive(d.path(), BARE_SSV, &mapped), &stepped()).unwrap_or_else(|e| panic!("{e}"));
}
