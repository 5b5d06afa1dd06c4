//! Modal mass-spring solver (Kobayashi, Yoshida, Kanda, "Control of
//! Mass-Spring System by Modal Analysis") as an FMI 3.0 Co-Simulation FMU.
//!
//! [`physics`] is the solver and knows nothing of FMI; [`fmi`] is the thin
//! layer of `fmi3*` exports over it; [`options`] are the enumerations both
//! share, generated from `modelDescription/variables.toml`; [`scenes`] gives
//! the canonical scenes of that table to the study, benchmarks and tests.
//! `docs/method.md` is the method, `docs/architecture.md` the shape of the code.

pub mod fmi;
pub mod measures;
pub mod options;
pub mod physics;
pub mod scenes;
