//! Twins through the FMU (`docs/method.md`, section 6): startOffset moves
//! every free node by that length in a direction drawn from startSeed when
//! the instance sets up, through `Simulator::displace`. A twin of the FMU is
//! the run of a simulator displaced by the same seeded directions, bit for
//! bit; startOffset = 0 is the canonical run, bit for bit; values out of
//! range are refused with the instance kept as it was.

use crate::common;

use common::*;
use modal_mass_spring::fmi::variables::vr;
use modal_mass_spring::measures::twin_offset;
use modal_mass_spring::model::Params;
use modal_mass_spring::physics::Simulator;

const H: f64 = 0.01;
const STEPS: usize = 30;
const FULL: i64 = 2;

/// An instance of the default scene with `reduction` and `nModes`, and the
/// twin's start values unless `None`.
fn instance(reduction: i64, n_modes: u64, twin: Option<(f64, u64)>) -> Fmu {
    let f = Fmu::new();
    assert_eq!(f.set_i64(vr::REDUCTION, reduction), OK);
    assert_eq!(f.set_u64(vr::N_MODES, n_modes), OK);
    if let Some((offset, seed)) = twin {
        assert_eq!(f.set_f64(vr::START_OFFSET, &[offset]), OK, "{:?}", f.messages());
        assert_eq!(f.set_u64(vr::START_SEED, seed), OK, "{:?}", f.messages());
    }
    f
}

/// The positions after each of STEPS steps, and before the first.
fn fmu_run(f: &Fmu) -> (Vec<f64>, Vec<Vec<f64>>) {
    f.init();
    let start = f.positions();
    let frames = (0..STEPS)
        .map(|_| {
            f.run(1, H);
            f.positions()
        })
        .collect();
    (start, frames)
}

/// The same scene as a simulator of the library, set up canonically.
fn simulator(reduction: i64, n_modes: u64) -> Simulator {
    let mut p = Params::start();
    p.set(vr::REDUCTION, &[reduction as f64]);
    p.set(vr::N_MODES, &[n_modes as f64]);
    p.build().unwrap()
}

fn sim_run(mut sim: Simulator) -> (Vec<f64>, Vec<Vec<f64>>) {
    let start = sim.positions().to_vec();
    let frames = (0..STEPS)
        .map(|_| {
            sim.do_step(H).unwrap();
            sim.positions().to_vec()
        })
        .collect();
    (start, frames)
}

fn all_bits(start: &[f64], frames: &[Vec<f64>]) -> Vec<u64> {
    bits(&[start.to_vec()].into_iter().chain(frames.iter().cloned()).flatten().collect::<Vec<_>>())
}

#[test]
fn the_seeded_directions_have_the_offset_as_length_and_follow_the_seed() {
    let (size, dim) = (1e-7, 3);
    let a = twin_offset(30, dim, size, 1);
    assert_eq!(a.len(), 30);
    for node in a.chunks(dim) {
        let len = node.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!((len - size).abs() < 1e-15 * size, "{len}");
    }
    assert_eq!(bits(&twin_offset(30, dim, size, 1)), bits(&a), "the same seed, the same start");
    let b = twin_offset(30, dim, size, 2);
    assert!(a.iter().zip(&b).all(|(x, y)| x != y), "another seed, another direction for every node");
    // The directions spread over every axis and both signs.
    for axis in 0..dim {
        let along: Vec<f64> = a.chunks(dim).map(|n| n[axis]).collect();
        assert!(along.iter().any(|&x| x > 0.3 * size) && along.iter().any(|&x| x < -0.3 * size), "axis {axis}: {along:?}");
    }
}

#[test]
fn a_full_space_twin_is_the_simulator_displaced_by_the_seeded_directions() {
    for seed in [1, 3] {
        let (start, frames) = fmu_run(&instance(FULL, 2, Some((1e-7, seed))));
        let mut sim = simulator(FULL, 2);
        let scene = sim.scene().clone();
        let canonical_start = sim.positions().to_vec();
        sim.displace(&twin_offset(scene.n_dofs(), scene.dim, 1e-7, seed)).unwrap();
        let (sim_start, sim_frames) = sim_run(sim);
        assert_eq!(all_bits(&start, &frames), all_bits(&sim_start, &sim_frames), "seed {seed}");
        // Every free node starts 1e-7 m from its canonical start, every held one on it.
        let d = scene.dim;
        for (node, (x, x0)) in start.chunks(d).zip(canonical_start.chunks(d)).enumerate() {
            let moved = x.iter().zip(x0).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
            if scene.slot_of_node[node] < scene.n_free {
                assert!((moved - 1e-7).abs() < 1e-9 * 1e-7 + 1e-15, "node {node}: {moved}");
            } else {
                assert_eq!(moved, 0.0, "held node {node}");
            }
        }
    }
}

#[test]
fn a_modal_twin_starts_at_the_modal_coordinates_of_the_displacement() {
    let f = instance(1, 6, Some((1e-4, 5)));
    let (start, frames) = fmu_run(&f);
    let mut sim = simulator(1, 6);
    let scene = sim.scene().clone();
    let canonical_start = sim.positions().to_vec();
    let dy = twin_offset(scene.n_dofs(), scene.dim, 1e-4, 5);
    let basis = sim.setup_data().unwrap().basis;
    let mut q = vec![0.0; basis.r];
    basis.project_displacement(&scene.dof_mass, &dy, &mut q);
    sim.displace(&q).unwrap();
    let (sim_start, sim_frames) = sim_run(sim);
    assert_eq!(all_bits(&start, &frames), all_bits(&sim_start, &sim_frames));
    // The basis holds part of the displacement: the start moved, by less than
    // the displacement itself in the mass norm (an M-orthogonal projection).
    let m = scene.dof_mass[0];
    let moved: f64 = start.iter().zip(&canonical_start).map(|(a, b)| m * (a - b).powi(2)).sum();
    let whole: f64 = dy.iter().zip(&scene.dof_mass).map(|(d, m)| m * d * d).sum();
    assert!(moved > 0.0 && moved < whole, "{moved} {whole}");
}

#[test]
fn no_offset_is_the_canonical_run_bit_for_bit() {
    for (reduction, n_modes) in [(1, 2), (FULL, 2)] {
        let (start, frames) = fmu_run(&instance(reduction, n_modes, None));
        let (zero_start, zero_frames) = fmu_run(&instance(reduction, n_modes, Some((0.0, 12345))));
        assert_eq!(all_bits(&zero_start, &zero_frames), all_bits(&start, &frames), "reduction {reduction}");
        let (sim_start, sim_frames) = sim_run(simulator(reduction, n_modes));
        assert_eq!(all_bits(&start, &frames), all_bits(&sim_start, &sim_frames), "reduction {reduction}");
        // A twin does differ from it.
        let (_, twin) = fmu_run(&instance(reduction, n_modes, Some((1e-7, 1))));
        assert_ne!(bits(&twin[STEPS - 1]), bits(&frames[STEPS - 1]), "reduction {reduction}");
    }
}

#[test]
fn offsets_and_seeds_out_of_range_are_refused_with_the_instance_kept() {
    let f = Fmu::new();
    assert_eq!(f.set_f64(vr::START_OFFSET, &[1e-7]), OK);
    let before = f.snapshot();
    for bad in [f64::NAN, f64::INFINITY, -1e-9, f64::next_up(1e-3), 1.0] {
        let status = f.set_f64(vr::START_OFFSET, &[bad]);
        let last = f.messages().last().cloned().unwrap_or_default();
        assert!(last.contains("startOffset"), "{bad}: {last}");
        f.expect_error(status, &format!("startOffset = {bad}"));
        assert_eq!(f.snapshot(), before, "startOffset = {bad} changed the instance");
    }
    for bad in [1u64 << 32, u64::MAX] {
        f.refused(f.set_u64(vr::START_SEED, bad), "startSeed");
        assert_eq!(f.snapshot(), before, "startSeed = {bad} changed the instance");
    }
    assert_eq!(f.set_f64(vr::START_OFFSET, &[1e-3]), OK, "the largest offset");
    assert_eq!(f.set_u64(vr::START_SEED, u32::MAX as u64), OK, "the largest seed");
    // A start value: fixed once the run has started.
    f.init();
    let running = f.snapshot();
    f.refused(f.set_f64(vr::START_OFFSET, &[1e-7]), "startOffset");
    assert_eq!(f.snapshot(), running);
}
