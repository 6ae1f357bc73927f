//! An SSD (with its FMUs, parameter sets and mappings) converted into the master's
//! [`SystemDescription`].

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::Path;

use serde_json::Value as Json;

use super::package::Package;
use super::ssd::{self, Binding, BindingMapping, BindingValues, Component, ConnectorType, Ssd};
use super::ssv::{self, Parameter, ParameterSet, Value};
use super::{ImportOptions, ImportedSsp, SspError};
use crate::coupling::Algorithm;
use crate::fmu::FmuArchive;
use crate::model_description::{Causality, ModelDescription, VarType};
use crate::system::{ConnectionSpec, InstanceSpec, LoadedSystem, SystemDescription};

/// (target name, value, the parameter as written, where it came from).
type Supplied = (String, Value, Parameter, String);

struct Importer {
    /// Where each field of the description comes from ([`LoadedSystem::origins`]).
    origins: BTreeMap<String, String>,
    pkg: Package,
    ssd_label: String,
    models: Vec<ModelDescription>,
    components: Vec<Component>,
}

pub(super) fn import(path: &Path, opts: &ImportOptions) -> Result<ImportedSsp, SspError> {
    let mut pkg = Package::open(path)?;
    let (text, ssd_label) = pkg.read_ssd()?;
    let ssd = ssd::parse(&ssd_label, &text)?;
    let unpacked = match pkg {
        // locked while the system lives, removed as stale by a later master when this one
        // is killed
        Package::Zip { .. } => Some(
            crate::fmu::extract::ExtractionDir::create(&crate::fmu::extract::extraction_root())
                .map_err(|reason| SspError::Read {
                    path: path.to_path_buf(),
                    reason,
                })?,
        ),
        Package::Dir { .. } => None,
    };
    let base_dir = match (&pkg, &unpacked) {
        (_, Some(t)) => t.path().to_path_buf(),
        (Package::Dir { dir, .. }, None) => dir.clone(),
        (Package::Zip { .. }, None) => path.to_path_buf(),
    };

    // components: names, FMUs
    let invalid = |line: usize, message: String| SspError::Invalid {
        file: ssd_label.clone(),
        line: Some(line),
        message,
    };
    let mut instances = Vec::new();
    let mut models = Vec::new();
    let mut fmu_sources = Vec::new();
    for (i, c) in ssd.system.components.iter().enumerate() {
        if c.name.is_empty() || c.name.contains('.') {
            return Err(SspError::Unsupported {
                file: ssd_label.clone(),
                line: Some(c.line),
                what: format!(
                    "component name '{}' (the master's instance names are non-empty and have no '.')",
                    c.name
                ),
            });
        }
        if ssd.system.components[..i].iter().any(|o| o.name == c.name) {
            return Err(invalid(
                c.line,
                format!("component name '{}' is used twice", c.name),
            ));
        }
        let rel = pkg
            .resolve(&c.source)
            .map_err(|r| invalid(c.line, format!("component '{}': source {r}", c.name)))?;
        let dest = base_dir.clone();
        let file = pkg.fmu_file(&rel, &dest, i)?;
        let unpacked = base_dir.join(&file);
        let archive = FmuArchive::open(&unpacked).map_err(|source| SspError::Fmu {
            file: ssd_label.clone(),
            component: c.name.clone(),
            message: source
                .to_string()
                .replace(&unpacked.display().to_string(), &pkg.file_label(&rel)),
            fmu_error: Box::new(source),
        })?;
        models.push(archive.model);
        fmu_sources.push(pkg.source_of(&rel));
        instances.push(InstanceSpec {
            name: c.name.clone(),
            fmu: file,
            parameters: BTreeMap::new(),
            step_multiple: 1,
            logging: false,
        });
    }
    if instances.is_empty() {
        return Err(invalid(1, "the system has no components".into()));
    }
    let origins = ssd
        .system
        .components
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let what = format!("component '{}' ({ssd_label} line {})", c.name, c.line);
            (format!("instances[{i}]"), what)
        })
        .collect();
    let mut imp = Importer {
        origins,
        pkg,
        ssd_label: ssd_label.clone(),
        models,
        components: ssd.system.components.clone(),
    };
    imp.check_connectors(&ssd)?;
    let connections = imp.connections(&ssd)?;
    let values = imp.parameters(&ssd)?;
    for (i, vals) in values.into_iter().enumerate() {
        instances[i].parameters = vals;
    }

    // timing
    let start_time = ssd.start_time_s.unwrap_or(0.0);
    let stop_time = opts.stop_time.or(ssd.stop_time_s).ok_or_else(|| {
        invalid(
            1,
            "no stop time: the SSD's DefaultExperiment has no stopTime (give one with --stop-time)"
                .into(),
        )
    })?;
    if let (None, Some(osp), Some(oms)) = (opts.step, ssd.base_step_s, ssd.system.step_s) {
        if (osp - oms).abs() > 1e-9 * osp.abs().max(oms.abs()) {
            // two tools' annotations that disagree: libcosim's is taken, and the user told
            log::warn!(
                target: "master",
                "{}: the SSD gives two communication steps, libcosim's osp:FixedStepAlgorithm \
                 baseStepSize {osp} s and OMSimulator's oms:FixedStepMaster stepSize {oms} s; \
                 using {osp} s (give --step to choose)",
                imp.ssd_label
            );
        }
    }
    // the step with where it comes from (None: the options)
    let (step, step_from) = [
        (opts.step, None),
        (
            ssd.base_step_s,
            Some("libcosim's osp:FixedStepAlgorithm baseStepSize"),
        ),
        (
            ssd.system.step_s,
            Some("OMSimulator's oms:FixedStepMaster stepSize"),
        ),
    ]
    .into_iter()
    .find_map(|(step, from)| step.map(|h| (h, from)))
    .ok_or_else(|| {
        invalid(
            1,
            "no communication step: neither libcosim's osp:FixedStepAlgorithm baseStepSize nor \
             OMSimulator's oms:FixedStepMaster stepSize is given (give one with --step)"
                .into(),
        )
    })?;
    for (i, c) in imp.components.iter().enumerate() {
        if let Some(h) = c.step_size_hint_s {
            let m = (h / step).round();
            if !(m >= 1.0 && (m * step - h).abs() <= 1e-9 * h.max(step) && m <= u32::MAX as f64) {
                return Err(invalid(
                    c.line,
                    format!(
                        "component '{}': step size hint {h} s is not a whole multiple of the communication step {step} s",
                        c.name
                    ),
                ));
            }
            instances[i].step_multiple = m as u32;
        }
    }
    // where the timing comes from, when the SSD gives it
    for (field, from_ssd) in [
        (
            "start_time",
            ssd.start_time_s
                .map(|_| "the DefaultExperiment's startTime"),
        ),
        (
            "stop_time",
            (opts.stop_time.is_none() && ssd.stop_time_s.is_some())
                .then_some("the DefaultExperiment's stopTime"),
        ),
        ("step", step_from),
    ] {
        if let Some(what) = from_ssd {
            imp.origins
                .insert(field.into(), format!("{what} ({})", imp.ssd_label));
        }
    }
    let coupling = &ssd.system.coupling;
    // the master's own settings where its export kept them (annotation), else what libcosim,
    // Ecos and fmpy do: Jacobi
    let algorithm = opts
        .algorithm
        .or(coupling.algorithm)
        .unwrap_or(Algorithm::Jacobi);
    let order = match &coupling.order {
        Some(order) if algorithm == Algorithm::GaussSeidel => {
            let names: BTreeSet<&str> = instances.iter().map(|i| i.name.as_str()).collect();
            let listed: BTreeSet<&str> = order.iter().map(String::as_str).collect();
            if listed == names && order.len() == names.len() {
                Some(order.clone())
            } else {
                // components renamed, added or removed since the export (by hand, by another
                // tool): the order is derived from the FMUs, as for any other SSP
                log::warn!(
                    target: "master",
                    "{}: the Gauss-Seidel order in the master's annotation ({}) names {} \
                     instead of this SSD's components; the order is derived from the FMUs' \
                     direct feedthrough instead",
                    imp.ssd_label,
                    super::ssd::MASTER_ANNOTATION,
                    order.join(", ")
                );
                None
            }
        }
        _ => None,
    };
    let desc = SystemDescription {
        instances,
        connections,
        start_time,
        stop_time,
        step,
        algorithm,
        order,
        record: None,
        init_sweeps: coupling.init_sweeps.unwrap_or(3),
        max_step_halvings: coupling.max_step_halvings.unwrap_or(0),
    };
    let mut system = LoadedSystem::from_description(desc, &base_dir, &imp.pkg.label());
    system.origins = std::mem::take(&mut imp.origins);
    Ok(ImportedSsp {
        system,
        version: ssd.version,
        files_read: imp.pkg.files_read().to_vec(),
        fmu_sources,
        _unpacked: unpacked,
    })
}

fn var_type_name(t: &ConnectorType) -> &'static str {
    match t {
        ConnectorType::Real { .. } => "Real",
        ConnectorType::Integer => "Integer",
        ConnectorType::Boolean => "Boolean",
        ConnectorType::String => "String",
        ConnectorType::Enumeration => "Enumeration",
    }
}

impl Importer {
    fn invalid(&self, line: usize, message: String) -> SspError {
        SspError::Invalid {
            file: self.ssd_label.clone(),
            line: Some(line),
            message,
        }
    }

    fn component_index(&self, name: &str) -> Option<usize> {
        self.components.iter().position(|c| c.name == name)
    }

    /// Every declared connector of a component is a variable of its FMU, of the same type,
    /// kind and unit.
    fn check_connectors(&self, ssd: &Ssd) -> Result<(), SspError> {
        for (i, c) in ssd.system.components.iter().enumerate() {
            let md = &self.models[i];
            for k in &c.connectors {
                let Some((_, v)) = md.variable(&k.name) else {
                    let hint = md
                        .suggest(&k.name)
                        .map(|n| format!(" (did you mean '{n}'?)"))
                        .unwrap_or_default();
                    return Err(self.invalid(
                        k.line,
                        format!(
                            "connector '{}.{}': the FMU (model '{}') has no variable '{}'{hint}",
                            c.name, k.name, md.model_name, k.name
                        ),
                    ));
                };
                let kind_ok = match k.kind.as_str() {
                    "input" => v.causality == Causality::Input,
                    "output" => v.causality == Causality::Output,
                    _ => true,
                };
                if !kind_ok {
                    return Err(self.invalid(
                        k.line,
                        format!(
                            "connector '{}.{}' of kind '{}' is a variable of causality '{}' in the FMU",
                            c.name, k.name, k.kind, v.causality
                        ),
                    ));
                }
                if let Some(t) = &k.ty {
                    let fits = matches!(
                        (t, v.var_type),
                        (ConnectorType::Real { .. }, VarType::Real)
                            | (ConnectorType::Integer, VarType::Integer)
                            | (ConnectorType::Boolean, VarType::Boolean)
                            | (ConnectorType::String, VarType::String)
                            | (ConnectorType::Enumeration, VarType::Enumeration)
                    );
                    if !fits {
                        return Err(self.invalid(
                            k.line,
                            format!(
                                "connector '{}.{}' is {} but the FMU's variable is {}",
                                c.name,
                                k.name,
                                var_type_name(t),
                                v.var_type
                            ),
                        ));
                    }
                    if let (ConnectorType::Real { unit: Some(u) }, Some(fu)) = (t, &v.unit) {
                        if !is_fmu_unit(ssd, None, md, u, fu) {
                            return Err(SspError::Unsupported {
                                file: self.ssd_label.clone(),
                                line: Some(k.line),
                                what: format!(
                                    "unit conversion: connector '{}.{}' is in [{u}] but the FMU's variable is in [{fu}]",
                                    c.name, k.name
                                ),
                            });
                        }
                    }
                }
            }
        }
        Ok(())
    }

    fn connections(&mut self, ssd: &Ssd) -> Result<Vec<ConnectionSpec>, SspError> {
        let mut out = Vec::new();
        for c in &ssd.system.connections {
            let (Some(se), Some(ee)) = (&c.start_element, &c.end_element) else {
                let conn = if c.start_element.is_none() {
                    &c.start_connector
                } else {
                    &c.end_connector
                };
                return Err(SspError::Unsupported {
                    file: self.ssd_label.clone(),
                    line: Some(c.line),
                    what: format!(
                        "connection to the system connector '{}.{conn}' (the master has no system inputs or outputs)",
                        ssd.system.name
                    ),
                });
            };
            // (component, causality, the FMU variable's unit, the connector's declared unit)
            type End = (usize, Causality, Option<String>, Option<String>);
            let end_of = |e: &str, k: &str| -> Result<End, SspError> {
                let Some(i) = self.component_index(e) else {
                    return Err(
                        self.invalid(c.line, format!("connection: no component named '{e}'"))
                    );
                };
                let md = &self.models[i];
                match md.variable(k) {
                    Some((_, v)) => Ok((i, v.causality, v.unit.clone(), connector_unit(ssd, i, k))),
                    None => Err(self.invalid(
                        c.line,
                        format!(
                            "connection: component '{e}' (model '{}') has no variable '{k}'{}",
                            md.model_name,
                            md.suggest(k)
                                .map(|n| format!(" (did you mean '{n}'?)"))
                                .unwrap_or_default()
                        ),
                    )),
                }
            };
            let (_, sc, s_fmu, s_declared) = end_of(se, &c.start_connector)?;
            let (_, ec, e_fmu, e_declared) = end_of(ee, &c.end_connector)?;
            let start = format!("{se}.{}", c.start_connector);
            let end = format!("{ee}.{}", c.end_connector);
            // Two FMU variables with their own units are converted by the system's plan (SSP
            // 1.0, 5.3.2), unless the connection suppresses conversion. A unit only a
            // connector declares (its FMU variable has none; check_connectors makes a declared
            // unit agree with the FMU's) would need a conversion of a value the FMU gives no
            // unit: refused, unless the connection suppresses conversion.
            let both_from_fmus = s_fmu.is_some() && e_fmu.is_some();
            let (su, eu) = (s_declared.or(s_fmu), e_declared.or(e_fmu));
            if let (Some(su), Some(eu), false, false) =
                (&su, &eu, both_from_fmus, c.suppress_unit_conversion)
            {
                if !same_unit(ssd, su, eu) {
                    return Err(SspError::Unsupported {
                        file: self.ssd_label.clone(),
                        line: Some(c.line),
                        what: format!(
                            "unit conversion: connection '{start}' [{su}] -> '{end}' [{eu}]: \
                             the master copies values unchanged (suppressUnitConversion=\"true\" \
                             on the connection says to)"
                        ),
                    });
                }
            }
            // SSP connections are directed start -> end; one written input -> output is
            // read the other way round.
            let (from, to) = if sc == Causality::Input && ec == Causality::Output {
                (end, start)
            } else {
                (start, end)
            };
            self.origins.insert(
                format!("connections[{}]", out.len()),
                format!(
                    "connection '{se}.{}' -> '{ee}.{}' ({} line {})",
                    c.start_connector, c.end_connector, self.ssd_label, c.line
                ),
            );
            out.push(ConnectionSpec {
                from,
                to,
                convert_units: !c.suppress_unit_conversion,
            });
        }
        Ok(out)
    }

    fn load_set(&mut self, b: &Binding) -> Result<(ParameterSet, String), SspError> {
        match &b.values {
            BindingValues::Inline(set) => {
                Ok((set.clone(), format!("{} line {}", self.ssd_label, b.line)))
            }
            BindingValues::File(src) => {
                let rel = self
                    .pkg
                    .resolve(src)
                    .map_err(|r| self.invalid(b.line, format!("parameter binding source {r}")))?;
                let label = self.pkg.file_label(&rel);
                let text = self.pkg.read_text(&rel)?;
                Ok((ssv::parse_ssv(&label, &text)?, label))
            }
        }
    }

    /// The (target name, value, origin) pairs a binding supplies, after prefix and mapping.
    fn binding_values(&mut self, b: &Binding) -> Result<(Vec<Supplied>, ParameterSet), SspError> {
        let (set, label) = self.load_set(b)?;
        let origin = |p: &Parameter| {
            format!(
                "parameter '{}' of set '{}' ({label} line {})",
                p.name, set.name, p.line
            )
        };
        let prefixed: Vec<(String, &Parameter)> = set
            .parameters
            .iter()
            .map(|p| (format!("{}{}", b.prefix, p.name), p))
            .collect();
        let mut out = Vec::new();
        match &b.mapping {
            None => {
                for (name, p) in &prefixed {
                    out.push((name.clone(), p.value.clone(), (*p).clone(), origin(p)));
                }
            }
            Some(m) => {
                let (mapping, mlabel) = match m {
                    BindingMapping::Inline(m) => {
                        (m.clone(), format!("{} line {}", self.ssd_label, b.line))
                    }
                    BindingMapping::File(src) => {
                        let rel = self.pkg.resolve(src).map_err(|r| {
                            self.invalid(b.line, format!("parameter mapping source {r}"))
                        })?;
                        let l = self.pkg.file_label(&rel);
                        let text = self.pkg.read_text(&rel)?;
                        (ssv::parse_ssm(&l, &text)?, l)
                    }
                };
                // by name: a set of many parameters and a mapping of as many entries stay linear
                let mut by_name: HashMap<&str, Vec<&Parameter>> = HashMap::new();
                for (n, p) in &prefixed {
                    by_name.entry(n.as_str()).or_default().push(p);
                }
                for e in &mapping.entries {
                    let hits: &[&Parameter] =
                        by_name.get(e.source.as_str()).map_or(&[], Vec::as_slice);
                    if hits.is_empty() {
                        return Err(SspError::Invalid {
                            file: mlabel.clone(),
                            line: Some(e.line),
                            message: format!(
                                "mapping entry source '{}' is not a parameter of set '{}' ({label})",
                                e.source, set.name
                            ),
                        });
                    }
                    for &p in hits {
                        let v = match &e.transformation {
                            None => p.value.clone(),
                            Some(t) => t.apply(&p.value).map_err(|r| SspError::Invalid {
                                file: mlabel.clone(),
                                line: Some(e.line),
                                message: format!("mapping '{}' -> '{}': {r}", e.source, e.target),
                            })?,
                        };
                        let o = format!(
                            "{} mapped to '{}' ({mlabel} line {})",
                            origin(p),
                            e.target,
                            e.line
                        );
                        out.push((e.target.clone(), v, (*p).clone(), o));
                    }
                }
            }
        }
        Ok((out, set))
    }

    /// Parameter values per component: component bindings first, then system bindings, so
    /// the higher level wins, and within a level a later binding wins (SSP 1.0/2.0 5.x
    /// ParameterBindings).
    #[allow(clippy::needless_range_loop)]
    fn parameters(&mut self, ssd: &Ssd) -> Result<Vec<BTreeMap<String, Json>>, SspError> {
        let mut out: Vec<BTreeMap<String, Json>> = (0..self.components.len())
            .map(|_| BTreeMap::new())
            .collect();
        for i in 0..self.components.len() {
            let bindings = self.components[i].bindings.clone();
            for b in &bindings {
                let (vals, set) = self.binding_values(b)?;
                for (target, v, p, origin) in vals {
                    if self.models[i].variable(&target).is_none() {
                        let md = &self.models[i];
                        let hint = md
                            .suggest(&target)
                            .map(|n| format!(" (did you mean '{n}'?)"))
                            .unwrap_or_default();
                        return Err(self.unmatched(
                            &origin,
                            format!(
                                "matches no variable of component '{}' (model '{}'){hint}",
                                self.components[i].name, md.model_name
                            ),
                        ));
                    }
                    let bound = self.convert(ssd, &set, i, &target, &v, &p, &origin)?;
                    self.origins
                        .insert(crate::system::parameter_field(i, &target), origin);
                    out[i].insert(target, bound);
                }
            }
        }
        for b in &ssd.system.bindings {
            let (vals, set) = self.binding_values(b)?;
            for (target, v, p, origin) in vals {
                if ssd.system.connectors.iter().any(|k| k.name == target) {
                    return Err(SspError::Unsupported {
                        file: self.ssd_label.clone(),
                        line: Some(b.line),
                        what: format!(
                            "{origin} sets the system connector '{target}' (the master has no system connectors)"
                        ),
                    });
                }
                let mut hit = false;
                for i in 0..self.components.len() {
                    let Some(var) = target
                        .strip_prefix(self.components[i].name.as_str())
                        .and_then(|r| r.strip_prefix('.'))
                    else {
                        continue;
                    };
                    if self.models[i].variable(var).is_some() {
                        let bound = self.convert(ssd, &set, i, var, &v, &p, &origin)?;
                        self.origins
                            .insert(crate::system::parameter_field(i, var), origin.clone());
                        out[i].insert(var.to_string(), bound);
                        hit = true;
                    }
                }
                if !hit {
                    let names: Vec<&str> =
                        self.components.iter().map(|c| c.name.as_str()).collect();
                    return Err(self.unmatched(
                        &origin,
                        format!(
                            "as '{target}' matches no 'component.variable' of system '{}' (components: {})",
                            ssd.system.name,
                            names.join(", ")
                        ),
                    ));
                }
            }
        }
        Ok(out)
    }

    /// SSP lets a tool ignore a parameter that matches nothing; the master refuses it, so a
    /// misspelt or misplaced parameter never goes unnoticed.
    fn unmatched(&self, origin: &str, why: String) -> SspError {
        SspError::Parameter {
            message: format!("{origin} {why}"),
        }
    }

    /// The JSON start value for variable `var` of component `i`.
    #[allow(clippy::too_many_arguments)]
    fn convert(
        &self,
        ssd: &Ssd,
        set: &ParameterSet,
        i: usize,
        var: &str,
        v: &Value,
        p: &Parameter,
        origin: &str,
    ) -> Result<Json, SspError> {
        let md = &self.models[i];
        let comp = &self.components[i].name;
        let fail = |why: String| SspError::Parameter {
            message: format!("{origin}: {why}"),
        };
        let Some((_, fv)) = md.variable(var) else {
            return Err(fail(format!("component '{comp}' has no variable '{var}'")));
        };
        if !fv.is_settable() {
            return Err(fail(format!(
                "'{comp}.{var}' has causality '{}' and variability '{}' and cannot be given a start value",
                fv.causality, fv.variability
            )));
        }
        let value = match (fv.var_type, v) {
            (VarType::Real, Value::Real(x)) => {
                if let (Some(u), Some(fu)) = (&p.unit, &fv.unit) {
                    if !is_fmu_unit(ssd, Some(set), md, u, fu) {
                        return Err(SspError::Unsupported {
                            file: origin.to_string(),
                            line: None,
                            what: format!(
                                "unit conversion: the value is in [{u}] but '{comp}.{var}' is in [{fu}]"
                            ),
                        });
                    }
                }
                Json::from(*x)
            }
            (VarType::Integer | VarType::Enumeration, Value::Integer(x)) => {
                if i32::try_from(*x).is_err() {
                    return Err(fail(format!("{x} does not fit a 32-bit FMI Integer")));
                }
                Json::from(*x)
            }
            // an item name; the system description resolves it against the FMU's type
            (VarType::Enumeration, Value::Enumeration(name)) => Json::from(name.clone()),
            (VarType::Boolean, Value::Boolean(b)) => Json::from(*b),
            (VarType::String, Value::String(s)) => Json::from(s.clone()),
            (t, v) => {
                return Err(fail(format!(
                    "a {} value cannot set '{comp}.{var}', which is {t}",
                    v.kind()
                )))
            }
        };
        Ok(value)
    }
}

/// The unit a component's connector `name` declares (a Real connector's `unit`).
fn connector_unit(ssd: &Ssd, component: usize, name: &str) -> Option<String> {
    ssd.system.components[component]
        .connectors
        .iter()
        .find(|k| k.name == name)
        .and_then(|k| match &k.ty {
            Some(ConnectorType::Real { unit }) => unit.clone(),
            _ => None,
        })
}

/// Whether units `a` and `b` are the same: the same name, or identical definitions in the SSD.
fn same_unit(ssd: &Ssd, a: &str, b: &str) -> bool {
    a == b
        || {
            let find = |n: &str| ssd.units.iter().find(|u| u.name == n);
            matches!((find(a), find(b)), (Some(x), Some(y)) if x.exponents == y.exponents && x.factor == y.factor && x.offset == y.offset)
        }
}

/// Whether the SSP's unit `a` (defined in the SSD, or in `set`) is the FMU's unit `fu`: the same
/// name, or the same SI exponents, factor and offset, `fu` defined by the FMU's own
/// UnitDefinitions where the SSP does not define it (`kilogram` in the SSP is the FMU's `kg`).
fn is_fmu_unit(
    ssd: &Ssd,
    set: Option<&ParameterSet>,
    md: &ModelDescription,
    a: &str,
    fu: &str,
) -> bool {
    if a == fu {
        return true;
    }
    let in_ssp = |n: &str| {
        set.into_iter()
            .flat_map(|s| s.units.iter())
            .chain(&ssd.units)
            .find(|u| u.name == n)
            .map(|u| (u.exponents, u.factor, u.offset))
    };
    let of_fmu = md
        .units
        .get(fu)
        .map(|u| (u.exponents, u.factor, u.offset))
        .or_else(|| in_ssp(fu));
    matches!((in_ssp(a), of_fmu), (Some(x), Some(y)) if x == y)
}
