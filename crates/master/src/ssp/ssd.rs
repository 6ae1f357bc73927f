//! The System Structure Description (SystemStructure.ssd, SSP 1.0 and 2.0) read into plain
//! structs. What the master cannot run is refused here, with the file and line.

use roxmltree::Node;

use super::ssv::{self, Mapping, ParameterSet};
use super::xml::{self, check_single_children, content, elements, is, Ctx, NS_SSC, NS_SSD};
use super::SspError;
use crate::show;

/// SSP's connector types as far as FMI 2.0 has them.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum ConnectorType {
    Real { unit: Option<String> },
    Integer,
    Boolean,
    String,
    Enumeration,
}

#[derive(Debug, Clone)]
pub(super) struct Connector {
    pub name: String,
    pub kind: String,
    pub ty: Option<ConnectorType>,
    pub line: usize,
}

#[derive(Debug, Clone)]
pub(super) struct Connection {
    pub start_element: Option<String>,
    pub start_connector: String,
    pub end_element: Option<String>,
    pub end_connector: String,
    /// `suppressUnitConversion="true"`: values pass unconverted between connectors of
    /// different units (SSP 1.0, 5.3.2); otherwise such a connection needs a conversion.
    pub suppress_unit_conversion: bool,
    pub line: usize,
}

/// Where a binding's parameter set comes from.
#[derive(Debug, Clone)]
pub(super) enum BindingValues {
    /// `source`: a .ssv file, relative to the SSD.
    File(String),
    Inline(ParameterSet),
}

#[derive(Debug, Clone)]
pub(super) enum BindingMapping {
    File(String),
    Inline(Mapping),
}

#[derive(Debug, Clone)]
pub(super) struct Binding {
    pub values: BindingValues,
    pub mapping: Option<BindingMapping>,
    pub prefix: String,
    pub line: usize,
}

#[derive(Debug, Clone)]
pub(super) struct Component {
    pub name: String,
    pub source: String,
    pub connectors: Vec<Connector>,
    pub bindings: Vec<Binding>,
    /// libcosim's `osp:StepSizeHint` [s].
    pub step_size_hint_s: Option<f64>,
    pub line: usize,
}

#[derive(Debug, Clone)]
pub(super) struct System {
    pub name: String,
    pub connectors: Vec<Connector>,
    pub components: Vec<Component>,
    pub connections: Vec<Connection>,
    pub bindings: Vec<Binding>,
    /// OMSimulator's `oms:FixedStepMaster stepSize` [s].
    pub step_s: Option<f64>,
    /// The master's own coupling settings, if an annotation of [`MASTER_ANNOTATION`] holds
    /// them (written by `master export-ssp`).
    pub coupling: CouplingSettings,
}

/// The `type` of the annotation in which `master export-ssp` keeps what SSP has no place
/// for: the coupling algorithm, the Gauss-Seidel order, the initial sweeps and the step
/// halvings (other tools skip annotations of types they do not know, SSP 1.0 1.4.4).
pub(super) const MASTER_ANNOTATION: &str = "org.rail-fmu.master";

/// The settings an annotation of [`MASTER_ANNOTATION`] holds (each absent when not given).
#[derive(Debug, Clone, Default, PartialEq)]
pub(super) struct CouplingSettings {
    pub algorithm: Option<crate::coupling::Algorithm>,
    pub order: Option<Vec<String>>,
    pub init_sweeps: Option<usize>,
    pub max_step_halvings: Option<u32>,
}

/// `<rfm:Coupling algorithm=".." initSweeps=".." maxStepHalvings=".."><rfm:Instance
/// name=".."/>...</rfm:Coupling>` inside an annotation of [`MASTER_ANNOTATION`].
fn parse_coupling(ctx: Ctx, a: Node) -> Result<CouplingSettings, SspError> {
    let mut out = CouplingSettings::default();
    let Some(c) = find_local(a, "Coupling").next() else {
        return Ok(out);
    };
    out.algorithm = match c.attribute("algorithm") {
        None => None,
        Some("jacobi") => Some(crate::coupling::Algorithm::Jacobi),
        Some("gauss-seidel") => Some(crate::coupling::Algorithm::GaussSeidel),
        Some(other) => {
            return Err(ctx.err(
                c,
                format!(
                    "coupling algorithm '{}': expected 'jacobi' or 'gauss-seidel'",
                    show::text(other)
                ),
            ))
        }
    };
    let whole = |attr: &str| -> Result<Option<u64>, SspError> {
        match c.attribute(attr) {
            None => Ok(None),
            Some(v) => v.trim().parse::<u64>().map(Some).map_err(|_| {
                ctx.err(
                    c,
                    format!("{attr} = '{}': not a whole number >= 0", show::text(v)),
                )
            }),
        }
    };
    out.init_sweeps = whole("initSweeps")?.map(|n| n as usize);
    out.max_step_halvings = whole("maxStepHalvings")?.map(|n| n.min(u64::from(u32::MAX)) as u32);
    let order: Vec<String> = find_local(c, "Instance")
        .map(|i| ctx.req(i, "name").map(str::to_string))
        .collect::<Result<_, _>>()?;
    out.order = (!order.is_empty()).then_some(order);
    Ok(out)
}

/// `ssc:Unit`: SI exponents (kg, m, s, A, K, mol, cd, rad), factor, offset.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct UnitDef {
    pub name: String,
    pub exponents: [i64; 8],
    pub factor: f64,
    pub offset: f64,
}

pub(super) use crate::model_description::BASE_UNIT_NAMES as BASE_UNITS;

#[derive(Debug, Clone)]
pub(super) struct Ssd {
    pub version: String,
    pub system: System,
    pub units: Vec<UnitDef>,
    pub start_time_s: Option<f64>,
    pub stop_time_s: Option<f64>,
    /// libcosim's `osp:FixedStepAlgorithm baseStepSize` [s].
    pub base_step_s: Option<f64>,
}

/// Parses the text of an .ssd file (`file` names it in messages).
pub(super) fn parse(file: &str, text: &str) -> Result<Ssd, SspError> {
    let (doc, lines) = xml::parse(file, text)?;
    let ctx = Ctx {
        file,
        lines: &lines,
    };
    let root = doc.root_element();
    if !is(root, NS_SSD, "SystemStructureDescription") {
        return Err(ctx.err(
            root,
            format!(
                "the root element is <{}> (namespace {}), not <ssd:SystemStructureDescription> of {NS_SSD}",
                root.tag_name().name(),
                root.tag_name().namespace().unwrap_or("none")
            ),
        ));
    }
    let version = ctx.req(root, "version")?.trim().to_string();
    if !(version == "2.0" || version == "1.0" || version.starts_with("1.0-")) {
        return Err(ctx.unsupported(
            root,
            format!(
                "SSP version '{}' (1.0 and 2.0 are read)",
                show::text(&version)
            ),
        ));
    }
    let mut system = None;
    let mut units = Vec::new();
    let (mut start, mut stop, mut base_step) = (None, None, None);
    check_single_children(ctx, root)?;
    for c in content(root) {
        match c.tag_name().name() {
            "System" if is(c, NS_SSD, "System") => system = Some(parse_system(ctx, c)?),
            "Units" if is(c, NS_SSD, "Units") => units = parse_units(ctx, c)?,
            // Enumeration item names are resolved by the FMUs' own type definitions.
            "Enumerations" if is(c, NS_SSD, "Enumerations") => {}
            "DefaultExperiment" if is(c, NS_SSD, "DefaultExperiment") => {
                start = ctx.f64(c, "startTime")?;
                stop = ctx.f64(c, "stopTime")?;
                for a in annotations(c) {
                    if a.attribute("type") == Some("com.opensimulationplatform") {
                        base_step = osp_algorithm(ctx, a)?.or(base_step);
                    }
                }
            }
            "Annotations" if c.tag_name().namespace() == Some(NS_SSD) => {}
            _ => return Err(ctx.unexpected(c)),
        }
    }
    let system = system.ok_or_else(|| ctx.err(root, "no <ssd:System>"))?;
    Ok(Ssd {
        version,
        system,
        units,
        start_time_s: start,
        stop_time_s: stop,
        base_step_s: base_step,
    })
}

/// The `ssc:Annotation` elements of an element's `ssd:Annotations`.
fn annotations<'a, 'i>(n: Node<'a, 'i>) -> impl Iterator<Item = Node<'a, 'i>> {
    elements(n)
        .filter(|c| is(*c, NS_SSD, "Annotations"))
        .flat_map(elements)
        .filter(|a| is(*a, NS_SSC, "Annotation"))
}

/// Elements below an annotation with local name `name`, any namespace (tools bind their
/// prefixes to various URIs).
fn find_local<'a, 'i>(n: Node<'a, 'i>, name: &'static str) -> impl Iterator<Item = Node<'a, 'i>> {
    n.descendants()
        .filter(move |d| d.is_element() && d.tag_name().name() == name)
}

/// libcosim: `<osp:Algorithm><osp:FixedStepAlgorithm baseStepSize=".."/></osp:Algorithm>`.
fn osp_algorithm(ctx: Ctx, a: Node) -> Result<Option<f64>, SspError> {
    let mut step = None;
    for alg in find_local(a, "Algorithm") {
        for k in elements(alg) {
            if k.tag_name().name() == "FixedStepAlgorithm" {
                step = ctx.f64(k, "baseStepSize")?;
            } else {
                return Err(ctx.unsupported(
                    k,
                    format!("co-simulation algorithm '{}'", k.tag_name().name()),
                ));
            }
        }
    }
    Ok(step)
}

pub(super) fn parse_units(ctx: Ctx, n: Node) -> Result<Vec<UnitDef>, SspError> {
    let mut out = Vec::new();
    for u in elements(n) {
        if !is(u, NS_SSC, "Unit") {
            return Err(ctx.unexpected(u));
        }
        let name = ctx.req(u, "name")?.to_string();
        let Some(b) = elements(u).find(|b| is(*b, NS_SSC, "BaseUnit")) else {
            return Err(ctx.err(u, format!("unit '{name}' has no <ssc:BaseUnit>")));
        };
        let mut exponents = [0; 8];
        for (e, key) in exponents.iter_mut().zip(BASE_UNITS) {
            *e = ctx.i64(b, key)?.unwrap_or(0);
        }
        out.push(UnitDef {
            name,
            exponents,
            factor: ctx.f64(b, "factor")?.unwrap_or(1.0),
            offset: ctx.f64(b, "offset")?.unwrap_or(0.0),
        });
    }
    Ok(out)
}

fn parse_system(ctx: Ctx, n: Node) -> Result<System, SspError> {
    let mut s = System {
        name: ctx.req(n, "name")?.to_string(),
        connectors: Vec::new(),
        components: Vec::new(),
        connections: Vec::new(),
        bindings: Vec::new(),
        step_s: None,
        coupling: CouplingSettings::default(),
    };
    check_single_children(ctx, n)?;
    for c in content(n) {
        if c.tag_name().namespace() != Some(NS_SSD) {
            return Err(ctx.unexpected(c));
        }
        match c.tag_name().name() {
            "Connectors" => s.connectors = parse_connectors(ctx, c)?,
            "ParameterBindings" => s.bindings = parse_bindings(ctx, c)?,
            "Elements" => {
                for e in elements(c) {
                    match e.tag_name().name() {
                        "Component" if is(e, NS_SSD, "Component") => {
                            s.components.push(parse_component(ctx, e)?)
                        }
                        "System" if is(e, NS_SSD, "System") => {
                            return Err(ctx.unsupported(
                                e,
                                format!(
                                    "nested system '{}' (the master runs one flat system of FMU components)",
                                    e.attribute("name").unwrap_or("")
                                ),
                            ))
                        }
                        "SignalDictionaryReference" => {
                            return Err(ctx.unsupported(e, "signal dictionary references"))
                        }
                        _ => return Err(ctx.unexpected(e)),
                    }
                }
            }
            "Connections" => {
                for e in elements(c) {
                    if !is(e, NS_SSD, "Connection") {
                        return Err(ctx.unexpected(e));
                    }
                    s.connections.push(parse_connection(ctx, e)?);
                }
            }
            "SignalDictionaries" => {
                if elements(c).next().is_some() {
                    return Err(ctx.unsupported(c, "signal dictionaries"));
                }
            }
            "Annotations" => {
                for a in annotations(n) {
                    if a.attribute("type") == Some(MASTER_ANNOTATION) {
                        s.coupling = parse_coupling(ctx, a)?;
                    }
                    if a.attribute("type") == Some("org.openmodelica") {
                        for m in find_local(a, "FixedStepMaster") {
                            s.step_s = ctx.f64(m, "stepSize")?.or(s.step_s);
                        }
                        if let Some(v) = find_local(a, "VariableStepMaster").next() {
                            return Err(ctx.unsupported(
                                v,
                                "OMSimulator's variable-step master (the master steps at a fixed communication step)",
                            ));
                        }
                    }
                }
            }
            // graphics do not change the simulation
            "ElementGeometry" | "SystemGeometry" | "GraphicalElements" => {}
            _ => return Err(ctx.unexpected(c)),
        }
    }
    Ok(s)
}

fn parse_component(ctx: Ctx, n: Node) -> Result<Component, SspError> {
    let name = ctx.req(n, "name")?.to_string();
    let ty = n
        .attribute("type")
        .unwrap_or("application/x-fmu-sharedlibrary");
    if ty != "application/x-fmu-sharedlibrary" {
        return Err(ctx.unsupported(
            n,
            format!(
                "component '{name}' of type '{ty}' (only FMUs, application/x-fmu-sharedlibrary)"
            ),
        ));
    }
    match n.attribute("implementation").unwrap_or("any") {
        "any" | "CoSimulation" => {}
        other => {
            return Err(ctx.unsupported(
                n,
                format!("component '{name}' with implementation '{other}' (co-simulation only)"),
            ))
        }
    }
    let source = n
        .attribute("source")
        .ok_or_else(|| ctx.unsupported(n, format!("component '{name}' without a source")))?
        .to_string();
    let mut comp = Component {
        name,
        source,
        connectors: Vec::new(),
        bindings: Vec::new(),
        step_size_hint_s: None,
        line: ctx.line(n),
    };
    check_single_children(ctx, n)?;
    for c in content(n) {
        if c.tag_name().namespace() != Some(NS_SSD) {
            return Err(ctx.unexpected(c));
        }
        match c.tag_name().name() {
            "Connectors" => comp.connectors = parse_connectors(ctx, c)?,
            "ParameterBindings" => comp.bindings = parse_bindings(ctx, c)?,
            "Annotations" => {
                for a in annotations(n) {
                    if a.attribute("type") == Some("com.opensimulationplatform") {
                        for h in find_local(a, "StepSizeHint") {
                            comp.step_size_hint_s = ctx.f64(h, "value")?;
                        }
                    }
                }
            }
            "ElementGeometry" => {}
            _ => return Err(ctx.unexpected(c)),
        }
    }
    Ok(comp)
}

fn parse_connectors(ctx: Ctx, n: Node) -> Result<Vec<Connector>, SspError> {
    let mut out = Vec::new();
    let mut seen: std::collections::HashMap<String, usize> = std::collections::HashMap::new();
    for c in elements(n) {
        if !is(c, NS_SSD, "Connector") {
            return Err(ctx.unexpected(c));
        }
        let name = ctx.req(c, "name")?.to_string();
        let kind = ctx.req(c, "kind")?.to_string();
        // the kinds the schemas allow: SSD 1.0 5.3.4, and those SSP 2.0 adds
        const KINDS: [&str; 9] = [
            "input",
            "output",
            "inout",
            "parameter",
            "calculatedParameter",
            "structuralParameter",
            "constant",
            "local",
            "unspecified",
        ];
        if !KINDS.contains(&kind.as_str()) {
            return Err(ctx.err(
                c,
                format!(
                    "connector '{}' has kind '{}': one of {}",
                    crate::show::text(&name),
                    crate::show::text(&kind),
                    KINDS.join(", ")
                ),
            ));
        }
        if let Some(first) = seen.insert(name.clone(), ctx.line(c)) {
            return Err(ctx.err(
                c,
                format!(
                    "connector '{}' is declared twice (first at line {first})",
                    crate::show::text(&name),
                ),
            ));
        }
        let mut ty = None;
        check_single_children(ctx, c)?;
        for t in content(c) {
            // SSP 1.0 has no arrays; 2.0 gives their size as <ssc:Dimension>
            if t.tag_name().name() == "Dimension" {
                return Err(ctx.unsupported(t, format!("array connector '{name}'")));
            }
            if t.tag_name().namespace() == Some(NS_SSC) {
                // one type: a second (<ssc:Integer/><ssc:Real/>) replaced the first
                if ty.replace(connector_type(ctx, t, &name)?).is_some() {
                    return Err(ctx.err(
                        t,
                        format!(
                            "connector '{}' has more than one type",
                            crate::show::text(&name)
                        ),
                    ));
                }
                continue;
            }
            match t.tag_name().name() {
                "ConnectorGeometry" | "Annotations" if t.tag_name().namespace() == Some(NS_SSD) => {
                }
                _ => return Err(ctx.unexpected(t)),
            }
        }
        out.push(Connector {
            name,
            kind,
            ty,
            line: ctx.line(c),
        });
    }
    Ok(out)
}

fn connector_type(ctx: Ctx, t: Node, name: &str) -> Result<ConnectorType, SspError> {
    Ok(match t.tag_name().name() {
        "Real" | "Float64" => ConnectorType::Real {
            unit: t.attribute("unit").map(str::to_string),
        },
        "Integer" | "Int32" => ConnectorType::Integer,
        "Boolean" => ConnectorType::Boolean,
        "String" => ConnectorType::String,
        "Enumeration" => ConnectorType::Enumeration,
        other => {
            return Err(ctx.unsupported(
                t,
                format!("connector '{name}' of type {other} (FMI 2.0 has Real, Integer, Boolean, String, Enumeration)"),
            ))
        }
    })
}

fn parse_connection(ctx: Ctx, e: Node) -> Result<Connection, SspError> {
    for attr in ["startIndices", "endIndices"] {
        if e.attribute(attr).is_some() {
            return Err(ctx.unsupported(e, format!("connection attribute '{attr}' (arrays)")));
        }
    }
    check_single_children(ctx, e)?;
    for t in content(e) {
        match t.tag_name().name() {
            "LinearTransformation" if is(t, NS_SSC, "LinearTransformation") => {
                let factor = ctx.f64(t, "factor")?.unwrap_or(1.0);
                let offset = ctx.f64(t, "offset")?.unwrap_or(0.0);
                if factor != 1.0 || offset != 0.0 {
                    return Err(ctx.unsupported(
                        t,
                        format!(
                            "connection transformation (factor {}, offset {}): the master \
                             copies values unchanged",
                            show::num(factor),
                            show::num(offset)
                        ),
                    ));
                }
            }
            "BooleanMappingTransformation"
            | "IntegerMappingTransformation"
            | "EnumerationMappingTransformation"
                if t.tag_name().namespace() == Some(NS_SSC) =>
            {
                return Err(ctx.unsupported(
                    t,
                    format!("connection transformation <ssc:{}>", t.tag_name().name()),
                ))
            }
            "ConnectionGeometry" | "Annotations" if t.tag_name().namespace() == Some(NS_SSD) => {}
            _ => return Err(ctx.unexpected(t)),
        }
    }
    Ok(Connection {
        start_element: e.attribute("startElement").map(str::to_string),
        start_connector: ctx.req(e, "startConnector")?.to_string(),
        end_element: e.attribute("endElement").map(str::to_string),
        end_connector: ctx.req(e, "endConnector")?.to_string(),
        // xs:boolean
        suppress_unit_conversion: matches!(
            e.attribute("suppressUnitConversion").map(str::trim),
            Some("true" | "1")
        ),
        line: ctx.line(e),
    })
}

fn check_source_base(ctx: Ctx, n: Node) -> Result<(), SspError> {
    match n.attribute("sourceBase").unwrap_or("SSD") {
        "SSD" => Ok(()),
        other => Err(ctx.unsupported(
            n,
            format!(
                "sourceBase=\"{}\" (sources relative to the SSD only)",
                show::text(other)
            ),
        )),
    }
}

fn parse_bindings(ctx: Ctx, n: Node) -> Result<Vec<Binding>, SspError> {
    let mut out = Vec::new();
    for b in elements(n) {
        if !is(b, NS_SSD, "ParameterBinding") {
            return Err(ctx.unexpected(b));
        }
        let ty = b
            .attribute("type")
            .unwrap_or("application/x-ssp-parameter-set");
        if ty != "application/x-ssp-parameter-set" {
            return Err(
                ctx.unsupported(b, format!("parameter binding of type '{}'", show::text(ty)))
            );
        }
        check_source_base(ctx, b)?;
        let mut inline = None;
        let mut mapping = None;
        check_single_children(ctx, b)?;
        for c in content(b) {
            match c.tag_name().name() {
                "ParameterValues" if is(c, NS_SSD, "ParameterValues") => {
                    let mut sets = elements(c);
                    match (sets.next(), sets.next()) {
                        (Some(set), None) => inline = Some(ssv::parse_set(ctx, set)?),
                        _ => {
                            return Err(ctx.err(
                                c,
                                "<ssd:ParameterValues> must hold exactly one <ssv:ParameterSet>",
                            ))
                        }
                    }
                }
                "ParameterMapping" if is(c, NS_SSD, "ParameterMapping") => {
                    let mty = c
                        .attribute("type")
                        .unwrap_or("application/x-ssp-parameter-mapping");
                    if mty != "application/x-ssp-parameter-mapping" {
                        return Err(ctx.unsupported(
                            c,
                            format!("parameter mapping of type '{}'", show::text(mty)),
                        ));
                    }
                    check_source_base(ctx, c)?;
                    mapping = Some(match c.attribute("source") {
                        Some(src) => BindingMapping::File(src.to_string()),
                        None => {
                            let mut maps = elements(c);
                            match (maps.next(), maps.next()) {
                                (Some(m), None) => BindingMapping::Inline(ssv::parse_mapping(ctx, m)?),
                                _ => {
                                    return Err(ctx.err(
                                        c,
                                        "an inline <ssd:ParameterMapping> must hold exactly one <ssm:ParameterMapping>",
                                    ))
                                }
                            }
                        }
                    });
                }
                "Annotations" if c.tag_name().namespace() == Some(NS_SSD) => {}
                _ => return Err(ctx.unexpected(c)),
            }
        }
        // SSP 1.0 5.3.5: with inline values the source "MUST be empty": an empty attribute is
        // as none (some tools write source="")
        let source = b.attribute("source").filter(|s| !s.is_empty());
        let values = match (source, inline) {
            (Some(src), None) => BindingValues::File(src.to_string()),
            (None, Some(set)) => BindingValues::Inline(set),
            (Some(_), Some(_)) => {
                return Err(ctx.err(
                    b,
                    "a parameter binding has both a source and inline <ssd:ParameterValues>",
                ))
            }
            (None, None) => {
                return Err(ctx.err(
                    b,
                    "a parameter binding has neither a source nor inline <ssd:ParameterValues>",
                ))
            }
        };
        out.push(Binding {
            values,
            mapping,
            prefix: b.attribute("prefix").unwrap_or("").to_string(),
            line: ctx.line(b),
        });
    }
    Ok(out)
}
