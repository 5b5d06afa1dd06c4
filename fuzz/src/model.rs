//! The variables of the FMU, read from modelDescription/variables.toml (the
//! file the FMU's variable table and modelDescription.xml are generated from).

use std::sync::OnceLock;

const SPEC: &str = include_str!("../../modelDescription/variables.toml");

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Dim {
    Fixed(u64),
    /// Sized by the structural parameter with this value reference.
    Param(u32),
}

#[derive(Debug)]
pub struct Variable {
    pub name: String,
    pub vr: u32,
    /// Float64, UInt64, Boolean or Enumeration (accessed as Int64).
    pub ty: String,
    pub dims: Vec<Dim>,
}

pub struct Model {
    pub instantiation_token: String,
    pub variables: Vec<Variable>,
}

fn value(line: &str, key: &str) -> Option<String> {
    let rest = line.strip_prefix(key)?.trim_start().strip_prefix('=')?.trim();
    Some(rest.to_string())
}

fn unquote(s: &str) -> String {
    s.trim().trim_matches('"').to_string()
}

/// The `[[variables]]` tables: `name`, `vr`, `type` and `dimensions`.
pub fn model() -> &'static Model {
    static M: OnceLock<Model> = OnceLock::new();
    M.get_or_init(|| {
        let token = SPEC.lines().find_map(|l| value(l, "instantiation_token")).map(|v| unquote(&v)).expect("instantiation_token");
        let mut raw: Vec<(String, u32, String, Vec<String>)> = Vec::new();
        let mut inside = false;
        for line in SPEC.lines().map(str::trim) {
            if line.starts_with('[') {
                inside = line == "[[variables]]";
                if inside {
                    raw.push((String::new(), u32::MAX, String::new(), Vec::new()));
                }
                continue;
            }
            let Some(v) = raw.last_mut().filter(|_| inside) else { continue };
            if let Some(x) = value(line, "name") {
                v.0 = unquote(&x);
            } else if let Some(x) = value(line, "vr") {
                v.1 = x.parse().expect("vr");
            } else if let Some(x) = value(line, "type") {
                v.2 = unquote(&x);
            } else if let Some(x) = value(line, "dimensions") {
                v.3 = x.trim_matches(|c| c == '[' || c == ']').split(',').map(unquote).filter(|d| !d.is_empty()).collect();
            }
        }
        let vr_of = |n: &str| raw.iter().find(|v| v.0 == n).unwrap_or_else(|| panic!("dimension {n}")).1;
        let variables = raw
            .iter()
            .map(|(name, vr, ty, dims)| Variable {
                name: name.clone(),
                vr: *vr,
                ty: ty.clone(),
                dims: dims.iter().map(|d| d.parse().map(Dim::Fixed).unwrap_or_else(|_| Dim::Param(vr_of(d)))).collect(),
            })
            .collect::<Vec<_>>();
        assert!(variables.len() > 10 && variables.iter().all(|v| v.vr != u32::MAX && !v.ty.is_empty()));
        Model { instantiation_token: token, variables }
    })
}

/// Value reference of the variable called `name`.
pub fn vr(name: &str) -> u32 {
    model().variables.iter().find(|v| v.name == name).unwrap_or_else(|| panic!("no variable {name}")).vr
}
