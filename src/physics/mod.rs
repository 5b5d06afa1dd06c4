//! Physics core: scenes, assembly, eigen decomposition and the modal and
//! full-space Newmark integrators. Knows nothing of FMI.
//!
//! Pipeline of one internal step (modal): `expand` (q -> x) ->
//! `evaluate_forces` (exact spring forces in physical space, paper eq. 1) ->
//! `project` (F = Phi^T f) -> `advance` (Newmark in the reduced space).

mod params;
mod simulator;

pub use params::*;
pub use simulator::{SimError, Simulator, Snapshot};
