//! Typed errors of the physics core.
//!
//! Each error says which quantity is at fault, which limit it passed and,
//! where there is one, what would lift it, in the terms of the physics
//! (`docs/method.md`). The FMI layer (`crate::model::messages`) turns them
//! into messages that name its variables; [`std::fmt::Display`] (thiserror) here is for
//! users of the core alone (tests, benchmarks, the study).

use crate::options::Integrator;

/// A quantity of the scene, the solver, the loads or a step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// Space dimension d.
    Dimension,
    /// Nodes per grid row.
    Columns,
    /// Grid rows.
    Rows,
    /// Rest distance between grid neighbours [m].
    Spacing,
    /// Lumped node mass [kg].
    NodeMass,
    /// Stiffness of the grid springs [N/m].
    SpringStiffness,
    /// Stiffness of the auxiliary out-of-plane springs [N/m].
    AuxStiffness,
    /// Upper bound on one internal step [s].
    MaxInternalStep,
    /// Number of modes kept or reported.
    Modes,
    /// Gravitational acceleration [m/s^2].
    Gravity,
    /// The force on the load node [N].
    PointLoad,
    Anchor,
    /// The holder's rotation vector [rad].
    Rotation,
    /// Mass-proportional Rayleigh damping alpha [1/s].
    DampingAlpha,
    /// Stiffness-proportional Rayleigh damping beta [s].
    DampingBeta,
    /// Gains of the kept modes.
    ModeWeights,
    /// Length of a communication step [s].
    StepSize,
    /// Relative error the cubature set is grown to reach.
    CubatureTolerance,
    /// Relative change of gravity's magnitude a trained basis trains for.
    TrainingScale,
    /// Tilt of gravity a trained basis trains for [rad].
    TrainingTilt,
    /// Length of each training run of a trained basis [s].
    TrainingTime,
    ErrorTolerance,
    /// Number of holders.
    Holders,
    /// A holder's displacement or rotation (holders 2 and on).
    HolderMotion,
}

impl Quantity {
    /// Its name in the words of `docs/method.md`.
    pub fn describe(self) -> &'static str {
        match self {
            Quantity::Dimension => "space dimension",
            Quantity::Columns => "nodes per row",
            Quantity::Rows => "rows",
            Quantity::Spacing => "node spacing",
            Quantity::NodeMass => "node mass",
            Quantity::SpringStiffness => "spring stiffness",
            Quantity::AuxStiffness => "auxiliary spring stiffness",
            Quantity::MaxInternalStep => "internal step bound",
            Quantity::Modes => "number of modes",
            Quantity::Gravity => "gravity",
            Quantity::PointLoad => "point load",
            Quantity::Anchor => "anchor displacement",
            Quantity::Rotation => "holder rotation",
            Quantity::DampingAlpha => "mass-proportional damping",
            Quantity::DampingBeta => "stiffness-proportional damping",
            Quantity::ModeWeights => "mode weights",
            Quantity::StepSize => "communication step",
            Quantity::CubatureTolerance => "cubature tolerance",
            Quantity::TrainingScale => "training range of gravity's magnitude",
            Quantity::TrainingTilt => "training range of gravity's tilt",
            Quantity::TrainingTime => "length of a training run",
            Quantity::ErrorTolerance => "error tolerance",
            Quantity::Holders => "number of holders",
            Quantity::HolderMotion => "holder displacement or rotation",
        }
    }
}

/// What a refused value had to be.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum Expected {
    /// Finite and > 0.
    #[error("finite and positive")]
    Positive,
    /// Finite and >= 0.
    #[error("finite and non-negative")]
    NonNegative,
    /// Finite.
    #[error("finite")]
    Finite,
    /// 2 or 3.
    #[error("2 or 3")]
    TwoOrThree,
    /// At least this value.
    #[error("at least {0}")]
    AtLeast(f64),
    /// At least 0 and below this value.
    #[error("finite, at least 0 and below {0}")]
    NonNegativeBelow(f64),
    /// At least 0 and at most this value.
    #[error("finite, at least 0 and at most {0}")]
    NonNegativeAtMost(f64),
    /// Above 0 and at most this value.
    #[error("above 0 and at most {0}")]
    PositiveAtMost(f64),
    /// At most this value in magnitude.
    #[error("finite and at most {0} in magnitude")]
    Within(f64),
    /// 1: a mode weight of an adaptive run, which approximates the
    /// unweighted physics on a basis of its own.
    #[error("1 in an adaptive run (it approximates the unweighted physics on a basis it chooses; weights act in a modal run)")]
    OneInAdaptive,
}

/// Why an internal step failed. The state is that of the start of the
/// communication step whenever one of these is returned.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum StepFailure {
    /// A coordinate or rate became NaN or infinite.
    #[error("the state became non-finite (internal step {dt:e} s); the integration diverged")]
    NonFinite { dt: f64 },
    /// Kinetic energy grew beyond what the loads could supply in one step.
    #[error("kinetic energy grew to {kinetic:e} J from {before:e} J in one step (internal step {dt:e} s); the integration diverged")]
    EnergyGrowth { kinetic: f64, before: f64, dt: f64 },
    /// The Newton iteration of an implicit step did not converge.
    #[error("implicit Newmark: Newton did not converge in {iterations} iterations at dt = {dt:e} s; shorten the internal steps")]
    NewtonNotConverged { iterations: usize, dt: f64 },
    /// The Newton matrix of an implicit step is singular.
    #[error("implicit Newmark: singular Newton matrix at dt = {dt:e} s")]
    SingularNewton { dt: f64 },
    /// The full-space Newton matrix is singular even as LDL^T (springs in
    /// compression buckle).
    #[error("the full-space Newmark matrix is singular (springs in compression buckle); shorten the internal steps")]
    Buckled,
    /// The trigonometric scheme: along the step, the part of the force
    /// beyond the modes' own springs changed as a stiffness `stiffness`
    /// [1/s^2] above `limit` = 4 / dt^2, beyond what its explicit kicks can
    /// follow (springs stretched or compressed far from rest stiffen modes
    /// whose own springs are soft).
    #[error("trigonometric scheme: the force beyond the modes' own springs stiffened to {stiffness:.3e} 1/s^2 along the step, above the {limit:.3e} 1/s^2 its explicit part follows at dt = {dt:e} s; shorten the internal steps")]
    RestTooStiff { stiffness: f64, limit: f64, dt: f64 },
    /// The anchor's velocity changes by `speed` at the start of the step:
    /// the sheet would move relative to it by more than half the spacing in
    /// one internal step of `dt` (`docs/method.md`, section 8).
    #[error("the anchor's velocity changes by {speed:e} m/s at the start of the step: the sheet would move relative to it by more than half the spacing per internal step of {dt:e} s (limit {limit:e} m/s); move the anchor more smoothly")]
    AnchorTooFast { speed: f64, limit: f64, dt: f64 },
    /// The holder's angular velocity changes by `rate` at the start of the
    /// step: the sheet's far end, `reach` from the pivot, would move
    /// relative to the holder by more than half the spacing in one internal step of `dt`.
    #[error("the holder's angular velocity changes by {rate:e} rad/s at the start of the step: the sheet, reaching {reach:e} m from the pivot, would move relative to the holder by more than half the spacing per internal step of {dt:e} s (limit {limit:e} rad/s); turn the holder more smoothly")]
    TurnTooFast { rate: f64, limit: f64, reach: f64, dt: f64 },
    /// Holder `holder` (2 or more) changes its velocity by `speed` at the
    /// start of the step, its far node `reach` from its pivot included: the
    /// sheet next to it would move relative to it by more than half the
    /// spacing in one internal step of `dt`.
    #[error("holder {holder}'s velocity changes by {speed:e} m/s at the start of the step: the sheet next to it would move relative to it by more than half the spacing per internal step of {dt:e} s (limit {limit:e} m/s); move the holder more smoothly")]
    HolderTooFast { holder: usize, speed: f64, limit: f64, dt: f64 },
    /// The explicit velocity update of a full-space step under a turning
    /// holder with stiffness-proportional damping did not converge (the
    /// holder turns by more than a radian per internal step).
    #[error("the velocity update with the Coriolis force did not converge at dt = {dt:e} s (the holder turns by {turn:e} rad per internal step); shorten the internal steps")]
    CoriolisNotConverged { turn: f64, dt: f64 },
}

/// An error of the physics core.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PhysicsError {
    /// A quantity outside what the solver can run.
    #[error("{} must be {expected}, got {value}", .quantity.describe())]
    Invalid { quantity: Quantity, value: f64, expected: Expected },
    /// An array of the wrong length.
    #[error("{} has {len} values, expected {expected}", .quantity.describe())]
    Length { quantity: Quantity, len: usize, expected: usize },
    /// More nodes than the arrays can hold.
    #[error("{nodes} nodes exceed the limit of {limit}")]
    TooManyNodes { nodes: f64, limit: usize },
    /// No node is free to move.
    #[error("no node is free to move: the scene has no free degree of freedom")]
    NoFreeNode,
    /// More modes asked for than there are free degrees of freedom.
    #[error("{modes} modes exceed the {dofs} free degrees of freedom of the scene")]
    ModesExceedDofs { modes: usize, dofs: usize },
    /// A dense eigen decomposition beyond its size limit.
    #[error("{modes} modes need a dense eigen decomposition of the {dofs} free DOFs, above the limit of {limit}; keep at most {partial_max} modes (solved by the partial eigensolver), or integrate in full space")]
    DenseEigenTooLarge { modes: usize, dofs: usize, limit: usize, partial_max: usize },
    /// More modes than the partial eigensolver can find reliably.
    #[error("{modes} modes are too many for the partial eigensolver on {coupled} coupled DOFs (at most 1/{fraction} of them)")]
    PartialTooManyModes { modes: usize, coupled: usize, fraction: usize },
    /// The partial eigensolver found fewer modes than asked for.
    #[error("the partial eigensolver found {found} of the {modes} lowest modes; keep fewer modes or integrate in full space")]
    PartialIncomplete { found: usize, modes: usize },
    /// The modes asked for reach a repeated eigenvalue the partial solver
    /// cannot resolve.
    #[error("the lowest {modes} modes reach a repeated eigenvalue ({lambda:.6e} 1/s^2), whose copies the partial eigensolver cannot all find; keep fewer modes (below the repeated one)")]
    RepeatedEigenvalue { modes: usize, lambda: f64 },
    /// The stiffness at the linearization point is not positive semi-definite.
    #[error("the stiffness at the linearization point has a negative eigenvalue {lambda}")]
    NegativeEigenvalue { lambda: f64 },
    /// A factorization or eigen decomposition failed.
    #[error("{what} failed: {detail}")]
    LinearAlgebra { what: &'static str, detail: String },
    /// No static equilibrium under the loads: Newton stopped at this
    /// fraction of the load, with this largest residual force relative to
    /// the largest load on a DOF.
    #[error("no static equilibrium found under the loads: Newton reached {load_fraction} of the load with a residual of {residual:.2e} of the largest load; linearize at rest")]
    NoEquilibrium { load_fraction: f64, residual: f64 },
    /// Every equilibrium found is unstable (its stiffness has a negative eigenvalue).
    #[error("every equilibrium found under the loads is unstable (its stiffness has a negative eigenvalue); linearize at rest")]
    UnstableEquilibrium,
    /// A basis built from the loads, and the loads are zero.
    #[error("modes chosen by the loads, or a static correction, need a load at set-up, and gravity and the point load are zero")]
    NoLoad,
    /// A non-zero point load on a node that is held (`held`) or not in the
    /// scene (`node` is the node index asked for, if any).
    #[error("the point load acts on node {node:?}, which is {}; choose a free node", if *.held { "held in place" } else { "not in the scene" })]
    LoadNode { node: Option<usize>, held: bool },
    /// The candidate vectors span fewer independent directions than asked for.
    #[error("the basis has {found} independent vectors, {wanted} were asked for")]
    BasisDeficient { wanted: usize, found: usize },
    /// The explicit integrator would need more than `limit` internal steps
    /// per internal step bound: the scene is too stiff for it.
    #[error("explicit Newmark is stable here only with internal steps of {stable_step:.3e} s (highest frequency {omega_max:.3e} rad/s of {}, stiffness / mass = {stiffness_per_mass:.3e} 1/s^2), {per_step:.2e} of them per internal step bound of {max_internal_step} s (limit {limit:e}): use implicit Newmark, fewer modes, or an internal step bound of {:.3e} s or less", kept(.modes), .stable_step * .limit)]
    ExplicitTooStiff {
        /// Largest stable internal step [s].
        stable_step: f64,
        /// Highest frequency of the integrated system [rad/s].
        omega_max: f64,
        /// Stiffest spring over the lightest node [1/s^2].
        stiffness_per_mass: f64,
        /// Internal steps per bound.
        per_step: f64,
        max_internal_step: f64,
        limit: f64,
        /// Modes kept, or `None` in full space.
        modes: Option<usize>,
    },
    /// A communication step that would need more internal steps than one call may take.
    #[error("a step of {h:e} s needs {steps:e} internal steps of at most {dt:e} s (limit {limit}); use the implicit integrator, fewer modes or a shorter communication step")]
    TooManyInternalSteps { h: f64, steps: f64, dt: f64, limit: usize },
    /// A communication step failed; the state is that of its start.
    #[error("step from t = {time} s failed: {cause}")]
    StepFailed {
        time: f64,
        #[source]
        cause: StepFailure,
    },
    /// The cubature set could not be grown to the tolerance within its
    /// size limit, or no spring left improves the fit.
    #[error("the cubature reached a relative force error of {reached:.3e} with {springs} springs, its limit (at most 1000 and half the springs), or the fit stopped improving, short of half the tolerance {tolerance:e} (the training's margin); that tolerance needs exact forces")]
    CubatureNotReached { tolerance: f64, reached: f64, springs: usize },
    /// More modes than a cubature is trained for.
    #[error("a cubature is trained for at most {limit} modes, {modes} are kept; keep fewer modes or use exact forces")]
    CubatureTooManyModes { modes: usize, limit: usize },
    /// The exact reduced run that makes the cubature's training poses diverged.
    #[error("the exact reduced run that makes the cubature's training poses diverged at t = {time} s; use exact forces")]
    CubatureTrainingDiverged { time: f64 },
    /// A full-space training run of a trained basis diverged.
    #[error("the full-space training run of the trained basis ({case}) diverged at t = {time} s; narrow the training range or choose another basis")]
    TrainingDiverged { case: String, time: f64 },
    /// Stored set-up data that does not fit the scene and solver.
    #[error("the stored set-up data does not fit the scene and solver: {what}")]
    SetupDataMismatch { what: &'static str },
    /// The scheme integrates the linear oscillator of every coordinate
    /// exactly and needs a space whose linear part is diagonal (the modal
    /// space); the full space's stiffness and damping couple its coordinates.
    #[error("the {} integrator integrates the linear oscillator of every mode exactly and needs the modal space; in full space the stiffness and the damping couple the coordinates", .scheme.name())]
    SchemeNeedsDiagonal { scheme: Integrator },
    /// The scheme integrates forces of the positions alone and cannot take
    /// the Coriolis force of a turning holder.
    #[error("the {} scheme integrates forces of the positions alone; a turning holder adds the Coriolis force, which depends on the rates", .scheme.name())]
    SchemeCannotTurn { scheme: Integrator },
    /// The held nodes cannot be split among the holders as asked.
    #[error("{0}")]
    Holders(HolderProblem),
    /// A snapshot whose arrays do not fit this simulator.
    #[error("the snapshot holds {len} state values, this simulator needs {expected}")]
    SnapshotLength { len: usize, expected: usize },
    /// A snapshot holding NaN or infinite values.
    #[error("the snapshot holds non-finite values")]
    SnapshotNotFinite,
    /// A snapshot an adaptive run cannot resume from, and why.
    #[error("an adaptive run cannot resume from this snapshot: {why}")]
    AdaptiveState { why: &'static str },
}

/// Why the held nodes cannot be given to the holders (holders counted from 1).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum HolderProblem {
    /// A custom pattern with a length other than the grid's nodes.
    #[error("the pattern of held nodes has {len} values, the grid has {expected} nodes")]
    PatternLength { len: usize, expected: usize },
    /// A node given to a holder beyond the number of holders.
    #[error("node (row {row}, column {col}) is given to holder {id}, and there are {holders} holders")]
    IdTooLarge { row: usize, col: usize, id: usize, holders: usize },
    /// A holder that holds no node.
    #[error("holder {holder} holds no node")]
    NoNode { holder: usize },
    /// A pattern that holds no node at all.
    #[error("the pattern holds no node: the sheet would fall")]
    NoHeldNode,
    /// More holders than held columns to split among them.
    #[error("{holders} holders cannot split the {columns} held columns among them (each needs a column)")]
    TooFewColumns { holders: usize, columns: usize },
    /// A holder that does not exist moved or turned.
    #[error("holder {holder} does not exist (there are {holders}); its displacement and rotation must stay 0")]
    Absent { holder: usize, holders: usize },
}

impl PhysicsError {
    /// The set-up refused the pairing of a space and a scheme, whatever the
    /// scene and the numbers (a scheme's [`check`](crate::physics::run::integrator::Scheme::check)):
    /// what tests, benchmarks and the study skip when they run every pair.
    pub fn refuses_pairing(&self) -> bool {
        matches!(self, PhysicsError::SchemeNeedsDiagonal { .. })
    }
}

/// The space of [`PhysicsError::ExplicitTooStiff`] in words.
fn kept(modes: &Option<usize>) -> String {
    match modes {
        Some(r) => format!("the {r} kept modes"),
        None => "full space".into(),
    }
}

/// Refuses `value` unless it is finite and positive.
pub fn positive(quantity: Quantity, value: f64) -> Result<(), PhysicsError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(PhysicsError::Invalid { quantity, value, expected: Expected::Positive })
    }
}

/// Refuses `value` unless it is finite and non-negative.
pub fn non_negative(quantity: Quantity, value: f64) -> Result<(), PhysicsError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(PhysicsError::Invalid { quantity, value, expected: Expected::NonNegative })
    }
}
