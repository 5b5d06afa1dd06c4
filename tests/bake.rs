//! A baked set-up (`resources/setup.bin`, `cargo xtask fmu --bake`): an
//! instance whose parameters match runs bit for bit as one that computes its
//! set-up (modal, trained, and adaptive with what its set-up chose); a
//! stale, corrupt or foreign bake is not used, and the log says why.

use crate::common;

use common::*;
use modal_mass_spring::fmi::exports::{fmi3EnterConfigurationMode, fmi3ExitConfigurationMode};
use modal_mass_spring::fmi::variables::vr;
use modal_mass_spring::model::bake;
use modal_mass_spring::model::Params;

/// The start values of `scene` with modes of the load, a static correction,
/// the given linearization and force evaluation.
fn params(scene: &str, linearization: i64, force: i64) -> Params {
    let mut p = Params::canonical(scene).unwrap();
    p.set(vr::N_MODES, &[6.0]);
    p.set(vr::MODE_SELECTION, &[2.0]);
    p.set(vr::STATIC_CORRECTION, &[1.0]);
    p.set(vr::LINEARIZATION, &[linearization as f64]);
    p.set(vr::FORCE_EVALUATION, &[force as f64]);
    p
}

/// A resources folder with startValues.txt for `p` and, if given, setup.bin.
pub(crate) fn resources(tag: &str, p: &Params, baked: Option<&[u8]>) -> String {
    let dir = std::env::temp_dir().join(format!("mms-bake-{}-{tag}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let text: String = modal_mass_spring::fmi::variables::VARIABLES
        .iter()
        .enumerate()
        .filter(|(_, v)| v.holds_value())
        .map(|(i, v)| format!("{} {}\n", v.name, p.values[i].iter().map(|x| x.to_string()).collect::<Vec<_>>().join(" ")))
        .collect();
    std::fs::write(dir.join("startValues.txt"), text).unwrap();
    let bin = dir.join(bake::FILE);
    match baked {
        Some(b) => std::fs::write(&bin, b).unwrap(),
        None => {
            let _ = std::fs::remove_file(&bin);
        }
    }
    format!("file://{}", dir.display())
}

fn history(f: &Fmu) -> Vec<Vec<u64>> {
    f.init();
    (0..50)
        .map(|_| {
            f.run(1, 0.01);
            f.outputs()
        })
        .collect()
}

#[test]
fn a_baked_set_up_runs_bit_for_bit_as_a_computed_one() {
    for (scene, linearization, force) in [("paper-2d-top-row", 1, 1), ("paper-2d-top-corners", 2, 2), ("paper-3d-sheet", 1, 2)] {
        let p = params(scene, linearization, force);
        let bytes = bake::write(&p, &p.build().unwrap()).expect("a modal set-up bakes");
        let computed = Fmu::with_resources("computed", Some(&resources(&format!("{scene}-none"), &p, None)));
        let baked = Fmu::with_resources("baked", Some(&resources(&format!("{scene}-baked"), &p, Some(&bytes))));
        let (a, b) = (history(&computed), history(&baked));
        assert!(baked.messages().iter().any(|m| m.contains("set-up taken from resources/setup.bin")), "{scene}: {:?}", baked.messages());
        assert!(!computed.messages().iter().any(|m| m.contains("setup.bin")), "{:?}", computed.messages());
        assert_eq!(a, b, "{scene}: the baked run differs from the computed one");
    }
}

#[test]
fn a_stale_corrupt_or_foreign_bake_is_not_used() {
    let p = params("paper-2d-top-row", 1, 2);
    let bytes = bake::write(&p, &p.build().unwrap()).unwrap();
    let dir = resources("stale", &p, Some(&bytes));

    // Stale: a fixed parameter changed after instantiation.
    let f = Fmu::with_resources("stale", Some(&dir));
    assert_eq!(f.set_f64(vr::CUBATURE_TOLERANCE, &[0.02]), OK);
    let stale = history(&f);
    let msgs = f.messages();
    assert!(msgs.iter().any(|m| m.contains("not used") && m.contains("cubatureTolerance = 0.01") && m.contains("0.02")), "{msgs:?}");
    let mut q = p.clone();
    q.set(vr::CUBATURE_TOLERANCE, &[0.02]);
    assert_eq!(stale, history(&Fmu::with_resources("fresh", Some(&resources("fresh", &q, None)))), "a stale bake must not change the run");

    // Stale: a structural parameter changed in Configuration Mode.
    let f = Fmu::with_resources("structural", Some(&dir));
    assert_eq!(unsafe { fmi3EnterConfigurationMode(f.inst) }, OK);
    assert_eq!(f.set_u64(vr::NX, 7), OK);
    assert_eq!(unsafe { fmi3ExitConfigurationMode(f.inst) }, OK);
    f.init();
    assert!(f.messages().iter().any(|m| m.contains("not used") && m.contains("nx")), "{:?}", f.messages());

    // A parameter set-up does not read (the integrator) keeps the bake.
    let f = Fmu::with_resources("integrator", Some(&dir));
    assert_eq!(f.set_i64(vr::INTEGRATOR, 2), OK);
    f.init();
    assert!(f.messages().iter().any(|m| m.contains("set-up taken from")), "{:?}", f.messages());

    // Corrupt: every single flipped byte is caught (CRC), the set-up computed.
    let unbaked = history(&Fmu::with_resources("unbaked", Some(&resources("unbaked", &p, None))));
    for at in (0..bytes.len()).step_by(bytes.len() / 13 + 1) {
        let mut bad = bytes.clone();
        bad[at] ^= 0x20;
        let f = Fmu::with_resources("corrupt", Some(&resources("corrupt", &p, Some(&bad))));
        assert_eq!(history(&f), unbaked, "byte {at}");
        assert!(f.messages().iter().any(|m| m.contains("not used")), "byte {at}: {:?}", f.messages());
    }
    // Foreign: not a bake at all, and a truncated one.
    for (tag, bad) in [("foreign", b"not a bake".to_vec()), ("truncated", bytes[..bytes.len() / 2].to_vec())] {
        let f = Fmu::with_resources(tag, Some(&resources(tag, &p, Some(&bad))));
        assert_eq!(history(&f), unbaked, "{tag}");
        assert!(f.messages().iter().any(|m| m.contains("not used")), "{tag}: {:?}", f.messages());
    }
}

/// The start values of `scene` with a trained basis of 6 vectors and the given force evaluation.
fn trained(scene: &str, force: i64) -> Params {
    let mut p = params(scene, 1, force);
    p.set(vr::MODE_SELECTION, &[3.0]);
    p.set(vr::STATIC_CORRECTION, &[0.0]);
    p
}

/// Where [`modal_mass_spring::physics::SetupData::to_bytes`] starts in a bake of `data_len` bytes of it.
fn data_section(bytes: &[u8], data_len: usize) -> std::ops::Range<usize> {
    let end = bytes.len() - 4;
    end - data_len..end
}

/// `bytes` with a CRC-32 of what comes before it.
fn resealed(mut bytes: Vec<u8>) -> Vec<u8> {
    let body = bytes.len() - 4;
    let crc = crc32fast::hash(&bytes[..body]);
    bytes[body..].copy_from_slice(&crc.to_le_bytes());
    bytes
}

/// Up to 50 steps of 0.01 s as bits, stopping at the first step that does
/// not complete (a discarded step is a clean refusal); every output read
/// must be finite: those of [`history`], then trainingRange and the adaptive run's three.
fn finite_history(f: &Fmu, what: &str) -> Vec<Vec<u64>> {
    f.init();
    let mut out = Vec::new();
    for _ in 0..50 {
        let s = f.step(f.time(), 0.01);
        let mut now = f.outputs();
        for r in [vr::TRAINING_RANGE, vr::ERROR_ESTIMATE, vr::REDUCED_FRACTION, vr::BASIS_SIZE] {
            now.extend(bits(&f.f64s(r, 1)));
        }
        assert!(now.iter().all(|&b| f64::from_bits(b).is_finite()), "{what}: a non-finite output after status {s}: {:?}", f.messages());
        if s != OK && s != WARNING {
            assert_eq!(s, DISCARD, "{what}: {:?}", f.messages());
            break;
        }
        out.push(now);
    }
    out
}

#[test]
fn a_baked_trained_basis_runs_bit_for_bit_as_a_computed_one() {
    for (scene, force) in [("paper-2d-top-row", 2), ("paper-3d-sheet", 2), ("paper-2d-top-corners", 1)] {
        let p = trained(scene, force);
        let sim = p.build().unwrap();
        assert!(sim.setup_data().unwrap().range.is_some(), "{scene}: a trained bake keeps its range");
        let bytes = bake::write(&p, &sim).expect("a trained set-up bakes");
        let computed = Fmu::with_resources("computed", Some(&resources(&format!("trained-{scene}-none"), &p, None)));
        let baked = Fmu::with_resources("baked", Some(&resources(&format!("trained-{scene}-baked"), &p, Some(&bytes))));
        let (a, b) = (history(&computed), history(&baked));
        assert!(baked.messages().iter().any(|m| m.contains("set-up taken from resources/setup.bin")), "{scene}: {:?}", baked.messages());
        assert_eq!(a, b, "{scene}: the baked trained run differs from the computed one");
        // trainingRange too: it is read from the baked range.
        assert_eq!(computed.f64s(vr::TRAINING_RANGE, 1), baked.f64s(vr::TRAINING_RANGE, 1), "{scene}");
    }
}

/// What the fuzz target `bake` does in its third mode, deterministically:
/// every k-th byte of the data section of a valid bake edited and the file
/// resealed, so that its CRC passes and the checks behind it are reached.
/// Each bake is refused ("not used") and the run is the computed one bit for
/// bit, or it is taken and every output of the run is finite.
#[test]
fn a_resealed_edit_of_the_data_is_refused_or_runs_finite() {
    // The adaptive bake's edits fall in its adaptive section (the rest is laid out as the others').
    let cases = [
        ("trained-cubature", trained("paper-2d-top-row", 2), 97),
        ("load-static", params("paper-2d-top-corners", 1, 1), 89),
        ("adaptive-cubature", adaptive(12, 0.1, 2), 499),
    ];
    for (tag, p, k) in cases {
        let sim = p.build().unwrap();
        let data = sim.setup_data().unwrap();
        let bytes = bake::write(&p, &sim).unwrap();
        let mut section = data_section(&bytes, data.to_bytes().len());
        if data.adaptive.is_some() {
            section.start += modal_mass_spring::physics::SetupData { adaptive: None, ..data }.to_bytes().len() - 1;
        }
        let computed = history(&Fmu::with_resources("computed", Some(&resources(&format!("edit-{tag}-none"), &p, None))));
        let (mut refused, mut taken) = (0, 0);
        for (i, at) in section.clone().step_by(k).enumerate() {
            let mut bad = bytes.clone();
            bad[at] ^= [0x01, 0x20, 0x80, 0xff][i % 4];
            let bad = resealed(bad);
            let f = Fmu::with_resources("edited", Some(&resources(&format!("edit-{tag}"), &p, Some(&bad))));
            let run = finite_history(&f, &format!("{tag}, byte {} of the data", at - section.start));
            let msgs = f.messages();
            if msgs.iter().any(|m| m.contains("not used")) {
                assert_eq!(
                    run.iter().map(|o| &o[..o.len() - 4]).collect::<Vec<_>>(),
                    computed,
                    "{tag}, byte {} of the data: refused, yet the run differs from the computed one",
                    at - section.start
                );
                refused += 1;
            } else {
                assert!(msgs.iter().any(|m| m.contains("set-up taken from")), "{tag}, byte {}: neither taken nor refused: {msgs:?}", at - section.start);
                taken += 1;
            }
        }
        println!("{tag}: {} bytes of data edited, every {k}th: {refused} refused, {taken} taken with finite runs", section.len());
        assert!(refused > 0 && taken > 0, "{tag}: {refused} refused, {taken} taken");
    }
}

/// Found by the edits above (a fixed node's coordinate of the point turned
/// into -5e303: the bake was taken and the potential energy was infinite):
/// a resealed bake whose linearization point or basis the set-up could not
/// have made is refused, naming what, and the run is the computed one.
#[test]
fn a_resealed_bake_with_a_point_or_basis_no_set_up_makes_is_refused() {
    let p = params("paper-2d-top-corners", 1, 2);
    let sim = p.build().unwrap();
    let data = sim.setup_data().unwrap();
    let bytes = bake::write(&p, &sim).unwrap();
    let section = data_section(&bytes, data.to_bytes().len());
    let computed = history(&Fmu::with_resources("computed", Some(&resources("regression-none", &p, None))));
    let n = data.basis.n;
    type Edit = fn(&mut modal_mass_spring::physics::SetupData, usize);
    let edits: [(&str, Edit, &str); 5] = [
        ("a fixed node far away", |d, n| d.point[n + 1] = -5e303, "linearization point"),
        ("a fixed node moved a little", |d, n| d.point[n] += 1e-3, "linearization point"),
        ("a point off the rest state that says it is at rest", |d, _| d.point[0] += 1e-3, "linearization point"),
        ("a basis vector doubled", |d, _| (0..d.basis.n).for_each(|k| d.basis.phi[k * d.basis.r] *= 2.0), "mass-normalized"),
        ("a basis entry of 1e300", |d, _| d.basis.phi[7] = 1e300, "mass-normalized"),
    ];
    for (what, edit, named) in edits {
        let mut d = data.clone();
        edit(&mut d, n);
        let mut bad = bytes.clone();
        bad[section.clone()].copy_from_slice(&d.to_bytes());
        let f = Fmu::with_resources("regression", Some(&resources("regression", &p, Some(&resealed(bad)))));
        assert_eq!(history(&f), computed, "{what}");
        assert!(f.messages().iter().any(|m| m.contains("not used") && m.contains(named)), "{what}: {:?}", f.messages());
    }
}

#[test]
fn full_space_has_nothing_to_bake() {
    let mut p = Params::canonical("paper-2d-top-row").unwrap();
    p.set(vr::REDUCTION, &[2.0]);
    assert!(bake::write(&p, &p.build().unwrap()).is_none());
}

// ---- reduction = adaptive: what its set-up chose, baked -------------------

/// cloth-3d on `n` x `n` nodes with reduction = adaptive at `tolerance`,
/// with exact forces (1) or cubature forces asked for (2), 4 reported modes.
pub(crate) fn adaptive(n: usize, tolerance: f64, force: i64) -> Params {
    let mut p = Params::canonical("cloth-3d").unwrap();
    p.set(vr::NX, &[n as f64]);
    p.set(vr::NY, &[n as f64]);
    p.set(vr::LOAD_COLUMN, &[(n / 2) as f64]);
    p.set(vr::N_MODES, &[4.0]);
    p.set(vr::REDUCTION, &[3.0]);
    p.set(vr::ERROR_TOLERANCE, &[tolerance]);
    p.set(vr::FORCE_EVALUATION, &[force as f64]);
    p.fit_arrays();
    p
}

/// `steps` steps of 0.01 s, the holder shaken 5 cm along x at 2 Hz for the
/// first 20 (outside the training program: the run falls back to full
/// space, and returns where its grown basis holds the state): every output,
/// errorEstimate, reducedFraction and basisSize (last) after each step, as bits.
fn shaken_history(f: &Fmu, steps: usize) -> Vec<Vec<u64>> {
    f.init();
    (0..steps)
        .map(|k| {
            let x = if k < 20 { 0.05 * (2.0 * std::f64::consts::PI * 2.0 * (k + 1) as f64 * 0.01).sin() } else { 0.0 };
            assert_eq!(f.set_f64(vr::ANCHOR_X, &[x]), OK);
            f.run(1, 0.01);
            let mut out = f.outputs();
            for r in [vr::ERROR_ESTIMATE, vr::REDUCED_FRACTION, vr::BASIS_SIZE] {
                out.extend(bits(&f.f64s(r, 1)));
            }
            out
        })
        .collect()
}

/// The basis size after each step of a [`shaken_history`].
fn basis_sizes(history: &[Vec<u64>]) -> Vec<f64> {
    history.iter().map(|o| f64::from_bits(*o.last().unwrap())).collect()
}

/// `bytes` (a bake whose data section is `section`) with `data` in its place, its length and CRC made to fit.
fn with_data(bytes: &[u8], section: &std::ops::Range<usize>, data: &[u8]) -> Vec<u8> {
    let mut b = bytes[..section.start - 8].to_vec();
    b.extend_from_slice(&(data.len() as u64).to_le_bytes());
    b.extend_from_slice(data);
    b.extend_from_slice(&[0; 4]);
    resealed(b)
}

#[test]
fn a_baked_adaptive_set_up_runs_bit_for_bit_as_a_computed_one() {
    // Exact forces (11 vectors on cloth 12 x 12 at 0.1); cubature forces
    // asked for and chosen (13 vectors and 16 error directions on 14 x 14 at 0.08).
    for (tag, p, cubature) in [("exact", adaptive(12, 0.1, 1), false), ("cubature", adaptive(14, 0.08, 2), true)] {
        let sim = p.build().unwrap();
        let data = sim.setup_data().expect("an adaptive set-up bakes");
        let choice = data.adaptive.as_ref().expect("with its adaptive section");
        assert_eq!(choice.error_set.is_some(), cubature, "{tag}");
        assert_eq!(sim.cubature_springs() < sim.scene().springs.len(), cubature, "{tag}");
        let bytes = bake::write(&p, &sim).unwrap();
        let computed = Fmu::with_resources("computed", Some(&resources(&format!("adaptive-{tag}-none"), &p, None)));
        let baked = Fmu::with_resources("baked", Some(&resources(&format!("adaptive-{tag}-baked"), &p, Some(&bytes))));
        let (a, b) = (shaken_history(&computed, 50), shaken_history(&baked, 50));
        assert!(baked.messages().iter().any(|m| m.contains("set-up taken from resources/setup.bin")), "{tag}: {:?}", baked.messages());
        assert!(!computed.messages().iter().any(|m| m.contains("setup.bin")), "{tag}: {:?}", computed.messages());
        // The run falls back to full space; with exact forces it returns on a
        // grown basis, with cubature forces its basis never grows (the
        // cubature is trained for the chosen basis).
        let (sizes, n, r) = (basis_sizes(&a), sim.n_dofs() as f64, data.basis.r as f64);
        let fell = sizes.iter().position(|&s| s == n).unwrap_or_else(|| panic!("{tag}: the run never fell back: {sizes:?}"));
        if cubature {
            assert!(sizes.iter().all(|&s| s == r || s == n), "{tag}: the basis grew: {sizes:?}");
        } else {
            assert!(sizes[fell..].iter().any(|&s| s > r && s < n), "{tag}: the run never returned on a grown basis: {sizes:?}");
        }
        assert_eq!(a, b, "{tag}: the baked adaptive run differs from the computed one");
        // The run is the stored choice's: a motion scale 1000 times the
        // stored one (resealed) is taken, and the estimate no longer sends
        // the run to full space (with cubature forces the force the error
        // directions do not see still may, later).
        let mut edited = data.clone();
        edited.adaptive.as_mut().unwrap().motion_scale *= 1e3;
        let bad = with_data(&bytes, &data_section(&bytes, data.to_bytes().len()), &edited.to_bytes());
        let f = Fmu::with_resources("edited", Some(&resources(&format!("adaptive-{tag}-edited"), &p, Some(&bad))));
        let sizes = basis_sizes(&shaken_history(&f, 50));
        assert!(f.messages().iter().any(|m| m.contains("set-up taken from")), "{tag}: {:?}", f.messages());
        let later = sizes.iter().position(|&s| s == n).unwrap_or(sizes.len());
        assert!(
            later > fell && sizes[..later].iter().all(|&s| s == r),
            "{tag}: with the edited motion scale the run fell back at {later}, not after {fell}: {sizes:?}"
        );
        if !cubature {
            assert_eq!(later, sizes.len(), "{tag}: with the edited motion scale the run fell back: {sizes:?}");
        }
    }
}

/// A bake's adaptive section that does not parse, or parses to what no
/// set-up of this scene makes, is refused with the reason in the log, and
/// the instance computes its set-up: its run is the computed one, bit for bit.
#[test]
fn a_corrupt_adaptive_section_is_refused_and_the_set_up_computed() {
    let p = adaptive(12, 0.1, 2);
    let sim = p.build().unwrap();
    let data = sim.setup_data().unwrap();
    assert!(data.adaptive.as_ref().unwrap().error_set.is_some(), "cubature forces, so the section has a spring set");
    let full = data.to_bytes();
    let bytes = bake::write(&p, &sim).unwrap();
    let section = data_section(&bytes, full.len());
    // The adaptive section starts at its flag, the last byte of the data without it.
    let flag_at = modal_mass_spring::physics::SetupData { adaptive: None, ..data.clone() }.to_bytes().len() - 1;
    assert_eq!(full[flag_at], 1);
    let computed = shaken_history(&Fmu::with_resources("computed", Some(&resources("adaptive-corrupt-none", &p, None))), 30);
    type Edit = fn(&mut modal_mass_spring::physics::AdaptiveChoice);
    let edits: [(&str, Edit, &str); 6] = [
        ("a pose of 3 values", |a| a.poses[3].truncate(3), "the file is corrupt"),
        ("an error direction with a NaN", |a| a.error_directions[0][5] = f64::NAN, "the file is corrupt"),
        ("no component", |a| a.components = 0, "the file is corrupt"),
        ("a spring weight of zero", |a| a.error_set.as_mut().unwrap().weights[0] = 0.0, "the file is corrupt"),
        ("a spring the scene does not have", |a| a.error_set.as_mut().unwrap().springs[0] = 1_000_000, "error model's spring set"),
        ("no spring set beside cubature forces", |a| a.error_set = None, "error model's spring set"),
    ];
    let mut bad_files: Vec<(String, Vec<u8>, &str)> = edits
        .iter()
        .map(|(what, edit, why)| {
            let mut d = data.clone();
            edit(d.adaptive.as_mut().unwrap());
            (what.to_string(), with_data(&bytes, &section, &d.to_bytes()), *why)
        })
        .collect();
    // Cut short: the section's last 8 bytes, and everything after its flag.
    for cut in [full.len() - 8, flag_at + 1] {
        bad_files.push((format!("the data cut at byte {cut} of {}", full.len()), with_data(&bytes, &section, &full[..cut]), "the file is corrupt"));
    }
    // A byte flipped in the section, not resealed: the CRC catches it.
    let mut flipped = bytes.clone();
    flipped[section.start + flag_at + 40] ^= 0x10;
    bad_files.push(("a flipped byte".into(), flipped, "the file is corrupt"));
    for (what, bad, why) in bad_files {
        let f = Fmu::with_resources("corrupt", Some(&resources("adaptive-corrupt", &p, Some(&bad))));
        assert_eq!(shaken_history(&f, 30), computed, "{what}: the run differs from the computed one");
        let msgs = f.messages();
        assert!(msgs.iter().any(|m| m.contains("resources/setup.bin not used, set-up computed") && m.contains(why)), "{what}: {msgs:?}");
        assert!(!msgs.iter().any(|m| m.contains("set-up taken from")), "{what}: {msgs:?}");
    }
    // Set-up data without an adaptive section (a modal set-up's) is refused by an adaptive run.
    let modal = modal_mass_spring::physics::SetupData { adaptive: None, ..data };
    let refused = p.build_with(Some(&modal));
    assert!(refused.as_ref().is_err_and(|e| e.to_string().contains("no adaptive set-up")), "{:?}", refused.err());
}

/// errorTolerance sizes the adaptive basis: a bake made for another one is not used.
#[test]
fn an_adaptive_bake_for_another_error_tolerance_is_not_used() {
    let p = adaptive(12, 0.05, 1);
    let bytes = bake::write(&p, &p.build().unwrap()).unwrap();
    let f = Fmu::with_resources("tolerance", Some(&resources("adaptive-tolerance", &p, Some(&bytes))));
    assert_eq!(f.set_f64(vr::ERROR_TOLERANCE, &[0.1]), OK);
    let stale = shaken_history(&f, 30);
    let msgs = f.messages();
    assert!(msgs.iter().any(|m| m.contains("not used") && m.contains("errorTolerance = 0.05") && m.contains("0.1")), "{msgs:?}");
    let mut q = p.clone();
    q.set(vr::ERROR_TOLERANCE, &[0.1]);
    let fresh = shaken_history(&Fmu::with_resources("fresh", Some(&resources("adaptive-tolerance-fresh", &q, None))), 30);
    assert_eq!(stale, fresh, "a bake for another tolerance must not change the run");
    // Taken, the bake would have shown: the tolerance it was made for sizes another basis.
    let baked = Fmu::with_resources("baked", Some(&resources("adaptive-tolerance-baked", &p, Some(&bytes))));
    let sizes = (basis_sizes(&stale)[0], basis_sizes(&shaken_history(&baked, 1))[0]);
    assert!(baked.messages().iter().any(|m| m.contains("set-up taken from")), "{:?}", baked.messages());
    assert_ne!(sizes.0, sizes.1, "the two tolerances size the same basis");
}
