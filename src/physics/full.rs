//! Full-space solver: the same model on every free DOF, no reduction.
//!
//! State: displacements u of the free DOFs from the linearization point,
//! x = x* + u. Mass M is the lumped diagonal, damping C = alpha M + beta K0
//! (Rayleigh, K0 the stiffness at x*, so the modal and full runs share one
//! damping model). Linear systems (the implicit Newton matrix, and the
//! explicit velocity update when beta > 0) are solved with faer's sparse
//! Cholesky LL^T, or LDL^T where compressed springs make the Newton matrix
//! indefinite; the symbolic analysis and every buffer are made once.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, LdltRef, LltRef, SymbolicCholesky, SymmetricOrdering};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

use super::forces::{SpringForces, StiffnessPattern};
use super::newmark::*;
use super::params::Tunables;
use super::scene::Scene;
use super::SimError;

pub struct FullSolver {
    pub pattern: StiffnessPattern,
    /// Upper triangle of K0, the stiffness at x*.
    pub k0: Vec<f64>,
    /// Displacements, velocities, accelerations of the free DOFs.
    pub u: Vec<f64>,
    pub v: Vec<f64>,
    pub a: Vec<f64>,
    mass: Vec<f64>,
    alpha: f64,
    beta: f64,
    /// M g per DOF.
    gravity_force: Vec<f64>,
    /// Slot positions of the last force evaluation.
    pub x: Vec<f64>,
    pub elastic: f64,
    spring_forces: SpringForces,
    h: Vec<f64>,
    y_new: Vec<f64>,
    v_new: Vec<f64>,
    a_new: Vec<f64>,
    rhs: Vec<f64>,
    cv: Vec<f64>,
    matrix: Vec<f64>,
    symbolic: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
    /// `l_values` holds LDL^T (the matrix was indefinite), not LL^T.
    indefinite: bool,
    mem: MemBuffer,
    /// (dt, alpha, beta) for which `l_values` holds M + dt/2 C (explicit, beta > 0).
    explicit_factor: Option<(f64, f64, f64)>,
    length_scale: f64,
}

impl FullSolver {
    pub fn new(scene: &Scene, pattern: StiffnessPattern, k0: Vec<f64>, tunables: &Tunables) -> Result<Self, SimError> {
        let n = scene.n_dofs();
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &pattern.col_ptr, None, &pattern.row_idx);
        let symbolic = factorize_symbolic_cholesky(sym, Side::Upper, SymmetricOrdering::Amd, Default::default())
            .map_err(|e| SimError { message: format!("sparse Cholesky analysis failed: {e:?}") })?;
        let req = StackReq::any_of(&[
            symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]);
        let l_values = vec![0.0; symbolic.len_val()];
        let nnz = pattern.nnz();
        let mut s = FullSolver {
            u: vec![0.0; n],
            v: vec![0.0; n],
            a: vec![0.0; n],
            mass: scene.dof_mass.clone(),
            alpha: 0.0,
            beta: 0.0,
            gravity_force: vec![0.0; n],
            x: scene.rest.clone(),
            elastic: 0.0,
            spring_forces: SpringForces::new(scene),
            h: vec![0.0; n],
            y_new: vec![0.0; n],
            v_new: vec![0.0; n],
            a_new: vec![0.0; n],
            rhs: vec![0.0; n],
            cv: vec![0.0; n],
            matrix: vec![0.0; nnz],
            symbolic,
            l_values,
            indefinite: false,
            mem: MemBuffer::new(req),
            explicit_factor: None,
            length_scale: 0.0,
            pattern,
            k0,
        };
        s.length_scale = scene.rest.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
        s.set_tunables(scene, tunables);
        s.reset_acceleration(scene);
        Ok(s)
    }

    pub fn set_tunables(&mut self, scene: &Scene, t: &Tunables) {
        let d = scene.dim;
        self.alpha = t.damping_alpha;
        self.beta = t.damping_beta;
        for (k, g) in self.gravity_force.iter_mut().enumerate() {
            *g = self.mass[k] * t.gravity[k % d];
        }
    }

    /// a = M^-1 (h(u) - C v) at the current state.
    pub fn reset_acceleration(&mut self, scene: &Scene) {
        let u = std::mem::take(&mut self.u);
        self.evaluate(scene, &u);
        self.u = u;
        let v = std::mem::take(&mut self.v);
        self.damping_times(&v);
        self.v = v;
        for k in 0..self.a.len() {
            self.a[k] = (self.h[k] - self.cv[k]) / self.mass[k];
        }
    }

    /// h(u) = f_springs(x* + u) + M g into `self.h`.
    fn evaluate(&mut self, scene: &Scene, u: &[f64]) {
        let n = u.len();
        for k in 0..n {
            self.x[k] = scene.rest[k] + u[k];
        }
        self.h.copy_from_slice(&self.gravity_force);
        self.elastic = self.spring_forces.add_to(scene, &self.x, &mut self.h);
    }

    /// cv = C v = alpha M v + beta K0 v.
    fn damping_times(&mut self, v: &[f64]) {
        if self.beta != 0.0 {
            self.pattern.sym_matvec(&self.k0, v, &mut self.cv);
            for k in 0..v.len() {
                self.cv[k] = self.alpha * self.mass[k] * v[k] + self.beta * self.cv[k];
            }
        } else {
            for k in 0..v.len() {
                self.cv[k] = self.alpha * self.mass[k] * v[k];
            }
        }
    }

    /// Factorizes `c_m M + c_k K0 (+ K(x) if tangent)` into `l_values`.
    fn factorize(&mut self, scene: &Scene, c_m: f64, c_k: f64, tangent: bool) -> Result<(), SimError> {
        for (m, k) in self.matrix.iter_mut().zip(&self.k0) {
            *m = c_k * k;
        }
        for (k, &pos) in self.pattern.diag.iter().enumerate() {
            self.matrix[pos] += c_m * self.mass[k];
        }
        if tangent {
            self.pattern.add_tangent(scene, &self.x, 1.0, &mut self.matrix);
        }
        let n = self.mass.len();
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &self.pattern.col_ptr, None, &self.pattern.row_idx);
        let a = SparseColMatRef::new(sym, &self.matrix);
        let stack = MemStack::new(&mut self.mem);
        let llt = self.symbolic.factorize_numeric_llt(&mut self.l_values, a, Side::Upper, LltRegularization::default(), Par::Seq, stack, Default::default());
        self.indefinite = llt.is_err();
        if !self.indefinite {
            return Ok(());
        }
        // Springs in compression have negative transverse stiffness; with
        // stiff springs it can outweigh M / (beta dt^2). Newton still
        // converges on the indefinite matrix: factor it as LDL^T.
        let stack = MemStack::new(&mut self.mem);
        let regularization = LdltRegularization { dynamic_regularization_signs: None, dynamic_regularization_delta: 0.0, dynamic_regularization_epsilon: 0.0 };
        self.symbolic
            .factorize_numeric_ldlt(&mut self.l_values, a, Side::Upper, regularization, Par::Seq, stack, Default::default())
            .map(|_| ())
            .map_err(|_| SimError { message: "full-space Newmark matrix is singular (springs in compression buckle); reduce maxInternalStep".into() })
    }

    /// Solves with the last factorization, in place.
    fn solve(&mut self, rhs: &mut [f64]) {
        let n = rhs.len();
        let stack = MemStack::new(&mut self.mem);
        let rhs = MatMut::from_column_major_slice_mut(rhs, n, 1);
        if self.indefinite {
            LdltRef::<usize, f64>::new(&self.symbolic, &self.l_values).solve_in_place_with_conj(Conj::No, rhs, Par::Seq, stack);
        } else {
            LltRef::<usize, f64>::new(&self.symbolic, &self.l_values).solve_in_place_with_conj(Conj::No, rhs, Par::Seq, stack);
        }
    }

    pub fn step_explicit(&mut self, scene: &Scene, dt: f64) -> Result<(), SimError> {
        let n = self.u.len();
        let mut y = std::mem::take(&mut self.y_new);
        predict(&self.u, &self.v, &self.a, dt, &mut y);
        self.evaluate(scene, &y);
        let mut rhs = std::mem::take(&mut self.rhs);
        for k in 0..n {
            rhs[k] = self.mass[k] * (self.v[k] + 0.5 * dt * self.a[k]) + 0.5 * dt * self.h[k];
        }
        if self.beta != 0.0 {
            // (M + dt/2 C) is constant while dt and the damping are: factor once.
            let key = (dt, self.alpha, self.beta);
            if self.explicit_factor != Some(key) {
                self.explicit_factor = None;
                let r = self.factorize(scene, 1.0 + 0.5 * dt * self.alpha, 0.5 * dt * self.beta, false);
                if let Err(e) = r {
                    self.y_new = y;
                    self.rhs = rhs;
                    return Err(e);
                }
                self.explicit_factor = Some(key);
            }
            self.solve(&mut rhs);
        } else {
            for k in 0..n {
                rhs[k] /= self.mass[k] * (1.0 + 0.5 * dt * self.alpha);
            }
        }
        self.damping_times(&rhs);
        for k in 0..n {
            self.a[k] = (self.h[k] - self.cv[k]) / self.mass[k];
        }
        self.v.copy_from_slice(&rhs);
        std::mem::swap(&mut self.u, &mut y);
        self.y_new = y;
        self.rhs = rhs;
        Ok(())
    }

    pub fn step_implicit(&mut self, scene: &Scene, dt: f64) -> Result<(), SimError> {
        let n = self.u.len();
        let mut y = std::mem::take(&mut self.y_new);
        let mut delta = std::mem::take(&mut self.rhs);
        predict(&self.u, &self.v, &self.a, dt, &mut y);
        let c0 = 4.0 / (dt * dt);
        let c1 = 2.0 / dt;
        self.explicit_factor = None;
        let mut done = false;
        // Built only on failure: the stepping loop must not allocate.
        let mut result = Ok(());
        let mut converged_at_end = false;
        for _ in 0..=MAX_NEWTON_ITERATIONS {
            self.evaluate(scene, &y);
            let (mut v_new, mut a_new) = (std::mem::take(&mut self.v_new), std::mem::take(&mut self.a_new));
            implicit_kinematics(&self.u, &self.v, &self.a, &y, dt, &mut v_new, &mut a_new);
            self.damping_times(&v_new);
            self.v_new = v_new;
            self.a_new = a_new;
            if done {
                converged_at_end = true;
                break;
            }
            for k in 0..n {
                delta[k] = -(self.mass[k] * self.a_new[k] + self.cv[k] - self.h[k]);
            }
            if let Err(e) = self.factorize(scene, c0 + c1 * self.alpha, c1 * self.beta, true) {
                result = Err(e);
                break;
            }
            self.solve(&mut delta);
            if !delta.iter().all(|d| d.is_finite()) {
                result = Err(SimError { message: format!("implicit Newmark: singular Newton matrix at dt = {dt:e} s") });
                break;
            }
            for k in 0..n {
                y[k] += delta[k];
            }
            done = converged(&delta, &y, self.length_scale);
        }
        if result.is_ok() && !converged_at_end {
            result = Err(SimError {
                message: format!("implicit Newmark: Newton did not converge in {MAX_NEWTON_ITERATIONS} iterations at dt = {dt:e} s; reduce maxInternalStep"),
            });
        }
        if result.is_ok() {
            std::mem::swap(&mut self.u, &mut y);
            self.v.copy_from_slice(&self.v_new);
            self.a.copy_from_slice(&self.a_new);
        }
        self.y_new = y;
        self.rhs = delta;
        result
    }

    /// Brings `x` and `elastic` in line with the current u (after a restore).
    pub fn refresh_positions(&mut self, scene: &Scene) {
        let u = std::mem::take(&mut self.u);
        self.evaluate(scene, &u);
        self.u = u;
    }
}
