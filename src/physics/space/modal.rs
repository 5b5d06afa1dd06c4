//! The modal space: the paper's method (`docs/method.md`, section 3).
//!
//! y = q, the coordinates of the r kept modes, with x = x* + Phi q. One force
//! evaluation is the pipeline `expand` (q -> x over the free DOFs) ->
//! exact spring forces in physical space -> `project` (Phi^T f). With
//! weights w_i and F = Phi^T (f_springs + M g) the mode equations are
//!
//! ```text
//!     q_i'' + c_i q_i' = h_i(q) = w_i F_i + (w_i - 1) lambda_i q_i,
//! ```
//!
//! i.e. q'' + c q' + lambda q = w r with r = F + lambda q: a weight scales
//! everything that drives a mode beyond its own linear spring. M = I
//! (Phi^T M Phi = I), C = diag(c_i), c_i = alpha + beta lambda_i.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor::lu_in_place, factor::lu_in_place_scratch, solve::solve_in_place_scratch, solve::solve_in_place_with_conj};
use faer::perm::PermRef;
use faer::{Conj, Mat, MatMut, Par, Side};

use super::Space;
use crate::physics::error::{PhysicsError, StepFailure};
use crate::physics::forces::{add_reduced_tangent, linearize, omega_sq_bound_full, SpringForces, SpringScratch};
use crate::physics::modes::ModalBasis;
use crate::physics::scene::Scene;
use crate::physics::state::Loads;

/// Above this many modes the explicit limit uses the full-space bound
/// instead of the eigenvalues of the reduced taut stiffness.
const DENSE_BOUND_MODES: usize = 64;

/// The constant model of the modal equations.
pub struct Modal {
    scene: Scene,
    basis: ModalBasis,
    /// Phi column-major (each mode contiguous), for the expand and project loops.
    phi_cols: Vec<f64>,
    springs: SpringForces,
    frequencies: Vec<f64>,
    /// Squared-frequency bound of the reduced system with unit weights.
    omega_sq_bound: f64,
    /// The modal coordinate of a one-length-scale displacement of the whole mass.
    newton_scale: f64,
}

/// Load terms and scratch of a modal run.
pub struct ModalWork {
    /// c_i = alpha + beta lambda_i.
    damping: Vec<f64>,
    /// Phi^T M g.
    gravity: Vec<f64>,
    /// Slot positions and elastic energy of the last force evaluation.
    x: Vec<f64>,
    elastic: f64,
    /// Spring forces on the free DOFs.
    f: Vec<f64>,
    springs: SpringScratch,
    /// Reduced tangent Phi^T K(x) Phi (column-major) and its scratch.
    kr: Vec<f64>,
    tangent_work: Vec<f64>,
    /// Newton matrix, LU-factored in place, with its row permutation.
    jac: Mat<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    mem: MemBuffer,
}

impl Modal {
    /// Linearizes `scene` at rest and keeps its `n_modes` lowest modes.
    pub fn new(scene: Scene, n_modes: usize) -> Result<Self, PhysicsError> {
        let (pattern, k0) = linearize(&scene);
        let basis = ModalBasis::lowest(&scene, &pattern, &k0, n_modes)?;
        let omega_sq_bound = if basis.r <= DENSE_BOUND_MODES { taut_reduced_bound(&scene, &basis)? } else { omega_sq_bound_full(&scene) };
        let newton_scale = scene.free_mass().sqrt() * scene.length_scale().max(f64::MIN_POSITIVE);
        let (n, r) = (basis.n, basis.r);
        let phi_cols = (0..r).flat_map(|j| (0..n).map(move |k| (k, j))).map(|(k, j)| basis.phi[k * r + j]).collect();
        Ok(Modal { springs: SpringForces::new(&scene), frequencies: basis.frequencies(), phi_cols, omega_sq_bound, newton_scale, basis, scene })
    }

    /// The kept modes.
    pub fn basis(&self) -> &ModalBasis {
        &self.basis
    }
}

impl Space for Modal {
    type Work = ModalWork;

    fn scene(&self) -> &Scene {
        &self.scene
    }

    fn coordinates(&self) -> usize {
        self.basis.r
    }

    fn kept_modes(&self) -> Option<usize> {
        Some(self.basis.r)
    }

    fn frequencies(&self) -> &[f64] {
        &self.frequencies
    }

    fn work(&self) -> ModalWork {
        let (n, r) = (self.basis.n, self.basis.r);
        let req =
            StackReq::any_of(&[lu_in_place_scratch::<usize, f64>(r, r, Par::Seq, Default::default()), solve_in_place_scratch::<usize, f64>(r, 1, Par::Seq)]);
        ModalWork {
            damping: vec![0.0; r],
            gravity: vec![0.0; r],
            x: self.scene.rest.clone(),
            elastic: 0.0,
            f: vec![0.0; n],
            springs: self.springs.scratch(&self.scene),
            kr: vec![0.0; r * r],
            tangent_work: vec![0.0; 6 * r],
            jac: Mat::zeros(r, r),
            perm: vec![0; r],
            perm_inv: vec![0; r],
            mem: MemBuffer::new(req),
        }
    }

    fn apply_loads(&self, loads: &Loads, w: &mut ModalWork) {
        let (n, r, d) = (self.basis.n, self.basis.r, self.scene.dim);
        for j in 0..r {
            w.damping[j] = loads.damping_alpha + loads.damping_beta * self.basis.lambda[j];
        }
        w.gravity.fill(0.0);
        for k in 0..n {
            let fk = self.scene.dof_mass[k] * loads.gravity[k % d];
            for j in 0..r {
                w.gravity[j] += self.basis.phi[k * r + j] * fk;
            }
        }
    }

    fn force(&self, loads: &Loads, q: &[f64], w: &mut ModalWork, h: &mut [f64]) {
        let n = self.basis.n;
        // expand: x = x* + Phi q over the free DOFs, one mode at a time
        w.x[..n].copy_from_slice(&self.scene.rest[..n]);
        for (col, qj) in self.phi_cols.chunks_exact(n).zip(q) {
            for (xk, p) in w.x[..n].iter_mut().zip(col) {
                *xk += p * qj;
            }
        }
        // exact spring forces in physical space
        w.f.fill(0.0);
        w.elastic = self.springs.add_to(&self.scene, &w.x, &mut w.springs, &mut w.f);
        // project: F = Phi^T (f + M g)
        for ((hj, col), gj) in h.iter_mut().zip(self.phi_cols.chunks_exact(n)).zip(&w.gravity) {
            *hj = gj + col.iter().zip(&w.f).map(|(p, fk)| p * fk).sum::<f64>();
        }
        // weights act on everything but the mode's own linear spring
        for (j, hj) in h.iter_mut().enumerate() {
            let wj = loads.mode_weights[j];
            *hj = wj * *hj + (wj - 1.0) * self.basis.lambda[j] * q[j];
        }
    }

    fn explicit_velocity(&self, dt: f64, v: &[f64], a: &[f64], h: &[f64], w: &mut ModalWork, v1: &mut [f64]) -> Result<(), StepFailure> {
        for j in 0..self.basis.r {
            v1[j] = (v[j] + 0.5 * dt * (a[j] + h[j])) / (1.0 + 0.5 * dt * w.damping[j]);
        }
        Ok(())
    }

    fn acceleration(&self, v: &[f64], h: &[f64], w: &mut ModalWork, a: &mut [f64]) {
        for j in 0..self.basis.r {
            a[j] = h[j] - w.damping[j] * v[j];
        }
    }

    fn residual(&self, v: &[f64], a: &[f64], h: &[f64], w: &mut ModalWork, r: &mut [f64]) {
        for j in 0..self.basis.r {
            r[j] = -(a[j] + w.damping[j] * v[j] - h[j]);
        }
    }

    /// J = c_m I + c_c diag(c) + W Phi^T K(x) Phi - diag((w - 1) lambda), LU with partial pivoting.
    fn factor(&self, loads: &Loads, c_m: f64, c_c: f64, w: &mut ModalWork) -> Result<(), StepFailure> {
        let r = self.basis.r;
        let weights = &loads.mode_weights;
        w.kr.fill(0.0);
        add_reduced_tangent(&self.scene, &w.x, &self.basis.phi, r, false, &mut w.kr, &mut w.tangent_work);
        for col in 0..r {
            for row in 0..r {
                w.jac[(row, col)] = weights[row] * w.kr[col * r + row];
            }
            w.jac[(col, col)] += c_m + c_c * w.damping[col] - (weights[col] - 1.0) * self.basis.lambda[col];
        }
        let stack = MemStack::new(&mut w.mem);
        lu_in_place(w.jac.as_mut(), &mut w.perm, &mut w.perm_inv, Par::Seq, stack, Default::default());
        Ok(())
    }

    fn solve(&self, w: &mut ModalWork, rhs: &mut [f64]) {
        let r = self.basis.r;
        let row_perm = PermRef::new_checked(&w.perm, &w.perm_inv, r);
        let jac = w.jac.as_ref();
        let stack = MemStack::new(&mut w.mem);
        solve_in_place_with_conj(jac, jac, row_perm, Conj::No, MatMut::from_column_major_slice_mut(rhs, r, 1), Par::Seq, stack);
    }

    fn newton_scale(&self) -> f64 {
        self.newton_scale
    }

    /// Weights above 1 scale the stiffness each mode sees beyond its own.
    fn omega_sq_bound(&self, loads: &Loads) -> f64 {
        loads.weight_max() * self.omega_sq_bound
    }

    fn positions<'w>(&self, w: &'w ModalWork) -> &'w [f64] {
        &w.x
    }

    fn elastic_energy(&self, w: &ModalWork) -> f64 {
        w.elastic
    }

    /// -(M g)^T u = -(Phi^T M g)^T q, relative to x*.
    fn gravity_potential(&self, _loads: &Loads, q: &[f64], w: &ModalWork) -> f64 {
        -w.gravity.iter().zip(q).map(|(g, q)| g * q).sum::<f64>()
    }

    /// 1/2 |q'|^2, since Phi^T M Phi = I.
    fn kinetic_energy(&self, v: &[f64]) -> f64 {
        0.5 * v.iter().map(|v| v * v).sum::<f64>()
    }

    /// Phi q'.
    fn dof_velocities(&self, v: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        for (col, vj) in self.phi_cols.chunks_exact(self.basis.n).zip(v) {
            for (o, p) in out.iter_mut().zip(col) {
                *o += p * vj;
            }
        }
    }

    fn modal_coordinates(&self, q: &[f64], out: &mut [f64]) {
        out.copy_from_slice(q);
    }
}

/// lambda_max(Phi^T K_taut Phi): bound on the squared frequencies of the
/// reduced system in any state without compressed springs.
fn taut_reduced_bound(scene: &Scene, basis: &ModalBasis) -> Result<f64, PhysicsError> {
    let r = basis.r;
    let mut kr = vec![0.0; r * r];
    let mut work = vec![0.0; 6 * r];
    add_reduced_tangent(scene, &scene.rest, &basis.phi, r, true, &mut kr, &mut work);
    let m = faer::Mat::<f64>::from_fn(r, r, |i, j| kr[j * r + i]);
    let ev = m
        .self_adjoint_eigenvalues(Side::Lower)
        .map_err(|e| PhysicsError::LinearAlgebra { what: "eigenvalues of the reduced stiffness", detail: format!("{e:?}") })?;
    Ok(ev.last().copied().unwrap_or(0.0).max(0.0))
}
