//! How far a scene is predictable (`docs/method.md`, section 6): full-space
//! twins started 1e-7 m from the canonical start, each free node moved by a
//! random vector of that length (seeded), against the canonical run. Cloth
//! is chaotic: its twins' E reaches 1e-3 within the run and ends far above
//! it; the paper's 2D sheet is regular: its twins stay within round-off of
//! the perturbation. E measured on either over the whole run says as much
//! about the scene as about any model.

use modal_mass_spring::canonical_scenes::{self, Setup};
use modal_mass_spring::measures::{predictability, trajectory_errors_by_window, twin_offset, Masses};
use modal_mass_spring::physics::*;

const H: f64 = 0.01;

/// Node positions after each of `steps` steps of `H`, the start moved by `kick`.
fn run(setup: &Setup, steps: usize, kick: Option<&[f64]>) -> (Vec<f64>, Vec<Vec<f64>>) {
    let mut sim = setup.simulator().unwrap();
    let start = sim.positions().to_vec();
    if let Some(dy) = kick {
        sim.displace(dy).unwrap();
    }
    let frames = (0..steps)
        .map(|_| {
            sim.do_step(H).unwrap();
            sim.positions().to_vec()
        })
        .collect();
    (start, frames)
}

/// (horizon, twins' floor at the end) of `setup` in full space over `steps` steps, 3 twins.
fn horizon(setup: Setup, steps: usize) -> (Option<f64>, f64) {
    let setup = setup.with_settings(Settings::new(Reduction::Full, Integrator::NewmarkExplicit, 0));
    let (start, reference) = run(&setup, steps, None);
    let scene = setup.grid.build().unwrap();
    let twins: Vec<Vec<f64>> = (1..=3)
        .map(|seed| {
            let (_, frames) = run(&setup, steps, Some(&twin_offset(scene.n_dofs(), scene.dim, 1e-7, seed)));
            trajectory_errors_by_window(&frames, &reference, &start, Masses::Equal)
        })
        .collect();
    let times: Vec<f64> = (1..=steps).map(|k| k as f64 * H).collect();
    predictability(&times, &twins, 1e-3)
}

#[test]
fn cloth_is_predictable_for_a_while_the_paper_sheet_throughout() {
    let (cloth, cloth_floor) = horizon(canonical_scenes::cloth(12, 12), 200);
    let (paper, paper_floor) = horizon(canonical_scenes::canonical("paper-2d-top-row").unwrap(), 200);
    println!(
        "cloth 12 x 12: horizon {cloth:?} s, twins' E over 2 s {cloth_floor:.2e}; paper-2d-top-row: horizon {paper:?}, twins' E over 2 s {paper_floor:.2e}"
    );
    let t = cloth.expect("the cloth's twins part within 2 s");
    assert!(t > 0.05 && t < 2.0, "{t}");
    assert!(cloth_floor > 1e-2, "{cloth_floor}");
    assert!(paper.is_none() && paper_floor < 1e-4, "{paper:?} {paper_floor}");
}

#[test]
fn a_twin_start_of_the_wrong_size_or_not_finite_is_refused_with_the_state_kept() {
    let mut sim = canonical_scenes::canonical("paper-2d-top-row")
        .unwrap()
        .with_settings(Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, 4))
        .simulator()
        .unwrap();
    sim.do_step(H).unwrap();
    let before = sim.snapshot();
    assert_eq!(sim.displace(&[0.0; 3]), Err(PhysicsError::SnapshotLength { len: 3, expected: 4 }));
    assert_eq!(sim.displace(&[0.0, f64::NAN, 0.0, 0.0]), Err(PhysicsError::SnapshotNotFinite));
    assert_eq!(sim.snapshot(), before);
    sim.displace(&[1e-3, 0.0, 0.0, 0.0]).unwrap();
    assert_eq!(sim.snapshot().state.y[0], before.state.y[0] + 1e-3);
}
