//! The stepping loop allocates nothing: a counting global allocator watches
//! `do_step`, a change of the point load, a moving anchor, a change of step
//! size, a turning holder and the reading of every output (trainingRange too) for every reduction and integrator
//! once set-up is done. Only allocations of the thread that steps count (the
//! test harness's own threads allocate when they please).

use crate::counting;

use counting::allocations;
use modal_mass_spring::canonical_scenes;
use modal_mass_spring::physics::*;

/// Every space and scheme, with the paper's basis and with each option
/// (modes chosen by the load, static correction, linearization at the
/// equilibrium, cubature forces, a trained basis with exact and cubature forces).
#[test]
fn do_step_allocates_nothing() {
    // (mode selection, static correction, linearization, force evaluation): the paper's first.
    use ForceEvaluation::{Cubature, Exact};
    use Linearization::{Equilibrium, Rest};
    let options = [
        (ModeSelection::Lowest, false, Rest, Exact),
        (ModeSelection::Load, true, Rest, Exact),
        (ModeSelection::Load, true, Equilibrium, Exact),
        (ModeSelection::Load, true, Rest, Cubature),
        (ModeSelection::Load, true, Equilibrium, Cubature),
        (ModeSelection::Trained, false, Rest, Exact),
        (ModeSelection::Trained, false, Rest, Cubature),
    ];
    for name in ["paper-2d-top-row", "paper-3d-sheet"] {
        // reduction = adaptive builds a modal space when it returns from full
        // space: its steps in each mode are checked below.
        for &reduction in Reduction::ALL.iter().filter(|&&r| r != Reduction::Adaptive) {
            for &integrator in Integrator::ALL {
                for &(mode_selection, static_correction, linearization, force_evaluation) in
                    if reduction == Reduction::Modal { &options[..] } else { &options[..1] }
                {
                    let solver = Settings { mode_selection, static_correction, linearization, force_evaluation, ..Settings::new(reduction, integrator, 4) };
                    let mut setup = canonical_scenes::canonical(name).unwrap().with_settings(solver);
                    setup.loads.damping_beta = 1e-3; // exercises the factorised explicit velocity update too
                                                     // A point load on the load node of the scene (a load pattern of the basis options too).
                    setup.loads.point_load = [0.01, -0.02, 0.0];
                    let mut sim = match setup.simulator() {
                        Ok(sim) => sim,
                        // A space the scheme refuses at set-up (the trigonometric scheme in full space).
                        Err(e) if e.refuses_pairing() && reduction != Reduction::Modal => continue,
                        Err(e) => panic!("{name} {reduction:?} {integrator:?}: {e}"),
                    };
                    sim.do_step(0.01).unwrap(); // first step may factorise
                    let mut loads = sim.loads().clone();
                    let n = allocations(|| {
                        for k in 0..20 {
                            sim.do_step(0.01).unwrap();
                            if k % 2 == 0 {
                                // The outputs computed on demand, read on every other step.
                                let x = sim.positions()[0] + sim.velocities()[0] + sim.potential_energy() + sim.force_residual();
                                let x = x + sim.load_node_position().unwrap()[0] + sim.load_node_velocity().unwrap()[1] + sim.anchor_force()[1];
                                // How far the run is from a trained basis's range (0 for the other bases).
                                let x = x + sim.training_range();
                                assert!(x.is_finite());
                            }
                        }
                        // A load change between steps derives the load terms again, without allocating.
                        loads.point_load = [-0.01, -0.03, 0.0];
                        sim.set_loads(&loads).unwrap();
                        sim.do_step(0.01).unwrap();
                        // A moving anchor (a kick of the rates) and another step size.
                        loads.anchor = [0.001, 0.0, 0.0];
                        sim.set_loads(&loads).unwrap();
                        sim.do_step(0.007).unwrap();
                        assert!(sim.anchor_force()[1].is_finite() && sim.anchor_torque()[2].is_finite());
                        // A turning holder (the Newmark schemes): its frame, kicks and outputs.
                        if integrator != Integrator::Trigonometric {
                            for k in 1..4 {
                                loads.rotation = [0.001 * k as f64, 0.002 * k as f64, 0.003 * k as f64];
                                sim.set_loads(&loads).unwrap();
                                sim.do_step(0.01).unwrap();
                                let x = sim.positions()[0] + sim.velocities()[0] + sim.potential_energy() + sim.kinetic_energy();
                                let x = x + sim.anchor_force()[0] + sim.anchor_torque()[2] + sim.load_node_velocity().unwrap()[0];
                                assert!(x.is_finite());
                            }
                        }
                    });
                    assert_eq!(n, 0, "{name} {reduction:?} {integrator:?} {mode_selection:?} {static_correction} {linearization:?} {force_evaluation:?}: {n} allocations in 20 steps and the outputs read");
                }
            }
        }
    }
}

/// An adaptive run's steps allocate nothing, reduced (estimates included)
/// and in full space (a fall-back included); only a return, which builds a
/// modal space for the grown basis, does.
#[test]
fn adaptive_steps_allocate_nothing() {
    // Exact forces with each scheme (the error model in full space), and cubature forces (in error directions).
    let cases = [
        (Integrator::NewmarkExplicit, ForceEvaluation::Exact),
        (Integrator::NewmarkImplicit, ForceEvaluation::Exact),
        (Integrator::Trigonometric, ForceEvaluation::Exact),
        (Integrator::NewmarkExplicit, ForceEvaluation::Cubature),
    ];
    for (integrator, force_evaluation) in cases {
        let settings = Settings { force_evaluation, ..Settings::new(Reduction::Adaptive, integrator, 4) };
        // Cubature on cloth 30 x 30 at a tolerance of 0.05 (12 vectors and 15 error directions, set up in a second).
        let scene = if force_evaluation == ForceEvaluation::Cubature {
            canonical_scenes::cloth(30, 30)
        } else {
            // Large enough for its basis to pay (at most one vector per ADAPTIVE_DOFS_PER_VECTOR DOFs).
            canonical_scenes::cloth(30, 30)
        };
        let mut setup = scene.with_settings(Settings {
            error_tolerance: if force_evaluation == ForceEvaluation::Cubature { 0.05 } else { settings.error_tolerance },
            ..settings
        });
        setup.loads.damping_beta = 1e-3;
        let mut sim = setup.simulator().unwrap_or_else(|e| panic!("{integrator:?}: {e}"));
        let directions = sim.reduction_status().error_directions;
        assert_eq!(directions > 0, force_evaluation == ForceEvaluation::Cubature, "{integrator:?}, {force_evaluation:?}: {directions} error directions");
        sim.do_step(0.01).unwrap();
        let mut loads = sim.loads().clone();
        let read = |sim: &mut Simulator| {
            let x = sim.positions()[0] + sim.velocities()[0] + sim.potential_energy() + sim.force_residual() + sim.anchor_force()[1];
            let s = sim.reduction_status();
            assert!((x + s.error_estimate + s.reduced_fraction).is_finite());
        };
        let n = allocations(|| {
            for _ in 0..40 {
                sim.do_step(0.01).unwrap();
                read(&mut sim);
            }
        });
        assert_eq!(sim.reduction_status().reduced_fraction, 1.0, "{integrator:?}: the program's own load stays reduced");
        assert_eq!(n, 0, "{integrator:?}: {n} allocations in 40 reduced steps");
        // Twice gravity, outside the program: full space from the next step on, with no return.
        loads.gravity = [0.0, -19.62, 0.0];
        let n = allocations(|| {
            sim.set_loads(&loads).unwrap();
            for _ in 0..40 {
                sim.do_step(0.01).unwrap();
                read(&mut sim);
            }
        });
        assert!(sim.reduction_status().reduced_fraction < 1.0, "{integrator:?}: fell back");
        assert_eq!(n, 0, "{integrator:?}: {n} allocations in a fall-back and 40 full-space steps");
    }
}
