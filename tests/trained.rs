//! Trained bases (`modeSelection = trained`, `docs/method.md` section 3):
//! the principal components of full-space runs under a training program,
//! diagonalized so each vector keeps a frequency; judged on cloth, which is
//! chaotic, within the window it is predictable (0.5 s and 1 s: its twins
//! started 1e-7 m away part at about 0.75 s, tests/predictability.rs).

use crate::common;

use common::*;
use modal_mass_spring::canonical_scenes::{self, Setup};
use modal_mass_spring::fmi::variables::vr;
use modal_mass_spring::measures::{trajectory_errors_by_window, Masses};
use modal_mass_spring::physics::setup::basis::linearize;
use modal_mass_spring::physics::setup::trained_basis::program;
use modal_mass_spring::physics::*;

const H: f64 = 0.01;

fn trained(r: usize, static_correction: bool, force: ForceEvaluation) -> Settings {
    Settings {
        mode_selection: ModeSelection::Trained,
        static_correction,
        force_evaluation: force,
        ..Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, r)
    }
}

/// Gravity 9.81 m/s^2 times `scale`, turned by `z_deg` about z, then by `x_deg` about x.
fn gravity(scale: f64, x_deg: f64, z_deg: f64) -> [f64; 3] {
    let (a, b) = (x_deg.to_radians(), z_deg.to_radians());
    let g = [9.81 * b.sin(), -9.81 * b.cos(), 0.0];
    [scale * g[0], scale * g[1] * a.cos(), scale * g[1] * a.sin()]
}

/// (start, frames, largest trainingRange) of `setup` with gravity `g` set after set-up, 1 s.
fn run(setup: &Setup, g: [f64; 3]) -> (Vec<f64>, Vec<Vec<f64>>, f64) {
    let mut sim = setup.simulator().unwrap_or_else(|e| panic!("{e}"));
    let start = sim.positions().to_vec();
    sim.set_loads(&Loads { gravity: g, ..sim.loads().clone() }).unwrap();
    let mut range: f64 = 0.0;
    let frames = (0..100)
        .map(|_| {
            sim.do_step(H).unwrap_or_else(|e| panic!("{e}"));
            range = range.max(sim.training_range());
            sim.positions().to_vec()
        })
        .collect();
    (start, frames, range)
}

/// E over [0, 0.5 s] and [0, 1 s] of `settings` on cloth 30 x 30 under `g` against full space, and the largest trainingRange.
fn cloth_error(settings: Settings, g: [f64; 3], reference: &[Vec<f64>]) -> (f64, f64, f64) {
    let (start, frames, range) = run(&canonical_scenes::cloth(30, 30).with_settings(settings), g);
    let e = trajectory_errors_by_window(&frames, reference, &start, Masses::Equal);
    (e[49], e[99], range)
}

#[test]
fn a_trained_basis_is_mass_orthonormal_and_diagonalizes_the_stiffness() {
    for (name, setup, r) in
        [("paper-2d-top-row", canonical_scenes::canonical("paper-2d-top-row").unwrap(), 8), ("cloth 12 x 12", canonical_scenes::cloth(12, 12), 16)]
    {
        for correction in [false, true] {
            let settings = trained(r, correction, ForceEvaluation::Exact);
            let setup = setup.with_settings(settings.clone());
            let sim = setup.simulator().unwrap();
            let data = sim.setup_data().unwrap();
            let scene = setup.grid.build().unwrap();
            let (n, b) = (scene.n_dofs(), &data.basis);
            let (_, pattern, stiffness) = linearize(&scene, &setup.loads, &settings).unwrap();
            let col = |j: usize| -> Vec<f64> { (0..n).map(|i| b.phi[i * r + j]).collect() };
            let mut kphi = vec![0.0; n];
            let (mut mass_err, mut stiff_err) = (0.0f64, 0.0f64);
            let lambda_max = b.lambda.iter().fold(0.0f64, |m, l| m.max(*l));
            for j in 0..r {
                pattern.sym_matvec(&stiffness, &col(j), &mut kphi);
                for i in 0..r {
                    let ci = col(i);
                    let m: f64 = (0..n).map(|k| ci[k] * scene.dof_mass[k] * b.phi[k * r + j]).sum();
                    let k: f64 = (0..n).map(|k| ci[k] * kphi[k]).sum();
                    mass_err = mass_err.max((m - if i == j { 1.0 } else { 0.0 }).abs());
                    stiff_err = stiff_err.max((k - if i == j { b.lambda[j] } else { 0.0 }).abs() / lambda_max);
                }
            }
            println!(
                "{name}, r = {r}, static correction {correction}: |Phi^T M Phi - I| {mass_err:.1e}, |Phi^T K Phi - diag(lambda)| / lambda_max {stiff_err:.1e}"
            );
            assert!(mass_err < 1e-10 && stiff_err < 1e-10, "{name}: {mass_err:e} {stiff_err:e}");
            assert!(b.lambda.windows(2).all(|w| w[0] <= w[1]) && b.lambda[0] > 0.0, "{:?}", b.lambda);
            let range = data.range.as_ref().expect("a trained basis states its range");
            assert_eq!((range.center.len(), range.half_width.len()), (r, r));
        }
    }
}

#[test]
fn on_cloth_a_trained_basis_reproduces_its_loads_and_loads_inside_its_range_it_never_ran() {
    let full = canonical_scenes::cloth(30, 30).with_settings(Settings::new(Reduction::Full, Integrator::NewmarkExplicit, 0));
    let canonical = gravity(1.0, 0.0, 0.0);
    let held_out = gravity(0.85, 10.0, 10.0);
    let (_, reference, _) = run(&full, canonical);
    let (_, reference_held, _) = run(&full, held_out);
    let (e05, e1, range) = cloth_error(trained(32, false, ForceEvaluation::Exact), canonical, &reference);
    let (h05, h1, h_range) = cloth_error(trained(32, false, ForceEvaluation::Exact), held_out, &reference_held);
    let load = Settings { mode_selection: ModeSelection::Load, static_correction: true, ..Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, 32) };
    let (l05, l1, _) = cloth_error(load.clone(), canonical, &reference);
    let (lh05, lh1, _) = cloth_error(load, held_out, &reference_held);
    println!("cloth 30 x 30, r = 32, E over [0, 0.5 s] / [0, 1 s]: trained {e05:.4} / {e1:.4} (trainingRange {range:.2}), held-out load 0.85 g tilted 10 degrees about x and z {h05:.4} / {h1:.4} ({h_range:.2})");
    println!("   load + static correction: {l05:.4} / {l1:.4}, held-out {lh05:.4} / {lh1:.4}");
    assert!(e05 <= 0.005 && e1 <= 0.005, "{e05} {e1}");
    assert!(h05 <= 0.006 && h1 <= 0.006, "{h05} {h1}");
    assert!(range <= 1.2 && h_range <= 1.2, "{range} {h_range}");
    // The eigenmodes chosen by the load do not get there.
    assert!(l1 > 3.0 * e1 && lh1 > 3.0 * h1, "{l1} {lh1}");

    // Cubature trained on the same snapshots keeps the error (r = 16: a set-up of a second).
    let (x05, x1, _) = cloth_error(trained(16, false, ForceEvaluation::Exact), held_out, &reference_held);
    let (c05, c1, _) = cloth_error(trained(16, false, ForceEvaluation::Cubature), held_out, &reference_held);
    println!("   r = 16, held-out load: exact forces {x05:.4} / {x1:.4}, cubature {c05:.4} / {c1:.4}");
    assert!(c05 <= 1.5 * x05 && c1 <= 1.5 * x1, "{c05} {x05} {c1} {x1}");
}

#[test]
fn a_load_outside_the_training_range_raises_the_indicator() {
    let settings = trained(16, false, ForceEvaluation::Exact);
    let (_, _, inside) = run(&canonical_scenes::cloth(30, 30).with_settings(settings.clone()), gravity(1.0, 0.0, 0.0));
    let (_, _, outside) = run(&canonical_scenes::cloth(30, 30).with_settings(settings), gravity(1.5, 45.0, 0.0));
    println!("cloth 30 x 30, r = 16: largest trainingRange {inside:.2} on the canonical load, {outside:.2} at 1.5 g tilted 45 degrees");
    assert!(inside <= 1.2, "{inside}");
    assert!(outside > 3.0, "{outside}");
    // Other bases have no training range.
    let mut sim = canonical_scenes::cloth(12, 12).with_settings(Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, 4)).simulator().unwrap();
    sim.do_step(H).unwrap();
    assert_eq!(sim.training_range(), 0.0);
}

#[test]
fn a_trained_set_up_with_cubature_runs_bit_for_bit_from_its_data() {
    for (setup, r) in [(canonical_scenes::canonical("paper-2d-top-row").unwrap(), 6), (canonical_scenes::canonical("paper-3d-sheet").unwrap(), 8)] {
        let setup = setup.with_settings(trained(r, true, ForceEvaluation::Cubature));
        let mut computed = setup.simulator().unwrap();
        let data = SetupData::from_bytes(&computed.setup_data().unwrap().to_bytes()).expect("the data reads back");
        assert!(data.cubature.is_some() && data.range.is_some());
        let mut stored = Simulator::with_setup(setup.grid.build().unwrap(), &setup.settings, &setup.loads, Some(&data)).unwrap();
        for _ in 0..50 {
            computed.do_step(H).unwrap();
            stored.do_step(H).unwrap();
            let bits = |s: &mut Simulator| {
                let range = s.training_range().to_bits();
                s.positions().iter().map(|x| x.to_bits()).chain([range]).collect::<Vec<u64>>()
            };
            assert_eq!(bits(&mut computed), bits(&mut stored));
        }
    }
}

#[test]
fn the_training_program_covers_the_set_up_loads_scaled_and_tilted_and_the_announced_motion() {
    let g_of = |c: &modal_mass_spring::physics::setup::trained_basis::Case| c.gravity.iter().map(|x| x * x).sum::<f64>().sqrt();
    let angle = |a: &[f64; 3], b: &[f64; 3]| {
        let dot: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
        let n = |v: &[f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        (dot / (n(a) * n(b))).clamp(-1.0, 1.0).acos()
    };
    for (setup, tilts) in [(canonical_scenes::canonical("paper-2d-top-row").unwrap(), 2), (canonical_scenes::cloth(12, 12), 4)] {
        let scene = setup.grid.build().unwrap();
        let settings = trained(4, false, ForceEvaluation::Exact);
        let cases = program(&scene, &setup.loads, &settings).unwrap();
        assert_eq!(cases.len(), 1 + 2 + tilts, "{cases:#?}");
        let g = setup.loads.gravity;
        assert_eq!(cases[0].gravity, g);
        let mags: Vec<f64> = cases.iter().map(g_of).collect();
        assert!((mags[1] / mags[0] - 0.7).abs() < 1e-12 && (mags[2] / mags[0] - 1.3).abs() < 1e-12, "{mags:?}");
        for c in &cases[3..] {
            assert!((g_of(c) / mags[0] - 1.0).abs() < 1e-12 && (angle(&c.gravity, &g) - 20f64.to_radians()).abs() < 1e-12, "{c:?}");
        }
        let moving = Settings { anchor_motion: true, anchor_rotation: true, ..settings };
        let more = program(&scene, &setup.loads, &moving).unwrap();
        let axes = if scene.dim == 2 { 1 } else { 3 };
        assert_eq!(more.len(), cases.len() + 2 * scene.dim + axes);
        assert_eq!(more.iter().filter(|c| c.spin != [0.0; 3]).count(), axes);
    }
}

#[test]
fn a_training_range_out_of_bounds_is_refused() {
    let setup = canonical_scenes::canonical("paper-2d-top-row").unwrap();
    let scene = setup.grid.build().unwrap();
    for (training, quantity) in [
        (TrainingProgram { scale: 1.0, ..TrainingProgram::default() }, Quantity::TrainingScale),
        (TrainingProgram { scale: -0.1, ..TrainingProgram::default() }, Quantity::TrainingScale),
        (TrainingProgram { scale: f64::NAN, ..TrainingProgram::default() }, Quantity::TrainingScale),
        (TrainingProgram { tilt: -0.1, ..TrainingProgram::default() }, Quantity::TrainingTilt),
        (TrainingProgram { tilt: 1.6, ..TrainingProgram::default() }, Quantity::TrainingTilt),
        (TrainingProgram { time: 0.0, ..TrainingProgram::default() }, Quantity::TrainingTime),
        (TrainingProgram { time: -1.0, ..TrainingProgram::default() }, Quantity::TrainingTime),
        (TrainingProgram { time: f64::INFINITY, ..TrainingProgram::default() }, Quantity::TrainingTime),
    ] {
        let settings = Settings { training, ..trained(4, false, ForceEvaluation::Exact) };
        match Simulator::new(scene.clone(), &settings, &Loads { mode_weights: vec![1.0; 4], ..setup.loads.clone() }) {
            Err(PhysicsError::Invalid { quantity: q, .. }) => assert_eq!(q, quantity),
            Err(e) => panic!("{e}"),
            Ok(_) => panic!("{:?} accepted", settings.training),
        }
    }
    // No load to train under.
    let none = Loads { gravity: [0.0; 3], mode_weights: vec![1.0; 4], ..setup.loads.clone() };
    assert!(matches!(Simulator::new(scene, &trained(4, false, ForceEvaluation::Exact), &none), Err(PhysicsError::NoLoad)));
}

/// Through the C functions: the range's limit warns once when the run
/// leaves it, the training parameters refuse bad values and keep theirs.
#[test]
fn through_the_fmu_leaving_the_range_warns_and_bad_training_values_are_refused() {
    let f = Fmu::new();
    assert_eq!(f.set_u64(vr::N_MODES, 6), OK);
    assert_eq!(f.set_i64(vr::MODE_SELECTION, 3), OK);
    for (r, bad) in [
        (vr::TRAINING_SCALE, 0.95),
        (vr::TRAINING_SCALE, f64::NAN),
        (vr::TRAINING_TILT, -0.1),
        (vr::TRAINING_TIME, 0.0),
        (vr::TRAINING_TIME, 11.0),
        (vr::TRAINING_RANGE_LIMIT, -1.0),
    ] {
        let before = f.f64s(r, 1);
        f.expect_error(f.set_f64(r, &[bad]), &format!("{r} = {bad}"));
        assert_eq!(f.f64s(r, 1), before, "{r}: the value is kept");
    }
    f.init();
    let range = |f: &Fmu| f.f64s(vr::TRAINING_RANGE, 1)[0];
    let mut inside = 0.0f64;
    for _ in 0..100 {
        assert_eq!(f.step(f.time(), 0.01), OK, "{:?}", f.messages());
        inside = inside.max(range(&f));
    }
    assert!(inside > 0.0 && inside <= 1.2, "{inside}");
    // Gravity twice as strong and turned 60 degrees: outside the range.
    assert_eq!(f.set_f64(vr::GRAVITY, &[2.0 * 9.81 * 60f64.to_radians().sin(), -2.0 * 9.81 * 60f64.to_radians().cos(), 0.0]), OK);
    let statuses: Vec<_> = (0..100).map(|_| f.step(f.time(), 0.01)).collect();
    assert!(range(&f) > 2.0, "{}", range(&f));
    assert!(statuses.iter().all(|&s| s == OK || s == WARNING));
    // Once, saying why (forceResidual may warn too, once, on its own step).
    let warned: Vec<String> = f.log.take().into_iter().filter(|(s, _, _)| *s == WARNING).map(|(_, _, m)| m).collect();
    let range_warnings = warned.iter().filter(|m| m.contains("trainingRange = ") && m.contains("trainingRangeLimit")).count();
    assert_eq!(range_warnings, 1, "{warned:?}");
    assert_eq!(statuses.iter().filter(|&&s| s == WARNING).count(), warned.len(), "{statuses:?}");
}
