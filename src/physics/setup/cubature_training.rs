//! Training of the optimized cubature (`docs/method.md`, section 4; the
//! model it trains is [`Cubature`], its evaluation): a set-up stage above
//! the spaces and the schemes, since it runs the exact reduced model with
//! the explicit Newmark scheme to find the poses a run will visit.
//!
//! Poses q_t from a short run of the exact reduced model under the set-up
//! loads (from rest, unit weights, no damping), sampled evenly, and random
//! poses around them; targets F(q_t) - F0; springs are added greedily,
//! those whose column (p_e(q_t) - p_e(0))_t correlates most with the
//! residual first, from a random pool of candidates, and the weights are
//! the non-negative least-squares fit on the springs chosen (Lawson-Hanson),
//! until the relative error sqrt(sum_t |F~(q_t) - F(q_t)|^2 / sum_t |F(q_t) - F0|^2)
//! is within half the tolerance on the training poses and on held-out poses
//! of the same kind (the margin keeps other poses of that kind within the
//! tolerance). Everything is seeded, so the set is the same on every machine.

use faer::{Col, Mat};
use ndarray::{Array1, Array2, ShapeBuilder};
use rand_chacha::rand_core::{RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::physics::error::{Expected, PhysicsError, Quantity};
use crate::physics::run::integrator::{Buffers, NewmarkExplicit, Scheme};
use crate::physics::run::space::{Candidate, Constants, Exact, Modal, Readout, Space};
use crate::physics::run::state::{Loads, State};
use crate::physics::settings::Settings;
use crate::physics::setup::scene::Scene;
use crate::physics::setup::setup_data::{SetupData, SpringSet};

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

/// Uniform in [0, 1) from the seeded stream.
fn uniform(rng: &mut ChaCha8Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// A chosen spring with its columns on the training and the held-out poses.
type Chosen<const D: usize> = (Candidate<D>, Vec<f64>, Vec<f64>);
/// Modal coordinates of a set of poses.
type Poses = Vec<Vec<f64>>;

/// The costly part of a cubature set-up: the basis `settings` ask for (or
/// that of `prebuilt`), and the spring set trained on it, as data for
/// `Modal::<Cubature>::new`. The training poses come from `snapshots`
/// (modal coordinates, e.g. a trained basis's training program) when
/// given, at most 2 [`RUN_POSES`] of them taken evenly, alternately
/// training and held out; else from a short exact reduced run and random
/// poses around it.
pub fn train(
    scene: Scene,
    loads: &Loads,
    settings: &Settings,
    prebuilt: Option<&SetupData>,
    snapshots: Option<&[Vec<f64>]>,
) -> Result<SetupData, PhysicsError> {
    let tol = settings.cubature_tolerance;
    if !(tol > 0.0 && tol <= 1.0) {
        return Err(PhysicsError::Invalid { quantity: Quantity::CubatureTolerance, value: tol, expected: Expected::PositiveAtMost(1.0) });
    }
    if settings.n_modes > MAX_MODES {
        return Err(PhysicsError::CubatureTooManyModes { modes: settings.n_modes, limit: MAX_MODES });
    }
    let space = Modal::<Exact>::new(scene, loads, settings, prebuilt)?;
    let (train_poses, held_poses) = match snapshots {
        Some(all) => {
            // The snapshots span the motions already: every other one trains, the rest are held out.
            let m = all.len().min(2 * RUN_POSES);
            let taken: Vec<&Vec<f64>> = (0..m).map(|i| &all[i * all.len() / m]).collect();
            (taken.iter().step_by(2).map(|q| q.to_vec()).collect(), taken.iter().skip(1).step_by(2).map(|q| q.to_vec()).collect())
        }
        None => {
            let (run, start) = run_poses(&space, loads, settings)?;
            around(&space, &run, &start)
        }
    };
    let set = match space.scene().dim {
        2 => select::<2>(&space, tol, &train_poses, &held_poses)?,
        _ => select::<3>(&space, tol, &train_poses, &held_poses)?,
    };
    let mut data = space.setup_data().expect("the modal space has set-up data");
    data.cubature = Some(set);
    Ok(data)
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Chooses the springs and their weights on the exact reduced model
/// `space`, from its training and held-out poses; see the module documentation.
fn select<const D: usize>(space: &Modal<Exact>, tol: f64, train_poses: &[Vec<f64>], held_poses: &[Vec<f64>]) -> Result<SpringSet, PhysicsError> {
    let (scene, modes) = (space.scene(), space.modes());
    let r = modes.basis.r;
    let max_springs = MAX_SPRINGS.min(scene.springs.len() / 2);
    let mut w = space.work(&Loads::physical(r)); // spring forces alone: the loads do not enter
                                                 // F(q) = Phi^T f(x* + Phi q), as the exact model evaluates it.
    let mut reduced = |q: &[f64], out: &mut [f64]| space.spring_force(q, &mut w, out);
    let mut f0 = vec![0.0; r];
    reduced(&vec![0.0; r], &mut f0);

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
    let train_t = targets(train_poses, &mut reduced);
    let held_t = targets(held_poses, &mut reduced);
    let (train_scale, held_scale) = (norm(&train_t).max(f64::MIN_POSITIVE), norm(&held_t).max(f64::MIN_POSITIVE));
    let goal = 0.5 * tol;

    let mut candidates: Vec<usize> = (0..scene.springs.len()).collect();
    let mut rng = ChaCha8Rng::seed_from_u64(SEED ^ 1);
    let (mt, mh) = (train_t.len(), held_t.len());
    // Chosen springs with their training and held-out columns.
    let mut chosen: Vec<Chosen<D>> = Vec::new();
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
                c.column(r, train_poses, &mut column);
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
            c.column(r, train_poses, &mut tc);
            c.column(r, held_poses, &mut hc);
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
        let apply = |target: &[f64], col: fn(&Chosen<D>) -> &Vec<f64>, out: &mut Vec<f64>| {
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

/// The weights of the chosen springs: the non-negative least-squares fit
/// of their columns to `target` (Lawson-Hanson), on columns scaled to unit
/// norm. With more rows than springs the fit runs on the triangle R of
/// A = Q R and on Qᵀ b (faer's Householder QR): |A x − b|² = |R x − Qᵀ b|²
/// + |b|² − |Qᵀ b|², the same minimizer on a square system.
fn fit<const D: usize>(chosen: &[Chosen<D>], target: &[f64]) -> Result<Vec<f64>, PhysicsError> {
    let norms: Vec<f64> = chosen.iter().map(|c| norm(&c.1)).collect();
    let (m, k) = (target.len(), chosen.len());
    let (a, b) = if m > k {
        let a = Mat::from_fn(m, k, |i, j| chosen[j].1[i] / norms[j]);
        let qr = a.qr();
        let qtb = qr.compute_thin_Q().transpose() * Col::from_fn(m, |i| target[i]);
        let r = qr.thin_R();
        (Array2::from_shape_fn((k, k).f(), |(i, j)| r[(i, j)]), Array1::from_shape_fn(k, |i| qtb[i]))
    } else {
        (Array2::from_shape_fn((m, k).f(), |(i, j)| chosen[j].1[i] / norms[j]), Array1::from(target.to_vec()))
    };
    // The solver panics where round-off leaves a weight it holds non-positive.
    let (x, _) = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| nnls::nnls(a.view(), b.view())))
        .map_err(|_| PhysicsError::LinearAlgebra { what: "the non-negative least squares of the cubature weights", detail: "round-off".into() })?;
    Ok(x.iter().zip(&norms).map(|(x, n)| x / n).collect())
}

/// The poses of a short exact run of
/// the reduced model `space` under the set-up gravity and point load, and
/// with anchor motion ahead ([`Settings::anchor_motion`]) the inertial load
/// of an anchor accelerating at |g| (at least 1 m/s^2) along +x, +y and +z
/// at once (from the rest state, unit weights, no damping, explicit Newmark
/// at its stable step, one period of the slowest kept mode up to 2 s), with
/// the coordinates of the rest state it starts from.
fn run_poses(space: &Modal<Exact>, set_up: &Loads, settings: &Settings) -> Result<(Poses, Vec<f64>), PhysicsError> {
    let (scene, modes) = (space.scene(), space.modes());
    let r = modes.basis.r;
    let mut loads = Loads { damping_alpha: 0.0, damping_beta: 0.0, anchor: [0.0; 3], mode_weights: vec![1.0; r], ..set_up.clone() };
    if settings.anchor_motion {
        // An anchor accelerating at |g| (at least 1 m/s^2) along every axis at once adds its inertial load.
        let accel = set_up.gravity[..scene.dim].iter().map(|g| g * g).sum::<f64>().sqrt().max(1.0);
        for g in &mut loads.gravity[..scene.dim] {
            *g -= accel;
        }
    }
    let mut w = space.work(&loads);
    space.apply_loads(&mut w);
    let mut start = vec![0.0; r];
    space.rest_coordinates(&mut start);
    let dt = NewmarkExplicit::stable_step(space.omega_sq_bound(&w)).ok_or(PhysicsError::CubatureTrainingDiverged { time: 0.0 })?;
    let lambda_min = modes.basis.lambda.iter().copied().filter(|l| *l > 0.0).fold(f64::INFINITY, f64::min);
    let span = (2.0 * std::f64::consts::PI / lambda_min.sqrt()).min(RUN_SECONDS);
    let steps = ((span / dt).ceil() as usize).clamp(RUN_POSES, RUN_STEPS);
    let every = steps / RUN_POSES;
    let mut buf = Buffers::new(r, 0);
    let mut state = State::at_rest(r);
    state.y.copy_from_slice(&start);
    NewmarkExplicit::settle(space, &mut w, &mut buf, &mut state);
    let mut run = Vec::with_capacity(RUN_POSES);
    for step in 1..=every * RUN_POSES {
        let diverged = NewmarkExplicit::step(space, &mut w, &mut buf, &mut state, dt).is_err();
        if diverged || !state.y.iter().chain(&state.v).all(|z| z.is_finite()) {
            return Err(PhysicsError::CubatureTrainingDiverged { time: step as f64 * dt });
        }
        if step % every == 0 {
            run.push(state.y.clone());
        }
    }
    Ok((run, start))
}

/// Training and held-out poses: every other pose of `run` (which starts
/// from `start`), and around them random poses q_start + s (q_t - q_start) + delta, s uniform
/// in [0.5, 1.25], delta_j uniform within a quarter of mode j's amplitude in
/// the run. With no motion (no load), the amplitude is 1 % of a whole-sheet
/// displacement by the scene's length scale.
fn around(space: &Modal<Exact>, run: &[Vec<f64>], start: &[f64]) -> (Poses, Poses) {
    let (scene, r) = (space.scene(), space.modes().basis.r);
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
    (train, held)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::run::space::{Cubature, ForceSetup, Modes, ReducedForce};
    use crate::physics::settings::{ForceEvaluation, Integrator, ModeSelection, Reduction};
    use crate::physics::setup::grid::{paper, FixedNodes, Grid};

    /// The paper's sheets: 10 x 10 in 2D, 7 x 7 in 3D with auxiliary springs, top row held, under gravity.
    fn sheet(name: &str) -> (Grid, Loads) {
        let dim = if name.contains("3d") { 3 } else { 2 };
        let (columns, rows) = if dim == 3 { (7, 7) } else { (10, 10) };
        let grid = paper(columns, rows, dim, FixedNodes::TopRow);
        let loads = Loads::physical(6);
        (grid, loads)
    }

    /// A cubature model of `name` on 6 load modes with a static correction, trained here.
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
        let data = train(scene.clone(), &loads, &settings, None, None).unwrap();
        let modes = Modes::new(data.basis.clone(), data.point.clone(), data.at_rest);
        let setup = ForceSetup { loads: &loads, settings: &settings, omega_sq_bound: data.omega_sq_bound, prebuilt: data.cubature.as_ref() };
        let cub = Cubature::new(&scene, &modes, &setup).unwrap();
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
