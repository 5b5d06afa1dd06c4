//! The model description generated from modelDescription/variables.toml:
//! parsed back with fmi-schema, checked with fmi-rs (the checks of
//! `fmusim validate`), compared with the variable table compiled into the
//! binary, and the canonical scenes compared with those of docs/method.md.

// The generator and Spec::model_description_xml (written with fmi-schema),
// declared at the test crate's root (tests/suite.rs), where they expect to be.
use crate::generate;

use std::collections::BTreeMap;

use fmi_schema::fmi3::Fmi3ModelDescription;
use modal_mass_spring::fmi::variables::{self, vr, Causality, Type, VARIABLES};
use modal_mass_spring::model::Params;
use modal_mass_spring::options::{FixedNodes, Integrator};

fn spec() -> generate::Spec {
    generate::load(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("modelDescription/variables.toml")).unwrap()
}

/// The default description and one per canonical scene.
fn descriptions() -> Vec<(String, String)> {
    let spec = spec();
    let mut out = vec![("default".to_string(), spec.model_description_xml(&BTreeMap::new()).unwrap())];
    for name in variables::scene_names() {
        let o = spec.scene(name).unwrap_or_else(|| panic!("scene {name} missing from variables.toml"));
        out.push((name.to_string(), spec.model_description_xml(&o).unwrap()));
    }
    out
}

#[test]
fn parses_with_fmi_schema_and_matches_the_binary() {
    for (name, xml) in descriptions() {
        let md: Fmi3ModelDescription = fmi_schema::deserialize(&xml).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(md.model_name, "ModalMassSpring");
        assert_eq!(md.instantiation_token, variables::INSTANTIATION_TOKEN);
        assert!(md.co_simulation.is_some(), "{name}: no CoSimulation element");
        assert!(md.model_exchange.is_none() && md.scheduled_execution.is_none());
        let parsed: BTreeMap<u32, String> = md.model_variables.iter_abstract().map(|v| (v.value_reference(), v.name().to_string())).collect();
        for v in VARIABLES.iter().filter(|v| v.ty != Type::Int64) {
            assert_eq!(parsed.get(&v.vr), Some(&v.name.to_string()), "{name}: {} (vr {})", v.name, v.vr);
        }
    }
}

#[test]
fn every_variable_of_the_xml_is_in_the_binary_table() {
    // Attribute-level comparison with a plain XML reader: catches any drift,
    // enumerations included.
    for (name, xml) in descriptions() {
        let md = fmi_rs::model_description::fmi3::ModelDescription::from_string(&xml).unwrap();
        assert_eq!(md.modelVariables.len(), VARIABLES.len(), "{name}");
        for (x, v) in md.modelVariables.iter().zip(VARIABLES) {
            assert_eq!((x.name.as_str(), x.valueReference), (v.name, v.vr), "{name}");
        }
    }
}

#[test]
fn validates_with_fmi_rs() {
    for (name, xml) in descriptions() {
        let md = fmi_rs::model_description::fmi3::ModelDescription::from_string(&xml).unwrap_or_else(|e| panic!("{name}: {e:?}"));
        let problems: Vec<String> = md.validate().into_iter().map(|p| p.message).collect();
        assert!(problems.is_empty(), "{name}: {problems:#?}");
    }
}

/// XSD validation (fmi-rs `schema` feature): `cargo test --features xsd`,
/// which `cargo xtask test` runs (linking the system libxml2 where GitHub
/// cannot be reached).
#[cfg(feature = "xsd")]
#[test]
fn validates_against_the_fmi3_xsd() {
    for (name, xml) in descriptions() {
        let problems = fmi_rs::schema::validate_fmi3_model_description(xml.as_bytes());
        assert!(problems.is_empty(), "{name}: {problems:#?}");
    }
    let broken = spec().model_description_xml(&BTreeMap::new()).unwrap().replacen("causality=\"output\"", "causality=\"outlet\"", 1);
    assert!(!fmi_rs::schema::validate_fmi3_model_description(broken.as_bytes()).is_empty());
}

#[test]
fn validation_catches_a_broken_description() {
    // The checks above must be able to fail: a duplicate value reference.
    let xml = spec().model_description_xml(&BTreeMap::new()).unwrap();
    let broken = xml.replacen("valueReference=\"2\"", "valueReference=\"1\"", 1);
    let md = fmi_rs::model_description::fmi3::ModelDescription::from_string(&broken).unwrap();
    assert!(!md.validate().is_empty());
}

/// The canonical scenes of `docs/method.md`, section 5: (name, nx, ny, dimension, fixedNodes, auxStiffness).
const METHOD_SCENES: [(&str, usize, usize, usize, FixedNodes, f64); 4] = [
    ("paper-2d-top-row", 10, 10, 2, FixedNodes::TopRow, 0.0),
    ("paper-2d-top-corners", 10, 10, 2, FixedNodes::TopCorners, 0.0),
    ("paper-3d-sheet", 7, 7, 3, FixedNodes::TopRow, 0.05),
    ("cloth-3d", 30, 30, 3, FixedNodes::TopRow, 0.05),
];

#[test]
fn scene_start_values_are_the_canonical_scenes() {
    let spec = spec();
    assert_eq!(spec.scene_names(), variables::scene_names().collect::<Vec<_>>());
    assert_eq!(variables::SCENES.len(), METHOD_SCENES.len());
    for (name, nx, ny, dim, fixed, aux) in METHOD_SCENES {
        let p = Params::canonical(name).unwrap_or_else(|| panic!("{name} is not a canonical scene"));
        let g = p.grid();
        assert_eq!((g.columns, g.rows, g.dim, g.fixed_nodes, g.aux_stiffness), (nx, ny, dim, fixed, aux), "{name}");
        // The defaults of docs/method.md, section 5.
        assert_eq!((g.spacing, g.node_mass, g.spring_stiffness, g.shear_springs, g.bending_springs), (0.1, 0.01, 50.0, true, false), "{name}");
        // The binary's scene and the XML generator's start values agree.
        let starts = spec.starts(&spec.scene(name).unwrap()).unwrap();
        for v in VARIABLES.iter().filter(|v| v.holds_value()) {
            assert_eq!(starts[v.name], p.get(v.vr), "{name}: {}", v.name);
        }
        assert_eq!(p.get(variables::vr::MODE_WEIGHTS).len(), p.scalar(variables::vr::N_MODES) as usize, "{name}: modeWeights fitted to nModes");
    }
}

#[test]
fn defaults_are_paper_2d_top_row() {
    let mut default = Params::start().grid();
    // auxStiffness acts in 3D only; its default is the 3D default k / 1000.
    assert_eq!(default.aux_stiffness, 0.05);
    default.aux_stiffness = 0.0;
    assert_eq!(default, Params::canonical("paper-2d-top-row").unwrap().grid());
    let p = Params::start();
    assert_eq!(p.get(variables::vr::N_MODES), [2.0]);
    assert_eq!(p.settings().integrator, Integrator::NewmarkExplicit);
    assert_eq!(p.loads().damping_alpha, 0.0);
}

/// A variable table with an input: the generator writes it as FMI 3.0 wants
/// (causality, start value, the outputs' dependencies) and the Rust table marks it.
const WITH_INPUT: &str = r#"
[[variables]]
name = "push"
vr = 990
type = "Float64"
causality = "input"
variability = "continuous"
start = 0.0
unit = "m"
description = "A test input"

[[variables]]
name = "reading"
vr = 991
type = "Float64"
causality = "output"
variability = "continuous"
depends_on = []
description = "An output that depends on no input directly"

[[variables]]
name = "echo"
vr = 992
type = "Float64"
causality = "output"
variability = "continuous"
depends_on = ["push"]
description = "An output that depends on the input directly"

[[variables]]
name = "silent"
vr = 993
type = "Float64"
causality = "output"
variability = "continuous"
description = "An output that declares no dependencies"
"#;

fn spec_with_input() -> Result<generate::Spec, String> {
    let text = std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("modelDescription/variables.toml")).unwrap();
    let (head, scenes) = text.split_once("\n[scenes.").unwrap();
    generate::parse(&format!("{head}\n{WITH_INPUT}\n[scenes.{scenes}"))
}

#[test]
fn inputs_are_generated_end_to_end() {
    let spec = spec_with_input().unwrap();
    let xml = spec.model_description_xml(&BTreeMap::new()).unwrap();
    assert!(xml.contains(r#"name="push" valueReference="990" description="A test input" causality="input" variability="continuous""#), "{xml}");
    assert!(attribute(&xml, "push", "start") == Some(0.0));
    assert!(xml.contains(r#"<Output valueReference="991" dependencies=""/>"#), "{xml}");
    assert!(xml.contains(r#"<Output valueReference="992" dependencies="990"/>"#), "{xml}");
    // Outputs that declare nothing depend on every input.
    assert!(xml.contains(r#"<Output valueReference="993"/>"#), "{xml}");
    let md = fmi_rs::model_description::fmi3::ModelDescription::from_string(&xml).unwrap();
    let problems: Vec<String> = md.validate().into_iter().map(|p| p.message).collect();
    assert!(problems.is_empty(), "{problems:#?}");
    #[cfg(feature = "xsd")]
    {
        let problems = fmi_rs::schema::validate_fmi3_model_description(xml.as_bytes());
        assert!(problems.is_empty(), "{problems:#?}");
    }
    let rust = spec.rust_source();
    assert!(rust.contains(r#"name: "push", vr: 990, ty: Type::Float64, causality: Causality::Input"#), "{rust}");
    // An input is set by the host, so it has a start value and a place in startValues.txt.
    assert!(spec.start_values_text(&BTreeMap::new()).unwrap().contains("\npush 0.0\n"));
    let broken = WITH_INPUT.replacen("start = 0.0\n", "", 1);
    let text = std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("modelDescription/variables.toml")).unwrap();
    let (head, _) = text.split_once("\n[scenes.").unwrap();
    assert!(generate::parse(&format!("{head}\n{broken}")).unwrap_err().contains("push: parameters and inputs"));
}

/// The FMU's own inputs (the point load): every output says which of them
/// it depends on directly, so chained FMUs see no algebraic loop where
/// there is none. Positions and velocities follow the inputs only through
/// the state; the potential energy, the force residual and the holder's
/// force and torque hold the point load's own term (with a reduced basis
/// the share of the load it cannot hold goes straight to the holder).
#[test]
fn every_output_declares_its_dependencies_on_the_point_load() {
    let text = std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("modelDescription/variables.toml")).unwrap();
    let spec = generate::parse(&text).unwrap();
    let xml = spec.model_description_xml(&BTreeMap::new()).unwrap();
    let direct = [
        vr::POTENTIAL_ENERGY,
        vr::FORCE_RESIDUAL,
        vr::ANCHOR_FORCE_X,
        vr::ANCHOR_FORCE_Y,
        vr::ANCHOR_FORCE_Z,
        vr::ANCHOR_TORQUE_X,
        vr::ANCHOR_TORQUE_Y,
        vr::ANCHOR_TORQUE_Z,
    ];
    let mut outputs = 0;
    for v in VARIABLES.iter().filter(|v| v.causality == Causality::Output) {
        let deps = if direct.contains(&v.vr) { format!("{} {} {}", vr::LOAD_X, vr::LOAD_Y, vr::LOAD_Z) } else { String::new() };
        let want = format!(r#"<Output valueReference="{}" dependencies="{deps}"/>"#, v.vr);
        assert!(xml.contains(&want), "{}: {want} not in the model description", v.name);
        outputs += 1;
    }
    assert_eq!(outputs, 40);
}

#[test]
fn c_header_declares_every_export() {
    let h = modal_mass_spring::fmi::C_HEADER;
    let names = [
        "GetVersion",
        "SetDebugLogging",
        "InstantiateModelExchange",
        "InstantiateCoSimulation",
        "InstantiateScheduledExecution",
        "FreeInstance",
        "EnterInitializationMode",
        "ExitInitializationMode",
        "EnterEventMode",
        "Terminate",
        "Reset",
        "GetFloat32",
        "GetFloat64",
        "GetInt8",
        "GetUInt8",
        "GetInt16",
        "GetUInt16",
        "GetInt32",
        "GetUInt32",
        "GetInt64",
        "GetUInt64",
        "GetBoolean",
        "GetString",
        "GetBinary",
        "GetClock",
        "SetFloat32",
        "SetFloat64",
        "SetInt8",
        "SetUInt8",
        "SetInt16",
        "SetUInt16",
        "SetInt32",
        "SetUInt32",
        "SetInt64",
        "SetUInt64",
        "SetBoolean",
        "SetString",
        "SetBinary",
        "SetClock",
        "GetNumberOfVariableDependencies",
        "GetVariableDependencies",
        "GetFMUState",
        "SetFMUState",
        "FreeFMUState",
        "SerializedFMUStateSize",
        "SerializeFMUState",
        "DeserializeFMUState",
        "GetDirectionalDerivative",
        "GetAdjointDerivative",
        "EnterConfigurationMode",
        "ExitConfigurationMode",
        "GetIntervalDecimal",
        "GetIntervalFraction",
        "GetShiftDecimal",
        "GetShiftFraction",
        "SetIntervalDecimal",
        "SetIntervalFraction",
        "SetShiftDecimal",
        "SetShiftFraction",
        "EvaluateDiscreteStates",
        "UpdateDiscreteStates",
        "EnterContinuousTimeMode",
        "CompletedIntegratorStep",
        "SetTime",
        "SetContinuousStates",
        "GetContinuousStateDerivatives",
        "GetEventIndicators",
        "GetContinuousStates",
        "GetNominalsOfContinuousStates",
        "GetNumberOfEventIndicators",
        "GetNumberOfContinuousStates",
        "EnterStepMode",
        "GetOutputDerivatives",
        "DoStep",
        "ActivateModelPartition",
    ];
    assert_eq!(names.len(), 75);
    for n in names {
        assert!(h.contains(&format!(" fmi3{n}(")) || h.contains(&format!("*fmi3{n}(")), "fmi3{n} missing from the header");
    }
}

/// Value of attribute `attr` of the element of variable `name` in `xml`.
fn attribute(xml: &str, name: &str, attr: &str) -> Option<f64> {
    let start = xml.find(&format!(" name=\"{name}\""))?;
    let tag = &xml[start..start + xml[start..].find('>')?];
    let at = tag.find(&format!(" {attr}=\""))? + attr.len() + 3;
    let value = &tag[at..at + tag[at..].find('"')?];
    Some(value.parse().unwrap_or_else(|_| panic!("{name}: {attr}={value}")))
}

#[test]
fn ranges_of_the_xml_are_those_the_binary_enforces() {
    let xml = spec().model_description_xml(&BTreeMap::new()).unwrap();
    for v in VARIABLES {
        assert_eq!(attribute(&xml, v.name, "min"), v.min, "{}: min", v.name);
        assert_eq!(attribute(&xml, v.name, "max"), v.max, "{}: max", v.name);
    }
    // Every numeric parameter is bounded on both sides; array sizes from 1 up.
    for v in VARIABLES.iter().filter(|v| v.holds_value() && matches!(v.ty, Type::Float64 | Type::UInt64)) {
        let (lo, hi) = (v.min.unwrap_or_else(|| panic!("{}: no min", v.name)), v.max.unwrap_or_else(|| panic!("{}: no max", v.name)));
        assert!(lo.is_finite() && hi.is_finite() && lo < hi, "{}", v.name);
        if v.causality == variables::Causality::StructuralParameter {
            assert!(lo >= 1.0, "{}", v.name);
        }
    }
}

#[test]
fn a_start_value_outside_its_range_is_refused() {
    let text = std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("modelDescription/variables.toml")).unwrap();
    let broken = text.replacen("start = 0.1\nunit = \"m\"\nmin = 1e-6", "start = 0.0\nunit = \"m\"\nmin = 1e-6", 1);
    assert_ne!(broken, text);
    let e = generate::parse(&broken).unwrap_err();
    assert!(e.contains("spacing: start value 0 is outside its range"), "{e}");
}

/// Every Rust file under `dir`, recursively.
fn rust_files(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            out.extend(rust_files(&p));
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
    out
}

#[test]
fn the_physics_core_names_no_fmi_variable() {
    // The names that are the FMU's own (camelCase, or the grid's nx and ny);
    // plain words such as "gravity" or "spacing" are the physics' too.
    let names: Vec<&str> = VARIABLES.iter().map(|v| v.name).filter(|n| n.chars().any(|c| c.is_ascii_uppercase()) || ["nx", "ny"].contains(n)).collect();
    assert!(names.contains(&"nModes") && names.contains(&"nx"));
    let files = rust_files(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/physics"));
    assert!(files.len() > 10);
    let mut found = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        for (i, line) in text.lines().enumerate() {
            let words: Vec<&str> = line.split(|c: char| !c.is_ascii_alphanumeric() && c != '_').collect();
            for n in &names {
                if words.contains(n) {
                    found.push(format!("{}:{}: {n}", f.display(), i + 1));
                }
            }
            // The FMI spelling of an option, "reduction = modal".
            if line.contains("reduction = ") || line.contains("integrator = ") {
                found.push(format!("{}:{}: {line}", f.display(), i + 1));
            }
        }
    }
    assert!(found.is_empty(), "FMI variable names in the physics core:\n{}", found.join("\n"));
}

#[test]
fn the_readme_tables_are_those_of_the_variable_table() {
    let readme = std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/variables.md")).unwrap();
    let section = readme.split_once(generate::README_BEGIN).and_then(|(_, rest)| rest.split_once(generate::README_END)).map(|(s, _)| s);
    let section = section.expect("docs/variables.md has no generated variable tables");
    assert_eq!(section.trim(), spec().readme_tables().trim(), "docs/variables.md's variable tables are stale: run `cargo xtask docs`");
    for v in VARIABLES {
        assert!(section.contains(&format!("| `{}` |", v.name)), "{} missing from docs/variables.md", v.name);
    }
}
