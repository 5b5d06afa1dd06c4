//! fmi3DeserializeFMUState and fmi3SetFMUState on arbitrary bytes, into an
//! instance in Step Mode.
//!
//! The first input byte chooses how the rest becomes a blob:
//! 0: the bytes as they are (header, checksum and all);
//! 1: the bytes as a payload, sealed with the FMU's header and a valid CRC-32;
//! 2: a valid state of the instance with byte edits (offset, xor) applied to
//!    its payload, resealed, so the checks behind the checksum are reached.
//!
//! A refused blob must leave the instance unchanged; an accepted one must
//! serialize back to a blob that reads back to itself, and when made current
//! give finite outputs and a step that succeeds with finite outputs or is
//! refused cleanly. Afterwards the instance is put back to its baseline.

#![no_main]

use std::ptr::null_mut;
use std::sync::{Mutex, OnceLock};

use libfuzzer_sys::fuzz_target;
use modal_mass_spring_fuzz::*;

/// Serialized state layout: magic, version, layout fingerprint (20 bytes),
/// payload length (8), payload, CRC-32 (4).
const PREFIX: usize = 20;
const HEADER: usize = PREFIX + 8;
const TRAILER: usize = 4;

struct Harness {
    env: Box<Env>,
    inst: fmi3Instance,
    baseline: fmi3FMUState,
    baseline_bytes: Vec<u8>,
}

// Only used under the mutex.
unsafe impl Send for Harness {}

fn harness() -> &'static Mutex<Harness> {
    static H: OnceLock<Mutex<Harness>> = OnceLock::new();
    H.get_or_init(|| {
        let f = fmi();
        let env = Box::<Env>::default();
        let inst = instantiate("fuzz", &env);
        assert!(!inst.is_null());
        unsafe {
            assert_eq!(f.fmi3EnterInitializationMode(inst, false, 0.0, 0.0, false, 0.0), OK);
            assert_eq!(f.fmi3ExitInitializationMode(inst), OK);
            for k in 0..5 {
                let (mut a, mut b, mut c, mut t) = (false, false, false, 0.0);
                assert_eq!(f.fmi3DoStep(inst, k as f64 * 0.01, 0.01, false, &mut a, &mut b, &mut c, &mut t), OK);
            }
        }
        let mut baseline = null_mut();
        assert_eq!(unsafe { f.fmi3GetFMUState(inst, &mut baseline) }, OK);
        let baseline_bytes = snapshot(inst);
        Mutex::new(Harness { env, inst, baseline, baseline_bytes })
    })
}

/// `payload` with the header of `like` and a valid checksum.
fn seal(like: &[u8], payload: &[u8]) -> Vec<u8> {
    let mut b = like[..PREFIX].to_vec();
    b.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    b.extend_from_slice(payload);
    let sum = crc32fast::hash(&b);
    b.extend_from_slice(&sum.to_le_bytes());
    b
}

fn serialized(inst: fmi3Instance, st: fmi3FMUState) -> Vec<u8> {
    let f = fmi();
    let mut n = 0;
    assert_eq!(unsafe { f.fmi3SerializedFMUStateSize(inst, st, &mut n) }, OK);
    let mut b = vec![0u8; n];
    assert_eq!(unsafe { f.fmi3SerializeFMUState(inst, st, b.as_mut_ptr(), n) }, OK);
    b
}

fuzz_target!(|data: &[u8]| {
    let Some((&how, rest)) = data.split_first() else { return };
    let f = fmi();
    let h = harness().lock().unwrap();
    let (inst, env, base) = (h.inst, &*h.env, &h.baseline_bytes);
    let blob = match how % 3 {
        0 => rest.to_vec(),
        1 => seal(base, rest),
        _ => {
            let mut p = base[HEADER..base.len() - TRAILER].to_vec();
            for e in rest.chunks_exact(3) {
                let at = u16::from_le_bytes([e[0], e[1]]) as usize % p.len();
                p[at] ^= e[2];
            }
            seal(base, &p)
        }
    };

    let mut st: fmi3FMUState = null_mut();
    let s = checked(inst, env, "fmi3DeserializeFMUState", false, &mut || unsafe { f.fmi3DeserializeFMUState(inst, blob.as_ptr(), blob.len(), &mut st) });
    if s == OK {
        assert!(!st.is_null());
        // Serializing what was accepted gives a blob that reads back to itself.
        let again = serialized(inst, st);
        let mut st2 = null_mut();
        assert_eq!(unsafe { f.fmi3DeserializeFMUState(inst, again.as_ptr(), again.len(), &mut st2) }, OK);
        assert!(serialized(inst, st2) == again, "serialization is not a fixed point");
        assert_eq!(unsafe { f.fmi3FreeFMUState(inst, &mut st2) }, OK);

        if checked(inst, env, "fmi3SetFMUState", false, &mut || unsafe { f.fmi3SetFMUState(inst, st) }) == OK {
            let _ = outputs(inst);
            let t = time(inst);
            let (mut a, mut b, mut c, mut last) = (false, false, false, 0.0);
            let step = checked(inst, env, "fmi3DoStep", true, &mut || unsafe { f.fmi3DoStep(inst, t, 1e-4, false, &mut a, &mut b, &mut c, &mut last) });
            if step == OK || step == WARNING {
                assert!(outputs(inst).is_some(), "outputs refused after a successful step");
            }
        }
        assert_eq!(unsafe { f.fmi3FreeFMUState(inst, &mut st) }, OK);
    } else {
        assert!(st.is_null());
    }

    assert_eq!(unsafe { f.fmi3SetFMUState(inst, h.baseline) }, OK);
    assert!(snapshot(inst) == h.baseline_bytes, "the baseline state did not come back");
});
