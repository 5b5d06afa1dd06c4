//! `documentation/index.html`: a short page describing the variables of one
//! FMU with its start values.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use super::{Dim, Spec};

impl Spec {
    /// Short HTML page describing the variables of an FMU with these start values.
    pub fn documentation_html(&self, overrides: &BTreeMap<String, Vec<f64>>, title: &str) -> Result<String, String> {
        let starts = self.starts(overrides)?;
        let mut h = String::new();
        let _ = writeln!(
            h,
            "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{t}</title></head><body>\n<h1>{t}</h1>\n<p>{}</p>",
            esc(&self.description),
            t = esc(title)
        );
        h.push_str(
            "<p>FMI 3.0 Co-Simulation. Structural parameters (nx, ny, dimension, nModes) are set in \
             Configuration Mode (or in the Instantiated state); fixed parameters before Initialization Mode ends; \
             tunable parameters also between communication steps, taking effect at the next step. \
             Enumerations are read and written with fmi3GetInt64/fmi3SetInt64. \
             Arrays are laid out row-major: positions[row][col][axis], node (row, col) rests at \
             (col &middot; spacing, &minus;row &middot; spacing).</p>\n",
        );
        h.push_str("<table border=\"1\" cellspacing=\"0\" cellpadding=\"3\">\n<tr><th>name</th><th>type</th><th>causality</th><th>variability</th><th>dimensions</th><th>start</th><th>unit</th><th>description</th></tr>\n");
        for v in &self.variables {
            let ty = v.declared_type.clone().map(|t| format!("Enumeration ({t})")).unwrap_or(v.ty.clone());
            let dims: Vec<String> = v
                .dims()
                .iter()
                .map(|d| match d {
                    Dim::Fixed(n) => n.to_string(),
                    Dim::Param(p) => p.clone(),
                })
                .collect();
            let start = starts.get(&v.name).map(|s| s.iter().map(|x| number(&v.ty, *x)).collect::<Vec<_>>().join(" ")).unwrap_or_default();
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                esc(&v.name),
                esc(&ty),
                v.causality,
                v.variability,
                esc(&dims.join(" x ")),
                esc(&start),
                esc(v.unit.as_deref().unwrap_or("")),
                esc(&v.description)
            );
        }
        h.push_str("</table>\n");
        for e in &self.enumerations {
            let _ = writeln!(h, "<h2>{}</h2>\n<p>{}</p>\n<ul>", esc(&e.name), esc(&e.description));
            for i in &e.items {
                let _ = writeln!(h, "<li>{} = {}: {}</li>", i.value, esc(&i.name), esc(&i.description));
            }
            h.push_str("</ul>\n");
        }
        h.push_str("</body></html>\n");
        Ok(h)
    }
}

/// A start value as the page shows it: booleans as words, integers plainly,
/// floats as Rust prints them back exactly.
fn number(ty: &str, x: f64) -> String {
    match ty {
        "Boolean" => (if x != 0.0 { "true" } else { "false" }).to_string(),
        "UInt64" | "Enumeration" => format!("{}", x as i64),
        _ => format!("{x:?}"),
    }
}

/// Escapes text for HTML content and attribute values.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}
