//! The run floor: what steps the sheet and reads it, built once at set-up
//! and then only written by the steps.
//!
//! - [`forces`]: exact spring forces (the kernel);
//! - [`stiffness`]: tangent stiffness, its sparsity and assembly;
//! - [`space`]: where the equations M y'' + C y' = h(y) live (modal, full),
//!   each a constant model with its own scratch;
//! - [`integrator`]: the schemes (explicit and implicit Newmark,
//!   trigonometric), written once against [`space::Space`];
//! - [`frame`]: the holder's frame and the mass moments of the sheet in it;
//! - [`holders`]: holders that move on their own, their slots and their reactions;
//! - [`state`]: [`state::State`] and [`state::Loads`], what changes while running;
//! - [`simulator`]: a space and a scheme bound together in a run (generic),
//!   the registry that chooses them, sub-stepping, divergence checks,
//!   outputs, behind the narrow traits `Steps`, `Reads` and `SetUp`.
//!
//! One modal force evaluation is the pipeline `expand` (q -> x) -> exact
//! spring forces in physical space -> `project` (Phi^T f).

pub mod error_directions;
pub mod error_model;
pub mod forces;
pub mod frame;
pub mod holders;
pub mod integrator;
pub mod simulator;
pub mod space;
pub mod state;
pub mod stiffness;
