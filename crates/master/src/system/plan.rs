//! Validation of a system description against the FMUs' model descriptions into a
//! [`CouplingPlan`].

use std::collections::HashMap;

use serde_json::Value;

use super::{json_value_for, type_of, LoadedSystem, SystemError};
use crate::coupling::{
    topological_order, Algorithm, ColumnInfo, CouplingPlan, PlanConnection, PlanInstance, Recorded,
    UnitConversion,
};
use crate::model_description::{BaseUnit, Causality, ModelDescription, VarType, BASE_UNIT_NAMES};
use crate::show::{num, text};
use crate::slave::VarRef;

impl LoadedSystem {
    /// Validates against the model descriptions (one per instance, same order) and builds the
    /// coupling plan. No FMU binary is needed.
    pub fn plan(&self, models: &[&ModelDescription]) -> Result<CouplingPlan, SystemError> {
        let d = &self.desc;
        if d.instances.is_empty() {
            return Err(self.invalid("instances", "instances", "at least one instance is needed"));
        }
        if models.len() != d.instances.len() {
            return Err(self.invalid(
                "instances",
                "instances",
                "internal: one model description per instance expected",
            ));
        }
        if !(d.step.is_finite() && d.step > 0.0) {
            return Err(self.invalid(
                "step",
                "step",
                format!("must be a positive number, got {}", num(d.step)),
            ));
        }
        self.check_stop_time(d.stop_time)?;
        let mut instances = Vec::new();
        let mut strings = Vec::new();
        for (i, inst) in d.instances.iter().enumerate() {
            let f = format!("instances[{i}].name");
            // a control character would also break a result file's column names
            if inst.name.is_empty()
                || inst.name.contains('.')
                || inst.name.contains(char::is_control)
            {
                return Err(self.invalid(
                    f,
                    &inst.name,
                    format!(
                        "'{}' is not a valid instance name (non-empty, no '.', no control \
                         character)",
                        text(&inst.name)
                    ),
                ));
            }
            if d.instances[..i].iter().any(|o| o.name == inst.name) {
                return Err(self.invalid(
                    f,
                    &inst.name,
                    format!("instance name '{}' is used twice", text(&inst.name)),
                ));
            }
            if inst.step_multiple == 0 {
                return Err(self.invalid(
                    format!("instances[{i}].step_multiple"),
                    "step_multiple",
                    "must be >= 1",
                ));
            }
            let md = models[i];
            let mut params = Vec::new();
            let mut parameter_names = Vec::new();
            let invalid = |f: String, needle: &str, r: String| self.invalid(f, needle, r);
            for (name, value) in &inst.parameters {
                params.push(start_value(i, md, name, value, &mut strings, &invalid)?);
                parameter_names.push(name.clone());
            }
            instances.push(PlanInstance {
                name: inst.name.clone(),
                step_multiple: inst.step_multiple,
                parameters: params,
                parameter_names,
            });
        }

        let mut connections = Vec::new();
        let mut inputs_taken: HashMap<(usize, usize), usize> = HashMap::new();
        let mut feedthrough_edges = Vec::new();
        // ((source instance, output index), (target instance, input index)) per connection
        let mut ends: Vec<((usize, usize), (usize, usize))> = Vec::new();
        for (ci, c) in d.connections.iter().enumerate() {
            let ff = format!("connections[{ci}].from");
            let tf = format!("connections[{ci}].to");
            let (fi, fvi, fv) = self.resolve(&ff, &c.from, models)?;
            let (ti, tvi, tv) = self.resolve(&tf, &c.to, models)?;
            if fv.causality != Causality::Output {
                return Err(self.invalid(
                    ff,
                    &c.from,
                    format!(
                        "'{}' has causality '{}', only outputs can be connection sources",
                        c.from, fv.causality
                    ),
                ));
            }
            if tv.causality != Causality::Input {
                return Err(self.invalid(
                    tf,
                    &c.to,
                    format!(
                        "'{}' has causality '{}', only inputs can be connection targets",
                        c.to, tv.causality
                    ),
                ));
            }
            if fi == ti {
                return Err(self.invalid(tf, &c.to, "connects an instance to itself"));
            }
            if fv.var_type != tv.var_type {
                return Err(self.invalid(
                    format!("connections[{ci}]"),
                    &c.to,
                    format!(
                        "type mismatch: '{}' is {} but '{}' is {}",
                        c.from, fv.var_type, c.to, tv.var_type
                    ),
                ));
            }
            let ty = type_of(fv.var_type);
            let items = |md: &ModelDescription, v| {
                md.enum_items(v)
                    .iter()
                    .map(|i| (i.value, i.name.clone()))
                    .collect::<Vec<_>>()
            };
            if items(models[fi], fv) != items(models[ti], tv) {
                return Err(self.invalid(
                    format!("connections[{ci}]"),
                    &c.to,
                    format!(
                        "enumeration mismatch: '{}' and '{}' have different items",
                        c.from, c.to
                    ),
                ));
            }
            let conversion = match (&fv.unit, &tv.unit) {
                (Some(uf), Some(ut)) if c.convert_units => {
                    let from = End {
                        model: models[fi],
                        unit: uf,
                        relative: fv.relative_quantity,
                    };
                    let to = End {
                        model: models[ti],
                        unit: ut,
                        relative: tv.relative_quantity,
                    };
                    let converted = if fv.var_type == VarType::Real {
                        unit_conversion(&from, &to)
                    } else if uf == ut {
                        Ok(None)
                    } else {
                        Err(format!(
                            "{} values are not converted (FMI 2.0 gives only a Real a unit)",
                            fv.var_type
                        ))
                    };
                    converted.map_err(|why| {
                        let field = format!("connections[{ci}]");
                        // an SSP connection is told otherwise than a JSON one
                        let unchanged = if self.origins.contains_key(&field) {
                            "suppressUnitConversion=\"true\" on the connection passes the value \
                             unchanged"
                        } else {
                            "\"convert_units\": false on the connection passes the value unchanged"
                        };
                        self.invalid(
                            field,
                            &c.to,
                            format!(
                                "unit mismatch: '{}' is in [{uf}] but '{}' is in [{ut}]: {why} \
                                 ({unchanged})",
                                c.from, c.to
                            ),
                        )
                    })?
                }
                _ => None,
            };
            if let Some(prev) = inputs_taken.insert((ti, tvi), ci) {
                return Err(self.invalid(
                    tf,
                    &c.to,
                    format!("input '{}' is already driven by connections[{prev}]", c.to),
                ));
            }
            // the order follows every direct dependency of the target's outputs
            if models[ti].has_direct_feedthrough(tvi) {
                feedthrough_edges.push((fi, ti));
            }
            ends.push(((fi, fvi), (ti, tvi)));
            connections.push(PlanConnection {
                from_instance: fi,
                from: VarRef {
                    vr: fv.value_reference,
                    ty,
                },
                to_instance: ti,
                to: VarRef {
                    vr: tv.value_reference,
                    ty,
                },
                label: c.from.clone(),
                feedthrough: false,
                source_depends_on_inputs: false,
                conversion,
            });
        }
        // Gauss-Seidel reads a target's outputs again after setting this input only if one of
        // them that is itself connected depends on it: outputs nothing consumes are read once,
        // when they are recorded.
        for (c, &((fi, fvi), (ti, tvi))) in connections.iter_mut().zip(&ends) {
            c.feedthrough = ends
                .iter()
                .any(|&((fi, fvi), _)| fi == ti && models[ti].output_depends_on(fvi, tvi));
            c.source_depends_on_inputs = ends
                .iter()
                .any(|&(_, (ti, tvi))| ti == fi && models[fi].output_depends_on(fvi, tvi));
        }

        let order = match &d.order {
            Some(names) => {
                let mut order = Vec::new();
                for (k, n) in names.iter().enumerate() {
                    let Some(i) = self.instance_index(n) else {
                        return Err(self.invalid(
                            format!("order[{k}]"),
                            n,
                            format!("unknown instance '{}'", text(n)),
                        ));
                    };
                    if order.contains(&i) {
                        return Err(self.invalid(
                            format!("order[{k}]"),
                            n,
                            format!("instance '{}' appears twice", text(n)),
                        ));
                    }
                    order.push(i);
                }
                if order.len() != d.instances.len() {
                    let missing: Vec<&str> = (0..d.instances.len())
                        .filter(|i| !order.contains(i))
                        .map(|i| d.instances[i].name.as_str())
                        .collect();
                    return Err(self.invalid(
                        "order",
                        "order",
                        format!("must list every instance; missing: {}", missing.join(", ")),
                    ));
                }
                order
            }
            None => {
                let (order, broken) = topological_order(d.instances.len(), &feedthrough_edges);
                if !broken.is_empty() && d.algorithm == Algorithm::GaussSeidel {
                    let names: Vec<&str> = broken
                        .iter()
                        .map(|&i| d.instances[i].name.as_str())
                        .collect();
                    log::warn!(target: "master", "{}: algebraic loop through direct feedthrough; Gauss-Seidel order breaks it at {}", self.file, names.join(", "));
                }
                order
            }
        };

        let label = |i: usize, v: &crate::model_description::Variable| match &v.unit {
            Some(u) => format!("{}.{} [{u}]", d.instances[i].name, v.name),
            None => format!("{}.{}", d.instances[i].name, v.name),
        };
        let recorded = |i: usize, v: &crate::model_description::Variable| {
            let ty = type_of(v.var_type);
            Recorded {
                instance: i,
                var: VarRef {
                    vr: v.value_reference,
                    ty,
                },
                label: label(i, v),
                info: ColumnInfo {
                    ty: Some(ty),
                    name: format!("{}.{}", d.instances[i].name, v.name),
                    unit: v.unit.clone(),
                    causality: v.causality.to_string(),
                    description: v.description.clone(),
                    instance: d.instances[i].name.clone(),
                    fmu_guid: models[i].guid.clone(),
                    items: models[i]
                        .enum_items(v)
                        .iter()
                        .map(|it| (it.value, it.name.clone()))
                        .collect(),
                },
            }
        };
        let limits =
            crate::coupling::RunLimits::from_env().map_err(|r| self.invalid("step", "step", r))?;
        let steps = limits
            .steps(d.stop_time - d.start_time, d.step)
            .map_err(|r| self.invalid("step", "step", r))?;
        let mut record = Vec::new();
        match &d.record {
            Some(list) => {
                // a list too long is refused before its names are resolved
                limits
                    .recorded(steps, list.len() + 1)
                    .map_err(|r| self.invalid("record", "record", r))?;
                let mut seen: HashMap<(usize, usize), usize> = HashMap::new();
                for (k, s) in list.iter().enumerate() {
                    let field = format!("record[{k}]");
                    let (i, vi, v) = self.resolve(&field, s, models)?;
                    if let Some(first) = seen.insert((i, vi), k) {
                        // one column per variable: a repeated name would give two columns of
                        // one name, which Parquet readers refuse
                        return Err(self.invalid(
                            field,
                            s,
                            format!("'{s}' is recorded already (record[{first}])"),
                        ));
                    }
                    record.push(recorded(i, v));
                }
            }
            None => {
                for (i, md) in models.iter().enumerate() {
                    for (vi, v) in md.variables.iter().enumerate() {
                        let connected_input =
                            v.causality == Causality::Input && inputs_taken.contains_key(&(i, vi));
                        if v.causality == Causality::Output || connected_input {
                            record.push(recorded(i, v));
                        }
                    }
                }
            }
        }

        limits
            .recorded(steps, record.len() + 1)
            .map_err(|r| self.invalid("record", "record", r))?;
        Ok(CouplingPlan {
            start_time: d.start_time,
            stop_time: d.stop_time,
            step: d.step,
            instances,
            connections,
            algorithm: d.algorithm,
            order,
            record,
            init_sweeps: d.init_sweeps,
            max_step_halvings: d.max_step_halvings,
            strings,
        })
    }

    /// The description's stop time is after the start time and a whole number of steps away
    /// from it.
    fn check_stop_time(&self, stop_time: f64) -> Result<(), SystemError> {
        self.stop_time_problem(stop_time)
            .map_err(|(field, reason)| self.invalid(field, field, reason))
    }

    /// Why `stop_time` cannot end a run of this description: (the field at fault, `stop_time`
    /// or `step`, and the reason).
    pub(super) fn stop_time_problem(&self, stop_time: f64) -> Result<(), (&'static str, String)> {
        let d = &self.desc;
        if !stop_time.is_finite() {
            return Err((
                "stop_time",
                format!("must be a finite number, got {}", num(stop_time)),
            ));
        }
        if !(d.start_time.is_finite() && stop_time > d.start_time) {
            return Err((
                "stop_time",
                format!(
                    "must be greater than start_time ({}), got {}",
                    num(d.start_time),
                    num(stop_time)
                ),
            ));
        }
        let span = stop_time - d.start_time;
        let limits = crate::coupling::RunLimits::from_env().map_err(|r| ("step", r))?;
        limits.steps(span, d.step).map_err(|r| ("step", r))?;
        if let Some(why) = crate::coupling::step_below_resolution(d.start_time, stop_time, d.step) {
            return Err(("step", why));
        }
        let n = (span / d.step).round();
        // a span shorter than half a step rounds to no step, which the run refuses too
        if n < 1.0 || (n * d.step - span).abs() > 1e-9 * span.max(d.step) {
            return Err((
                "step",
                format!(
                    "stop_time - start_time = {} s is not an integer multiple of step = {} s",
                    num(span),
                    num(d.step)
                ),
            ));
        }
        Ok(())
    }
}

/// Builds the error of a field: (field, text to find the line by, reason).
pub(super) type Invalid<'a> = dyn Fn(String, &str, String) -> SystemError + 'a;

/// The start value `name = value` of instance `i` (model `md`): a settable variable, the
/// value converted to its type (a String's text added to `strings`).
pub(super) fn start_value(
    i: usize,
    md: &ModelDescription,
    name: &str,
    value: &Value,
    strings: &mut Vec<String>,
    invalid: &Invalid,
) -> Result<(VarRef, f64), SystemError> {
    let field = super::parameter_field(i, name);
    let Some((_, v)) = md.variable(name) else {
        let hint = md
            .suggest(name)
            .map(|n| format!(" (did you mean '{n}'?)"))
            .unwrap_or_default();
        return Err(invalid(
            field,
            name,
            format!(
                "unknown variable '{}' in model '{}'{hint}",
                text(name),
                md.model_name
            ),
        ));
    };
    if !v.is_settable() {
        return Err(invalid(
            field,
            name,
            format!(
                "'{name}' has causality '{}' and variability '{}' and cannot be given a start value",
                v.causality, v.variability
            ),
        ));
    }
    let ty = type_of(v.var_type);
    let x = json_value_for(md, v, value, strings).map_err(|r| invalid(field.clone(), name, r))?;
    if matches!(v.var_type, VarType::Real | VarType::Integer) {
        // the FMU refuses such a value at fmi2SetXXX, in every run: said here, before one
        // a dimensionless "1" is no unit to print after a number ("2 1 is above ... 1 1")
        let unit = v
            .unit
            .as_deref()
            .filter(|u| !u.trim().is_empty() && u.trim() != "1")
            .map_or(String::new(), |u| format!(" {u}"));
        let outside = match (v.min, v.max) {
            (Some(lo), _) if x < lo => Some(format!("below its minimum {}{unit}", num(lo))),
            (_, Some(hi)) if x > hi => Some(format!("above its maximum {}{unit}", num(hi))),
            _ => None,
        };
        if let Some(why) = outside {
            let reason = format!(
                "{}{unit} is {why} (declared by model '{}' for '{}')",
                num(x),
                md.model_name,
                text(name)
            );
            return Err(invalid(field, name, reason));
        }
    }
    Ok((
        VarRef {
            vr: v.value_reference,
            ty,
        },
        x,
    ))
}

/// One end of a connection, for [`unit_conversion`].
struct End<'a> {
    model: &'a ModelDescription,
    unit: &'a str,
    /// FMI 2.0 `relativeQuantity`: a difference, converted without the BaseUnit offsets.
    relative: bool,
}

/// The conversion of a Real from one end's unit to the other's, by the BaseUnit each model's
/// UnitDefinitions give its unit (FMI 2.0, 2.2.2): None when the values need none (the same
/// unit, or one name defined alike, or a unit a model does not define under a name both
/// use); `Err`: why there is none.
fn unit_conversion(from: &End, to: &End) -> Result<Option<UnitConversion>, String> {
    let defined = |e: &End| e.model.units.get(e.unit).copied();
    let (f, t) = match (defined(from), defined(to)) {
        (Some(f), Some(t)) => (f, t),
        // one name, not defined by both: taken as the same unit, as before units converted
        _ if from.unit == to.unit => return Ok(None),
        (None, _) => return Err(undefined(from)),
        (_, None) => return Err(undefined(to)),
    };
    if f.exponents != t.exponents {
        return Err(format!(
            "they measure different quantities ([{}] = {}, [{}] = {})",
            from.unit,
            base_units_text(&f),
            to.unit,
            base_units_text(&t)
        ));
    }
    if !(f.factor.is_finite() && t.factor.is_finite() && f.factor != 0.0 && t.factor != 0.0) {
        return Err("a BaseUnit factor is 0 or not finite".into());
    }
    let (mut f_offset, mut t_offset) = (f.offset, t.offset);
    match (from.relative, to.relative) {
        // differences: the offsets do not apply (FMI 2.0, 2.2.7: 10 degC = 10 K)
        (true, true) => (f_offset, t_offset) = (0.0, 0.0),
        (false, false) => {}
        _ if f_offset == 0.0 && t_offset == 0.0 => {}
        _ => {
            return Err(
                "one is a relative quantity (a difference) and the other is not, and the \
                 units' offsets differ"
                    .into(),
            )
        }
    }
    Ok(UnitConversion::between(
        (f.factor, f_offset),
        (t.factor, t_offset),
    ))
}

fn undefined(e: &End) -> String {
    format!(
        "model '{}' gives [{}] no BaseUnit in its UnitDefinitions, so the value cannot be \
         converted",
        e.model.model_name, e.unit
    )
}

/// A BaseUnit's SI base units, e.g. `kg m s-2` (`1` for none).
fn base_units_text(b: &BaseUnit) -> String {
    let parts: Vec<String> = BASE_UNIT_NAMES
        .iter()
        .zip(b.exponents)
        .filter(|(_, e)| *e != 0)
        .map(|(n, e)| {
            if e == 1 {
                n.to_string()
            } else {
                format!("{n}{e}")
            }
        })
        .collect();
    if parts.is_empty() {
        "1".into()
    } else {
        parts.join(" ")
    }
}
