//! Physics core: the mass-spring model, its modal reduction and the time
//! integrators of `docs/method.md`. Knows nothing of FMI.
//!
//! - [`scene`]: what the solver simulates (slots, springs, masses); [`grid`]
//!   builds the canonical scenes, nothing else knows there is a grid;
//! - [`forces`]: exact spring forces, tangent stiffness, sparsity;
//! - [`modes`]: the generalized eigen decomposition K phi = lambda M phi;
//! - [`mode_classes`]: what each mode looks like (out of plane, mirror symmetry);
//! - [`basis`]: where to linearize ([`equilibrium`]), which modes to keep, the static correction;
//! - [`space`]: where the equations M y'' + C y' = h(y) live (modal, full),
//!   each a constant model with its own scratch;
//! - [`integrator`]: the schemes (explicit and implicit Newmark), written
//!   once against [`space::Space`];
//! - [`engine`]: a space and a scheme bound together;
//! - [`frame`]: the holder's frame and the mass moments of the sheet in it;
//! - [`state`]: [`State`] and [`Loads`], what changes while running;
//! - [`simulator`]: set-up, sub-stepping, divergence checks, outputs;
//! - [`snapshots`]: trained bases, a set-up stage that runs the full-space model under a training program;
//! - [`training`]: the cubature's training, a set-up stage that runs the exact reduced model;
//! - [`bake`]: the costly products of a modal set-up as data, to store and reuse;
//! - [`error`]: typed errors that name the quantity and the limit.
//!
//! One modal force evaluation is the pipeline `expand` (q -> x) -> exact
//! spring forces in physical space -> `project` (Phi^T f).

pub mod bake;
pub mod basis;
pub mod engine;
pub mod equilibrium;
pub mod error;
pub mod forces;
pub mod frame;
pub mod grid;
pub mod integrator;
pub mod mode_classes;
pub mod modes;
pub mod scene;
pub mod settings;
pub mod simulator;
pub mod snapshots;
pub mod space;
pub mod state;
pub mod training;

pub use bake::{SetupData, SpringSet, TrainedRange};
pub use error::{PhysicsError, Quantity, StepFailure};
pub use grid::{FixedNodes, Grid};
pub use integrator::EXPLICIT_SAFETY;
pub use mode_classes::ModeClasses;
pub use scene::Scene;
pub use settings::{ForceEvaluation, Integrator, Linearization, ModeSelection, Reduction, Settings, Training};
pub use simulator::{internal_step_count, Simulator, MAX_INTERNAL_STEPS_PER_CALL, STEP_COUNT_TOLERANCE};
pub use state::{Loads, Snapshot, State};
