//! Physics core: scenes, assembly, eigen decomposition and the modal and
//! full-space Newmark integrators. Knows nothing of FMI.
//!
//! Pipeline of one modal force evaluation: `expand` (q -> x) ->
//! `SpringForces` (exact spring forces in physical space, paper eq. 1)
//! -> `project` (F = Phi^T f) -> Newmark update in the reduced space.

pub mod forces;
pub mod full;
pub mod modal;
pub mod modes;
pub mod newmark;
mod params;
pub mod scene;
mod simulator;

pub use params::*;
pub use simulator::{SimError, Simulator, Snapshot, EXPLICIT_SAFETY, MAX_INTERNAL_STEPS_PER_CALL};
