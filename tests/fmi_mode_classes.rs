//! modeOutOfPlane and modeSymmetry, read through the C functions on the
//! canonical scenes, say which mode is which: in 3D the lowest modes are the
//! auxiliary springs' out-of-plane cluster and the modes gravity loads lie
//! in the plane; in 2D nothing leaves the plane and, the canonical grids
//! being mirror-symmetric, every mode is symmetric or antisymmetric.

use crate::common;

use common::*;
use modal_mass_spring::fmi::exports::*;
use modal_mass_spring::fmi::variables::{index_of, vr, Type, SCENES, VARIABLES};
use modal_mass_spring::options::ModeSelection;

/// How far from 0 or +-1 a class may read where the structure makes it
/// exact. At rest the flat sheet's stiffness does not couple the
/// out-of-plane DOFs to the in-plane ones, and mirror-symmetric stiffness
/// and masses do not couple symmetric to antisymmetric shapes: the
/// eigensolver mixes two modes only by round-off, with an amplitude a of
/// about eps * lambda_max / gap, which is below 2.2e-8 where neighbouring
/// eigenvalues are at least 1e-8 lambda_max apart (checked by [`simple`];
/// the closest pair on these scenes is 3e-7 lambda_max apart). A mix enters
/// both classes squared (1 - |s| = 2 a^2 < 1e-15), and the sums over 200
/// DOFs add some 200 eps = 4e-14: 1e-12 holds both (measured: 1.4e-15).
/// A mode that is really mixed reads 1e-2 or more off.
const EXACT: f64 = 1e-12;

/// An instance set to the canonical scene `name`, through the setters.
fn scene(name: &str) -> Fmu {
    let f = Fmu::new();
    let s = SCENES.iter().find(|s| s.name == name).unwrap();
    for &(r, values) in s.values {
        let v = values[0];
        let status = match VARIABLES[index_of(r).unwrap()].ty {
            Type::Float64 => f.set_f64(r, &[v]),
            Type::UInt64 => f.set_u64(r, v as u64),
            Type::Int64 => f.set_i64(r, v as i64),
            Type::Boolean => unsafe { fmi3SetBoolean(f.inst, &r, 1, &(v != 0.0), 1) },
        };
        assert_eq!(status, OK, "{name}: {:?}", f.messages());
    }
    f
}

/// (frequencies, modeOutOfPlane, modeSymmetry) of `f`.
fn classes(f: &Fmu) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let r = f.sizes().3;
    (f.f64s(vr::MODE_FREQUENCIES, r), f.f64s(vr::MODE_OUT_OF_PLANE, r), f.f64s(vr::MODE_SYMMETRY, r))
}

/// Neighbouring eigenvalues lambda = omega^2 (outside `cluster`) are
/// apart by at least 1e-8 of the largest, so round-off mixes no two modes
/// by more than [`EXACT`] allows.
fn simple(omega: &[f64], cluster: impl Fn(f64) -> bool) {
    let top = omega.iter().fold(0.0f64, |m, &w| m.max(w * w));
    let lambdas: Vec<f64> = omega.iter().filter(|&&w| !cluster(w)).map(|w| w * w).collect();
    for p in lambdas.windows(2) {
        assert!(p[1] - p[0] > 1e-8 * top, "a repeated frequency: {p:?}");
    }
}

#[test]
fn three_d_cluster_is_out_of_plane_and_load_modes_in_it() {
    let f = scene("paper-3d-sheet");
    let (omega, out, sym) = classes(&f);
    assert_eq!(omega.len(), 126);
    // One mode per free node at sqrt(auxStiffness / nodeMass), the lowest.
    let aux = (0.05f64 / 0.01).sqrt();
    let in_cluster = |w: f64| (w - aux).abs() < 1e-9 * aux;
    let cluster: Vec<usize> = (0..omega.len()).filter(|&i| in_cluster(omega[i])).collect();
    assert_eq!(cluster, (0..42).collect::<Vec<_>>(), "{omega:?}");
    simple(&omega, in_cluster);
    for i in 0..omega.len() {
        if in_cluster(omega[i]) {
            assert!(out[i] > 1.0 - EXACT, "mode {i}: {}", out[i]);
            // A repeated frequency: any mix of its eigenspace, but a correlation all the same.
            assert!(sym[i].abs() <= 1.0 + 1e-12, "mode {i}: {}", sym[i]);
        } else {
            assert!(out[i] < EXACT, "mode {i}: {}", out[i]);
            assert!(1.0 - sym[i].abs() < EXACT, "mode {i}: {}", sym[i]);
        }
    }
    // Both kinds are there in the plane.
    assert!(sym[42..].iter().any(|&s| s > 0.0) && sym[42..].iter().any(|&s| s < 0.0));
    // Readable in Step Mode too, the same.
    f.init();
    assert_eq!(bits(&classes(&f).1), bits(&out));

    // The modes gravity (along -y, on the mid-line) loads: in the plane and symmetric.
    let f = scene("paper-3d-sheet");
    assert_eq!(f.set_u64(vr::N_MODES, 6), OK);
    assert_eq!(f.set_i64(vr::MODE_SELECTION, ModeSelection::Load as i64), OK);
    let (omega, out, sym) = classes(&f);
    assert!(omega.iter().all(|&w| w > 1.5 * aux), "{omega:?}");
    for i in 0..6 {
        assert!(out[i] < EXACT && sym[i] > 1.0 - EXACT, "load mode {i}: {} {}", out[i], sym[i]);
    }
}

#[test]
fn two_d_modes_are_in_plane_and_symmetric_or_antisymmetric() {
    for name in ["paper-2d-top-row", "paper-2d-top-corners"] {
        for reduction in [1u64, 2] {
            let f = scene(name);
            // Every mode of the scene: the modal basis keeps them, full space reports them.
            let (nx, ny, _, _) = f.sizes();
            let held = if name.ends_with("row") { nx } else { 2 };
            let dofs = 2 * (nx * ny - held);
            assert_eq!(f.set_u64(vr::N_MODES, dofs as u64), OK);
            assert_eq!(f.set_i64(vr::REDUCTION, reduction as i64), OK);
            let (omega, out, sym) = classes(&f);
            assert_eq!(omega.len(), dofs);
            simple(&omega, |_| false);
            let what = format!("{name}, reduction {reduction}");
            assert!(out.iter().all(|&o| o == 0.0), "{what}: {out:?}");
            for (i, s) in sym.iter().enumerate() {
                assert!(1.0 - s.abs() < EXACT, "{what}, mode {i}: {s}");
            }
            let plus = sym.iter().filter(|&&s| s > 0.0).count();
            assert!(plus > dofs / 3 && plus < 2 * dofs / 3, "{what}: {plus} of {dofs} symmetric");
        }
    }
}

/// modeShapes is the basis the FMU integrates in, laid out as positions:
/// mass-normalized and orthogonal, 0 on the held nodes, its out-of-plane
/// shares those of modeOutOfPlane, and after a run the free nodes sit at
/// rest + sum_i phi_i q_i with q = modalCoordinates. In full space the
/// modes it reports, all of them here, so the same holds (q = Phi^T M u).
#[test]
fn mode_shapes_are_the_basis_the_fmu_runs_in() {
    for (name, modes, reduction) in
        [("paper-3d-sheet", 126u64, 1i64), ("paper-2d-top-corners", 12, 1), ("paper-2d-top-row", 2, 1), ("paper-2d-top-corners", 196, 2)]
    {
        let f = scene(name);
        assert_eq!(f.set_u64(vr::N_MODES, modes), OK);
        assert_eq!(f.set_i64(vr::REDUCTION, reduction), OK);
        let (nx, ny, d, r) = f.sizes();
        let n = nx * ny;
        let (_, out, _) = classes(&f);
        let phi = f.f64s(vr::MODE_SHAPES, r * n * d);
        let mass = f.f64s(vr::NODE_MASS, 1)[0];
        let held: Vec<usize> = if name.ends_with("corners") { vec![0, nx - 1] } else { (0..nx).collect() };
        let shape = |i: usize| &phi[i * n * d..(i + 1) * n * d];
        for i in 0..r {
            for &k in &held {
                assert!(shape(i)[k * d..(k + 1) * d].iter().all(|&v| v == 0.0), "{name}: mode {i} moves held node {k}");
            }
            for j in 0..=i {
                let m: f64 = shape(i).iter().zip(shape(j)).map(|(a, b)| mass * a * b).sum();
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((m - want).abs() < 1e-12, "{name}: phi_{i}^T M phi_{j} = {m}");
            }
            let z: f64 = if d == 3 { shape(i).chunks(3).map(|p| mass * p[2] * p[2]).sum() } else { 0.0 };
            assert!((z - out[i]).abs() < 1e-12, "{name}: mode {i}: out of plane {z} against {}", out[i]);
        }

        // Gravity tilted out of the plane and sideways: every kind of mode moves.
        assert_eq!(f.set_f64(vr::GRAVITY, &[2.0, -9.81, 3.0]), OK);
        f.init();
        let rest = f.f64s(vr::POSITIONS, n * d);
        for k in 0..50 {
            // (the 2-mode sheet warns that its basis holds little of a sideways force: it does)
            let status = f.step(k as f64 * 0.01, 0.01);
            assert!(status == OK || status == WARNING, "{name}: {:?}", f.messages());
        }
        let (x, q) = (f.f64s(vr::POSITIONS, n * d), f.f64s(vr::MODAL_COORDINATES, r));
        let scale = x.iter().zip(&rest).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(scale > 1e-3, "{name}: the sheet did not move");
        let name = format!("{name}, reduction {reduction}");
        for (c, (xc, rc)) in x.iter().zip(&rest).enumerate() {
            let expanded: f64 = (0..r).map(|i| phi[i * n * d + c] * q[i]).sum();
            assert!((xc - rc - expanded).abs() < 1e-12 * scale, "{name}: coordinate {c}: {} against {expanded}", xc - rc);
        }
        // A shape stays what it was in Step Mode.
        assert_eq!(bits(&f.f64s(vr::MODE_SHAPES, r * n * d)), bits(&phi));
    }
}

/// Full space makes the modes it reports when they are first read: a
/// set-up whose nModes the eigensolvers cannot give (cloth 60 x 60 in 3D,
/// 10 620 free DOFs, 700 modes: more than the partial solver takes, too
/// many DOFs for the dense one) sets up and steps; reading a mode output is
/// refused with the reason, and the run goes on from where it was.
#[test]
fn full_space_makes_its_reported_modes_when_they_are_read() {
    let f = Fmu::new();
    for (r, x) in [(vr::NX, 60), (vr::NY, 60), (vr::DIMENSION, 3), (vr::N_MODES, 700)] {
        assert_eq!(f.set_u64(r, x), OK);
    }
    assert_eq!(f.set_i64(vr::REDUCTION, 2), OK);
    f.init();
    assert_eq!(f.step(0.0, 0.01), OK, "{:?}", f.messages());
    let before = f.positions();
    for r in [vr::MODAL_COORDINATES, vr::MODE_FREQUENCIES] {
        let (s, _) = f.get_f64(r, 700);
        f.refused(s, "the nModes = 700 reported modes cannot be made");
    }
    assert_eq!(bits(&f.positions()), bits(&before));
    assert_eq!(f.step(0.01, 0.01), OK, "{:?}", f.messages());
    // With modes it can make, it reports them as the modal space keeps them.
    let g = Fmu::new();
    assert_eq!(g.set_u64(vr::N_MODES, 6), OK);
    assert_eq!(g.set_i64(vr::REDUCTION, 2), OK);
    g.init();
    let m = Fmu::new();
    assert_eq!(m.set_u64(vr::N_MODES, 6), OK);
    m.init();
    assert_eq!(bits(&g.f64s(vr::MODE_FREQUENCIES, 6)), bits(&m.f64s(vr::MODE_FREQUENCIES, 6)));
}
