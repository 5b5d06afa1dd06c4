//! How a scene is integrated: every choice made at set-up, in one type.
//!
//! The enumerations are those of the variable table (`crate::options`,
//! generated from `modelDescription/variables.toml`), so their items are
//! defined once; this type gathers them with the numbers that go with them.
//! Its defaults are the table's start values (`crate::options::start`),
//! written nowhere else; the physics checks only what makes a value
//! physically meaningless, the table's ranges are the FMU's.

use crate::options::start;
pub use crate::options::{ForceEvaluation, Integrator, Linearization, ModeSelection, Reduction};

/// Everything the set-up of a [`crate::physics::Simulator`] chooses besides the scene and the loads.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Space the equations live in (`docs/method.md`, sections 3 and 4).
    pub reduction: Reduction,
    /// Scheme of the internal steps (`docs/method.md`, section 4).
    pub integrator: Integrator,
    /// Modes kept by the modal space; in full space the number of modes
    /// whose frequencies and coordinates are reported (0: none).
    pub n_modes: usize,
    /// Which modes the basis keeps: the lowest (the paper's) or those the
    /// loads excite most (`docs/method.md`, section 3).
    pub mode_selection: ModeSelection,
    /// The static responses to the loads join the basis.
    pub static_correction: bool,
    /// Where the modes are computed: at rest (the paper's) or at the static
    /// equilibrium under the set-up loads.
    pub linearization: Linearization,
    /// The anchor will move: its inertial load along each axis, M e_i, is
    /// a load pattern of the basis and the cubature's training (`docs/method.md`, section 8).
    pub anchor_motion: bool,
    /// The holder will turn: the inertial loads of its angular
    /// acceleration and of its spin about each axis it can turn about
    /// (M (e_i x s) and M s_perp,i, s the rest positions about the pivot) are
    /// load patterns of the basis (`docs/method.md`, section 8).
    pub anchor_rotation: bool,
    /// How the modal space evaluates the projected spring force: every
    /// spring (the paper's) or a trained cubature (`docs/method.md`, section 4).
    pub force_evaluation: ForceEvaluation,
    /// With [`ForceEvaluation::Cubature`]: the relative error of Phi^T f on
    /// the training and held-out poses the cubature set is grown to reach.
    pub cubature_tolerance: f64,
    /// With [`Reduction::Adaptive`]: the error E the run may reach
    /// (`docs/method.md`, sections 6 and 10).
    pub error_tolerance: f64,
    /// Upper bound on one internal step [s].
    pub max_internal_step: f64,
    /// Split a communication step into internal steps that keep the
    /// explicit integrator stable. Only tests switch this off, to show why it exists.
    pub substepping: bool,
    /// With [`ModeSelection::Trained`]: the loads its training program runs.
    pub training: TrainingProgram,
    /// With several holders and `anchor_motion` or `anchor_rotation`: the
    /// constraint modes of the holders join the basis (`docs/method.md`,
    /// section 9). Only tests and the study switch this off, to measure what they bring.
    pub constraint_modes: bool,
    /// Threads of the full space's spring forces and node updates (1: the
    /// caller's thread alone). The trajectory is bit for bit the same for
    /// any count; only the elastic energy's sum is ordered differently.
    pub threads: usize,
}

/// The range a trained basis is trained for (`docs/method.md`, section 3;
/// [`crate::physics::setup::trained_basis`]): the full-space model runs from rest under
/// the set-up gravity scaled by 1 - `scale`, 1 and 1 + `scale`, and tilted by
/// `tilt` either way about each axis normal to it that the scene can tilt
/// about, for `time` each (plus the holder's accelerations and spins the
/// settings announce, and the point load's range).
#[derive(Clone, Debug, PartialEq)]
pub struct TrainingProgram {
    /// Relative change of gravity's magnitude, in [0, 1) (1 - scale > 0: gravity keeps its sense).
    pub scale: f64,
    /// Tilt of gravity's direction [rad], in [0, pi/2].
    pub tilt: f64,
    /// Length of each training run [s], positive.
    pub time: f64,
}

impl Default for TrainingProgram {
    /// The table's start values: 0.7 to 1.3 times the set-up gravity, tilted up to 20 degrees, 1 s per run.
    fn default() -> Self {
        TrainingProgram { scale: start::TRAINING_SCALE, tilt: start::TRAINING_TILT, time: start::TRAINING_TIME }
    }
}

impl Settings {
    /// `n_modes` modes, the given space and scheme, and every other choice
    /// at the table's start value: the paper's basis (the lowest modes at
    /// rest, no correction) and forces (every spring), internal steps of at
    /// most 10 ms.
    pub fn new(reduction: Reduction, integrator: Integrator, n_modes: usize) -> Self {
        Settings {
            reduction,
            integrator,
            n_modes,
            mode_selection: start::MODE_SELECTION,
            static_correction: start::STATIC_CORRECTION,
            linearization: start::LINEARIZATION,
            anchor_motion: start::ANCHOR_MOTION,
            anchor_rotation: start::ANCHOR_ROTATION,
            force_evaluation: start::FORCE_EVALUATION,
            cubature_tolerance: start::CUBATURE_TOLERANCE,
            error_tolerance: start::ERROR_TOLERANCE,
            max_internal_step: start::MAX_INTERNAL_STEP,
            substepping: true,
            training: TrainingProgram::default(),
            constraint_modes: true,
            threads: start::THREADS,
        }
    }
}
