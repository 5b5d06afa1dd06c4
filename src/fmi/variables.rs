//! The variable table generated from `modelDescription/variables.toml`.

// The table's bounds are the decimal values of the TOML file (one of them is
// pi/2 written out), which clippy takes for approximated constants.
#![allow(clippy::approx_constant)]

/// How a variable is accessed (enumerations use `Int64`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Type {
    Float64,
    Int64,
    UInt64,
    Boolean,
}

impl Type {
    pub fn name(self) -> &'static str {
        match self {
            Type::Float64 => "Float64",
            Type::Int64 => "Int64",
            Type::UInt64 => "UInt64",
            Type::Boolean => "Boolean",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Causality {
    Independent,
    StructuralParameter,
    Parameter,
    CalculatedParameter,
    Input,
    Output,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variability {
    Fixed,
    Tunable,
    Continuous,
}

/// One array dimension: fixed, or the value of the structural parameter with this value reference.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dim {
    Fixed(usize),
    Param(u32),
}

#[derive(Debug)]
pub struct Variable {
    pub name: &'static str,
    pub vr: u32,
    pub ty: Type,
    pub causality: Causality,
    pub variability: Variability,
    /// Start values (booleans as 0/1); arrays sized by structural parameters
    /// are fitted by repeating the first element.
    pub start: &'static [f64],
    /// Range of the model description (inclusive), enforced by every setter,
    /// by startValues.txt and by deserialization.
    pub min: Option<f64>,
    pub max: Option<f64>,
    pub dims: &'static [Dim],
    /// Allowed values of an enumeration (empty otherwise).
    pub enum_values: &'static [i64],
}

impl Variable {
    /// Parameters and inputs hold a value in the instance (set by the host,
    /// part of every FMU state); the rest come from the simulator.
    pub fn holds_value(&self) -> bool {
        matches!(self.causality, Causality::StructuralParameter | Causality::Parameter | Causality::Input)
    }
}

/// A canonical scene: the start values that differ from the defaults.
#[derive(Debug)]
pub struct CanonicalScene {
    pub name: &'static str,
    /// (value reference, values).
    pub values: &'static [(u32, &'static [f64])],
}

include!(concat!(env!("OUT_DIR"), "/variables.rs"));

/// Names of the canonical scenes.
pub fn scene_names() -> impl Iterator<Item = &'static str> {
    SCENES.iter().map(|s| s.name)
}

/// Index into [`VARIABLES`] of a value reference.
pub fn index_of(vr: u32) -> Option<usize> {
    VARIABLES.iter().position(|v| v.vr == vr)
}
