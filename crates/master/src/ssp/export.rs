//! A system description written as a self-contained SSP 1.0 archive.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::fmt::Write as _;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use serde_json::Value as Json;

use super::ssd::BASE_UNITS;
use super::xml::{escape, NS_SSC, NS_SSD, NS_SSV};
use super::SspError;
use crate::model_description::{Causality, ModelDescription, VarType};
use crate::system::{split_ref, LoadedSystem};

const NS_OSP: &str = "http://opensimulationplatform.com/SSP/OSPAnnotations";
const NS_OMS: &str =
    "https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd";
/// The namespace of the master's own annotation ([`super::ssd::MASTER_ANNOTATION`]).
const NS_MASTER: &str = "urn:rail-fmu:master:coupling";

/// The name of every parameter set written. Ecos applies parameter sets only when its
/// simulation is initialised with their name; one name for all makes one `init` apply all.
pub const PARAMETER_SET_NAME: &str = "initial";

/// What an export wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportSummary {
    /// Archive members in order (SystemStructure.ssd, FMUs, parameter sets).
    pub files: Vec<String>,
    pub components: usize,
    pub connections: usize,
    pub parameters: usize,
}

impl std::fmt::Display for ExportSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} components, {} connections, {} parameters, {} files",
            self.components,
            self.connections,
            self.parameters,
            self.files.len()
        )
    }
}

/// A unit of an FMU's UnitDefinitions that has a BaseUnit.
#[derive(Debug, Clone, PartialEq)]
struct Unit {
    exponents: [i64; 8],
    factor: f64,
    offset: f64,
}

/// What the export needs from an FMU's modelDescription.xml beyond [`ModelDescription`]: units
/// with their SI exponents, and the declared type of Enumeration variables.
#[derive(Default)]
struct FmuExtras {
    units: HashMap<String, Unit>,
    enum_types: HashMap<String, String>,
}

fn read_extras(path: &Path) -> Result<FmuExtras, SspError> {
    let err = |r: String| SspError::Export(format!("{}: {r}", path.display()));
    let f = std::fs::File::open(path).map_err(|e| err(e.to_string()))?;
    let mut zip = zip::ZipArchive::new(f).map_err(|e| err(e.to_string()))?;
    let mut text = String::new();
    zip.by_name("modelDescription.xml")
        .map_err(|e| err(e.to_string()))?
        .take(64 << 20)
        .read_to_string(&mut text)
        .map_err(|e| err(e.to_string()))?;
    let doc = roxmltree::Document::parse(&text).map_err(|e| err(e.to_string()))?;
    let mut x = FmuExtras::default();
    for u in doc.descendants().filter(|n| n.has_tag_name("Unit")) {
        let (Some(name), Some(b)) = (
            u.attribute("name"),
            u.children().find(|c| c.has_tag_name("BaseUnit")),
        ) else {
            continue;
        };
        let mut exponents = [0i64; 8];
        for (e, k) in exponents.iter_mut().zip(BASE_UNITS) {
            *e = b.attribute(k).and_then(|v| v.parse().ok()).unwrap_or(0);
        }
        let num = |k: &str, d: f64| b.attribute(k).and_then(|v| v.parse().ok()).unwrap_or(d);
        x.units.insert(
            name.to_string(),
            Unit {
                exponents,
                factor: num("factor", 1.0),
                offset: num("offset", 0.0),
            },
        );
    }
    for v in doc
        .descendants()
        .filter(|n| n.has_tag_name("ScalarVariable"))
    {
        if let (Some(name), Some(t)) = (
            v.attribute("name"),
            v.children()
                .find(|c| c.has_tag_name("Enumeration"))
                .and_then(|e| e.attribute("declaredType")),
        ) {
            x.enum_types.insert(name.to_string(), t.to_string());
        }
    }
    Ok(x)
}

/// `x` as xs:double text that reads back to the same f64.
fn real(x: f64) -> String {
    format!("{x:?}")
}

pub(super) fn export(sys: &LoadedSystem, out: &Path) -> Result<ExportSummary, SspError> {
    let archives = sys.open_fmus()?;
    let models: Vec<&ModelDescription> = archives.iter().map(|a| &a.model).collect();
    // everything the master would refuse is refused before anything is written
    sys.plan(&models)?;
    let d = &sys.desc;

    // one resource per FMU file; equal file names of different FMUs get a suffix
    let mut resource_of: Vec<String> = Vec::new();
    let mut by_path: HashMap<PathBuf, String> = HashMap::new();
    let mut used: BTreeSet<String> = BTreeSet::new();
    let mut fmu_members: Vec<(String, PathBuf)> = Vec::new();
    for i in 0..d.instances.len() {
        let p = sys.fmu_path(i);
        // the file itself: `dist/X.fmu` and `systems/../dist/X.fmu` are one member
        let key = std::fs::canonicalize(&p)
            .or_else(|_| std::path::absolute(&p))
            .unwrap_or(p.clone());
        if let Some(r) = by_path.get(&key) {
            resource_of.push(r.clone());
            continue;
        }
        let stem = p.file_stem().and_then(|s| s.to_str()).unwrap_or("");
        let name = unique_member(&mut used, stem, "fmu");
        by_path.insert(key, name.clone());
        fmu_members.push((name.clone(), p));
        resource_of.push(name);
    }
    let extras: Vec<FmuExtras> = (0..d.instances.len())
        .map(|i| read_extras(&sys.fmu_path(i)))
        .collect::<Result<_, _>>()?;

    // connectors: every connected variable, and recorded inputs and outputs
    let mut connector_names: Vec<BTreeSet<String>> = vec![BTreeSet::new(); d.instances.len()];
    let index = |inst: &str| d.instances.iter().position(|x| x.name == inst);
    let mut refs: Vec<&str> = Vec::new();
    for c in &d.connections {
        refs.push(&c.from);
        refs.push(&c.to);
    }
    for r in d.record.iter().flatten() {
        refs.push(r);
    }
    for r in refs {
        if let Some((inst, var)) = split_ref(r) {
            if let Some(i) = index(inst) {
                if let Some((_, v)) = models[i].variable(var) {
                    if matches!(v.causality, Causality::Input | Causality::Output) {
                        connector_names[i].insert(var.to_string());
                    }
                }
            }
        }
    }

    let mut units_used: BTreeMap<String, Unit> = BTreeMap::new();
    // the Enumeration types the connectors name, with their items (ssd:Enumerations)
    let mut enums_used: BTreeMap<String, Vec<(i32, String)>> = BTreeMap::new();
    let mut ssd = String::new();
    let name = escape(
        Path::new(&sys.file)
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("system"),
    );
    let _ = writeln!(ssd, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        ssd,
        r#"<ssd:SystemStructureDescription xmlns:ssd="{NS_SSD}" xmlns:ssc="{NS_SSC}" xmlns:ssv="{NS_SSV}" xmlns:osp="{NS_OSP}" xmlns:oms="{NS_OMS}" xmlns:rfm="{NS_MASTER}" version="1.0" name="{name}" generationTool="master {}">"#,
        env!("CARGO_PKG_VERSION")
    );
    let _ = writeln!(ssd, r#"  <ssd:System name="{name}">"#);
    let _ = writeln!(ssd, "    <ssd:Elements>");
    let mut ssv_members: Vec<(String, String)> = Vec::new();
    let mut n_params = 0;
    for (i, inst) in d.instances.iter().enumerate() {
        let md = models[i];
        let _ = writeln!(
            ssd,
            r#"      <ssd:Component name="{}" type="application/x-fmu-sharedlibrary" source="{}" implementation="CoSimulation">"#,
            escape(&inst.name),
            escape(&resource_of[i])
        );
        if !connector_names[i].is_empty() {
            let _ = writeln!(ssd, "        <ssd:Connectors>");
            for v in md
                .variables
                .iter()
                .filter(|v| connector_names[i].contains(&v.name))
            {
                let kind = if v.causality == Causality::Input {
                    "input"
                } else {
                    "output"
                };
                let ty = match v.var_type {
                    VarType::Real => match v
                        .unit
                        .as_ref()
                        .and_then(|u| extras[i].units.get(u).map(|d| (u, d)))
                    {
                        Some((u, def)) => {
                            note_unit(&mut units_used, u, def, &inst.name)?;
                            format!(r#"<ssc:Real unit="{}"/>"#, escape(u))
                        }
                        None => "<ssc:Real/>".to_string(),
                    },
                    VarType::Integer => "<ssc:Integer/>".to_string(),
                    VarType::Boolean => "<ssc:Boolean/>".to_string(),
                    VarType::String => "<ssc:String/>".to_string(),
                    VarType::Enumeration => match extras[i].enum_types.get(&v.name) {
                        Some(t) => {
                            let mut items: Vec<(i32, String)> = md
                                .enum_items(v)
                                .iter()
                                .map(|it| (it.value, it.name.clone()))
                                .collect();
                            items.sort();
                            // one type per name in an SSD: a type of the same name with other
                            // items (another FMU's) is named after its instance
                            let name = match enums_used.get(t) {
                                Some(known) if *known != items => format!("{}.{t}", inst.name),
                                _ => t.clone(),
                            };
                            enums_used.entry(name.clone()).or_insert(items);
                            format!(r#"<ssc:Enumeration name="{}"/>"#, escape(&name))
                        }
                        None => {
                            return Err(SspError::Export(format!(
                                "'{}.{}' is an Enumeration without a declaredType",
                                inst.name, v.name
                            )))
                        }
                    },
                };
                let _ = writeln!(
                    ssd,
                    r#"          <ssd:Connector name="{}" kind="{kind}">{ty}</ssd:Connector>"#,
                    escape(&v.name)
                );
            }
            let _ = writeln!(ssd, "        </ssd:Connectors>");
        }
        if !inst.parameters.is_empty() {
            let member = unique_member(&mut used, &inst.name, "ssv");
            let text = parameter_set(md, &extras[i], &inst.name, &inst.parameters)?;
            n_params += inst.parameters.len();
            let _ = writeln!(ssd, "        <ssd:ParameterBindings>");
            let _ = writeln!(
                ssd,
                r#"          <ssd:ParameterBinding source="{}"/>"#,
                escape(&member)
            );
            let _ = writeln!(ssd, "        </ssd:ParameterBindings>");
            ssv_members.push((member, text));
        }
        if inst.step_multiple > 1 {
            let _ = writeln!(
                ssd,
                r#"        <ssd:Annotations><ssc:Annotation type="com.opensimulationplatform"><osp:StepSizeHint value="{}"/></ssc:Annotation></ssd:Annotations>"#,
                real(d.step * f64::from(inst.step_multiple))
            );
        }
        let _ = writeln!(ssd, "      </ssd:Component>");
    }
    let _ = writeln!(ssd, "    </ssd:Elements>");
    if !d.connections.is_empty() {
        let _ = writeln!(ssd, "    <ssd:Connections>");
        for c in &d.connections {
            let (Some((fi, fv)), Some((ti, tv))) = (split_ref(&c.from), split_ref(&c.to)) else {
                return Err(SspError::Export(format!(
                    "connection '{}' -> '{}' is not of the form instance.variable",
                    c.from, c.to
                )));
            };
            let _ = writeln!(
                ssd,
                r#"      <ssd:Connection startElement="{}" startConnector="{}" endElement="{}" endConnector="{}"{}/>"#,
                escape(fi),
                escape(fv),
                escape(ti),
                escape(tv),
                // SSP converts between connectors of different units unless told not to
                if c.convert_units {
                    ""
                } else {
                    r#" suppressUnitConversion="true""#
                }
            );
        }
        let _ = writeln!(ssd, "    </ssd:Connections>");
    }
    let _ = writeln!(
        ssd,
        r#"    <ssd:Annotations><ssc:Annotation type="org.openmodelica"><oms:Annotations><oms:SimulationInformation><oms:FixedStepMaster description="oms-ma" stepSize="{}"/></oms:SimulationInformation></oms:Annotations></ssc:Annotation>"#,
        real(d.step)
    );
    // what SSP has no place for, in an annotation of the master's that other tools skip:
    // `master run` on the archive couples as the description said
    let algorithm = match d.algorithm {
        crate::coupling::Algorithm::Jacobi => "jacobi",
        crate::coupling::Algorithm::GaussSeidel => "gauss-seidel",
    };
    let _ = write!(
        ssd,
        r#"      <ssc:Annotation type="{}"><rfm:Coupling algorithm="{algorithm}" initSweeps="{}" maxStepHalvings="{}">"#,
        super::ssd::MASTER_ANNOTATION,
        d.init_sweeps,
        d.max_step_halvings
    );
    for name in d.order.iter().flatten() {
        let _ = write!(ssd, r#"<rfm:Instance name="{}"/>"#, escape(name));
    }
    let _ = writeln!(ssd, "</rfm:Coupling></ssc:Annotation></ssd:Annotations>");
    let _ = writeln!(ssd, "  </ssd:System>");
    if !enums_used.is_empty() {
        let _ = writeln!(ssd, "  <ssd:Enumerations>");
        for (name, items) in &enums_used {
            let _ = write!(ssd, r#"    <ssc:Enumeration name="{}">"#, escape(name));
            for (value, item) in items {
                let _ = write!(
                    ssd,
                    r#"<ssc:Item name="{}" value="{value}"/>"#,
                    escape(item)
                );
            }
            let _ = writeln!(ssd, "</ssc:Enumeration>");
        }
        let _ = writeln!(ssd, "  </ssd:Enumerations>");
    }
    if !units_used.is_empty() {
        let _ = writeln!(ssd, "  <ssd:Units>");
        for (n, u) in &units_used {
            let _ = writeln!(ssd, "    {}", unit_xml(n, u));
        }
        let _ = writeln!(ssd, "  </ssd:Units>");
    }
    let _ = writeln!(
        ssd,
        r#"  <ssd:DefaultExperiment startTime="{}" stopTime="{}">"#,
        real(d.start_time),
        real(d.stop_time)
    );
    let _ = writeln!(
        ssd,
        r#"    <ssd:Annotations><ssc:Annotation type="com.opensimulationplatform"><osp:Algorithm><osp:FixedStepAlgorithm baseStepSize="{}"/></osp:Algorithm></ssc:Annotation></ssd:Annotations>"#,
        real(d.step)
    );
    let _ = writeln!(ssd, "  </ssd:DefaultExperiment>");
    let _ = writeln!(ssd, "</ssd:SystemStructureDescription>");

    // every text written, checked once where it is whole (names of the system, its file,
    // instances, units): a String parameter's value was refused by name already
    writable("SystemStructure.ssd", &ssd)?;
    for (member, text) in &ssv_members {
        writable(member, text)?;
    }
    // the archive, built in memory and written atomically
    let io = |e: std::io::Error| SspError::Export(e.to_string());
    let zerr = |e: zip::result::ZipError| SspError::Export(e.to_string());
    let deflated = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .last_modified_time(zip::DateTime::default());
    // FMUs are zips already
    let stored = deflated.compression_method(zip::CompressionMethod::Stored);
    let mut z = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let mut files = Vec::new();
    z.start_file("SystemStructure.ssd", deflated)
        .map_err(zerr)?;
    z.write_all(ssd.as_bytes()).map_err(io)?;
    files.push("SystemStructure.ssd".to_string());
    for (member, path) in &fmu_members {
        let bytes = std::fs::read(path)
            .map_err(|e| SspError::Export(format!("{}: {e}", path.display())))?;
        z.start_file(member.as_str(), stored).map_err(zerr)?;
        z.write_all(&bytes).map_err(io)?;
        files.push(member.clone());
    }
    for (member, text) in &ssv_members {
        z.start_file(member.as_str(), deflated).map_err(zerr)?;
        z.write_all(text.as_bytes()).map_err(io)?;
        files.push(member.clone());
    }
    let bytes = z.finish().map_err(zerr)?.into_inner();
    crate::output::write_bytes_atomic(out, &bytes)?;
    Ok(ExportSummary {
        files,
        components: d.instances.len(),
        connections: d.connections.len(),
        parameters: n_params,
    })
}

/// Refuses a text that XML 1.0 cannot hold (see [`fmu_binary::forbidden_in_xml`]): the
/// archive would hold a file that no SSP importer reads.
fn writable(what: &str, text: &str) -> Result<(), SspError> {
    match fmu_binary::forbidden_in_xml(text) {
        None => Ok(()),
        Some(c) => Err(SspError::Export(format!(
            "{what} holds the character U+{:04X}, which an SSP file (XML 1.0) cannot hold",
            u32::from(c)
        ))),
    }
}

fn note_unit(
    used: &mut BTreeMap<String, Unit>,
    name: &str,
    def: &Unit,
    instance: &str,
) -> Result<(), SspError> {
    match used.get(name) {
        Some(u) if u != def => Err(SspError::Export(format!(
            "unit '{name}' of instance '{instance}' is defined differently by another FMU of the system"
        ))),
        Some(_) => Ok(()),
        None => {
            used.insert(name.to_string(), def.clone());
            Ok(())
        }
    }
}

fn unit_xml(name: &str, u: &Unit) -> String {
    let mut s = format!(r#"<ssc:Unit name="{}"><ssc:BaseUnit"#, escape(name));
    for (e, k) in u.exponents.iter().zip(BASE_UNITS) {
        if *e != 0 {
            let _ = write!(s, r#" {k}="{e}""#);
        }
    }
    if u.factor != 1.0 {
        let _ = write!(s, r#" factor="{}""#, real(u.factor));
    }
    if u.offset != 0.0 {
        let _ = write!(s, r#" offset="{}""#, real(u.offset));
    }
    s.push_str("/></ssc:Unit>");
    s
}

/// The .ssv text of one instance's parameters, typed by the FMU's variables.
fn parameter_set(
    md: &ModelDescription,
    extras: &FmuExtras,
    instance: &str,
    params: &BTreeMap<String, Json>,
) -> Result<String, SspError> {
    let mut s = String::new();
    let mut units: BTreeMap<String, Unit> = BTreeMap::new();
    let _ = writeln!(s, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        s,
        r#"<ssv:ParameterSet xmlns:ssv="{NS_SSV}" xmlns:ssc="{NS_SSC}" version="1.0" name="{PARAMETER_SET_NAME}">"#
    );
    let _ = writeln!(s, "  <ssv:Parameters>");
    for (name, value) in params {
        let bad = || {
            SspError::Export(format!(
                "{instance}.{name}: the value {value} does not fit the variable"
            ))
        };
        let (_, v) = md.variable(name).ok_or_else(bad)?;
        let typed = match (v.var_type, value) {
            (VarType::Real, Json::Number(n)) => {
                let x = n.as_f64().ok_or_else(bad)?;
                match v
                    .unit
                    .as_ref()
                    .and_then(|u| extras.units.get(u).map(|d| (u, d)))
                {
                    Some((u, def)) => {
                        units.insert(u.clone(), def.clone());
                        format!(r#"<ssv:Real value="{}" unit="{}"/>"#, real(x), escape(u))
                    }
                    None => format!(r#"<ssv:Real value="{}"/>"#, real(x)),
                }
            }
            (VarType::Integer | VarType::Enumeration, Json::Number(n)) => {
                format!(r#"<ssv:Integer value="{}"/>"#, n.as_i64().ok_or_else(bad)?)
            }
            // an item name as its value: libcosim aborts on ssv:Enumeration and fmpy reads
            // every Enumeration value as an integer
            (VarType::Enumeration, Json::String(item)) => {
                let value = md
                    .enum_items(v)
                    .iter()
                    .find(|i| &i.name == item)
                    .ok_or_else(bad)?
                    .value;
                format!(r#"<ssv:Integer value="{value}"/>"#)
            }
            (VarType::Boolean, Json::Bool(b)) => format!(r#"<ssv:Boolean value="{b}"/>"#),
            (VarType::String, Json::String(t)) => {
                writable(&format!("the value of {instance}.{name}"), t)?;
                format!(r#"<ssv:String value="{}"/>"#, escape(t))
            }
            _ => return Err(bad()),
        };
        let _ = writeln!(
            s,
            r#"    <ssv:Parameter name="{}">{typed}</ssv:Parameter>"#,
            escape(name)
        );
    }
    let _ = writeln!(s, "  </ssv:Parameters>");
    if !units.is_empty() {
        let _ = writeln!(s, "  <ssv:Units>");
        for (n, u) in &units {
            let _ = writeln!(s, "    {}", unit_xml(n, u));
        }
        let _ = writeln!(s, "  </ssv:Units>");
    }
    let _ = writeln!(s, "</ssv:ParameterSet>");
    Ok(s)
}

/// `resources/<stem>.<extension>` with the stem made safe from `name` ([`safe_member_stem`]),
/// `_2`, `_3`, ... appended against a member already in `used`; recorded in `used`.
fn unique_member(used: &mut BTreeSet<String>, name: &str, extension: &str) -> String {
    let stem = safe_member_stem(name);
    let mut member = format!("resources/{stem}.{extension}");
    let mut k = 2;
    while used.contains(&member) {
        member = format!("resources/{stem}_{k}.{extension}");
        k += 1;
    }
    used.insert(member.clone());
    member
}

/// A name for an archive member made from `name`: letters, digits, `_` and `-` kept, anything
/// else `_`, at most 64 characters ("component" when nothing is left). An SSD refers to members
/// by URI: a space, `%`, `#` or `?` in a member name would have to be percent-encoded, a `/`
/// would make a folder, and a long name is truncated by some unpacking hosts.
fn safe_member_stem(name: &str) -> String {
    let stem: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .take(64)
        .collect();
    if stem.trim_matches('_').is_empty() {
        "component".to_string()
    } else {
        stem
    }
}
