//! The modal basis a scene needs (`docs/method.md`, section 3): where to
//! linearize, which modes to keep, and whether to add the static response
//! to the loads.
//!
//! - **Linearization** at rest (the paper), or at the static equilibrium
//!   under the loads ([`crate::physics::setup::equilibrium`]), where the stiffness includes
//!   the geometric stiffness of the stretched springs.
//! - **Selection**: the r lowest modes (the paper), or the r modes that
//!   carry most of the static response to the loads, ranked by
//!   |φ_iᵀ f| / λ_i for each load pattern f. On scenes up to
//!   [`DENSE_CANDIDATES`] free DOFs every mode is a candidate; above, the
//!   candidates are the Ritz pairs of a Krylov space grown from K⁻¹ f
//!   (load-dependent Ritz vectors, Wilson, Yuan and Dickens 1982), which
//!   reaches the loaded modes from one sparse factorization however many
//!   unloaded modes lie below them.
//! - **Static correction**: the static responses K⁻¹ f join the kept modes;
//!   the enriched set is M-orthonormalized and diagonalized in its own
//!   span (Rayleigh–Ritz), so every basis vector has a frequency and
//!   Φᵀ M Φ = I, Φᵀ K Φ = diag(λ) hold as for eigenmodes. The number of
//!   modes counts every basis vector.

use faer::linalg::matmul::matmul;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Accum, Col, Mat, MatMut, MatRef, Par, Side};

use crate::physics::error::PhysicsError;
use crate::physics::run::frame::cross;
use crate::physics::run::state::Loads;
use crate::physics::run::stiffness::StiffnessPattern;
use crate::physics::settings::{Linearization, ModeSelection, Settings};
use crate::physics::setup::equilibrium::equilibrium;
use crate::physics::setup::modes::ModalBasis;
use crate::physics::setup::scene::Scene;
use crate::physics::vector_unit;

/// Scenes up to this many free DOFs rank every mode (a dense decomposition);
/// larger ones rank load-dependent Ritz pairs.
pub const DENSE_CANDIDATES: usize = 1500;
/// Krylov vectors per kept mode in the load-dependent Ritz space (and at least this many more than kept).
const RITZ_FACTOR: usize = 4;
const RITZ_EXTRA: usize = 16;
/// A vector whose M-norm falls below this fraction of its own after
/// orthogonalization against the basis is taken as already in it.
const DEPENDENT: f64 = 1e-8;

/// A linearization point and the modes built there.
pub struct Basis {
    /// Slot positions x* the modal coordinates are measured from.
    pub point: Vec<f64>,
    /// x* is the rest positions of the scene.
    pub at_rest: bool,
    pub pattern: StiffnessPattern,
    /// Upper triangle of the stiffness K(x*).
    pub stiffness: Vec<f64>,
    pub modes: ModalBasis,
}

/// The load patterns the options rank and correct for: M g, when gravity
/// is not zero, and the point load on its node, when it is not zero
/// (`docs/method.md`, section 8). With `anchor_motion` the inertial load of
/// an anchor acceleration along each axis, M e_i, takes the place of M g
/// (whose span it holds). With `anchor_rotation` the inertial loads of the
/// holder's angular acceleration and of its spin about each axis it can
/// turn about (z alone in 2D) join them: M (e_i x s) and M (s - e_i (e_i . s)),
/// s = x_rest - X0 about the pivot.
pub fn load_patterns(scene: &Scene, loads: &Loads, anchor_motion: bool, anchor_rotation: bool) -> Vec<Vec<f64>> {
    let d = scene.dim;
    let g = &loads.gravity[..d];
    let mut patterns = Vec::new();
    if anchor_motion {
        for i in 0..d {
            patterns.push((0..scene.n_dofs()).map(|k| if k % d == i { scene.dof_mass[k] } else { 0.0 }).collect());
        }
    } else if g.iter().any(|&x| x != 0.0) {
        patterns.push((0..scene.n_dofs()).map(|k| scene.dof_mass[k] * g[k % d]).collect());
    }
    if let Some((dof, f)) = loads.point_force(scene) {
        let mut p = vec![0.0; scene.n_dofs()];
        p[dof..dof + d].copy_from_slice(f);
        patterns.push(p);
    }
    if anchor_rotation {
        let pivot = scene.pivot();
        let axes: &[usize] = if d == 2 { &[2] } else { &[0, 1, 2] };
        for &axis in axes {
            let e: [f64; 3] = std::array::from_fn(|i| if i == axis { 1.0 } else { 0.0 });
            let (mut euler, mut spin) = (vec![0.0; scene.n_dofs()], vec![0.0; scene.n_dofs()]);
            for k in 0..scene.n_free {
                let s: [f64; 3] = std::array::from_fn(|i| if i < d { scene.rest[k * d + i] - pivot[i] } else { 0.0 });
                let turned = cross(&e, &s);
                for i in 0..d {
                    let m = scene.dof_mass[k * d + i];
                    euler[k * d + i] = m * turned[i];
                    spin[k * d + i] = m * (s[i] - e[i] * s[axis]);
                }
            }
            patterns.push(euler);
            patterns.push(spin);
        }
    }
    patterns
}

/// The external load on the free DOFs: M g plus the point load (`docs/method.md`, section 8).
pub fn external_load(scene: &Scene, loads: &Loads) -> Vec<f64> {
    let d = scene.dim;
    let mut f: Vec<f64> = (0..scene.n_dofs()).map(|k| scene.dof_mass[k] * loads.gravity[k % d]).collect();
    if let Some((dof, p)) = loads.point_force(scene) {
        for (fk, pk) in f[dof..dof + d].iter_mut().zip(p) {
            *fk += pk;
        }
    }
    f
}

/// The linearization point x* `settings` ask for (rest, or the static
/// equilibrium under the set-up loads), the stiffness pattern and the
/// upper triangle of K(x*).
pub fn linearize(scene: &Scene, loads: &Loads, settings: &Settings) -> Result<(Vec<f64>, StiffnessPattern, Vec<f64>), PhysicsError> {
    let pattern = StiffnessPattern::new(scene);
    let point = match settings.linearization {
        Linearization::Rest => scene.rest.clone(),
        Linearization::Equilibrium => equilibrium(scene, &pattern, &external_load(scene, loads))?,
    };
    let stiffness = stiffness_at(scene, &pattern, &point);
    Ok((point, pattern, stiffness))
}

/// The upper triangle of K(x) on `pattern` (x over every slot): what
/// [`linearize`] assembles at its point, bit for bit.
pub fn stiffness_at(scene: &Scene, pattern: &StiffnessPattern, x: &[f64]) -> Vec<f64> {
    let mut stiffness = vec![0.0; pattern.nnz()];
    pattern.add_tangent(scene, x, 1.0, &mut stiffness);
    stiffness
}

/// The vectors a static correction adds to a basis linearized at `point`:
/// at rest the static responses K⁻¹ f to every load pattern; at the
/// equilibrium the sag x* - x_rest itself (known exactly), and with the
/// holder moving or turning the responses to its inertial loads through
/// the tangent stiffness there.
pub fn static_vectors(
    scene: &Scene,
    pattern: &StiffnessPattern,
    stiffness: &[f64],
    point: &[f64],
    patterns: &[Vec<f64>],
    settings: &Settings,
) -> Result<Vec<Vec<f64>>, PhysicsError> {
    let n = scene.n_dofs();
    if settings.linearization == Linearization::Rest {
        let solver = ShiftedStiffness::new(scene, pattern, stiffness)?;
        return Ok(patterns.iter().map(|f| solver.solve(f)).collect());
    }
    let mut vectors = vec![(0..n).map(|k| point[k] - scene.rest[k]).collect::<Vec<f64>>()];
    if settings.anchor_motion || settings.anchor_rotation {
        let solver = ShiftedStiffness::new(scene, pattern, stiffness)?;
        let translation = if settings.anchor_motion { scene.dim } else { 0 };
        let rotation = if settings.anchor_rotation { 2 * if scene.dim == 2 { 1 } else { 3 } } else { 0 };
        let inertial = patterns[..translation].iter().chain(&patterns[patterns.len() - rotation..]);
        vectors.extend(inertial.map(|f| solver.solve(f)));
    }
    Ok(vectors)
}

/// The constraint modes of the holders that move on their own
/// (Craig–Bampton; `docs/method.md`, section 9): for each such holder and
/// each unit motion of its slots it may make, the static displacement of
/// the free DOFs, u = K_ff⁻¹ K_fh b, through the stiffness K(x*) at the
/// linearization point. The unit motions span every rigid placement of
/// the holder exactly, however far it turns: a translation e_i
/// (`anchor_motion`), and e_i ((X - P)_j) for every pair of axes i, j
/// (`anchor_rotation`: R - I has d² entries), those that move a slot.
/// Empty with one holder, or when the holders will not move.
pub fn constraint_vectors(
    scene: &Scene,
    pattern: &StiffnessPattern,
    stiffness: &[f64],
    point: &[f64],
    settings: &Settings,
) -> Result<Vec<Vec<f64>>, PhysicsError> {
    let holders = scene.moving_holders();
    if holders.is_empty() || !settings.constraint_modes || !(settings.anchor_motion || settings.anchor_rotation) {
        return Ok(Vec::new());
    }
    let d = scene.dim;
    let mut vectors = Vec::new();
    let solver = ShiftedStiffness::new(scene, pattern, stiffness)?;
    for h in holders {
        let mut held = vec![false; scene.rest.len() / d];
        h.slots.iter().for_each(|&s| held[s] = true);
        // Unit motions: (axis i moved, lever axis j or none for a translation).
        let mut motions: Vec<(usize, Option<usize>)> = Vec::new();
        if settings.anchor_motion {
            motions.extend((0..d).map(|i| (i, None)));
        }
        if settings.anchor_rotation {
            motions.extend((0..d).flat_map(|i| (0..d).map(move |j| (i, Some(j)))));
        }
        for (i, lever) in motions {
            let shift = |slot: usize| -> f64 { lever.map_or(1.0, |j| scene.rest[slot * d + j] - h.pivot[j]) };
            let f = held_pull(scene, point, |slot| {
                let b = if held[slot] { shift(slot) } else { 0.0 };
                std::array::from_fn(|c| if c == i { b } else { 0.0 })
            });
            if f.iter().any(|&x| x != 0.0) {
                vectors.push(solver.solve(&f));
            }
        }
    }
    Ok(vectors)
}

/// The linear static response of the free DOFs at rest to the held slots
/// placed at `x` (every slot's position; the free ones are not read):
/// u = K_ff⁻¹ K_fh (x_h - X_h), K the stiffness at rest. Where a run
/// starts when a holder is set away from its rest place before it starts.
pub fn static_response(scene: &Scene, x: &[f64]) -> Result<Vec<f64>, PhysicsError> {
    let d = scene.dim;
    let (pattern, stiffness) = crate::physics::run::stiffness::linearize(scene);
    let f = held_pull(scene, &scene.rest, |slot| std::array::from_fn(|c| if c < d { x[slot * d + c] - scene.rest[slot * d + c] } else { 0.0 }));
    Ok(ShiftedStiffness::new(scene, &pattern, &stiffness)?.solve(&f))
}

/// K_fh b: the pull on the free DOFs, through the springs' tangent at the
/// slot positions `point`, of the held slots moved by `moved(slot)` (z
/// ignored in 2D). A spring with one free end adds K_e b to that end.
fn held_pull(scene: &Scene, point: &[f64], moved: impl Fn(usize) -> [f64; 3]) -> Vec<f64> {
    let (d, n_free) = (scene.dim, scene.n_free);
    let mut f = vec![0.0; scene.n_dofs()];
    for s in &scene.springs {
        let (free, other) = match (s.a < n_free, s.b < n_free) {
            (true, false) => (s.a, s.b),
            (false, true) => (s.b, s.a),
            _ => continue,
        };
        let b = moved(other);
        if b[..d].iter().all(|&m| m == 0.0) {
            continue;
        }
        let dvec: Vec<f64> = (0..d).map(|c| point[s.b * d + c] - point[s.a * d + c]).collect();
        for (r, fr) in f[free * d..(free + 1) * d].iter_mut().enumerate() {
            *fr += (0..d).map(|c| tangent_entry(&dvec, s.k, s.rest, r, c) * b[c]).sum::<f64>();
        }
    }
    f
}

/// Entry (r, c) of a spring's tangent block k [u uᵀ + (1 - l0/l)(I - u uᵀ)], u = d / l.
fn tangent_entry(d: &[f64], k: f64, l0: f64, r: usize, c: usize) -> f64 {
    let l = d.iter().map(|x| x * x).sum::<f64>().sqrt();
    let uu = d[r] * d[c] / (l * l);
    let id = if r == c { 1.0 } else { 0.0 };
    k * (uu + (1.0 - l0 / l) * (id - uu))
}

/// What [`build`] refuses before any work: more modes than free DOFs, and
/// a selection that needs a load (`load`, the static correction) without
/// one; else the load patterns ([`load_patterns`]) it looked at.
pub fn refuse_early(scene: &Scene, loads: &Loads, n_modes: usize, settings: &Settings) -> Result<Vec<Vec<f64>>, PhysicsError> {
    let n = scene.n_dofs();
    if n_modes > n {
        return Err(PhysicsError::ModesExceedDofs { modes: n_modes, dofs: n });
    }
    let patterns = load_patterns(scene, loads, settings.anchor_motion, settings.anchor_rotation);
    let needs_load = settings.mode_selection == ModeSelection::Load || settings.static_correction;
    if needs_load && patterns.is_empty() {
        return Err(PhysicsError::NoLoad);
    }
    Ok(patterns)
}

/// The basis of `n_modes` vectors on `scene` under `loads`, chosen and
/// linearized as `settings` ask (`mode_selection`, `static_correction`,
/// `linearization`, `anchor_motion`). A trained basis comes from its
/// training program ([`crate::physics::setup::trained_basis`]), not from here: where one is
/// asked for only to report modal coordinates (full space), the lowest
/// modes are reported.
pub fn build(scene: &Scene, loads: &Loads, n_modes: usize, settings: &Settings) -> Result<Basis, PhysicsError> {
    let n = scene.n_dofs();
    let patterns = refuse_early(scene, loads, n_modes, settings)?;
    let (point, pattern, stiffness) = linearize(scene, loads, settings)?;
    let at_rest = settings.linearization == Linearization::Rest;
    let selection = match settings.mode_selection {
        ModeSelection::Trained => ModeSelection::Lowest,
        other => other,
    };
    let constraints = constraint_vectors(scene, &pattern, &stiffness, &point, settings)?;
    let plain = selection == ModeSelection::Lowest && !settings.static_correction && constraints.is_empty();
    let modes = if plain {
        ModalBasis::lowest(scene, &pattern, &stiffness, n_modes)?
    } else {
        let static_list = if settings.static_correction { static_vectors(scene, &pattern, &stiffness, &point, &patterns, settings)? } else { Vec::new() };
        // Every static vector and constraint mode has its place (at the equilibrium there is one more static vector than load patterns: the sag).
        let statics = (static_list.len() + constraints.len()).min(n_modes);
        let eigen = n_modes - statics;
        // Candidates in the order they are wanted; a few more than needed
        // stand in for static responses the modes already hold.
        let spare = statics;
        let candidates = match selection {
            ModeSelection::Load => {
                // Away from rest the run starts displaced from x* by x_rest - x*: its modal amplitudes count too.
                let start: Option<Vec<f64>> = (!at_rest).then(|| (0..n).map(|k| scene.rest[k] - point[k]).collect());
                ranked(scene, &pattern, &stiffness, &patterns, start.as_deref(), (eigen + spare).min(n))?
            }
            _ => ModalBasis::lowest(scene, &pattern, &stiffness, (eigen + spare).min(n))?,
        };
        let columns = |b: &ModalBasis, j: usize| -> Vec<f64> { (0..n).map(|i| b.phi[i * b.r + j]).collect() };
        let mut vectors: Vec<Vec<f64>> = (0..eigen.min(candidates.r)).map(|j| columns(&candidates, j)).collect();
        vectors.extend(static_list);
        vectors.extend(constraints);
        vectors.extend((eigen..candidates.r).map(|j| columns(&candidates, j)));
        orthonormal_ritz(scene, &pattern, &stiffness, &vectors, n_modes)?
    };
    Ok(Basis { point, at_rest, pattern, stiffness, modes })
}

/// The `r` modes with the largest amplitude in the static response to the
/// load patterns, |φ_iᵀ f| / λ_i, or in the displacement `start` the run
/// begins with, |φ_iᵀ M u₀|; ascending in frequency.
fn ranked(
    scene: &Scene,
    pattern: &StiffnessPattern,
    stiffness: &[f64],
    patterns: &[Vec<f64>],
    start: Option<&[f64]>,
    r: usize,
) -> Result<ModalBasis, PhysicsError> {
    let n = scene.n_dofs();
    let all = if n <= DENSE_CANDIDATES {
        ModalBasis::dense(scene, pattern, stiffness, n)?
    } else {
        load_ritz(scene, pattern, stiffness, patterns, start, (RITZ_FACTOR * r).max(r + RITZ_EXTRA).min(n))?
    };
    let lambda_floor = 1e-12 * all.lambda.iter().fold(0.0f64, |m, l| m.max(*l)).max(f64::MIN_POSITIVE);
    let share = |j: usize| -> f64 {
        let loaded =
            patterns.iter().map(|f| (0..n).map(|i| all.phi[i * all.r + j] * f[i]).sum::<f64>().abs() / all.lambda[j].max(lambda_floor)).fold(0.0, f64::max);
        let started = start.map_or(0.0, |u| (0..n).map(|i| all.phi[i * all.r + j] * scene.dof_mass[i] * u[i]).sum::<f64>().abs());
        loaded.max(started)
    };
    let mut order: Vec<(f64, usize)> = (0..all.r).map(|j| (share(j), j)).collect();
    order.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    let mut keep: Vec<usize> = order.iter().take(r).map(|&(_, j)| j).collect();
    keep.sort_unstable(); // ascending frequency, as the modes came
    let mut phi = vec![0.0; n * keep.len()];
    for i in 0..n {
        for (c, &j) in keep.iter().enumerate() {
            phi[i * keep.len() + c] = all.phi[i * all.r + j];
        }
    }
    Ok(ModalBasis { n, r: keep.len(), lambda: keep.iter().map(|&j| all.lambda[j]).collect(), phi })
}

/// `m` Ritz pairs of the Krylov space of (K − σM)⁻¹ M grown from (K − σM)⁻¹ f
/// for every load pattern f, and from the start displacement (σ a small
/// negative shift, so the factor exists where K is singular).
fn load_ritz(
    scene: &Scene,
    pattern: &StiffnessPattern,
    stiffness: &[f64],
    patterns: &[Vec<f64>],
    start: Option<&[f64]>,
    m: usize,
) -> Result<ModalBasis, PhysicsError> {
    let solver = ShiftedStiffness::new(scene, pattern, stiffness)?;
    let mass = &scene.dof_mass;
    let mut basis = MOrthonormal::new(mass, m);
    let mut block: Vec<Vec<f64>> = patterns.iter().map(|f| solver.solve(f)).collect();
    block.extend(start.map(|u| u.to_vec()));
    while !basis.full() && !block.is_empty() {
        let mut next = Vec::new();
        for v in block {
            if let Some(q) = basis.push(&v) {
                let mq: Vec<f64> = q.iter().zip(mass).map(|(a, b)| a * b).collect();
                next.push(solver.solve(&mq));
                if basis.full() {
                    break;
                }
            }
        }
        block = next;
    }
    rayleigh_ritz(pattern, stiffness, basis.columns())
}

/// An M-orthonormal set of columns grown one vector at a time: classical
/// Gram-Schmidt against all columns so far, as faer's matrix-vector
/// products Qᵀ (M v) and v − Q c, repeated once where the first pass left
/// less than 1/√2 of the norm ("twice is enough", Kahan and Parlett).
struct MOrthonormal<'a> {
    mass: &'a [f64],
    q: Mat<f64>,
    k: usize,
    /// Scratch: M v.
    mv: Col<f64>,
}

impl<'a> MOrthonormal<'a> {
    fn new(mass: &'a [f64], capacity: usize) -> Self {
        MOrthonormal { mass, q: Mat::zeros(mass.len(), capacity), k: 0, mv: Col::zeros(mass.len()) }
    }

    fn len(&self) -> usize {
        self.k
    }

    fn full(&self) -> bool {
        self.k == self.q.ncols()
    }

    /// The columns so far.
    fn columns(&self) -> MatRef<'_, f64> {
        self.q.as_ref().subcols(0, self.k)
    }

    /// Adds what of `v` is M-orthogonal to the columns, M-normalized, and
    /// returns it; `None` (nothing added) if the set is full or less than
    /// [`DEPENDENT`] of `v`'s M-norm is left.
    fn push(&mut self, v: &[f64]) -> Option<&[f64]> {
        if self.full() {
            return None;
        }
        let (n, k, mass) = (self.mass.len(), self.k, self.mass);
        let m_norm = |x: &[f64]| x.iter().zip(mass).map(|(a, m)| m * a * a).sum::<f64>().sqrt();
        let norm0 = m_norm(v);
        if !(norm0 > 0.0 && norm0.is_finite()) {
            return None;
        }
        let (done, mut rest) = self.q.as_mut().split_at_col_mut(k);
        let mut x = rest.rb_mut().col_mut(0);
        for (i, &vi) in v.iter().enumerate() {
            x[i] = vi;
        }
        let mut norm = norm0;
        if k > 0 {
            let mut c = Col::<f64>::zeros(k);
            for _ in 0..2 {
                for i in 0..n {
                    self.mv[i] = mass[i] * x[i];
                }
                matmul(c.as_mat_mut(), Accum::Replace, done.rb().transpose(), self.mv.as_mat(), 1.0, Par::Seq);
                matmul(x.rb_mut().as_mat_mut(), Accum::Add, done.rb(), c.as_mat(), -1.0, Par::Seq);
                let before = norm;
                norm = m_norm(x.rb().try_as_col_major().expect("contiguous").as_slice());
                if norm > std::f64::consts::FRAC_1_SQRT_2 * before {
                    break;
                }
            }
        }
        if !(norm > DEPENDENT * norm0) {
            return None;
        }
        x.try_as_col_major_mut().expect("contiguous").as_slice_mut().iter_mut().for_each(|a| *a /= norm);
        self.k += 1;
        Some(self.q.col(k).try_as_col_major().expect("contiguous").as_slice())
    }
}

/// The first independent directions of `vectors` (in their order),
/// M-orthonormalized as [`orthonormal_ritz`] takes them (n x k, k at most
/// `r`): their span, without the stiffness products and the eigen
/// decomposition that make it a basis.
pub fn m_orthonormal_span(mass: &[f64], vectors: &[Vec<f64>], r: usize) -> Mat<f64> {
    let mut q = MOrthonormal::new(mass, r.min(vectors.len()));
    for v in vectors {
        if q.full() {
            break;
        }
        q.push(v);
    }
    q.columns().to_owned()
}

/// ‖s − Q Qᵀ M s‖²_M = ‖s‖²_M − |Qᵀ M s|² for M-orthonormal columns `q`:
/// what of `s` their span leaves out (faer's product; the difference of two
/// sums, so accurate to round-off of ‖s‖²_M).
pub fn left_out_sq(mass: &[f64], q: MatRef<'_, f64>, s: &[f64]) -> f64 {
    let ms = Col::<f64>::from_fn(s.len(), |i| mass[i] * s[i]);
    let mut c = Col::<f64>::zeros(q.ncols());
    matmul(c.as_mat_mut(), Accum::Replace, q.transpose(), ms.as_mat(), 1.0, Par::Seq);
    vector_unit::clean();
    let all: f64 = s.iter().zip(ms.iter()).map(|(a, b)| a * b).sum();
    (all - c.iter().map(|x| x * x).sum::<f64>()).max(0.0)
}

/// The first `r` independent directions of `vectors` (in their order),
/// M-orthonormalized ([`MOrthonormal`]), then diagonalized in their span
/// ([`rayleigh_ritz`]).
pub fn orthonormal_ritz(scene: &Scene, pattern: &StiffnessPattern, stiffness: &[f64], vectors: &[Vec<f64>], r: usize) -> Result<ModalBasis, PhysicsError> {
    let mut q = MOrthonormal::new(&scene.dof_mass, r);
    for v in vectors {
        if q.full() {
            break;
        }
        q.push(v);
    }
    if q.len() < r {
        return Err(PhysicsError::BasisDeficient { wanted: r, found: q.len() });
    }
    rayleigh_ritz(pattern, stiffness, q.columns())
}

/// The M-orthonormal columns Q (n x r) diagonalized in their span: Φ = Q Z
/// with Zᵀ (Qᵀ K Q) Z = diag(λ), Zᵀ Z = I. K Q column by column, the two
/// dense products Qᵀ (K Q) and Q Z by faer, and faer's self-adjoint eigen
/// decomposition of the r x r matrix.
fn rayleigh_ritz(pattern: &StiffnessPattern, stiffness: &[f64], q: MatRef<'_, f64>) -> Result<ModalBasis, PhysicsError> {
    let (n, r) = (q.nrows(), q.ncols());
    let mut kq = Mat::<f64>::zeros(n, r);
    for j in 0..r {
        let x = q.col(j).try_as_col_major().expect("contiguous").as_slice();
        pattern.sym_matvec(stiffness, x, kq.col_mut(j).try_as_col_major_mut().expect("contiguous").as_slice_mut());
    }
    let mut kr = Mat::<f64>::zeros(r, r);
    matmul(kr.as_mut(), Accum::Replace, q.transpose(), kq.as_ref(), 1.0, Par::Seq);
    drop(kq);
    // Symmetrize the round-off away before the symmetric solver reads one triangle.
    for j in 0..r {
        for i in 0..j {
            let s = 0.5 * (kr[(i, j)] + kr[(j, i)]);
            kr[(i, j)] = s;
            kr[(j, i)] = s;
        }
    }
    let evd =
        kr.self_adjoint_eigen(Side::Lower).map_err(|e| PhysicsError::LinearAlgebra { what: "Rayleigh-Ritz eigen decomposition", detail: format!("{e:?}") })?;
    let (s, z) = (evd.S(), evd.U());
    let lambda_max = (0..r).fold(0.0f64, |m, j| m.max(s[j].abs()));
    let mut lambda = Vec::with_capacity(r);
    for j in 0..r {
        let l = s[j];
        // Round-off around a zero eigenvalue may come out slightly negative.
        let l = if l < 0.0 && l.abs() <= 1e-10 * lambda_max { 0.0 } else { l };
        if !(l >= 0.0) {
            return Err(PhysicsError::NegativeEigenvalue { lambda: l });
        }
        lambda.push(l);
    }
    // Φ row-major (n x r) is Φᵀ = Zᵀ Qᵀ column-major (r x n).
    let mut phi = vec![0.0; n * r];
    matmul(MatMut::from_column_major_slice_mut(&mut phi, r, n), Accum::Replace, z.transpose(), q.transpose(), 1.0, Par::Seq);
    Ok(ModalBasis { n, r, lambda, phi })
}

/// Solves with K − σM, σ a small negative shift (so a singular K factors;
/// the solution differs from K⁺f by a relative σ/λ_min).
struct ShiftedStiffness {
    llt: faer::sparse::linalg::solvers::Llt<usize, f64>,
}

impl ShiftedStiffness {
    fn new(scene: &Scene, pattern: &StiffnessPattern, stiffness: &[f64]) -> Result<Self, PhysicsError> {
        let n = scene.n_dofs();
        let diag_max = pattern.diag.iter().enumerate().fold(0.0f64, |m, (k, &p)| m.max(stiffness[p] / scene.dof_mass[k]));
        let sigma = -1e-9 * diag_max;
        let mut vals = stiffness.to_vec();
        for (k, &p) in pattern.diag.iter().enumerate() {
            vals[p] -= sigma * scene.dof_mass[k];
        }
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &pattern.col_ptr, None, &pattern.row_idx);
        let llt = SparseColMatRef::new(sym, &vals)
            .sp_cholesky(Side::Upper)
            .map_err(|e| PhysicsError::LinearAlgebra { what: "sparse Cholesky factorization of the stiffness", detail: format!("{e:?}") })?;
        Ok(ShiftedStiffness { llt })
    }

    fn solve(&self, f: &[f64]) -> Vec<f64> {
        let mut x = faer::Col::<f64>::from_fn(f.len(), |i| f[i]);
        faer::linalg::solvers::Solve::solve_in_place(&self.llt, x.as_mat_mut());
        x.iter().copied().collect()
    }
}
