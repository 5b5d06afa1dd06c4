//! A holder that turns (`anchorRX`, `anchorRY`, `anchorRZ`; `docs/method.md`,
//! section 8): the sheet integrated in the holder's frame with the
//! centrifugal, Coriolis and Euler forces. A turntable settles in the
//! centrifugal equilibrium of an independent static solve, with the
//! centripetal pull on the holder and no torque; every mode kept, the
//! modal space is the full space under rotation and translation; against
//! an independent integration in the ground's frame, with the held nodes
//! moved on their circles, the error falls at the scheme's order; the
//! holder's work is the change of the sheet's energy plus the damping
//! loss; refusals keep the state; the FMU state holds the orientation.

use crate::common;

use common::*;
use modal_mass_spring::canonical_scenes;
use modal_mass_spring::fmi::variables::vr;
use modal_mass_spring::physics::run::forces::{SpringForces, SpringScratch};
use modal_mass_spring::physics::run::frame::{apply, apply_transposed, cross, dot, rotation};
use modal_mass_spring::physics::run::stiffness::StiffnessPattern;
use modal_mass_spring::physics::*;
use nalgebra::{DMatrix, DVector};

fn settings(reduction: Reduction, integrator: Integrator, modes: usize) -> Settings {
    Settings::new(reduction, integrator, modes)
}

/// The scene `name` with `solver`, gravity `gravity` and damping `alpha`.
fn simulator(name: &str, solver: Settings, gravity: [f64; 3], alpha: f64) -> Simulator {
    let mut setup = canonical_scenes::canonical(name).unwrap().with_settings(solver);
    setup.loads.gravity = gravity;
    setup.loads.damping_alpha = alpha;
    setup.simulator().unwrap()
}

/// A turn about z that spins up smoothly to `rate` (time constant 0.5 s).
fn spin_up(rate: f64) -> impl Fn(f64) -> [f64; 3] {
    move |t: f64| [0.0, 0.0, rate * (t - 0.5 * (1.0 - (-t / 0.5).exp()))]
}

/// Runs `sim` for `steps` steps of `h`, the holder's targets on `theta(t)`
/// and `a(t)` at the end of each step; calls `each` after every step.
fn drive(sim: &mut Simulator, steps: usize, h: f64, theta: &dyn Fn(f64) -> [f64; 3], a: &dyn Fn(f64) -> [f64; 3], mut each: impl FnMut(&mut Simulator, usize)) {
    for k in 0..steps {
        let t = (k + 1) as f64 * h;
        let mut loads = sim.loads().clone();
        loads.rotation = theta(t);
        loads.anchor = a(t);
        sim.set_loads(&loads).unwrap();
        sim.do_step(h).unwrap();
        each(sim, k);
    }
}

fn still(_: f64) -> [f64; 3] {
    [0.0; 3]
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

/// Positions in the holder's frame from ground positions: X0 + R^T (X - X0 - a).
fn into_frame(scene: &Scene, ground: &[f64], theta: &[f64; 3], a: &[f64; 3]) -> Vec<f64> {
    let (d, pivot, r) = (scene.dim, scene.pivot(), rotation(theta));
    ground
        .chunks_exact(d)
        .flat_map(|x| {
            let rho: [f64; 3] = std::array::from_fn(|i| if i < d { x[i] - pivot[i] - a[i] } else { 0.0 });
            let back = apply_transposed(&r, &rho);
            (0..d).map(move |i| pivot[i] + back[i]).collect::<Vec<_>>()
        })
        .collect()
}

/// The centrifugal equilibrium of a 2D sheet turning at `rate` about z
/// with gravity 0, solved by Newton in the rotating frame on the free DOFs:
/// f(x) + M rate^2 (x - X0) = 0, with the tangent K(x) - M rate^2, dense.
/// Slot positions.
fn spinning_equilibrium(scene: &Scene, rate: f64) -> Vec<f64> {
    let (n, d, pivot) = (scene.n_dofs(), scene.dim, scene.pivot());
    let springs = SpringForces::new(scene);
    let mut scratch = springs.scratch(scene);
    let pattern = StiffnessPattern::new(scene);
    let mut x = scene.rest.clone();
    for _ in 0..50 {
        let mut f = vec![0.0; n];
        springs.add_to(scene, &x, &mut scratch, &mut f);
        for k in 0..n {
            f[k] += scene.dof_mass[k] * rate * rate * (x[k] - pivot[k % d]);
        }
        let mut upper = vec![0.0; pattern.nnz()];
        pattern.add_tangent(scene, &x, 1.0, &mut upper);
        let mut k = DMatrix::<f64>::zeros(n, n);
        for c in 0..n {
            for p in pattern.col_ptr[c]..pattern.col_ptr[c + 1] {
                let r = pattern.row_idx[p];
                k[(r, c)] = upper[p];
                k[(c, r)] = upper[p];
            }
            k[(c, c)] -= scene.dof_mass[c] * rate * rate;
        }
        let step = k.lu().solve(&DVector::from_vec(f)).unwrap();
        for i in 0..n {
            x[i] += step[i];
        }
        if step.amax() < 1e-14 {
            return x;
        }
    }
    panic!("the static solve did not converge");
}

#[test]
fn a_turntable_settles_in_its_centrifugal_equilibrium() {
    let (scene, rate, h) = ("paper-2d-top-row", 2.5, 0.01);
    let theta = spin_up(rate);
    for (label, solver) in [
        ("full, explicit", settings(Reduction::Full, Integrator::NewmarkExplicit, 0)),
        ("full, implicit", settings(Reduction::Full, Integrator::NewmarkImplicit, 0)),
        ("modal, every mode", settings(Reduction::Modal, Integrator::NewmarkExplicit, 180)),
        ("modal, every mode, implicit", settings(Reduction::Modal, Integrator::NewmarkImplicit, 180)),
    ] {
        let mut sim = simulator(scene, solver, [0.0; 3], 8.0);
        let steps = 1500;
        drive(&mut sim, steps, h, &theta, &still, |_, _| {});
        let t = steps as f64 * h;
        let sc = sim.scene().clone();
        let local = into_frame(&sc, &sim.positions().to_vec(), &theta(t), &[0.0; 3]);
        let want = spinning_equilibrium(&sc, rate);
        let slots: Vec<f64> = sc.slot_of_node.iter().flat_map(|&s| want[s * 2..s * 2 + 2].to_vec()).collect();
        let err = max_abs_diff(&local, &slots);
        let stretch = max_abs_diff(&slots, &sc.slot_of_node.iter().flat_map(|&s| sc.rest[s * 2..s * 2 + 2].to_vec()).collect::<Vec<_>>());
        // The holder pulls the sheet round: it feels m w^2 S outward, S the first moment about the pivot.
        let pivot = sc.pivot();
        let mut s = [0.0; 3];
        for k in 0..sc.n_free {
            for i in 0..2 {
                s[i] += sc.dof_mass[2 * k] * (want[2 * k + i] - pivot[i]);
            }
        }
        let pull = apply(&rotation(&theta(t)), &s.map(|x| x * rate * rate));
        let (force, torque) = (sim.anchor_force(), sim.anchor_torque());
        let off = ((force[0] - pull[0]).powi(2) + (force[1] - pull[1]).powi(2)).sqrt() / (pull[0].powi(2) + pull[1].powi(2)).sqrt();
        println!(
            "{label}: positions off the static solve by {err:.1e} m (the spin stretches the sheet by {stretch:.3} m); force {force:.5?} N, \
             the centripetal pull {pull:.5?} N, off by {off:.1e}; torque {torque:?} N m"
        );
        assert!(stretch > 0.01, "the spin stretches the sheet");
        assert!(err < 1e-8, "{label}: {err:e} m");
        assert!(off < 1e-8, "{label}: force off by {off:e}");
        assert!(torque[2].abs() < 1e-8 * (pull[0].powi(2) + pull[1].powi(2)).sqrt(), "{label}: torque {torque:?}");
    }
}

/// A smooth swing of the holder: turning about z (2D) or a tilted axis
/// (3D) while translating.
fn swing_theta(d: usize) -> impl Fn(f64) -> [f64; 3] {
    move |t: f64| {
        let s = 0.4 * (1.0 - (3.0 * t).cos());
        if d == 2 {
            [0.0, 0.0, s]
        } else {
            [0.3 * s, 0.5 * s, 0.8 * s]
        }
    }
}

fn swing_anchor(t: f64) -> [f64; 3] {
    let c = 1.0 - (4.0 * t).cos();
    [0.02 * c, 0.01 * c, 0.01 * c]
}

/// Everything a turning run reports after each step.
fn record(sim: &mut Simulator) -> Vec<f64> {
    let mut row = sim.positions().to_vec();
    row.extend(sim.velocities());
    row.extend(sim.anchor_force());
    row.extend(sim.anchor_torque());
    row.push(sim.kinetic_energy());
    row.push(sim.potential_energy());
    row.extend(sim.load_node_position().unwrap());
    row.extend(sim.load_node_velocity().unwrap());
    row
}

#[test]
fn every_mode_is_the_full_space_under_rotation_and_translation() {
    for (scene, dofs) in [("paper-2d-top-row", 180), ("paper-3d-sheet", 126)] {
        for integrator in [Integrator::NewmarkExplicit, Integrator::NewmarkImplicit] {
            let run = |reduction, modes| {
                let mut solver = settings(reduction, integrator, modes);
                solver.max_internal_step = 2e-4;
                let mut sim = simulator(scene, solver, [0.0, -9.81, 0.0], 1.0);
                let mut loads = sim.loads().clone();
                loads.point_load = [0.5, -1.0, 0.3];
                sim.set_loads(&loads).unwrap();
                let mut rows = Vec::new();
                let d = sim.scene().dim;
                drive(&mut sim, 60, 0.01, &swing_theta(d), &swing_anchor, |s, _| rows.push(record(s)));
                rows
            };
            let (full, modal) = (run(Reduction::Full, 0), run(Reduction::Modal, dofs));
            let scale = full.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
            let worst = full.iter().zip(&modal).fold(0.0f64, |m, (a, b)| m.max(max_abs_diff(a, b))) / scale;
            let moved = max_abs_diff(&full[0], &full[full.len() - 1]) / scale;
            println!("{scene}, {integrator:?}: every mode vs full space under rotation and translation: {worst:.1e} of the largest output (the run moves them by {moved:.2})");
            assert!(worst < 1e-9, "{scene}, {integrator:?}: {worst:e}");
        }
    }
}

/// The same sheet integrated in the ground's frame: free nodes by RK4 on
/// m X'' = f(X) + m g - alpha m (X' - V_frame(X)), the held nodes placed on
/// their circles, the holder turning about z at the constant rate of each
/// communication step (the first-order hold of its samples). Node
/// positions (output order) at each communication point.
fn ground_frame_reference(scene: &Scene, theta: &dyn Fn(f64) -> [f64; 3], g: [f64; 3], alpha: f64, h: f64, steps: usize, substeps: usize) -> Vec<Vec<f64>> {
    let (d, n, pivot) = (scene.dim, scene.n_dofs(), scene.pivot());
    let springs = SpringForces::new(scene);
    let mut scratch = springs.scratch(scene);
    let mut x = scene.rest.clone();
    let mut v = vec![0.0; n];
    let mut out = Vec::new();
    // Held slots at angle phi about the pivot.
    let place_held = |x: &mut [f64], phi: f64| {
        let (s, c) = phi.sin_cos();
        for slot in scene.n_free..scene.rest.len() / d {
            let (rx, ry) = (scene.rest[slot * d] - pivot[0], scene.rest[slot * d + 1] - pivot[1]);
            x[slot * d] = pivot[0] + c * rx - s * ry;
            x[slot * d + 1] = pivot[1] + s * rx + c * ry;
        }
    };
    let accel = |x: &mut Vec<f64>, v: &[f64], phi: f64, w: f64, scratch: &mut SpringScratch| -> Vec<f64> {
        place_held(x, phi);
        let mut f = vec![0.0; n];
        springs.add_to(scene, x, scratch, &mut f);
        (0..n)
            .map(|k| {
                let (node, i) = (k / d, k % d);
                // Frame velocity at X: w e_z x (X - X0).
                let frame = if i == 0 { -w * (x[node * d + 1] - pivot[1]) } else { w * (x[node * d] - pivot[0]) };
                f[k] / scene.dof_mass[k] + g[i] - alpha * (v[k] - frame)
            })
            .collect()
    };
    let mut phi0 = 0.0;
    for k in 0..steps {
        let phi1 = theta((k + 1) as f64 * h)[2];
        let w = (phi1 - phi0) / h;
        let dt = h / substeps as f64;
        for s in 0..substeps {
            let p = phi0 + w * s as f64 * dt;
            let mut y = x.clone();
            let k1v = accel(&mut y, &v, p, w, &mut scratch);
            let k1x = v.clone();
            for i in 0..n {
                y[i] = x[i] + 0.5 * dt * k1x[i];
            }
            let v2: Vec<f64> = (0..n).map(|i| v[i] + 0.5 * dt * k1v[i]).collect();
            let k2v = accel(&mut y, &v2, p + 0.5 * w * dt, w, &mut scratch);
            for i in 0..n {
                y[i] = x[i] + 0.5 * dt * v2[i];
            }
            let v3: Vec<f64> = (0..n).map(|i| v[i] + 0.5 * dt * k2v[i]).collect();
            let k3v = accel(&mut y, &v3, p + 0.5 * w * dt, w, &mut scratch);
            for i in 0..n {
                y[i] = x[i] + dt * v3[i];
            }
            let v4: Vec<f64> = (0..n).map(|i| v[i] + dt * k3v[i]).collect();
            let k4v = accel(&mut y, &v4, p + w * dt, w, &mut scratch);
            for i in 0..n {
                x[i] += dt / 6.0 * (k1x[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i]);
                v[i] += dt / 6.0 * (k1v[i] + 2.0 * k2v[i] + 2.0 * k3v[i] + k4v[i]);
            }
        }
        phi0 = phi1;
        place_held(&mut x, phi0);
        out.push(scene.slot_of_node.iter().flat_map(|&s| x[s * d..s * d + d].to_vec()).collect());
    }
    out
}

#[test]
fn the_turning_frame_agrees_with_a_ground_frame_integration_at_the_schemes_order() {
    let (h, steps) = (0.01, 50);
    let theta = |t: f64| [0.0, 0.0, 0.6 * (1.0 - (4.0 * t).cos())];
    let (g, alpha) = ([0.0, -9.81, 0.0], 0.5);
    let scene = canonical_scenes::canonical("paper-2d-top-row").unwrap().grid.build().unwrap();
    let reference = ground_frame_reference(&scene, &theta, g, alpha, h, steps, 100);
    let mut errors = Vec::new();
    for dt in [2e-3, 1e-3, 5e-4] {
        let mut solver = settings(Reduction::Full, Integrator::NewmarkExplicit, 0);
        solver.max_internal_step = dt;
        let mut sim = simulator("paper-2d-top-row", solver, g, alpha);
        let mut worst = 0.0f64;
        drive(&mut sim, steps, h, &theta, &still, |s, k| worst = worst.max(max_abs_diff(s.positions(), &reference[k])));
        println!("internal step {dt:e} s: largest position error against the ground-frame RK4 run {worst:.3e} m");
        errors.push(worst);
    }
    let turned = max_abs_diff(&reference[steps - 1], &scene.slot_of_node.iter().flat_map(|&s| scene.rest[s * 2..s * 2 + 2].to_vec()).collect::<Vec<_>>());
    println!("the holder swings the sheet by {turned:.3} m; error ratios {:.2}, {:.2}", errors[0] / errors[1], errors[1] / errors[2]);
    assert!(turned > 0.3);
    for w in errors.windows(2) {
        assert!(w[0] / w[1] > 3.5 && w[0] / w[1] < 4.5, "second order: {errors:?}");
    }
}

/// The holder's work on the sheet, -(F . a' + tau . w) integrated over the
/// run, equals the change of the sheet's energy (kinetic and potential, in
/// the ground's frame) plus what the damping took, alpha m |v_rel|^2.
#[test]
fn the_holders_work_is_the_change_of_energy_plus_the_damping_loss() {
    let gap = |h: f64, turn: bool, shift: bool, label: &str| {
        let (work, change, loss) = run_balance(h, h.min(1e-3), turn, shift);
        let gap = (work - change - loss).abs() / work.abs().max(change.abs());
        println!("{label}, h = {h:e} s: holder's work {work:.6} J, energy change {change:.6} J, damping loss {loss:.6} J; off by {gap:.2e} of the work");
        gap
    };
    let (coarse, fine) = (gap(2e-3, true, true, "turning and moving"), gap(1e-3, true, true, "turning and moving"));
    let (turning, moving) = (gap(1e-3, true, false, "turning"), gap(1e-3, false, true, "moving"));
    for g in [coarse, fine, turning, moving] {
        assert!(g < 1e-4, "{g:e}");
    }
    assert!(fine < coarse, "the balance tightens as the step shrinks: {coarse:e}, {fine:e}");
}

/// The holder's work, the change of the sheet's energy and the damping
/// loss over 1 s of steps of `h` (internal steps `dt`), the holder turning
/// and moving as `turn` and `shift` say.
fn run_balance(h: f64, dt: f64, turn: bool, shift: bool) -> (f64, f64, f64) {
    {
        let mut solver = settings(Reduction::Full, Integrator::NewmarkExplicit, 0);
        solver.max_internal_step = dt;
        let alpha = 0.5;
        let mut sim = simulator("paper-2d-top-row", solver, [0.0, -9.81, 0.0], alpha);
        let sc = sim.scene().clone();
        let (d, pivot) = (sc.dim, sc.pivot());
        let theta = |t: f64| if turn { swing_theta(2)(t) } else { [0.0; 3] };
        let swing_anchor = |t: f64| if shift { swing_anchor(t) } else { [0.0; 3] };
        let energy = |s: &mut Simulator| s.kinetic_energy() + s.potential_energy();
        let damping_power = |s: &mut Simulator, w: f64, th: f64, a: [f64; 3], c: [f64; 3]| {
            let (x, v) = (s.positions().to_vec(), s.velocities().to_vec());
            let mut p = 0.0;
            for (node, &slot) in sc.slot_of_node.iter().enumerate() {
                if slot >= sc.n_free {
                    continue;
                }
                let rho = [x[node * d] - pivot[0] - a[0], x[node * d + 1] - pivot[1] - a[1], 0.0];
                let frame = cross(&[0.0, 0.0, w], &rho);
                let rel = [v[node * d] - c[0] - frame[0], v[node * d + 1] - c[1] - frame[1], 0.0];
                let _ = th;
                p += alpha * sc.dof_mass[slot * d] * dot(&rel, &rel);
            }
            p
        };
        let e0 = energy(&mut sim);
        let (mut f0, mut t0) = (sim.anchor_force(), sim.anchor_torque());
        let mut p0 = 0.0;
        let (mut work, mut loss) = (0.0, 0.0);
        let steps = (1.0 / h).round() as usize;
        let (mut th0, mut a0) = ([0.0; 3], [0.0; 3]);
        for k in 0..steps {
            let t = (k + 1) as f64 * h;
            let (th1, a1) = (theta(t), swing_anchor(t));
            let w = (th1[2] - th0[2]) / h;
            let c: [f64; 3] = std::array::from_fn(|i| (a1[i] - a0[i]) / h);
            let mut loads = sim.loads().clone();
            loads.rotation = th1;
            loads.anchor = a1;
            sim.set_loads(&loads).unwrap();
            sim.do_step(h).unwrap();
            let (f1, t1) = (sim.anchor_force(), sim.anchor_torque());
            // The holder moves at c and turns at w over the step; F and tau are the sheet's on it.
            work -= h * (dot(&c, &f0.map(|x| 0.5 * x)) + dot(&c, &f1.map(|x| 0.5 * x)) + w * 0.5 * (t0[2] + t1[2]));
            let p1 = damping_power(&mut sim, w, th1[2], a1, c);
            // At the start of a step the rates jump with the holder's: the power just after the kick.
            loss += 0.5 * h * (p0 + p1);
            (f0, t0, p0, th0, a0) = (f1, t1, p1, th1, a1);
        }
        let change = energy(&mut sim) - e0;
        (work, change, loss)
    }
}

#[test]
fn refusals_keep_the_state() {
    let mut sim = simulator("paper-2d-top-row", settings(Reduction::Modal, Integrator::NewmarkExplicit, 6), [0.0, -9.81, 0.0], 1.0);
    drive(&mut sim, 10, 0.01, &spin_up(1.0), &still, |_, _| {});
    let before = sim.snapshot();
    let mut loads = sim.loads().clone();
    for bad in [f64::NAN, f64::INFINITY, 2e6] {
        loads.rotation = [0.0, 0.0, bad];
        assert!(matches!(sim.set_loads(&loads), Err(PhysicsError::Invalid { quantity: Quantity::Rotation, .. })), "{bad}");
        assert_eq!(sim.snapshot(), before);
    }
    // A spin change of 1000 rad/s in one step: the far end would jump by tens of metres.
    loads.rotation = [0.0, 0.0, before.state.rotation[2] + 10.0];
    sim.set_loads(&loads).unwrap();
    let positions = sim.positions().to_vec();
    match sim.do_step(0.01) {
        Err(PhysicsError::StepFailed { cause: StepFailure::TurnTooFast { .. }, .. }) => {}
        other => panic!("{other:?}"),
    }
    assert_eq!(sim.snapshot().state, before.state, "the refused step keeps the state");
    assert_eq!(sim.positions(), &positions[..]);
    // The trigonometric scheme takes a holder turned before the run and kept still, not a turning one.
    let mut setup = canonical_scenes::canonical("paper-2d-top-row").unwrap().with_settings(settings(Reduction::Modal, Integrator::Trigonometric, 4));
    setup.loads.rotation = [0.0, 0.0, 0.3];
    let mut trig = setup.simulator().unwrap();
    trig.do_step(0.01).unwrap();
    let mut loads = trig.loads().clone();
    loads.rotation = [0.0, 0.0, 0.31];
    assert_eq!(trig.set_loads(&loads), Err(PhysicsError::SchemeCannotTurn { scheme: Integrator::Trigonometric }));
}

/// A sheet hung from a turned holder and kept still settles with the
/// holder's turn: at rest in the ground's frame its holder force is the
/// weight, whatever the basis.
#[test]
fn a_turned_holder_kept_still_carries_the_weight() {
    for (label, solver) in [
        ("full", settings(Reduction::Full, Integrator::NewmarkExplicit, 0)),
        ("modal 2 lowest", settings(Reduction::Modal, Integrator::NewmarkExplicit, 2)),
        ("modal 4, trigonometric", settings(Reduction::Modal, Integrator::Trigonometric, 4)),
    ] {
        let mut setup = canonical_scenes::canonical("paper-2d-top-row").unwrap().with_settings(solver);
        setup.loads.rotation = [0.0, 0.0, 0.4];
        setup.loads.damping_alpha = 8.0;
        let mut sim = setup.simulator().unwrap();
        for _ in 0..2000 {
            sim.do_step(0.01).unwrap();
        }
        let weight = sim.scene().free_mass() * 9.81;
        let f = sim.anchor_force();
        let off = (f[0].powi(2) + (f[1] + weight).powi(2)).sqrt() / weight;
        println!("{label}: holder turned by 0.4 rad: force {f:.6?} N, off the weight by {off:.1e}");
        assert!(off < 1e-9, "{label}: {off:e}");
    }
}

// ---- through the C ABI ----

#[test]
fn fmi_the_fmu_state_holds_the_orientation() {
    let f = Fmu::new();
    assert_eq!(f.set_f64(vr::DAMPING_ALPHA, &[0.5]), OK);
    f.init();
    let turn = spin_up(1.5);
    let drive = |f: &Fmu, from: usize, n: usize| {
        for k in from..from + n {
            assert_eq!(f.set_f64(vr::ANCHOR_R_Z, &[turn((k + 1) as f64 * 0.01)[2]]), OK, "{:?}", f.messages());
            assert_eq!(f.step(k as f64 * 0.01, 0.01), OK, "{:?}", f.messages());
        }
    };
    drive(&f, 0, 30);
    let torque = f.f64s(vr::ANCHOR_TORQUE_Z, 1)[0];
    assert!(torque.abs() > 1e-3, "the turning holder feels a torque: {torque}");
    f.assert_resumes(|f| {
        drive(f, 30, 20);
        let mut out = f.outputs();
        for r in [vr::ANCHOR_FORCE_X, vr::ANCHOR_FORCE_Y, vr::ANCHOR_TORQUE_Z, vr::LOAD_NODE_X, vr::LOAD_NODE_V_Y] {
            out.extend(bits(&f.f64s(r, 1)));
        }
        out
    });
    // NaN and angles beyond the range are refused, and the value stays.
    assert_eq!(f.set_f64(vr::ANCHOR_R_Z, &[f64::NAN]), ERROR);
    assert_eq!(f.set_f64(vr::ANCHOR_R_Z, &[2e6]), ERROR);
    assert!(f.f64s(vr::ANCHOR_R_Z, 1)[0].is_finite());
}

/// The leave-out options under a turning holder: settled under gravity,
/// then swung up to 0.8 rad about z for 2 s with light damping. Eight
/// vectors chosen by the loads with their static responses follow the full
/// space's load node and holder force better when `anchorRotation` adds
/// the turning's inertial loads to the patterns, and the cubature trained
/// for that basis runs the turn as well; linearized at the equilibrium
/// both run it.
#[test]
fn prepared_bases_follow_the_full_space_under_a_turning_holder() {
    let scene = "paper-2d-top-row";
    let theta = swing_theta(2);
    let run = |solver: Settings| {
        let mut sim = simulator(scene, solver, [0.0, -9.81, 0.0], 8.0);
        for _ in 0..1000 {
            sim.do_step(0.01).unwrap();
        }
        let mut loads = sim.loads().clone();
        loads.damping_alpha = 0.5;
        sim.set_loads(&loads).unwrap();
        let mut rows = Vec::new();
        drive(&mut sim, 200, 0.01, &theta, &still, |s, _| {
            let mut row = s.load_node_position().unwrap()[..2].to_vec();
            row.extend(&s.anchor_force()[..2]);
            row.push(s.anchor_torque()[2]);
            rows.push(row);
        });
        rows
    };
    let full = run(settings(Reduction::Full, Integrator::NewmarkExplicit, 0));
    let largest = |k: usize| full.iter().fold(0.0f64, |m, r| m.max(r[k].abs()));
    let (size, force, torque) = (1.0, largest(3), largest(4));
    let prepared = |rotation: bool, cubature: bool, equilibrium: bool| {
        let mut s = settings(Reduction::Modal, Integrator::NewmarkExplicit, 8);
        s.mode_selection = ModeSelection::Load;
        s.static_correction = true;
        s.anchor_motion = true;
        s.anchor_rotation = rotation;
        if cubature {
            s.force_evaluation = ForceEvaluation::Cubature;
        }
        if equilibrium {
            s.linearization = Linearization::Equilibrium;
        }
        s
    };
    let mut errors = Vec::new();
    for (label, solver) in [
        ("8 by load + static correction, anchorMotion", prepared(false, false, false)),
        ("the same + anchorRotation", prepared(true, false, false)),
        ("the same + anchorRotation, cubature", prepared(true, true, false)),
        ("at the equilibrium, anchorMotion", prepared(false, false, true)),
        ("at the equilibrium, + anchorRotation", prepared(true, false, true)),
    ] {
        let rows = run(solver);
        let err = |k: usize, scale: f64| full.iter().zip(&rows).fold(0.0f64, |m, (a, b)| m.max((a[k] - b[k]).abs())) / scale;
        let (node, f, t) = (err(0, size).max(err(1, size)), err(2, force).max(err(3, force)), err(4, torque));
        println!("{label}: load node off by {node:.2e} m, holder force by {f:.2e} and torque by {t:.2e} of the largest");
        errors.push([node, f, t]);
    }
    assert!(errors[1][0] < errors[0][0] && errors[1][1] < errors[0][1], "anchorRotation prepares the basis for the turn: {errors:?}");
    assert!(errors[2][0] < 2.0 * errors[1][0] && errors[2][1] < 2.0 * errors[1][1], "the cubature runs the turn: {errors:?}");
    // At the equilibrium the turn's patterns take the place of two eigenmodes, which this swing
    // needed more (measured: load node 1.13e-2 m without them, 2.06e-2 m with): both run it.
    assert!(errors[3][0] < 2.0 * errors[1][0] && errors[4][0] < 3.0 * errors[1][0], "linearized at the equilibrium: {errors:?}");
}
