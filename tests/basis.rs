//! The basis options: modes chosen by the loads, the static correction and
//! the linearization at the loaded equilibrium (docs/method.md, section 3).

use crate::common;

use common::*;
use modal_mass_spring::canonical_scenes;
use modal_mass_spring::fmi::exports::{fmi3EnterInitializationMode, fmi3ExitInitializationMode};
use modal_mass_spring::fmi::variables::vr;
use modal_mass_spring::physics::run::forces::SpringForces;
use modal_mass_spring::physics::run::stiffness::StiffnessPattern;
use modal_mass_spring::physics::setup::basis::{self, Basis};
use modal_mass_spring::physics::setup::equilibrium::equilibrium;
use modal_mass_spring::physics::*;

fn options(mode_selection: ModeSelection, static_correction: bool, linearization: Linearization) -> Settings {
    Settings { mode_selection, static_correction, linearization, ..paper() }
}

/// The paper's basis: the lowest modes at rest.
fn paper() -> Settings {
    Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, 0)
}

fn build(scene: &str, r: usize, o: &Settings) -> (Scene, Basis) {
    let setup = canonical_scenes::canonical(scene).unwrap();
    let s = setup.grid.build().unwrap();
    let b = basis::build(&s, &setup.loads, r, o).unwrap();
    (s, b)
}

fn column(b: &Basis, j: usize) -> Vec<f64> {
    let m = &b.modes;
    (0..m.n).map(|i| m.phi[i * m.r + j]).collect()
}

#[test]
fn load_selection_leaves_out_what_gravity_does_not_excite() {
    // 2D, top row fixed: the lowest mode is a sideways sway, orthogonal to gravity along -y.
    let (s, lowest) = build("paper-2d-top-row", 1, &paper());
    let g = basis::load_patterns(&s, &Loads::physical(0), false, false).remove(0);
    let sway = column(&lowest, 0);
    let gnorm = g.iter().zip(&s.dof_mass).map(|(f, m)| f * f / m).sum::<f64>().sqrt();
    let driven: f64 = sway.iter().zip(&g).map(|(a, b)| a * b).sum::<f64>() / gnorm;
    assert!(driven.abs() < 1e-10, "gravity drives the lowest mode: {driven}");
    let (_, load) = build("paper-2d-top-row", 8, &options(ModeSelection::Load, false, Linearization::Rest));
    let w0 = lowest.modes.lambda[0];
    assert!(load.modes.lambda.iter().all(|l| (l - w0).abs() > 1e-6 * w0), "mode 1 (lambda {w0}) kept: {:?}", load.modes.lambda);
    for j in 0..8 {
        let share: f64 = column(&load, j).iter().zip(&g).map(|(a, b)| a * b).sum();
        assert!(share.abs() > 1e-8, "mode {j} kept although gravity does not drive it");
    }

    // 3D sheet: the lowest modes are the out-of-plane cluster; the loaded ones lie in the plane.
    let (_, lowest) = build("paper-3d-sheet", 8, &paper());
    let (_, load) = build("paper-3d-sheet", 8, &options(ModeSelection::Load, false, Linearization::Rest));
    for j in 0..8 {
        let (lo, ld) = (column(&lowest, j), column(&load, j));
        let out = |v: &[f64]| v.iter().skip(2).step_by(3).map(|x| x.abs()).fold(0.0, f64::max) / v.iter().map(|x| x.abs()).fold(0.0, f64::max);
        assert!(out(&lo) > 0.999, "lowest mode {j} is not out of the plane");
        assert!(out(&ld) < 1e-10, "load mode {j} leaves the plane: {}", out(&ld));
    }
}

#[test]
fn ritz_vectors_are_mass_orthonormal_and_diagonalise_k() {
    for (scene, lin) in
        // cloth-3d (2 610 free DOFs) ranks load-dependent Ritz vectors, the others every mode.
        [
            ("paper-2d-top-row", Linearization::Rest),
            ("paper-2d-top-corners", Linearization::Equilibrium),
            ("paper-3d-sheet", Linearization::Rest),
            ("cloth-3d", Linearization::Rest),
        ]
    {
        let o = options(ModeSelection::Load, true, lin);
        let (s, b) = build(scene, 8, &o);
        let (n, r) = (b.modes.n, b.modes.r);
        let mut kphi = vec![0.0; n];
        for i in 0..r {
            let ci = column(&b, i);
            b.pattern.sym_matvec(&b.stiffness, &ci, &mut kphi);
            for j in 0..r {
                let cj = column(&b, j);
                let mij: f64 = (0..n).map(|k| cj[k] * s.dof_mass[k] * ci[k]).sum();
                let kij: f64 = (0..n).map(|k| cj[k] * kphi[k]).sum();
                let delta = if i == j { 1.0 } else { 0.0 };
                assert!((mij - delta).abs() < 1e-10, "{scene}: Phi^T M Phi [{i},{j}] = {mij}");
                assert!((kij - delta * b.modes.lambda[i]).abs() < 1e-9 * b.modes.lambda[r - 1], "{scene}: Phi^T K Phi [{i},{j}] = {kij}");
            }
        }
        // modeFrequencies are the Ritz values.
        let solver = Settings { n_modes: 8, ..o.clone() };
        let sim = canonical_scenes::canonical(scene).unwrap().with_settings(solver).simulator().unwrap();
        for (w, l) in sim.mode_frequencies().iter().zip(&b.modes.lambda) {
            assert!((w * w - l).abs() <= 1e-12 * l.max(1.0), "{scene}: frequency {w}, lambda {l}");
        }
    }
}

/// The M-norm of what of `u` the basis cannot represent, relative to `u`.
fn outside(s: &Scene, b: &Basis, u: &[f64]) -> f64 {
    let n = b.modes.n;
    let mut q = vec![0.0; b.modes.r];
    b.modes.project_displacement(&s.dof_mass, u, &mut q);
    let mut rest = u.to_vec();
    for (j, qj) in q.iter().enumerate() {
        for (k, rk) in rest.iter_mut().enumerate() {
            *rk -= b.modes.phi[k * b.modes.r + j] * qj;
        }
    }
    let norm = |v: &[f64]| (0..n).map(|k| s.dof_mass[k] * v[k] * v[k]).sum::<f64>().sqrt();
    norm(&rest) / norm(u)
}

#[test]
fn the_static_correction_holds_the_sag() {
    // At rest: the static response K^-1 M g.
    let (s, b) = build("paper-2d-top-row", 4, &options(ModeSelection::Load, true, Linearization::Rest));
    let g = basis::load_patterns(&s, &Loads::physical(0), false, false).remove(0);
    let (_, all) = build("paper-2d-top-row", s.n_dofs(), &paper());
    // K^-1 M g from every mode: sum phi (phi^T M g) / lambda.
    let mut sag = vec![0.0; s.n_dofs()];
    for j in 0..all.modes.r {
        let c = column(&all, j);
        let q: f64 = c.iter().zip(&g).map(|(a, b)| a * b).sum::<f64>() / all.modes.lambda[j];
        sag.iter_mut().zip(&c).for_each(|(u, p)| *u += q * p);
    }
    assert!(outside(&s, &b, &sag) < 1e-8, "{}", outside(&s, &b, &sag));
    let (_, plain) = build("paper-2d-top-row", 4, &options(ModeSelection::Load, false, Linearization::Rest));
    assert!(outside(&s, &plain, &sag) > 1e-3, "without the correction the sag lies outside the basis");
    // At the equilibrium: the displacement from rest, so a run starts exactly at rest.
    let solver = Settings { n_modes: 4, ..options(ModeSelection::Load, true, Linearization::Equilibrium) };
    let setup = canonical_scenes::canonical("paper-2d-top-corners").unwrap().with_settings(solver);
    let mut sim = setup.simulator().unwrap();
    let rest = setup.grid.build().unwrap();
    let d = rest.dim;
    let start = rest.slot_of_node.iter().flat_map(|&slot| (0..d).map(move |i| (slot, i)));
    let err = start.zip(sim.positions()).map(|((slot, i), x)| (x - rest.rest[slot * d + i]).abs()).fold(0.0, f64::max);
    assert!(err < 1e-12, "the run starts {err} m from rest");
}

#[test]
fn the_equilibrium_balances_gravity_and_matches_a_damped_run() {
    for name in ["paper-2d-top-corners", "paper-3d-sheet"] {
        let setup = canonical_scenes::canonical(name).unwrap();
        let s = setup.grid.build().unwrap();
        let pattern = StiffnessPattern::new(&s);
        let x = equilibrium(&s, &pattern, &modal_mass_spring::physics::setup::basis::external_load(&s, &setup.loads)).unwrap();
        let mut f: Vec<f64> = basis::load_patterns(&s, &setup.loads, false, false).remove(0);
        let gravity = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let springs = SpringForces::new(&s);
        springs.add_to(&s, &x, &mut springs.scratch(&s), &mut f);
        let residual = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(residual <= 1e-9 * gravity, "{name}: residual {residual}");
        // A damped full-space run comes to rest there.
        let mut damped = setup.with_settings(Settings::new(Reduction::Full, Integrator::NewmarkImplicit, 0));
        damped.loads.damping_alpha = 20.0;
        let mut sim = damped.simulator().unwrap();
        for _ in 0..2000 {
            sim.do_step(0.01).unwrap();
        }
        let p = sim.positions();
        let diff = s.slot_of_node.iter().enumerate().filter(|(_, &slot)| slot < s.n_free).flat_map(|(node, &slot)| (0..s.dim).map(move |i| (node, slot, i)));
        let diff = diff.map(|(node, slot, i)| (p[node * s.dim + i] - x[slot * s.dim + i]).abs()).fold(0.0, f64::max);
        assert!(diff < 1e-6, "{name}: the damped run rests {diff} m from the equilibrium");
    }
}

#[test]
fn the_equilibrium_removes_the_zero_eigenvalues_of_a_flat_3d_sheet() {
    // Without auxiliary springs a flat sheet has no stiffness out of its plane at rest.
    let mut setup = canonical_scenes::canonical("paper-3d-sheet").unwrap();
    setup.grid.aux_stiffness = 0.0;
    let s = setup.grid.build().unwrap();
    let all = s.n_dofs();
    let at_rest = basis::build(&s, &setup.loads, all, &paper()).unwrap();
    let top = at_rest.modes.lambda[all - 1];
    assert!(at_rest.modes.lambda.iter().filter(|&&l| l <= 1e-10 * top).count() >= 42, "at rest: {:?}", &at_rest.modes.lambda[..4]);
    // Hung under gravity the sheet is in tension, and buckles out of its plane
    // where springs across it are compressed: the stable equilibrium has no zero eigenvalue.
    let eq = basis::build(&s, &setup.loads, all, &options(ModeSelection::Lowest, false, Linearization::Equilibrium)).unwrap();
    let (lo, hi) = (eq.modes.lambda[0], eq.modes.lambda[all - 1]);
    assert!(lo > 1.0 && lo > 1e-6 * hi, "lowest eigenvalue at the equilibrium {lo} (highest {hi})");
    // And a run in its modes is stable.
    let solver = Settings { n_modes: 16, ..options(ModeSelection::Load, true, Linearization::Equilibrium) };
    let run = setup.with_settings(solver);
    let mut sim = run.simulator().unwrap();
    let bound = s.free_mass() * 9.81 * s.reach();
    for _ in 0..200 {
        sim.do_step(0.01).unwrap();
        assert!(sim.positions().iter().all(|x| x.is_finite()));
        assert!(sim.kinetic_energy() < bound, "kinetic energy {} above what gravity can supply {bound}", sim.kinetic_energy());
    }
    assert!(sim.kinetic_energy() > 0.0);
}

#[test]
fn all_modes_at_the_equilibrium_reproduce_full_space_to_round_off() {
    let setup = canonical_scenes::canonical("paper-2d-top-corners").unwrap();
    let n = setup.grid.build().unwrap().n_dofs();
    for integrator in [Integrator::NewmarkExplicit, Integrator::NewmarkImplicit] {
        let mut modal = Settings::new(Reduction::Modal, integrator, n);
        modal.linearization = Linearization::Equilibrium;
        // Mass-proportional damping only: the modal space damps with the
        // stiffness at its linearization point, full space with the one at rest.
        let mut a = setup.with_settings(modal);
        a.loads.damping_alpha = 0.3;
        let mut b = setup.with_settings(Settings::new(Reduction::Full, integrator, 0));
        b.loads.damping_alpha = 0.3;
        let (mut sa, mut sb) = (a.simulator().unwrap(), b.simulator().unwrap());
        let start = sb.positions().to_vec();
        for _ in 0..50 {
            sa.do_step(0.01).unwrap();
            sb.do_step(0.01).unwrap();
        }
        let disp = sb.positions().iter().zip(&start).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        let diff = sa.positions().iter().zip(sb.positions()).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(disp > 1e-2 && diff < 1e-9 * disp.max(1.0), "{integrator:?}: modal vs full {diff} (displacement {disp})");
    }
}

#[test]
fn a_basis_from_the_loads_needs_a_load() {
    let f = Fmu::new();
    assert_eq!(f.set_i64(vr::MODE_SELECTION, 2), OK);
    assert_eq!(f.set_f64(vr::GRAVITY, &[0.0, 0.0, 0.0]), OK);
    assert_eq!(unsafe { fmi3EnterInitializationMode(f.inst, false, 0.0, 0.0, false, 0.0) }, OK);
    let before = f.snapshot();
    let s = unsafe { fmi3ExitInitializationMode(f.inst) };
    let messages = f.messages();
    assert_eq!(s, ERROR, "{messages:?}");
    assert!(messages.last().unwrap().contains("modeSelection = load"), "{messages:?}");
    // Still in Initialization Mode, nothing changed: gravity can be set and the set-up tried again.
    assert_eq!(f.snapshot(), before);
    assert_eq!(f.set_f64(vr::GRAVITY, &[0.0, -9.81, 0.0]), OK);
    assert_eq!(unsafe { fmi3ExitInitializationMode(f.inst) }, OK, "{:?}", f.messages());
}

#[test]
fn force_residual_rises_when_the_scene_leaves_the_basis() {
    // Eight modes chosen for gravity along -y, with its static response.
    let f = Fmu::new();
    assert_eq!(f.set_u64(vr::N_MODES, 8), OK);
    assert_eq!(f.set_i64(vr::MODE_SELECTION, 2), OK);
    let on: bool = true;
    assert_eq!(unsafe { modal_mass_spring::fmi::exports::fmi3SetBoolean(f.inst, &vr::STATIC_CORRECTION, 1, &on, 1) }, OK);
    f.init();
    let residual = |f: &Fmu| f.f64s(vr::FORCE_RESIDUAL, 1)[0];
    let mut inside = 0.0f64;
    for _ in 0..100 {
        assert_eq!(f.step(f.time(), 0.01), OK, "{:?}", f.messages());
        inside = inside.max(residual(&f));
    }
    assert!(inside < 0.5, "forceResidual within the basis's range: {inside}");
    // Gravity turned sideways: the modes cannot follow it.
    assert_eq!(f.set_f64(vr::GRAVITY, &[19.62, -9.81, 0.0]), OK);
    let mut statuses = Vec::new();
    let mut outside = 0.0f64;
    for _ in 0..100 {
        statuses.push(f.step(f.time(), 0.01));
        outside = outside.max(residual(&f));
    }
    assert!(outside > 0.7, "forceResidual with sideways gravity: {outside}");
    // The first step past forceResidualLimit returns fmi3Warning, once, and says why.
    assert_eq!(statuses.iter().filter(|&&s| s == WARNING).count(), 1, "{statuses:?}");
    assert!(statuses.iter().all(|&s| s == OK || s == WARNING));
    let warned: Vec<String> = f.log.take().into_iter().filter(|(s, _, _)| *s == WARNING).map(|(_, _, m)| m).collect();
    assert!(warned.len() == 1 && warned[0].contains("forceResidual") && warned[0].contains("forceResidualLimit"), "{warned:?}");
    // forceResidualLimit = 0 turns the check off: the same steps run quietly, the output still reads.
    let quiet = Fmu::new();
    assert_eq!(quiet.set_u64(vr::N_MODES, 8), OK);
    assert_eq!(quiet.set_i64(vr::MODE_SELECTION, 2), OK);
    assert_eq!(unsafe { modal_mass_spring::fmi::exports::fmi3SetBoolean(quiet.inst, &vr::STATIC_CORRECTION, 1, &on, 1) }, OK);
    assert_eq!(quiet.set_f64(vr::FORCE_RESIDUAL_LIMIT, &[0.0]), OK);
    quiet.init();
    assert_eq!(quiet.set_f64(vr::GRAVITY, &[19.62, -9.81, 0.0]), OK);
    let statuses: Vec<_> = (0..100).map(|_| quiet.step(quiet.time(), 0.01)).collect();
    assert!(statuses.iter().all(|&s| s == OK), "{statuses:?}");
    assert!(residual(&quiet) > 0.7, "forceResidual is still computed when read: {}", residual(&quiet));
    // Full space represents every force.
    let full = Fmu::new();
    assert_eq!(full.set_i64(vr::REDUCTION, 2), OK);
    full.init();
    full.run(10, 0.01);
    assert_eq!(residual(&full), 0.0);
}

/// With cubature forces the steps visit a few springs and a residual check
/// visits them all: the check runs after the first step, after every change
/// of the loads and otherwise every `residual_period` steps, a tenth of the
/// steps' own spring visits at most. Gravity turned sideways is caught at
/// the very next step, as with exact forces.
#[test]
fn with_cubature_the_residual_check_runs_after_a_load_change_and_every_few_steps() {
    let f = Fmu::new();
    assert_eq!(f.set_u64(vr::N_MODES, 8), OK);
    assert_eq!(f.set_i64(vr::MODE_SELECTION, 2), OK);
    assert_eq!(f.set_i64(vr::FORCE_EVALUATION, 2), OK);
    let on: bool = true;
    assert_eq!(unsafe { modal_mass_spring::fmi::exports::fmi3SetBoolean(f.inst, &vr::STATIC_CORRECTION, 1, &on, 1) }, OK);
    f.init();
    for _ in 0..50 {
        assert_eq!(f.step(f.time(), 0.01), OK, "{:?}", f.messages());
    }
    // Gravity turned along x, which the basis (built for gravity along -y) holds none of.
    assert_eq!(f.set_f64(vr::GRAVITY, &[9.81, 0.0, 0.0]), OK);
    assert_eq!(f.step(f.time(), 0.01), WARNING, "the step after the change of gravity is checked: {:?}", f.messages());
    // The period: every spring against the springs one step visits.
    let mut solver = Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, 8);
    solver.mode_selection = ModeSelection::Load;
    solver.static_correction = true;
    solver.force_evaluation = ForceEvaluation::Cubature;
    let mut sim = canonical_scenes::canonical("paper-2d-top-row").unwrap().with_settings(solver.clone()).simulator().unwrap();
    sim.do_step(0.01).unwrap();
    let (all, visited) = (sim.scene().springs.len(), sim.cubature_springs() * sim.internal_steps_last());
    let period = modal_mass_spring::model::residual_period(&sim);
    println!("cubature: {visited} spring visits a step of {all} springs: a check every {period} steps");
    assert!(visited < all && period > 1);
    assert_eq!(period, (all as f64 / (0.1 * visited as f64)).ceil() as u64);
    // Exact forces and full space visit every spring each step: a check after every step.
    for (reduction, evaluation) in [(Reduction::Modal, ForceEvaluation::Exact), (Reduction::Full, ForceEvaluation::Exact)] {
        let s = Settings { reduction, force_evaluation: evaluation, ..solver.clone() };
        let mut sim = canonical_scenes::canonical("paper-2d-top-row").unwrap().with_settings(s).simulator().unwrap();
        sim.do_step(0.01).unwrap();
        assert_eq!(modal_mass_spring::model::residual_period(&sim), 1, "{reduction:?}");
    }
}

/// The reduced taut stiffness made a spring's row at a time and then by
/// faer's product is the one summed spring by spring as G^T K_e G, to
/// round-off, in 2D and 3D and with held nodes (whose rows of Phi are zero).
#[test]
fn the_reduced_taut_stiffness_by_rows_is_the_one_summed_spring_by_spring() {
    use modal_mass_spring::physics::run::stiffness::{add_reduced_tangent, reduced_taut_stiffness};
    for (scene, r) in [("paper-2d-top-row", 12), ("cloth-3d", 40)] {
        let (s, b) = build(scene, r, &paper());
        let r = b.modes.r;
        let mut by_spring = vec![0.0; r * r];
        add_reduced_tangent(&s, &s.rest, &b.modes.phi, r, true, &mut by_spring, &mut vec![0.0; 6 * r]);
        let mut by_rows = vec![0.0; r * r];
        reduced_taut_stiffness(&s, &b.modes.phi, r, &mut by_rows);
        let size = by_spring.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let diff = by_spring.iter().zip(&by_rows).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(size > 0.0 && diff <= 1e-12 * size, "{scene}: {diff:e} of {size:e}");
    }
}
