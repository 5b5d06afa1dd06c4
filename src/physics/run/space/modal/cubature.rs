//! Optimized cubature of the projected spring force (`docs/method.md`,
//! section 4): a few springs with non-negative weights stand for all of them
//! (An, Kim and James 2008).
//!
//! The projected spring force is a sum over the springs,
//!
//! ```text
//!     F(q) = Phi^T f(x* + Phi q) = sum_e p_e(q),    p_e(q) = G_e^T g_e(d0_e - G_e q),
//! ```
//!
//! with G_e = Phi_a - Phi_b (the D x r rows of its two ends, zero at a held
//! end), d0_e = x*_b - x*_a and g_e(d) = k (l - l0) / l d the spring's force
//! on end a. Cubature keeps F0 = F(0) exact and replaces the sum of the
//! changes by a weighted sum over a small set S, w_e >= 0:
//!
//! ```text
//!     F~(q) = F0 + sum_{e in S} w_e (p_e(q) - p_e(0)) = c + sum_{e in S} w_e p_e(q),    c = F0 - sum_S w_e p_e(0).
//! ```
//!
//! Every term is the gradient of an energy (each kept spring's, weighted),
//! so F~ is conservative like F and the linearization point stays an
//! equilibrium of the reduced model; a step visits only the springs of S,
//! and x is never expanded beyond their ends. The tangent is
//! sum_S w_e G_e^T K_e(x) G_e, positive wherever the kept springs are taut.
//!
//! The set and its weights are trained at set-up by [`crate::physics::setup::cubature_training`]
//! (on poses of a short exact reduced run) or taken from a bake.
//!
//! Holders that move on their own (`docs/method.md`, section 9) move the
//! held end of the springs that end on their nodes, by δ from x*: those
//! springs' change is added exactly, whatever the set,
//!
//! ```text
//!     F~(q) += sum_{e at a moving holder} G_e^T (g_e(d0_e - G_e q ± δ_e) - g_e(d0_e - G_e q)),
//! ```
//!
//! (+ where the held end is b, − where it is a), with its tangent and energy;
//! nothing changes while every holder is in its place.

use super::reduced::{ForceSetup, Modes, ReducedForce};
use crate::physics::error::PhysicsError;
use crate::physics::run::forces::{pull, SpringForces, SpringScratch};
use crate::physics::run::stiffness::{add_projected_block, block};
use crate::physics::setup::scene::Scene;
use crate::physics::setup::setup_data::SpringSet;

/// A weighted subset of the springs, with the exact force at the linearization point.
pub struct Cubature {
    /// Scene index of each kept spring.
    ids: Vec<usize>,
    /// Per kept spring, G = Phi_a - Phi_b, D x r row-major.
    g: Vec<f64>,
    /// Per kept spring, d0 = x*_b - x*_a (D values).
    d0: Vec<f64>,
    /// Per kept spring: weight, weight times stiffness, rest length.
    weights: Vec<f64>,
    wk: Vec<f64>,
    l0: Vec<f64>,
    /// c = F0 - sum w p_e(0).
    offset: Vec<f64>,
    /// U(0) - sum w U_e(0): the model's energy equals every spring's at q = 0.
    energy_offset: f64,
    /// Every spring, for the outputs at communication points.
    exact: SpringForces,
    /// The springs with one free end and one on a holder that moves on its own.
    held: Vec<HeldSpring>,
    /// Relative error of F - F0 on the training poses and on the held-out ones.
    pub training_error: f64,
    pub held_out_error: f64,
}

/// A spring from a free slot to a slot of a holder that moves on its own.
struct HeldSpring {
    /// G = Phi_a - Phi_b, D x r row-major (zero at the held end).
    g: Vec<f64>,
    d0: [f64; 3],
    k: f64,
    l0: f64,
    /// The held slot, and +1 when it is the spring's end b, -1 when it is a.
    slot: usize,
    sign: f64,
}

/// The kept springs' vectors of the last evaluation, and the outputs' scratch.
pub struct CubatureWork {
    /// Per held spring: its vector with the holder in place and moved (2 D
    /// values), and whether it moved, at the last evaluation.
    held_d: Vec<f64>,
    held_moved: Vec<bool>,
    /// d = d0 - G q per kept spring.
    d: Vec<f64>,
    /// Slot positions, spring forces and elastic energy of every spring at
    /// `exact_at`, computed when an output asks.
    x: Vec<f64>,
    f: Vec<f64>,
    elastic: f64,
    springs: SpringScratch,
    /// `x` is the expansion of the current q; `f` and `elastic` are its forces and energy.
    x_valid: bool,
    exact_valid: bool,
    /// D x r scratch of the tangent.
    kg: Vec<f64>,
}

impl ReducedForce for Cubature {
    type Work = CubatureWork;

    /// Trains the set, or takes the stored one, and assembles the model.
    fn new(scene: &Scene, modes: &Modes, setup: &ForceSetup) -> Result<Self, PhysicsError> {
        // The set is trained at set-up (`crate::physics::setup::cubature_training`) or stored.
        let set = setup.prebuilt.cloned().ok_or(PhysicsError::SetupDataMismatch { what: "a cubature needs its trained spring set" })?;
        Ok(match scene.dim {
            2 => assemble::<2>(scene, modes, set),
            _ => assemble::<3>(scene, modes, set),
        })
    }

    fn spring_set(&self) -> Option<SpringSet> {
        Some(SpringSet { springs: self.ids.clone(), weights: self.weights.clone(), training_error: self.training_error, held_out_error: self.held_out_error })
    }

    fn work(&self, scene: &Scene, modes: &Modes) -> CubatureWork {
        CubatureWork {
            held_d: vec![0.0; 2 * scene.dim * self.held.len()],
            held_moved: vec![false; self.held.len()],
            d: vec![0.0; self.d0.len()],
            x: modes.point.clone(),
            f: vec![0.0; modes.basis.n],
            elastic: 0.0,
            springs: self.exact.scratch(scene),
            x_valid: false,
            exact_valid: false,
            kg: vec![0.0; scene.dim * modes.basis.r],
        }
    }

    fn project(&self, scene: &Scene, modes: &Modes, q: &[f64], w: &mut CubatureWork, out: &mut [f64]) {
        w.x_valid = false;
        w.exact_valid = false;
        match scene.dim {
            2 => {
                self.project_d::<2>(modes.basis.r, q, w, out);
                self.held_d::<2>(modes, q, w, out);
            }
            _ => {
                self.project_d::<3>(modes.basis.r, q, w, out);
                self.held_d::<3>(modes, q, w, out);
            }
        }
    }

    fn add_tangent(&self, scene: &Scene, modes: &Modes, w: &mut CubatureWork, kr: &mut [f64]) {
        match scene.dim {
            2 => self.tangent_d::<2>(modes.basis.r, w, kr),
            _ => self.tangent_d::<3>(modes.basis.r, w, kr),
        }
    }

    fn slots_mut<'w>(&self, w: &'w mut CubatureWork) -> &'w mut [f64] {
        &mut w.x
    }

    fn positions<'w>(&self, _scene: &Scene, modes: &Modes, q: &[f64], w: &'w mut CubatureWork) -> &'w [f64] {
        Self::expand(modes, q, w);
        &w.x
    }

    fn elastic_energy(&self, scene: &Scene, modes: &Modes, q: &[f64], w: &mut CubatureWork) -> f64 {
        self.evaluate_exact(scene, modes, q, w);
        w.elastic
    }

    /// U~(q) = U(0) - c^T q + sum_S w_e (U_e(q) - U_e(0)), U_e = 1/2 k (l - l0)^2:
    /// the energy whose negative gradient is F~ (-dU_e/dq = G^T g_e), from
    /// the kept springs' vectors of the last evaluation.
    fn model_energy(&self, scene: &Scene, _modes: &Modes, q: &[f64], w: &mut CubatureWork) -> f64 {
        let springs: f64 =
            w.d.chunks_exact(scene.dim)
                .zip(self.wk.iter().zip(&self.l0))
                .map(|(v, (&wk, &l0))| {
                    let l = v.iter().map(|c| c * c).sum::<f64>().sqrt();
                    0.5 * wk * (l - l0) * (l - l0)
                })
                .sum();
        let d = scene.dim;
        let held: f64 = w
            .held_d
            .chunks_exact(2 * d)
            .zip(&self.held)
            .zip(&w.held_moved)
            .filter(|(_, moved)| **moved)
            .map(|((v, h), _)| {
                let energy = |x: &[f64]| 0.5 * h.k * (x.iter().map(|c| c * c).sum::<f64>().sqrt() - h.l0).powi(2);
                energy(&v[d..]) - energy(&v[..d])
            })
            .sum();
        self.energy_offset - self.offset.iter().zip(q).map(|(c, q)| c * q).sum::<f64>() + springs + held
    }

    fn spring_forces<'w>(&self, scene: &Scene, modes: &Modes, q: &[f64], w: &'w mut CubatureWork) -> &'w [f64] {
        self.evaluate_exact(scene, modes, q, w);
        &w.f
    }

    fn springs(&self, _scene: &Scene) -> usize {
        self.ids.len()
    }

    /// lambda_max(sum_S w_e k_e G_e^T G_e): the cubature model's own
    /// stiffness with every kept spring at its taut bound.
    fn taut_bound(&self, scene: &Scene, modes: &Modes) -> Option<f64> {
        let (r, d) = (modes.basis.r, scene.dim);
        let mut m = faer::Mat::<f64>::zeros(r, r);
        for (e, &wk) in self.wk.iter().enumerate() {
            let g = &self.g[e * d * r..(e + 1) * d * r];
            for col in 0..r {
                for row in 0..r {
                    m[(row, col)] += wk * (0..d).map(|i| g[i * r + row] * g[i * r + col]).sum::<f64>();
                }
            }
        }
        m.self_adjoint_eigenvalues(faer::Side::Lower).ok().and_then(|ev| ev.last().copied())
    }
}

impl Cubature {
    /// x* + Phi q, once per state.
    fn expand(modes: &Modes, q: &[f64], w: &mut CubatureWork) {
        if !w.x_valid {
            modes.expand(q, &mut w.x);
            w.x_valid = true;
        }
    }

    /// The positions, forces and energy of every spring at q, once per state.
    fn evaluate_exact(&self, scene: &Scene, modes: &Modes, q: &[f64], w: &mut CubatureWork) {
        if w.exact_valid {
            return;
        }
        Self::expand(modes, q, w);
        w.f.fill(0.0);
        w.elastic = self.exact.add_to(scene, &w.x, &mut w.springs, &mut w.f);
        w.exact_valid = true;
    }

    /// F~(q) = c + sum_S w_e G_e^T g_e(d0 - G_e q).
    fn project_d<const D: usize>(&self, r: usize, q: &[f64], w: &mut CubatureWork, out: &mut [f64]) {
        out.copy_from_slice(&self.offset);
        for (((g, d0), d), (&wk, &l0)) in self.g.chunks_exact(D * r).zip(self.d0.chunks_exact(D)).zip(w.d.chunks_exact_mut(D)).zip(self.wk.iter().zip(&self.l0))
        {
            let mut dv = [0.0; D];
            for i in 0..D {
                dv[i] = d0[i] - g[i * r..(i + 1) * r].iter().zip(q).map(|(a, b)| a * b).sum::<f64>();
            }
            d.copy_from_slice(&dv);
            let gv = pull(&dv, wk, l0);
            for i in 0..D {
                for (o, gij) in out.iter_mut().zip(&g[i * r..(i + 1) * r]) {
                    *o += gij * gv[i];
                }
            }
        }
    }

    /// kr += sum_S w_e G_e^T K_e(d_e) G_e at the vectors of the last
    /// evaluation, and G_e^T (K_e(moved) - K_e(in place)) G_e of the springs
    /// at moving holders.
    fn tangent_d<const D: usize>(&self, r: usize, w: &mut CubatureWork, kr: &mut [f64]) {
        let kg = &mut w.kg;
        for ((g, d), (&wk, &l0)) in self.g.chunks_exact(D * r).zip(w.d.chunks_exact(D)).zip(self.wk.iter().zip(&self.l0)) {
            let ke = block::<D>(d.try_into().expect("D values"), wk, l0);
            add_projected_block::<D>(&ke, g, r, kg, kr);
        }
        for ((h, v), _) in self.held.iter().zip(w.held_d.chunks_exact(2 * D)).zip(&w.held_moved).filter(|(_, m)| **m) {
            let change = block::<D>(v[D..].try_into().expect("D values"), h.k, h.l0) - block::<D>(v[..D].try_into().expect("D values"), h.k, h.l0);
            add_projected_block::<D>(&change, &h.g, r, kg, kr);
        }
    }

    /// out += G^T (g(d0 - G q ± δ) - g(d0 - G q)) for every spring at a
    /// holder that moved (δ its held end's displacement from x*, in the
    /// slot positions the run placed).
    fn held_d<const D: usize>(&self, modes: &Modes, q: &[f64], w: &mut CubatureWork, out: &mut [f64]) {
        let r = modes.basis.r;
        for ((h, v), moved) in self.held.iter().zip(w.held_d.chunks_exact_mut(2 * D)).zip(w.held_moved.iter_mut()) {
            let delta: [f64; D] = std::array::from_fn(|i| w.x[h.slot * D + i] - modes.point[h.slot * D + i]);
            *moved = delta != [0.0; D];
            if !*moved {
                continue;
            }
            let rest: [f64; D] = std::array::from_fn(|i| h.d0[i] - h.g[i * r..(i + 1) * r].iter().zip(q).map(|(a, b)| a * b).sum::<f64>());
            let now: [f64; D] = std::array::from_fn(|i| rest[i] + h.sign * delta[i]);
            v[..D].copy_from_slice(&rest);
            v[D..].copy_from_slice(&now);
            let (a, b) = (pull(&now, h.k, h.l0), pull(&rest, h.k, h.l0));
            for i in 0..D {
                for (o, gij) in out.iter_mut().zip(&h.g[i * r..(i + 1) * r]) {
                    *o += gij * (a[i] - b[i]);
                }
            }
        }
    }
}

/// One spring's geometry for the training columns.
pub struct Candidate<const D: usize> {
    /// Its index in the scene.
    pub index: usize,
    /// G = Phi_a - Phi_b, D x r row-major.
    pub g: Vec<f64>,
    pub d0: [f64; D],
    pub k: f64,
    pub l0: f64,
    /// g_e(d0).
    pub f0: [f64; D],
}

impl<const D: usize> Candidate<D> {
    pub fn new(scene: &Scene, modes: &Modes, e: usize) -> Option<Self> {
        let (r, nf) = (modes.basis.r, scene.n_free);
        let s = &scene.springs[e];
        let phi = &modes.basis.phi;
        let mut g = vec![0.0; D * r];
        for i in 0..D {
            for j in 0..r {
                let pa = if s.a < nf { phi[(s.a * D + i) * r + j] } else { 0.0 };
                let pb = if s.b < nf { phi[(s.b * D + i) * r + j] } else { 0.0 };
                g[i * r + j] = pa - pb;
            }
        }
        if g.iter().all(|v| *v == 0.0) {
            return None;
        }
        let d0: [f64; D] = std::array::from_fn(|i| modes.point[s.b * D + i] - modes.point[s.a * D + i]);
        Some(Candidate { index: e, f0: pull(&d0, s.k, s.rest), g, d0, k: s.k, l0: s.rest })
    }

    /// p_e(q_t) - p_e(0) for every pose (r values each): G^T [g(d0 - G q) - g(d0)].
    pub fn column(&self, r: usize, poses: &[Vec<f64>], out: &mut [f64]) {
        for (q, o) in poses.iter().zip(out.chunks_exact_mut(r)) {
            let d: [f64; D] = std::array::from_fn(|i| self.d0[i] - self.g[i * r..(i + 1) * r].iter().zip(q).map(|(a, b)| a * b).sum::<f64>());
            let f = pull(&d, self.k, self.l0);
            let v: [f64; D] = std::array::from_fn(|i| f[i] - self.f0[i]);
            o.fill(0.0);
            for i in 0..D {
                for (oj, gij) in o.iter_mut().zip(&self.g[i * r..(i + 1) * r]) {
                    *oj += gij * v[i];
                }
            }
        }
    }
}

/// F(0) = Phi^T f(x*), exactly, in the same passes a training pose takes,
/// and the elastic energy of every spring there.
fn exact_at_point(scene: &Scene, modes: &Modes, exact: &SpringForces) -> (Vec<f64>, f64) {
    let mut x = modes.point.clone();
    let mut f = vec![0.0; modes.basis.n];
    let r = modes.basis.r;
    modes.expand(&vec![0.0; r], &mut x);
    let energy = exact.add_to(scene, &x, &mut exact.scratch(scene), &mut f);
    let mut out = vec![0.0; r];
    modes.project(&f, &mut out);
    (out, energy)
}

/// The springs from a free slot to a slot of a holder that moves on its own.
fn held_springs<const D: usize>(scene: &Scene, modes: &Modes) -> Vec<HeldSpring> {
    let nf = scene.n_free;
    let mut moving = vec![false; scene.rest.len() / D];
    scene.moving_holders().iter().flat_map(|h| &h.slots).for_each(|&s| moving[s] = true);
    (0..scene.springs.len())
        .filter_map(|e| {
            let s = &scene.springs[e];
            let (slot, sign) = match (s.a < nf, s.b < nf) {
                (true, false) if moving[s.b] => (s.b, 1.0),
                (false, true) if moving[s.a] => (s.a, -1.0),
                _ => return None,
            };
            let c = Candidate::<D>::new(scene, modes, e)?;
            Some(HeldSpring { g: c.g, d0: std::array::from_fn(|i| if i < D { c.d0[i] } else { 0.0 }), k: c.k, l0: c.l0, slot, sign })
        })
        .collect()
}

/// The model of a spring set: each kept spring's G and d0,
/// c = F0 - sum w p_e(0), and the energy constant U(0) - sum w U_e(0).
fn assemble<const D: usize>(scene: &Scene, modes: &Modes, set: SpringSet) -> Cubature {
    let r = modes.basis.r;
    let exact = SpringForces::new(scene);
    let (offset, energy_at_point) = exact_at_point(scene, modes, &exact);
    let mut cub = Cubature {
        ids: Vec::new(),
        g: Vec::new(),
        d0: Vec::new(),
        weights: Vec::new(),
        wk: Vec::new(),
        l0: Vec::new(),
        offset,
        energy_offset: energy_at_point,
        exact,
        held: held_springs::<D>(scene, modes),
        training_error: set.training_error,
        held_out_error: set.held_out_error,
    };
    for (&e, &w) in set.springs.iter().zip(&set.weights) {
        // A spring with both ends held contributes nothing and was never chosen.
        let Some(c) = Candidate::<D>::new(scene, modes, e) else { continue };
        cub.ids.push(e);
        cub.g.extend_from_slice(&c.g);
        cub.d0.extend_from_slice(&c.d0);
        cub.weights.push(w);
        cub.wk.push(w * c.k);
        cub.l0.push(c.l0);
        let l = c.d0.iter().map(|v| v * v).sum::<f64>().sqrt();
        cub.energy_offset -= 0.5 * w * c.k * (l - c.l0) * (l - c.l0);
        for j in 0..r {
            // c -= w p_e(0) = w G^T g(d0)
            cub.offset[j] -= w * (0..D).map(|m| c.g[m * r + j] * c.f0[m]).sum::<f64>();
        }
    }
    cub
}
