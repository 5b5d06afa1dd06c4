//! terminalsAndIcons/terminalsAndIcons.xml (FMI 3.0, section 2.4.9): the
//! sheet's holders and its load node as terminals, found in the table by
//! the names of their variables, as an `Fmi3TerminalsAndIcons` of the
//! `fmi-schema` crate, serialized by it. The convention and the choice of
//! `matchingRule`, `terminalKind` and `variableKind` are in docs/terminals.md.
//!
//! - Holder 1 is `anchorX`, `anchorY`, `anchorZ`, `anchorRX`, `anchorRY`,
//!   `anchorRZ` (inputs) and `anchorForceX/Y/Z`, `anchorTorqueX/Y/Z`
//!   (outputs); holder k ≥ 2 the same names with k after `anchor`
//!   (`anchor2X`, `anchor2ForceY`). Every holder with a variable in the
//!   table is a terminal `holder{k}`, in the order of k.
//! - The load node is `loadX/Y/Z` (inputs) and `loadNodeX/Y/Z`,
//!   `loadNodeVX/VY/VZ` (outputs): the terminal `loadNode`.
//!
//! A group with some of its variables in the table but not all, or one
//! with the wrong type, shape or causality, is an error: the FMU is not
//! built.
//!
//! Not declared by `generate.rs`, like `generate/xml.rs`: it needs
//! `fmi-schema`, which the build script does not have. The xtask and
//! `tests/terminals.rs` include it beside `generate.rs`, which they include
//! as the crate-root module `generate`.

use std::collections::BTreeSet;

use fmi_schema::fmi3 as md;

use crate::generate::Spec;

/// One member of a terminal: the variable's name after its group's prefix,
/// the member name, the `variableKind` and the causality the variable must have.
type Member = (&'static str, &'static str, &'static str, &'static str);

/// A holder's members, after `anchor` (holder 1) or `anchor{k}`.
pub const HOLDER: [Member; 12] = [
    ("X", "x", "signal", "input"),
    ("Y", "y", "signal", "input"),
    ("Z", "z", "signal", "input"),
    ("RX", "rx", "signal", "input"),
    ("RY", "ry", "signal", "input"),
    ("RZ", "rz", "signal", "input"),
    ("ForceX", "forceX", "outflow", "output"),
    ("ForceY", "forceY", "outflow", "output"),
    ("ForceZ", "forceZ", "outflow", "output"),
    ("TorqueX", "torqueX", "outflow", "output"),
    ("TorqueY", "torqueY", "outflow", "output"),
    ("TorqueZ", "torqueZ", "outflow", "output"),
];

/// The load node's members (whole variable names).
pub const LOAD_NODE: [Member; 9] = [
    ("loadX", "forceX", "inflow", "input"),
    ("loadY", "forceY", "inflow", "input"),
    ("loadZ", "forceZ", "inflow", "input"),
    ("loadNodeX", "x", "signal", "output"),
    ("loadNodeY", "y", "signal", "output"),
    ("loadNodeZ", "z", "signal", "output"),
    ("loadNodeVX", "vx", "signal", "output"),
    ("loadNodeVY", "vy", "signal", "output"),
    ("loadNodeVZ", "vz", "signal", "output"),
];

/// Members are matched by name, and a connection may leave some out: a
/// holder joined to a load node (a point, which takes no torque) connects
/// x, y, z and forceX, forceY, forceZ.
pub const MATCHING_RULE: &str = "bus";
/// Vendor-specific kinds (FMI 3.0: they start with `_vendorName` or `_toolName`).
pub const HOLDER_KIND: &str = "_ModalMassSpring_holder";
pub const LOAD_NODE_KIND: &str = "_ModalMassSpring_loadNode";

/// The prefix of holder k's variables.
pub fn holder_prefix(k: u32) -> String {
    if k == 1 {
        "anchor".into()
    } else {
        format!("anchor{k}")
    }
}

impl Spec {
    /// The numbers of the holders with a variable in the table, ascending:
    /// 1 for `anchorX` and its group, k for `anchor{k}X` and its group
    /// (k ≥ 2, written without leading zeros).
    pub fn holders(&self) -> Result<Vec<u32>, String> {
        let mut found = BTreeSet::new();
        for v in &self.variables {
            let Some(rest) = v.name.strip_prefix("anchor") else { continue };
            let digits = rest.len() - rest.trim_start_matches(|c: char| c.is_ascii_digit()).len();
            let (number, suffix) = rest.split_at(digits);
            if !HOLDER.iter().any(|m| m.0 == suffix) {
                continue;
            }
            let k = match number {
                "" => 1,
                n => match n.parse::<u32>() {
                    Ok(k) if k >= 2 && n == k.to_string() => k,
                    _ => return Err(format!("{}: holder numbers run from 2 without leading zeros (holder 1 is anchor{suffix})", v.name)),
                },
            };
            found.insert(k);
        }
        Ok(found.into_iter().collect())
    }

    /// The terminals: one per holder, then the load node's.
    pub fn terminals(&self) -> Result<Vec<md::Terminal>, String> {
        let mut out = Vec::new();
        for k in self.holders()? {
            let prefix = holder_prefix(k);
            let members: Vec<(String, &Member)> = HOLDER.iter().map(|m| (format!("{prefix}{}", m.0), m)).collect();
            let description = format!(
                "Holder {k}: {prefix}X, {prefix}Y, {prefix}Z, its displacement, and {prefix}RX, {prefix}RY, {prefix}RZ, its rotation vector (inputs); \
                 {prefix}ForceX/Y/Z and {prefix}TorqueX/Y/Z, the force and torque the sheet exerts on it (outputs)"
            );
            out.push(self.terminal(&format!("holder{k}"), HOLDER_KIND, description, &members)?);
        }
        let members: Vec<(String, &Member)> = LOAD_NODE.iter().map(|m| (m.0.to_string(), m)).collect();
        if members.iter().any(|(name, _)| self.variable(name).is_some()) {
            let description = "The load node (loadRow, loadColumn): loadX, loadY, loadZ, the point load on it (inputs); \
                               loadNodeX/Y/Z and loadNodeVX/VY/VZ, its position and velocity (outputs)";
            out.push(self.terminal("loadNode", LOAD_NODE_KIND, description.into(), &members)?);
        }
        Ok(out)
    }

    /// One terminal; every member must be a scalar Float64 of its causality.
    fn terminal(&self, name: &str, kind: &str, description: String, members: &[(String, &Member)]) -> Result<md::Terminal, String> {
        let missing: Vec<&str> = members.iter().filter(|(v, _)| self.variable(v).is_none()).map(|(v, _)| v.as_str()).collect();
        if !missing.is_empty() {
            return Err(format!("terminal {name}: the table has some of its variables but not {}", missing.join(", ")));
        }
        let mut variables = Vec::new();
        for (variable, &(_, member, variable_kind, causality)) in members {
            let v = self.variable(variable).unwrap();
            if v.ty != "Float64" || !v.dimensions.is_empty() || v.causality != causality {
                return Err(format!("terminal {name}: {variable} must be a scalar Float64 {causality} (member {member}, {variable_kind})"));
            }
            variables.push(md::TerminalMemberVariable {
                variable_name: variable.clone(),
                member_name: Some(member.into()),
                variable_kind: variable_kind.into(),
                annotations: None,
            });
        }
        Ok(md::Terminal {
            name: name.into(),
            matching_rule: MATCHING_RULE.into(),
            terminal_kind: Some(kind.into()),
            description: Some(description),
            terminal_member_variables: variables,
            ..Default::default()
        })
    }

    /// terminalsAndIcons/terminalsAndIcons.xml: the terminals (no
    /// `Terminals` element when there is none: the schema wants one or
    /// more in it), no icon.
    pub fn terminals_and_icons_xml(&self) -> Result<String, String> {
        let terminals = self.terminals()?;
        let doc = md::Fmi3TerminalsAndIcons {
            fmi_version: "3.0".into(),
            terminals: (!terminals.is_empty()).then_some(md::Terminals { terminals }),
            annotations: None,
        };
        Ok(fmi_schema::serialize(&doc, false).map_err(|e| format!("terminalsAndIcons.xml: {e}"))? + "\n")
    }
}
