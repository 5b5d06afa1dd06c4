//! The model description generated from modelDescription/variables.toml:
//! parsed back with fmi-schema, checked with fmi-rs (the checks of
//! `fmusim validate`), compared with the variable table compiled into the
//! binary, and the scene start values compared with SceneParams::canonical.

#[path = "../modelDescription/generate.rs"]
mod generate;

use std::collections::BTreeMap;

use fmi_schema::fmi3::Fmi3ModelDescription;
use modal_mass_spring::fmi::variables::{self, Type, VARIABLES};
use modal_mass_spring::physics::{FixedNodes, SceneParams, SCENE_NAMES};

fn spec() -> generate::Spec {
    generate::load(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("modelDescription/variables.toml")).unwrap()
}

/// The default description and one per canonical scene.
fn descriptions() -> Vec<(String, String)> {
    let spec = spec();
    let mut out = vec![("default".to_string(), spec.model_description_xml(&BTreeMap::new()).unwrap())];
    for name in SCENE_NAMES {
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

fn scene_from_starts(s: &BTreeMap<String, Vec<f64>>) -> SceneParams {
    let x = |n: &str| s[n][0];
    SceneParams {
        nx: x("nx") as usize,
        ny: x("ny") as usize,
        dimension: x("dimension") as usize,
        spacing: x("spacing"),
        node_mass: x("nodeMass"),
        spring_stiffness: x("springStiffness"),
        shear_springs: x("shearSprings") != 0.0,
        bending_springs: x("bendingSprings") != 0.0,
        aux_stiffness: x("auxStiffness"),
        fixed_nodes: if x("fixedNodes") == 2.0 { FixedNodes::TopCorners } else { FixedNodes::TopRow },
    }
}

#[test]
fn scene_start_values_are_the_canonical_scenes() {
    let spec = spec();
    assert_eq!(spec.scene_names().len(), SCENE_NAMES.len());
    for name in SCENE_NAMES {
        let starts = spec.starts(&spec.scene(name).unwrap()).unwrap();
        assert_eq!(scene_from_starts(&starts), SceneParams::canonical(name).unwrap(), "{name}");
        let n_modes = starts["nModes"][0] as usize;
        assert_eq!(starts["modeWeights"].len(), n_modes, "{name}: modeWeights fitted to nModes");
    }
}

#[test]
fn defaults_are_paper_2d_top_row() {
    let spec = spec();
    let starts = spec.starts(&BTreeMap::new()).unwrap();
    let mut default = SceneParams::canonical("paper-2d-top-row").unwrap();
    // auxStiffness acts in 3D only; its default is the 3D default k / 1000.
    default.aux_stiffness = 0.05;
    assert_eq!(scene_from_starts(&starts), default);
    assert_eq!(starts["nModes"], vec![2.0]);
    assert_eq!(starts["integrator"], vec![1.0]);
    assert_eq!(starts["dampingAlpha"], vec![0.0]);
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
    for v in VARIABLES.iter().filter(|v| v.is_parameter() && matches!(v.ty, Type::Float64 | Type::UInt64)) {
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
