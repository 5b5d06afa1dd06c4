//! The trigonometric integrator (`integrator = trigonometric`,
//! `docs/method.md`, section 4): its propagator against the matrix
//! exponential in every damping regime; exact runs of a linear space at any
//! step and its static solution as a fixed point (modal runs of the sheet:
//! `trigonometric_runs.rs`).

use modal_mass_spring::physics::error::StepFailure;
use modal_mass_spring::physics::run::frame::{Frame, Moments};
use modal_mass_spring::physics::run::integrator::{Buffers, Propagator, Scheme, Trigonometric};
use modal_mass_spring::physics::run::simulator::Run;
use modal_mass_spring::physics::run::space::{Constants, Diagonal, Layout, Readout, Space};
use modal_mass_spring::physics::*;

// ---------------------------------------------------------------------------
// The exact oscillator, by another road: exp(t M) of the augmented system
// (y, v, 1)' = M (y, v, 1), M = [[0, 1, 0], [-lambda, -c, b], [0, 0, 0]],
// by scaling and squaring of its Taylor series.

type M3 = [[f64; 3]; 3];

fn mul(a: &M3, b: &M3) -> M3 {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

fn expm(m: &M3) -> M3 {
    let norm = m.iter().map(|r| r.iter().map(|x| x.abs()).sum::<f64>()).fold(0.0, f64::max);
    let squarings = if norm > 0.25 { (norm / 0.25).log2().ceil() as i32 } else { 0 };
    let s = 0.5f64.powi(squarings);
    let a: M3 = std::array::from_fn(|i| std::array::from_fn(|j| m[i][j] * s));
    let mut sum: M3 = std::array::from_fn(|i| std::array::from_fn(|j| if i == j { 1.0 } else { 0.0 }));
    let mut term = sum;
    for k in 1..30 {
        term = mul(&term, &a);
        for row in term.iter_mut() {
            for x in row.iter_mut() {
                *x /= k as f64;
            }
        }
        for i in 0..3 {
            for j in 0..3 {
                sum[i][j] += term[i][j];
            }
        }
    }
    for _ in 0..squarings {
        sum = mul(&sum, &sum);
    }
    sum
}

/// exp(t M) for lambda, c and the load b, balanced: computed for the rate
/// in units of w = max(sqrt(lambda), 1/t), where every entry of t M is at most
/// of the order of t omega and t c.
fn propagate(lambda: f64, c: f64, b: f64, t: f64) -> M3 {
    let w = lambda.sqrt().max(1.0 / t);
    let e = expm(&[[0.0, t * w, 0.0], [-lambda * t / w, -c * t, b * t / w], [0.0, 0.0, 0.0]]);
    [[e[0][0], e[0][1] / w, e[0][2]], [e[1][0] * w, e[1][1], e[1][2] * w], [0.0, 0.0, 1.0]]
}

/// (y(t), v(t)) of y'' + c y' + lambda y = b from (y0, v0).
fn exact(lambda: f64, c: f64, b: f64, y0: f64, v0: f64, t: f64) -> (f64, f64) {
    let e = propagate(lambda, c, b, t);
    (e[0][0] * y0 + e[0][1] * v0 + e[0][2], e[1][0] * y0 + e[1][1] * v0 + e[1][2])
}

/// One step of `p` on (y, v) under the constant load b.
fn apply(p: &Propagator, b: f64, y: f64, v: f64) -> (f64, f64) {
    (p.yy * y + p.yv * v + p.yg * b, p.vy * y + p.vv * v + p.yv * b)
}

/// Every regime of the propagator (short steps, oscillating, near
/// critical, strongly overdamped, lambda = 0 with and without damping)
/// and the boundaries between its three forms: each entry as exp(dt M)
/// gives it, to round-off, measured in the natural units of the entry.
#[test]
fn the_propagator_is_the_exact_damped_oscillator_in_every_regime() {
    let dt = 0.02;
    let a_values = [0.0, 1e-9, 1e-4, 0.3, 0.999, 1.0, 1.001, 2.0, 9.0, 30.0, 300.0, 1e4];
    let b_values = [0.0, 1e-6, 0.01, 0.5, 1.0, 1.99, 2.0, 2.01, 3.0, 10.0, 60.0, 1e3];
    let mut worst = (0.0f64, 0.0, 0.0);
    for &a in &a_values {
        for &bb in &b_values {
            let (lambda, c) = (a / (dt * dt), bb / dt);
            let p = Propagator::new(lambda, c, dt);
            // Units: a unit displacement and its rate, a rate of the time scale
            // min(dt, 1/omega), and the response to a unit load.
            let e = propagate(lambda, c, 1.0, dt);
            let w = a.sqrt().max(1.0);
            let pairs = [
                (p.yy, e[0][0], 1.0),
                (p.yv, e[0][1], dt / w),
                (p.vy, e[1][0], w / dt),
                (p.vv, e[1][1], 1.0),
                (p.yg, e[0][2], dt * dt / (w * w)),
                (p.yv, e[1][2], dt / w),
            ];
            // The reference loses about a bit per squaring: its error grows as the norm of dt M.
            let tolerance = 1e-14 * a.sqrt().max(bb).max(1.0);
            for (got, want, unit) in pairs {
                let err = (got - want).abs() / unit;
                assert!(err < tolerance, "a = {a}, b = {bb}: {got:e} against {want:e} (error {err:e} of the unit {unit:e})");
                if err / tolerance > worst.0 {
                    worst = (err / tolerance, a, bb);
                }
            }
            assert!((p.filter - if a > 0.0 { a.sqrt().sin() / a.sqrt() } else { 1.0 }).abs() < 1e-15);
        }
    }
    println!("largest error of a propagator entry: {:.2} of the tolerance (a = {}, b = {})", worst.0, worst.1, worst.2);
    // Stiff coordinates far beyond any step: bounded, and the static response exact.
    for (lambda, c) in [(1e15, 0.0), (1e15, 1e11), (1e12, 1e9), (0.0, 1e12)] {
        let p = Propagator::new(lambda, c, 0.01);
        let entries = [p.yy, p.yv, p.yg, p.vy, p.vv, p.filter, p.kick];
        assert!(entries.iter().all(|x| x.is_finite()), "lambda {lambda:e}, c {c:e}: {p:?}");
        if lambda > 0.0 {
            let (y, v) = apply(&p, 1.0, 1.0 / lambda, 0.0);
            assert!((y * lambda - 1.0).abs() < 1e-12 && (v * lambda).abs() < 1e-6, "static response: {y:e}, {v:e}");
        }
    }
    // The rate filter is bounded at every xi (near odd multiples of pi too) and 1 at 0.
    let mut largest = 0.0f64;
    for k in 0..200_000 {
        let xi = 1e-4 + k as f64 * 1e-4 * std::f64::consts::PI;
        largest = largest.max(Propagator::new(xi * xi, 0.0, 1.0).kick.abs());
    }
    assert!(largest < 1.35, "rate filter up to {largest}");
    assert!((Propagator::new(1e-12, 0.0, 1.0).kick - 1.0).abs() < 1e-12);
}

// ---------------------------------------------------------------------------
// A linear space: independent damped oscillators under constant loads,
// h_i(y) = w_i b_i - lambda_i y_i (every coordinate a mode whose springs are
// linear), with the weights and Rayleigh damping of the modal space.

struct Linear {
    scene: Scene,
    lambda: Vec<f64>,
    /// Generalized load before the weights.
    load: Vec<f64>,
    frequencies: Vec<f64>,
    /// Force evaluations so far.
    evaluations: std::cell::Cell<usize>,
}

struct LinearWork {
    loads: Loads,
    slots: Vec<f64>,
    damping: Vec<f64>,
    load: Vec<f64>,
}

impl AsRef<Loads> for LinearWork {
    fn as_ref(&self) -> &Loads {
        &self.loads
    }
}

impl AsMut<Loads> for LinearWork {
    fn as_mut(&mut self) -> &mut Loads {
        &mut self.loads
    }
}

impl Linear {
    fn new(lambda: &[f64], load: &[f64]) -> Self {
        let scene =
            Scene { dim: 2, n_nodes: 1, n_free: 1, slot_of_node: vec![0], rest: vec![0.0, 0.0], dof_mass: vec![1.0, 1.0], springs: vec![], holders: vec![] };
        Linear {
            scene,
            lambda: lambda.to_vec(),
            load: load.to_vec(),
            frequencies: lambda.iter().map(|l| l.sqrt()).collect(),
            evaluations: std::cell::Cell::new(0),
        }
    }
}

impl Constants for Linear {
    fn scene(&self) -> &Scene {
        &self.scene
    }

    fn layout(&self) -> Layout<'_> {
        let n = self.lambda.len();
        Layout { scene: &self.scene, coordinates: n, kept_modes: Some(n), springs: 0, frequencies: &self.frequencies, trained: None, newton_scale: 1.0 }
    }

    fn rest_coordinates(&self, y: &mut [f64]) {
        y.fill(0.0);
    }
}

impl Space for Linear {
    type Work = LinearWork;

    fn work(&self, loads: &Loads) -> LinearWork {
        LinearWork { slots: self.scene.rest.clone(), loads: loads.clone(), damping: vec![0.0; self.lambda.len()], load: vec![0.0; self.lambda.len()] }
    }

    fn apply_loads(&self, w: &mut LinearWork) {
        for i in 0..self.lambda.len() {
            w.damping[i] = w.loads.damping_alpha + w.loads.damping_beta * self.lambda[i];
            w.load[i] = w.loads.mode_weights[i] * self.load[i];
        }
    }

    fn slots_mut<'w>(&self, w: &'w mut LinearWork) -> &'w mut [f64] {
        &mut w.slots
    }

    fn force(&self, y: &[f64], w: &mut LinearWork, h: &mut [f64]) {
        self.evaluations.set(self.evaluations.get() + 1);
        for i in 0..y.len() {
            h[i] = w.load[i] - self.lambda[i] * y[i];
        }
    }

    fn explicit_velocity(&self, _dt: f64, _v: &[f64], _a: &[f64], _h: &[f64], _w: &mut LinearWork, _v1: &mut [f64]) -> Result<(), StepFailure> {
        unreachable!("the trigonometric scheme only")
    }

    fn acceleration(&self, v: &[f64], h: &[f64], w: &mut LinearWork, a: &mut [f64]) {
        for i in 0..v.len() {
            a[i] = h[i] - w.damping[i] * v[i];
        }
    }

    fn residual(&self, _v: &[f64], _a: &[f64], _h: &[f64], _w: &mut LinearWork, _r: &mut [f64]) {
        unreachable!("the trigonometric scheme only")
    }

    fn factor(&self, _c_m: f64, _c_c: f64, _w: &mut LinearWork) -> Result<(), StepFailure> {
        unreachable!("the trigonometric scheme only")
    }

    fn solve(&self, _w: &mut LinearWork, _rhs: &mut [f64]) {
        unreachable!("the trigonometric scheme only")
    }

    fn omega_sq_bound(&self, _w: &LinearWork) -> f64 {
        self.lambda.iter().fold(0.0, |m, &l| m.max(l))
    }

    fn diagonal<'a>(&'a self, w: &'a LinearWork) -> Option<Diagonal<'a>> {
        Some(Diagonal { stiffness: &self.lambda, damping: &w.damping, load: &w.load })
    }

    fn add_translation_rate(&self, _w: &LinearWork, _c: &[f64; 3], _v: &mut [f64]) {}

    fn add_rotation_rate(&self, _w: &LinearWork, _c: &[f64; 3], _y: &[f64], _v: &mut [f64]) {}

    fn turn(&self, _frame: &Frame, _w: &mut LinearWork) {}
}

impl Readout for Linear {
    fn spring_force(&self, y: &[f64], _w: &mut LinearWork, out: &mut [f64]) {
        for i in 0..y.len() {
            out[i] = -self.lambda[i] * y[i];
        }
    }
    fn positions<'w>(&self, _y: &[f64], _w: &'w mut LinearWork) -> &'w [f64] {
        &[]
    }
    fn slot_velocity(&self, _v: &[f64], _slot: usize) -> [f64; 3] {
        [0.0; 3]
    }
    fn elastic_energy(&self, y: &[f64], _w: &mut LinearWork) -> f64 {
        y.iter().zip(&self.lambda).map(|(y, l)| 0.5 * l * y * y).sum()
    }
    fn gravity_potential(&self, y: &[f64], w: &LinearWork) -> f64 {
        -y.iter().zip(&w.load).map(|(y, b)| y * b).sum::<f64>()
    }
    fn kinetic_energy(&self, v: &[f64]) -> f64 {
        0.5 * v.iter().map(|v| v * v).sum::<f64>()
    }
    fn momentum(&self, _v: &[f64]) -> [f64; 3] {
        [0.0; 3]
    }
    fn first_moment(&self, _y: &[f64]) -> [f64; 3] {
        [0.0; 3]
    }
    fn moments(&self, _y: &[f64], _v: &[f64]) -> Moments {
        Moments::default()
    }
    fn dof_velocities(&self, _v: &[f64], _out: &mut [f64]) {}
    fn modal_coordinates(&self, y: &[f64], out: &mut [f64]) {
        out.copy_from_slice(y);
    }
    fn force_residual(&self, _gravity: &[f64; 3], _point: &[f64; 3], _y: &[f64], _w: &mut LinearWork) -> f64 {
        0.0
    }
}
/// Stiffnesses of the linear space: a free coordinate, slow, middle and
/// fast ones (omega = 0, 2, 10, 50, 100 rad/s).
const LAMBDA: [f64; 5] = [0.0, 4.0, 100.0, 2500.0, 1e4];
const LOAD: [f64; 5] = [0.3, -2.0, 30.0, 500.0, -800.0];

fn linear_loads(alpha: f64, beta: f64, weights: &[f64]) -> Loads {
    Loads { damping_alpha: alpha, damping_beta: beta, mode_weights: weights.to_vec(), ..Loads::physical(weights.len()) }
}

/// `steps` steps of `dt` of the linear space from (y0, v0), after a settle
/// as at the start of a run; (y, v) after each step.
fn linear_run(loads: &Loads, y0: &[f64], v0: &[f64], dt: f64, steps: usize) -> Vec<(Vec<f64>, Vec<f64>)> {
    let space = Linear::new(&LAMBDA, &LOAD);
    let mut w = space.work(loads);
    space.apply_loads(&mut w);
    let mut buf = Buffers::new(LAMBDA.len(), Trigonometric::SCRATCH);
    let mut state = State::at_rest(LAMBDA.len());
    state.y.copy_from_slice(y0);
    state.v.copy_from_slice(v0);
    Trigonometric::settle(&space, &mut w, &mut buf, &mut state);
    let mut out = Vec::new();
    for _ in 0..steps {
        Trigonometric::step(&space, &mut w, &mut buf, &mut state, dt).unwrap();
        out.push((state.y.clone(), state.v.clone()));
    }
    out
}

/// A linear problem (the part of the force beyond each mode's own spring
/// is the constant load) runs as the exact solution of every damped
/// oscillator, to round-off, at any step: short, xi = pi and 2 pi for the
/// fast coordinates, and far beyond every period. Weight 0 leaves a
/// coordinate its free oscillation (at rest: 0); weight 2 doubles its load.
#[test]
fn a_linear_space_runs_the_exact_oscillators_at_any_step() {
    let weights = [1.0, 2.0, 1.0, 0.0, 0.5];
    let y0 = [0.01, -0.02, 0.3, 0.05, -0.04];
    let v0 = [0.1, 0.2, -1.0, 3.0, 2.0];
    let pi = std::f64::consts::PI;
    let mut worst = 0.0f64;
    for (alpha, beta) in [(0.0, 0.0), (0.5, 1e-3), (3.0, 0.05)] {
        let loads = linear_loads(alpha, beta, &weights);
        for dt in [0.001, 0.02, pi / 50.0, 2.0 * pi / 100.0, pi / 100.0 * 3.0, 0.37, 2.5] {
            let steps = 60;
            let run = linear_run(&loads, &y0, &v0, dt, steps);
            for (n, (y, v)) in run.iter().enumerate() {
                let t = dt * (n + 1) as f64;
                for i in 0..LAMBDA.len() {
                    let c = alpha + beta * LAMBDA[i];
                    let (ye, ve) = exact(LAMBDA[i], c, weights[i] * LOAD[i], y0[i], v0[i], t);
                    // Scale: the amplitude of the coordinate (its oscillation about the static
                    // displacement, or the distance a free one has gone) and of its rate.
                    let omega = LAMBDA[i].sqrt();
                    let b = weights[i] * LOAD[i];
                    let scale = y0[i].abs() + v0[i].abs() * t.min(1.0 / omega) + b.abs() * (t * t).min(1.0 / LAMBDA[i]) + ye.abs();
                    let err = ((y[i] - ye).abs() / scale).max((v[i] - ve).abs() / (scale * omega.max(1.0 / t) + ve.abs()));
                    worst = worst.max(err);
                    assert!(
                        err < 1e-11,
                        "alpha {alpha}, beta {beta}, dt {dt}, step {n}, coordinate {i}: y {:e} against {ye:e}, v {:e} against {ve:e}",
                        y[i],
                        v[i]
                    );
                }
            }
        }
    }
    println!("largest relative difference from the exact oscillators: {worst:.2e}");
    // A deleted coordinate at rest stays exactly at rest.
    let run = linear_run(&linear_loads(0.2, 1e-3, &weights), &[0.0; 5], &[0.0; 5], 0.02, 100);
    assert!(run.iter().all(|(y, v)| y[3] == 0.0 && v[3] == 0.0), "a deleted mode moved");
}

/// The static solution of the linear part, y = w b / lambda, is a fixed
/// point of the scheme at any step (xi = pi, 2 pi, far beyond), and a
/// damped run from rest settles on it.
#[test]
fn the_static_solution_is_a_fixed_point_at_any_step() {
    let weights = [1.0, 2.0, 1.0, 1.0, 0.5];
    let statics: Vec<f64> = (1..5).map(|i| weights[i] * LOAD[i] / LAMBDA[i]).collect();
    let pi = std::f64::consts::PI;
    for dt in [0.001, 0.02, pi / 50.0, 2.0 * pi / 100.0, 0.37, 10.0] {
        for (alpha, beta) in [(0.0, 0.0), (0.5, 1e-3)] {
            let loads = linear_loads(alpha, beta, &weights);
            let mut y0 = vec![0.0];
            y0.extend(&statics);
            let run = linear_run(&loads, &y0, &[0.0; 5], dt, 50);
            let (y, v) = run.last().unwrap();
            for i in 1..5 {
                assert!((y[i] - statics[i - 1]).abs() <= 1e-14 * statics[i - 1].abs(), "dt {dt}, coordinate {i}: {:e} from {:e}", y[i], statics[i - 1]);
                assert!(v[i].abs() <= 1e-12 * statics[i - 1].abs() * LAMBDA[i].sqrt(), "dt {dt}, coordinate {i}: rate {:e}", v[i]);
            }
        }
    }
    // From rest under damping, at a step far beyond every period.
    let loads = linear_loads(2.0, 0.01, &weights);
    let run = linear_run(&loads, &[0.0; 5], &[0.0; 5], 0.5, 200);
    let (y, _) = run.last().unwrap();
    for i in 1..5 {
        assert!((y[i] - statics[i - 1]).abs() <= 1e-12 * statics[i - 1].abs(), "coordinate {i}: {:e} from {:e}", y[i], statics[i - 1]);
    }
}

// ---------------------------------------------------------------------------
// The modal space.

/// Load modes with a static correction (at rest).

/// One force evaluation per internal step, at the filtered coordinates:
/// the forces at the state are evaluated once, when an output first needs
/// them (here the potential energy), and the step guard's energy needs none.
#[test]
fn one_force_evaluation_per_step_until_an_output_needs_the_forces() {
    let loads = linear_loads(0.5, 1e-3, &[1.0; 5]);
    let settings = Settings::new(Reduction::Modal, Integrator::Trigonometric, LAMBDA.len());
    let mut run = Run::<Linear, Trigonometric>::new(Linear::new(&LAMBDA, &LOAD), &settings, &loads).unwrap();
    // Away from rest, so that the step guard has an energy to weigh growth against.
    run.displace(&[0.1; 5]).unwrap();
    run.do_step(0.01).unwrap();
    let count = |r: &Run<Linear, Trigonometric>| r.space().evaluations.get();
    let start = count(&run);
    for _ in 0..10 {
        // One internal step per call; the guard weighs the force model's energy each time.
        run.do_step(0.01).unwrap();
        assert_eq!(run.internal_steps_last(), 1);
    }
    assert_eq!(count(&run) - start, 10, "one evaluation per step, none for the guard");
    let e1 = run.potential_energy();
    assert_eq!(count(&run) - start, 11, "the potential energy evaluates the forces at the state");
    let e2 = run.potential_energy();
    assert_eq!((count(&run) - start, e1), (11, e2), "and only once");
}
