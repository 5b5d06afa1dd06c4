//! Anchor motion (anchorX, anchorY, anchorZ; `docs/method.md`, section 8):
//! the sheet integrated in the anchor's frame against an independent
//! integration in the ground's frame, the equivalence principle, every
//! mode against the full space, resonance at a mode's frequency (and none
//! at a deleted mode), the load patterns of a moving anchor, and the FMI
//! interface (refusals, fmi3Discard, FMU state).

use crate::common;

use common::*;
use modal_mass_spring::canonical_scenes::{self, Setup};
use modal_mass_spring::fmi::variables::vr;
use modal_mass_spring::physics::*;

/// The paper's 2D scene on a `columns` x `rows` grid with `solver`.
fn small(columns: usize, rows: usize, solver: Settings) -> Setup {
    let mut setup = canonical_scenes::canonical("paper-2d-top-row").unwrap();
    setup.grid.columns = columns;
    setup.grid.rows = rows;
    setup.loads.load_node = None;
    setup.with_settings(solver)
}

fn full(max_internal_step: f64) -> Settings {
    let mut s = Settings::new(Reduction::Full, Integrator::NewmarkExplicit, 0);
    s.max_internal_step = max_internal_step;
    s
}

/// The anchor's target at the end of a step ending at `t`: a swing
/// (2 cm along x, 1 cm up and back) at 5 rad/s.
fn swing(t: f64) -> [f64; 3] {
    let w = 5.0;
    [0.02 * (w * t).sin(), 0.01 * (1.0 - (w * t).cos()), 0.0]
}

/// Runs `sim` for `steps` communication steps of `h`, the anchor's target
/// set to `path(end of step)` before each; node positions after each step.
fn drive(sim: &mut Simulator, steps: usize, h: f64, path: impl Fn(f64) -> [f64; 3]) -> Vec<Vec<f64>> {
    let mut out = Vec::new();
    for k in 0..steps {
        let mut loads = sim.loads().clone();
        loads.anchor = path((k + 1) as f64 * h);
        sim.set_loads(&loads).unwrap();
        sim.do_step(h).unwrap();
        out.push(sim.positions().to_vec());
    }
    out
}

/// Slot accelerations in the ground's frame: every spring, gravity, and
/// mass-proportional damping of the velocity relative to the anchor.
fn ground_accel(scene: &Scene, loads: &Loads, x: &[f64], v: &[f64], anchor_rate: &[f64; 3], a: &mut [f64]) {
    let (d, n) = (scene.dim, scene.n_dofs());
    let mut f = vec![0.0; x.len()];
    for s in &scene.springs {
        let diff: Vec<f64> = (0..d).map(|i| x[s.b * d + i] - x[s.a * d + i]).collect();
        let l = diff.iter().map(|c| c * c).sum::<f64>().sqrt();
        let t = s.k * (l - s.rest) / l;
        for i in 0..d {
            f[s.a * d + i] += t * diff[i];
            f[s.b * d + i] -= t * diff[i];
        }
    }
    for k in 0..n {
        let m = scene.dof_mass[k];
        a[k] = f[k] / m + loads.gravity[k % d] - loads.damping_alpha * (v[k] - anchor_rate[k % d]);
    }
}

/// The free slots' positions integrated in the ground's frame by classical
/// Runge-Kutta (steps of `dt`), every held point (nodes and the anchor
/// points of auxiliary springs) moved linearly between the targets `path`
/// gives at the communication points, as the FMU defines the anchor's
/// motion; node positions after each communication step.
fn reference(scene: &Scene, loads: &Loads, steps: usize, h: f64, dt: f64, path: impl Fn(f64) -> [f64; 3]) -> Vec<Vec<f64>> {
    let (d, n) = (scene.dim, scene.n_dofs());
    let mut x = scene.rest.clone();
    let mut v = vec![0.0; n];
    let sub = (h / dt).round() as usize;
    let dt = h / sub as f64;
    let mut out = Vec::new();
    let mut from = [0.0; 3];
    for k in 0..steps {
        let to = path((k + 1) as f64 * h);
        let rate: [f64; 3] = std::array::from_fn(|i| (to[i] - from[i]) / h);
        let start = from;
        let held = |x: &mut [f64], s: f64| {
            for j in n..x.len() {
                x[j] = scene.rest[j] + start[j % d] + rate[j % d] * s;
            }
        };
        for i in 0..sub {
            let s0 = i as f64 * dt;
            let eval = |xs: &[f64], vs: &[f64], s: f64, a: &mut [f64]| {
                let mut xf = xs.to_vec();
                held(&mut xf, s);
                ground_accel(scene, loads, &xf, vs, &rate, a);
            };
            let (mut k1, mut k2, mut k3, mut k4) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
            let shifted = |x: &[f64], v: &[f64], c: f64| -> Vec<f64> {
                let mut y = x.to_vec();
                for j in 0..n {
                    y[j] += c * v[j];
                }
                y
            };
            eval(&x, &v, s0, &mut k1);
            let (x2, v2) = (shifted(&x, &v, dt / 2.0), (0..n).map(|j| v[j] + dt / 2.0 * k1[j]).collect::<Vec<_>>());
            eval(&x2, &v2, s0 + dt / 2.0, &mut k2);
            let (x3, v3) = (shifted(&x, &v2, dt / 2.0), (0..n).map(|j| v[j] + dt / 2.0 * k2[j]).collect::<Vec<_>>());
            eval(&x3, &v3, s0 + dt / 2.0, &mut k3);
            let (x4, v4) = (shifted(&x, &v3, dt), (0..n).map(|j| v[j] + dt * k3[j]).collect::<Vec<_>>());
            eval(&x4, &v4, s0 + dt, &mut k4);
            for j in 0..n {
                x[j] += dt / 6.0 * (v[j] + 2.0 * v2[j] + 2.0 * v3[j] + v4[j]);
                v[j] += dt / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
            }
        }
        held(&mut x, h);
        from = to;
        let mut nodes = vec![0.0; scene.n_nodes * d];
        for (node, &slot) in scene.slot_of_node.iter().enumerate() {
            nodes[node * d..node * d + d].copy_from_slice(&x[slot * d..slot * d + d]);
        }
        out.push(nodes);
    }
    out
}

fn max_diff(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    a.iter().zip(b).flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs())).fold(0.0, f64::max)
}

/// The FMU integrates the sheet in the anchor's frame (a velocity kick when
/// the anchor's velocity changes, relative damping); an integration of the
/// same sheet in the ground's frame, with the held points moved, agrees,
/// and the difference is the explicit scheme's O(dt^2) error. Measured
/// (0.5 s, swing of 2 cm at 5 rad/s, 5 x 4 grid): 6.7e-7 m at dt = 2e-4,
/// 1.7e-7 m at 1e-4.
#[test]
fn the_anchor_frame_matches_an_integration_in_the_ground_frame() {
    let (h, steps) = (0.01, 50);
    let mut errors = Vec::new();
    for dt in [2e-4, 1e-4] {
        let mut setup = small(5, 4, full(dt));
        setup.loads.damping_alpha = 0.5;
        let scene = setup.grid.build().unwrap();
        let want = reference(&scene, &setup.loads, steps, h, 2.5e-5, swing);
        let mut sim = setup.simulator().unwrap();
        let got = drive(&mut sim, steps, h, swing);
        let corner = scene.slot_of_node[4 * 5 - 1] * 2;
        let sway = got.iter().map(|x| (x[(4 * 5 - 1) * 2] - scene.rest[corner]).abs()).fold(0.0, f64::max);
        let err = max_diff(&got, &want);
        println!("dt = {dt:e}: largest difference {err:.3e} m (sway of the bottom corner up to {sway:.3} m)");
        errors.push(err);
    }
    assert!(errors[1] < 1e-6, "anchor frame vs ground frame: {:e} m at dt = 1e-4", errors[1]);
    assert!(errors[0] / errors[1] > 3.0, "the difference does not fall as dt^2: {errors:?}");
}

/// An anchor accelerating at a constant rate gives, relative to the
/// anchor, the motion of a still anchor under gravity g - a. The targets
/// lie on the parabola at every communication point; between them the
/// anchor moves linearly, so the agreement converges as the step shrinks.
#[test]
fn equivalence_principle() {
    let accel = [3.0, 2.0, 0.0];
    for (label, solver) in [
        ("full space", full(1e-3)),
        ("modal, 12 lowest modes", {
            let mut s = Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, 12);
            s.max_internal_step = 1e-3;
            s
        }),
    ] {
        let mut errors = Vec::new();
        for h in [0.02, 0.01, 0.005] {
            let steps = (1.0 / h) as usize;
            let setup = canonical_scenes::canonical("paper-2d-top-row").unwrap().with_settings(solver.clone());
            let mut moving = setup.simulator().unwrap();
            let parabola = |t: f64| [0.5 * accel[0] * t * t, 0.5 * accel[1] * t * t, 0.0];
            let got = drive(&mut moving, steps, h, parabola);
            let mut still_setup = setup.clone();
            still_setup.loads.gravity = [-accel[0], -9.81 - accel[1], 0.0];
            let mut still = still_setup.simulator().unwrap();
            let mut err: f64 = 0.0;
            for (k, x) in got.iter().enumerate() {
                still.do_step(h).unwrap();
                let a = parabola((k + 1) as f64 * h);
                for (i, (xm, xs)) in x.iter().zip(still.positions()).enumerate() {
                    err = err.max((xm - a[i % 2] - xs).abs());
                }
            }
            println!("{label}, h = {h}: largest difference relative to the anchor {err:.3e} m");
            errors.push(err);
        }
        assert!(errors[2] < 0.6 * errors[1] && errors[1] < 0.6 * errors[0], "{label}: does not converge: {errors:?}");
        assert!(errors[2] < 2e-3, "{label}: {:e} m at h = 0.005", errors[2]);
    }
}

/// Every mode kept, the modal space is the full space in other
/// coordinates, with the anchor moving and a point load switched on.
#[test]
fn every_mode_matches_the_full_space_with_anchor_motion_and_a_load() {
    let run = |reduction| {
        let mut solver = Settings::new(reduction, Integrator::NewmarkExplicit, if reduction == Reduction::Modal { 180 } else { 0 });
        solver.max_internal_step = 2e-4;
        let setup = canonical_scenes::canonical("paper-2d-top-row").unwrap().with_settings(solver);
        let mut sim = setup.simulator().unwrap();
        assert!(sim.max_stable_step() == 2e-4);
        let mut trace = Vec::new();
        for k in 0..100 {
            let mut loads = sim.loads().clone();
            loads.anchor = swing((k + 1) as f64 * 0.01);
            if k == 30 {
                loads.point_load = [1.0, -2.0, 0.0];
            }
            sim.set_loads(&loads).unwrap();
            sim.do_step(0.01).unwrap();
            let mut row = sim.positions().to_vec();
            row.extend(sim.velocities());
            row.extend(sim.anchor_force());
            row.push(sim.kinetic_energy());
            row.push(sim.potential_energy());
            trace.push(row);
        }
        trace
    };
    let (modal, full) = (run(Reduction::Modal), run(Reduction::Full));
    let err = max_diff(&modal, &full);
    println!("every mode vs full space with anchor motion and a load: {err:.3e}");
    assert!(err < 1e-9, "{err:e}");
}

/// Amplitude of modal coordinate `j` over a run of `seconds` with the
/// anchor moving as `A sin(omega t)` along x, from the still sheet without
/// gravity (a linear response) and without damping.
fn response(weights: &[f64], j: usize, omega: f64, seconds: f64) -> f64 {
    let mut solver = Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, weights.len());
    solver.max_internal_step = 1e-3;
    let mut setup = canonical_scenes::canonical("paper-2d-top-row").unwrap().with_settings(solver);
    setup.loads.gravity = [0.0; 3];
    setup.loads.mode_weights = weights.to_vec();
    let mut sim = setup.simulator().unwrap();
    let h = 0.005;
    let mut peak: f64 = 0.0;
    for k in 0..(seconds / h) as usize {
        let mut loads = sim.loads().clone();
        loads.anchor = [1e-4 * (omega * (k + 1) as f64 * h).sin(), 0.0, 0.0];
        sim.set_loads(&loads).unwrap();
        sim.do_step(h).unwrap();
        peak = peak.max(sim.modal_coordinates()[j].abs());
    }
    peak
}

/// Harmonic anchor motion at a mode's frequency resonates in that mode;
/// the same at 1.5 times the frequency does not; with the mode's weight at
/// 0 the mode stays at rest.
#[test]
fn harmonic_anchor_motion_resonates_in_its_mode_and_not_in_a_deleted_one() {
    let r = 4;
    let solver = Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, r);
    let setup = canonical_scenes::canonical("paper-2d-top-row").unwrap().with_settings(solver);
    let sim = setup.simulator().unwrap();
    let omegas = sim.mode_frequencies().to_vec();
    // The lowest mode is the sheet swinging sideways: an anchor moving along x drives it.
    let j = 0;
    let seconds = 20.0 * 2.0 * std::f64::consts::PI / omegas[j];
    let ones = vec![1.0; r];
    let at = response(&ones, j, omegas[j], seconds);
    let off = response(&ones, j, 1.5 * omegas[j], seconds);
    let mut deleted = ones.clone();
    deleted[j] = 0.0;
    let gone = response(&deleted, j, omegas[j], seconds);
    println!("mode {j} (omega {:.3} rad/s) over 20 periods: peak {at:.3e} driven at omega, {off:.3e} at 1.5 omega, {gone:e} with weight 0", omegas[j]);
    assert!(at > 10.0 * off, "no resonance: {at:e} at omega, {off:e} at 1.5 omega");
    assert_eq!(gone, 0.0, "a deleted mode moved");
}

/// With `anchorMotion` the basis chosen by the loads holds the static
/// response to a sideways anchor acceleration: 8 load modes with static
/// correction follow a sideways-accelerating anchor far closer to the full
/// space than the same options prepared for gravity alone.
#[test]
fn a_moving_anchor_is_a_load_pattern() {
    let accel = 2.0;
    let path = |t: f64| [0.5 * accel * t * t, 0.0, 0.0];
    let (h, steps) = (0.01, 100);
    let mut reference_solver = full(1e-3);
    reference_solver.max_internal_step = 1e-3;
    let setup = canonical_scenes::canonical("paper-2d-top-row").unwrap();
    let want = drive(&mut setup.with_settings(reference_solver).simulator().unwrap(), steps, h, path);
    let mut errors = Vec::new();
    for anchor_motion in [false, true] {
        let mut solver = Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, 8);
        solver.max_internal_step = 1e-3;
        solver.mode_selection = ModeSelection::Load;
        solver.static_correction = true;
        solver.anchor_motion = anchor_motion;
        let got = drive(&mut setup.with_settings(solver).simulator().unwrap(), steps, h, path);
        let err = max_diff(&got, &want);
        println!("8 load modes + static correction, anchorMotion = {anchor_motion}: largest difference from full space {err:.3e} m");
        errors.push(err);
    }
    assert!(errors[1] < 0.2 * errors[0], "anchorMotion does not help: {errors:?}");
}

#[test]
fn fmi_anchor_inputs_refuse_non_finite_values_and_keep_the_state() {
    let f = Fmu::started();
    assert_eq!(f.set_f64(vr::ANCHOR_X, &[0.01]), OK);
    f.run(3, 0.01);
    let before = f.outputs();
    let state = f.snapshot();
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 2e6] {
        f.refused(f.set_f64(vr::ANCHOR_Y, &[bad]), "anchorY = ");
        assert_eq!(f.f64s(vr::ANCHOR_Y, 1), vec![0.0]);
    }
    assert_eq!(f.outputs(), before, "outputs unchanged");
    assert_eq!(f.snapshot(), state, "state unchanged");
    f.run(1, 0.01);
}

/// A jump of the anchor too fast for one internal step is refused with
/// fmi3Discard; the state is that of before the step, and the run goes on
/// once the anchor's target is back within reach.
#[test]
fn fmi_an_anchor_jump_too_large_is_discarded_and_the_state_kept() {
    let f = Fmu::started();
    f.run(5, 0.01);
    let before = f.outputs();
    let state = f.snapshot();
    let t = f.time();
    assert_eq!(f.set_f64(vr::ANCHOR_X, &[5.0]), OK);
    assert_eq!(f.step(t, 0.01), DISCARD);
    let last = f.messages().last().cloned().unwrap_or_default();
    assert!(last.contains("the anchor's velocity changes by"), "{last}");
    assert_eq!(f.outputs(), before, "outputs unchanged");
    assert_eq!(f.time(), t);
    assert_eq!(f.set_f64(vr::ANCHOR_X, &[0.0]), OK);
    assert_eq!(f.snapshot(), state, "state unchanged");
    f.run(2, 0.01);
}

/// The anchor is where the outputs say: held nodes at rest + anchor, the
/// load node's outputs among the positions, and velocities that include
/// the anchor's. An anchor set before initialization places the sheet.
#[test]
fn fmi_outputs_follow_the_anchor() {
    let f = Fmu::new();
    assert_eq!(f.set_f64(vr::ANCHOR_X, &[0.5]), OK);
    f.init();
    let rest = Fmu::started();
    let (x, x0) = (f.positions(), rest.positions());
    for (a, b) in x.chunks(2).zip(x0.chunks(2)) {
        assert!((a[0] - b[0] - 0.5).abs() < 1e-15 && a[1] == b[1], "the sheet starts shifted with the anchor");
    }
    for k in 1..=10 {
        assert_eq!(f.set_f64(vr::ANCHOR_X, &[0.5 + 0.001 * k as f64]), OK);
        f.run(1, 0.01);
        // read after every step: each step's velocities are computed anew
        let v = f.f64s(vr::VELOCITIES, x0.len());
        assert!((v[0] - 0.1).abs() < 1e-9, "after step {k} held node 0 moves with the anchor: {}", v[0]);
    }
    let x = f.positions();
    let v = f.f64s(vr::VELOCITIES, x.len());
    assert!((x[0] - x0[0] - 0.51).abs() < 1e-12, "held node 0 at rest + anchor: {}", x[0] - x0[0]);
    assert!((v[0] - 0.1).abs() < 1e-9, "held node 0 moves with the anchor: {}", v[0]);
    let node = 95;
    assert_eq!(f.f64s(vr::LOAD_NODE_X, 1)[0], x[node * 2]);
    assert_eq!(f.f64s(vr::LOAD_NODE_V_X, 1)[0], v[node * 2]);
}

/// An FMU state taken while the anchor moves resumes bit for bit, through
/// get/set and through serialization, with the anchor's target changing
/// after the state was taken.
#[test]
fn fmi_state_with_a_moving_anchor_resumes_bit_for_bit() {
    let f = Fmu::started();
    let target = |k: usize| 0.01 * (0.3 * k as f64).sin();
    for k in 0..10 {
        assert_eq!(f.set_f64(vr::ANCHOR_X, &[target(k)]), OK);
        f.run(1, 0.01);
    }
    f.assert_resumes(|f: &Fmu| {
        let mut out = Vec::new();
        for k in 10..30 {
            assert_eq!(f.set_f64(vr::ANCHOR_X, &[target(k)]), OK);
            f.run(1, 0.01);
            out.extend(bits(&f.positions()));
        }
        out
    });
}

/// Held nodes move with the anchor at its rate over the last step, whatever
/// rates came before it, and after a restored state at that state's rate.
#[test]
fn held_nodes_move_at_the_anchor_rate_of_the_step() {
    let mut sim = canonical_scenes::canonical("paper-2d-top-row").unwrap().simulator().unwrap();
    sim.do_step(0.02).unwrap();
    let start = sim.snapshot();
    for (k, target) in [0.01, 0.03, 0.02].into_iter().enumerate() {
        let mut loads = sim.loads().clone();
        loads.anchor[0] = target;
        sim.set_loads(&loads).unwrap();
        let before = sim.snapshot().state.anchor[0];
        sim.do_step(0.02).unwrap();
        let rate = (target - before) / 0.02;
        let held = sim.velocities()[0];
        assert!((held - rate).abs() < 1e-12, "step {k}: held node at {held} m/s, the anchor at {rate} m/s");
    }
    sim.restore(&start).unwrap();
    assert_eq!(sim.velocities()[0], 0.0, "a held node after the restored state");
}

/// The load node's position and velocity and the anchor force, read
/// without the node positions (one node, the springs on the held nodes),
/// are the bits read after the positions, in every space and force model.
#[test]
fn port_outputs_alone_are_the_bits_of_the_full_outputs() {
    let cubature = {
        let mut s = Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, 8);
        s.mode_selection = ModeSelection::Load;
        s.static_correction = true;
        s.linearization = Linearization::Equilibrium;
        s.anchor_motion = true;
        s.force_evaluation = ForceEvaluation::Cubature;
        s
    };
    for (label, solver) in
        [("full space", full(0.01)), ("modal, lowest 6", Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, 6)), ("modal, cubature", cubature)]
    {
        let setup = canonical_scenes::canonical("paper-2d-top-row").unwrap().with_settings(solver);
        let (mut alone, mut after) = (setup.simulator().unwrap(), setup.simulator().unwrap());
        for k in 0..40 {
            for sim in [&mut alone, &mut after] {
                let mut loads = sim.loads().clone();
                loads.anchor = swing((k + 1) as f64 * 0.01);
                loads.point_load = [0.5, -1.0, 0.0];
                sim.set_loads(&loads).unwrap();
                sim.do_step(0.01).unwrap();
            }
            let ports = |sim: &mut Simulator| [sim.load_node_position().unwrap(), sim.load_node_velocity().unwrap(), sim.anchor_force()];
            let a = ports(&mut alone);
            after.positions();
            after.velocities();
            let b = ports(&mut after);
            assert_eq!(a.map(|v| v.map(f64::to_bits)), b.map(|v| v.map(f64::to_bits)), "{label}, step {k}");
        }
    }
}
