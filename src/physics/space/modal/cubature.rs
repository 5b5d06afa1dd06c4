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
//! Set-up (training): poses q_t from a short run of the exact reduced model
//! under the set-up loads (from rest, unit weights, no damping), sampled
//! evenly, and random poses around them; targets F(q_t) - F0; springs are
//! added greedily, those whose column (p_e(q_t) - p_e(0))_t correlates most
//! with the residual first, from a random pool of candidates, and the
//! weights are the non-negative least-squares fit on the springs chosen
//! (Lawson-Hanson), until the relative error
//! sqrt(sum_t |F~(q_t) - F(q_t)|^2 / sum_t |F(q_t) - F0|^2) is within half
//! the tolerance on the training poses and on held-out poses of the same
//! kind (the margin keeps other poses of that kind within the tolerance).
//! Everything is seeded, so the set is the same on every machine.

use ndarray::{Array1, Array2};
use rand_chacha::rand_core::{RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::reduced::{ForceSetup, Modes, ReducedForce};
use crate::physics::bake::SpringSet;
use crate::physics::error::PhysicsError;
use crate::physics::forces::{block, pull, SpringForces, SpringScratch};
use crate::physics::scene::Scene;

/// Poses sampled along the training run (half train, half held out).
const RUN_POSES: usize = 48;
/// Random poses around them, per set.
const RANDOM_POSES: usize = 24;
/// Candidate springs scored per greedy round.
const POOL: usize = 512;
/// Longest training run [s] and most steps it may take.
const RUN_SECONDS: f64 = 2.0;
const RUN_STEPS: usize = 4000;
/// Most modes a cubature is trained for: its training matrix has 96 r rows
/// and each fit costs rows x springs^2.
pub const MAX_MODES: usize = 64;
/// Most springs a cubature set may keep (and at most half the scene's):
/// beyond, exact forces are as cheap.
pub const MAX_SPRINGS: usize = 1000;
/// Rounds without a 1 % fall of the training error before set-up gives up.
const STALL_ROUNDS: usize = 20;
/// Seed of the pose and candidate draws.
const SEED: u64 = 0x6d6f_6461_6c5f_6375;

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
    /// Relative error of F - F0 on the training poses and on the held-out ones.
    pub training_error: f64,
    pub held_out_error: f64,
}

/// The kept springs' vectors of the last evaluation, and the outputs' scratch.
pub struct CubatureWork {
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
        let set = match setup.prebuilt {
            Some(set) => set.clone(),
            None => match scene.dim {
                2 => train::<2>(scene, modes, setup)?,
                _ => train::<3>(scene, modes, setup)?,
            },
        };
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
            2 => self.project_d::<2>(modes.basis.r, q, w, out),
            _ => self.project_d::<3>(modes.basis.r, q, w, out),
        }
    }

    fn add_tangent(&self, scene: &Scene, modes: &Modes, w: &mut CubatureWork, kr: &mut [f64]) {
        match scene.dim {
            2 => self.tangent_d::<2>(modes.basis.r, w, kr),
            _ => self.tangent_d::<3>(modes.basis.r, w, kr),
        }
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
        self.energy_offset - self.offset.iter().zip(q).map(|(c, q)| c * q).sum::<f64>() + springs
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

    /// kr += sum_S w_e G_e^T K_e(d_e) G_e at the vectors of the last evaluation.
    fn tangent_d<const D: usize>(&self, r: usize, w: &mut CubatureWork, kr: &mut [f64]) {
        let kg = &mut w.kg;
        for ((g, d), (&wk, &l0)) in self.g.chunks_exact(D * r).zip(w.d.chunks_exact(D)).zip(self.wk.iter().zip(&self.l0)) {
            let ke = block::<D>(d.try_into().expect("D values"), wk, l0);
            for i in 0..D {
                for j in 0..r {
                    kg[i * r + j] = (0..D).map(|m| ke[(i, m)] * g[m * r + j]).sum();
                }
            }
            for col in 0..r {
                for row in 0..r {
                    kr[col * r + row] += (0..D).map(|i| g[i * r + row] * kg[i * r + col]).sum::<f64>();
                }
            }
        }
    }
}

/// Uniform in [0, 1) from the seeded stream.
fn uniform(rng: &mut ChaCha8Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// One spring's geometry for the training columns.
struct Candidate<const D: usize> {
    /// Its index in the scene.
    index: usize,
    g: Vec<f64>,
    d0: [f64; D],
    k: f64,
    l0: f64,
    /// g_e(d0).
    f0: [f64; D],
}

impl<const D: usize> Candidate<D> {
    fn new(scene: &Scene, modes: &Modes, e: usize) -> Option<Self> {
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
    fn column(&self, r: usize, poses: &[Vec<f64>], out: &mut [f64]) {
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

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Chooses the springs and their weights; see the module documentation.
fn train<const D: usize>(scene: &Scene, modes: &Modes, setup: &ForceSetup) -> Result<SpringSet, PhysicsError> {
    let tol = setup.settings.cubature_tolerance;
    if !(tol > 0.0 && tol <= 1.0) {
        return Err(PhysicsError::Invalid {
            quantity: crate::physics::error::Quantity::CubatureTolerance,
            value: tol,
            expected: crate::physics::error::Expected::PositiveAtMost(1.0),
        });
    }
    let r = modes.basis.r;
    if r > MAX_MODES {
        return Err(PhysicsError::CubatureTooManyModes { modes: r, limit: MAX_MODES });
    }
    let max_springs = MAX_SPRINGS.min(scene.springs.len() / 2);
    let exact = SpringForces::new(scene);
    let mut scratch = exact.scratch(scene);
    let mut x = modes.point.clone();
    let mut f = vec![0.0; modes.basis.n];
    // F(q) = Phi^T f(x* + Phi q)
    let mut reduced = |q: &[f64], out: &mut [f64]| {
        modes.expand(q, &mut x);
        f.fill(0.0);
        exact.add_to(scene, &x, &mut scratch, &mut f);
        modes.project(&f, out);
    };
    let (f0, _) = exact_at_point(scene, modes, &exact);

    let (train_poses, held_poses) = poses(scene, modes, setup, &mut reduced)?;
    // F(q_t) - F0 per pose
    let targets = |poses: &[Vec<f64>], reduced: &mut dyn FnMut(&[f64], &mut [f64])| -> Vec<f64> {
        let mut t = vec![0.0; poses.len() * r];
        for (q, c) in poses.iter().zip(t.chunks_exact_mut(r)) {
            reduced(q, c);
            for (cj, fj) in c.iter_mut().zip(&f0) {
                *cj -= fj;
            }
        }
        t
    };
    let train_t = targets(&train_poses, &mut reduced);
    let held_t = targets(&held_poses, &mut reduced);
    let (train_scale, held_scale) = (norm(&train_t).max(f64::MIN_POSITIVE), norm(&held_t).max(f64::MIN_POSITIVE));
    let goal = 0.5 * tol;

    let mut candidates: Vec<usize> = (0..scene.springs.len()).collect();
    let mut rng = ChaCha8Rng::seed_from_u64(SEED ^ 1);
    let (mt, mh) = (train_t.len(), held_t.len());
    // Chosen springs with their training and held-out columns.
    let mut chosen: Vec<(Candidate<D>, Vec<f64>, Vec<f64>)> = Vec::new();
    let mut weights: Vec<f64> = Vec::new();
    let mut residual = train_t.clone();
    let mut held_residual = held_t.clone();
    let (mut train_err, mut held_err) = (norm(&residual) / train_scale, norm(&held_residual) / held_scale);
    let mut column = vec![0.0; mt];
    // Rounds since the training error last fell by 1 %, and the best error then.
    let (mut stalled, mut best) = (0usize, train_err);
    while train_err > goal || held_err > goal {
        if chosen.len() >= max_springs || stalled >= STALL_ROUNDS {
            return Err(PhysicsError::CubatureNotReached { tolerance: tol, reached: train_err.max(held_err), springs: chosen.len() });
        }
        // Score a random pool of the springs not chosen yet.
        let pool = POOL.min(candidates.len());
        for i in 0..pool {
            let j = i + (rng.next_u64() % (candidates.len() - i) as u64) as usize;
            candidates.swap(i, j);
        }
        let mut scored: Vec<(f64, usize)> = Vec::with_capacity(pool);
        for (i, &e) in candidates[..pool].iter().enumerate() {
            if let Some(c) = Candidate::<D>::new(scene, modes, e) {
                c.column(r, &train_poses, &mut column);
                let nrm = norm(&column);
                if nrm > 0.0 {
                    let corr = column.iter().zip(&residual).map(|(a, b)| a * b).sum::<f64>() / nrm;
                    if corr > 0.0 {
                        scored.push((corr, i));
                    }
                }
            }
        }
        if scored.is_empty() {
            if pool == candidates.len() {
                return Err(PhysicsError::CubatureNotReached { tolerance: tol, reached: train_err.max(held_err), springs: chosen.len() });
            }
            stalled += 1;
            continue;
        }
        scored.sort_by(|a, b| b.0.total_cmp(&a.0));
        let add = (chosen.len() / 4).max(1).min(scored.len()).min(max_springs - chosen.len());
        let mut taken: Vec<usize> = scored[..add].iter().map(|s| s.1).collect();
        taken.sort_unstable_by(|a, b| b.cmp(a));
        for i in taken {
            let e = candidates.swap_remove(i);
            let c = Candidate::<D>::new(scene, modes, e).expect("scored candidates have a column");
            let mut tc = vec![0.0; mt];
            let mut hc = vec![0.0; mh];
            c.column(r, &train_poses, &mut tc);
            c.column(r, &held_poses, &mut hc);
            chosen.push((c, tc, hc));
        }
        weights = fit(&chosen, &train_t)?;
        // Springs the fit gives no weight go back to the pool.
        let mut k = 0;
        chosen.retain(|c| {
            k += 1;
            let keep = weights[k - 1] > 0.0;
            if !keep {
                candidates.push(c.0.index);
            }
            keep
        });
        weights.retain(|w| *w > 0.0);
        let apply = |target: &[f64], col: fn(&(Candidate<D>, Vec<f64>, Vec<f64>)) -> &Vec<f64>, out: &mut Vec<f64>| {
            out.copy_from_slice(target);
            for (c, w) in chosen.iter().zip(&weights) {
                for (o, a) in out.iter_mut().zip(col(c)) {
                    *o -= w * a;
                }
            }
        };
        apply(&train_t, |c| &c.1, &mut residual);
        apply(&held_t, |c| &c.2, &mut held_residual);
        train_err = norm(&residual) / train_scale;
        held_err = norm(&held_residual) / held_scale;
        if train_err < 0.99 * best {
            (stalled, best) = (0, train_err);
        } else {
            stalled += 1;
        }
    }

    // The springs with a weight, in scene order (visited along memory).
    let mut kept: Vec<(usize, f64)> = chosen.iter().zip(&weights).filter(|(_, w)| **w > 0.0).map(|(c, w)| (c.0.index, *w)).collect();
    kept.sort_by_key(|k| k.0);
    Ok(SpringSet {
        springs: kept.iter().map(|k| k.0).collect(),
        weights: kept.iter().map(|k| k.1).collect(),
        training_error: train_err,
        held_out_error: held_err,
    })
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

/// The weights of the chosen springs: the non-negative least-squares fit
/// of their columns to `target` (Lawson-Hanson), on columns scaled to unit
/// norm.
fn fit<const D: usize>(chosen: &[(Candidate<D>, Vec<f64>, Vec<f64>)], target: &[f64]) -> Result<Vec<f64>, PhysicsError> {
    let norms: Vec<f64> = chosen.iter().map(|c| norm(&c.1)).collect();
    let a = Array2::from_shape_fn((target.len(), chosen.len()), |(i, j)| chosen[j].1[i] / norms[j]);
    let b = Array1::from(target.to_vec());
    // The solver panics where round-off leaves a weight it holds non-positive.
    let (x, _) = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| nnls::nnls(a.view(), b.view())))
        .map_err(|_| PhysicsError::LinearAlgebra { what: "the non-negative least squares of the cubature weights", detail: "round-off".into() })?;
    Ok(x.iter().zip(&norms).map(|(x, n)| x / n).collect())
}

/// Training and held-out poses: every other sample of a short exact run of
/// the reduced model under the set-up gravity and point load, and with
/// anchor motion ahead ([`ForceSetup::anchor_motion`]) the inertial load of an anchor accelerating at |g| (at least
/// 1 m/s^2) along +x, +y and +z at once (from the rest state, unit
/// weights, no damping, explicit Newmark at 0.9 of its stable step, one
/// period of the slowest kept mode up to 2 s), and around them random poses
/// q_start + s (q_t - q_start) + delta, s uniform in [0.5, 1.25], delta_j
/// uniform within a quarter of mode j's amplitude in the run. With no motion
/// (no load), the amplitude is 1 % of a whole-sheet displacement by the
/// scene's length scale.
fn poses(
    scene: &Scene,
    modes: &Modes,
    setup: &ForceSetup,
    reduced: &mut dyn FnMut(&[f64], &mut [f64]),
) -> Result<(Vec<Vec<f64>>, Vec<Vec<f64>>), PhysicsError> {
    let (n, r) = (modes.basis.n, modes.basis.r);
    let mut gravity = vec![0.0; r];
    let mut load = crate::physics::basis::external_load(scene, setup.loads);
    if setup.settings.anchor_motion {
        // An anchor accelerating at |g| (at least 1 m/s^2) along every axis at once adds its inertial load.
        let accel = setup.loads.gravity[..scene.dim].iter().map(|g| g * g).sum::<f64>().sqrt().max(1.0);
        for (k, fk) in load.iter_mut().enumerate() {
            *fk -= scene.dof_mass[k] * accel;
        }
    }
    for (k, fk) in load.into_iter().enumerate() {
        for (j, gj) in gravity.iter_mut().enumerate() {
            *gj += modes.basis.phi[k * r + j] * fk;
        }
    }
    let mut q = vec![0.0; r];
    if !modes.at_rest {
        let u: Vec<f64> = (0..n).map(|k| scene.rest[k] - modes.point[k]).collect();
        modes.basis.project_displacement(&scene.dof_mass, &u, &mut q);
    }
    let start = q.clone();
    let mut accel = |q: &[f64], a: &mut [f64]| {
        reduced(q, a);
        for (aj, gj) in a.iter_mut().zip(&gravity) {
            *aj += gj;
        }
    };
    let dt = 0.9 * 2.0 / setup.omega_sq_bound.sqrt();
    let lambda_min = modes.basis.lambda.iter().copied().filter(|l| *l > 0.0).fold(f64::INFINITY, f64::min);
    let span = (2.0 * std::f64::consts::PI / lambda_min.sqrt()).min(RUN_SECONDS);
    let steps = ((span / dt).ceil() as usize).clamp(RUN_POSES, RUN_STEPS);
    let every = steps / RUN_POSES;
    let (mut v, mut a, mut a1) = (vec![0.0; r], vec![0.0; r], vec![0.0; r]);
    accel(&q, &mut a);
    let mut run = Vec::with_capacity(RUN_POSES);
    for step in 1..=every * RUN_POSES {
        for j in 0..r {
            q[j] += dt * v[j] + 0.5 * dt * dt * a[j];
        }
        accel(&q, &mut a1);
        for j in 0..r {
            v[j] += 0.5 * dt * (a[j] + a1[j]);
        }
        std::mem::swap(&mut a, &mut a1);
        if !q.iter().chain(&v).all(|z| z.is_finite()) {
            return Err(PhysicsError::CubatureTrainingDiverged { time: step as f64 * dt });
        }
        if step % every == 0 {
            run.push(q.clone());
        }
    }
    let mut amplitude: Vec<f64> = (0..r).map(|j| run.iter().fold(0.0f64, |m, p| m.max((p[j] - start[j]).abs()))).collect();
    if amplitude.iter().all(|a| *a == 0.0) {
        let whole = scene.free_mass().sqrt() * scene.length_scale();
        amplitude.fill(0.01 * whole);
    }
    let random = |seed: u64| -> Vec<Vec<f64>> {
        let mut rng = ChaCha8Rng::seed_from_u64(SEED ^ seed);
        (0..RANDOM_POSES)
            .map(|_| {
                let base = &run[(rng.next_u64() % run.len() as u64) as usize];
                let s = 0.5 + 0.75 * uniform(&mut rng);
                (0..r).map(|j| start[j] + s * (base[j] - start[j]) + 0.25 * amplitude[j] * (2.0 * uniform(&mut rng) - 1.0)).collect()
            })
            .collect()
    };
    let mut train: Vec<Vec<f64>> = run.iter().step_by(2).cloned().collect();
    train.extend(random(2));
    let mut held: Vec<Vec<f64>> = run.iter().skip(1).step_by(2).cloned().collect();
    held.extend(random(3));
    Ok((train, held))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::basis;
    use crate::physics::grid::{FixedNodes, Grid};
    use crate::physics::settings::{ForceEvaluation, Integrator, ModeSelection, Reduction, Settings};
    use crate::physics::state::Loads;

    /// The paper's sheets: 10 x 10 in 2D, 7 x 7 in 3D with auxiliary springs, top row held, under gravity.
    fn sheet(name: &str) -> (Grid, Loads) {
        let dim = if name.contains("3d") { 3 } else { 2 };
        let (columns, rows) = if dim == 3 { (7, 7) } else { (10, 10) };
        let grid = Grid {
            columns,
            rows,
            dim,
            spacing: 0.1,
            node_mass: 0.01,
            spring_stiffness: 50.0,
            shear_springs: true,
            bending_springs: false,
            aux_stiffness: if dim == 3 { 0.05 } else { 0.0 },
            fixed_nodes: FixedNodes::TopRow,
        };
        let loads = Loads::physical(6);
        (grid, loads)
    }

    /// A cubature model of `name` on 6 load modes with a static correction.
    fn model(name: &str) -> (Scene, Modes, Cubature) {
        let (grid, loads) = sheet(name);
        let scene = grid.build().unwrap();
        let settings = Settings {
            mode_selection: ModeSelection::Load,
            static_correction: true,
            force_evaluation: ForceEvaluation::Cubature,
            cubature_tolerance: 0.002,
            ..Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, 6)
        };
        let built = basis::build(&scene, &loads, 6, &settings).unwrap();
        let modes = Modes::new(built.modes, built.point, built.at_rest);
        let bound = crate::physics::space::modal::reduced::taut_reduced_bound(&scene, &modes.basis).unwrap();
        let cub = Cubature::new(&scene, &modes, &ForceSetup { loads: &loads, settings: &settings, omega_sq_bound: bound, prebuilt: None }).unwrap();
        (scene, modes, cub)
    }

    /// Central differences of the model energy U~ against the force F~ =
    /// -dU~/dq, and U~(0) against the energy of every spring at q = 0.
    #[test]
    fn the_force_is_minus_the_gradient_of_the_model_energy() {
        for name in ["paper-2d-top-row", "paper-3d-sheet"] {
            let (scene, modes, cub) = model(name);
            let mut w = cub.work(&scene, &modes);
            let r = modes.basis.r;
            let zero = vec![0.0; r];
            let mut f = vec![0.0; r];
            cub.project(&scene, &modes, &zero, &mut w, &mut f);
            let (model0, exact0) = (cub.model_energy(&scene, &modes, &zero, &mut w), cub.elastic_energy(&scene, &modes, &zero, &mut w));
            assert!((model0 - exact0).abs() <= 1e-9 * exact0.abs().max(1e-12), "{name}: U~(0) = {model0}, U(0) = {exact0}");
            let q: Vec<f64> = (0..r).map(|j| 0.3 * (j as f64 + 1.0).sin()).collect();
            cub.project(&scene, &modes, &q, &mut w, &mut f);
            let scale = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let h = 1e-6;
            for j in 0..r {
                let (mut qp, mut qm) = (q.clone(), q.clone());
                qp[j] += h;
                qm[j] -= h;
                let mut scratch = vec![0.0; r];
                cub.project(&scene, &modes, &qp, &mut w, &mut scratch);
                let up = cub.model_energy(&scene, &modes, &qp, &mut w);
                cub.project(&scene, &modes, &qm, &mut w, &mut scratch);
                let um = cub.model_energy(&scene, &modes, &qm, &mut w);
                let fd = -(up - um) / (2.0 * h);
                assert!((fd - f[j]).abs() <= 1e-6 * scale, "{name}: F~[{j}] = {} against -dU~/dq = {fd}", f[j]);
            }
        }
    }

    /// Central differences of F~ against the tangent -dF~/dq it reports.
    #[test]
    fn the_tangent_is_the_derivative_of_the_force() {
        for name in ["paper-2d-top-row", "paper-3d-sheet"] {
            let (scene, modes, cub) = model(name);
            let mut w = cub.work(&scene, &modes);
            let r = modes.basis.r;
            let q: Vec<f64> = (0..r).map(|j| 0.3 * (j as f64 + 1.0).sin()).collect();
            let mut f = vec![0.0; r];
            cub.project(&scene, &modes, &q, &mut w, &mut f);
            let mut k = vec![0.0; r * r];
            cub.add_tangent(&scene, &modes, &mut w, &mut k);
            let h = 1e-6;

            for j in 0..r {
                let (mut qp, mut qm) = (q.clone(), q.clone());
                qp[j] += h;
                qm[j] -= h;
                let (mut fp, mut fm) = (vec![0.0; r], vec![0.0; r]);
                cub.project(&scene, &modes, &qp, &mut w, &mut fp);
                cub.project(&scene, &modes, &qm, &mut w, &mut fm);
                for i in 0..r {
                    let fd = -(fp[i] - fm[i]) / (2.0 * h);
                    let scale = k.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                    assert!((fd - k[j * r + i]).abs() <= 1e-6 * scale, "{name}: K[{i}, {j}] = {} against {fd}", k[j * r + i]);
                }
            }
        }
    }
}
