//! terminalsAndIcons/terminalsAndIcons.xml, generated from
//! modelDescription/variables.toml (modelDescription/generate/terminals.rs,
//! the convention in docs/terminals.md): one terminal per holder found in
//! the table by the names of its variables, one for the load node; every
//! member a variable of the binary's table with the causality its kind
//! needs; parsed back with fmi-schema, resolved against the model
//! description, and (feature `xsd`) valid against the FMI 3.0 schema.

// The generator, declared at the test crate's root (tests/suite.rs).
use crate::generate;

use std::collections::BTreeMap;

use fmi_schema::fmi3::{resolve_terminals, Fmi3ModelDescription, Fmi3TerminalsAndIcons, Terminal};
use modal_mass_spring::fmi::variables::{Causality, VARIABLES};

fn table() -> String {
    std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("modelDescription/variables.toml")).unwrap()
}

/// The table with `extra` variables appended (its scenes dropped).
fn with(extra: &str) -> Result<generate::Spec, String> {
    let text = table();
    let (head, _) = text.split_once("\n[scenes.").unwrap();
    generate::parse(&format!("{head}\n{extra}"))
}

/// Holder 1's variables after `anchor`, and the causality of each.
const HOLDER: [(&str, &str); 12] = [
    ("X", "input"),
    ("Y", "input"),
    ("Z", "input"),
    ("RX", "input"),
    ("RY", "input"),
    ("RZ", "input"),
    ("ForceX", "output"),
    ("ForceY", "output"),
    ("ForceZ", "output"),
    ("TorqueX", "output"),
    ("TorqueY", "output"),
    ("TorqueZ", "output"),
];

/// Table entries of holder k's variables (`groups` of HOLDER, or another
/// list), value references from 100000 + 100 k.
fn holder_entries(k: u32, groups: &[(&str, &str)]) -> String {
    let mut s = String::new();
    for (i, (suffix, causality)) in groups.iter().enumerate() {
        let start = if *causality == "input" { "start = 0.0\n" } else { "" };
        s.push_str(&format!(
            "[[variables]]\nname = \"anchor{k}{suffix}\"\nvr = {}\ntype = \"Float64\"\ncausality = \"{causality}\"\nvariability = \"continuous\"\n{start}description = \"Holder {k}, {suffix}\"\n\n",
            100_000 + 100 * k + i as u32
        ));
    }
    s
}

fn parse(xml: &str) -> Fmi3TerminalsAndIcons {
    fmi_schema::deserialize(xml).unwrap_or_else(|e| panic!("{e}\n{xml}"))
}

fn terminals(doc: &Fmi3TerminalsAndIcons) -> &[Terminal] {
    &doc.terminals.as_ref().expect("no Terminals element").terminals
}

/// (variableName, memberName, variableKind) of each member.
fn members(t: &Terminal) -> Vec<(&str, &str, &str)> {
    t.terminal_member_variables.iter().map(|m| (m.variable_name.as_str(), m.member_name.as_deref().unwrap(), m.variable_kind.as_str())).collect()
}

/// Every member names a variable of `spec` with the causality its kind
/// needs, and the model description of `spec` resolves every member.
fn check_against(spec: &generate::Spec, doc: &Fmi3TerminalsAndIcons) {
    for t in terminals(doc) {
        t.validate_matching_rule().unwrap();
        for (variable, member, kind) in members(t) {
            let v = spec.variable(variable).unwrap_or_else(|| panic!("{}: {variable} is not in the table", t.name));
            // Kirchhoff's flows: what comes in is set by the importer, what goes out read from the FMU;
            // positions are set on a holder and read from the load node.
            let want = match (kind, t.name.as_str()) {
                ("inflow", _) => "input",
                ("outflow", _) => "output",
                ("signal", "loadNode") => "output",
                ("signal", _) => "input",
                (other, _) => panic!("{}.{member}: unknown variableKind {other}", t.name),
            };
            assert_eq!((v.causality.as_str(), v.ty.as_str()), (want, "Float64"), "{}.{member} ({variable}, {kind})", t.name);
        }
    }
    let md: Fmi3ModelDescription = fmi_schema::deserialize(&spec.model_description_xml(&BTreeMap::new()).unwrap()).unwrap();
    if let Err(e) = resolve_terminals(doc, &md) {
        panic!("{e:?}");
    }
}

#[test]
fn every_holder_and_the_load_node_are_terminals() {
    let spec = generate::parse(&table()).unwrap();
    let xml = spec.terminals_and_icons_xml().unwrap();
    let doc = parse(&xml);
    assert_eq!(doc.fmi_version, "3.0");
    let holders = spec.holders().unwrap();
    assert_eq!(holders.first(), Some(&1), "holder 1 (anchorX, ...) is in the table");
    let mut names: Vec<String> = holders.iter().map(|k| format!("holder{k}")).collect();
    names.push("loadNode".into());
    assert_eq!(terminals(&doc).iter().map(|t| t.name.clone()).collect::<Vec<_>>(), names);
    for t in terminals(&doc) {
        assert_eq!(t.matching_rule, "bus", "{}", t.name);
    }

    let holder1 = &terminals(&doc)[0];
    assert_eq!(holder1.terminal_kind.as_deref(), Some("_ModalMassSpring_holder"));
    assert_eq!(
        members(holder1),
        [
            ("anchorX", "x", "signal"),
            ("anchorY", "y", "signal"),
            ("anchorZ", "z", "signal"),
            ("anchorRX", "rx", "signal"),
            ("anchorRY", "ry", "signal"),
            ("anchorRZ", "rz", "signal"),
            ("anchorForceX", "forceX", "outflow"),
            ("anchorForceY", "forceY", "outflow"),
            ("anchorForceZ", "forceZ", "outflow"),
            ("anchorTorqueX", "torqueX", "outflow"),
            ("anchorTorqueY", "torqueY", "outflow"),
            ("anchorTorqueZ", "torqueZ", "outflow"),
        ]
    );
    let load = terminals(&doc).last().unwrap();
    assert_eq!(load.terminal_kind.as_deref(), Some("_ModalMassSpring_loadNode"));
    assert_eq!(
        members(load),
        [
            ("loadX", "forceX", "inflow"),
            ("loadY", "forceY", "inflow"),
            ("loadZ", "forceZ", "inflow"),
            ("loadNodeX", "x", "signal"),
            ("loadNodeY", "y", "signal"),
            ("loadNodeZ", "z", "signal"),
            ("loadNodeVX", "vx", "signal"),
            ("loadNodeVY", "vy", "signal"),
            ("loadNodeVZ", "vz", "signal"),
        ]
    );
    // Holder k's members are holder 1's with k after "anchor".
    for (t, k) in terminals(&doc).iter().zip(&holders).skip(1) {
        let want: Vec<String> = HOLDER.iter().map(|(suffix, _)| format!("anchor{k}{suffix}")).collect();
        assert_eq!(members(t).iter().map(|m| m.0).collect::<Vec<_>>(), want, "{}", t.name);
        assert_eq!(members(t).iter().map(|m| (m.1, m.2)).collect::<Vec<_>>(), members(holder1).iter().map(|m| (m.1, m.2)).collect::<Vec<_>>());
    }
    check_against(&spec, &doc);

    // The binary's table (compiled from the same file) agrees on every member.
    for t in terminals(&doc) {
        for (variable, member, kind) in members(t) {
            let v = VARIABLES.iter().find(|v| v.name == variable).unwrap_or_else(|| panic!("{variable} is not in the binary"));
            let input = v.causality == Causality::Input;
            assert!(input || v.causality == Causality::Output, "{}.{member}: {variable} is neither input nor output", t.name);
            assert_eq!(input, kind == "inflow" || (kind == "signal" && t.name != "loadNode"), "{}.{member}: {variable}", t.name);
        }
    }
}

#[test]
fn holders_are_found_by_the_names_of_their_variables() {
    let before = generate::parse(&table()).unwrap().holders().unwrap();
    // Two more holders, with a gap between them.
    let last = *before.last().unwrap();
    let (a, b) = (last + 1, last + 3);
    let spec = with(&(holder_entries(a, &HOLDER) + &holder_entries(b, &HOLDER))).unwrap();
    let mut want = before.clone();
    want.extend([a, b]);
    assert_eq!(spec.holders().unwrap(), want);
    let xml = spec.terminals_and_icons_xml().unwrap();
    let doc = parse(&xml);
    let names: Vec<&str> = terminals(&doc).iter().map(|t| t.name.as_str()).collect();
    assert_eq!(names[names.len() - 3..], [format!("holder{a}").as_str(), &format!("holder{b}"), "loadNode"]);
    let hb = &terminals(&doc)[names.len() - 2];
    assert_eq!(members(hb)[0], (format!("anchor{b}X").as_str(), "x", "signal"));
    assert_eq!(members(hb)[11], (format!("anchor{b}TorqueZ").as_str(), "torqueZ", "outflow"));
    check_against(&spec, &doc);
    #[cfg(feature = "xsd")]
    assert_eq!(xsd::problems(&xml), Vec::<String>::new());

    // Other anchor variables (anchorMotion, a parameter of holder 1) are no members.
    assert!(spec.variable("anchorMotion").is_some() && !xml.contains("anchorMotion"));
}

#[test]
fn a_holder_with_a_variable_missing_or_of_the_wrong_causality_is_refused() {
    let k = *generate::parse(&table()).unwrap().holders().unwrap().last().unwrap() + 1;
    let without_torque_z: Vec<_> = HOLDER.iter().copied().filter(|(s, _)| *s != "TorqueZ").collect();
    let e = with(&holder_entries(k, &without_torque_z)).unwrap().terminals_and_icons_xml().unwrap_err();
    assert!(e.contains(&format!("terminal holder{k}")) && e.contains(&format!("anchor{k}TorqueZ")), "{e}");

    let force_as_input: Vec<_> = HOLDER.iter().map(|&(s, c)| if s == "ForceX" { (s, "input") } else { (s, c) }).collect();
    let e = with(&holder_entries(k, &force_as_input)).unwrap().terminals_and_icons_xml().unwrap_err();
    assert!(e.contains(&format!("anchor{k}ForceX must be a scalar Float64 output")), "{e}");

    // Holder 1 has no number; numbers are written plainly.
    for bad in ["1", "01"] {
        let e = with(&holder_entries(0, &[("X", "input")]).replace("anchor0X", &format!("anchor{bad}X"))).unwrap().holders().unwrap_err();
        assert!(e.contains(&format!("anchor{bad}X")), "{e}");
    }
}

/// fmi-rs 0.3 (feature `schema`) validates a document with libxml2 against
/// an XSD, resolving the FMI 3.0 schema files by name from the copies it
/// embeds (its `custom_entity_loader`), but its Rust API offers the model
/// description's schema only. A schema that includes
/// fmi3TerminalsAndIcons.xsd, given to the same C function with the same
/// resolver, validates terminalsAndIcons.xml against the official schema.
#[cfg(feature = "xsd")]
mod xsd {
    use std::ffi::{c_char, c_int, c_void, CStr};

    type Loader = unsafe extern "C" fn(*const c_char, *const c_char, *mut c_void) -> *mut c_void;

    extern "C" {
        fn xmlInitParser();
        fn validate_xml_document(
            document: *const c_char,
            document_size: c_int,
            schema: *const c_char,
            schema_size: c_int,
            messages: *mut *mut *mut c_char,
            loader: Option<Loader>,
        ) -> c_int;
        fn free_messages(len: c_int, messages: *mut *mut c_char);
        fn custom_entity_loader(url: *const c_char, id: *const c_char, ctxt: *mut c_void) -> *mut c_void;
    }

    const SCHEMA: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<xs:schema xmlns:xs="http://www.w3.org/2001/XMLSchema" elementFormDefault="qualified" attributeFormDefault="unqualified">
    <xs:include schemaLocation="fmi3TerminalsAndIcons.xsd"/>
</xs:schema>"#;

    /// What the FMI 3.0 schema finds wrong with `xml`.
    pub fn problems(xml: &str) -> Vec<String> {
        let mut messages = std::ptr::null_mut();
        // SAFETY: buffers with their lengths; the messages are read, then freed by the library that made them.
        unsafe {
            xmlInitParser();
            let n = validate_xml_document(
                xml.as_ptr().cast(),
                xml.len() as c_int,
                SCHEMA.as_ptr().cast(),
                SCHEMA.len() as c_int,
                &mut messages,
                Some(custom_entity_loader),
            );
            let out = (0..n.max(0) as usize).map(|i| CStr::from_ptr(*messages.add(i)).to_string_lossy().trim_end().to_string()).collect();
            if n > 0 {
                free_messages(n, messages);
            }
            out
        }
    }
}

/// XSD validation (fmi-rs `schema` feature): `cargo test --features xsd`,
/// which `cargo xtask test` runs.
#[cfg(feature = "xsd")]
#[test]
fn validates_against_the_fmi3_xsd() {
    let xml = generate::parse(&table()).unwrap().terminals_and_icons_xml().unwrap();
    assert_eq!(xsd::problems(&xml), Vec::<String>::new());
    // The check can fail: a member without its required variableKind, a terminal without its matchingRule.
    for broken in [xml.replacen(r#" variableKind="signal""#, "", 1), xml.replacen(r#" matchingRule="bus""#, "", 1)] {
        assert_ne!(broken, xml);
        let problems = xsd::problems(&broken);
        assert!(!problems.is_empty(), "{broken}");
        println!("{problems:?}");
    }
}
