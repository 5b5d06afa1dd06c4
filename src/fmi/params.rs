//! The values of the parameters and inputs of an instance, stored by the
//! glue against the generated variable table: what the host set, what an
//! FMU state holds, what fmi3Reset goes back to. What the values mean is
//! the model's ([`super::model::Model`]).

use super::variables::{index_of, Dim, Variability, Variable, VARIABLES};

/// Current values of the parameters and inputs, indexed like [`VARIABLES`]
/// (empty for the other variables). Booleans are 0/1, integers exact
/// (range-checked), enumerations their item values.
#[derive(Clone, Debug, PartialEq)]
pub struct Params {
    pub values: Vec<Vec<f64>>,
}

impl Params {
    /// Start values, arrays fitted to the start values of their structural parameters.
    pub fn start() -> Self {
        let mut p = Params { values: VARIABLES.iter().map(|v| if v.holds_value() { v.start.to_vec() } else { Vec::new() }).collect() };
        p.fit_arrays();
        p
    }

    /// Start values from `resources/startValues.txt` (`name value...` per
    /// line, written by `cargo xtask fmu`); variables not listed keep their
    /// compiled start value. Every value is range-checked.
    pub fn from_text(text: &str) -> Result<Self, String> {
        let mut p = Params::start();
        for line in text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')) {
            let mut words = line.split_whitespace();
            let name = words.next().unwrap();
            let i = VARIABLES.iter().position(|v| v.name == name && v.holds_value()).ok_or(format!("{name} is not a parameter or input"))?;
            let values = words.map(|w| w.parse::<f64>().map_err(|_| format!("{name}: {w} is not a number"))).collect::<Result<Vec<_>, _>>()?;
            for x in &values {
                super::values::check_value(&VARIABLES[i], Some(*x)).map_err(|m| format!("{name} = {x}: {m}"))?;
            }
            p.values[i] = values;
        }
        for (i, v) in VARIABLES.iter().enumerate().filter(|(_, v)| v.holds_value() && v.dims.is_empty()) {
            if p.values[i].len() != 1 {
                return Err(format!("{} needs one value", v.name));
            }
        }
        for (i, v) in VARIABLES.iter().enumerate().filter(|(_, v)| v.holds_value() && !v.dims.is_empty()) {
            if p.values[i].len() != p.size_of(v) {
                if v.dims.iter().any(|d| matches!(d, Dim::Param(_))) && !text.lines().any(|l| l.split_whitespace().next() == Some(v.name)) {
                    continue; // fitted below
                }
                return Err(format!("{} needs {} values, got {}", v.name, p.size_of(v), p.values[i].len()));
            }
        }
        p.fit_arrays();
        Ok(p)
    }

    pub fn get(&self, vr: u32) -> &[f64] {
        &self.values[index_of(vr).expect("known value reference")]
    }

    /// Sets the values of `vr` (unchecked; for tests and the study) and
    /// fits the arrays a structural parameter sizes.
    pub fn set(&mut self, vr: u32, values: &[f64]) {
        self.values[index_of(vr).expect("known value reference")] = values.to_vec();
        self.fit_arrays();
    }

    pub fn scalar(&self, vr: u32) -> f64 {
        self.get(vr)[0]
    }

    /// A count (a UInt64 value, range-checked when set).
    pub fn count(&self, vr: u32) -> usize {
        self.scalar(vr) as usize
    }

    /// Current number of elements of `v`.
    pub fn size_of(&self, v: &Variable) -> usize {
        v.dims
            .iter()
            .map(|d| match *d {
                Dim::Fixed(n) => n,
                Dim::Param(p) => self.count(p),
            })
            .product()
    }

    /// Resizes parameter arrays after a structural parameter changed: the
    /// existing prefix is kept, new elements repeat the first start value.
    pub fn fit_arrays(&mut self) {
        for (i, v) in VARIABLES.iter().enumerate() {
            if v.holds_value() && !v.dims.is_empty() {
                let n = self.size_of(v);
                if self.values[i].len() != n {
                    let fill = v.start.first().copied().unwrap_or(0.0);
                    self.values[i].resize(n, fill);
                }
            }
        }
    }

    /// True if the fixed values (structural and fixed parameters: what the
    /// set-up depends on) of the two are the same.
    pub fn same_fixed(&self, other: &Params) -> bool {
        VARIABLES.iter().enumerate().filter(|(_, v)| v.holds_value() && v.variability == Variability::Fixed).all(|(i, _)| self.values[i] == other.values[i])
    }
}
