//! Modal solver: the paper's method.
//!
//! State: modal coordinates q (r of them) with x = x* + Phi q. Each force
//! evaluation runs the pipeline `expand` (q -> x) -> `SpringForces`
//! (exact, in physical space) -> `project` (Phi^T f). With weights w and
//! F = Phi^T (f_springs + M g), the mode equations are
//!   q_i'' + c_i q_i' = h_i(q) = w_i F_i + (w_i - 1) lambda_i q_i,
//! i.e. q'' + c q' + lambda q = w r with r = F + lambda q (METHOD.md section 3).
//! All buffers are sized at construction; stepping allocates nothing.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor::lu_in_place, factor::lu_in_place_scratch, solve::solve_in_place_scratch, solve::solve_in_place_with_conj};
use faer::{Conj, Mat, Par};

use super::forces::{add_reduced_tangent, SpringForces};
use super::modes::ModalBasis;
use super::newmark::*;
use super::params::Tunables;
use super::scene::Scene;
use super::SimError;

pub struct ModalSolver {
    pub basis: ModalBasis,
    /// Modal coordinates, velocities, accelerations.
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    /// Rayleigh damping per mode, c_i = alpha + beta lambda_i.
    c: Vec<f64>,
    w: Vec<f64>,
    /// Phi^T M g, refreshed when gravity changes.
    gravity_modal: Vec<f64>,
    /// Slot positions of the last force evaluation.
    pub x: Vec<f64>,
    /// Elastic energy at `x`.
    pub elastic: f64,
    spring_forces: SpringForces,
    /// Phi column-major (each mode contiguous), for the expand and project loops.
    phi_cols: Vec<f64>,
    f: Vec<f64>,
    h: Vec<f64>,
    q_new: Vec<f64>,
    v_new: Vec<f64>,
    a_new: Vec<f64>,
    residual: Mat<f64>,
    jac: Mat<f64>,
    kr: Vec<f64>,
    work: Vec<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    mem: MemBuffer,
    /// Newton scale: the modal coordinate of a one-spacing displacement of one node.
    q_scale: f64,
}

impl ModalSolver {
    pub fn new(scene: &Scene, basis: ModalBasis, tunables: &Tunables, q_scale: f64) -> Self {
        let (n, r) = (basis.n, basis.r);
        let req =
            StackReq::any_of(&[lu_in_place_scratch::<usize, f64>(r, r, Par::Seq, Default::default()), solve_in_place_scratch::<usize, f64>(r, 1, Par::Seq)]);
        let mut s = ModalSolver {
            q: vec![0.0; r],
            qd: vec![0.0; r],
            qdd: vec![0.0; r],
            c: vec![0.0; r],
            w: vec![1.0; r],
            gravity_modal: vec![0.0; r],
            x: scene.rest.clone(),
            elastic: 0.0,
            spring_forces: SpringForces::new(scene),
            phi_cols: (0..r).flat_map(|j| (0..n).map(move |k| (k, j))).map(|(k, j)| basis.phi[k * r + j]).collect(),
            f: vec![0.0; n],
            h: vec![0.0; r],
            q_new: vec![0.0; r],
            v_new: vec![0.0; r],
            a_new: vec![0.0; r],
            residual: Mat::zeros(r, 1),
            jac: Mat::zeros(r, r),
            kr: vec![0.0; r * r],
            work: vec![0.0; 6 * r],
            perm: vec![0; r],
            perm_inv: vec![0; r],
            mem: MemBuffer::new(req),
            q_scale,
            basis,
        };
        s.set_tunables(scene, tunables);
        s.reset_acceleration(scene);
        s
    }

    /// Takes new loads and gains; the acceleration is left to the caller.
    pub fn set_tunables(&mut self, scene: &Scene, t: &Tunables) {
        let (n, r, d) = (self.basis.n, self.basis.r, scene.dim);
        for j in 0..r {
            self.c[j] = t.damping_alpha + t.damping_beta * self.basis.lambda[j];
            self.w[j] = t.mode_weights[j];
        }
        self.gravity_modal.fill(0.0);
        for k in 0..n {
            let fk = scene.dof_mass[k] * t.gravity[k % d];
            for j in 0..r {
                self.gravity_modal[j] += self.basis.phi[k * r + j] * fk;
            }
        }
    }

    /// a = h(q) - c q' at the current state (after a load change or at start).
    pub fn reset_acceleration(&mut self, scene: &Scene) {
        let q = std::mem::take(&mut self.q);
        self.evaluate(scene, &q);
        self.q = q;
        for j in 0..self.basis.r {
            self.qdd[j] = self.h[j] - self.c[j] * self.qd[j];
        }
    }

    /// h(q) into `self.h`, positions into `self.x`, elastic energy into `self.elastic`.
    fn evaluate(&mut self, scene: &Scene, q: &[f64]) {
        let n = self.basis.n;
        // expand: x = x* + Phi q over the free DOFs, one mode at a time
        self.x[..n].copy_from_slice(&scene.rest[..n]);
        for (col, qj) in self.phi_cols.chunks_exact(n).zip(q) {
            for (xk, p) in self.x[..n].iter_mut().zip(col) {
                *xk += p * qj;
            }
        }
        // exact spring forces in physical space
        self.f.fill(0.0);
        self.elastic = self.spring_forces.add_to(scene, &self.x, &mut self.f);
        // project: F = Phi^T (f + M g)
        for ((hj, col), gj) in self.h.iter_mut().zip(self.phi_cols.chunks_exact(n)).zip(&self.gravity_modal) {
            *hj = gj + col.iter().zip(&self.f).map(|(p, fk)| p * fk).sum::<f64>();
        }
        // weights act on everything but the mode's own linear spring
        for j in 0..self.basis.r {
            self.h[j] = self.w[j] * self.h[j] + (self.w[j] - 1.0) * self.basis.lambda[j] * q[j];
        }
    }

    pub fn step_explicit(&mut self, scene: &Scene, dt: f64) -> Result<(), SimError> {
        let mut q_new = std::mem::take(&mut self.q_new);
        predict(&self.q, &self.qd, &self.qdd, dt, &mut q_new);
        self.evaluate(scene, &q_new);
        for j in 0..self.basis.r {
            let v = (self.qd[j] + 0.5 * dt * (self.qdd[j] + self.h[j])) / (1.0 + 0.5 * dt * self.c[j]);
            self.qdd[j] = self.h[j] - self.c[j] * v;
            self.qd[j] = v;
        }
        std::mem::swap(&mut self.q, &mut q_new);
        self.q_new = q_new;
        Ok(())
    }

    pub fn step_implicit(&mut self, scene: &Scene, dt: f64) -> Result<(), SimError> {
        let r = self.basis.r;
        let mut y = std::mem::take(&mut self.q_new);
        predict(&self.q, &self.qd, &self.qdd, dt, &mut y);
        let c0 = 4.0 / (dt * dt);
        let c1 = 2.0 / dt;
        let mut done = false;
        // Built only on failure: the stepping loop must not allocate.
        let mut result = Ok(());
        let mut converged_at_end = false;
        for _ in 0..=MAX_NEWTON_ITERATIONS {
            self.evaluate(scene, &y);
            implicit_kinematics(&self.q, &self.qd, &self.qdd, &y, dt, &mut self.v_new, &mut self.a_new);
            if done {
                converged_at_end = true;
                break;
            }
            for j in 0..r {
                self.residual[(j, 0)] = -(self.a_new[j] + self.c[j] * self.v_new[j] - self.h[j]);
            }
            // J = c0 I + c1 diag(c) + W Phi^T K(x) Phi - diag((w - 1) lambda)
            self.kr.fill(0.0);
            add_reduced_tangent(scene, &self.x, &self.basis.phi, r, false, &mut self.kr, &mut self.work);
            for col in 0..r {
                for row in 0..r {
                    self.jac[(row, col)] = self.w[row] * self.kr[col * r + row];
                }
                self.jac[(col, col)] += c0 + c1 * self.c[col] - (self.w[col] - 1.0) * self.basis.lambda[col];
            }
            let stack = MemStack::new(&mut self.mem);
            let (_, row_perm) = lu_in_place(self.jac.as_mut(), &mut self.perm, &mut self.perm_inv, Par::Seq, stack, Default::default());
            let jac = self.jac.as_ref();
            let stack = MemStack::new(&mut self.mem);
            solve_in_place_with_conj(jac, jac, row_perm, Conj::No, self.residual.as_mut(), Par::Seq, stack);
            let delta = self.residual.col(0).try_as_col_major().unwrap().as_slice();
            if !delta.iter().all(|d| d.is_finite()) {
                result = Err(SimError { message: format!("implicit Newmark: singular Newton matrix at dt = {dt:e} s") });
                break;
            }
            for j in 0..r {
                y[j] += delta[j];
            }
            done = converged(delta, &y, self.q_scale);
        }
        if result.is_ok() && !converged_at_end {
            result = Err(SimError {
                message: format!("implicit Newmark: Newton did not converge in {MAX_NEWTON_ITERATIONS} iterations at dt = {dt:e} s; reduce maxInternalStep"),
            });
        }
        if result.is_ok() {
            std::mem::swap(&mut self.q, &mut y);
            self.qd.copy_from_slice(&self.v_new);
            self.qdd.copy_from_slice(&self.a_new);
        }
        self.q_new = y;
        result
    }

    /// Velocities of the free DOFs, Phi q'.
    pub fn dof_velocities(&self, out: &mut [f64]) {
        out.fill(0.0);
        for (col, vj) in self.phi_cols.chunks_exact(self.basis.n).zip(&self.qd) {
            for (o, p) in out.iter_mut().zip(col) {
                *o += p * vj;
            }
        }
    }

    /// Kinetic energy 1/2 v^T M v = 1/2 |q'|^2, since Phi^T M Phi = I.
    pub fn kinetic_energy(&self) -> f64 {
        0.5 * self.qd.iter().map(|v| v * v).sum::<f64>()
    }

    /// Potential of gravity -(M g)^T u = -(Phi^T M g)^T q, relative to x*.
    pub fn gravity_potential(&self) -> f64 {
        -self.gravity_modal.iter().zip(&self.q).map(|(g, q)| g * q).sum::<f64>()
    }

    /// Brings `x` and `elastic` in line with the current q (after a restore).
    pub fn refresh_positions(&mut self, scene: &Scene) {
        let q = std::mem::take(&mut self.q);
        self.evaluate(scene, &q);
        self.q = q;
    }
}
