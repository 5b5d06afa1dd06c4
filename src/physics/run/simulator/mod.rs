//! The simulator: set-up (the space and scheme the settings name,
//! bound once), the communication step split into internal steps, the
//! checks that catch a diverging step, and the outputs (what a host reads).
//!
//! [`Run`] is a space `S` integrated by a scheme `I` with everything that
//! changes while running: the space's work (which holds the loads), the
//! [`State`], a backup of the state taken before every communication step,
//! and the [`Outputs`] of the last good step. It is generic, so a step
//! calls the space and the scheme without indirection. [`Simulator`] is
//! the run the settings chose at set-up ([`build`], the registry: which
//! space, force model and scheme), behind the three narrow traits of
//! [`Sheet`] that the model and the tests use: [`Steps`] (stepping, the
//! loads, the state), [`Reads`] (the outputs) and [`SetUp`] (the set-up's
//! products). The outputs that cost more than the reduced state (node
//! positions and velocities, the energy of every spring, the force
//! residual) are computed when first asked for after a step and kept until
//! the state changes: a host that reads only some of them, or reads them
//! less often than it steps, pays only for those (`docs/method.md`, section 4).
//!
//! - here: the types;
//! - `registry.rs`: which run the settings name, and [`Simulator`];
//! - `adaptive/`: the adaptive reduction, a reduced run and its full-space twin;
//! - `estimators.rs`: the error models an adaptive run keeps;
//! - `sheet.rs`: the traits;
//! - `stepping.rs`: set-up of a run, the step, load changes, snapshots;
//! - `outputs.rs`: what a host reads.

mod adaptive;
mod estimators;
mod outputs;
pub mod registry;
mod sheet;
mod stepping;

use std::marker::PhantomData;

pub use sheet::{FallBackCause, Reads, ReductionStatus, SetUp, Sheet, Steps, Switch};

use crate::physics::run::frame::into_frame;
use crate::physics::run::integrator::{Buffers, Scheme};
use crate::physics::run::space::Readout;
use crate::physics::run::state::{Loads, State};
use crate::physics::settings::Settings;
use crate::physics::setup::scene::{Scene, MAX_HOLDERS};

/// Internal steps one communication step may take before it is refused.
pub const MAX_INTERNAL_STEPS_PER_CALL: usize = 10_000_000;
/// Internal steps one internal step bound may be split into by a scheme's
/// stability limit before set-up refuses the scheme: beyond it the scene is
/// too stiff for it, unless the host asked for steps that short by lowering
/// the bound.
pub const MAX_STABLE_SUBSTEPS: f64 = 1e4;
/// Relative amount by which a communication step may exceed a whole number
/// of longest internal steps and still be split into that number. Masters
/// compute the same step size differently (fmpy sends 0.009999999999999787,
/// fmusim 0.01000000000000001 for 0.01 s after t = 1 s), a few ulps apart;
/// the number of internal steps must not depend on that. 1e-8 is far above
/// the ulp (2.2e-16) and above the round-off of a step computed as the
/// difference of two times up to t = 1e6 h, and far below anything that
/// changes stability (internal steps stay within 0.9 (1 + 1e-8) of the
/// explicit limit).
pub const STEP_COUNT_TOLERANCE: f64 = 1e-8;
/// Kinetic energy growth in one communication step, relative to the energy
/// at its start plus the work the loads can do across the scene, that is
/// taken as a blow-up.
const ENERGY_GROWTH_LIMIT: f64 = 1e6;

/// Internal steps of at most `dt_max` (up to [`STEP_COUNT_TOLERANCE`]) that make up `h`.
pub fn internal_step_count(h: f64, dt_max: f64) -> f64 {
    (h / dt_max * (1.0 - STEP_COUNT_TOLERANCE)).ceil().max(1.0)
}

/// Which of the costly outputs have been computed for the current state.
#[derive(Clone, Copy, Debug, Default)]
struct Fresh {
    positions: bool,
    /// The holder's force and torque.
    anchor: bool,
    torque: bool,
    /// Each holder's force and torque.
    holders: bool,
    velocities: bool,
    potential: bool,
    residual: bool,
    /// The reported modal coordinates (Φᵀ M (x − x*) in full space: O(n r)).
    coordinates: bool,
}

/// Space `S` integrated by scheme `I`, and everything that changes while it runs.
pub struct Run<S: Readout, I: Scheme> {
    /// The space: the constant model of the equations.
    space: S,
    /// The space's work: the loads (the one place the physics reads them,
    /// [`Steps::loads`]), their terms and the scratch.
    work: S::Work,
    /// The scheme's vectors.
    buffers: Buffers,
    /// y'' of the scheme's motion, for the holder's force and torque.
    acceleration: Vec<f64>,
    /// The forces of `work` are those at the state's coordinates (see [`Scheme::ENDS_AT_STATE`]).
    current: bool,
    settings: Settings,
    state: State,
    /// The loads before the change in progress of [`Simulator::edit_loads`],
    /// kept to restore them if the change is refused (never read as the loads).
    spare: Loads,
    /// The state at the start of the current communication step, restored
    /// if it fails (the loads do not change within a step).
    backup: State,
    outputs: Outputs,
    /// Which of the costly outputs match the state.
    fresh: Fresh,
    /// Kinetic energy plus |potential energy as the force model sums it| of
    /// the state, for the blow-up guard of the next step [J].
    energy: f64,
    internal_steps_last: usize,
    /// Mass of the free nodes and the distance they can travel, for the blow-up bound.
    free_mass: f64,
    reach: f64,
    /// Shortest spring at rest (the grid spacing) [m], for the anchor's speed limit.
    spacing: f64,
    /// The pivot X0, how far from it the sheet can reach, and sum m (x_rest - X0).
    pivot: [f64; 3],
    arm: f64,
    rest_moment: [f64; 3],
    /// Gravity and the point load turned into the holder's frame at the
    /// state's orientation, while it has turned.
    local: FrameLoads,
    /// Per holder that moves on its own: the springs that end on its slots
    /// (for its reaction), and how far its slots reach from its pivot (for its speed limit).
    holder_ends: Vec<Vec<(usize, bool)>>,
    holder_arms: Vec<f64>,
    /// (holder among those that move on their own, node) for every node they hold.
    holder_nodes: Vec<(usize, usize)>,
    scheme: PhantomData<I>,
}

/// Gravity and the point load in the holder's frame.
#[derive(Clone, Copy, Debug, Default)]
struct FrameLoads {
    gravity: [f64; 3],
    point_load: [f64; 3],
}

/// Everything a simulator reports after a step.
#[derive(Clone, Debug)]
pub struct Outputs {
    /// Node positions in output order, `dim` per node, held nodes included [m].
    pub positions: Vec<f64>,
    /// Node velocities, same layout [m/s].
    pub velocities: Vec<f64>,
    /// Node positions in the holder's frame, while it has turned [m].
    pub frame_positions: Vec<f64>,
    /// Velocities of the free DOFs.
    pub dof_velocities: Vec<f64>,
    /// Coordinates of the kept or reported modes.
    pub modal_coordinates: Vec<f64>,
    /// 1/2 v^T M v [J].
    pub kinetic: f64,
    /// Elastic energy plus gravity potential relative to rest [J].
    pub potential: f64,
    /// The part of the force the space cannot represent, relative to the load.
    pub force_residual: f64,
    /// The force the sheet exerts on its holder, from the momentum balance
    /// (`docs/method.md`, section 8) [N]; z is 0 in 2D.
    pub anchor_force: [f64; 3],
    /// The torque the sheet exerts on its holder about the pivot [N m].
    pub anchor_torque: [f64; 3],
    /// Per holder, the force and the torque the sheet exerts on it (about
    /// its pivot), holder 1's the momentum balance less the others' (`docs/method.md`, section 9).
    pub holder_forces: [[f64; 3]; MAX_HOLDERS],
    pub holder_torques: [[f64; 3]; MAX_HOLDERS],
}

impl Outputs {
    pub fn new(scene: &Scene, modes: usize) -> Self {
        let nodes = scene.n_nodes * scene.dim;
        Outputs {
            positions: vec![0.0; nodes],
            velocities: vec![0.0; nodes],
            frame_positions: vec![0.0; nodes],
            dof_velocities: vec![0.0; scene.n_dofs()],
            modal_coordinates: vec![0.0; modes],
            kinetic: 0.0,
            potential: 0.0,
            force_residual: 0.0,
            anchor_force: [0.0; 3],
            anchor_torque: [0.0; 3],
            holder_forces: [[0.0; 3]; MAX_HOLDERS],
            holder_torques: [[0.0; 3]; MAX_HOLDERS],
        }
    }
}

/// Gravity and the point load of `loads` turned into the frame of orientation `r`.
fn turn_loads(loads: &Loads, r: &[f64; 9], d: usize) -> FrameLoads {
    FrameLoads { gravity: into_frame(r, &loads.gravity, d), point_load: into_frame(r, &loads.point_load, d) }
}

/// Slot-ordered values into node order, for the nodes whose slot is below
/// `limit` (the free slots for velocities; every slot for positions); the
/// other nodes get 0 (held nodes have no velocity of their own: the
/// anchor's is added to every node afterwards). Fixed length `D` keeps each
/// copy a pair of moves instead of a `memmove` call.
fn to_node_order<const D: usize>(slot_of_node: &[usize], limit: usize, from: &[f64], to: &mut [f64]) {
    for (&slot, t) in slot_of_node.iter().zip(to.chunks_exact_mut(D)) {
        let t = <&mut [f64; D]>::try_from(t).expect("D values");
        if slot < limit {
            *t = *<&[f64; D]>::try_from(&from[slot * D..slot * D + D]).expect("D values");
        } else {
            *t = [0.0; D];
        }
    }
}
