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
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, LdltRef, LltRef, SymbolicCholesky, SymmetricOrdering};
use faer::sparse::SymbolicSparseColMatRef;
use faer::{Conj, MatMut, Par, Side};
use rayon::prelude::*;
use std::sync::OnceLock;

mod linear;
mod readout;

use super::equations::{Constants, Diagonal, Layout, Space};
use crate::physics::error::{PhysicsError, StepFailure};
use crate::physics::run::forces::{SpringForces, SpringScratch, SpringSplit};
use crate::physics::run::frame::{cross, dot, Frame};
use crate::physics::run::state::Loads;
use crate::physics::run::stiffness::{linearize, omega_sq_bound_full, StiffnessPattern};
use crate::physics::settings::Settings;
use crate::physics::setup::basis;
use crate::physics::setup::modes::ModalBasis;
use crate::physics::setup::scene::Scene;
use crate::physics::vector_unit;

/// The constant model of the full-space equations.
pub struct Full {
    scene: Scene,
    springs: SpringForces,
    pattern: StiffnessPattern,
    /// Upper triangle of K0, the stiffness at x*.
    k0: Vec<f64>,
    symbolic: SymbolicCholesky<usize>,
    /// The modes whose coordinates and frequencies are reported, made when
    /// first asked for ([`Constants::modes_made`]): what they are made from,
    /// and the result.
    reported_from: Option<(Loads, Settings)>,
    reported: OnceLock<Result<Reported, PhysicsError>>,
    omega_sq_bound: f64,
    newton_scale: f64,
    /// The pivot X0.
    pivot: [f64; 3],
    /// In 3D, per free node, the positions of its (x, y), (x, z), (y, z)
    /// entries in the stiffness pattern (SKIP where none).
    node_pairs: Vec<[usize; 3]>,
    /// The threads of the spring forces and node updates when
    /// `settings.threads` > 1 (see [`SpringForces::set_to_parallel`]).
    pool: Option<rayon::ThreadPool>,
}

/// DOFs per task of the parallel node updates.
const NODE_TASK: usize = 4096;

/// The reported modes of a full-space run.
struct Reported {
    modes: ModalBasis,
    /// x_rest - x* of the modes, when x* is not the rest positions.
    offset: Option<Vec<f64>>,
    frequencies: Vec<f64>,
}

/// No entry in the pattern.
const SKIP: usize = usize::MAX;

/// Load terms and scratch of a full-space run.
pub struct FullWork {
    /// The loads of the run: the one place its gravity, point load and damping live.
    loads: Loads,
    alpha: f64,
    beta: f64,
    /// M g plus the point load, per DOF.
    gravity: Vec<f64>,
    /// Slot positions and elastic energy of the last force evaluation.
    x: Vec<f64>,
    elastic: f64,
    springs: SpringScratch,
    /// The split of the force evaluation over the threads (with a pool).
    split: Option<SpringSplit>,
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
    /// The holder's frame has left its rest orientation ([`Space::turn`]), and its spin.
    turning: bool,
    spin: [f64; 3],
    /// The right side and the previous iterate of the Coriolis velocity update.
    rhs: Vec<f64>,
    previous: Vec<f64>,
}

impl AsRef<Loads> for FullWork {
    fn as_ref(&self) -> &Loads {
        &self.loads
    }
}

impl AsMut<Loads> for FullWork {
    fn as_mut(&mut self) -> &mut Loads {
        &mut self.loads
    }
}

impl Full {
    /// Assembles the stiffness at rest and its symbolic Cholesky analysis.
    /// The basis of the `settings.n_modes` vectors the settings ask for
    /// (under the set-up `loads`), whose coordinates and frequencies are
    /// reported, is made when first asked for: a run that does not read
    /// them does not pay for them (on cloth 30 x 30, 900 of them took 3.5 s
    /// of set-up). What can be refused without making it is refused here.
    pub fn new(scene: Scene, loads: &Loads, settings: &Settings) -> Result<Self, PhysicsError> {
        let (pattern, k0) = linearize(&scene);
        let reported_from = if settings.n_modes > 0 {
            basis::refuse_early(&scene, loads, settings.n_modes, settings)?;
            Some((loads.clone(), settings.clone()))
        } else {
            None
        };
        let n = scene.n_dofs();
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &pattern.col_ptr, None, &pattern.row_idx);
        let symbolic = factorize_symbolic_cholesky(sym, Side::Upper, SymmetricOrdering::Amd, Default::default())
            .map_err(|e| PhysicsError::LinearAlgebra { what: "sparse Cholesky analysis", detail: format!("{e:?}") })?;
        let node_pairs = if scene.dim == 3 {
            let find =
                |r: usize, c: usize| pattern.row_idx[pattern.col_ptr[c]..pattern.col_ptr[c + 1]].binary_search(&r).map_or(SKIP, |i| pattern.col_ptr[c] + i);
            (0..scene.n_free).map(|k| [find(3 * k, 3 * k + 1), find(3 * k, 3 * k + 2), find(3 * k + 1, 3 * k + 2)]).collect()
        } else {
            Vec::new()
        };
        let pool = if settings.threads > 1 {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(settings.threads).build();
            Some(pool.map_err(|e| PhysicsError::LinearAlgebra { what: "thread pool", detail: e.to_string() })?)
        } else {
            None
        };
        Ok(Full {
            pool,
            pivot: scene.pivot(),
            node_pairs,
            springs: SpringForces::new(&scene),
            omega_sq_bound: omega_sq_bound_full(&scene),
            newton_scale: scene.length_scale().max(1e-300),
            reported_from,
            reported: OnceLock::new(),
            symbolic,
            pattern,
            k0,
            scene,
        })
    }
}

impl Full {
    /// The reported modes, made if they are not yet (`None`: none asked for).
    fn reported(&self) -> Option<&Result<Reported, PhysicsError>> {
        let (loads, settings) = self.reported_from.as_ref()?;
        Some(self.reported.get_or_init(|| {
            let b = basis::build(&self.scene, loads, settings.n_modes, settings)?;
            let offset = (!b.at_rest).then(|| (0..self.scene.n_dofs()).map(|k| self.scene.rest[k] - b.point[k]).collect());
            Ok(Reported { frequencies: b.modes.frequencies(), modes: b.modes, offset })
        }))
    }

    /// h = f_springs(x) + M g + f_p at the slot positions in `w` (gravity
    /// and the springs in one pass, as adding the springs to a copy of
    /// gravity); turning, the centrifugal force joins it.
    fn force_at_slots(&self, w: &mut FullWork, h: &mut [f64]) {
        w.elastic = match (&self.pool, &mut w.split) {
            (Some(pool), Some(split)) => self.springs.set_to_parallel(&self.scene, &w.x, &mut w.springs, split, pool, &w.gravity, h),
            _ => self.springs.set_to(&self.scene, &w.x, &mut w.springs, &w.gravity, h),
        };
        if w.turning {
            let (d, spin) = (self.scene.dim, w.spin);
            let w2 = dot(&spin, &spin);
            for (k, hk) in h.chunks_exact_mut(d).enumerate() {
                let m = self.scene.dof_mass[k * d];
                let rho: [f64; 3] = std::array::from_fn(|i| if i < d { w.x[k * d + i] - self.pivot[i] } else { 0.0 });
                let along = dot(&spin, &rho);
                for i in 0..d {
                    hk[i] += m * (w2 * rho[i] - spin[i] * along);
                }
            }
        }
    }
}

impl Constants for Full {
    fn scene(&self) -> &Scene {
        &self.scene
    }

    fn layout(&self) -> Layout<'_> {
        Layout {
            scene: &self.scene,
            coordinates: self.scene.n_dofs(),
            kept_modes: None,
            springs: self.scene.springs.len(),
            // Those of the reported modes once made (Constants::modes_made).
            frequencies: self.reported.get().and_then(|r| r.as_ref().ok()).map_or(&[], |r| &r.frequencies),
            newton_scale: self.newton_scale,
            trained: None,
        }
    }

    fn modes(&self) -> Option<&ModalBasis> {
        self.reported().and_then(|r| r.as_ref().ok()).map(|r| &r.modes)
    }

    fn modes_made(&self) -> Result<(), &PhysicsError> {
        match self.reported() {
            Some(Err(e)) => Err(e),
            _ => Ok(()),
        }
    }

    /// u = 0: the full space measures from the rest positions.
    fn rest_coordinates(&self, u: &mut [f64]) {
        u.fill(0.0);
    }
}

impl Space for Full {
    type Work = FullWork;

    fn work(&self, loads: &Loads) -> FullWork {
        let n = self.scene.n_dofs();
        let req = StackReq::any_of(&[
            self.symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
            self.symbolic.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()),
            self.symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]);
        FullWork {
            loads: loads.clone(),
            alpha: 0.0,
            beta: 0.0,
            gravity: vec![0.0; n],
            x: self.scene.rest.clone(),
            elastic: 0.0,
            springs: self.springs.scratch(&self.scene),
            split: self.pool.as_ref().map(|p| self.springs.split(p.current_num_threads())),
            cv: vec![0.0; n],
            matrix: vec![0.0; self.pattern.nnz()],
            l_values: vec![0.0; self.symbolic.len_val()],
            indefinite: false,
            mem: MemBuffer::new(req),
            explicit_factor: None,
            turning: false,
            spin: [0.0; 3],
            rhs: vec![0.0; n],
            previous: vec![0.0; n],
        }
    }

    fn apply_loads(&self, w: &mut FullWork) {
        let d = self.scene.dim;
        let loads = &w.loads;
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
        w.turning = false;
    }

    /// M R^T g + R^T f_p per DOF, and the spin.
    fn turn(&self, frame: &Frame, w: &mut FullWork) {
        let d = self.scene.dim;
        for (k, g) in w.gravity.iter_mut().enumerate() {
            *g = self.scene.dof_mass[k] * frame.gravity[k % d];
        }
        if let Some((dof, _)) = w.loads.point_force(&self.scene) {
            for (i, g) in w.gravity[dof..dof + d].iter_mut().enumerate() {
                *g += frame.load[i];
            }
        }
        w.turning = true;
        w.spin = frame.spin;
    }

    fn slots_mut<'w>(&self, w: &'w mut FullWork) -> &'w mut [f64] {
        &mut w.x
    }

    /// u' += c x (x_rest + u - X0) on every free node.
    fn add_rotation_rate(&self, _w: &FullWork, c: &[f64; 3], u: &[f64], v: &mut [f64]) {
        let d = self.scene.dim;
        for (k, vk) in v.chunks_exact_mut(d).enumerate() {
            let rho: [f64; 3] = std::array::from_fn(|i| if i < d { self.scene.rest[k * d + i] + u[k * d + i] - self.pivot[i] } else { 0.0 });
            let dv = cross(c, &rho);
            for i in 0..d {
                vk[i] += dv[i];
            }
        }
    }

    /// h(u) = f_springs(x* + u) + M g + f_p; turning, with M R^T g + R^T f_p
    /// and the centrifugal force m (Omega^2 rho - Omega (Omega . rho)), rho = x - X0.
    fn force(&self, u: &[f64], w: &mut FullWork, h: &mut [f64]) {
        for k in 0..u.len() {
            w.x[k] = self.scene.rest[k] + u[k];
        }
        self.force_at_slots(w, h);
    }

    /// The predictor and x = x* + u1 in one pass, then h as [`Self::force`].
    #[allow(clippy::too_many_arguments)]
    fn predicted_force(&self, y: &[f64], v: &[f64], a: &[f64], dt: f64, y1: &mut [f64], w: &mut FullWork, h: &mut [f64]) {
        let half_dt2 = 0.5 * dt * dt;
        let rest = &self.scene.rest;
        let update = |first: usize, y1: &mut [f64], x: &mut [f64]| {
            for (i, (y1, x)) in y1.iter_mut().zip(x).enumerate() {
                let k = first + i;
                *y1 = y[k] + dt * v[k] + half_dt2 * a[k];
                *x = rest[k] + *y1;
            }
        };
        let n = y1.len();
        match &self.pool {
            Some(pool) => pool.install(|| {
                y1.par_chunks_mut(NODE_TASK).zip(w.x[..n].par_chunks_mut(NODE_TASK)).enumerate().for_each(|(t, (y1, x))| update(t * NODE_TASK, y1, x))
            }),
            None => update(0, y1, &mut w.x[..n]),
        }
        self.force_at_slots(w, h);
    }

    /// Without stiffness-proportional damping and not turning, v1 and the
    /// new a in one pass: v1 = (M (v + dt/2 a) + dt/2 h) / (M (1 + dt/2 alpha)),
    /// a1 = (h - alpha M v1) / M, each DOF as the two calls compute it.
    fn explicit_rates(&self, dt: f64, v: &[f64], a: &mut [f64], h: &[f64], w: &mut FullWork, v1: &mut [f64]) -> Result<(), StepFailure> {
        if w.turning || w.beta != 0.0 {
            self.explicit_velocity(dt, v, a, h, w, v1)?;
            self.acceleration(v1, h, w, a);
            return Ok(());
        }
        let (mass, alpha) = (&self.scene.dof_mass, w.alpha);
        let update = |first: usize, v1: &mut [f64], a: &mut [f64]| {
            for (i, (v1, a)) in v1.iter_mut().zip(a).enumerate() {
                let (k, m) = (first + i, mass[first + i]);
                let vk = (m * (v[k] + 0.5 * dt * *a) + 0.5 * dt * h[k]) / (m * (1.0 + 0.5 * dt * alpha));
                *v1 = vk;
                *a = (h[k] - alpha * m * vk) / m;
            }
        };
        match &self.pool {
            Some(pool) => {
                pool.install(|| v1.par_chunks_mut(NODE_TASK).zip(a.par_chunks_mut(NODE_TASK)).enumerate().for_each(|(t, (v1, a))| update(t * NODE_TASK, v1, a)))
            }
            None => update(0, v1, a),
        }
        Ok(())
    }

    /// Turning, (M + dt/2 C + dt M [Omega]x) v1 = the same right side: the
    /// Coriolis force taken with the damping; node by node in closed form
    /// without stiffness-proportional damping, else by fixed-point
    /// iteration on the Coriolis term, which contracts by dt |Omega| per iterate.
    fn explicit_velocity(&self, dt: f64, v: &[f64], a: &[f64], h: &[f64], w: &mut FullWork, v1: &mut [f64]) -> Result<(), StepFailure> {
        let mass = &self.scene.dof_mass;
        for k in 0..v1.len() {
            v1[k] = mass[k] * (v[k] + 0.5 * dt * a[k]) + 0.5 * dt * h[k];
        }
        if w.turning && w.spin != [0.0; 3] {
            return self.coriolis_velocity(dt, w, v1);
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
        if w.turning {
            self.add_coriolis(v, w.spin, -1.0, false, a);
        }
    }

    fn residual(&self, v: &[f64], a: &[f64], h: &[f64], w: &mut FullWork, r: &mut [f64]) {
        self.damping_times(v, w);
        for k in 0..r.len() {
            r[k] = -(self.scene.dof_mass[k] * a[k] + w.cv[k] - h[k]);
        }
        if w.turning {
            self.add_coriolis(v, w.spin, -1.0, true, r);
        }
    }

    /// c_m M + c_c (alpha M + beta K0) + K(x): the tangent of -h is the
    /// stiffness K(x). Turning, the centrifugal force's softening
    /// -m (Omega^2 I - Omega Omega^T) joins it; the Coriolis term's skew part
    /// c_c 2 M [Omega]x is left out of the symmetric factor, so Newton then
    /// converges at a rate of about dt |Omega| per iterate instead of quadratically.
    fn factor(&self, c_m: f64, c_c: f64, w: &mut FullWork) -> Result<(), StepFailure> {
        w.explicit_factor = None;
        let spin = if w.turning { w.spin } else { [0.0; 3] };
        self.factorize_with_spin(c_m + c_c * w.alpha, c_c * w.beta, &spin, w)
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
        vector_unit::clean();
    }

    fn omega_sq_bound(&self, _w: &FullWork) -> f64 {
        self.omega_sq_bound
    }

    /// K0 and C couple the DOFs: no diagonal form.
    fn diagonal<'a>(&'a self, _w: &'a FullWork) -> Option<Diagonal<'a>> {
        None
    }

    /// u' += 1 c on every free node.
    fn add_translation_rate(&self, _w: &FullWork, c: &[f64; 3], v: &mut [f64]) {
        let d = self.scene.dim;
        for (k, vk) in v.iter_mut().enumerate() {
            *vk += c[k % d];
        }
    }
}
