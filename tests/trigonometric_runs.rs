//! The trigonometric integrator in modal runs (`integrator = trigonometric`,
//! `docs/method.md`, section 4): near dt omega = k pi, the energy of a long
//! undamped run, a step too long refused, against explicit Newmark at small
//! steps with every basis and force option, the ports and the weights; the
//! FMU state through the C ABI; the refusal in full space.

use crate::common;

use common::*;
use modal_mass_spring::canonical_scenes;
use modal_mass_spring::fmi::variables::vr;
use modal_mass_spring::physics::*;

fn load_static(s: Settings) -> Settings {
    Settings { mode_selection: ModeSelection::Load, static_correction: true, ..s }
}

fn modal(integrator: Integrator, modes: usize, max_internal_step: f64) -> Settings {
    Settings { max_internal_step, ..Settings::new(Reduction::Modal, integrator, modes) }
}

/// Total energy (kinetic + potential) of `sim`.
fn energy(sim: &mut Simulator) -> f64 {
    sim.kinetic_energy() + sim.potential_energy()
}

/// Steps at which a kept mode of the paper's scene with 16 modes of the
/// load and a static correction turns by pi, 2 pi or 3 pi (the fastest,
/// the static correction, and two slower ones; up to 12 times the step
/// that resolves it), and a hair off them, undamped, for 2000 steps: the run
/// stays finite, and its kinetic energy and the error of its energy stay
/// below a fifth of the work gravity can do across the sheet (they reach
/// 4 % and 5 % of it: near such steps modes trade energy through the rest
/// of the force, within bounds).
#[test]
fn no_blow_up_at_steps_where_a_mode_turns_by_a_multiple_of_pi() {
    let setup = canonical_scenes::canonical("paper-2d-top-row").unwrap();
    let probe = setup.with_settings(load_static(modal(Integrator::Trigonometric, 16, 0.02))).simulator().unwrap();
    let omega = probe.mode_frequencies().to_vec();
    let pi = std::f64::consts::PI;
    let mut cases = Vec::new();
    for &j in &[15usize, 8, 3] {
        for k in [1.0, 2.0, 3.0] {
            for off in [0.0, 1e-9, -1e-6] {
                cases.push((j, k, (k * pi / omega[j]) * (1.0 + off)));
            }
        }
    }
    let (mut worst_kinetic, mut worst_energy) = (0.0f64, 0.0f64);
    for (j, k, dt) in cases {
        let mut sim = setup.with_settings(load_static(modal(Integrator::Trigonometric, 16, dt))).simulator().unwrap();
        let e0 = energy(&mut sim);
        // The work gravity can do across the sheet: the scale of every energy here.
        let work = sim.scene().free_mass() * 9.81 * sim.scene().reach();
        let (mut k_max, mut dev) = (0.0f64, 0.0f64);
        for _ in 0..2000 {
            sim.do_step(dt).unwrap_or_else(|e| panic!("mode {j}, xi = {k} pi: {e}"));
            assert_eq!(sim.internal_steps_last(), 1);
            k_max = k_max.max(sim.kinetic_energy());
            dev = dev.max((energy(&mut sim) - e0).abs());
        }
        worst_kinetic = worst_kinetic.max(k_max / work);
        worst_energy = worst_energy.max(dev / work);
        assert!(k_max < 0.2 * work, "mode {j}, xi = {k} pi: kinetic energy {k_max:e} J, the work gravity can do {work:e} J");
        assert!(dev < 0.2 * work, "mode {j}, xi = {k} pi: the energy strays by {dev:e} J, the work gravity can do {work:e} J");
    }
    println!("largest kinetic energy {worst_kinetic:.3e}, largest |E - E0| {worst_energy:.3e}, of the work gravity can do");
}

/// An undamped run of 5000 steps of 0.02 s (16 modes of the load and a
/// static correction): the energy strays no further at the end than at the
/// start, and by less than 2 % of the largest kinetic energy.
#[test]
fn the_energy_of_a_long_undamped_run_stays_bounded() {
    let setup = canonical_scenes::canonical("paper-2d-top-row").unwrap();
    let mut sim = setup.with_settings(load_static(modal(Integrator::Trigonometric, 16, 0.02))).simulator().unwrap();
    let e0 = energy(&mut sim);
    let steps = 5000;
    let (mut k_max, mut first, mut last) = (0.0f64, 0.0f64, 0.0f64);
    for n in 0..steps {
        sim.do_step(0.02).unwrap();
        k_max = k_max.max(sim.kinetic_energy());
        let dev = (energy(&mut sim) - e0).abs();
        if n < steps / 5 {
            first = first.max(dev);
        } else if n >= steps - steps / 5 {
            last = last.max(dev);
        }
    }
    println!("|E - E0| / largest kinetic energy: {:.3e} over the first fifth, {:.3e} over the last", first / k_max, last / k_max);
    assert!(last < 0.02 * k_max && first < 0.02 * k_max, "energy strays by {first:e} then {last:e} J (kinetic up to {k_max:e} J)");
    assert!(last < 1.5 * first, "the energy drifts: {first:e} then {last:e} J");
}

/// The kicks follow the rest of the force explicitly. Under 1e4 m/s² the
/// 3D sheet's springs stretch far beyond their rest length and stiffen its
/// out-of-plane modes (whose own springs are the soft auxiliary ones) to
/// about k/m: at internal steps of 10 ms the step that passes 4/dt^2 is
/// refused and the state kept; at 2 ms the run goes on with its energy
/// bounded.
#[test]
fn a_step_too_long_for_the_stiffened_rest_of_the_force_is_refused() {
    let run = |dt: f64| {
        let mut setup = canonical_scenes::canonical("paper-3d-sheet").unwrap().with_settings(modal(Integrator::Trigonometric, 58, dt));
        setup.loads.gravity = [0.0, -1e4, 0.0];
        setup.simulator().unwrap()
    };
    let mut sim = run(0.01);
    let refused = (0..50).find_map(|_| {
        let before = sim.snapshot();
        sim.do_step(0.01).err().map(|e| (e, before))
    });
    let (err, before) = refused.expect("no step refused in 0.5 s");
    println!("{err}");
    assert!(matches!(err, PhysicsError::StepFailed { cause: StepFailure::RestTooStiff { .. }, .. }), "{err:?}");
    assert_eq!(sim.snapshot(), before, "the state of before the refused step");
    let mut sim = run(0.002);
    let e0 = energy(&mut sim);
    let mut k_max = 0.0f64;
    for _ in 0..50 {
        sim.do_step(0.01).unwrap();
        k_max = k_max.max(sim.kinetic_energy());
        assert!((energy(&mut sim) - e0).abs() < 1e-2 * k_max, "energy strays by {:e} J", energy(&mut sim) - e0);
    }
}

/// Node positions after every step of `h`, `steps` steps, with the loads
/// `change` sets before step k (anchor target, point load, gravity).
fn drive(sim: &mut Simulator, steps: usize, h: f64, change: &dyn Fn(usize, &mut Loads)) -> Vec<Vec<f64>> {
    let mut out = Vec::new();
    for k in 0..steps {
        let mut loads = sim.loads().clone();
        change(k, &mut loads);
        sim.set_loads(&loads).unwrap();
        sim.do_step(h).unwrap();
        out.push(sim.positions().to_vec());
    }
    out
}

fn max_diff(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    a.iter().zip(b).flat_map(|(x, y)| x.iter().zip(y)).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max)
}

/// Largest node displacement from the start over a run.
fn motion(run: &[Vec<f64>], start: &[f64]) -> f64 {
    run.iter().flat_map(|x| x.iter().zip(start)).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max)
}

/// Both schemes integrate the same modal equations (weights other than 1,
/// one of them 0, Rayleigh damping): at small steps they agree, the
/// trigonometric scheme converging at second order to the explicit scheme's
/// solution at a far smaller step, and the deleted mode stays at 0.
#[test]
fn agrees_with_explicit_newmark_at_small_steps() {
    let setup = canonical_scenes::canonical("paper-2d-top-row").unwrap();
    let r = 8;
    let weights = [1.0, 0.5, 2.0, 1.0, 0.0, 1.0, 1.5, 1.0];
    let run = |integrator, dt: f64| {
        let mut s = setup.with_settings(modal(integrator, r, dt));
        s.loads.mode_weights = weights.to_vec();
        s.loads.damping_alpha = 0.3;
        s.loads.damping_beta = 2e-4;
        let mut sim = s.simulator().unwrap();
        let mut out = Vec::new();
        let mut deleted = 0.0f64;
        for _ in 0..50 {
            sim.do_step(0.02).unwrap();
            out.push(sim.positions().to_vec());
            deleted = deleted.max(sim.modal_coordinates()[4].abs());
        }
        (out, deleted)
    };
    let (reference, _) = run(Integrator::NewmarkExplicit, 1e-5);
    let mut errors = Vec::new();
    for dt in [4e-3, 2e-3, 1e-3] {
        let (got, deleted) = run(Integrator::Trigonometric, dt);
        assert_eq!(deleted, 0.0, "the deleted mode moved");
        errors.push(max_diff(&got, &reference));
    }
    let (explicit, _) = run(Integrator::NewmarkExplicit, 1e-3);
    println!(
        "trigonometric at 4, 2, 1 ms against explicit Newmark at 0.01 ms: {errors:?} m; explicit Newmark at 1 ms: {:e} m",
        max_diff(&explicit, &reference)
    );
    assert!(errors[2] < 1e-5, "1 ms: {:e} m", errors[2]);
    for w in errors.windows(2) {
        assert!(w[0] / w[1] > 3.5, "not second order: {errors:?}");
    }
}

/// Every basis and force option with the ports: the modes of the loads
/// with a static correction, linearized at rest and at the equilibrium,
/// exact and cubature forces, a moving anchor and a point load that changes
/// between steps. Against explicit Newmark at 0.1 ms with the same options,
/// the trigonometric scheme at 5 ms steps is within 1 % of the motion, closer
/// than explicit Newmark at the same communication step (which sub-steps),
/// and four times closer at half the step.
#[test]
fn every_option_with_a_moving_anchor_and_a_point_load() {
    let setup = canonical_scenes::canonical("paper-2d-top-row").unwrap();
    let change = |k: usize, loads: &mut Loads| {
        let t = (k + 1) as f64 * 0.01;
        loads.anchor = [0.02 * (5.0 * t).sin(), 0.01 * (1.0 - (5.0 * t).cos()), 0.0];
        loads.point_load = if k < 30 { [0.5, -1.0, 0.0] } else { [-0.5, 0.2, 0.0] };
    };
    let mut cases = Vec::new();
    for linearization in [Linearization::Rest, Linearization::Equilibrium] {
        for evaluation in [ForceEvaluation::Exact, ForceEvaluation::Cubature] {
            cases.push((linearization, evaluation));
        }
    }
    for (linearization, evaluation) in cases {
        let sim = |integrator, dt| {
            let mut s = load_static(modal(integrator, 8, dt));
            s.linearization = linearization;
            s.anchor_motion = true;
            s.force_evaluation = evaluation;
            let mut setup = setup.with_settings(s);
            setup.loads.point_load = [0.5, -1.0, 0.0];
            setup.simulator().unwrap()
        };
        let mut reference = sim(Integrator::NewmarkExplicit, 1e-4);
        let start = reference.positions().to_vec();
        let want = drive(&mut reference, 60, 0.01, &change);
        let mut trig = sim(Integrator::Trigonometric, 5e-3);
        let got = drive(&mut trig, 60, 0.01, &change);
        let halved = drive(&mut sim(Integrator::Trigonometric, 2.5e-3), 60, 0.01, &change);
        let mut explicit = sim(Integrator::NewmarkExplicit, 5e-3);
        let explicit_run = drive(&mut explicit, 60, 0.01, &change);
        let (err, err_halved, err_explicit) = (max_diff(&got, &want), max_diff(&halved, &want), max_diff(&explicit_run, &want));
        let moved = motion(&want, &start);
        println!(
            "{:?}, {evaluation:?}: trigonometric at 5 and 2.5 ms {err:.3e}, {err_halved:.3e} m; explicit Newmark at 5 ms ({} internal steps) {err_explicit:.3e} m; motion {moved:.3e} m",
            linearization,
            explicit.internal_steps_last()
        );
        assert!(got.iter().flatten().all(|x| x.is_finite()));
        assert!(err < 1e-2 * moved, "{:?}, {evaluation:?}: {err:e} m of {moved:e} m", linearization);
        assert!(err < err_explicit, "{:?}, {evaluation:?}: {err:e} m, explicit Newmark {err_explicit:e} m", linearization);
        assert!(err_halved < 0.35 * err, "{:?}, {evaluation:?}: not second order, {err:e} then {err_halved:e} m", linearization);
        let ports = [trig.load_node_position().unwrap(), trig.load_node_velocity().unwrap(), trig.anchor_force()];
        assert!(ports.iter().flatten().all(|x| x.is_finite()));
    }
}

// ---------------------------------------------------------------------------
// The FMU.

fn trigonometric_fmu() -> Fmu {
    let f = Fmu::new();
    assert_eq!(f.set_i64(vr::INTEGRATOR, 3), OK);
    assert_eq!(f.set_u64(vr::N_MODES, 12), OK);
    assert_eq!(f.set_i64(vr::MODE_SELECTION, 2), OK);
    assert_eq!(f.set_f64(vr::MAX_INTERNAL_STEP, &[0.02]), OK);
    assert_eq!(unsafe { modal_mass_spring::fmi::exports::fmi3SetBoolean(f.inst, &vr::STATIC_CORRECTION, 1, &true, 1) }, OK);
    assert_eq!(f.set_f64(vr::DAMPING_ALPHA, &[0.1]), OK);
    f.init();
    f
}

/// An FMU state taken mid-run resumes bit for bit, through get/set and
/// through serialization, while gravity, the point load and the anchor
/// change after it was taken.
#[test]
fn fmi_state_resumes_bit_for_bit() {
    let f = trigonometric_fmu();
    f.run(10, 0.02);
    f.assert_resumes(|f: &Fmu| {
        let mut out = Vec::new();
        for k in 0..30 {
            assert_eq!(f.set_f64(vr::ANCHOR_X, &[0.01 * (0.3 * k as f64).sin()]), OK);
            if k == 10 {
                assert_eq!(f.set_f64(vr::GRAVITY, &[1.0, -9.81, 0.0]), OK);
                assert_eq!(f.set_f64(vr::LOAD_X, &[0.3]), OK);
            }
            f.run(1, 0.02);
            out.extend(f.outputs());
        }
        out
    });
}

/// In full space the stiffness and the damping couple every DOF: the
/// scheme is refused at set-up, in the core and through the FMU, with a
/// message that names both variables.
#[test]
fn refused_in_full_space() {
    let setup = canonical_scenes::canonical("paper-2d-top-row").unwrap();
    let err = setup.with_settings(Settings::new(Reduction::Full, Integrator::Trigonometric, 0)).simulator().err();
    assert_eq!(err, Some(PhysicsError::SchemeNeedsDiagonal { scheme: Integrator::Trigonometric }));
    let f = Fmu::new();
    assert_eq!(f.set_i64(vr::INTEGRATOR, 3), OK);
    assert_eq!(f.set_i64(vr::REDUCTION, 2), OK);
    assert_eq!(unsafe { modal_mass_spring::fmi::exports::fmi3EnterInitializationMode(f.inst, false, 0.0, 0.0, false, 0.0) }, OK);
    let status = unsafe { modal_mass_spring::fmi::exports::fmi3ExitInitializationMode(f.inst) };
    let message = f.messages().last().cloned().unwrap_or_default();
    assert!(message.contains("integrator = trigonometric") && message.contains("reduction = modal") && message.contains("reduction = full"), "{message}");
    f.expect_error(status, "trigonometric in full space");
}
