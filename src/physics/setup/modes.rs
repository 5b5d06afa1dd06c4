//! Generalized eigen decomposition K phi = lambda M phi over the free DOFs.
//!
//! M is diagonal, so the problem is reduced to the symmetric standard one
//! K~ psi = lambda psi with K~ = M^-1/2 K M^-1/2 and phi = M^-1/2 psi. The
//! modes come out mass-orthonormal: Phi^T M Phi = I and
//! Phi^T K Phi = diag(lambda). Two solvers, both faer's:
//!
//! - `dense`: every eigenpair of K~ (O(n^3)), for small scenes or many modes;
//! - `partial`: the r lowest only, by Krylov-Schur on the shift-inverted
//!   operator M^1/2 (K - sigma M)^-1 M^1/2 with a sparse Cholesky factor of
//!   K - sigma M, for large scenes and few modes (cloth at 100 x 100 nodes).

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::solvers::Solve;
use faer::matrix_free::eigen::{partial_self_adjoint_eigen, partial_self_adjoint_eigen_scratch, PartialEigenParams};
use faer::matrix_free::LinOp;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Col, Mat, MatMut, MatRef, Par, Side};

use crate::physics::error::PhysicsError;
use crate::physics::run::stiffness::StiffnessPattern;
use crate::physics::setup::scene::Scene;

/// Largest dense eigenproblem attempted (free DOFs): its matrix alone takes
/// n^2 * 8 bytes, 512 MB at this size, and O(n^3) work.
pub const MAX_DENSE_DOFS: usize = 8000;

/// Scenes up to this many free DOFs always use the dense solver (it is
/// cheap there and needs no convergence check).
const PARTIAL_MIN_DOFS: usize = 600;
/// The partial solver is used while r is at most this fraction of the DOFs:
/// its search space (2r vectors) must stay far below the dimension, where
/// faer's Lanczos re-orthogonalisation can spin without end once the space
/// becomes invariant (seen at r = 512 of 1740 coupled DOFs).
const PARTIAL_MAX_FRACTION: usize = 16;

/// The kept modes, lowest first.
#[derive(Clone, Debug)]
pub struct ModalBasis {
    /// Free DOFs.
    pub n: usize,
    /// Modes kept.
    pub r: usize,
    /// Eigenvalues lambda_i = omega_i^2 [1/s^2], ascending.
    pub lambda: Vec<f64>,
    /// Mode shapes, row-major `n x r` (a DOF's row is contiguous).
    pub phi: Vec<f64>,
}

impl ModalBasis {
    /// The `r` lowest modes of the stiffness whose upper triangle is `k_vals`
    /// on `pattern`, with the diagonal masses of `scene`.
    pub fn lowest(scene: &Scene, pattern: &StiffnessPattern, k_vals: &[f64], r: usize) -> Result<Self, PhysicsError> {
        let n = scene.n_dofs();
        if r > n {
            return Err(PhysicsError::ModesExceedDofs { modes: r, dofs: n });
        }
        if n > PARTIAL_MIN_DOFS && r * PARTIAL_MAX_FRACTION <= n {
            match Self::partial(scene, pattern, k_vals, r) {
                Ok(basis) => Ok(basis),
                // Where the dense solver can run, it settles what the partial one cannot.
                Err(_) if n <= MAX_DENSE_DOFS => Self::dense(scene, pattern, k_vals, r),
                Err(e) => Err(e),
            }
        } else {
            Self::dense(scene, pattern, k_vals, r)
        }
    }

    /// All eigenpairs of K~ by faer's dense self-adjoint eigensolver; keeps the lowest `r`.
    pub fn dense(scene: &Scene, pattern: &StiffnessPattern, k_vals: &[f64], r: usize) -> Result<Self, PhysicsError> {
        let n = scene.n_dofs();
        if n > MAX_DENSE_DOFS {
            return Err(PhysicsError::DenseEigenTooLarge { modes: r, dofs: n, limit: MAX_DENSE_DOFS, partial_max: n / PARTIAL_MAX_FRACTION });
        }
        let inv_sqrt_m: Vec<f64> = scene.dof_mass.iter().map(|m| 1.0 / m.sqrt()).collect();
        let mut kt = Mat::<f64>::zeros(n, n);
        for c in 0..n {
            for pos in pattern.col_ptr[c]..pattern.col_ptr[c + 1] {
                let row = pattern.row_idx[pos];
                let v = k_vals[pos] * inv_sqrt_m[row] * inv_sqrt_m[c];
                kt[(row, c)] = v;
                kt[(c, row)] = v;
            }
        }
        let evd = kt
            .self_adjoint_eigen(Side::Lower)
            .map_err(|e| PhysicsError::LinearAlgebra { what: "eigen decomposition of the stiffness matrix", detail: format!("{e:?}") })?;
        let s = evd.S();
        let lambda_max = if n > 0 { s[n - 1].abs() } else { 0.0 };
        Self::from_pairs(n, r, (0..r).map(|j| s[j]), lambda_max, evd.U(), &inv_sqrt_m)
    }

    /// The `r` lowest eigenpairs only: the largest eigenvalues mu = 1 / (lambda - sigma)
    /// of A = M^1/2 (K - sigma M)^-1 M^1/2, by faer's Krylov-Schur solver.
    /// sigma is a small negative shift, so K - sigma M is positive definite
    /// even where K has zero eigenvalues.
    ///
    /// A Krylov space grown from one vector holds one direction per distinct
    /// eigenvalue, so copies of a repeated eigenvalue are found only through
    /// round-off, and some may be skipped: the r returned pairs would then
    /// not be the r lowest. Uncoupled DOFs (the source of the large clusters)
    /// are split off exactly; a result that still holds a repeated
    /// eigenvalue is refused.
    pub fn partial(scene: &Scene, pattern: &StiffnessPattern, k_vals: &[f64], r: usize) -> Result<Self, PhysicsError> {
        let n = scene.n_dofs();
        let mass = &scene.dof_mass;
        let diag_max = pattern.diag.iter().enumerate().fold(0.0f64, |m, (k, &pos)| m.max(k_vals[pos] / mass[k]));
        // A DOF with no stiffness coupling to any other is an exact eigenpair
        // (e_k, K_kk / m_k) and is split off: the out-of-plane DOFs of a flat
        // 3D sheet at rest are such, all with one value, and that cluster
        // would make the Krylov space invariant in floating point.
        let mut coupled = vec![false; n];
        for c in 0..n {
            for pos in pattern.col_ptr[c]..pattern.col_ptr[c + 1] {
                let row = pattern.row_idx[pos];
                if row != c && k_vals[pos] != 0.0 {
                    coupled[row] = true;
                    coupled[c] = true;
                }
            }
        }
        let block: Vec<usize> = (0..n).filter(|&k| coupled[k]).collect();
        if r.min(block.len()) * PARTIAL_MAX_FRACTION > block.len() {
            return Err(PhysicsError::PartialTooManyModes { modes: r, coupled: block.len(), fraction: PARTIAL_MAX_FRACTION });
        }
        let (block_lambda, block_vectors) = coupled_block_lowest(pattern, k_vals, mass, &block, r.min(block.len()), diag_max)?;
        // Merge with the isolated DOFs, lowest first (ties: block modes, then DOF order).
        let mut pairs: Vec<(f64, Result<usize, usize>)> = block_lambda.iter().enumerate().map(|(j, &l)| (l, Ok(j))).collect();
        pairs.extend((0..n).filter(|&k| !coupled[k]).map(|k| (k_vals[pattern.diag[k]] / mass[k], Err(k))));
        pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
        pairs.truncate(r);
        let mut u = Mat::<f64>::zeros(n, r);
        for (j, (_, source)) in pairs.iter().enumerate() {
            match *source {
                Ok(col) => {
                    for (i, &k) in block.iter().enumerate() {
                        u[(k, j)] = block_vectors[(i, col)];
                    }
                }
                Err(k) => u[(k, j)] = 1.0,
            }
        }
        let inv_sqrt_m: Vec<f64> = mass.iter().map(|m| 1.0 / m.sqrt()).collect();
        Self::from_pairs(n, r, pairs.iter().map(|p| p.0), diag_max, u.as_ref(), &inv_sqrt_m)
    }

    /// Basis from the eigenpairs of K~ (ascending values, orthonormal vectors
    /// as columns of `u`).
    fn from_pairs(
        n: usize,
        r: usize,
        values: impl Iterator<Item = f64>,
        lambda_max: f64,
        u: MatRef<'_, f64>,
        inv_sqrt_m: &[f64],
    ) -> Result<Self, PhysicsError> {
        let lambda = values
            .map(|l| {
                // Round-off around a zero eigenvalue (mechanism, rigid mode) may come out slightly negative.
                if l < 0.0 && l.abs() <= 1e-10 * lambda_max {
                    0.0
                } else {
                    l
                }
            })
            .collect::<Vec<_>>();
        if let Some(&l) = lambda.iter().find(|l| !(**l >= 0.0)) {
            return Err(PhysicsError::NegativeEigenvalue { lambda: l });
        }
        let mut phi = vec![0.0; n * r];
        for i in 0..n {
            for j in 0..r {
                phi[i * r + j] = u[(i, j)] * inv_sqrt_m[i];
            }
        }
        Ok(ModalBasis { n, r, lambda, phi })
    }

    /// omega_i = sqrt(lambda_i) [rad/s].
    pub fn frequencies(&self) -> Vec<f64> {
        self.lambda.iter().map(|l| l.max(0.0).sqrt()).collect()
    }

    /// q = Phi^T M u: the modal coordinates of a displacement of the free DOFs.
    pub fn project_displacement(&self, mass: &[f64], u: &[f64], q: &mut [f64]) {
        q.fill(0.0);
        for i in 0..self.n {
            let mu = mass[i] * u[i];
            let row = &self.phi[i * self.r..(i + 1) * self.r];
            for (qj, p) in q.iter_mut().zip(row) {
                *qj += p * mu;
            }
        }
    }
}

/// The `r` lowest eigenpairs of K~ restricted to the DOFs `block` (ascending
/// values; orthonormal vectors over the block), by Krylov-Schur on the
/// shift-inverted operator.
fn coupled_block_lowest(
    pattern: &StiffnessPattern,
    k_vals: &[f64],
    mass: &[f64],
    block: &[usize],
    r: usize,
    diag_max: f64,
) -> Result<(Vec<f64>, Mat<f64>), PhysicsError> {
    let nb = block.len();
    if r == 0 {
        return Ok((Vec::new(), Mat::zeros(nb, 0)));
    }
    // Upper CSC of K - sigma M on the block (the index map is increasing, so
    // rows stay sorted).
    let sigma = -1e-9 * diag_max;
    let mut index = vec![usize::MAX; mass.len()];
    for (i, &k) in block.iter().enumerate() {
        index[k] = i;
    }
    let (mut col_ptr, mut row_idx, mut vals) = (vec![0usize], Vec::new(), Vec::new());
    for &c in block {
        for pos in pattern.col_ptr[c]..pattern.col_ptr[c + 1] {
            let row = pattern.row_idx[pos];
            if index[row] != usize::MAX {
                row_idx.push(index[row]);
                vals.push(k_vals[pos] - if row == c { sigma * mass[c] } else { 0.0 });
            }
        }
        col_ptr.push(row_idx.len());
    }
    let sym = SymbolicSparseColMatRef::new_checked(nb, nb, &col_ptr, None, &row_idx);
    let llt = SparseColMatRef::new(sym, &vals)
        .sp_cholesky(Side::Upper)
        .map_err(|e| PhysicsError::LinearAlgebra { what: "sparse Cholesky factorization of the shifted stiffness", detail: format!("{e:?}") })?;
    let mut op = ShiftInvert { llt, sqrt_m: block.iter().map(|&k| mass[k].sqrt()).collect(), scale: 1.0 };
    // Scale A so its largest eigenvalue is near 1 and the absolute residual
    // tolerance of the Krylov-Schur solver is a relative one: a few inverse
    // iterations estimate mu_max.
    let mut v = Col::<f64>::from_fn(nb, start_vector);
    let mut mu = 1.0;
    for _ in 0..4 {
        v /= v.norm_l2();
        let mut w = Col::<f64>::zeros(nb);
        op.apply(w.as_mat_mut(), v.as_mat(), Par::Seq, MemStack::new(&mut MemBuffer::new(StackReq::EMPTY)));
        mu = w.norm_l2();
        v = w;
    }
    op.scale = 1.0 / mu;
    // Clean spectra converge in a few restarts; many more mean a cluster.
    let params = PartialEigenParams { max_restarts: 30, ..Default::default() };
    let mut vectors = Mat::<f64>::zeros(nb, r);
    let mut values = vec![0.0; r];
    let v0 = Col::<f64>::from_fn(nb, start_vector);
    let mut mem = MemBuffer::new(partial_self_adjoint_eigen_scratch::<f64>(&op, r, Par::Seq, params));
    let info = partial_self_adjoint_eigen(vectors.as_mut(), &mut values, &op, v0.as_ref(), 1e-12, Par::Seq, MemStack::new(&mut mem), params);
    if info.n_converged_eigen < r {
        return Err(PhysicsError::PartialIncomplete { found: info.n_converged_eigen, modes: r });
    }
    // Ascending lambda = sigma + 1 / mu, with mu unscaled.
    let lambda_of = |j: usize| sigma + op.scale / values[j];
    let mut order: Vec<usize> = (0..r).collect();
    order.sort_by(|&a, &b| lambda_of(a).total_cmp(&lambda_of(b)));
    let lambda: Vec<f64> = order.iter().map(|&j| lambda_of(j)).collect();
    if let Some(w) = lambda.windows(2).find(|w| (w[1] - w[0]).abs() <= 1e-8 * w[1].abs().max(1e-12 * diag_max)) {
        return Err(PhysicsError::RepeatedEigenvalue { modes: r, lambda: w[0] });
    }
    Ok((lambda, Mat::<f64>::from_fn(nb, r, |i, j| vectors[(i, order[j])])))
}

/// A = scale * M^1/2 (K - sigma M)^-1 M^1/2, applied with the Cholesky factor.
#[derive(Debug)]
struct ShiftInvert {
    llt: faer::sparse::linalg::solvers::Llt<usize, f64>,
    sqrt_m: Vec<f64>,
    scale: f64,
}

impl LinOp<f64> for ShiftInvert {
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> StackReq {
        StackReq::EMPTY
    }

    fn nrows(&self) -> usize {
        self.sqrt_m.len()
    }

    fn ncols(&self) -> usize {
        self.sqrt_m.len()
    }

    fn apply(&self, mut out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, _par: Par, _stack: &mut MemStack) {
        for j in 0..rhs.ncols() {
            for i in 0..rhs.nrows() {
                out[(i, j)] = rhs[(i, j)] * self.sqrt_m[i];
            }
        }
        self.llt.solve_in_place(&mut out);
        for j in 0..rhs.ncols() {
            for i in 0..rhs.nrows() {
                out[(i, j)] *= self.scale * self.sqrt_m[i];
            }
        }
    }

    fn conj_apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, par: Par, stack: &mut MemStack) {
        self.apply(out, rhs, par, stack);
    }
}

/// A fixed pseudo-random start vector (splitmix64), so that no mode is
/// orthogonal to it by symmetry and runs are reproducible.
fn start_vector(i: usize) -> f64 {
    let mut z = (i as u64).wrapping_add(1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64 - 0.5
}
