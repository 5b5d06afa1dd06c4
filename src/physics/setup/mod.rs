//! The set-up floor: what is computed once, before the first step, from
//! the scene, the settings and the loads at set-up.
//!
//! - [`scene`]: what the solver simulates (slots, springs, masses); [`grid`]
//!   builds the canonical scenes, nothing else knows there is a grid;
//! - [`modes`]: the generalized eigen decomposition K phi = lambda M phi;
//! - [`equilibrium`]: where to linearize (the static equilibrium under the loads);
//! - [`basis`]: which modes to keep, the static correction, Rayleigh-Ritz;
//! - [`trained_basis`]: a basis trained on full-space runs under a training
//!   program (it runs the run floor's full space);
//! - [`cubature_training`]: the cubature's spring set, trained on the exact
//!   reduced model (it runs the run floor's modal space);
//! - [`mode_classes`]: what each mode looks like (out of plane, mirror symmetry);
//! - [`setup_data`]: the costly products of a modal set-up as data, to store and reuse.
//!
//! The run floor ([`super::run`]) takes these products; the two training
//! stages in turn run the run floor's spaces and schemes. No file depends
//! on one that depends on it (`tests/physics_layers.rs`).

pub mod adaptive_basis;
pub mod basis;
pub mod cubature_training;
pub mod equilibrium;
pub mod grid;
pub mod mode_classes;
pub mod modes;
pub mod scene;
pub mod setup_data;
pub mod trained_basis;
