//! Trained bases (`docs/method.md`, section 3): a set-up stage above the
//! spaces and the schemes, since it runs the full-space model.
//!
//! **Training program** ([`program`]): the full-space model runs from rest
//! under loads drawn from what the scene will see: the set-up gravity g
//! scaled by 1 - s, 1 and 1 + s and tilted by ±θ about each axis normal to g
//! the scene can tilt about (z in 2D; two axes in 3D); with `anchor_motion`
//! the anchor accelerating at a = |g| / 2 either way along each axis (in the
//! holder's frame the gravity g - a); with `anchor_rotation` the holder
//! jerked from rest into a spin Ω about each axis it can turn about, Ω² ℓ =
//! 0.3 |g| (ℓ the scene's length scale); with a point load at set-up that
//! load scaled by 0 and 1 + s. Each run lasts `time` undamped (the motion
//! does not die out before the run ends, and the basis does not depend on
//! the damping, which may change after set-up), explicit Newmark at its stable step, and gives [`SAMPLES`] snapshots of
//! the displacement from the linearization point, d = x - x*.
//!
//! **Basis**: the mass-weighted principal components of the snapshots D,
//! the left singular vectors u_j of M^{1/2} D (faer's thin SVD) mapped back,
//! M^{-1/2} u_j, in the order of their singular values; with a static
//! correction the first r - p of them and the p static responses
//! ([`basis::static_vectors`]). They are M-orthonormalized and K(x*) is
//! diagonalized in their span (Rayleigh–Ritz), so Φᵀ M Φ = I and
//! Φᵀ K(x*) Φ = diag(λ): every vector keeps a frequency and a weight, and the
//! schemes, weights and outputs work as with eigenmodes.
//!
//! **Range**: the box of the snapshots' coordinates q = Φᵀ M d
//! ([`TrainedRange`]); the distance of a state from it is what
//! [`crate::physics::Simulator::training_range`] reports. With cubature forces the cubature trains on the
//! same snapshots ([`cubature_training::train`](crate::physics::setup::cubature_training::train)).

use faer::Mat;

use crate::physics::error::{Expected, PhysicsError, Quantity};
use crate::physics::run::frame::{apply, cross, dot, norm, rotation, Frame};
use crate::physics::run::holders::{self, Placement};
use crate::physics::run::integrator::{Buffers, NewmarkExplicit, Scheme};
use crate::physics::run::space::{basis_bound, Full, Space};
use crate::physics::run::state::{Loads, State};
use crate::physics::run::stiffness::StiffnessPattern;
use crate::physics::settings::{ForceEvaluation, Linearization, Reduction, Settings, TrainingProgram};
use crate::physics::setup::basis::{self, load_patterns};
use crate::physics::setup::cubature_training;
use crate::physics::setup::scene::Scene;
use crate::physics::setup::setup_data::{SetupData, TrainedRange};

/// Snapshots taken evenly over each training run.
pub const SAMPLES: usize = 40;
/// The anchor's training acceleration, as a share of |g|.
const ANCHOR_ACCELERATION: f64 = 0.5;
/// The holder's training spin: centrifugal acceleration Ω² ℓ as a share of |g|.
const SPIN_ACCELERATION: f64 = 0.3;
/// How far the training moves each holder other than the first, as a share of ℓ.
const HOLDER_SHIFT: f64 = 0.1;

/// One run of the training program: the loads in the holder's frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// What it is, for messages and the documentation.
    pub label: String,
    pub gravity: [f64; 3],
    pub point_load: [f64; 3],
    /// The spin the holder is jerked into at the start [rad/s].
    pub spin: [f64; 3],
    /// A holder that moves on its own (counted among those) jerked away
    /// from its place at the start and held there [m].
    pub holder: Option<(usize, [f64; 3])>,
}

/// Refuses a training program that means nothing physically: gravity
/// scaled to zero or reversed (scale in [0, 1)), tilted past the normal
/// (tilt in [0, pi/2]) or runs of no length. The FMU's narrower ranges are
/// the variable table's.
pub fn check(t: &TrainingProgram) -> Result<(), PhysicsError> {
    let fail = |quantity, value, expected| Err(PhysicsError::Invalid { quantity, value, expected });
    if !(t.scale >= 0.0 && t.scale < 1.0) {
        return fail(Quantity::TrainingScale, t.scale, Expected::NonNegativeBelow(1.0));
    }
    if !(t.tilt >= 0.0 && t.tilt <= std::f64::consts::FRAC_PI_2) {
        return fail(Quantity::TrainingTilt, t.tilt, Expected::NonNegativeAtMost(std::f64::consts::FRAC_PI_2));
    }
    if !(t.time > 0.0 && t.time.is_finite()) {
        return fail(Quantity::TrainingTime, t.time, Expected::Positive);
    }
    Ok(())
}

/// The training program of `scene` under the set-up `loads` (see the module documentation).
pub fn program(scene: &Scene, loads: &Loads, settings: &Settings) -> Result<Vec<Case>, PhysicsError> {
    let t = &settings.training;
    check(t)?;
    let d = scene.dim;
    let mut g = [0.0; 3];
    g[..d].copy_from_slice(&loads.gravity[..d]);
    let mut p = [0.0; 3];
    if let Some((_, f)) = loads.point_force(scene) {
        p[..d].copy_from_slice(f);
    }
    let g_norm = norm(&g);
    if g_norm == 0.0 && p == [0.0; 3] {
        return Err(PhysicsError::NoLoad);
    }
    let case = |label: String, gravity: [f64; 3], point_load: [f64; 3], spin: [f64; 3]| Case { label, gravity, point_load, spin, holder: None };
    let scaled = |v: &[f64; 3], s: f64| -> [f64; 3] { std::array::from_fn(|i| s * v[i]) };
    let mut cases = vec![case("the set-up loads".into(), g, p, [0.0; 3])];
    if t.scale > 0.0 && g_norm > 0.0 {
        for s in [1.0 - t.scale, 1.0 + t.scale] {
            cases.push(case(format!("gravity x {s}"), scaled(&g, s), p, [0.0; 3]));
        }
    }
    if t.tilt > 0.0 && g_norm > 0.0 {
        for (name, axis) in tilt_axes(&g, d) {
            for sign in [1.0, -1.0] {
                let turned = apply(&rotation(&scaled(&axis, sign * t.tilt)), &g);
                cases.push(case(format!("gravity tilted {:+.1} degrees about {name}", sign * t.tilt.to_degrees()), turned, p, [0.0; 3]));
            }
        }
    }
    if p != [0.0; 3] {
        for s in [0.0, 1.0 + t.scale] {
            cases.push(case(format!("point load x {s}"), g, scaled(&p, s), [0.0; 3]));
        }
    }
    let reference = if g_norm > 0.0 { g_norm } else { 1.0 };
    if settings.anchor_motion {
        let a = ANCHOR_ACCELERATION * reference;
        for i in 0..d {
            for sign in [1.0, -1.0] {
                let mut gi = g;
                gi[i] -= sign * a;
                cases.push(case(format!("anchor accelerating at {:+} m/s^2 along {}", sign * a, AXES[i]), gi, p, [0.0; 3]));
            }
        }
    }
    if settings.anchor_rotation {
        let omega = (SPIN_ACCELERATION * reference / scene.length_scale().max(f64::MIN_POSITIVE)).sqrt();
        let axes: &[usize] = if d == 2 { &[2] } else { &[0, 1, 2] };
        for &i in axes {
            let spin: [f64; 3] = std::array::from_fn(|k| if k == i { omega } else { 0.0 });
            cases.push(case(format!("holder jerked into a spin of {omega:.3} rad/s about {}", AXES[i]), g, p, spin));
        }
    }
    if settings.anchor_motion {
        // Every other holder pulled away from its place either way along each axis: the sheet stretched between them.
        let shift = HOLDER_SHIFT * scene.length_scale();
        for j in 0..scene.moving_holders().len() {
            for i in 0..d {
                for sign in [1.0, -1.0] {
                    let moved: [f64; 3] = std::array::from_fn(|k| if k == i { sign * shift } else { 0.0 });
                    let label = format!("holder {} moved {:+.3} m along {}", j + 2, sign * shift, AXES[i]);
                    cases.push(Case { holder: Some((j, moved)), ..case(label, g, p, [0.0; 3]) });
                }
            }
        }
    }
    Ok(cases)
}

const AXES: [&str; 3] = ["x", "y", "z"];

/// The axes gravity `g` tilts about: z in 2D; in 3D the two unit axes
/// normal to g, the first also normal to the coordinate axis g is least
/// aligned with.
fn tilt_axes(g: &[f64; 3], d: usize) -> Vec<(String, [f64; 3])> {
    if d == 2 {
        return vec![("z".into(), [0.0, 0.0, 1.0])];
    }
    let least = (0..3).min_by(|&a, &b| g[a].abs().total_cmp(&g[b].abs())).expect("three axes");
    let e: [f64; 3] = std::array::from_fn(|k| if k == least { 1.0 } else { 0.0 });
    let unit = |v: [f64; 3]| -> [f64; 3] {
        let n = norm(&v);
        std::array::from_fn(|k| v[k] / n)
    };
    let a1 = unit(cross(g, &e));
    let a2 = unit(cross(g, &a1));
    let name = |a: &[f64; 3]| -> String {
        match (0..3).find(|&k| (dot(a, a) - a[k] * a[k]).abs() < 1e-12) {
            Some(k) => AXES[k].into(),
            None => format!("({:.2}, {:.2}, {:.2})", a[0], a[1], a[2]),
        }
    };
    vec![(name(&a1), a1), (name(&a2), a2)]
}

/// The snapshots of the training program: one column of D (the
/// displacements from `point`, free DOFs) per sample, every run in turn.
pub fn snapshots(scene: &Scene, loads: &Loads, settings: &Settings, point: &[f64]) -> Result<Vec<Vec<f64>>, PhysicsError> {
    let cases = program(scene, loads, settings)?;
    let full_settings = Settings { reduction: Reduction::Full, n_modes: 0, ..settings.clone() };
    let space = Full::new(scene.clone(), loads, &full_settings)?;
    let n = scene.n_dofs();
    let mut columns = Vec::with_capacity(cases.len() * SAMPLES);
    for case in &cases {
        let run_loads = Loads {
            gravity: case.gravity,
            point_load: case.point_load,
            anchor: [0.0; 3],
            rotation: [0.0; 3],
            mode_weights: Vec::new(),
            damping_alpha: 0.0,
            damping_beta: 0.0,
            ..loads.clone()
        };
        let mut w = space.work(&run_loads);
        let mut buf = Buffers::new(n, NewmarkExplicit::SCRATCH);
        let mut state = State::at_rest(n);
        space.apply_loads(&mut w);
        if let Some((j, moved)) = case.holder {
            let at: Vec<Placement> = (0..scene.moving_holders().len()).map(|k| Placement::new(if k == j { moved } else { [0.0; 3] }, &[0.0; 3])).collect();
            holders::place(scene, &Placement::new([0.0; 3], &[0.0; 3]), &at, space.slots_mut(&mut w));
        }
        if case.spin != [0.0; 3] {
            // In the holder's frame the sheet at rest gets -Ω x ρ at once.
            space.turn(&Frame { gravity: case.gravity, load: case.point_load, spin: case.spin }, &mut w);
            let back: [f64; 3] = std::array::from_fn(|i| -case.spin[i]);
            space.add_rotation_rate(&w, &back, &state.y, &mut state.v);
        }
        let diverged = |time: f64| PhysicsError::TrainingDiverged { case: case.label.clone(), time };
        let stable = NewmarkExplicit::stable_step(space.omega_sq_bound(&w)).ok_or_else(|| diverged(0.0))?;
        let time = settings.training.time;
        let steps = ((time / stable).ceil() as usize).max(SAMPLES);
        let dt = time / steps as f64;
        NewmarkExplicit::settle(&space, &mut w, &mut buf, &mut state);
        let mut next = 1;
        for step in 1..=steps {
            let failed = NewmarkExplicit::step(&space, &mut w, &mut buf, &mut state, dt).is_err();
            if failed || !state.y.iter().chain(&state.v).all(|z| z.is_finite()) {
                return Err(diverged(step as f64 * dt));
            }
            // Sample j at the step nearest j time / SAMPLES.
            if step * SAMPLES >= next * steps {
                columns.push((0..n).map(|k| scene.rest[k] + state.y[k] - point[k]).collect());
                next += 1;
            }
        }
    }
    Ok(columns)
}

/// The first `count` mass-weighted principal components of `columns`
/// (see the module documentation), as vectors over the free DOFs.
pub fn principal_components(mass: &[f64], columns: &[Vec<f64>], count: usize) -> Result<Vec<Vec<f64>>, PhysicsError> {
    let (n, m) = (mass.len(), columns.len());
    let root: Vec<f64> = mass.iter().map(|m| m.sqrt()).collect();
    let weighted = Mat::<f64>::from_fn(n, m, |i, j| root[i] * columns[j][i]);
    let svd = weighted
        .thin_svd()
        .map_err(|e| PhysicsError::LinearAlgebra { what: "singular value decomposition of the training snapshots", detail: format!("{e:?}") })?;
    let (u, s) = (svd.U(), svd.S());
    // Components in the order of their singular values, largest first.
    let mut order: Vec<usize> = (0..u.ncols()).collect();
    order.sort_by(|&a, &b| s[b].total_cmp(&s[a]));
    let largest = order.first().map_or(0.0, |&j| s[j]);
    Ok(order.into_iter().take(count).filter(|&j| s[j] > 1e-12 * largest).map(|j| (0..n).map(|i| u[(i, j)] / root[i]).collect()).collect())
}

/// The costly part of a trained set-up, as data for `Modal::new`: the
/// basis of `settings.n_modes` vectors from the training program's
/// snapshots, its range, and with cubature forces the cubature trained on
/// the same snapshots.
pub fn train(scene: Scene, loads: &Loads, settings: &Settings) -> Result<SetupData, PhysicsError> {
    let r = settings.n_modes;
    let n = scene.n_dofs();
    if r > n {
        return Err(PhysicsError::ModesExceedDofs { modes: r, dofs: n });
    }
    let (point, pattern, stiffness) = basis::linearize(&scene, loads, settings)?;
    let columns = snapshots(&scene, loads, settings, &point)?;
    let at = Linearized { point, pattern: &pattern, stiffness: &stiffness };
    let statics = fixed_vectors(&scene, loads, settings, &at)?;
    train_on(scene, loads, settings, at, statics, &columns)
}

/// Where a basis is linearized: the point x*, and the stiffness K(x*) on its pattern.
pub struct Linearized<'a> {
    pub point: Vec<f64>,
    pub pattern: &'a StiffnessPattern,
    pub stiffness: &'a [f64],
}

/// The vectors a trained basis keeps whatever its snapshots: the static
/// correction's (with `static_correction`) and the holders' constraint modes.
pub fn fixed_vectors(scene: &Scene, loads: &Loads, settings: &Settings, at: &Linearized) -> Result<Vec<Vec<f64>>, PhysicsError> {
    let mut statics = if settings.static_correction {
        let patterns = load_patterns(scene, loads, settings.anchor_motion, settings.anchor_rotation);
        if patterns.is_empty() {
            return Err(PhysicsError::NoLoad);
        }
        basis::static_vectors(scene, at.pattern, at.stiffness, &at.point, &patterns, settings)?
    } else {
        Vec::new()
    };
    statics.extend(basis::constraint_vectors(scene, at.pattern, at.stiffness, &at.point, settings)?);
    Ok(statics)
}

/// [`train`] on snapshots `columns` (displacements from `at.point`) already
/// taken, keeping `statics` (see [`fixed_vectors`]) among the `settings.n_modes` vectors.
pub fn train_on(
    scene: Scene,
    loads: &Loads,
    settings: &Settings,
    at: Linearized,
    statics: Vec<Vec<f64>>,
    columns: &[Vec<f64>],
) -> Result<SetupData, PhysicsError> {
    let r = settings.n_modes;
    let Linearized { point, pattern, stiffness } = at;
    let p = statics.len().min(r);
    // A few more components than needed stand in for static responses the components already hold.
    let components = principal_components(&scene.dof_mass, columns, r + p)?;
    let mut vectors: Vec<Vec<f64>> = components[..(r - p).min(components.len())].to_vec();
    vectors.extend(statics);
    vectors.extend(components.iter().skip(r - p).cloned());
    let modes = basis::orthonormal_ritz(&scene, pattern, stiffness, &vectors, r)?;
    let omega_sq_bound = basis_bound(&scene, &modes)?;
    let poses: Vec<Vec<f64>> = columns
        .iter()
        .map(|dcol| {
            let mut q = vec![0.0; r];
            modes.project_displacement(&scene.dof_mass, dcol, &mut q);
            q
        })
        .collect();
    let range = TrainedRange::of(&poses, r);
    let at_rest = settings.linearization == Linearization::Rest;
    let data = SetupData { basis: modes, point, at_rest, omega_sq_bound, cubature: None, range: Some(range), adaptive: None };
    if settings.force_evaluation == ForceEvaluation::Cubature {
        return cubature_training::train(scene, loads, settings, Some(&data), Some(&poses));
    }
    Ok(data)
}
