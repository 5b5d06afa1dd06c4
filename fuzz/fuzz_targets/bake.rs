//! The baked set-up loader on arbitrary bytes, reached as an importer
//! reaches it: the bytes are written as `setup.bin` into a resources folder
//! beside the `startValues.txt` of a scene, and an instance of the FMU's
//! release library is instantiated there, initialized and stepped.
//!
//! Three scenes, each baked once at start by the crate's `bake` example
//! (`$MMS_BAKE_EXAMPLE`, which `cargo xtask fuzz` builds): a trained basis
//! with cubature forces, modes of the load with a static correction
//! linearized at the equilibrium, and reduction = adaptive with cubature
//! forces (its bake has the adaptive section: the chosen basis, the error
//! directions, the spring sets, the poses). The first input byte chooses the scene
//! and how the rest becomes a file:
//! 0: the bytes as they are;
//! 1: the bytes as the data section, behind the valid bake's header
//!    (magic, version, key) and sealed with a valid CRC-32;
//! 2: the valid bake with byte edits (offset, xor) of its data section,
//!    resealed, so the checks behind the checksum are reached.
//!
//! A finding is a crash, fmi3Fatal, a refused call that logged nothing or
//! changed the instance, a bake taken whose run gives a non-finite output,
//! a bake neither taken ("set-up taken from") nor refused ("not used"), a
//! refused bake whose run differs from the computed set-up's, or the valid
//! bake (no edit) whose run differs from it.

#![no_main]

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Mutex, OnceLock};

use libfuzzer_sys::fuzz_target;
use modal_mass_spring_fuzz::*;

/// Communication steps of a run and their size [s].
const STEPS: usize = 5;
const H: f64 = 0.02;

/// (name, startValues.txt): small scenes, so that a refused bake's computed set-up takes milliseconds.
const SCENES: [(&str, &str); 3] = [
    ("trained-cubature", "nx 6\nny 5\nnModes 4\nmodeSelection 3\nforceEvaluation 2\n"),
    ("load-static-equilibrium", "nx 6\nny 5\nnModes 4\nmodeSelection 2\nstaticCorrection 1\nlinearization 2\n"),
    // reduction = adaptive with cubature forces on a 3D sheet: the bake has its adaptive section.
    (
        "adaptive-cubature",
        "nx 6\nny 6\ndimension 3\nauxStiffness 0.05\nloadColumn 3\nnModes 4\nreduction 3\nerrorTolerance 0.1\nforceEvaluation 2\ntrainingTime 0.3\n",
    ),
];

struct Scene {
    /// The resources folder the inputs are written into.
    dir: PathBuf,
    bake: Vec<u8>,
    /// Where the data section (`SetupData::to_bytes`) is in `bake`; its u64 length is just before it.
    data: std::ops::Range<usize>,
    /// The run of the computed set-up.
    reference: Vec<u64>,
}

fn harness() -> &'static Mutex<Vec<Scene>> {
    static H: OnceLock<Mutex<Vec<Scene>>> = OnceLock::new();
    H.get_or_init(|| {
        let root = std::env::temp_dir().join(format!("mms-fuzz-bake-{}", std::process::id()));
        let example = std::env::var_os("MMS_BAKE_EXAMPLE")
            .map(PathBuf::from)
            .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/release/examples/bake"));
        let scenes = SCENES
            .iter()
            .map(|(name, starts)| {
                let dir = root.join(name);
                std::fs::create_dir_all(&dir).unwrap();
                std::fs::write(dir.join("startValues.txt"), starts).unwrap();
                let file = dir.join("setup.bin");
                let out = Command::new(&example)
                    .arg(dir.join("startValues.txt"))
                    .arg(&file)
                    .output()
                    .unwrap_or_else(|e| panic!("{}: {e} (build it with cargo build --release --example bake, or set MMS_BAKE_EXAMPLE)", example.display()));
                assert!(out.status.success(), "the bake of {name} failed: {}", String::from_utf8_lossy(&out.stderr));
                let bake = std::fs::read(&file).unwrap();
                let data = data_section(&bake).unwrap_or_else(|| panic!("{name}: the bake does not parse"));
                std::fs::remove_file(&file).unwrap();
                let (reference, how) = run(&dir);
                assert_eq!(how, How::Computed, "{name}: no setup.bin, yet the log speaks of one");
                std::fs::write(&file, &bake).unwrap();
                let (baked, how) = run(&dir);
                assert_eq!(how, How::Taken, "{name}: the valid bake was not taken");
                assert!(baked == reference, "{name}: the valid bake runs differently from the computed set-up");
                eprintln!("bake: {name}, {} bytes ({} of data)", bake.len(), data.len());
                Scene { dir, bake, data, reference }
            })
            .collect();
        Mutex::new(scenes)
    })
}

/// The data section of a bake (layout in src/model/bake.rs): magic, version
/// (u32 length + bytes), key (u32 count, then u32 vr, u32 n, n f64 each),
/// u64 length, data, CRC-32.
fn data_section(b: &[u8]) -> Option<std::ops::Range<usize>> {
    let u32_at = |at: usize| Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?) as usize);
    let mut at = 8;
    at += 4 + u32_at(at)?;
    let count = u32_at(at)?;
    at += 4;
    for _ in 0..count {
        at += 8 + 8 * u32_at(at + 4)?;
    }
    let len = u64::from_le_bytes(b.get(at..at + 8)?.try_into().ok()?) as usize;
    (at + 8 + len + 4 == b.len()).then_some(at + 8..at + 8 + len)
}

/// `body` with its CRC-32 appended.
fn sealed(mut body: Vec<u8>) -> Vec<u8> {
    let crc = crc32fast::hash(&body);
    body.extend_from_slice(&crc.to_le_bytes());
    body
}

#[derive(Debug, PartialEq)]
enum How {
    /// No word of setup.bin in the log.
    Computed,
    Taken,
    Refused,
}

/// Instantiates in `dir`, initializes and steps; every output and
/// trainingRange after each step as bits (each read finite), and what the
/// log says of the bake.
fn run(dir: &Path) -> (Vec<u64>, How) {
    let f = fmi();
    let env = Env { keep: true, ..Default::default() };
    let inst = instantiate_with("fuzz-bake", &env, Some(dir.to_str().unwrap()));
    assert!(!inst.is_null(), "instantiation failed: {:?}", env.messages.lock().unwrap());
    // Every category: "set-up taken from" is logged with fmi3OK.
    assert_eq!(unsafe { f.fmi3SetDebugLogging(inst, true, 0, std::ptr::null()) }, OK);
    assert_eq!(unsafe { f.fmi3EnterInitializationMode(inst, false, 0.0, 0.0, false, 0.0) }, OK);
    let s = checked(inst, &env, "fmi3ExitInitializationMode", false, &mut || unsafe { f.fmi3ExitInitializationMode(inst) });
    assert_eq!(s, OK, "the set-up failed: {:?}", env.messages.lock().unwrap());
    let training_range = vr("trainingRange");
    let mut seen = Vec::new();
    for k in 0..STEPS {
        let (mut a, mut b, mut c, mut last) = (false, false, false, 0.0);
        let s = checked(inst, &env, "fmi3DoStep", true, &mut || unsafe { f.fmi3DoStep(inst, k as f64 * H, H, false, &mut a, &mut b, &mut c, &mut last) });
        let outputs = outputs(inst).expect("outputs refused after initialization");
        let mut range = f64::NAN;
        assert_eq!(unsafe { f.fmi3GetFloat64(inst, &training_range, 1, &mut range, 1) }, OK);
        assert!(range.is_finite(), "non-finite trainingRange {range}");
        seen.push(s as u64);
        seen.extend(outputs.iter().chain([&range]).map(|x| x.to_bits()));
        if s != OK && s != WARNING {
            break;
        }
    }
    unsafe { f.fmi3FreeInstance(inst) };
    let messages = env.messages.lock().unwrap();
    let taken = messages.iter().any(|m| m.contains("set-up taken from resources/setup.bin"));
    let refused = messages.iter().any(|m| m.contains("setup.bin not used"));
    let how = match (taken, refused) {
        (true, false) => How::Taken,
        (false, true) => How::Refused,
        (false, false) => How::Computed,
        (true, true) => panic!("the bake both taken and refused: {messages:?}"),
    };
    (seen, how)
}

fuzz_target!(|data: &[u8]| {
    let Some((&how, rest)) = data.split_first() else { return };
    let scenes = harness().lock().unwrap();
    let scene = &scenes[(how / 3) as usize % scenes.len()];
    let (bake, data) = (&scene.bake, &scene.data);
    let file = match how % 3 {
        0 => rest.to_vec(),
        1 => {
            let mut b = bake[..data.start - 8].to_vec();
            b.extend_from_slice(&(rest.len() as u64).to_le_bytes());
            b.extend_from_slice(rest);
            sealed(b)
        }
        _ => {
            let mut b = bake[..bake.len() - 4].to_vec();
            for e in rest.chunks_exact(3) {
                let at = data.start + u16::from_le_bytes([e[0], e[1]]) as usize % data.len();
                b[at] ^= e[2];
            }
            sealed(b)
        }
    };
    std::fs::write(scene.dir.join("setup.bin"), &file).unwrap();
    let (seen, how) = run(&scene.dir);
    match how {
        How::Refused => assert!(seen == scene.reference, "a refused bake changed the run"),
        // Every output of the run was read finite.
        How::Taken if file == *bake => assert!(seen == scene.reference, "the valid bake runs differently from the computed set-up"),
        How::Taken => {}
        How::Computed => panic!("a setup.bin neither taken nor refused"),
    }
});
