//! springNeighbours lists exactly the springs between nodes of the scene
//! the FMU builds (each pair once, in output order), for grids with and
//! without shear and bending springs, in 2D and in 3D (whose auxiliary
//! springs, to points off the sheet, are left out).

use crate::common;

use std::collections::BTreeSet;

use common::*;
use modal_mass_spring::fmi::exports::*;
use modal_mass_spring::fmi::variables::vr;
use modal_mass_spring::model::{Params, MAX_SPRINGS_PER_NODE};

/// The node pairs (i < j) of the springs of the scene `p` describes.
fn scene_pairs(p: &Params) -> BTreeSet<(usize, usize)> {
    let scene = p.grid().build().unwrap();
    let node_of = |slot: usize| scene.slot_of_node.iter().position(|&s| s == slot);
    scene.springs.iter().filter_map(|s| Some((node_of(s.a)?, node_of(s.b)?))).map(|(a, b)| (a.min(b), a.max(b))).collect()
}

/// The pairs the FMU reports, every one checked to be listed once, ascending per node.
fn fmu_pairs(f: &Fmu) -> BTreeSet<(usize, usize)> {
    let (nx, ny, _, _) = f.sizes();
    let n = nx * ny;
    let mut ends = vec![0u64; n * MAX_SPRINGS_PER_NODE];
    assert_eq!(unsafe { fmi3GetUInt64(f.inst, &vr::SPRING_NEIGHBOURS, 1, ends.as_mut_ptr(), ends.len()) }, OK, "{:?}", f.messages());
    let mut pairs = BTreeSet::new();
    for (i, js) in ends.chunks(MAX_SPRINGS_PER_NODE).enumerate() {
        let listed: Vec<usize> = js.iter().map(|&j| j as usize).take_while(|&j| j < n).collect();
        assert!(js[listed.len()..].iter().all(|&j| j as usize == n), "node {i}: {js:?}");
        assert!(listed.windows(2).all(|w| w[0] < w[1]) && listed.iter().all(|&j| j > i), "node {i}: {js:?}");
        pairs.extend(listed.into_iter().map(|j| (i, j)));
    }
    pairs
}

#[test]
fn spring_neighbours_are_the_scene_springs() {
    for (nx, ny, dim, shear, bending) in
        [(10usize, 10usize, 2usize, true, false), (4, 3, 2, false, false), (5, 6, 3, true, true), (1, 4, 2, true, true), (7, 2, 3, false, true)]
    {
        let f = Fmu::new();
        for (r, x) in [(vr::NX, nx), (vr::NY, ny), (vr::DIMENSION, dim), (vr::N_MODES, 1)] {
            assert_eq!(f.set_u64(r, x as u64), OK, "{:?}", f.messages());
        }
        let flags = [shear, bending];
        let refs = [vr::SHEAR_SPRINGS, vr::BENDING_SPRINGS];
        assert_eq!(unsafe { fmi3SetBoolean(f.inst, refs.as_ptr(), 2, flags.as_ptr(), 2) }, OK, "{:?}", f.messages());
        let mut p = Params::start();
        for (r, x) in [(vr::NX, nx), (vr::NY, ny), (vr::DIMENSION, dim), (vr::N_MODES, 1)] {
            p.set(r, &[x as f64]);
        }
        p.set(vr::SHEAR_SPRINGS, &[shear as u8 as f64]);
        p.set(vr::BENDING_SPRINGS, &[bending as u8 as f64]);
        let what = format!("{nx} x {ny}, {dim}D, shear {shear}, bending {bending}");
        let expected = scene_pairs(&p);
        // Along rows and columns, plus two diagonals per cell and the bending
        // springs, but those along the held top row (they never act).
        let along = |n: usize, gap: usize| n.saturating_sub(gap);
        let mut count = ny * along(nx, 1) + nx * along(ny, 1) - along(nx, 1);
        if shear {
            count += 2 * along(nx, 1) * along(ny, 1);
        }
        if bending {
            count += ny * along(nx, 2) + nx * along(ny, 2) - along(nx, 2);
        }
        assert_eq!(expected.len(), count, "{what}: the scene");
        // Readable before initialization (a calculated parameter), and the same after.
        assert_eq!(fmu_pairs(&f), expected, "{what}");
        f.init();
        assert_eq!(fmu_pairs(&f), expected, "{what}: in Step Mode");
    }
}
