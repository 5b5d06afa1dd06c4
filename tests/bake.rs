//! A baked set-up (`resources/setup.bin`, `cargo xtask fmu --bake`): an
//! instance whose parameters match runs bit for bit as one that computes its
//! set-up; a stale, corrupt or foreign bake is not used, and the log says why.

mod common;

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
fn resources(tag: &str, p: &Params, baked: Option<&[u8]>) -> String {
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

#[test]
fn full_space_has_nothing_to_bake() {
    let mut p = Params::canonical("paper-2d-top-row").unwrap();
    p.set(vr::REDUCTION, &[2.0]);
    assert!(bake::write(&p, &p.build().unwrap()).is_none());
}
