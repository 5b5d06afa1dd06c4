//! Physics errors as messages that name the FMU's variables: the one place
//! where the quantities of the core meet the names of the model description.

use crate::fmi::params::Params;
use crate::fmi::variables::vr;
use crate::options::{Integrator, Reduction};
use crate::physics::{FallBackCause, HolderProblem, PhysicsError, Quantity, ReductionStatus, StepFailure, Switch};

/// The variable that sets `q`.
pub fn variable(q: Quantity) -> &'static str {
    match q {
        Quantity::Dimension => "dimension",
        Quantity::Columns => "nx",
        Quantity::Rows => "ny",
        Quantity::Spacing => "spacing",
        Quantity::NodeMass => "nodeMass",
        Quantity::SpringStiffness => "springStiffness",
        Quantity::AuxStiffness => "auxStiffness",
        Quantity::MaxInternalStep => "maxInternalStep",
        Quantity::Modes => "nModes",
        Quantity::Gravity => "gravity",
        Quantity::PointLoad => "loadX, loadY, loadZ",
        Quantity::Anchor => "anchorX, anchorY, anchorZ",
        Quantity::Rotation => "anchorRX, anchorRY, anchorRZ",
        Quantity::DampingAlpha => "dampingAlpha",
        Quantity::DampingBeta => "dampingBeta",
        Quantity::ModeWeights => "modeWeights",
        Quantity::StepSize => "communicationStepSize",
        Quantity::CubatureTolerance => "cubatureTolerance",
        Quantity::TrainingScale => "trainingScale",
        Quantity::TrainingTilt => "trainingTilt",
        Quantity::TrainingTime => "trainingTime",
        Quantity::ErrorTolerance => "errorTolerance",
        Quantity::Holders => "nHolders",
        Quantity::HolderMotion => "anchor{k}X ... anchor{k}RZ",
    }
}

/// An adaptive run's last fall-back or return (`docs/method.md`, section
/// 10) for the log; `time0` is the start time of the run.
pub fn switch(status: &ReductionStatus, time0: f64) -> String {
    let (fraction, estimate) = (status.reduced_fraction, status.error_estimate);
    match status.last_switch {
        Switch::FallBack { time, why } => {
            let cause = match why {
                FallBackCause::OutsideProgram => "gravity or the point load is outside the training program (trainingScale, trainingTilt)".to_string(),
                FallBackCause::Error { estimate, limit } => {
                    format!("the estimated error of the state reached {estimate:.2e} of the motion, above {limit:.2e} (0.4 errorTolerance)")
                }
                FallBackCause::Unseen { share, limit } => format!(
                    "the force the error model cannot see reached {share:.2} of the load, above {limit:.2}; errorEstimate \
                     leaves out the error that force drove before (it may read low from here)"
                ),
            };
            format!(
                "reduction = adaptive: full space from t = {} ({cause}); errorEstimate {estimate:.2e}, reducedFraction {fraction:.3}",
                seconds(time0 + time)
            )
        }
        Switch::Return { time, vectors } => format!(
            "reduction = adaptive: back to the reduced model at t = {} on {vectors} vectors; errorEstimate {estimate:.2e}, \
             reducedFraction {fraction:.3}",
            seconds(time0 + time)
        ),
        Switch::None => "reduction = adaptive: no switch".to_string(),
    }
}

/// A time to nine decimals, without trailing zeros (0.13999999999999999 as 0.14).
fn seconds(t: f64) -> String {
    let s = format!("{t:.9}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// `e` in the words of the model description, for an instance with values `p`.
pub fn describe(e: &PhysicsError, p: &Params) -> String {
    use PhysicsError::*;
    let integrator = |i: Integrator| format!("integrator = {}", i.name());
    match e {
        Invalid { quantity, value, expected } => format!("{} must be {expected}, got {value}", variable(*quantity)),
        Length { quantity, len, expected } => format!("{} has {len} values, nModes is {expected}", variable(*quantity)),
        TooManyNodes { nodes, limit } => format!("nx * ny = {nodes} exceeds the limit of {limit} nodes"),
        NoFreeNode => format!(
            "ny = {} (nx = {}) leaves no free node under fixedNodes: the scene has no free degree of freedom; \
             it needs ny >= 2 (or nx >= 3 with top-corners)",
            p.scalar(vr::NY),
            p.scalar(vr::NX)
        ),
        ModesExceedDofs { modes, dofs } => format!("nModes = {modes} exceeds the {dofs} free degrees of freedom of the scene"),
        DenseEigenTooLarge { modes, dofs, limit, partial_max } => format!(
            "nModes = {modes} needs a dense eigen decomposition of the {dofs} free DOFs, above the limit of {limit}; \
             keep at most {partial_max} modes (solved by the partial eigensolver), or use reduction = {}",
            Reduction::Full.name()
        ),
        PartialTooManyModes { modes, coupled, fraction } => {
            format!("nModes = {modes} is too many for the partial eigensolver on {coupled} coupled DOFs (at most 1/{fraction} of them)")
        }
        PartialIncomplete { found, modes } => {
            format!(
                "the partial eigensolver found {found} of the nModes = {modes} lowest modes; keep fewer modes or use reduction = {}",
                Reduction::Full.name()
            )
        }
        RepeatedEigenvalue { modes, lambda } => format!(
            "the lowest nModes = {modes} modes reach a repeated eigenvalue ({lambda:.6e} 1/s^2), whose copies the partial \
             eigensolver cannot all find; keep fewer modes (below the repeated one)"
        ),
        NegativeEigenvalue { lambda } => format!("the stiffness matrix at rest has a negative eigenvalue {lambda}"),
        LinearAlgebra { .. } => e.to_string(),
        NoEquilibrium { load_fraction, residual } => format!(
            "linearization = equilibrium: no static equilibrium found under gravity and the point load (Newton reached {load_fraction} of \
             the load with a residual of {residual:.2e} of the largest load); use linearization = rest, or a smaller load"
        ),
        UnstableEquilibrium => "linearization = equilibrium: every equilibrium found under the loads is unstable (its stiffness has a \
                                negative eigenvalue); use linearization = rest"
            .into(),
        NoLoad => "modeSelection = load or trained and staticCorrection = true build the basis from the loads at set-up, and gravity and the point load (loadX, loadY, loadZ) are zero: \
                   set gravity or the point load before initialization, or use modeSelection = lowest without staticCorrection"
            .into(),
        LoadNode { .. } => format!(
            "the load node (loadRow, loadColumn) must be a free node of the grid: {}",
            p.load_node_problem().unwrap_or_else(|| format!("loadRow = {}, loadColumn = {}", p.scalar(vr::LOAD_ROW), p.scalar(vr::LOAD_COLUMN)))
        ),
        BasisDeficient { wanted, found } => format!("the basis has {found} independent vectors, nModes = {wanted}: keep fewer modes"),
        ExplicitTooStiff { stable_step, omega_max, stiffness_per_mass, per_step, max_internal_step, limit, modes } => {
            let kept = match modes {
                Some(r) => format!("the {r} kept modes"),
                None => "full space".to_string(),
            };
            format!(
                "{} is stable here only with internal steps of {stable_step:.3e} s \
                 (highest frequency {omega_max:.3e} rad/s of {kept}, springStiffness / nodeMass = {stiffness_per_mass:.3e} 1/s^2), \
                 {per_step:.2e} of them per maxInternalStep = {max_internal_step} s (limit {limit:e}): \
                 use {}, fewer modes (nModes), or set maxInternalStep to {:.3e} s or less to accept steps that short",
                integrator(Integrator::NewmarkExplicit),
                integrator(Integrator::NewmarkImplicit),
                stable_step * limit,
            )
        }
        TooManyInternalSteps { h, steps, dt, limit } => format!(
            "a step of {h:e} s needs {steps:e} internal steps of at most {dt:e} s (limit {limit}); \
             use {}, fewer modes (nModes) or a shorter communication step",
            integrator(Integrator::NewmarkImplicit)
        ),
        StepFailed { time, cause } => format!("step from t = {time} s failed: {}", failure(cause)),
        CubatureNotReached { tolerance, reached, springs } => format!(
            "forceEvaluation = cubature: the cubature set reached a relative force error of {reached:.3e} with {springs} springs, \
             its limit (at most 1000 and half the springs) or where the fit stopped improving, short of half of \
             cubatureTolerance = {tolerance:e}; raise cubatureTolerance or use forceEvaluation = exact"
        ),
        CubatureTooManyModes { modes, limit } => {
            format!("forceEvaluation = cubature is trained for at most {limit} modes, nModes = {modes}; keep fewer modes or use forceEvaluation = exact")
        }
        CubatureTrainingDiverged { time } => format!(
            "forceEvaluation = cubature: the exact reduced run under gravity that makes the training poses diverged at t = {time} s; \
             use forceEvaluation = exact"
        ),
        TrainingDiverged { case, time } => format!(
            "modeSelection = trained: the full-space training run ({case}) diverged at t = {time} s; narrow the training range \
             (trainingScale, trainingTilt) or choose another modeSelection"
        ),
        SetupDataMismatch { .. } => e.to_string(),
        SchemeNeedsDiagonal { scheme } => format!(
            "{} integrates the linear oscillator of every mode exactly and needs reduction = {}: with reduction = {} the \
             stiffness and the damping couple every degree of freedom; use reduction = {}, or {} or {} in full space",
            integrator(*scheme),
            Reduction::Modal.name(),
            Reduction::Full.name(),
            Reduction::Modal.name(),
            integrator(Integrator::NewmarkExplicit),
            integrator(Integrator::NewmarkImplicit),
        ),
        SchemeCannotTurn { scheme } => format!(
            "{} integrates forces of the positions alone; a turning holder (anchorRX, anchorRY, anchorRZ changing in Step Mode) adds \
             the Coriolis force, which depends on the rates: use {} or {} (a holder turned before initialization and kept still is accepted)",
            integrator(*scheme),
            integrator(Integrator::NewmarkExplicit),
            integrator(Integrator::NewmarkImplicit),
        ),
        Holders(problem) => holders(problem, p),
        SnapshotLength { len, expected } => format!("the state holds {len} values per array, this scene needs {expected}"),
        SnapshotNotFinite => "the state holds non-finite values".into(),
        AdaptiveState { why } => format!("reduction = adaptive: the state cannot be restored: {why}"),
    }
}

/// Why the held nodes cannot be split as asked, in the variables' names.
fn holders(problem: &HolderProblem, p: &Params) -> String {
    let n = p.scalar(vr::N_HOLDERS);
    match problem {
        HolderProblem::PatternLength { len, expected } => format!("holderOfNode has {len} values, the grid nx * ny has {expected} nodes"),
        HolderProblem::IdTooLarge { row, col, id, holders } => {
            format!("holderOfNode[{row}][{col}] = {id} names a holder beyond nHolders = {holders}: use 0 (free) to {holders}")
        }
        HolderProblem::NoNode { holder } => format!(
            "holder {holder} holds no node (nHolders = {n}, fixedNodes = {}): {}",
            fixed_name(p),
            if p.scalar(vr::FIXED_NODES) == 3.0 { "give it nodes in holderOfNode or lower nHolders" } else { "lower nHolders" }
        ),
        HolderProblem::NoHeldNode => "fixedNodes = custom and holderOfNode holds no node: the sheet would fall; give at least one node a holder".into(),
        HolderProblem::TooFewColumns { holders, columns } => format!(
            "nHolders = {holders} cannot split the {columns} held columns of fixedNodes = {} among them (each holder needs a column): \
             lower nHolders, or use fixedNodes = custom with holderOfNode",
            fixed_name(p)
        ),
        HolderProblem::Absent { holder, holders } => {
            format!("anchor{holder}X ... anchor{holder}RZ move holder {holder}, and nHolders = {holders}: only 0 is accepted for a holder that does not exist")
        }
    }
}

fn fixed_name(p: &Params) -> &'static str {
    crate::options::FixedNodes::from_value(p.scalar(vr::FIXED_NODES) as i64).map_or("?", |f| f.name())
}

fn failure(cause: &StepFailure) -> String {
    let integrator = |i: Integrator| format!("integrator = {}", i.name());
    match cause {
        StepFailure::NonFinite { .. } | StepFailure::EnergyGrowth { .. } | StepFailure::SingularNewton { .. } => cause.to_string(),
        StepFailure::AnchorTooFast { speed, limit, dt } => format!(
            "the anchor's velocity changes by {speed:e} m/s at the start of the step (anchorX, anchorY, anchorZ): the sheet would \
             move relative to it by more than half the spacing per internal step of {dt:e} s (limit {limit:e} m/s); move the anchor \
             in smaller steps, or lower maxInternalStep"
        ),
        StepFailure::TurnTooFast { rate, limit, reach, dt } => format!(
            "the holder's angular velocity changes by {rate:e} rad/s at the start of the step (anchorRX, anchorRY, anchorRZ): the \
             sheet, reaching {reach:e} m from the pivot, would move relative to the holder by more than half the spacing per internal \
             step of {dt:e} s (limit {limit:e} rad/s); turn the holder in smaller steps, or lower maxInternalStep"
        ),
        StepFailure::HolderTooFast { holder, speed, limit, dt } => format!(
            "holder {holder}'s velocity changes by {speed:e} m/s at the start of the step (anchor{holder}X ... anchor{holder}RZ): the \
             sheet next to it would move relative to it by more than half the spacing per internal step of {dt:e} s (limit {limit:e} \
             m/s); move the holder in smaller steps, or lower maxInternalStep"
        ),
        StepFailure::CoriolisNotConverged { .. } => format!("{cause}; lower maxInternalStep"),
        StepFailure::NewtonNotConverged { iterations, dt } => {
            format!("implicit Newmark: Newton did not converge in {iterations} iterations at dt = {dt:e} s; reduce maxInternalStep")
        }
        StepFailure::Buckled => "the full-space Newmark matrix is singular (springs in compression buckle); reduce maxInternalStep".into(),
        StepFailure::RestTooStiff { stiffness, limit, dt } => format!(
            "{}: the force beyond the modes' own springs (springs stretched or compressed far from rest) stiffened to {stiffness:.3e} \
             1/s^2 along the step, above the {limit:.3e} 1/s^2 its explicit part follows at internal steps of {dt:e} s; use a \
             shorter communication step or maxInternalStep (below {:.3e} s), or {}",
            integrator(Integrator::Trigonometric),
            2.0 / stiffness.sqrt(),
            integrator(Integrator::NewmarkExplicit),
        ),
    }
}
