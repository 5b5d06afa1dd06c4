//! Cubature forces (`docs/method.md`, section 4): the projected spring force
//! is reproduced within `cubatureTolerance` on poses the set-up never saw,
//! runs with both integrators stay close to exact forces with the same
//! basis, and the FMU reports how many springs it keeps.

use crate::common;

use common::*;
use modal_mass_spring::canonical_scenes;
use modal_mass_spring::fmi::variables::vr;
use modal_mass_spring::measures::{trajectory_error, Masses};
use modal_mass_spring::physics::*;

fn solver(integrator: Integrator, r: usize, linearization: Linearization, force: ForceEvaluation, tolerance: f64) -> Settings {
    let mut s = Settings::new(Reduction::Modal, integrator, r);
    s.mode_selection = ModeSelection::Load;
    s.static_correction = true;
    s.linearization = linearization;
    s.force_evaluation = force;
    s.cubature_tolerance = tolerance;
    s.max_internal_step = 0.001;
    s
}

/// Uniform in [-1, 1) from a small deterministic stream (not the set-up's).
fn noise(seed: &mut u64) -> f64 {
    *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    ((*seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

/// Held-out poses: the exact run at every communication point of 1 ms
/// steps over 1 s (the training run samples other instants), and random
/// scalings and perturbations of them from a stream of this test's own.
fn held_out_poses(exact: &mut Simulator) -> Vec<Vec<f64>> {
    let mut run = vec![exact.modal_coordinates().to_vec()];
    for k in 0..1000 {
        exact.do_step(0.001).unwrap();
        if k % 7 == 3 {
            run.push(exact.modal_coordinates().to_vec());
        }
    }
    let r = run[0].len();
    let amplitude: Vec<f64> = (0..r).map(|j| run.iter().fold(0.0f64, |m, q| m.max((q[j] - run[0][j]).abs()))).collect();
    let mut seed = 12345u64;
    let mut poses = run.clone();
    for i in 0..run.len() {
        let s = 0.6 + 0.3 * noise(&mut seed);
        poses.push((0..r).map(|j| run[0][j] + s * (run[i][j] - run[0][j]) + 0.2 * amplitude[j] * noise(&mut seed)).collect());
    }
    poses
}

/// sqrt(sum |F~ - F|^2 / sum |F - F(0)|^2) over the poses.
fn relative_force_error(cubature: &mut Simulator, exact: &mut Simulator, poses: &[Vec<f64>]) -> f64 {
    let zero = vec![0.0; poses[0].len()];
    let f0 = exact.spring_force(&zero).unwrap();
    let (mut num, mut den) = (0.0, 0.0);
    for q in poses {
        let (fc, fe) = (cubature.spring_force(q).unwrap(), exact.spring_force(q).unwrap());
        num += fc.iter().zip(&fe).map(|(a, b)| (a - b).powi(2)).sum::<f64>();
        den += fe.iter().zip(&f0).map(|(a, b)| (a - b).powi(2)).sum::<f64>();
    }
    (num / den).sqrt()
}

#[test]
fn cubature_reproduces_the_projected_force_on_held_out_poses() {
    for (name, r, lin) in [
        ("paper-2d-top-row", 8, Linearization::Rest),
        ("paper-2d-top-corners", 8, Linearization::Equilibrium),
        ("paper-3d-sheet", 8, Linearization::Rest),
        ("cloth-3d", 16, Linearization::Rest),
    ] {
        for tolerance in [0.01, 0.002] {
            let setup = canonical_scenes::canonical(name).unwrap();
            let mut exact = setup.with_settings(solver(Integrator::NewmarkExplicit, r, lin, ForceEvaluation::Exact, tolerance)).simulator().unwrap();
            let mut cubature = setup.with_settings(solver(Integrator::NewmarkExplicit, r, lin, ForceEvaluation::Cubature, tolerance)).simulator().unwrap();
            let poses = held_out_poses(&mut exact);
            let e = relative_force_error(&mut cubature, &mut exact, &poses);
            let (kept, all) = (cubature.cubature_springs(), exact.cubature_springs());
            eprintln!("{name} r = {r} {lin:?}, tolerance {tolerance}: {kept} of {all} springs, held-out force error {e:.2e}");
            assert!(e <= tolerance, "{name}: held-out relative force error {e:.3e} above the tolerance {tolerance}");
            assert!(kept < all, "{name}: {kept} of {all} springs kept");
        }
    }
}

#[test]
fn cubature_runs_follow_exact_forces_with_both_integrators() {
    let setup = canonical_scenes::canonical("paper-2d-top-row").unwrap();
    for integrator in [Integrator::NewmarkExplicit, Integrator::NewmarkImplicit] {
        let frames = |force| {
            let mut s = solver(integrator, 8, Linearization::Rest, force, 0.002);
            s.max_internal_step = 0.005;
            let mut sim = setup.with_settings(s).simulator().unwrap();
            let mut out = vec![sim.positions().to_vec()];
            for _ in 0..200 {
                sim.do_step(0.01).unwrap();
                out.push(sim.positions().to_vec());
            }
            out
        };
        let exact = frames(ForceEvaluation::Exact);
        let e = trajectory_error(&frames(ForceEvaluation::Cubature), &exact, &exact[0], Masses::Equal);
        eprintln!("{integrator:?}: E(cubature, exact) = {e:.2e} over 2 s");
        assert!(e <= 0.01, "{integrator:?}: E(cubature, exact) = {e}");
    }
}

#[test]
fn the_fmu_reports_the_springs_it_keeps_and_refuses_bad_tolerances() {
    let springs = |evaluation: i64| {
        let f = Fmu::new();
        assert_eq!(f.set_i64(vr::MODE_SELECTION, 2), OK);
        let on = true;
        assert_eq!(unsafe { modal_mass_spring::fmi::exports::fmi3SetBoolean(f.inst, &vr::STATIC_CORRECTION, 1, &on, 1) }, OK);
        assert_eq!(f.set_i64(vr::FORCE_EVALUATION, evaluation), OK);
        for bad in [0.0, -1e-3, 1.5, f64::NAN, f64::INFINITY] {
            assert_eq!(f.set_f64(vr::CUBATURE_TOLERANCE, &[bad]), ERROR, "cubatureTolerance = {bad}");
            assert!(f.messages().iter().any(|m| m.contains("cubatureTolerance")), "{:?}", f.messages());
        }
        assert_eq!(f.f64s(vr::CUBATURE_TOLERANCE, 1), vec![0.01], "the value before the refused ones is kept");
        for bad in [0, 3, -1] {
            assert_eq!(f.set_i64(vr::FORCE_EVALUATION, bad), ERROR, "forceEvaluation = {bad}");
        }
        f.init();
        f.run(10, 0.01);
        f.get_u64(vr::CUBATURE_SPRINGS)
    };
    let (exact, cubature) = (springs(1), springs(2));
    let all = canonical_scenes::canonical("paper-2d-top-row").unwrap().grid.build().unwrap().springs.len() as u64;
    assert_eq!(exact, all);
    assert!(cubature > 0 && cubature < all / 4, "{cubature} of {all}");
}

/// The costly outputs are computed when read (`docs/method.md`, section 4):
/// a run that reads every output after every step and one that reads
/// nothing for 300 steps report the same bits then, with exact and
/// cubature forces, both schemes; and reading does not change the run.
#[test]
fn outputs_read_or_not_give_the_same_run() {
    let p = canonical_scenes::canonical("paper-2d-top-row").unwrap().grid;
    for force in [ForceEvaluation::Exact, ForceEvaluation::Cubature] {
        for integrator in [Integrator::NewmarkExplicit, Integrator::NewmarkImplicit] {
            let s = solver(integrator, 8, Linearization::Rest, force, 0.01);
            let mut reader = Simulator::new(p.build().unwrap(), &s, &Loads::physical(8)).unwrap();
            let mut quiet = Simulator::new(p.build().unwrap(), &s, &Loads::physical(8)).unwrap();
            let read = |sim: &mut Simulator| -> Vec<u64> {
                let mut bits: Vec<u64> = sim.positions().iter().map(|x| x.to_bits()).collect();
                bits.extend(sim.velocities().iter().map(|x| x.to_bits()));
                bits.extend(sim.modal_coordinates().iter().map(|x| x.to_bits()));
                bits.extend([sim.kinetic_energy(), sim.potential_energy(), sim.force_residual()].map(f64::to_bits));
                bits
            };
            for _ in 0..300 {
                reader.do_step(0.01).unwrap();
                read(&mut reader);
                quiet.do_step(0.01).unwrap();
            }
            assert!(reader.kinetic_energy() > 0.0, "{force:?} {integrator:?}: the run moves");
            assert_eq!(read(&mut reader), read(&mut quiet), "{force:?} {integrator:?}: outputs read every step and once differ");
        }
    }
}
