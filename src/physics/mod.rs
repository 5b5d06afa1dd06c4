//! Physics core: the mass-spring model, its modal reduction and the time
//! integrators of `docs/method.md`. Knows nothing of FMI.
//!
//! Two floors, each a folder:
//!
//! - [`setup`]: what is computed once from the scene, the settings and the
//!   loads at set-up (scene and grid, modes, equilibrium, bases, the
//!   trained basis and its program, the cubature's training, mode classes,
//!   the set-up as data);
//! - [`run`]: what steps and reads the sheet (spaces, schemes, the
//!   simulator, forces, the holder's frame, state);
//!
//! and beside them [`vector_unit`] (the CPU's vector state after faer's kernels),
//! [`settings`] (every choice of a set-up, in one type) and
//! [`error`] (typed errors that name the quantity and the limit).

pub mod error;
pub mod run;
pub mod settings;
pub mod setup;
pub mod vector_unit;

pub use error::{HolderProblem, PhysicsError, Quantity, StepFailure};
pub use run::integrator::EXPLICIT_SAFETY;
pub use run::simulator::registry::Simulator;
pub use run::simulator::{
    internal_step_count, FallBackCause, Reads, ReductionStatus, SetUp, Sheet, Steps, Switch, MAX_INTERNAL_STEPS_PER_CALL, STEP_COUNT_TOLERANCE,
};
pub use run::state::{AdaptivePart, Loads, Motion, Pose, Snapshot, State, OTHER_HOLDERS};
pub use settings::{ForceEvaluation, Integrator, Linearization, ModeSelection, Reduction, Settings, TrainingProgram};
pub use setup::adaptive_basis::FullThroughout;
pub use setup::adaptive_basis::DOFS_PER_VECTOR as ADAPTIVE_DOFS_PER_VECTOR;
pub use setup::adaptive_basis::JOINT_CUBATURE_MODES as ADAPTIVE_JOINT_CUBATURE_MODES;
pub use setup::grid::{FixedNodes, Grid};
pub use setup::mode_classes::ModeClasses;
pub use setup::scene::{Holder, Scene, MAX_HOLDERS};
pub use setup::setup_data::{AdaptiveChoice, SetupData, SpringSet, TrainedRange};
