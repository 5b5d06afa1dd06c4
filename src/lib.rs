//! Modal mass-spring solver (Kobayashi, Yoshida, Kanda, "Control of
//! Mass-Spring System by Modal Analysis") as an FMI 3.0 Co-Simulation FMU.
//!
//! [`physics`] is the solver and knows nothing of FMI; [`fmi`] is the thin,
//! generic layer of `fmi3*` exports; [`model`] is the model it exports, what
//! the variables mean to the physics; [`options`] are the enumerations both
//! share, generated from `modelDescription/variables.toml`; [`canonical_scenes`] gives
//! the canonical scenes of that table to the study, benchmarks and tests.
//! `docs/method.md` is the method, `docs/architecture.md` the shape of the code.

pub mod bytes;
pub mod canonical_scenes;
pub mod fmi;
pub mod measures;
pub mod model;
pub mod options;
pub mod physics;
pub mod status;

/// The model this FMU exports: the one place the generic FMI layer is bound
/// to it (the Reference FMUs' `config.h`), outside the layer itself.
pub type TheModel = model::MassSpring;
