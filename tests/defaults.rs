//! The variable table (`modelDescription/variables.toml`) is the one source
//! of start values: what the physics uses when nothing is set is what the
//! FMU starts with, read here through the table's values (`Params::start`)
//! on one side and the physics' own defaults on the other. A literal
//! written into the physics instead of the generated `options::start`
//! constants, or a table entry changed without the physics following,
//! fails here.

use modal_mass_spring::fmi::variables::{vr, VARIABLES};
use modal_mass_spring::model::Params;
use modal_mass_spring::options::start;
use modal_mass_spring::physics::{Loads, Settings, TrainingProgram};

#[test]
fn the_physics_defaults_are_the_start_values_of_the_table() {
    let p = Params::start();
    let from_table = p.settings();
    // Settings::new takes the space, the scheme and the mode count; every other choice is its default.
    let defaults = Settings::new(start::REDUCTION, start::INTEGRATOR, start::N_MODES);
    assert_eq!(from_table, defaults, "Settings: the table's start values (left) against the physics' defaults (right)");
    assert_eq!(from_table.training, TrainingProgram::default());

    let loads = p.loads();
    let physical = Loads { load_node: loads.load_node, ..Loads::physical(from_table.n_modes) };
    assert_eq!(loads, physical, "Loads: the table's start values (left) against the physics' defaults (right)");
}

#[test]
fn the_generated_start_constants_are_the_tables() {
    let start_of = |r: u32| VARIABLES.iter().find(|v| v.vr == r).unwrap().start.to_vec();
    assert_eq!(start_of(vr::TRAINING_SCALE), [start::TRAINING_SCALE]);
    assert_eq!(start_of(vr::TRAINING_TILT), [start::TRAINING_TILT]);
    assert_eq!(start_of(vr::TRAINING_TIME), [start::TRAINING_TIME]);
    assert_eq!(start_of(vr::CUBATURE_TOLERANCE), [start::CUBATURE_TOLERANCE]);
    assert_eq!(start_of(vr::MAX_INTERNAL_STEP), [start::MAX_INTERNAL_STEP]);
    assert_eq!(start_of(vr::GRAVITY), start::GRAVITY);
    assert_eq!(start_of(vr::N_MODES), [start::N_MODES as f64]);
    assert_eq!(start_of(vr::REDUCTION), [start::REDUCTION.value() as f64]);
    assert_eq!(start_of(vr::STATIC_CORRECTION), [start::STATIC_CORRECTION as u8 as f64]);
}
