//! The Markdown tables of docs/variables.md: the variables, the enumerations and the
//! canonical scenes (`cargo xtask docs`).

use std::collections::BTreeMap;
use std::fmt::Write as _;

use super::{Dim, Spec};

/// Markers of the generated tables in docs/variables.md.
pub const README_BEGIN: &str = "<!-- variables: generated from modelDescription/variables.toml by `cargo xtask docs` -->";
pub const README_END: &str = "<!-- end of generated variables -->";

impl Spec {
    /// docs/variables.md's tables of the variables, the enumerations and the
    /// canonical scenes (Markdown), written by `cargo xtask docs` between
    /// the markers [`README_BEGIN`] and [`README_END`].
    pub fn readme_tables(&self) -> String {
        let starts = self.starts(&BTreeMap::new()).expect("the defaults are valid");
        let mut m = String::new();
        m.push_str("| name | type | causality / variability | start | unit | description |\n|---|---|---|---|---|---|\n");
        for v in &self.variables {
            let dims: String = v
                .dims()
                .iter()
                .map(|d| match d {
                    Dim::Fixed(n) => format!("[{n}]"),
                    Dim::Param(p) => format!("[`{p}`]"),
                })
                .collect();
            let ty = match &v.declared_type {
                Some(t) => format!("Enumeration `{t}`"),
                None if dims.is_empty() => v.ty.clone(),
                None => format!("{} {dims}", v.ty),
            };
            let start = match (starts.get(&v.name), &v.declared_type) {
                (Some(s), Some(t)) => {
                    let item = self.enumerations.iter().find(|e| &e.name == t).and_then(|e| e.items.iter().find(|i| i.value as f64 == s[0]));
                    format!("{} (`{}`)", s[0] as i64, item.map_or("", |i| i.name.as_str()))
                }
                (Some(s), None) => s.iter().map(|x| readme_number(&v.ty, *x)).collect::<Vec<_>>().join(" "),
                (None, _) => String::new(),
            };
            let range = match (v.min, v.max) {
                (Some(lo), Some(hi)) if dims.is_empty() => format!(" [{} … {}]", readme_number(&v.ty, lo), readme_number(&v.ty, hi)),
                (Some(lo), Some(hi)) => format!(" [each {} … {}]", readme_number(&v.ty, lo), readme_number(&v.ty, hi)),
                _ => String::new(),
            };
            let _ = writeln!(
                m,
                "| `{}` | {ty} | {} / {} | {start} | {} | {}{range} |",
                v.name,
                v.causality,
                v.variability,
                v.unit.as_deref().unwrap_or(""),
                v.description.replace('|', "\\|")
            );
        }
        m.push_str("\nEnumerations are read and written with `fmi3GetInt64` / `fmi3SetInt64`.\n\n| type | items |\n|---|---|\n");
        for e in &self.enumerations {
            let items: Vec<String> = e.items.iter().map(|i| format!("{} `{}`: {}", i.value, i.name, i.description)).collect();
            let _ = writeln!(m, "| `{}` | {} |", e.name, items.join("; "));
        }
        m.push_str("\nCanonical scenes (`cargo xtask fmu --scene NAME` bakes one into an FMU), as start values that differ from the defaults:\n\n| scene | start values |\n|---|---|\n");
        for name in self.scene_names() {
            let values: Vec<String> = self
                .scene(&name)
                .unwrap()
                .iter()
                .map(|(var, x)| {
                    let v = self.variable(var).unwrap();
                    format!("`{var}` = {}", x.iter().map(|x| readme_number(&v.ty, *x)).collect::<Vec<_>>().join(" "))
                })
                .collect();
            let _ = writeln!(m, "| `{name}` | {} |", values.join(", "));
        }
        m
    }
}

/// A number as the README shows it: integers plainly, very small or large
/// values as powers of ten.
fn readme_number(ty: &str, x: f64) -> String {
    match ty {
        "Boolean" => (if x != 0.0 { "true" } else { "false" }).to_string(),
        "UInt64" | "Enumeration" => format!("{}", x as i64),
        _ if x != 0.0 && (x.abs() >= 1e4 || x.abs() < 1e-3) => format!("{x:e}"),
        _ => format!("{x}"),
    }
}
