//! Modal mass-spring solver (Kobayashi, Yoshida, Kanda, "Control of
//! Mass-Spring System by Modal Analysis") as an FMI 3.0 Co-Simulation FMU.
//!
//! [`physics`] is the solver and knows nothing of FMI; [`fmi`] is the thin
//! layer of `fmi3*` exports over it.

pub mod fmi;
pub mod physics;
