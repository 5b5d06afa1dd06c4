//! What changes while a scene runs, apart from what stays fixed after set-up.
//!
//! - [`State`]: the generalized coordinates of the space the equations live
//!   in (modal coordinates q, or full-space displacements u from the
//!   linearization point), their rates and the time;
//! - [`Loads`]: what the environment sets between steps (gravity, a point
//!   load on one node, damping, mode weights);
//! - [`Snapshot`]: a state with its loads, all a run needs to resume. The
//!   simulator's backup before a step and the FMU state are snapshots.

use crate::options::start;
use crate::physics::error::{non_negative, positive, Expected, HolderProblem, PhysicsError, Quantity};
use crate::physics::setup::scene::{Scene, MAX_HOLDERS};

/// Holders that move on their own, beside the first (whose frame the
/// sheet is integrated in): holders 2 to [`MAX_HOLDERS`].
pub const OTHER_HOLDERS: usize = MAX_HOLDERS - 1;

/// Where a holder is to be: its displacement from its rest place and its
/// rotation vector about its pivot from its rest orientation (z alone in 2D).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Pose {
    /// [m]; z is ignored in 2D.
    pub anchor: [f64; 3],
    /// [rad]; x and y are ignored in 2D.
    pub rotation: [f64; 3],
}

/// Where a holder is at a state's time and how it moved over the last
/// communication step (first-order hold: constant velocity and spin).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Motion {
    /// Displacement from its rest place [m].
    pub anchor: [f64; 3],
    /// Velocity over the last communication step [m/s].
    pub anchor_rate: [f64; 3],
    /// Rotation vector from its rest orientation [rad].
    pub rotation: [f64; 3],
    /// Angular velocity in its own axes over the last communication step [rad/s].
    pub spin: [f64; 3],
}

impl Motion {
    fn values(&self) -> impl Iterator<Item = &f64> {
        self.anchor.iter().chain(&self.anchor_rate).chain(&self.rotation).chain(&self.spin)
    }

    /// It has left its rest place or moves.
    pub fn moved(&self) -> bool {
        self.values().any(|&x| x != 0.0)
    }
}

/// Largest component of the holder's rotation vector [rad]: 1e6 rad is
/// 160 000 turns, and keeps the angle's round-off below 1e-10 rad.
pub const MAX_ROTATION: f64 = 1e6;

/// Coordinates y, rates y' and accelerations y'' of the generalized
/// coordinates, and the time since the start of the run.
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    /// Time since the start of the run [s].
    pub time: f64,
    /// y: modal coordinates, or displacements of the free DOFs.
    pub y: Vec<f64>,
    /// y'.
    pub v: Vec<f64>,
    /// y'' (Newmark); the trigonometric scheme keeps the rest of its force
    /// at the filtered coordinates, e(phi y), here instead (`docs/method.md`, section 4).
    pub a: Vec<f64>,
    /// Displacement of the anchor (every held node) from its rest position
    /// at `time` [m]; z is 0 in 2D. y measures the free DOFs from the
    /// anchor's frame (`docs/method.md`, section 8).
    pub anchor: [f64; 3],
    /// Velocity of the anchor over the last communication step [m/s].
    pub anchor_rate: [f64; 3],
    /// The holder's orientation at `time`, as the rotation vector theta
    /// (axis x angle) from its rest orientation [rad]; only z in 2D. y
    /// measures the free DOFs in the holder's frame (`docs/method.md`, section 8).
    pub rotation: [f64; 3],
    /// The holder's angular velocity in its own axes over the last
    /// communication step [rad/s].
    pub spin: [f64; 3],
    /// Holders 2 and on: where they are at `time` and how they moved
    /// (`docs/method.md`, section 9); at rest beyond the scene's holders.
    pub holders: [Motion; OTHER_HOLDERS],
}

impl State {
    /// At rest at the linearization point, at time 0, with `n` coordinates.
    pub fn at_rest(n: usize) -> Self {
        State {
            time: 0.0,
            y: vec![0.0; n],
            v: vec![0.0; n],
            a: vec![0.0; n],
            anchor: [0.0; 3],
            anchor_rate: [0.0; 3],
            rotation: [0.0; 3],
            spin: [0.0; 3],
            holders: [Motion::default(); OTHER_HOLDERS],
        }
    }

    /// Number of generalized coordinates.
    pub fn len(&self) -> usize {
        self.y.len()
    }

    pub fn is_empty(&self) -> bool {
        self.y.is_empty()
    }

    /// Copies `other` into `self` without allocating (same lengths).
    /// Takes the time and the holders' motions of `other`, keeping y, y' and y''.
    pub fn copy_frame_from(&mut self, other: &State) {
        self.time = other.time;
        self.anchor = other.anchor;
        self.anchor_rate = other.anchor_rate;
        self.rotation = other.rotation;
        self.spin = other.spin;
        self.holders = other.holders;
    }

    pub fn copy_from(&mut self, other: &State) {
        self.time = other.time;
        self.y.copy_from_slice(&other.y);
        self.v.copy_from_slice(&other.v);
        self.a.copy_from_slice(&other.a);
        self.anchor = other.anchor;
        self.anchor_rate = other.anchor_rate;
        self.rotation = other.rotation;
        self.spin = other.spin;
        self.holders = other.holders;
    }

    /// Every value is a finite number.
    pub fn is_finite(&self) -> bool {
        self.time.is_finite()
            && self
                .y
                .iter()
                .chain(&self.v)
                .chain(&self.a)
                .chain(&self.anchor)
                .chain(&self.anchor_rate)
                .chain(&self.rotation)
                .chain(&self.spin)
                .chain(self.holders.iter().flat_map(Motion::values))
                .all(|x| x.is_finite())
    }
}

/// Loads and gains that may change between communication steps.
#[derive(Debug, PartialEq)]
pub struct Loads {
    /// Gravitational acceleration [m/s^2]; z is ignored in 2D.
    pub gravity: [f64; 3],
    /// A force on one node, the load node [N]; z is ignored in 2D
    /// (`docs/method.md`, section 8). Like gravity it is held constant over
    /// a communication step.
    pub point_load: [f64; 3],
    /// The load node, by its index in the scene's output order; `None`
    /// when the chosen node is not in the scene. A node that is held, or
    /// absent, may only carry a zero point load.
    pub load_node: Option<usize>,
    /// Where the anchor (every held node) is to be at the end of the next
    /// communication step, as a displacement from its rest position [m]; z
    /// is ignored in 2D. Over the step the anchor moves linearly from where
    /// it is ([`State::anchor`]) to here (`docs/method.md`, section 8).
    pub anchor: [f64; 3],
    /// The holder's orientation at the end of the next communication step,
    /// as a rotation vector from its rest orientation [rad]; x and y are
    /// ignored in 2D. Over the step the holder turns at a constant rate
    /// from where it is ([`State::rotation`]) to here (`docs/method.md`, section 8).
    pub rotation: [f64; 3],
    /// Where holders 2 and on are to be at the end of the next
    /// communication step; over the step each moves linearly and turns at
    /// a constant rate from where it is ([`State::holders`]). Only rest is
    /// accepted beyond the scene's holders.
    pub holders: [Pose; OTHER_HOLDERS],
    /// Rayleigh mass-proportional damping alpha [1/s].
    pub damping_alpha: f64,
    /// Rayleigh stiffness-proportional damping beta [s].
    pub damping_beta: f64,
    /// Gain w_i per mode (`docs/method.md`, section 3); one per mode kept
    /// or reported, used by the modal space only.
    pub mode_weights: Vec<f64>,
    /// The error E an adaptive run may reach from the next step on (when
    /// it falls back and returns, `docs/method.md`, section 10); `None`: the
    /// one it was set up for ([`crate::physics::Settings::error_tolerance`],
    /// which chose its basis). Other runs do not read it.
    pub error_tolerance: Option<f64>,
}

impl Clone for Loads {
    fn clone(&self) -> Self {
        Loads { mode_weights: self.mode_weights.clone(), ..*self }
    }

    /// Reusing the weights' buffer: a load change between steps allocates
    /// nothing. Every other field is `Copy`, so a new one needs no line here.
    fn clone_from(&mut self, source: &Self) {
        let mut weights = std::mem::take(&mut self.mode_weights);
        weights.clone_from(&source.mode_weights);
        *self = Loads { mode_weights: weights, ..*source };
    }
}

impl Loads {
    /// Earth gravity along -y, no damping, every weight 1 (the physical model).
    pub fn physical(n_modes: usize) -> Self {
        Loads {
            gravity: start::GRAVITY,
            point_load: [start::LOAD_X, start::LOAD_Y, start::LOAD_Z],
            load_node: None,
            anchor: [start::ANCHOR_X, start::ANCHOR_Y, start::ANCHOR_Z],
            rotation: [start::ANCHOR_R_X, start::ANCHOR_R_Y, start::ANCHOR_R_Z],
            holders: [Pose::default(); OTHER_HOLDERS],
            damping_alpha: start::DAMPING_ALPHA,
            damping_beta: start::DAMPING_BETA,
            mode_weights: vec![1.0; n_modes],
            error_tolerance: None,
        }
    }

    /// The first free DOF of the load node in `scene`, if the node is in
    /// the scene and free to move.
    pub fn load_dof(&self, scene: &Scene) -> Option<usize> {
        let slot = *scene.slot_of_node.get(self.load_node?)?;
        (slot < scene.n_free).then_some(slot * scene.dim)
    }

    /// The point load over the `dim` coordinates of the scene, if it is not zero.
    pub fn active_point_load(&self, dim: usize) -> Option<&[f64]> {
        let f = &self.point_load[..dim];
        f.iter().any(|&x| x != 0.0).then_some(f)
    }

    /// The point load on the free DOFs of `scene`: its first DOF and its
    /// `dim` components, when it is not zero and its node is free.
    pub fn point_force(&self, scene: &Scene) -> Option<(usize, &[f64])> {
        Some((self.load_dof(scene)?, self.active_point_load(scene.dim)?))
    }

    /// [`Self::point_force`] with the point load `point` (the load as a
    /// turned frame sees it) on this load node.
    pub fn point_force_as<'p>(&self, point: &'p [f64; 3], scene: &Scene) -> Option<(usize, &'p [f64])> {
        let f = &point[..scene.dim];
        Some((self.load_dof(scene)?, f.iter().any(|&x| x != 0.0).then_some(f)?))
    }

    /// The same loads apart from the holders' targets.
    pub fn same_but_anchor(&self, other: &Loads) -> bool {
        self.gravity == other.gravity
            && self.point_load == other.point_load
            && self.load_node == other.load_node
            && self.damping_alpha == other.damping_alpha
            && self.damping_beta == other.damping_beta
            && self.mode_weights == other.mode_weights
    }

    /// Refuses loads that do not fit `scene`: a holder it does not have
    /// moved, a non-zero point load on a node that is held or not in the scene.
    pub fn validate_on(&self, scene: &Scene) -> Result<(), PhysicsError> {
        let holders = scene.holders.len().max(1);
        if let Some(j) = self.holders.iter().enumerate().skip(holders - 1).position(|(_, p)| *p != Pose::default()) {
            return Err(PhysicsError::Holders(HolderProblem::Absent { holder: holders + 1 + j, holders }));
        }
        if self.active_point_load(scene.dim).is_some() && self.load_dof(scene).is_none() {
            let held = self.load_node.is_some_and(|n| n < scene.n_nodes);
            return Err(PhysicsError::LoadNode { node: self.load_node, held });
        }
        Ok(())
    }

    /// Largest weight, and at least 1: weights above 1 scale the stiffness
    /// the explicit integrator sees and the energy the loads can supply.
    pub fn weight_max(&self) -> f64 {
        self.mode_weights.iter().fold(1.0f64, |m, w| m.max(*w))
    }

    /// Refuses loads the solver cannot use, for `n_modes` modes.
    pub fn validate(&self, n_modes: usize) -> Result<(), PhysicsError> {
        if let Some(&g) = self.gravity.iter().find(|g| !g.is_finite()) {
            return Err(PhysicsError::Invalid { quantity: Quantity::Gravity, value: g, expected: Expected::Finite });
        }
        if let Some(&f) = self.point_load.iter().find(|f| !f.is_finite()) {
            return Err(PhysicsError::Invalid { quantity: Quantity::PointLoad, value: f, expected: Expected::Finite });
        }
        if let Some(&a) = self.anchor.iter().find(|a| !a.is_finite()) {
            return Err(PhysicsError::Invalid { quantity: Quantity::Anchor, value: a, expected: Expected::Finite });
        }
        if let Some(&a) = self.rotation.iter().find(|a| !(a.abs() <= MAX_ROTATION)) {
            return Err(PhysicsError::Invalid { quantity: Quantity::Rotation, value: a, expected: Expected::Within(MAX_ROTATION) });
        }
        for p in &self.holders {
            if let Some(&a) = p.anchor.iter().find(|a| !a.is_finite()) {
                return Err(PhysicsError::Invalid { quantity: Quantity::HolderMotion, value: a, expected: Expected::Finite });
            }
            if let Some(&a) = p.rotation.iter().find(|a| !(a.abs() <= MAX_ROTATION)) {
                return Err(PhysicsError::Invalid { quantity: Quantity::HolderMotion, value: a, expected: Expected::Within(MAX_ROTATION) });
            }
        }
        non_negative(Quantity::DampingAlpha, self.damping_alpha)?;
        non_negative(Quantity::DampingBeta, self.damping_beta)?;
        if let Some(t) = self.error_tolerance {
            positive(Quantity::ErrorTolerance, t)?;
        }
        if self.mode_weights.len() != n_modes {
            return Err(PhysicsError::Length { quantity: Quantity::ModeWeights, len: self.mode_weights.len(), expected: n_modes });
        }
        self.mode_weights.iter().try_for_each(|&w| non_negative(Quantity::ModeWeights, w))
    }
}

/// A state with the loads acting on it (and, for an adaptive run, what it
/// keeps beside the state of the run that steps).
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    pub state: State,
    pub loads: Loads,
    pub adaptive: Option<Box<AdaptivePart>>,
}

/// What an adaptive run keeps beside the state of the run that steps
/// (`docs/method.md`, section 10): its mode, the error model's state, the
/// estimate's sums and schedule, the stretch in full space and the vectors
/// its basis grew by.
#[derive(Clone, Debug, PartialEq)]
pub struct AdaptivePart {
    pub in_full: bool,
    /// `error` holds the state of the twin that goes on beside the run in
    /// full space (its y, y', y''; format 11), not e.
    pub twin: bool,
    /// e, e', e'' of the error model (free DOFs), or the twin's y, y', y''.
    pub error: [Vec<f64>; 3],
    /// Σ ‖ê‖²_M, Σ ‖x − x0‖²_M, ‖e‖²_M and Σ m |x − x0|² at the last estimate, the time since it,
    /// and the unseen residual's share (squared) at the last check of it (format 10; 0 before).
    pub sums: [f64; 6],
    /// Internal steps reduced and in all; the estimate's gap, period and steps since the last.
    pub counts: [u64; 5],
    /// Steps of the stretch in full space, the length it should reach, the next pose slot.
    pub stretch: [u64; 3],
    /// The stretch's poses kept (displacements from the linearization point).
    pub seen: Vec<Vec<f64>>,
    /// The vectors the basis grew by, oldest first.
    pub grown: Vec<Vec<f64>>,
    /// The slot positions the full-space error model was last linearized at (empty: at set-up, or none).
    pub linearized: Vec<f64>,
}

impl AdaptivePart {
    /// Every value is finite, every pose and grown vector has `n` values and
    /// each of the error model's `error_len`.
    pub fn fits(&self, n: usize, error_len: usize) -> bool {
        self.seen.iter().chain(&self.grown).all(|v| v.len() == n)
            && self.error.iter().all(|v| v.len() == error_len)
            && self.error.iter().chain(&self.seen).chain(&self.grown).flatten().chain(&self.sums).chain(&self.linearized).all(|x| x.is_finite())
    }
}
