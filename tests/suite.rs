//! Every integration test of the crate, one module per file of tests/, in
//! one test binary: each binary compiles the solver's generic code it uses
//! anew, so one binary instead of one per file saves much of the test build.
//! Run one file's tests with its module as the filter:
//! `cargo test --release --test suite -- stability::`.

mod common;
// The counting global allocator of the no-allocation tests (one per binary).
#[path = "common/counting.rs"]
mod counting;
// The model description's generator, as xtask compiles it (at the crate root).
#[path = "../modelDescription/generate.rs"]
mod generate;
#[path = "../modelDescription/generate/xml.rs"]
mod model_description_xml;
#[path = "../modelDescription/generate/terminals.rs"]
mod terminals_and_icons_xml;

mod adaptive;
mod anchor;
mod bake;
mod basis;
mod cubature;
mod defaults;
mod fmi_abi;
mod fmi_adaptive_log;
mod fmi_import;
mod fmi_mode_classes;
mod fmi_model_description;
mod fmi_soak;
mod fmi_springs;
mod fmi_state;
mod fmi_state_machine;
mod fmi_threads;
mod fmi_twins;
mod glue_is_generic;
mod holder;
mod holders;
mod layers;
mod no_alloc;
mod no_alloc_abi;
mod physics;
mod point_load;
mod predictability;
mod stability;
mod terminals;
mod trained;
mod trajectories;
mod trigonometric;
mod trigonometric_runs;
mod turning;
