//! Generator shared by `build.rs` (Rust variable table) and `cargo xtask fmu`
//! (modelDescription.xml, documentation): both read `variables.toml` through
//! this file, so the XML and the value references of the binary cannot drift.
//!
//! Needs the `serde` (derive) and `toml` crates in the including crate.

#![allow(dead_code)]

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use serde::Deserialize;

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct Spec {
    pub model_name: String,
    pub model_identifier: String,
    pub instantiation_token: String,
    pub description: String,
    pub generation_tool: String,
    pub co_simulation: BTreeMap<String, bool>,
    pub default_experiment: DefaultExperiment,
    pub log_categories: Vec<LogCategory>,
    pub units: Vec<Unit>,
    pub enumerations: Vec<Enumeration>,
    pub variables: Vec<Variable>,
    #[serde(default)]
    pub scenes: BTreeMap<String, BTreeMap<String, toml::Value>>,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct DefaultExperiment {
    pub start_time: f64,
    pub stop_time: f64,
    pub step_size: f64,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct LogCategory {
    pub name: String,
    pub description: String,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct Unit {
    pub name: String,
    /// Also the name of the Float64Type that carries the unit.
    pub quantity: String,
    pub base: BTreeMap<String, i32>,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct Enumeration {
    pub name: String,
    pub description: String,
    pub items: Vec<Item>,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct Item {
    pub name: String,
    pub value: i64,
    pub description: String,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct Variable {
    pub name: String,
    pub vr: u32,
    #[serde(rename = "type")]
    pub ty: String,
    #[serde(default)]
    pub declared_type: Option<String>,
    pub causality: String,
    pub variability: String,
    #[serde(default)]
    pub start: Option<toml::Value>,
    #[serde(default)]
    pub min: Option<f64>,
    #[serde(default)]
    pub max: Option<f64>,
    #[serde(default)]
    pub unit: Option<String>,
    pub description: String,
    #[serde(default)]
    pub dimensions: Vec<toml::Value>,
    /// Outputs: the inputs this output depends on directly at a
    /// communication point (ModelStructure `dependencies`); absent: every input.
    #[serde(default)]
    pub depends_on: Option<Vec<String>>,
}

/// One array dimension: a fixed size or the value of a structural parameter.
#[derive(Debug, Clone, PartialEq)]
pub enum Dim {
    Fixed(u64),
    Param(String),
}

impl Variable {
    pub fn dims(&self) -> Vec<Dim> {
        self.dimensions
            .iter()
            .map(|d| match d {
                toml::Value::Integer(n) => Dim::Fixed(*n as u64),
                toml::Value::String(s) => Dim::Param(s.clone()),
                other => panic!("dimension of {} must be an integer or a name, got {other}", self.name),
            })
            .collect()
    }

    /// Start values as numbers (booleans as 0/1); empty when there is none.
    pub fn start_numbers(&self) -> Vec<f64> {
        self.start.as_ref().map(numbers).unwrap_or_default()
    }

    pub fn has_start(&self) -> bool {
        self.start.is_some()
    }

    /// Parameters and inputs: the variables the importer sets.
    pub fn holds_value(&self) -> bool {
        matches!(self.causality.as_str(), "parameter" | "structuralParameter" | "input")
    }
}

fn numbers(v: &toml::Value) -> Vec<f64> {
    match v {
        toml::Value::Integer(i) => vec![*i as f64],
        toml::Value::Float(f) => vec![*f],
        toml::Value::Boolean(b) => vec![if *b { 1.0 } else { 0.0 }],
        toml::Value::Array(a) => a.iter().flat_map(numbers).collect(),
        other => panic!("unsupported start value {other}"),
    }
}

pub fn load(path: &Path) -> Result<Spec, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    parse(&text).map_err(|e| format!("{}: {e}", path.display()))
}

pub fn parse(text: &str) -> Result<Spec, String> {
    let spec: Spec = toml::from_str(text).map_err(|e| e.to_string())?;
    spec.check()?;
    Ok(spec)
}

const TYPES: [&str; 4] = ["Float64", "UInt64", "Boolean", "Enumeration"];
const CAUSALITIES: [&str; 6] = ["independent", "structuralParameter", "parameter", "calculatedParameter", "input", "output"];

impl Spec {
    fn check(&self) -> Result<(), String> {
        let mut vrs = std::collections::BTreeSet::new();
        let mut names = std::collections::BTreeSet::new();
        for v in &self.variables {
            if !vrs.insert(v.vr) {
                return Err(format!("duplicate value reference {}", v.vr));
            }
            if !names.insert(v.name.as_str()) {
                return Err(format!("duplicate variable name {}", v.name));
            }
            if !TYPES.contains(&v.ty.as_str()) {
                return Err(format!("{}: unknown type {}", v.name, v.ty));
            }
            if !CAUSALITIES.contains(&v.causality.as_str()) {
                return Err(format!("{}: unknown causality {}", v.name, v.causality));
            }
            if v.unit.is_some() && (v.ty != "Float64" || v.declared_type.is_some()) {
                return Err(format!("{}: only Float64 variables without declared_type may have a unit", v.name));
            }
            if v.ty == "Enumeration" {
                let t = v.declared_type.as_deref().ok_or(format!("{}: enumeration needs declared_type", v.name))?;
                if !self.enumerations.iter().any(|e| e.name == t) {
                    return Err(format!("{}: unknown enumeration type {t}", v.name));
                }
            }
            if let (Some(lo), Some(hi)) = (v.min, v.max) {
                if lo > hi {
                    return Err(format!("{}: min {lo} is above max {hi}", v.name));
                }
            }
            if (v.min.is_some() || v.max.is_some()) && !matches!(v.ty.as_str(), "Float64" | "UInt64") {
                return Err(format!("{}: only Float64 and UInt64 variables have a range", v.name));
            }
            for x in v.start_numbers() {
                if v.min.is_some_and(|lo| x < lo) || v.max.is_some_and(|hi| x > hi) {
                    return Err(format!("{}: start value {x} is outside its range", v.name));
                }
            }
            // Stored as f64 in the binary: UInt64 values must stay exact.
            if v.ty == "UInt64" && !v.max.is_some_and(|m| m <= 9.0e15) {
                return Err(format!("{}: UInt64 variables need a max below 2^53", v.name));
            }
            if let Some(u) = &v.unit {
                if !self.units.iter().any(|x| &x.name == u) {
                    return Err(format!("{}: unit {u} is not defined", v.name));
                }
            }
            if v.holds_value() != v.has_start() {
                return Err(format!("{}: parameters and inputs, and only they, have a start value", v.name));
            }
            if v.causality == "input" && v.variability != "continuous" && v.variability != "discrete" {
                return Err(format!("{}: an input is continuous or discrete", v.name));
            }
            if let Some(deps) = &v.depends_on {
                if v.causality != "output" {
                    return Err(format!("{}: only outputs have depends_on", v.name));
                }
                for d in deps {
                    if self.variable(d).is_none_or(|x| x.causality != "input") {
                        return Err(format!("{}: depends_on names {d}, which is not an input", v.name));
                    }
                }
            }
            for d in v.dims() {
                if let Dim::Param(p) = d {
                    let target = self.variable(&p).ok_or(format!("{}: dimension {p} is not a variable", v.name))?;
                    if target.causality != "structuralParameter" || target.ty != "UInt64" {
                        return Err(format!("{}: dimension {p} must be a UInt64 structural parameter", v.name));
                    }
                }
            }
        }
        for (scene, values) in &self.scenes {
            for name in values.keys() {
                if self.variable(name).is_none_or(|v| !v.has_start()) {
                    return Err(format!("scene {scene}: {name} is not a parameter"));
                }
            }
        }
        Ok(())
    }

    pub fn variable(&self, name: &str) -> Option<&Variable> {
        self.variables.iter().find(|v| v.name == name)
    }

    /// Start values of every parameter with `overrides` applied and arrays
    /// fitted to the sizes their structural parameters give.
    pub fn starts(&self, overrides: &BTreeMap<String, Vec<f64>>) -> Result<BTreeMap<String, Vec<f64>>, String> {
        let mut out = BTreeMap::new();
        for v in self.variables.iter().filter(|v| v.has_start()) {
            let values = overrides.get(&v.name).cloned().unwrap_or_else(|| v.start_numbers());
            out.insert(v.name.clone(), values);
        }
        for name in overrides.keys() {
            if !out.contains_key(name) {
                return Err(format!("{name} is not a parameter"));
            }
        }
        for v in self.variables.iter().filter(|v| v.has_start()) {
            let size = self.size(v, &out)?;
            let values = out.get_mut(&v.name).unwrap();
            if values.len() != size {
                if overrides.contains_key(&v.name) {
                    return Err(format!("{} needs {size} start values, got {}", v.name, values.len()));
                }
                fit(values, size);
            }
        }
        Ok(out)
    }

    /// Number of elements of `v` given the structural parameter values in `starts`.
    pub fn size(&self, v: &Variable, starts: &BTreeMap<String, Vec<f64>>) -> Result<usize, String> {
        let mut n = 1usize;
        for d in v.dims() {
            n *= match d {
                Dim::Fixed(k) => k as usize,
                Dim::Param(p) => starts.get(&p).and_then(|x| x.first()).copied().ok_or(format!("no value for {p}"))? as usize,
            };
        }
        Ok(n)
    }

    /// Start-value overrides of a canonical scene.
    pub fn scene(&self, name: &str) -> Option<BTreeMap<String, Vec<f64>>> {
        self.scenes.get(name).map(|t| t.iter().map(|(k, v)| (k.clone(), numbers(v))).collect())
    }

    pub fn scene_names(&self) -> Vec<String> {
        self.scenes.keys().cloned().collect()
    }

    /// modelDescription.xml (FMI 3.0, Co-Simulation) with the given start values.
    pub fn model_description_xml(&self, overrides: &BTreeMap<String, Vec<f64>>) -> Result<String, String> {
        let starts = self.starts(overrides)?;
        let mut x = String::new();
        let w = &mut x;
        w.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        let _ = writeln!(
            w,
            "<fmiModelDescription fmiVersion=\"3.0\" modelName=\"{}\" instantiationToken=\"{}\" description=\"{}\" generationTool=\"{}\" variableNamingConvention=\"flat\">",
            esc(&self.model_name),
            esc(&self.instantiation_token),
            esc(&self.description),
            esc(&self.generation_tool)
        );
        let _ = write!(w, "  <CoSimulation modelIdentifier=\"{}\"", esc(&self.model_identifier));
        for (k, v) in &self.co_simulation {
            let _ = write!(w, " {k}=\"{v}\"");
        }
        w.push_str("/>\n  <UnitDefinitions>\n");
        for u in &self.units {
            let _ = write!(w, "    <Unit name=\"{}\"><BaseUnit", esc(&u.name));
            for (k, e) in &u.base {
                let _ = write!(w, " {k}=\"{e}\"");
            }
            w.push_str("/></Unit>\n");
        }
        w.push_str("  </UnitDefinitions>\n  <TypeDefinitions>\n");
        for u in &self.units {
            let _ = writeln!(w, "    <Float64Type name=\"{q}\" quantity=\"{q}\" unit=\"{}\"/>", esc(&u.name), q = esc(&u.quantity));
        }
        for e in &self.enumerations {
            let _ = writeln!(w, "    <EnumerationType name=\"{}\" description=\"{}\">", esc(&e.name), esc(&e.description));
            for i in &e.items {
                let _ = writeln!(w, "      <Item name=\"{}\" value=\"{}\" description=\"{}\"/>", esc(&i.name), i.value, esc(&i.description));
            }
            w.push_str("    </EnumerationType>\n");
        }
        w.push_str("  </TypeDefinitions>\n  <LogCategories>\n");
        for c in &self.log_categories {
            let _ = writeln!(w, "    <Category name=\"{}\" description=\"{}\"/>", esc(&c.name), esc(&c.description));
        }
        let d = &self.default_experiment;
        let _ = writeln!(
            w,
            "  </LogCategories>\n  <DefaultExperiment startTime=\"{}\" stopTime=\"{}\" stepSize=\"{}\"/>\n  <ModelVariables>",
            d.start_time, d.stop_time, d.step_size
        );
        for v in &self.variables {
            let _ = write!(
                w,
                "    <{} name=\"{}\" valueReference=\"{}\" description=\"{}\" causality=\"{}\" variability=\"{}\"",
                v.ty,
                esc(&v.name),
                v.vr,
                esc(&v.description),
                v.causality,
                v.variability
            );
            if let Some(t) = &v.declared_type {
                let _ = write!(w, " declaredType=\"{}\"", esc(t));
            }
            if let Some(u) = &v.unit {
                let t = &self.units.iter().find(|x| &x.name == u).unwrap().quantity;
                let _ = write!(w, " declaredType=\"{}\"", esc(t));
            }
            if let Some(m) = v.min {
                let _ = write!(w, " min=\"{}\"", number(&v.ty, m));
            }
            if let Some(m) = v.max {
                let _ = write!(w, " max=\"{}\"", number(&v.ty, m));
            }
            if let Some(s) = starts.get(&v.name) {
                let s: Vec<String> = s.iter().map(|x| number(&v.ty, *x)).collect();
                let _ = write!(w, " start=\"{}\"", s.join(" "));
            }
            let dims = v.dims();
            if dims.is_empty() {
                w.push_str("/>\n");
            } else {
                w.push_str(">\n");
                for d in dims {
                    match d {
                        Dim::Fixed(n) => {
                            let _ = writeln!(w, "      <Dimension start=\"{n}\"/>");
                        }
                        Dim::Param(p) => {
                            let _ = writeln!(w, "      <Dimension valueReference=\"{}\"/>", self.variable(&p).unwrap().vr);
                        }
                    }
                }
                let _ = writeln!(w, "    </{}>", v.ty);
            }
        }
        w.push_str("  </ModelVariables>\n  <ModelStructure>\n");
        let mut outputs: Vec<&Variable> = self.variables.iter().filter(|v| v.causality == "output").collect();
        outputs.sort_by_key(|v| v.vr);
        for v in &outputs {
            let _ = writeln!(w, "    <Output valueReference=\"{}\"{}/>", v.vr, self.dependencies(v));
        }
        let mut initial: Vec<&Variable> = self.variables.iter().filter(|v| v.causality == "output" || v.causality == "calculatedParameter").collect();
        initial.sort_by_key(|v| v.vr);
        for v in &initial {
            let _ = writeln!(w, "    <InitialUnknown valueReference=\"{}\"{}/>", v.vr, self.dependencies(v));
        }
        w.push_str("  </ModelStructure>\n</fmiModelDescription>\n");
        Ok(x)
    }

    /// The `dependencies` attribute of an output in ModelStructure: the
    /// inputs it declares in `depends_on` (none: it depends on the inputs
    /// only through the state, so chained FMUs form no algebraic loop). No
    /// attribute (every known) where the table declares nothing or has no input.
    fn dependencies(&self, v: &Variable) -> String {
        match &v.depends_on {
            Some(deps) if self.variables.iter().any(|x| x.causality == "input") => {
                let vrs: Vec<String> = deps.iter().map(|d| self.variable(d).unwrap().vr.to_string()).collect();
                format!(" dependencies=\"{}\"", vrs.join(" "))
            }
            _ => String::new(),
        }
    }

    /// `resources/startValues.txt`: one line per parameter, `name value...`,
    /// read by the binary at instantiation (importers need not apply the
    /// start values of modelDescription.xml themselves).
    pub fn start_values_text(&self, overrides: &BTreeMap<String, Vec<f64>>) -> Result<String, String> {
        let starts = self.starts(overrides)?;
        let mut t = String::from("# Start values of this FMU, generated with its modelDescription.xml\n");
        for v in self.variables.iter().filter(|v| v.has_start()) {
            let s: Vec<String> = starts[&v.name].iter().map(|x| format!("{x:?}")).collect();
            let _ = writeln!(t, "{} {}", v.name, s.join(" "));
        }
        Ok(t)
    }

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

    /// The README's tables of the variables, the enumerations and the
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

    /// Rust source of the variable table; `include!`d by `src/fmi/variables.rs`,
    /// which defines `Variable`, `Type`, `Causality`, `Variability` and `Dim`.
    pub fn rust_source(&self) -> String {
        let mut r = String::new();
        let _ = writeln!(r, "// Generated by modelDescription/generate.rs from variables.toml. Do not edit.");
        let _ = writeln!(r, "pub const MODEL_IDENTIFIER: &str = {:?};", self.model_identifier);
        let _ = writeln!(r, "pub const INSTANTIATION_TOKEN: &str = {:?};", self.instantiation_token);
        let cats: Vec<String> = self.log_categories.iter().map(|c| format!("{:?}", c.name)).collect();
        let _ = writeln!(r, "pub const LOG_CATEGORIES: &[&str] = &[{}];", cats.join(", "));
        let _ = writeln!(r, "/// Identifies the variable layout in serialized FMU states.");
        let _ = writeln!(r, "pub const LAYOUT_FINGERPRINT: u64 = {:#018x};", self.fingerprint());
        let _ = writeln!(r, "/// Value references.\npub mod vr {{");
        for v in &self.variables {
            let _ = writeln!(r, "    pub const {}: u32 = {};", screaming(&v.name), v.vr);
        }
        r.push_str("}\n\npub static VARIABLES: &[Variable] = &[\n");
        for v in &self.variables {
            let ty = if v.ty == "Enumeration" { "Int64".to_string() } else { v.ty.clone() };
            let enum_values: Vec<String> = v
                .declared_type
                .as_ref()
                .and_then(|t| self.enumerations.iter().find(|e| &e.name == t))
                .map(|e| e.items.iter().map(|i| i.value.to_string()).collect())
                .unwrap_or_default();
            let start: Vec<String> = v.start_numbers().iter().map(|x| format!("{x:?}")).collect();
            let dims: Vec<String> = v
                .dims()
                .iter()
                .map(|d| match d {
                    Dim::Fixed(n) => format!("Dim::Fixed({n})"),
                    Dim::Param(p) => format!("Dim::Param({})", self.variable(p).unwrap().vr),
                })
                .collect();
            let _ = writeln!(
                r,
                "    Variable {{ name: {:?}, vr: {}, ty: Type::{ty}, causality: Causality::{}, variability: Variability::{}, \
                 start: &[{}], min: {}, max: {}, dims: &[{}], enum_values: &[{}] }},",
                v.name,
                v.vr,
                camel(&v.causality),
                camel(&v.variability),
                start.join(", "),
                opt(v.min),
                opt(v.max),
                dims.join(", "),
                enum_values.join(", ")
            );
        }
        r.push_str("];\n\n/// The canonical scenes: start values that differ from the defaults.\npub static SCENES: &[CanonicalScene] = &[\n");
        for name in self.scene_names() {
            let values: Vec<String> = self
                .scene(&name)
                .unwrap()
                .iter()
                .map(|(var, x)| {
                    let numbers: Vec<String> = x.iter().map(|v| format!("{v:?}")).collect();
                    format!("({}, &[{}])", self.variable(var).unwrap().vr, numbers.join(", "))
                })
                .collect();
            let _ = writeln!(r, "    CanonicalScene {{ name: {name:?}, values: &[{}] }},", values.join(", "));
        }
        r.push_str("];\n");
        r
    }

    /// Rust source of the option enumerations (one Rust enum per
    /// `[[enumerations]]` table, one variant per item, named in CamelCase
    /// from the item's name); `include!`d by `src/options.rs`.
    pub fn options_source(&self) -> String {
        let mut r = String::new();
        let _ = writeln!(r, "// Generated by modelDescription/generate.rs from variables.toml. Do not edit.");
        for e in &self.enumerations {
            let name = &e.name;
            let variants: Vec<String> = e.items.iter().map(|i| variant(&i.name)).collect();
            let _ = writeln!(r, "\n/// {}\n#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]\npub enum {name} {{", e.description);
            for (i, v) in e.items.iter().zip(&variants) {
                let _ = writeln!(r, "    /// `{}` ({}): {}\n    {v} = {},", i.name, i.value, i.description, i.value);
            }
            let _ = writeln!(r, "}}\n\nimpl {name} {{");
            let all: Vec<String> = variants.iter().map(|v| format!("{name}::{v}")).collect();
            let _ = writeln!(r, "    /// Every item, in the order of the variable table.\n    pub const ALL: &'static [{name}] = &[{}];", all.join(", "));
            let _ = writeln!(
                r,
                "    /// The item with this value in the model description.\n    pub fn from_value(value: i64) -> Option<Self> {{\n        match value {{"
            );
            for (i, v) in e.items.iter().zip(&variants) {
                let _ = writeln!(r, "            {} => Some({name}::{v}),", i.value);
            }
            let _ = writeln!(r, "            _ => None,\n        }}\n    }}");
            let _ = writeln!(r, "    /// The value of the item in the model description.\n    pub fn value(self) -> i64 {{\n        self as i64\n    }}");
            let _ = writeln!(r, "    /// The name of the item in the model description.\n    pub fn name(self) -> &'static str {{\n        match self {{");
            for (i, v) in e.items.iter().zip(&variants) {
                let _ = writeln!(r, "            {name}::{v} => {:?},", i.name);
            }
            let _ = writeln!(r, "        }}\n    }}\n}}");
        }
        r
    }

    fn fingerprint(&self) -> u64 {
        let mut s = String::new();
        for v in &self.variables {
            let _ = write!(s, "{}|{}|{}|{}|{}|{:?};", v.name, v.vr, v.ty, v.causality, v.variability, v.dims());
        }
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for b in s.bytes() {
            h ^= b as u64;
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
        h
    }
}

/// Markers of the generated tables in README.md.
pub const README_BEGIN: &str = "<!-- variables: generated from modelDescription/variables.toml by `cargo xtask docs` -->";
pub const README_END: &str = "<!-- end of generated variables -->";

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

/// Repeats the first element (or 0) to reach `size`, keeping what is there.
pub fn fit(values: &mut Vec<f64>, size: usize) {
    let fill = values.first().copied().unwrap_or(0.0);
    values.resize(size, fill);
}

fn number(ty: &str, x: f64) -> String {
    match ty {
        "Boolean" => (if x != 0.0 { "true" } else { "false" }).to_string(),
        "UInt64" | "Enumeration" => format!("{}", x as i64),
        _ => format!("{x:?}"),
    }
}

fn opt(x: Option<f64>) -> String {
    match x {
        Some(v) => format!("Some({v:?})"),
        None => "None".to_string(),
    }
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

fn camel(s: &str) -> String {
    let mut c = s.chars();
    match c.next() {
        Some(f) => f.to_ascii_uppercase().to_string() + c.as_str(),
        None => String::new(),
    }
}

/// `newmark-explicit` -> `NewmarkExplicit`.
fn variant(item: &str) -> String {
    item.split(['-', '_', ' ']).map(camel).collect()
}

fn screaming(s: &str) -> String {
    let mut out = String::new();
    for (i, ch) in s.chars().enumerate() {
        if ch.is_ascii_uppercase() && i > 0 {
            out.push('_');
        }
        out.push(ch.to_ascii_uppercase());
    }
    out
}
