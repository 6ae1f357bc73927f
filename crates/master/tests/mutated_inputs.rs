//! Property: whatever a modelDescription.xml, a system description, a run set or the members of
//! an SSP (its .ssd, .ssv and .ssm) say, reading and validating them is an error or a success,
//! never a panic. Valid inputs are mutated (bytes deleted, duplicated, replaced, and fragments
//! known to be tricky inserted) and fed to the readers and to the validation that turns them
//! into a coupling plan.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use std::io::Write;
use std::path::Path;

use master::model_description::ModelDescription;
use master::runset::RunSet;
use master::ssp::{import, ImportOptions};
use master::system::LoadedSystem;
use proptest::prelude::*;

const MD: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="MassSpring" guid="{abc}" variableNamingConvention="structured">
  <CoSimulation modelIdentifier="MassSpring" canGetAndSetFMUstate="true"/>
  <TypeDefinitions><SimpleType name="Position"><Real unit="m"/></SimpleType></TypeDefinitions>
  <DefaultExperiment startTime="0" stopTime="1" stepSize="1e-3"/>
  <ModelVariables>
    <ScalarVariable name="m" valueReference="0" causality="parameter" variability="fixed"><Real start="1" unit="kg"/></ScalarVariable>
    <ScalarVariable name="force" valueReference="1" causality="input"><Real start="0"/></ScalarVariable>
    <ScalarVariable name="position" valueReference="2" causality="output"><Real declaredType="Position"/></ScalarVariable>
    <ScalarVariable name="der(position)" valueReference="3" causality="local"><Real unit="m/s"/></ScalarVariable>
    <ScalarVariable name="mode" valueReference="0" causality="parameter" variability="fixed"><Integer start="1"/></ScalarVariable>
    <ScalarVariable name="on" valueReference="0" causality="output" variability="discrete"><Boolean/></ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs><Unknown index="3" dependencies="2"/><Unknown index="6" dependencies=""/></Outputs></ModelStructure>
</fmiModelDescription>"#;

const SYSTEM: &str = r#"{
  "instances": [{"name": "a", "fmu": "A.fmu", "parameters": {"m": 2.0, "mode": 3}},
                {"name": "b", "fmu": "B.fmu", "step_multiple": 2}],
  "connections": [{"from": "a.position", "to": "b.force"}, {"from": "b.position", "to": "a.force"}],
  "start_time": 0.0, "stop_time": 1.0, "step": 0.001, "algorithm": "jacobi",
  "record": ["a.position", "b.on"], "init_sweeps": 2, "max_step_halvings": 3
}"#;

/// An SSP in the libcosim and SSP 1.0 styles over two copies of the FMU above: a system binding
/// inline, a component binding from an .ssv through an .ssm mapping, connectors with units,
/// unit definitions, the step as an annotation.
const SSD: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription" xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" xmlns:ssm="http://ssp-standard.org/SSP1/SystemStructureParameterMapping" xmlns:osp="http://opensimulationplatform.com/SSP/OSPAnnotations" name="mutated" version="1.0">
  <ssd:System name="root">
    <ssd:ParameterBindings>
      <ssd:ParameterBinding>
        <ssd:ParameterValues>
          <ssv:ParameterSet version="1.0" name="system">
            <ssv:Parameters>
              <ssv:Parameter name="b.m"><ssv:Real value="2" unit="kg"/></ssv:Parameter>
              <ssv:Parameter name="b.mode"><ssv:Integer value="3"/></ssv:Parameter>
            </ssv:Parameters>
          </ssv:ParameterSet>
        </ssd:ParameterValues>
      </ssd:ParameterBinding>
    </ssd:ParameterBindings>
    <ssd:Elements>
      <ssd:Component name="a" type="application/x-fmu-sharedlibrary" source="resources/a.fmu">
        <ssd:Connectors>
          <ssd:Connector name="force" kind="input"><ssc:Real/></ssd:Connector>
          <ssd:Connector name="position" kind="output"><ssc:Real unit="m"/></ssd:Connector>
        </ssd:Connectors>
        <ssd:ParameterBindings>
          <ssd:ParameterBinding source="resources/a.ssv">
            <ssd:ParameterMapping source="resources/a.ssm"/>
          </ssd:ParameterBinding>
        </ssd:ParameterBindings>
        <ssd:Annotations>
          <ssc:Annotation type="com.opensimulationplatform"><osp:StepSizeHint value="0.002"/></ssc:Annotation>
        </ssd:Annotations>
      </ssd:Component>
      <ssd:Component name="b" source="resources/b.fmu">
        <ssd:Connectors>
          <ssd:Connector name="force" kind="input"><ssc:Real/></ssd:Connector>
          <ssd:Connector name="position" kind="output"><ssc:Real unit="m"/></ssd:Connector>
        </ssd:Connectors>
      </ssd:Component>
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="a" startConnector="position" endElement="b" endConnector="force"/>
      <ssd:Connection startElement="b" startConnector="position" endElement="a" endConnector="force"/>
    </ssd:Connections>
  </ssd:System>
  <ssd:Units>
    <ssc:Unit name="m"><ssc:BaseUnit m="1"/></ssc:Unit>
    <ssc:Unit name="kg"><ssc:BaseUnit kg="1"/></ssc:Unit>
  </ssd:Units>
  <ssd:DefaultExperiment startTime="0" stopTime="1">
    <ssd:Annotations>
      <ssc:Annotation type="com.opensimulationplatform">
        <osp:Algorithm><osp:FixedStepAlgorithm baseStepSize="0.001"/></osp:Algorithm>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:DefaultExperiment>
</ssd:SystemStructureDescription>"#;

const SSV: &str = r#"<ssv:ParameterSet xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" version="1.0" name="initial">
  <ssv:Parameters>
    <ssv:Parameter name="mass"><ssv:Real value="3"/></ssv:Parameter>
    <ssv:Parameter name="mode"><ssv:Integer value="2"/></ssv:Parameter>
  </ssv:Parameters>
</ssv:ParameterSet>"#;

const SSM: &str = r#"<ssm:ParameterMapping xmlns:ssm="http://ssp-standard.org/SSP1/SystemStructureParameterMapping" xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" version="1.0">
  <ssm:MappingEntry source="mass" target="m"><ssc:LinearTransformation factor="10" offset="1"/></ssm:MappingEntry>
  <ssm:MappingEntry source="mode" target="mode"><ssc:IntegerMappingTransformation><ssc:MapEntry source="2" target="5"/></ssc:IntegerMappingTransformation></ssm:MappingEntry>
</ssm:ParameterMapping>"#;

/// The FMU of both components: the modelDescription above and an (unloadable) binary.
fn fmu_bytes() -> Vec<u8> {
    let (dir, suffix) = master::fmu::platform_binary_dir().unwrap();
    let mut z = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let o = zip::write::SimpleFileOptions::default();
    z.start_file("modelDescription.xml", o).unwrap();
    z.write_all(MD.as_bytes()).unwrap();
    z.start_file(format!("binaries/{dir}/MassSpring{suffix}"), o)
        .unwrap();
    z.finish().unwrap().into_inner()
}

/// Writes `x.ssp` with these texts and the two FMUs into `dir`, imports it.
fn import_ssp(
    dir: &Path,
    ssd: &str,
    ssv: &str,
    ssm: &str,
) -> Result<master::ssp::ImportedSsp, String> {
    let p = dir.join("x.ssp");
    let mut z = zip::ZipWriter::new(std::fs::File::create(&p).unwrap());
    let o = zip::write::SimpleFileOptions::default();
    let fmu = fmu_bytes();
    for (name, bytes) in [
        ("SystemStructure.ssd", ssd.as_bytes()),
        ("resources/a.ssv", ssv.as_bytes()),
        ("resources/a.ssm", ssm.as_bytes()),
        ("resources/a.fmu", &fmu),
        ("resources/b.fmu", &fmu),
    ] {
        z.start_file(name, o).unwrap();
        z.write_all(bytes).unwrap();
    }
    z.finish().unwrap();
    import(&p, &ImportOptions::default()).map_err(|e| e.to_string())
}

const RUNSET: &str = r#"{
  "system": {"instances": [{"name": "a", "fmu": "A.fmu"}, {"name": "b", "fmu": "B.fmu"}],
             "connections": [{"from": "a.position", "to": "b.force"}],
             "stop_time": 1.0, "step": 0.01},
  "product": {"a.m": [1, 2, 3], "b.mode": [0, 1]},
  "runs": [{"name": "extra", "parameters": {"a.m": 9}}]
}"#;

/// Fragments that have broken readers: entities, NULs, huge numbers, unbalanced markup.
const FRAGMENTS: &[&str] = &[
    "<",
    ">",
    "&",
    "&#0;",
    "&#x1;",
    "&#xFFFFFFFF;",
    "&amp",
    "\"",
    "'",
    "\0",
    "\u{FEFF}",
    "</ModelVariables>",
    "<ModelVariables>",
    "<ScalarVariable name=\"x\" valueReference=\"0\">",
    "<ScalarVariable name=\"x\" valueReference=\"4294967296\" causality=\"input\"><Real/></ScalarVariable>",
    "<Unknown index=\"0\"/>",
    "<Unknown index=\"18446744073709551616\" dependencies=\"1 2 99999\"/>",
    " initial=\"exact\"",
    " initial=\"bogus\"",
    " variability=\"continuous\"",
    " causality=\"independent\"",
    " start=\"1e999\"",
    "der(",
    "[1,",
    "<!DOCTYPE x [<!ENTITY a \"&a;&a;\">]>",
    "<![CDATA[",
    "<?xml version=\"1.0\"?>",
    "{",
    "}",
    "[",
    "]",
    ",",
    ":",
    "null",
    "1e308",
    "-1e-320",
    "4294967296",
    "18446744073709551616",
    "\"..\"",
    "\"a.\"",
    "\".b\"",
    "\"a.position\"",
    "\"step\": 1e-300,",
    "\"stop_time\": 1e300,",
    "\"step_multiple\": 0,",
];

#[derive(Debug, Clone)]
enum Mutation {
    Delete { at: usize, len: usize },
    Duplicate { at: usize, len: usize },
    Replace { at: usize, byte: u8 },
    Insert { at: usize, fragment: usize },
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), 1usize..40).prop_map(|(at, len)| Mutation::Delete { at, len }),
        (any::<usize>(), 1usize..200).prop_map(|(at, len)| Mutation::Duplicate { at, len }),
        (any::<usize>(), any::<u8>()).prop_map(|(at, byte)| Mutation::Replace { at, byte }),
        (any::<usize>(), 0..FRAGMENTS.len())
            .prop_map(|(at, fragment)| Mutation::Insert { at, fragment }),
    ]
}

fn mutate(text: &str, mutations: &[Mutation]) -> String {
    let mut b = text.as_bytes().to_vec();
    for m in mutations {
        let n = b.len().max(1);
        match *m {
            Mutation::Delete { at, len } => {
                let at = at % n;
                let end = (at + len).min(b.len());
                if at < end {
                    b.drain(at..end);
                }
            }
            Mutation::Duplicate { at, len } => {
                let at = at % n;
                let end = (at + len).min(b.len());
                let piece: Vec<u8> = b[at.min(b.len())..end].to_vec();
                b.splice(end..end, piece);
            }
            Mutation::Replace { at, byte } => {
                if !b.is_empty() {
                    let at = at % b.len();
                    b[at] = byte;
                }
            }
            Mutation::Insert { at, fragment } => {
                let at = at % (b.len() + 1);
                b.splice(at..at, FRAGMENTS[fragment].bytes());
            }
        }
    }
    String::from_utf8_lossy(&b).into_owned()
}

fn models() -> Vec<ModelDescription> {
    let md = ModelDescription::parse(MD).unwrap();
    vec![md.clone(), md]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, ..ProptestConfig::default() })]

    #[test]
    fn model_descriptions_never_panic(ms in prop::collection::vec(mutation(), 1..6)) {
        let text = mutate(MD, &ms);
        if let Ok(md) = ModelDescription::parse(&text) {
            // what a system's validation asks of a description
            for i in 0..md.variables.len() {
                let _ = md.has_direct_feedthrough(i);
            }
            let _ = md.suggest("positon");
            let _ = md.variable("position");
        }
    }

    #[test]
    fn system_descriptions_never_panic(ms in prop::collection::vec(mutation(), 1..6)) {
        let text = mutate(SYSTEM, &ms);
        let models = models();
        let refs: Vec<&ModelDescription> = models.iter().collect();
        if let Ok(sys) = LoadedSystem::from_json_str(&text, Path::new("/d"), "system.json") {
            if sys.desc.instances.len() == refs.len() {
                let _ = sys.plan(&refs);
            } else {
                let many: Vec<&ModelDescription> =
                    (0..sys.desc.instances.len()).map(|_| &models[0]).collect();
                let _ = sys.plan(&many);
            }
        }
    }

    #[test]
    fn run_sets_never_panic(ms in prop::collection::vec(mutation(), 1..6)) {
        let text = mutate(RUNSET, &ms);
        let _ = RunSet::jobs_from_str(&text, Path::new("/d"), "set.json");
    }
}

proptest! {
    // each case writes and imports an archive: fewer cases than the in-memory readers above
    #![proptest_config(ProptestConfig { cases: 600, ..ProptestConfig::default() })]

    #[test]
    fn ssp_members_never_panic(member in 0usize..3, ms in prop::collection::vec(mutation(), 1..6)) {
        let d = tempfile::tempdir().unwrap();
        let (ssd, ssv, ssm) = match member {
            0 => (mutate(SSD, &ms), SSV.to_string(), SSM.to_string()),
            1 => (SSD.to_string(), mutate(SSV, &ms), SSM.to_string()),
            _ => (SSD.to_string(), SSV.to_string(), mutate(SSM, &ms)),
        };
        if let Ok(imported) = import_ssp(d.path(), &ssd, &ssv, &ssm) {
            let models = models();
            let n = imported.system.desc.instances.len();
            let many: Vec<&ModelDescription> = (0..n).map(|_| &models[0]).collect();
            let _ = imported.system.plan(&many);
        }
    }
}

#[test]
fn the_unmutated_inputs_are_valid() {
    // the properties above start from inputs that pass, so mutations probe real paths
    let models = models();
    let refs: Vec<&ModelDescription> = models.iter().collect();
    let sys = LoadedSystem::from_json_str(SYSTEM, Path::new("/d"), "system.json").unwrap();
    let plan = sys.plan(&refs).unwrap();
    assert_eq!(plan.connections.len(), 2);
    assert_eq!(plan.record.len(), 2);
    let jobs = RunSet::jobs_from_str(RUNSET, Path::new("/d"), "set.json").unwrap();
    assert_eq!(jobs.len(), 7);
    let d = tempfile::tempdir().unwrap();
    let imported = import_ssp(d.path(), SSD, SSV, SSM).unwrap();
    let desc = &imported.system.desc;
    assert_eq!((desc.step, desc.instances[0].step_multiple), (0.001, 2));
    assert_eq!(desc.connections.len(), 2);
    // the component binding through the mapping (10 * 3 + 1, 2 -> 5), the system's inline set
    assert_eq!(desc.instances[0].parameters["m"], serde_json::json!(31.0));
    assert_eq!(desc.instances[0].parameters["mode"], serde_json::json!(5));
    assert_eq!(desc.instances[1].parameters["m"], serde_json::json!(2.0));
    assert_eq!(desc.instances[1].parameters["mode"], serde_json::json!(3));
}
