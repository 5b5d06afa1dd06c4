//! The modal space: the paper's method (`docs/method.md`, section 3).
//!
//! y = q, the coordinates of the r kept modes, with x = x* + Phi q. The
//! projected spring force Phi^T f(x* + Phi q) and its tangent come from a
//! [`ReducedForce`]: [`Exact`] is the paper's pipeline `expand` (q -> x over
//! the free DOFs) -> exact spring forces in physical space -> `project`
//! (Phi^T f). With weights w_i and F = Phi^T (f_springs + M g) the mode
//! equations are
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
use faer::{Conj, Mat, MatMut, Par};

mod cubature;
mod exact;
mod inertia;
mod reduced;
mod residual;
mod work;

pub use cubature::{Candidate, Cubature};
pub use exact::Exact;
pub use inertia::Inertia;
pub use reduced::{taut_reduced_bound, ForceSetup, Modes, ReducedForce};
pub use work::ModalWork;

use super::equations::{Constants, Diagonal, Layout, Readout, Space};
use crate::physics::error::{PhysicsError, StepFailure};
use crate::physics::run::frame::{dot, Frame, Moments};
use crate::physics::run::state::Loads;
use crate::physics::run::stiffness::omega_sq_bound_full;
use crate::physics::settings::Settings;
use crate::physics::setup::basis;
use crate::physics::setup::modes::ModalBasis;
use crate::physics::setup::scene::Scene;
use crate::physics::setup::setup_data::{SetupData, TrainedRange};
use crate::physics::vector_unit;

/// Above this many modes the explicit limit uses the full-space bound
/// instead of the eigenvalues of the reduced taut stiffness.
const DENSE_BOUND_MODES: usize = 64;

/// The constant model of the modal equations, with force model `F`.
pub struct Modal<F: ReducedForce = Exact> {
    scene: Scene,
    modes: Modes,
    force: F,
    frequencies: Vec<f64>,
    /// Squared-frequency bound of the reduced system with unit weights.
    omega_sq_bound: f64,
    /// The same with every spring (before the force model's own bound).
    bound: f64,
    /// The modal coordinate of a one-length-scale displacement of the whole mass.
    newton_scale: f64,
    /// 1 / m_k per free DOF.
    inv_mass: Vec<f64>,
    /// The mass moments of the free nodes as polynomials in q.
    inertia: Inertia,
    /// sum m_k (x*_k - x_rest,k) per axis, for the potential of turned gravity.
    sag: [f64; 3],
    /// The range a trained basis was trained for.
    range: Option<TrainedRange>,
}

impl<F: ReducedForce> Modal<F> {
    /// Builds the basis of `settings.n_modes` vectors `settings` ask for
    /// (under the set-up `loads`) and sets up the force model.
    /// The basis, its point and the bound come from `prebuilt` when given
    /// (checked to fit), else they are computed.
    pub fn new(scene: Scene, loads: &Loads, settings: &Settings, prebuilt: Option<&SetupData>) -> Result<Self, PhysicsError> {
        let n_modes = settings.n_modes;
        let (modes, bound) = match prebuilt {
            Some(data) => {
                check_prebuilt(&scene, n_modes, data)?;
                (Modes::new(data.basis.clone(), data.point.clone(), data.at_rest), data.omega_sq_bound)
            }
            None => {
                let built = basis::build(&scene, loads, n_modes, settings)?;
                let bound = basis_bound(&scene, &built.modes)?;
                (Modes::new(built.modes, built.point, built.at_rest), bound)
            }
        };
        let newton_scale = scene.free_mass().sqrt() * scene.length_scale().max(f64::MIN_POSITIVE);
        let frequencies = modes.basis.frequencies();
        let setup = ForceSetup { loads, settings, omega_sq_bound: bound, prebuilt: prebuilt.and_then(|d| d.cubature.as_ref()) };
        let force = F::new(&scene, &modes, &setup)?;
        let omega_sq_bound = force.taut_bound(&scene, &modes).map_or(bound, |b| b.max(bound));
        let inv_mass = scene.dof_mass.iter().map(|m| 1.0 / m).collect();
        let inertia = Inertia::new(&scene, &modes);
        let d = scene.dim;
        let mut sag = [0.0; 3];
        for k in 0..modes.basis.n {
            sag[k % d] += scene.dof_mass[k] * (modes.point[k] - scene.rest[k]);
        }
        let range = prebuilt.and_then(|d| d.range.clone());
        Ok(Modal { force, frequencies, omega_sq_bound, bound, newton_scale, inv_mass, inertia, sag, range, modes, scene })
    }

    /// The kept modes.
    pub fn basis(&self) -> &ModalBasis {
        &self.modes.basis
    }

    /// The kept modes in both layouts, and the point they are measured from.
    pub fn modes(&self) -> &Modes {
        &self.modes
    }
}

impl<F: ReducedForce> Constants for Modal<F> {
    fn scene(&self) -> &Scene {
        &self.scene
    }

    fn layout(&self) -> Layout<'_> {
        Layout {
            scene: &self.scene,
            coordinates: self.modes.basis.r,
            kept_modes: Some(self.modes.basis.r),
            springs: self.force.springs(&self.scene),
            frequencies: &self.frequencies,
            newton_scale: self.newton_scale,
            trained: self.range.as_ref(),
        }
    }

    fn setup_data(&self) -> Option<SetupData> {
        Some(SetupData {
            basis: self.modes.basis.clone(),
            point: self.modes.point.clone(),
            at_rest: self.modes.at_rest,
            omega_sq_bound: self.bound,
            cubature: self.force.spring_set(),
            range: self.range.clone(),
            adaptive: None,
        })
    }

    fn modes(&self) -> Option<&ModalBasis> {
        Some(&self.modes.basis)
    }

    /// q = Phi^T M (x_rest - x*): the rest positions as the basis sees them
    /// (exact when they lie in its span, as with a static correction).
    fn rest_coordinates(&self, q: &mut [f64]) {
        q.fill(0.0);
        if self.modes.at_rest {
            return;
        }
        let n = self.modes.basis.n;
        let u: Vec<f64> = (0..n).map(|k| self.scene.rest[k] - self.modes.point[k]).collect();
        self.modes.basis.project_displacement(&self.scene.dof_mass, &u, q);
    }
}

impl<F: ReducedForce> Space for Modal<F> {
    type Work = ModalWork<F::Work>;

    fn work(&self, loads: &Loads) -> ModalWork<F::Work> {
        let r = self.modes.basis.r;
        let req =
            StackReq::any_of(&[lu_in_place_scratch::<usize, f64>(r, r, Par::Seq, Default::default()), solve_in_place_scratch::<usize, f64>(r, 1, Par::Seq)]);
        ModalWork {
            damping: vec![0.0; r],
            loads: loads.clone(),
            gravity: vec![0.0; r],
            weighted_load: vec![0.0; r],
            gravity_offset: 0.0,
            force: self.force.work(&self.scene, &self.modes),
            kr: vec![0.0; r * r],
            generalized: vec![0.0; r],
            generalized_scratch: vec![0.0; r],
            load_scale: 0.0,
            jac: Mat::zeros(r, r),
            perm: vec![0; r],
            perm_inv: vec![0; r],
            mem: MemBuffer::new(req),
            turning: false,
            spin: [0.0; 3],
            centrifugal: vec![0.0; r],
            spin_stiffness: vec![0.0; r * r],
            coriolis: vec![0.0; r * r],
            velocity: Mat::zeros(r, r),
            velocity_perm: vec![0; r],
            velocity_perm_inv: vec![0; r],
            velocity_dt: f64::NAN,
        }
    }

    fn apply_loads(&self, w: &mut Self::Work) {
        let (n, r, d) = (self.modes.basis.n, self.modes.basis.r, self.scene.dim);
        let loads = &w.loads;
        for j in 0..r {
            w.damping[j] = loads.damping_alpha + loads.damping_beta * self.modes.basis.lambda[j];
        }
        w.gravity.fill(0.0);
        w.gravity_offset = 0.0;
        w.load_scale = 0.0;
        for k in 0..n {
            let fk = self.scene.dof_mass[k] * loads.gravity[k % d];
            w.load_scale += fk * loads.gravity[k % d];
            for j in 0..r {
                w.gravity[j] += self.modes.basis.phi[k * r + j] * fk;
            }
            w.gravity_offset -= fk * (self.modes.point[k] - self.scene.rest[k]);
        }
        // The point load joins M g: Phi^T f_p, its potential and its share of the load scale
        // (`docs/method.md`, section 8). Skipped when zero, so runs without it are unchanged.
        if let Some((dof, f)) = loads.point_force(&self.scene) {
            for (i, &fi) in f.iter().enumerate() {
                let k = dof + i;
                for j in 0..r {
                    w.gravity[j] += self.modes.basis.phi[k * r + j] * fi;
                }
                w.gravity_offset -= fi * (self.modes.point[k] - self.scene.rest[k]);
                let mg = self.scene.dof_mass[k] * loads.gravity[k % d];
                w.load_scale += ((mg + fi) * (mg + fi) - mg * mg) * self.inv_mass[k];
            }
        }
        for ((l, g), wj) in w.weighted_load.iter_mut().zip(&w.gravity).zip(&loads.mode_weights) {
            *l = wj * g;
        }
        w.turning = false;
        w.velocity_dt = f64::NAN;
    }

    /// Phi^T (M R^T g + R^T f_p) = sum_i T_i (R^T g)_i + Phi_p^T R^T f_p, O(r), and
    /// the spin's terms when it changed, O(r^2) (`docs/method.md`, section 8).
    fn turn(&self, frame: &Frame, w: &mut Self::Work) {
        let (n, r, d) = (self.modes.basis.n, self.modes.basis.r, self.scene.dim);
        let point = w.loads.point_force(&self.scene).map(|(dof, _)| dof);
        for j in 0..r {
            let t = self.inertia.translation(j);
            w.gravity[j] = t[0] * frame.gravity[0] + t[1] * frame.gravity[1] + t[2] * frame.gravity[2];
            if let Some(dof) = point {
                for i in 0..d {
                    w.gravity[j] += self.modes.basis.phi[(dof + i) * r + j] * frame.load[i];
                }
            }
            w.weighted_load[j] = w.loads.mode_weights[j] * w.gravity[j];
        }
        w.gravity_offset = -dot(&frame.gravity, &self.sag)
            - point.map_or(0.0, |dof| (0..d).map(|i| frame.load[i] * (self.modes.point[dof + i] - self.scene.rest[dof + i])).sum());
        let _ = n;
        if !w.turning || w.spin != frame.spin {
            self.inertia.spin_terms(&frame.spin, &mut w.centrifugal, &mut w.spin_stiffness, &mut w.coriolis);
            w.spin = frame.spin;
            w.velocity_dt = f64::NAN;
        }
        w.turning = true;
    }

    fn slots_mut<'w>(&self, w: &'w mut Self::Work) -> &'w mut [f64] {
        self.force.slots_mut(&mut w.force)
    }

    fn force(&self, q: &[f64], w: &mut Self::Work, h: &mut [f64]) {
        // F = Phi^T (f + M g)
        self.force.project(&self.scene, &self.modes, q, &mut w.force, h);
        for (hj, gj) in h.iter_mut().zip(&w.gravity) {
            *hj += gj;
        }
        if w.turning {
            // The centrifugal force of the holder's spin, c0 + Kc q.
            let r = q.len();
            for (j, hj) in h.iter_mut().enumerate() {
                *hj += w.centrifugal[j] + dot_slices(&w.spin_stiffness[j * r..(j + 1) * r], q);
            }
        }
        w.generalized.copy_from_slice(h);
        // weights act on everything but the mode's own linear spring
        for (j, hj) in h.iter_mut().enumerate() {
            let wj = w.loads.mode_weights[j];
            *hj = wj * *hj + (wj - 1.0) * self.modes.basis.lambda[j] * q[j];
        }
    }

    /// Turning, (I + dt/2 (diag c + W Gamma)) v1 = v + dt/2 (a + h): the
    /// Coriolis force taken with the damping, by an LU factored once per
    /// step size and spin.
    fn explicit_velocity(&self, dt: f64, v: &[f64], a: &[f64], h: &[f64], w: &mut Self::Work, v1: &mut [f64]) -> Result<(), StepFailure> {
        let r = self.modes.basis.r;
        if !w.turning {
            for j in 0..r {
                v1[j] = (v[j] + 0.5 * dt * (a[j] + h[j])) / (1.0 + 0.5 * dt * w.damping[j]);
            }
            return Ok(());
        }
        if w.velocity_dt != dt {
            for j in 0..r {
                for i in 0..r {
                    w.velocity[(j, i)] = 0.5 * dt * w.loads.mode_weights[j] * w.coriolis[j * r + i];
                }
                w.velocity[(j, j)] += 1.0 + 0.5 * dt * w.damping[j];
            }
            let stack = MemStack::new(&mut w.mem);
            lu_in_place(w.velocity.as_mut(), &mut w.velocity_perm, &mut w.velocity_perm_inv, Par::Seq, stack, Default::default());
            vector_unit::clean();
            w.velocity_dt = dt;
        }
        for j in 0..r {
            v1[j] = v[j] + 0.5 * dt * (a[j] + h[j]);
        }
        let perm = PermRef::new_checked(&w.velocity_perm, &w.velocity_perm_inv, r);
        let lu = w.velocity.as_ref();
        let stack = MemStack::new(&mut w.mem);
        solve_in_place_with_conj(lu, lu, perm, Conj::No, MatMut::from_column_major_slice_mut(v1, r, 1), Par::Seq, stack);
        vector_unit::clean();
        Ok(())
    }

    fn acceleration(&self, v: &[f64], h: &[f64], w: &mut Self::Work, a: &mut [f64]) {
        let r = self.modes.basis.r;
        for j in 0..r {
            a[j] = h[j] - w.damping[j] * v[j];
            if w.turning {
                a[j] -= w.loads.mode_weights[j] * dot_slices(&w.coriolis[j * r..(j + 1) * r], v);
            }
        }
    }

    fn residual(&self, v: &[f64], a: &[f64], h: &[f64], w: &mut Self::Work, res: &mut [f64]) {
        let r = self.modes.basis.r;
        for j in 0..r {
            res[j] = -(a[j] + w.damping[j] * v[j] - h[j]);
            if w.turning {
                res[j] -= w.loads.mode_weights[j] * dot_slices(&w.coriolis[j * r..(j + 1) * r], v);
            }
        }
    }

    /// J = c_m I + c_c diag(c) + W Phi^T K(x) Phi - diag((w - 1) lambda), LU with partial pivoting.
    fn factor(&self, c_m: f64, c_c: f64, w: &mut Self::Work) -> Result<(), StepFailure> {
        let r = self.modes.basis.r;
        let weights = &w.loads.mode_weights;
        w.kr.fill(0.0);
        self.force.add_tangent(&self.scene, &self.modes, &mut w.force, &mut w.kr);
        for col in 0..r {
            for row in 0..r {
                w.jac[(row, col)] = weights[row] * w.kr[col * r + row];
                if w.turning {
                    // The Coriolis force with the damping, the centrifugal force's softening with the stiffness.
                    w.jac[(row, col)] += weights[row] * (c_c * w.coriolis[row * r + col] - w.spin_stiffness[row * r + col]);
                }
            }
            w.jac[(col, col)] += c_m + c_c * w.damping[col] - (weights[col] - 1.0) * self.modes.basis.lambda[col];
        }
        let stack = MemStack::new(&mut w.mem);
        lu_in_place(w.jac.as_mut(), &mut w.perm, &mut w.perm_inv, Par::Seq, stack, Default::default());
        Ok(())
    }

    fn solve(&self, w: &mut Self::Work, rhs: &mut [f64]) {
        let r = self.modes.basis.r;
        let row_perm = PermRef::new_checked(&w.perm, &w.perm_inv, r);
        let jac = w.jac.as_ref();
        let stack = MemStack::new(&mut w.mem);
        solve_in_place_with_conj(jac, jac, row_perm, Conj::No, MatMut::from_column_major_slice_mut(rhs, r, 1), Par::Seq, stack);
    }

    /// Weights above 1 scale the stiffness each mode sees beyond its own.
    fn omega_sq_bound(&self, w: &Self::Work) -> f64 {
        w.loads.weight_max() * self.omega_sq_bound
    }

    /// Phi^T K0 Phi = diag(lambda), Phi^T C Phi = diag(alpha + beta lambda),
    /// and the weighted generalized load w_i (Phi^T (M g + f_p))_i.
    fn diagonal<'a>(&'a self, w: &'a Self::Work) -> Option<Diagonal<'a>> {
        Some(Diagonal { stiffness: &self.modes.basis.lambda, damping: &w.damping, load: &w.weighted_load })
    }

    /// q' += w_j Phi^T M (c x rho): a rigid rotation about the pivot, projected and weighted like every load.
    fn add_rotation_rate(&self, w: &Self::Work, c: &[f64; 3], q: &[f64], v: &mut [f64]) {
        for (j, vj) in v.iter_mut().enumerate() {
            *vj += w.loads.mode_weights[j] * self.inertia.rotation_rate(j, c, q);
        }
    }

    /// q' += w_i Phi^T M (1 c): a rigid velocity c of the free nodes,
    /// projected and weighted like every load.
    fn add_translation_rate(&self, w: &Self::Work, c: &[f64; 3], v: &mut [f64]) {
        for (j, vj) in v.iter_mut().enumerate() {
            let t = self.inertia.translation(j);
            *vj += w.loads.mode_weights[j] * (t[0] * c[0] + t[1] * c[1] + t[2] * c[2]);
        }
    }
}

impl<F: ReducedForce> Readout for Modal<F> {
    fn spring_force(&self, q: &[f64], w: &mut Self::Work, out: &mut [f64]) {
        self.force.project(&self.scene, &self.modes, q, &mut w.force, out);
    }

    fn positions<'w>(&self, q: &[f64], w: &'w mut Self::Work) -> &'w [f64] {
        self.force.positions(&self.scene, &self.modes, q, &mut w.force)
    }

    fn elastic_energy(&self, q: &[f64], w: &mut Self::Work) -> f64 {
        self.force.elastic_energy(&self.scene, &self.modes, q, &mut w.force)
    }

    fn model_energy(&self, q: &[f64], w: &mut Self::Work) -> f64 {
        self.force.model_energy(&self.scene, &self.modes, q, &mut w.force) + self.gravity_potential(q, w)
    }

    /// -(M g + f_p)^T (x - x_rest) = -(M g + f_p)^T (x* - x_rest) - (Phi^T (M g + f_p))^T q.
    fn gravity_potential(&self, q: &[f64], w: &Self::Work) -> f64 {
        let modal = -w.gravity.iter().zip(q).map(|(g, q)| g * q).sum::<f64>();
        if self.modes.at_rest {
            modal
        } else {
            w.gravity_offset + modal
        }
    }

    /// The part of the physical force at q that the basis cannot hold,
    /// relative to the load: with f = f_springs(x) + M g and F = Phi^T f,
    /// r = f - M Phi F, and ||r|| / ||M g|| in the M^-1 norm (the spring
    /// forces' norm where gravity is zero). Since Phi^T M Phi = I, r is
    /// M^-1-orthogonal to M Phi F and ||r||^2 = ||f||^2 - |F|^2: one pass over
    /// the free DOFs, with F kept from the last force evaluation.
    fn force_residual(&self, gravity: &[f64; 3], point: &[f64; 3], q: &[f64], w: &mut Self::Work) -> f64 {
        let d = self.scene.dim;
        let (mass, inv_mass) = (&self.scene.dof_mass, &self.inv_mass);
        let springs = self.force.spring_forces(&self.scene, &self.modes, q, &mut w.force);
        let (mut total, mut spring) = (0.0, 0.0);
        for (k, fk) in springs.iter().enumerate() {
            let t = fk + mass[k] * gravity[k % d];
            total += t * t * inv_mass[k];
            spring += fk * fk * inv_mass[k];
        }
        if let Some((dof, f)) = w.loads.point_force_as(point, &self.scene) {
            // The point load is part of the physical force on its node.
            for (i, &fi) in f.iter().enumerate() {
                let k = dof + i;
                let t = springs[k] + mass[k] * gravity[k % d];
                total += ((t + fi) * (t + fi) - t * t) * inv_mass[k];
            }
        }
        let held: f64 = w.generalized.iter().map(|f| f * f).sum();
        let scale = if w.load_scale > 0.0 { w.load_scale } else { spring };
        if scale > 0.0 {
            ((total - held).max(0.0) / scale).sqrt()
        } else {
            0.0
        }
    }

    /// 1/2 |q'|^2, since Phi^T M Phi = I.
    fn kinetic_energy(&self, v: &[f64]) -> f64 {
        0.5 * v.iter().map(|v| v * v).sum::<f64>()
    }

    /// x* + Phi q at one slot, summed mode by mode as [`Modes::expand`] does
    /// (the same bits), without expanding the others; held slots stay at x*.
    fn slot_position(&self, q: &[f64], slot: usize, w: &mut Self::Work) -> [f64; 3] {
        let (n, d) = (self.modes.basis.n, self.scene.dim);
        if slot * d >= n {
            // A held slot: where its holder put it.
            let x = self.force.slots_mut(&mut w.force);
            return std::array::from_fn(|i| if i < d { x[slot * d + i] } else { 0.0 });
        }
        let mut x = [0.0; 3];
        for i in 0..d {
            let k = slot * d + i;
            x[i] = self.modes.point[k];
            if k < n {
                for (col, qj) in self.modes.cols.chunks_exact(n).zip(q) {
                    x[i] += col[k] * qj;
                }
            }
        }
        x
    }

    /// Phi q' at one free slot, summed as [`Modes::expand_rates`] does.
    fn slot_velocity(&self, v: &[f64], slot: usize) -> [f64; 3] {
        let (n, d) = (self.modes.basis.n, self.scene.dim);
        let mut out = [0.0; 3];
        for (i, o) in out.iter_mut().enumerate().take(d) {
            let k = slot * d + i;
            for (col, vj) in self.modes.cols.chunks_exact(n).zip(v) {
                *o += col[k] * vj;
            }
        }
        out
    }

    /// sum_k m_k e_k (Phi q')_k = sum_j (Phi^T M e)_j q'_j per axis.
    fn momentum(&self, v: &[f64]) -> [f64; 3] {
        self.inertia.momentum(v)
    }

    fn first_moment(&self, q: &[f64]) -> [f64; 3] {
        self.inertia.first_moment(q)
    }

    fn moments(&self, q: &[f64], v: &[f64]) -> Moments {
        self.inertia.moments(q, v)
    }

    /// Phi q'.
    fn dof_velocities(&self, v: &[f64], out: &mut [f64]) {
        self.modes.expand_rates(v, out);
    }

    fn modal_coordinates(&self, q: &[f64], out: &mut [f64]) {
        out.copy_from_slice(q);
    }
}
/// Stored set-up data fits `scene` and `n_modes`: sizes, finite values, unit-mass modes are not re-checked
/// (the data is what a set-up of the same parameters wrote).
/// Squared-frequency bound of the reduced system on `basis` with every
/// spring: the eigenvalues of the reduced taut stiffness up to
/// [`DENSE_BOUND_MODES`] modes, the full-space bound above.
pub fn basis_bound(scene: &Scene, basis: &ModalBasis) -> Result<f64, PhysicsError> {
    if basis.r <= DENSE_BOUND_MODES {
        taut_reduced_bound(scene, basis)
    } else {
        Ok(omega_sq_bound_full(scene))
    }
}

fn check_prebuilt(scene: &Scene, n_modes: usize, data: &SetupData) -> Result<(), PhysicsError> {
    let b = &data.basis;
    let fail = |what| Err(PhysicsError::SetupDataMismatch { what });
    if b.n != scene.n_dofs() || b.r != n_modes || b.phi.len() != b.n * b.r || b.lambda.len() != b.r {
        return fail("basis size");
    }
    if data.point.len() != scene.rest.len() {
        return fail("linearization point size");
    }
    if !b.phi.iter().chain(&b.lambda).chain(&data.point).all(|x| x.is_finite()) || !(data.omega_sq_bound >= 0.0 && data.omega_sq_bound.is_finite()) {
        return fail("non-finite values");
    }
    // x* is the rest state, or an equilibrium that moves only free DOFs (the
    // first n coordinates): a fixed node elsewhere would pull the sheet
    // from where it hangs. Its springs' energy must be a number.
    if (data.at_rest && data.point != scene.rest)
        || data.point[b.n..] != scene.rest[b.n..]
        || !crate::physics::run::forces::elastic_energy(scene, &data.point).is_finite()
    {
        return fail("linearization point");
    }
    // Every basis vector is mass-normalized, phi_j^T M phi_j = 1 (each set-up
    // orthonormalizes to round-off, 1e-10); n r operations.
    let norm_error = |j: usize| ((0..b.n).map(|k| scene.dof_mass[k] * b.phi[k * b.r + j] * b.phi[k * b.r + j]).sum::<f64>() - 1.0).abs();
    if (0..b.r).map(norm_error).any(|e| e.is_nan() || e > 1e-6) {
        return fail("basis not mass-normalized");
    }
    if data.range.as_ref().is_some_and(|t| t.center.len() != b.r || t.half_width.len() != b.r) {
        return fail("trained range size");
    }
    if let Some(c) = &data.cubature {
        if c.springs.len() != c.weights.len() || c.springs.iter().any(|&s| s >= scene.springs.len()) || !c.weights.iter().all(|w| w.is_finite() && *w > 0.0) {
            return fail("cubature set");
        }
    }
    Ok(())
}

/// sum a_i b_i.
#[inline]
fn dot_slices(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
