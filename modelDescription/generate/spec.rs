//! The parser of `variables.toml`: the serde structs of the table, the
//! checks a valid table passes, and the start values of an FMU (defaults,
//! a canonical scene's overrides, arrays fitted to their sizes).

use std::collections::BTreeMap;
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
    /// The serialized-state format that added it (absent: format 5 or
    /// earlier): states of an earlier format, which lack it, start it at its start value.
    #[serde(default)]
    pub since_format: Option<u32>,
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
/// The boolean capability flags of the FMI 3.0 `CoSimulation` element.
pub const CO_SIMULATION_FLAGS: [&str; 13] = [
    "needsExecutionTool",
    "canBeInstantiatedOnlyOncePerProcess",
    "canGetAndSetFMUState",
    "canSerializeFMUState",
    "providesDirectionalDerivatives",
    "providesAdjointDerivatives",
    "providesPerElementDependencies",
    "canHandleVariableCommunicationStepSize",
    "providesIntermediateUpdate",
    "mightReturnEarlyFromDoStep",
    "canReturnEarlyAfterIntermediateUpdate",
    "hasEventMode",
    "providesEvaluateDiscreteStates",
];
/// The exponents of the FMI 3.0 `BaseUnit` element (the SI base units and rad).
pub const BASE_UNITS: [&str; 8] = ["kg", "m", "s", "A", "K", "mol", "cd", "rad"];

impl Spec {
    fn check(&self) -> Result<(), String> {
        if let Some(k) = self.co_simulation.keys().find(|k| !CO_SIMULATION_FLAGS.contains(&k.as_str())) {
            return Err(format!("co_simulation: {k} is not a capability flag of FMI 3.0 CoSimulation"));
        }
        for u in &self.units {
            if let Some(k) = u.base.keys().find(|k| !BASE_UNITS.contains(&k.as_str())) {
                return Err(format!("unit {}: {k} is not a base unit (one of {})", u.name, BASE_UNITS.join(", ")));
            }
        }
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
}

/// Repeats the first element (or 0) to reach `size`, keeping what is there.
pub fn fit(values: &mut Vec<f64>, size: usize) {
    let fill = values.first().copied().unwrap_or(0.0);
    values.resize(size, fill);
}
