//! The error model of a reduced run with cubature forces (`docs/method.md`,
//! section 10): the model of [`crate::physics::run::error_model`] solved in a
//! few error directions instead of full space, its force and stiffness
//! evaluated on a cubature, so that an estimate costs about as much as a
//! few reduced steps.
//!
//! The error e = x_full − x of the reduced trajectory x = x* + Φ q obeys,
//! linearized, M e'' + K e = r with r = f(x) − M Φ Φᵀ f(x). The model keeps
//! e ≈ Ψ z in k error directions Ψ (M-orthonormal and M-orthogonal to Φ:
//! the principal components of the training program beyond the basis and the
//! rigid translations a holder's kick leaves out of it), where
//!
//! ```text
//! z'' + C z = Ψᵀ r = Ψᵀ f(x),    C = Ψᵀ K Ψ    (Ψᵀ M Φ = 0),
//! ```
//!
//! integrated with the trapezoidal rule over the time since the last
//! estimate, r and C taken at the step's end. Both come from a spring set S
//! with weights w (the cubature of An, Kim and James, trained at set-up on
//! the program's poses for the forces projected on [Φ Ψ]):
//!
//! ```text
//! Ψᵀ f_springs(x) ≈ c + Σ_S w_e G_eᵀ g_e(x_b − x_a),    C ≈ Σ_S w_e G_eᵀ K_e G_e,
//! ```
//!
//! G_e = Ψ_a − Ψ_b (the rows of the spring's ends, zero at a held end), g_e
//! the spring's pull on end a, c = Ψᵀ f_springs(x*) − Σ_S w_e G_eᵀ g_e(x*)
//! (exact at the linearization point), K_e the spring's tangent with the
//! tension's geometric stiffness and without a compressed spring's
//! negative one. Gravity adds Ψᵀ M g (three sums kept from set-up), a point
//! load its node's rows. ‖e‖_M = |z|.
//!
//! One estimate: |S| (D k² + 10 k + 30) operations, the D k² of them in
//! one matrix product, a k x k Cholesky factorization and the slot
//! positions of the state; nothing is allocated. What it leaves
//! out: the error outside Φ and Ψ, the cubature's own error, and what the
//! full-space model leaves out (the error of the coordinates the basis
//! holds, a holder's inertial loads, buckling, full space's step error).
//! The first it cannot estimate, but it can see the force that drives it:
//! [`DirectionModel::seen_sq`] gives the part of the full residual r
//! in the span of M Ψ, hence the part outside it (one pass over every spring), and an adaptive
//! run does not trust the model where that part is large.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::{cholesky_in_place, cholesky_in_place_scratch, LltRegularization};
use faer::linalg::cholesky::llt::solve::solve_in_place_with_conj;
use faer::linalg::matmul::matmul;
use faer::{Accum, Conj, MatMut, MatRef, Par};

use crate::physics::error::PhysicsError;
use crate::physics::run::error_model::{ErrorState, BETA};
use crate::physics::run::forces::pull;
use crate::physics::setup::modes::ModalBasis;
use crate::physics::setup::scene::Scene;
use crate::physics::setup::setup_data::SpringSet;

/// A candidate direction is kept if at least this share of it is left after
/// removing its part in the basis and in the directions before it.
const NEW_SHARE: f64 = 1e-6;

/// The error directions beside `basis` from `candidates` (free DOFs of a
/// scene with masses `mass`): each less its part in the basis and in the
/// directions before it (twice, for round-off), M-normalized, kept if
/// anything is left.
pub fn error_directions(mass: &[f64], basis: &ModalBasis, candidates: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let dot = |u: &[f64], v: &[f64]| -> f64 { mass.iter().zip(u).zip(v).map(|((m, a), b)| m * a * b).sum() };
    let mut kept: Vec<Vec<f64>> = Vec::new();
    let mut q = vec![0.0; basis.r];
    for c in candidates {
        let size = dot(c, c).sqrt();
        if !(size > 0.0) {
            continue;
        }
        let mut u = c.clone();
        for _ in 0..2 {
            basis.project_displacement(mass, &u, &mut q);
            for (i, ui) in u.iter_mut().enumerate() {
                *ui -= basis.phi[i * basis.r..(i + 1) * basis.r].iter().zip(&q).map(|(p, q)| p * q).sum::<f64>();
            }
            for w in &kept {
                let s = dot(w, &u);
                u.iter_mut().zip(w).for_each(|(a, b)| *a -= s * b);
            }
        }
        let left = dot(&u, &u).sqrt();
        if left > NEW_SHARE * size {
            u.iter_mut().for_each(|a| *a /= left);
            kept.push(u);
        }
    }
    kept
}

/// Gravity, and the point force as its first DOF and value.
pub type ExternalLoads<'a> = (&'a [f64; 3], Option<(usize, &'a [f64])>);

/// The constant part of the model and its scratch.
pub struct DirectionModel {
    dim: usize,
    n: usize,
    mass: Vec<f64>,
    /// Ψ, row-major n x k.
    psi: Vec<f64>,
    k: usize,
    /// The spring set: scene index and weight of each spring, and its G_e (D x k each).
    springs: Vec<usize>,
    weights: Vec<f64>,
    gs: Vec<f64>,
    /// The sampled springs' end positions (D values each, a then b).
    ends: Vec<f64>,
    /// c, and Ψᵀ M e_axis for each axis.
    offset: Vec<f64>,
    mass_axis: Vec<f64>,
    /// C (column-major k x k), I + h²/4 C and its factor, Ψᵀ r, the right-hand side.
    c: Vec<f64>,
    factor: Vec<f64>,
    forcing: Vec<f64>,
    rhs: Vec<f64>,
    /// Ψᵀ f of [`Self::seen_sq`].
    seen: Vec<f64>,
    /// G_e of one spring (D x k, at set-up), and W_e = w_e K_e G_e of every spring in the set (laid out as `gs`).
    g: Vec<f64>,
    kg: Vec<f64>,
    /// G_eᵀ d of one spring.
    s: Vec<f64>,
    mem: MemBuffer,
}

impl DirectionModel {
    /// The model in `directions` (see [`error_directions`]) on the spring set
    /// `set`, exact at the slot positions `point` (x*).
    pub fn new(scene: &Scene, directions: &[Vec<f64>], set: &SpringSet, point: &[f64]) -> Self {
        let (d, n, k) = (scene.dim, scene.n_dofs(), directions.len());
        let mut psi = vec![0.0; n * k];
        for (j, w) in directions.iter().enumerate() {
            for (i, x) in w.iter().enumerate() {
                psi[i * k + j] = *x;
            }
        }
        let mut mass_axis = vec![0.0; 3 * k];
        for i in 0..n {
            for j in 0..k {
                mass_axis[(i % d) * k + j] += scene.dof_mass[i] * psi[i * k + j];
            }
        }
        let req = cholesky_in_place_scratch::<f64>(k, Par::Seq, Default::default());
        let mut model = DirectionModel {
            dim: d,
            n,
            mass: scene.dof_mass.clone(),
            psi,
            k,
            springs: set.springs.clone(),
            weights: set.weights.clone(),
            gs: Vec::new(),
            ends: vec![0.0; 2 * d * set.springs.len()],
            offset: vec![0.0; k],
            mass_axis,
            c: vec![0.0; k * k],
            factor: vec![0.0; k * k],
            forcing: vec![0.0; k],
            seen: vec![0.0; k],
            rhs: vec![0.0; k],
            g: vec![0.0; 3 * k],
            s: vec![0.0; k],
            kg: vec![0.0; d * k * set.springs.len()],
            mem: MemBuffer::new(StackReq::any_of(&[req])),
        };
        // c = Ψᵀ f_springs(x*) − Σ_S w G_eᵀ g_e(x*).
        let mut exact = vec![0.0; k];
        for e in 0..scene.springs.len() {
            model.add_spring(scene, point, e, 1.0, &mut exact);
        }
        let mut sampled = vec![0.0; k];
        for (&e, &w) in set.springs.iter().zip(&set.weights) {
            model.add_spring(scene, point, e, w, &mut sampled);
        }
        for ((o, a), b) in model.offset.iter_mut().zip(&exact).zip(&sampled) {
            *o = a - b;
        }
        let mut gs = Vec::with_capacity(set.springs.len() * d * k);
        for &e in &set.springs {
            model.fill_g(scene, e);
            gs.extend_from_slice(&model.g[..d * k]);
        }
        model.gs = gs;
        model
    }

    /// G_e = Ψ_a − Ψ_b of spring `e` into `self.g` (row i for coordinate i; zero at a held end).
    fn fill_g(&mut self, scene: &Scene, e: usize) {
        let (d, k, s) = (self.dim, self.k, &scene.springs[e]);
        let n_free = self.n / d;
        let g = &mut self.g[..d * k];
        g.fill(0.0);
        for (slot, sign) in [(s.a, 1.0), (s.b, -1.0)] {
            if slot < n_free {
                for i in 0..d {
                    for (gj, p) in g[i * k..(i + 1) * k].iter_mut().zip(&self.psi[(slot * d + i) * k..(slot * d + i + 1) * k]) {
                        *gj += sign * p;
                    }
                }
            }
        }
    }

    /// |Ψᵀ f|² of a force `f` on the free DOFs, by faer's n k product
    /// (nothing is allocated). Since Ψ is M-orthonormal, M Ψ Ψᵀ f is f's
    /// M⁻¹-orthogonal projection on the span of M Ψ, of size |Ψᵀ f|.
    pub fn seen_sq(&mut self, f: &[f64]) -> f64 {
        let (n, k) = (self.n, self.k);
        // Ψ row-major n x k is Ψᵀ column-major k x n.
        let psi_t = MatRef::from_column_major_slice(&self.psi, k, n);
        let seen = MatMut::from_column_major_slice_mut(&mut self.seen, k, 1);
        matmul(seen, Accum::Replace, psi_t, MatRef::from_column_major_slice(f, n, 1), 1.0, Par::Seq);
        crate::physics::vector_unit::clean();
        self.seen.iter().map(|z| z * z).sum()
    }

    /// The number of error directions k.
    pub fn directions(&self) -> usize {
        self.k
    }

    /// out += w G_eᵀ g_e(x_b − x_a) for spring `e` at slot positions `x` (set-up).
    fn add_spring(&mut self, scene: &Scene, x: &[f64], e: usize, w: f64, out: &mut [f64]) {
        self.fill_g(scene, e);
        let (d, k, s) = (self.dim, self.k, &scene.springs[e]);
        let dv: Vec<f64> = (0..d).map(|i| x[s.b * d + i] - x[s.a * d + i]).collect();
        let pulled = match d {
            2 => pull::<2>(&[dv[0], dv[1]], s.k, s.rest).to_vec(),
            _ => pull::<3>(&[dv[0], dv[1], dv[2]], s.k, s.rest).to_vec(),
        };
        for i in 0..d {
            for (o, gj) in out.iter_mut().zip(&self.g[i * k..(i + 1) * k]) {
                *o += w * gj * pulled[i];
            }
        }
    }

    /// Ψᵀ f_springs − c and C over the spring set at the end positions in
    /// `self.ends`. Per spring, with d = x_b − x_a, l = |d|, s = G_eᵀ d (k
    /// values) and l₀' = min(l₀, l) (no compressed spring's negative stiffness):
    /// its pull k (1 − l₀/l) d gives G_eᵀ g_e = k (1 − l₀/l) s, and
    /// W_e = w K_e G_e = w k (l₀'/l³ d sᵀ + (1 − l₀'/l) G_e); then
    /// C = Σ_e G_eᵀ W_e as one product of the stacked G and W (faer's matrix
    /// product). About 10 k operations per spring and 2 D k² in the product.
    fn sampled<const D: usize>(&mut self, scene: &Scene, forcing: &mut [f64]) {
        let k = self.k;
        if k == 0 {
            return;
        }
        let s = &mut self.s[..k];
        for ((((&e, &w), g), ends), kg) in
            self.springs.iter().zip(&self.weights).zip(self.gs.chunks_exact(D * k)).zip(self.ends.chunks_exact(2 * D)).zip(self.kg.chunks_exact_mut(D * k))
        {
            let spring = &scene.springs[e];
            let d: [f64; D] = std::array::from_fn(|i| ends[D + i] - ends[i]);
            let l = d.iter().map(|c| c * c).sum::<f64>().sqrt();
            if !(l > 0.0) {
                // A spring of zero length pulls nowhere and has no direction: no part in either.
                kg.fill(0.0);
                continue;
            }
            let inv = 1.0 / l;
            s.fill(0.0);
            for (i, di) in d.iter().enumerate() {
                for (sj, gj) in s.iter_mut().zip(&g[i * k..(i + 1) * k]) {
                    *sj += di * gj;
                }
            }
            let pulled = w * spring.k * (1.0 - spring.rest * inv);
            for (o, sj) in forcing.iter_mut().zip(s.iter()) {
                *o += pulled * sj;
            }
            let axis = spring.rest.min(l) * inv;
            let (a, b) = (w * spring.k * axis * inv * inv, w * spring.k * (1.0 - axis));
            for (i, di) in d.iter().enumerate() {
                let ad = a * di;
                for ((x, gj), sj) in kg[i * k..(i + 1) * k].iter_mut().zip(&g[i * k..(i + 1) * k]).zip(s.iter()) {
                    *x = ad * sj + b * gj;
                }
            }
        }
        // The stacked G and W, row-major (|S| D) x k, are column-major k x (|S| D).
        let cols = self.springs.len() * D;
        let g = MatRef::from_column_major_slice(&self.gs, k, cols);
        let w = MatRef::from_column_major_slice(&self.kg, k, cols);
        matmul(MatMut::from_column_major_slice_mut(&mut self.c, k, k), Accum::Replace, g, w.transpose(), 1.0, Par::Seq);
        crate::physics::vector_unit::clean();
    }

    /// The sampled springs' ends at slot positions `x`.
    pub fn ends_at(&mut self, scene: &Scene, x: &[f64]) {
        let d = self.dim;
        for (&e, ends) in self.springs.iter().zip(self.ends.chunks_exact_mut(2 * d)) {
            let s = &scene.springs[e];
            ends[..d].copy_from_slice(&x[s.a * d..(s.a + 1) * d]);
            ends[d..].copy_from_slice(&x[s.b * d..(s.b + 1) * d]);
        }
    }

    /// The sampled springs' ends at x = x* + Φ q (a free end, `basis` and
    /// `point` the slot positions x*) or where `slots` has them (a held end),
    /// without expanding x: |S| 2 D r operations.
    pub fn ends_modal(&mut self, scene: &Scene, basis: &ModalBasis, point: &[f64], q: &[f64], slots: &[f64]) {
        let (d, r) = (self.dim, basis.r);
        let n_free = self.n / d;
        for (&e, ends) in self.springs.iter().zip(self.ends.chunks_exact_mut(2 * d)) {
            let s = &scene.springs[e];
            for (end, slot) in [(0, s.a), (1, s.b)] {
                for i in 0..d {
                    let dof = slot * d + i;
                    ends[end * d + i] =
                        if slot < n_free { point[dof] + basis.phi[dof * r..(dof + 1) * r].iter().zip(q).map(|(p, q)| p * q).sum::<f64>() } else { slots[dof] };
                }
            }
        }
    }

    /// C and Ψᵀ r at the ends of the last [`Self::ends_at`] or
    /// [`Self::ends_modal`] under `gravity` and the point force `point` (its
    /// first DOF and value), or C alone (r = 0: the run is in full space,
    /// which adds no error).
    pub fn linearize(&mut self, scene: &Scene, loads: Option<ExternalLoads>) {
        let k = self.k;
        self.c.fill(0.0);
        let mut forcing = std::mem::take(&mut self.forcing);
        forcing.fill(0.0);
        match self.dim {
            2 => self.sampled::<2>(scene, &mut forcing),
            _ => self.sampled::<3>(scene, &mut forcing),
        }
        for b in 0..k {
            for a in 0..b {
                let mean = 0.5 * (self.c[a * k + b] + self.c[b * k + a]);
                self.c[a * k + b] = mean;
                self.c[b * k + a] = mean;
            }
        }
        match loads {
            None => forcing.fill(0.0),
            Some((gravity, point)) => {
                for (j, f) in forcing.iter_mut().enumerate() {
                    *f += self.offset[j] + (0..self.dim).map(|a| gravity[a] * self.mass_axis[a * k + j]).sum::<f64>();
                }
                if let Some((dof, p)) = point {
                    for (i, pi) in p.iter().enumerate() {
                        for (f, psi) in forcing.iter_mut().zip(&self.psi[(dof + i) * k..(dof + i + 1) * k]) {
                            *f += psi * pi;
                        }
                    }
                }
            }
        }
        self.forcing = forcing;
    }

    /// Advances `s` by `h` under the forcing and C of the last [`Self::linearize`]:
    /// a = (I + h²/4 C)⁻¹ (Ψᵀ r − C (z + h z' + h²/4 z'')),
    /// z += h z' + h²/4 (z'' + a), z' += h/2 (z'' + a), z'' = a.
    pub fn advance(&mut self, s: &mut ErrorState, h: f64) -> Result<(), PhysicsError> {
        let k = self.k;
        if k == 0 {
            return Ok(());
        }
        let cc = BETA * h * h;
        s.predict(h);
        for i in 0..k {
            self.rhs[i] = self.forcing[i] - (0..k).map(|j| self.c[j * k + i] * s.e[j]).sum::<f64>();
        }
        for (f, c) in self.factor.iter_mut().zip(&self.c) {
            *f = cc * c;
        }
        for j in 0..k {
            self.factor[j * k + j] += 1.0;
        }
        let stack = MemStack::new(&mut self.mem);
        cholesky_in_place(MatMut::from_column_major_slice_mut(&mut self.factor, k, k), LltRegularization::default(), Par::Seq, stack, Default::default())
            .map_err(|e| PhysicsError::LinearAlgebra { what: "Cholesky factorization of the error model", detail: format!("{e:?}") })?;
        let stack = MemStack::new(&mut self.mem);
        solve_in_place_with_conj(
            MatRef::from_column_major_slice(&self.factor, k, k),
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut self.rhs, k, 1),
            Par::Seq,
            stack,
        );
        s.correct(h, &self.rhs);
        Ok(())
    }

    /// z += Ψᵀ M u, z' += Ψᵀ M w for a displacement error `u` and a velocity error `w` (free DOFs).
    pub fn add(&self, s: &mut ErrorState, u: &[f64], w: &[f64]) {
        let k = self.k;
        for (i, row) in self.psi.chunks_exact(k.max(1)).enumerate().take(self.n) {
            let (mu, mw) = (self.mass[i] * u[i], self.mass[i] * w[i]);
            for j in 0..k {
                s.e[j] += row[j] * mu;
                s.v[j] += row[j] * mw;
            }
        }
    }

    /// z' += Ψᵀ M kick for the same velocity `kick` on every free node. O(k).
    pub fn add_uniform_velocity(&self, s: &mut ErrorState, kick: &[f64; 3]) {
        for j in 0..self.k {
            s.v[j] += (0..self.dim).map(|a| kick[a] * self.mass_axis[a * self.k + j]).sum::<f64>();
        }
    }

    /// Ψ z and Ψ z' over the free DOFs into `e` and `v` (n each).
    pub fn error_into(&self, s: &ErrorState, e: &mut [f64], v: &mut [f64]) {
        if self.k == 0 {
            e.fill(0.0);
            v.fill(0.0);
            return;
        }
        for ((row, e), v) in self.psi.chunks_exact(self.k).zip(e.iter_mut()).zip(v.iter_mut()) {
            *e = row.iter().zip(&s.e).map(|(p, x)| p * x).sum();
            *v = row.iter().zip(&s.v).map(|(p, x)| p * x).sum();
        }
    }
}
