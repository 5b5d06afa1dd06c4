//! Recorded trajectories, checked bit for bit: the four canonical scenes x
//! {modal, full} x {explicit, implicit} Newmark over 1 s of communication
//! steps of 0.01 s, driven through the fmi3 C functions, with damping, mode
//! weights other than 1 and a change of gravity and weights at t = 0.5 s.
//!
//! `tests/data/trajectories.txt` holds, per cell and step, a 64-bit FNV-1a
//! hash of the bits of every output (time, positions, velocities, modal
//! coordinates, energies) and the bits of the two energies, so a failure
//! names the first step that differs and by how much the energies moved.
//! A change of the arithmetic of the solver shows here as a failure; where
//! such a change is intended, `MMS_TRAJECTORIES_WRITE=1 cargo test --release
//! --test suite trajectories::` records the new trajectories (say why in the commit).

use crate::common;

use std::fmt::Write as _;
use std::path::PathBuf;

use common::*;
use modal_mass_spring::fmi::variables::vr;
use modal_mass_spring::model::Params;

/// Canonical scene and the modes its modal cells keep: those of the
/// stability matrix. In 3D the lowest modes are the out-of-plane cluster,
/// which the z component of gravity below drives.
const CELLS: [(&str, u64); 4] = [("paper-2d-top-row", 2), ("paper-2d-top-corners", 4), ("paper-3d-sheet", 58), ("cloth-3d", 16)];

const STEPS: usize = 100;
const H: f64 = 0.01;

fn fnv(words: &[u64]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for w in words {
        for b in w.to_le_bytes() {
            h ^= b as u64;
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    h
}

fn weights(r: usize, pattern: &[f64]) -> Vec<f64> {
    (0..r).map(|i| pattern[i % pattern.len()]).collect()
}

/// One line per step: `scene reduction integrator step hash kinetic potential`.
fn record(scene: &str, modes: u64, reduction: i64, integrator: i64) -> String {
    let f = Fmu::new();
    let p = Params::canonical(scene).unwrap();
    for r in [vr::NX, vr::NY, vr::DIMENSION] {
        assert_eq!(f.set_u64(r, p.scalar(r) as u64), OK);
    }
    assert_eq!(f.set_u64(vr::N_MODES, modes), OK);
    assert_eq!(f.set_i64(vr::FIXED_NODES, p.scalar(vr::FIXED_NODES) as i64), OK);
    assert_eq!(f.set_f64(vr::AUX_STIFFNESS, &[p.scalar(vr::AUX_STIFFNESS)]), OK);
    assert_eq!(f.set_i64(vr::REDUCTION, reduction), OK);
    assert_eq!(f.set_i64(vr::INTEGRATOR, integrator), OK);
    assert_eq!(f.set_f64(vr::GRAVITY, &[0.5, -9.81, -3.0]), OK);
    assert_eq!(f.set_f64(vr::DAMPING_ALPHA, &[0.2]), OK);
    assert_eq!(f.set_f64(vr::DAMPING_BETA, &[1e-4]), OK);
    let r = modes as usize;
    assert_eq!(f.set_f64(vr::MODE_WEIGHTS, &weights(r, &[1.0, 0.5, 2.0])), OK);
    f.init();
    let mut out = String::new();
    for k in 0..STEPS {
        if k == STEPS / 2 {
            assert_eq!(f.set_f64(vr::GRAVITY, &[-1.0, -9.81, 2.0]), OK, "{:?}", f.messages());
            assert_eq!(f.set_f64(vr::MODE_WEIGHTS, &weights(r, &[1.0])), OK, "{:?}", f.messages());
        }
        // fmi3Warning: a completed step whose forceResidual passed its limit.
        let status = f.step(f.time(), H);
        assert!(status == OK || status == WARNING, "{scene} {reduction} {integrator}: {:?}", f.messages());
        let o = f.outputs();
        let energies = &o[o.len() - 2..];
        let _ = writeln!(out, "{scene} {reduction} {integrator} {k} {:016x} {:016x} {:016x}", fnv(&o), energies[0], energies[1]);
    }
    out
}

fn data_file() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/trajectories.txt")
}

/// Energies of the two lines, for the failure message.
fn energies(line: &str) -> (f64, f64) {
    let w: Vec<&str> = line.split_whitespace().collect();
    let e = |s: &str| f64::from_bits(u64::from_str_radix(s, 16).unwrap());
    (e(w[5]), e(w[6]))
}

#[test]
fn trajectories_are_bit_for_bit_those_recorded() {
    let cells: Vec<(&str, u64, i64, i64)> =
        CELLS.iter().flat_map(|&(s, m)| [1, 2].into_iter().flat_map(move |red| [1, 2].into_iter().map(move |int| (s, m, red, int)))).collect();
    let runs: Vec<String> = std::thread::scope(|s| {
        let handles: Vec<_> = cells.iter().map(|&(scene, modes, red, int)| s.spawn(move || record(scene, modes, red, int))).collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    let now = runs.concat();
    if std::env::var_os("MMS_TRAJECTORIES_WRITE").is_some() {
        std::fs::create_dir_all(data_file().parent().unwrap()).unwrap();
        std::fs::write(data_file(), &now).unwrap();
        return;
    }
    let recorded = std::fs::read_to_string(data_file()).expect("tests/data/trajectories.txt is missing");
    assert_eq!(recorded.lines().count(), now.lines().count(), "number of recorded steps");
    let mut differing = Vec::new();
    for (want, got) in recorded.lines().zip(now.lines()) {
        let key = |l: &str| l.split_whitespace().take(4).collect::<Vec<_>>().join(" ");
        assert_eq!(key(want), key(got));
        if want != got {
            let ((k0, p0), (k1, p1)) = (energies(want), energies(got));
            differing.push(format!("{}: kinetic {k0:e} -> {k1:e}, potential {p0:e} -> {p1:e}", key(want)));
        }
    }
    // The first step that differs in each cell is enough to locate a change.
    let mut first = Vec::new();
    for d in &differing {
        let cell = d.split_whitespace().take(3).collect::<Vec<_>>().join(" ");
        if !first.iter().any(|f: &String| f.starts_with(&cell)) {
            first.push(d.clone());
        }
    }
    assert!(differing.is_empty(), "{} of {} steps differ from the recording; first in each cell:\n{}", differing.len(), now.lines().count(), first.join("\n"));
}
