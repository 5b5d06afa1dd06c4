//! The full space: the same model on every free DOF, no reduction
//! (`docs/method.md`, section 4), the reference of every comparison.
//!
//! y = u, the displacements of the free DOFs from x*, x = x* + u. M is the
//! lumped diagonal, C = alpha M + beta K0 (Rayleigh, K0 the stiffness at x*,
//! so the modal and full runs share one damping model). Linear systems (the
//! implicit Newton matrix, and the explicit velocity update when beta > 0)
//! are solved with faer's sparse Cholesky LL^T, or LDL^T where compressed
//! springs make the Newton matrix indefinite; the symbolic analysis is made
//! at set-up.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, LdltRef, LltRef, SymbolicCholesky, SymmetricOrdering};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

use super::equations::{Diagonal, Layout, Readout, Space};
use crate::physics::basis;
use crate::physics::error::{PhysicsError, StepFailure};
use crate::physics::forces::{linearize, omega_sq_bound_full, SpringForces, SpringScratch, StiffnessPattern};
use crate::physics::frame::{add_outer, Moments};
use crate::physics::modes::ModalBasis;
use crate::physics::scene::Scene;
use crate::physics::settings::Settings;
use crate::physics::state::Loads;

/// The constant model of the full-space equations.
pub struct Full {
    scene: Scene,
    springs: SpringForces,
    pattern: StiffnessPattern,
    /// Upper triangle of K0, the stiffness at x*.
    k0: Vec<f64>,
    symbolic: SymbolicCholesky<usize>,
    /// Modes whose coordinates and frequencies are reported, if any.
    reported: Option<ModalBasis>,
    /// x_rest - x* of the reported modes, when x* is not the rest positions.
    reported_offset: Option<Vec<f64>>,
    frequencies: Vec<f64>,
    omega_sq_bound: f64,
    newton_scale: f64,
}

/// Load terms and scratch of a full-space run.
pub struct FullWork {
    alpha: f64,
    beta: f64,
    /// M g plus the point load, per DOF.
    gravity: Vec<f64>,
    /// Slot positions and elastic energy of the last force evaluation.
    x: Vec<f64>,
    elastic: f64,
    springs: SpringScratch,
    /// C v.
    cv: Vec<f64>,
    /// Values of the matrix to factor, on the stiffness pattern.
    matrix: Vec<f64>,
    l_values: Vec<f64>,
    /// `l_values` holds LDL^T (the matrix was indefinite), not LL^T.
    indefinite: bool,
    mem: MemBuffer,
    /// (dt, alpha, beta) for which `l_values` holds M + dt/2 C (explicit, beta > 0).
    explicit_factor: Option<(f64, f64, f64)>,
}

impl Full {
    /// Assembles the stiffness at rest and its symbolic Cholesky analysis;
    /// builds the basis of `reported_modes` vectors `options` ask for (under
    /// the set-up `loads`) when that is not 0, to report its coordinates.
    pub fn new(scene: Scene, loads: &Loads, settings: &Settings) -> Result<Self, PhysicsError> {
        let reported_modes = settings.n_modes;
        let (pattern, k0) = linearize(&scene);
        let (reported, reported_offset) = if reported_modes > 0 {
            let b = basis::build(&scene, loads, reported_modes, settings)?;
            let offset = (!b.at_rest).then(|| (0..scene.n_dofs()).map(|k| scene.rest[k] - b.point[k]).collect());
            (Some(b.modes), offset)
        } else {
            (None, None)
        };
        let n = scene.n_dofs();
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &pattern.col_ptr, None, &pattern.row_idx);
        let symbolic = factorize_symbolic_cholesky(sym, Side::Upper, SymmetricOrdering::Amd, Default::default())
            .map_err(|e| PhysicsError::LinearAlgebra { what: "sparse Cholesky analysis", detail: format!("{e:?}") })?;
        Ok(Full {
            springs: SpringForces::new(&scene),
            frequencies: reported.as_ref().map(|b| b.frequencies()).unwrap_or_default(),
            omega_sq_bound: omega_sq_bound_full(&scene),
            newton_scale: scene.length_scale().max(1e-300),
            reported,
            reported_offset,
            symbolic,
            pattern,
            k0,
            scene,
        })
    }

    /// cv = C v = alpha M v + beta K0 v.
    fn damping_times(&self, v: &[f64], w: &mut FullWork) {
        let mass = &self.scene.dof_mass;
        if w.beta != 0.0 {
            self.pattern.sym_matvec(&self.k0, v, &mut w.cv);
            for k in 0..v.len() {
                w.cv[k] = w.alpha * mass[k] * v[k] + w.beta * w.cv[k];
            }
        } else {
            for k in 0..v.len() {
                w.cv[k] = w.alpha * mass[k] * v[k];
            }
        }
    }

    /// Factorizes `c_m M + c_k K0 (+ K(x) if tangent)` into `w.l_values`.
    fn factorize(&self, c_m: f64, c_k: f64, tangent: bool, w: &mut FullWork) -> Result<(), StepFailure> {
        for (m, k) in w.matrix.iter_mut().zip(&self.k0) {
            *m = c_k * k;
        }
        for (k, &pos) in self.pattern.diag.iter().enumerate() {
            w.matrix[pos] += c_m * self.scene.dof_mass[k];
        }
        if tangent {
            self.pattern.add_tangent(&self.scene, &w.x, 1.0, &mut w.matrix);
        }
        let n = self.scene.n_dofs();
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &self.pattern.col_ptr, None, &self.pattern.row_idx);
        let a = SparseColMatRef::new(sym, &w.matrix);
        let stack = MemStack::new(&mut w.mem);
        let llt = self.symbolic.factorize_numeric_llt(&mut w.l_values, a, Side::Upper, LltRegularization::default(), Par::Seq, stack, Default::default());
        w.indefinite = llt.is_err();
        if !w.indefinite {
            return Ok(());
        }
        // Springs in compression have negative transverse stiffness; with
        // stiff springs it can outweigh M / (beta dt^2). Newton still
        // converges on the indefinite matrix: factor it as LDL^T.
        let stack = MemStack::new(&mut w.mem);
        let regularization = LdltRegularization { dynamic_regularization_signs: None, dynamic_regularization_delta: 0.0, dynamic_regularization_epsilon: 0.0 };
        self.symbolic
            .factorize_numeric_ldlt(&mut w.l_values, a, Side::Upper, regularization, Par::Seq, stack, Default::default())
            .map(|_| ())
            .map_err(|_| StepFailure::Buckled)
    }
}

impl Space for Full {
    type Work = FullWork;

    fn scene(&self) -> &Scene {
        &self.scene
    }

    fn layout(&self) -> Layout<'_> {
        Layout {
            scene: &self.scene,
            coordinates: self.scene.n_dofs(),
            kept_modes: None,
            springs: self.scene.springs.len(),
            frequencies: &self.frequencies,
            newton_scale: self.newton_scale,
        }
    }

    fn work(&self) -> FullWork {
        let n = self.scene.n_dofs();
        let req = StackReq::any_of(&[
            self.symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
            self.symbolic.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()),
            self.symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]);
        FullWork {
            alpha: 0.0,
            beta: 0.0,
            gravity: vec![0.0; n],
            x: self.scene.rest.clone(),
            elastic: 0.0,
            springs: self.springs.scratch(&self.scene),
            cv: vec![0.0; n],
            matrix: vec![0.0; self.pattern.nnz()],
            l_values: vec![0.0; self.symbolic.len_val()],
            indefinite: false,
            mem: MemBuffer::new(req),
            explicit_factor: None,
        }
    }

    /// u = 0: the full space measures from the rest positions.
    fn rest_coordinates(&self, u: &mut [f64]) {
        u.fill(0.0);
    }

    fn apply_loads(&self, loads: &Loads, w: &mut FullWork) {
        let d = self.scene.dim;
        w.alpha = loads.damping_alpha;
        w.beta = loads.damping_beta;
        for (k, g) in w.gravity.iter_mut().enumerate() {
            *g = self.scene.dof_mass[k] * loads.gravity[k % d];
        }
        // The point load joins M g (`docs/method.md`, section 8).
        if let Some((dof, f)) = loads.point_force(&self.scene) {
            for (g, fi) in w.gravity[dof..dof + d].iter_mut().zip(f) {
                *g += fi;
            }
        }
    }

    /// h(u) = f_springs(x* + u) + M g + f_p.
    fn force(&self, _loads: &Loads, u: &[f64], w: &mut FullWork, h: &mut [f64]) {
        for k in 0..u.len() {
            w.x[k] = self.scene.rest[k] + u[k];
        }
        h.copy_from_slice(&w.gravity);
        w.elastic = self.springs.add_to(&self.scene, &w.x, &mut w.springs, h);
    }

    fn explicit_velocity(&self, dt: f64, v: &[f64], a: &[f64], h: &[f64], w: &mut FullWork, v1: &mut [f64]) -> Result<(), StepFailure> {
        let mass = &self.scene.dof_mass;
        for k in 0..v1.len() {
            v1[k] = mass[k] * (v[k] + 0.5 * dt * a[k]) + 0.5 * dt * h[k];
        }
        if w.beta != 0.0 {
            // (M + dt/2 C) is constant while dt and the damping are: factor once.
            let key = (dt, w.alpha, w.beta);
            if w.explicit_factor != Some(key) {
                w.explicit_factor = None;
                self.factorize(1.0 + 0.5 * dt * w.alpha, 0.5 * dt * w.beta, false, w)?;
                w.explicit_factor = Some(key);
            }
            self.solve(w, v1);
        } else {
            for k in 0..v1.len() {
                v1[k] /= mass[k] * (1.0 + 0.5 * dt * w.alpha);
            }
        }
        Ok(())
    }

    fn acceleration(&self, v: &[f64], h: &[f64], w: &mut FullWork, a: &mut [f64]) {
        self.damping_times(v, w);
        for k in 0..a.len() {
            a[k] = (h[k] - w.cv[k]) / self.scene.dof_mass[k];
        }
    }

    fn residual(&self, v: &[f64], a: &[f64], h: &[f64], w: &mut FullWork, r: &mut [f64]) {
        self.damping_times(v, w);
        for k in 0..r.len() {
            r[k] = -(self.scene.dof_mass[k] * a[k] + w.cv[k] - h[k]);
        }
    }

    /// c_m M + c_c (alpha M + beta K0) + K(x): the tangent of -h is the stiffness K(x).
    fn factor(&self, _loads: &Loads, c_m: f64, c_c: f64, w: &mut FullWork) -> Result<(), StepFailure> {
        w.explicit_factor = None;
        self.factorize(c_m + c_c * w.alpha, c_c * w.beta, true, w)
    }

    fn solve(&self, w: &mut FullWork, rhs: &mut [f64]) {
        let n = rhs.len();
        let stack = MemStack::new(&mut w.mem);
        let rhs = MatMut::from_column_major_slice_mut(rhs, n, 1);
        if w.indefinite {
            LdltRef::<usize, f64>::new(&self.symbolic, &w.l_values).solve_in_place_with_conj(Conj::No, rhs, Par::Seq, stack);
        } else {
            LltRef::<usize, f64>::new(&self.symbolic, &w.l_values).solve_in_place_with_conj(Conj::No, rhs, Par::Seq, stack);
        }
    }

    fn omega_sq_bound(&self, _loads: &Loads) -> f64 {
        self.omega_sq_bound
    }

    /// K0 and C couple the DOFs: no diagonal form.
    fn diagonal<'a>(&'a self, _w: &'a FullWork) -> Option<Diagonal<'a>> {
        None
    }

    /// u' += 1 c on every free node.
    fn add_translation_rate(&self, _loads: &Loads, c: &[f64; 3], v: &mut [f64]) {
        let d = self.scene.dim;
        for (k, vk) in v.iter_mut().enumerate() {
            *vk += c[k % d];
        }
    }
}

impl Readout for Full {
    fn spring_force(&self, u: &[f64], w: &mut FullWork, out: &mut [f64]) {
        for k in 0..u.len() {
            w.x[k] = self.scene.rest[k] + u[k];
        }
        out.fill(0.0);
        w.elastic = self.springs.add_to(&self.scene, &w.x, &mut w.springs, out);
    }

    fn positions<'w>(&self, _u: &[f64], w: &'w mut FullWork) -> &'w [f64] {
        &w.x
    }

    fn elastic_energy(&self, _u: &[f64], w: &mut FullWork) -> f64 {
        w.elastic
    }

    /// -(M g)^T u, summed node by node, and -f_p^T u at the load node.
    fn gravity_potential(&self, loads: &Loads, u: &[f64], _w: &FullWork) -> f64 {
        let d = self.scene.dim;
        let g = &loads.gravity;
        let work: f64 = u.chunks_exact(d).zip(self.scene.dof_mass.chunks_exact(d)).map(|(u, m)| (0..d).map(|i| m[i] * g[i] * u[i]).sum::<f64>()).sum();
        match loads.point_force(&self.scene) {
            Some((dof, f)) => -work - f.iter().zip(&u[dof..dof + d]).map(|(f, u)| f * u).sum::<f64>(),
            None => -work,
        }
    }

    fn kinetic_energy(&self, v: &[f64]) -> f64 {
        0.5 * v.iter().zip(&self.scene.dof_mass).map(|(v, m)| m * v * v).sum::<f64>()
    }

    fn slot_velocity(&self, v: &[f64], slot: usize) -> [f64; 3] {
        let d = self.scene.dim;
        std::array::from_fn(|i| if i < d { v[slot * d + i] } else { 0.0 })
    }

    fn momentum(&self, v: &[f64]) -> [f64; 3] {
        let (d, mut p) = (self.scene.dim, [0.0; 3]);
        for (k, (vk, m)) in v.iter().zip(&self.scene.dof_mass).enumerate() {
            p[k % d] += m * vk;
        }
        p
    }

    fn first_moment(&self, u: &[f64]) -> [f64; 3] {
        let (d, pivot, mut s) = (self.scene.dim, self.scene.pivot(), [0.0; 3]);
        for (k, (uk, m)) in u.iter().zip(&self.scene.dof_mass).enumerate() {
            s[k % d] += m * (self.scene.rest[k] + uk - pivot[k % d]);
        }
        s
    }

    /// Node by node, rho = x_rest + u - X0.
    fn moments(&self, u: &[f64], v: &[f64]) -> Moments {
        let (d, pivot) = (self.scene.dim, self.scene.pivot());
        let mut out = Moments::default();
        for (k, m) in self.scene.dof_mass.iter().step_by(d).enumerate() {
            let rho: [f64; 3] = std::array::from_fn(|i| if i < d { self.scene.rest[k * d + i] + u[k * d + i] - pivot[i] } else { 0.0 });
            let vel: [f64; 3] = std::array::from_fn(|i| if i < d { v[k * d + i] } else { 0.0 });
            for i in 0..3 {
                out.first[i] += m * rho[i];
                out.momentum[i] += m * vel[i];
            }
            add_outer(&mut out.second, *m, &rho, &rho);
            add_outer(&mut out.flux, *m, &vel, &rho);
        }
        out
    }

    /// z = a + M^-1 C v.
    fn undamped_acceleration(&self, v: &[f64], a: &[f64], w: &mut FullWork, z: &mut [f64]) {
        self.damping_times(v, w);
        for k in 0..z.len() {
            z[k] = a[k] + w.cv[k] / self.scene.dof_mass[k];
        }
    }

    fn dof_velocities(&self, v: &[f64], out: &mut [f64]) {
        out.copy_from_slice(v);
    }

    /// Every force is represented: 0.
    fn force_residual(&self, _loads: &Loads, _u: &[f64], _w: &mut FullWork) -> f64 {
        0.0
    }

    /// q = Phi^T M (x - x*) on the reported modes.
    fn modal_coordinates(&self, u: &[f64], out: &mut [f64]) {
        if let Some(b) = &self.reported {
            match &self.reported_offset {
                None => b.project_displacement(&self.scene.dof_mass, u, out),
                Some(offset) => {
                    let d: Vec<f64> = u.iter().zip(offset).map(|(a, b)| a + b).collect();
                    b.project_displacement(&self.scene.dof_mass, &d, out);
                }
            }
        }
    }
}
