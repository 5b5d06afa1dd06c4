//! The adaptive reduction at set-up and on each return from full space
//! (`docs/method.md`, section 10): the basis sized for the error tolerance,
//! and the basis grown from what a full-space stretch saw.
//!
//! **Size.** The training program's snapshots d_k (displacements from the
//! linearization point x*, [`trained_basis::snapshots`]) are split by sample:
//! the even ones train, the odd ones are held out. With c_j the first j
//! mass-weighted principal components of the even ones (M-orthonormal),
//! the held-out projection error of j components is
//!
//! ```text
//! P(j) = sqrt( Σ_k ‖d_k − Σ_{i≤j} c_i c_iᵀ M d_k‖²_M / Σ_k ‖d_k‖²_M ),   k odd,
//! ```
//!
//! the part of the held-out motion j components cannot hold, measured as
//! E is. The basis keeps the fewest components with P(j) ≤
//! [`PROJECTION_SHARE`] × tolerance (the rest of the tolerance is left to
//! the dynamics: a basis that holds every pose to P still moves between
//! them with an error), plus the vectors a trained basis always keeps
//! ([`trained_basis::fixed_vectors`]), and is trained on every snapshot as
//! a trained basis is ([`trained_basis::train_on`]).
//!
//! **Growth.** After a stretch in full space, the stretch's displacements
//! less their part in the basis, s_k − Φ Φᵀ M s_k, give their principal
//! components; the largest [`GROWTH`] of them (at least one) join the
//! basis, which is M-orthonormalized and diagonalized again
//! ([`basis::orthonormal_ritz`]). The trained vectors always stay; the
//! vectors grown stay while the basis holds at most [`CAP_FACTOR`] times
//! the size chosen at set-up, the oldest dropped first.
//!
//! **Forces.** Cubature forces where they pay ([`CUBATURE_PAYS`] springs
//! per vector, or [`CUBATURE_SPRINGS_PER_VECTOR`] when asked for) and the
//! basis with its error directions holds at most [`JOINT_CUBATURE_MODES`]
//! vectors: one cubature is trained for the basis and the error directions
//! together ([`error_cubature`]); it serves the error model
//! ([`crate::physics::run::error_directions`]) and every grown basis.
//!
//! **Stored.** What costs time here (the training runs, the basis and both
//! cubatures) is kept as set-up data with an adaptive section
//! ([`Chosen::stored`]); [`choose_from`] rebuilds the same choice from it,
//! bit for bit, deriving the rest again (the stiffness at x*, the trained
//! vectors, the settings of the trained basis).

use crate::physics::error::PhysicsError;
use crate::physics::run::error_directions::error_directions;
use crate::physics::run::space::basis_bound;
use crate::physics::run::state::Loads;
use crate::physics::run::stiffness::StiffnessPattern;
use crate::physics::settings::{ForceEvaluation, Linearization, ModeSelection, Settings};
use crate::physics::setup::basis;
use crate::physics::setup::cubature_training;
use crate::physics::setup::modes::ModalBasis;
use crate::physics::setup::scene::Scene;
use crate::physics::setup::setup_data::{AdaptiveChoice, SetupData, SpringSet};
use crate::physics::setup::trained_basis::{self, principal_components, Linearized};

/// The reduced model pays where the chosen basis holds at most one vector
/// per this many free DOFs; on a smaller scene the run is full space
/// throughout. A reduced step expands and projects through the basis (2 n r
/// flops each way, at least n²/8 beyond this) besides its force pass; a
/// full-space step costs a pass over the springs, a few per DOF (measured
/// in report/: on paper-2d-top-row, 180 DOFs and 34 vectors, a run with the
/// estimate took 7x the full-space run's time at the same step).
pub const DOFS_PER_VECTOR: usize = 32;

/// Why an adaptive run goes in full space throughout, where it does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FullThroughout {
    /// The basis holds more than one vector per [`DOFS_PER_VECTOR`] free DOFs.
    FewDofs,
    /// Cubature forces would pay ([`CUBATURE_PAYS`] springs per vector) but
    /// the basis and its error directions pass [`JOINT_CUBATURE_MODES`]:
    /// exact forces visit every spring at each reduced step, as a full-space
    /// step does, beside 4 n r operations, and the full-space error model's
    /// sparse factorization costs tens of steps on a scene this large
    /// (cloth 100 x 100 at a tolerance of 0.003, 28 vectors: a reduced step
    /// 0.92 ms against 0.7 ms for full space at 1/240 s, an estimate 60 to
    /// 130 ms; 1.5 s of simulation in 2.7 s against 0.26 s in full space).
    ExactForces,
}

/// Whether the reduced model of `chosen` on `scene` can pay, and if not why
/// not: the run then goes in full space throughout.
pub fn full_throughout(scene: &Scene, chosen: &Chosen) -> Option<FullThroughout> {
    let r = chosen.data.basis.r.max(1);
    if scene.n_dofs() < DOFS_PER_VECTOR * r {
        Some(FullThroughout::FewDofs)
    } else if chosen.choice.error_set.is_none() && scene.springs.len() / r >= CUBATURE_PAYS {
        Some(FullThroughout::ExactForces)
    } else {
        None
    }
}

/// Share of the tolerance the held-out projection error may take.
pub const PROJECTION_SHARE: f64 = 0.25;
/// The basis may grow to this many times its size at set-up.
pub const CAP_FACTOR: usize = 2;
/// Share of the set-up size one return from full space may add (at least one vector).
pub const GROWTH: f64 = 0.25;

/// What set-up chose for an adaptive run: the stored part ([`Chosen::stored`]) and what is derived from it.
pub struct Chosen {
    /// The trained basis (and its cubature, if asked for); no adaptive section (that is `choice`).
    pub data: SetupData,
    /// The rest of what set-up chose: the components kept and their
    /// held-out error, the motion scale, the training poses, the error
    /// model's candidate directions (the held-out split's principal
    /// components beyond the basis, up to [`ERROR_DIRECTIONS`] times as many
    /// as it holds, and the rigid translations) and, with cubature forces,
    /// its spring set.
    pub choice: AdaptiveChoice,
    /// The stiffness at the linearization point, for the error model.
    pub pattern: StiffnessPattern,
    pub stiffness: Vec<f64>,
    /// The basis vectors of the trained set-up, as columns (kept through every growth).
    pub trained: Vec<Vec<f64>>,
    /// The settings of the trained basis: its size, force model and cubature tolerance.
    pub settings: Settings,
}

impl Chosen {
    /// The set-up data [`choose_from`] rebuilds this choice from: the
    /// trained basis with the choice as its adaptive section.
    pub fn stored(&self) -> SetupData {
        SetupData { adaptive: Some(self.choice.clone()), ..self.data.clone() }
    }
}

/// The error model may take this many times as many principal components as the basis holds.
pub const ERROR_DIRECTIONS: usize = 1;

/// With cubature forces asked for, they are used when the scene has at least this many springs per basis vector.
pub const CUBATURE_SPRINGS_PER_VECTOR: usize = 20;
/// Cubature forces are used whatever was asked for when the scene has at
/// least this many springs per basis vector: a cubature keeps about 10 to 30
/// springs per vector, and a reduced step with exact forces visits every
/// spring, as a full-space step does.
pub const CUBATURE_PAYS: usize = 1000;
/// Cubature forces only where the basis and the error directions together
/// hold at most this many vectors: training their cubature grows with the
/// springs it keeps (about 2 s for 33 vectors on cloth 100 x 100), and the
/// 57 of cloth 40 x 40 stop at the cubature's 1000 springs short of its goal.
pub const JOINT_CUBATURE_MODES: usize = 40;

/// The held-out projection error P(j) for j = 0 ..= components of `train`
/// (see the module documentation), and the components.
pub fn held_out_errors(mass: &[f64], train: &[Vec<f64>], held_out: &[Vec<f64>], components: usize) -> Result<(Vec<f64>, Vec<Vec<f64>>), PhysicsError> {
    let c = principal_components(mass, train, components)?;
    let total: f64 = held_out.iter().map(|d| m_dot(mass, d, d)).sum();
    let mut left = total;
    let mut errors = vec![ratio(left, total)];
    for cj in &c {
        left -= held_out.iter().map(|d| m_dot(mass, cj, d).powi(2)).sum::<f64>();
        errors.push(ratio(left.max(0.0), total));
    }
    Ok((errors, c))
}

fn ratio(part: f64, total: f64) -> f64 {
    if total > 0.0 {
        (part / total).sqrt()
    } else {
        0.0
    }
}

/// uᵀ M v.
pub fn m_dot(mass: &[f64], u: &[f64], v: &[f64]) -> f64 {
    mass.iter().zip(u).zip(v).map(|((m, a), b)| m * a * b).sum()
}

/// The set-up of an adaptive run on `scene` under the set-up `loads` (see the module documentation).
pub fn choose(scene: &Scene, loads: &Loads, settings: &Settings) -> Result<Chosen, PhysicsError> {
    let n = scene.n_dofs();
    let trained_settings = Settings { mode_selection: ModeSelection::Trained, ..settings.clone() };
    let (point, pattern, stiffness) = basis::linearize(scene, loads, &trained_settings)?;
    let columns = trained_basis::snapshots(scene, loads, &trained_settings, &point)?;
    let (even, odd): (Vec<Vec<f64>>, Vec<Vec<f64>>) = {
        let (e, o): (Vec<_>, Vec<_>) = columns.iter().enumerate().partition(|(k, _)| k % 2 == 0);
        (e.into_iter().map(|(_, c)| c.clone()).collect(), o.into_iter().map(|(_, c)| c.clone()).collect())
    };
    let most = even.len().min(n);
    let (errors, mut pcs) = held_out_errors(&scene.dof_mass, &even, &odd, most)?;
    drop((even, odd));
    let target = PROJECTION_SHARE * settings.error_tolerance;
    let found = errors.iter().position(|&e| e <= target);
    let components = found.unwrap_or(errors.len() - 1).max(1);
    // The error model's directions: the components beyond the basis, and the rigid translations.
    let mut error_directions: Vec<Vec<f64>> = pcs.drain(..).skip(components).take(ERROR_DIRECTIONS * components).collect();
    for axis in 0..scene.dim {
        error_directions.push((0..n).map(|i| if i % scene.dim == axis { 1.0 } else { 0.0 }).collect());
    }
    let motion_scale = (columns.iter().map(|d| m_dot(&scene.dof_mass, d, d)).sum::<f64>() / columns.len().max(1) as f64).sqrt();
    let at = Linearized { point, pattern: &pattern, stiffness: &stiffness };
    let statics = trained_basis::fixed_vectors(scene, loads, &trained_settings, &at)?;
    let size = (components + statics.len()).min(n);
    // Cubature forces where they pay (asked for, or a scene with many springs
    // per vector), at the tolerance's accuracy, for the basis and the error directions.
    let per_vector = scene.springs.len() / size.max(1);
    let cubature = (per_vector >= CUBATURE_PAYS || settings.force_evaluation == ForceEvaluation::Cubature && per_vector >= CUBATURE_SPRINGS_PER_VECTOR)
        && size + error_directions.len() <= JOINT_CUBATURE_MODES;
    let sized = sized_settings(settings, size, cubature);
    let data = trained_basis::train_on(scene.clone(), loads, &sized, at, statics, &columns)?;
    let poses: Vec<Vec<f64>> = columns
        .iter()
        .map(|d| {
            let mut q = vec![0.0; data.basis.r];
            data.basis.project_displacement(&scene.dof_mass, d, &mut q);
            q
        })
        .collect();
    drop(columns);
    let error_set = if cubature { Some(error_cubature(scene, loads, &sized, &data, &error_directions, &poses)?) } else { None };
    let trained = columns_of(&data.basis);
    let choice = AdaptiveChoice {
        held_out_error: errors[components.min(errors.len() - 1)],
        components,
        short: found.is_none(),
        motion_scale,
        poses,
        error_directions,
        error_set,
    };
    Ok(Chosen { data, choice, pattern, stiffness, trained, settings: sized })
}

/// The settings of the trained basis of `size` vectors an adaptive run
/// with `settings` steps on, with cubature forces or exact ones; the
/// cubature is trained to the error tolerance (at most 1).
fn sized_settings(settings: &Settings, size: usize, cubature: bool) -> Settings {
    Settings {
        n_modes: size,
        mode_selection: ModeSelection::Trained,
        force_evaluation: if cubature { ForceEvaluation::Cubature } else { ForceEvaluation::Exact },
        cubature_tolerance: settings.error_tolerance.min(1.0),
        ..settings.clone()
    }
}

/// [`choose`] from what it stored ([`Chosen::stored`] of a set-up of the
/// same scene, set-up loads and settings), bit for bit: the stiffness at
/// the stored linearization point assembled as [`basis::linearize`]
/// assembles it, the trained vectors the stored basis's columns, the
/// settings those of a basis of its size with cubature forces where it has
/// a cubature. Refuses data without an adaptive section or whose sizes or
/// spring sets do not fit `scene` (the basis itself is checked where the
/// reduced run takes it).
pub fn choose_from(scene: &Scene, settings: &Settings, stored: &SetupData) -> Result<Chosen, PhysicsError> {
    let fail = |what| Err(PhysicsError::SetupDataMismatch { what });
    let Some(choice) = &stored.adaptive else {
        return fail("it holds no adaptive set-up");
    };
    let (n, r) = (stored.basis.n, stored.basis.r);
    if n != scene.n_dofs() || Some(stored.basis.phi.len()) != n.checked_mul(r) || stored.point.len() != scene.rest.len() {
        return fail("basis size");
    }
    if !choice.fits(n, r) {
        return fail("adaptive set-up");
    }
    let springs = scene.springs.len();
    if choice.error_set.is_some() != stored.cubature.is_some() || choice.error_set.as_ref().is_some_and(|c| c.springs.iter().any(|&s| s >= springs)) {
        return fail("error model's spring set");
    }
    let mut data = stored.clone();
    let choice = data.adaptive.take().expect("checked above");
    let pattern = StiffnessPattern::new(scene);
    let stiffness = basis::stiffness_at(scene, &pattern, &data.point);
    let trained = columns_of(&data.basis);
    let settings = sized_settings(settings, r, data.cubature.is_some());
    Ok(Chosen { data, choice, pattern, stiffness, trained, settings })
}

/// The cubature of the error model (`crate::physics::run::error_directions`): a spring
/// set trained on the program's poses `poses` (coordinates in `data`'s basis)
/// for the forces projected on the basis and its error directions from
/// `candidates` together.
fn error_cubature(
    scene: &Scene,
    loads: &Loads,
    settings: &Settings,
    data: &SetupData,
    candidates: &[Vec<f64>],
    poses: &[Vec<f64>],
) -> Result<SpringSet, PhysicsError> {
    let b = &data.basis;
    let directions = error_directions(&scene.dof_mass, b, candidates);
    let (n, r, k) = (b.n, b.r, directions.len());
    let mut phi = Vec::with_capacity(n * (r + k));
    for i in 0..n {
        phi.extend_from_slice(&b.phi[i * r..(i + 1) * r]);
        phi.extend(directions.iter().map(|d| d[i]));
    }
    let top = b.lambda.iter().copied().fold(0.0, f64::max);
    let lambda = b.lambda.iter().copied().chain(std::iter::repeat_n(top, k)).collect();
    let joint = SetupData { basis: ModalBasis { n, r: r + k, lambda, phi }, cubature: None, range: None, adaptive: None, ..data.clone() };
    let padded: Vec<Vec<f64>> = poses.iter().map(|q| q.iter().copied().chain(std::iter::repeat_n(0.0, k)).collect()).collect();
    let settings = Settings { n_modes: r + k, force_evaluation: ForceEvaluation::Cubature, ..settings.clone() };
    let trained = cubature_training::train(scene.clone(), loads, &settings, Some(&joint), Some(&padded))?;
    Ok(trained.cubature.expect("a cubature training gives a spring set"))
}

/// The columns of a basis (row-major n x r) as vectors.
pub fn columns_of(b: &ModalBasis) -> Vec<Vec<f64>> {
    (0..b.r).map(|j| (0..b.n).map(|i| b.phi[i * b.r + j]).collect()).collect()
}

/// The directions a stretch in full space saw that `current` does not
/// hold: the largest `count` principal components of the stretch's
/// displacements `seen` (from the linearization point) less their part in
/// `current`, those above 1e-6 of the largest displacement seen.
pub fn new_directions(scene: &Scene, current: &ModalBasis, seen: &[Vec<f64>], count: usize) -> Result<Vec<Vec<f64>>, PhysicsError> {
    let mass = &scene.dof_mass;
    let mut q = vec![0.0; current.r];
    let rests: Vec<Vec<f64>> = seen
        .iter()
        .map(|s| {
            current.project_displacement(mass, s, &mut q);
            let mut rest = s.clone();
            for (i, ri) in rest.iter_mut().enumerate() {
                *ri -= current.phi[i * current.r..(i + 1) * current.r].iter().zip(&q).map(|(p, q)| p * q).sum::<f64>();
            }
            rest
        })
        .collect();
    let largest = seen.iter().map(|s| m_dot(mass, s, s)).fold(0.0, f64::max).sqrt();
    let biggest_rest = rests.iter().map(|s| m_dot(mass, s, s)).fold(0.0, f64::max).sqrt();
    if !(biggest_rest > 1e-6 * largest) {
        return Ok(Vec::new());
    }
    principal_components(mass, &rests, count)
}

/// The basis of `vectors` (trained first, then grown), M-orthonormalized
/// and diagonalized with the stiffness at the linearization point, as the
/// data a modal space is built from; with cubature forces the error
/// model's spring set serves it (trained for the set-up basis and the
/// directions beyond it; not trained again).
pub fn grown_setup(scene: &Scene, chosen: &Chosen, vectors: &[Vec<f64>]) -> Result<SetupData, PhysicsError> {
    let modes = match basis::orthonormal_ritz(scene, &chosen.pattern, &chosen.stiffness, vectors, vectors.len()) {
        Err(PhysicsError::BasisDeficient { found, .. }) if found > 0 => basis::orthonormal_ritz(scene, &chosen.pattern, &chosen.stiffness, vectors, found)?,
        other => other?,
    };
    let omega_sq_bound = basis_bound(scene, &modes)?;
    Ok(SetupData {
        basis: modes,
        point: chosen.data.point.clone(),
        at_rest: chosen.settings.linearization == Linearization::Rest,
        omega_sq_bound,
        cubature: chosen.choice.error_set.clone(),
        range: None,
        adaptive: None,
    })
}
