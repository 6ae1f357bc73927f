//! documentation/index.html of an FMU: the model's own text (equations, interpretations) plus
//! tables generated from the declaration (variables, enumerations, capabilities).

use std::fmt::Write as _;

use crate::model::FmuModel;
use crate::xml::{
    check_declaration, enumeration_types, escape, fmt_real, value_references, DeclarationError,
    StartValue, CAPABILITIES,
};

/// documentation/index.html: the model's own text plus a generated variable table.
pub fn documentation_html<M: FmuModel>() -> Result<String, DeclarationError> {
    let vars = M::variables();
    let starts = check_declaration::<M>(&vars)?;
    let vrs = value_references(&vars);
    let info = M::INFO;
    let mut h = String::new();
    let _ = writeln!(
        h,
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{0}</title>\
         <style>body{{font-family:sans-serif;max-width:60em;margin:2em auto}}\
         table{{border-collapse:collapse}}td,th{{border:1px solid #999;padding:2px 6px}}</style>\
         </head><body>\n<h1>{0}</h1>\n<p>{1}</p>",
        escape(info.name),
        escape(info.description)
    );
    h.push_str(info.documentation_html);
    let _ = writeln!(
        h,
        "\n<h2>Variables</h2>\n<table><tr><th>name</th><th>vr</th><th>type</th><th>causality</th>\
         <th>variability</th><th>start</th><th>unit</th><th>min</th><th>max</th><th>description</th></tr>"
    );
    for (i, v) in vars.iter().enumerate() {
        let m = &v.meta;
        let start = match starts.get(i) {
            Some(Some(StartValue::Real(r))) => fmt_real(*r),
            Some(Some(StartValue::Integer(n))) => match m.enumeration.and_then(|e| e.item(*n)) {
                Some(item) => format!("{n} ({})", escape(item.name)),
                None => n.to_string(),
            },
            Some(Some(StartValue::Boolean(b))) => b.to_string(),
            Some(Some(StartValue::String(s))) => escape(s),
            _ => String::new(),
        };
        let type_cell = match m.enumeration {
            Some(e) => format!("Enumeration <code>{}</code>", escape(e.name)),
            None => m.var_type.xml_name().to_string(),
        };
        let _ = writeln!(
            h,
            "<tr><td><code>{}</code></td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            escape(&m.name),
            vrs[i],
            type_cell,
            m.causality.xml_name(),
            m.variability.xml_name(),
            start,
            m.unit.unwrap_or(""),
            m.min.map(fmt_real).unwrap_or_default(),
            m.max.map(fmt_real).unwrap_or_default(),
            escape(&m.description)
        );
    }
    let _ = writeln!(h, "</table>");
    let types = enumeration_types(&vars);
    if !types.is_empty() {
        let _ = writeln!(h, "<h2>Enumerations</h2>");
        for e in types {
            let _ = writeln!(
                h,
                "<h3><code>{}</code></h3>\n<p>{}</p>\n<table><tr><th>value</th><th>item</th><th>description</th></tr>",
                escape(e.name),
                escape(e.description)
            );
            for item in e.items {
                let _ = writeln!(
                    h,
                    "<tr><td>{}</td><td><code>{}</code></td><td>{}</td></tr>",
                    item.value,
                    escape(item.name),
                    escape(item.description)
                );
            }
            let _ = writeln!(h, "</table>");
        }
    }
    let _ = writeln!(h, "<h2>Co-simulation capabilities</h2>\n<ul>");
    for (k, v) in CAPABILITIES {
        let _ = writeln!(h, "<li><code>{k}</code> = {v}</li>");
    }
    let _ = writeln!(h, "</ul>");
    let _ = writeln!(
        h,
        "<h2>Initialization Mode</h2>\n<p>Every variable read in Initialization Mode has the \
         value the FMU gives it right after fmi2ExitInitializationMode with the parameters and \
         inputs set so far, so a host may solve its initial coupling there. A parameter that \
         fmi2ExitInitializationMode would refuse makes those reads return fmi2Warning naming \
         it.</p>"
    );
    let _ = writeln!(
        h,
        "<h2>Licence</h2>\n<p>{} {} (<a href=\"LICENSE-MIT.txt\">LICENSE-MIT.txt</a>, \
         <a href=\"LICENSE-APACHE.txt\">LICENSE-APACHE.txt</a>, in this folder).</p>",
        crate::xml::COPYRIGHT,
        crate::xml::LICENSE_ID
    );
    let _ = writeln!(h, "</body></html>");
    Ok(h)
}
