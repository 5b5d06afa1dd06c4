//! Generalized eigen decomposition K phi = lambda M phi over the free DOFs.
//!
//! M is diagonal, so the problem is reduced to the symmetric standard one
//! K~ psi = lambda psi with K~ = M^-1/2 K M^-1/2 and phi = M^-1/2 psi, which
//! faer's self-adjoint eigensolver handles. The modes come out
//! mass-orthonormal: Phi^T M Phi = I and Phi^T K Phi = diag(lambda).

use faer::{Mat, Side};

use super::forces::StiffnessPattern;
use super::scene::Scene;
use super::SimError;

/// Largest dense eigenproblem attempted (free DOFs): its matrix alone takes
/// n^2 * 8 bytes, 512 MB at this size, and O(n^3) work.
pub const MAX_DENSE_DOFS: usize = 8000;

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
    pub fn lowest(scene: &Scene, pattern: &StiffnessPattern, k_vals: &[f64], r: usize) -> Result<Self, SimError> {
        let n = scene.n_dofs();
        if r > n {
            return Err(SimError {
                message: format!("nModes = {r} exceeds the {n} free degrees of freedom of the scene"),
            });
        }
        if n > MAX_DENSE_DOFS {
            return Err(SimError {
                message: format!(
                    "nModes = {r} needs an eigen decomposition of the {n} free DOFs, above the dense limit of \
                     {MAX_DENSE_DOFS}; use reduction = full with nModes = 0, or a smaller grid"
                ),
            });
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
        let evd = kt.self_adjoint_eigen(Side::Lower).map_err(|e| SimError {
            message: format!("eigen decomposition of the stiffness matrix failed: {e:?}"),
        })?;
        let s = evd.S();
        let u = evd.U();
        let lambda_max = if n > 0 { s[n - 1].abs() } else { 0.0 };
        let lambda = (0..r)
            .map(|j| {
                // Round-off around a zero eigenvalue (mechanism, rigid mode) may come out slightly negative.
                let l = s[j];
                if l < 0.0 && l.abs() <= 1e-10 * lambda_max { 0.0 } else { l }
            })
            .collect::<Vec<_>>();
        if let Some(&l) = lambda.iter().find(|l| **l < 0.0) {
            return Err(SimError { message: format!("stiffness matrix at rest has a negative eigenvalue {l}") });
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
