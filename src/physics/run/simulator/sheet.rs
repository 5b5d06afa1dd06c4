//! What the model, the tests and the tools use of a run: three narrow
//! traits, each at most 15 methods, implemented once by the generic
//! [`super::Run`] (no layer between them and the space), and [`Sheet`],
//! all three together, which [`super::Simulator`] holds as an object.

use crate::physics::error::PhysicsError;
use crate::physics::run::state::{Loads, Snapshot};
use crate::physics::settings::Settings;
use crate::physics::setup::mode_classes::ModeClasses;
use crate::physics::setup::modes::ModalBasis;
use crate::physics::setup::scene::Scene;
use crate::physics::setup::setup_data::SetupData;

/// Stepping, the loads and the state.
pub trait Steps {
    /// Longest internal step: the internal step bound, and the scheme's
    /// stability limit under the current loads (weights above 1 scale the
    /// stiffness a mode sees).
    fn max_stable_step(&self) -> f64;
    /// Advances by `h` seconds in equal internal steps no longer than
    /// [`Self::max_stable_step`]. On error the state is that of the start of the call.
    fn do_step(&mut self, h: f64) -> Result<(), PhysicsError>;
    /// The scene being simulated.
    fn scene(&self) -> &Scene;
    /// Time since the start of the run [s].
    fn time(&self) -> f64;
    /// Free degrees of freedom.
    fn n_dofs(&self) -> usize;
    /// The loads of the run, as the physics reads them.
    fn loads(&self) -> &Loads;
    fn settings(&self) -> &Settings;
    /// Internal steps taken by the last successful `do_step`.
    fn internal_steps_last(&self) -> usize;
    /// Changes the loads in place, where the physics reads them, effective
    /// from now: all or nothing (refused loads are restored as they were).
    /// The acceleration is recomputed at the current state, so a load
    /// change acts as a step input; a change of the anchor's or the
    /// holder's targets alone acts from the next step on. Allocates
    /// nothing when the mode weights keep their number.
    fn edit_loads(&mut self, edit: &mut dyn FnMut(&mut Loads)) -> Result<(), PhysicsError>;
    /// Moves the generalized coordinates by `dy` (displacements of the free
    /// DOFs in full space, modal coordinates in the modal space) and makes
    /// the accelerations those of the new positions, as at the start of a
    /// run: the start of a twin run a hair away from this one, which shows
    /// how far a scene is predictable (`docs/method.md`, section 6). On
    /// error nothing changes.
    fn displace(&mut self, dy: &[f64]) -> Result<(), PhysicsError>;
    /// [`Self::displace`] by a displacement `dy` of the free DOFs: in the
    /// modal space by its modal coordinates q = Phi^T M dy (the part the
    /// basis holds).
    fn displace_dofs(&mut self, dy: &[f64]) -> Result<(), PhysicsError>;
    /// The state and the loads: all a run needs to resume.
    fn snapshot(&self) -> Snapshot;
    /// Resumes from a snapshot of a simulator of the same scene and settings.
    /// On error nothing changes.
    fn restore(&mut self, s: &Snapshot) -> Result<(), PhysicsError>;
}

/// What a host reads: the outputs in the ground's frame.
pub trait Reads {
    /// Node positions, `dim` per node in the scene's output order, held
    /// nodes included [m]. The modal space expands them from q when first
    /// asked after a step.
    fn positions(&mut self) -> &[f64];
    /// Node velocities, same layout as positions [m/s].
    fn velocities(&mut self) -> &[f64];
    /// Position of the load node (z 0 in 2D), if the node is in the scene
    /// [m]: read from the node positions when they are computed, else
    /// computed for this node alone.
    fn load_node_position(&mut self) -> Option<[f64; 3]>;
    /// Velocity of the load node (z 0 in 2D), if the node is in the scene [m/s].
    fn load_node_velocity(&mut self) -> Option<[f64; 3]>;
    /// The force the sheet exerts on its holder, from the momentum balance
    /// of the free nodes (`docs/method.md`, section 8):
    /// F = m_free g + f_p - sum M y'', y'' of the motion the scheme
    /// integrates, so the damping's reaction (it acts on the motion
    /// relative to the holder) is the holder's and, in 3D, so is what the
    /// auxiliary springs carry (their points ride with the holder). O(r) in
    /// the modal space; z is 0 in 2D [N].
    fn anchor_force(&mut self) -> [f64; 3];
    /// The torque the sheet exerts on its holder about the pivot, from the
    /// balance of angular momentum (`docs/method.md`, section 8):
    /// S x g + rho_p x f_p - sum m rho x y'', less, while the holder turns at w,
    /// 2 (w tr N - N w) - w x (J w); only z in 2D. O(r^2) in the modal space [N m].
    fn anchor_torque(&mut self) -> [f64; 3];
    /// The force the sheet exerts on holder `k` (counted from 0; 0 beyond
    /// the scene's holders): for every holder but the first, the forces of
    /// the springs that end on its slots; for the first, [`Self::anchor_force`]
    /// less the others', so that they add up to it (`docs/method.md`, section 9).
    /// O(springs on the holders x r) in the modal space; z is 0 in 2D [N].
    fn holder_force(&mut self, k: usize) -> [f64; 3];
    /// The torque the sheet exerts on holder `k` about its pivot (the rest
    /// position of its first node, carried by its displacement), the same
    /// way; only z in 2D [N m].
    fn holder_torque(&mut self, k: usize) -> [f64; 3];
    /// 1/2 v^T M v [J].
    fn kinetic_energy(&self) -> f64;
    /// Elastic energy of the springs plus gravitational energy relative to
    /// rest [J]: every spring, whatever the force model; computed when first
    /// asked after a step.
    fn potential_energy(&mut self) -> f64;
    /// The part of the physical force the basis cannot represent, relative
    /// to the load (0 in full space); computed when first asked after a step.
    fn force_residual(&mut self) -> f64;
    /// Coordinates of the kept (modal) or reported (full) modes; computed
    /// when first asked after a step (in full space Φᵀ M (x − x*), O(n r)).
    fn modal_coordinates(&mut self) -> &[f64];
    /// The spring force at generalized coordinates `y` as the space
    /// evaluates it: Phi^T f(x* + Phi y) in the modal space (every spring,
    /// or the cubature), f(x_rest + y) in full space. For diagnostics; the
    /// run is not affected.
    fn spring_force(&mut self, y: &[f64]) -> Result<Vec<f64>, PhysicsError>;
    /// How far the state is from the range a trained basis was trained
    /// for ([`crate::physics::TrainedRange::distance`] of the modal
    /// coordinates: at most 1 inside); 0 for other bases and in full
    /// space. O(r).
    fn training_range(&self) -> f64;
}

/// The products of the set-up: the modes, their classes, the costly data, the cubature.
pub trait SetUp {
    /// omega_i of the kept or reported modes, ascending [rad/s].
    fn mode_frequencies(&self) -> &[f64];
    /// Makes the reported modes of a full-space run, which are made when
    /// first asked for, and says why they cannot be, if they cannot (then
    /// the mode outputs are empty or 0).
    fn modes_made(&self) -> Result<(), &PhysicsError> {
        Ok(())
    }
    /// The kept (modal) or reported (full) modes: shapes Phi (row-major n x r over the free DOFs), lambda_i.
    fn mode_shapes(&self) -> Option<&ModalBasis>;
    /// Out-of-plane share and mirror symmetry of each mode of [`Self::mode_shapes`] (empty without). O(n r).
    fn mode_classes(&self) -> ModeClasses;
    /// Every mode of [`Self::mode_shapes`] laid out on the grid as the node
    /// outputs are, `[r][n_nodes][dim]`, 0 on held nodes (empty without). O(n r).
    fn mode_grid_shapes(&self) -> Vec<f64>;
    /// The costly products of the set-up (modal space, and an adaptive run's
    /// set-up as it chose it), to store and pass to [`Self::with_setup`] later.
    fn setup_data(&self) -> Option<SetupData>;
    /// Springs one force evaluation visits: every spring, or the cubature set.
    fn cubature_springs(&self) -> usize;
    /// Where the run stands in its reduction: the estimated error E so far,
    /// the share of internal steps taken reduced, and the vectors of the
    /// basis it steps now (the free DOFs in full space). Only an adaptive
    /// run estimates (`docs/method.md`, section 10); the others report 0, and 1 or 0.
    fn reduction_status(&self) -> ReductionStatus;
}

/// See [`SetUp::reduction_status`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReductionStatus {
    pub error_estimate: f64,
    pub reduced_fraction: f64,
    pub basis_size: usize,
    /// The basis size chosen at set-up, and whether the run reduces at all
    /// (an adaptive run on a scene too small for its basis to pay runs in full space throughout).
    pub chosen_size: usize,
    pub reduces: bool,
    /// Why an adaptive run goes in full space throughout, where it does.
    pub why_full: Option<crate::physics::setup::adaptive_basis::FullThroughout>,
    /// The error model's directions (an adaptive run with cubature forces), 0 where it works in full space or there is none.
    pub error_directions: usize,
    /// Switches between the reduced model and full space so far (an
    /// adaptive run's fall-backs and returns), and the last of them.
    pub switches: u64,
    pub last_switch: Switch,
}

/// A switch of an adaptive run between its reduced model and full space
/// (`docs/method.md`, section 10), at `time` since set-up [s].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Switch {
    None,
    /// To full space, at the start of the step from `time`.
    FallBack {
        time: f64,
        why: FallBackCause,
    },
    /// Back to the reduced model at `time`, on `vectors` basis vectors.
    Return {
        time: f64,
        vectors: usize,
    },
}

/// Why an adaptive run went to full space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FallBackCause {
    /// Gravity or the point load outside the training program.
    OutsideProgram,
    /// The estimated error of the state passed `limit` (both relative to the motion).
    Error { estimate: f64, limit: f64 },
    /// The residual force the error directions do not see passed `limit` (both relative to the load).
    Unseen { share: f64, limit: f64 },
}

/// A run: everything [`super::Simulator`] offers.
pub trait Sheet: Steps + Reads + SetUp + Send {}

impl<T: Steps + Reads + SetUp + Send> Sheet for T {}
