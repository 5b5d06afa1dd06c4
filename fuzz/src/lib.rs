//! What both fuzz targets share: the fmi3 functions ([`api`]), the variables
//! ([`model`]), an instance with a logger that counts messages by status,
//! and the checks every call must pass.
//!
//! A finding is any of: a crash or sanitizer report, fmi3Fatal (a caught
//! panic), a refused call that logged nothing or changed the instance, a
//! non-finite output after a successful call.

#![allow(clippy::missing_safety_doc)]

pub mod api;
pub mod model;

use std::ffi::{c_void, CStr, CString};
use std::ptr::{null, null_mut};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

pub use api::*;
pub use model::{model, vr, Dim};

pub const OK: fmi3Status = 0;
pub const WARNING: fmi3Status = 1;
pub const DISCARD: fmi3Status = 2;
pub const ERROR: fmi3Status = 3;
pub const FATAL: fmi3Status = 4;

/// Counts of log messages by status (OK .. Fatal); the instanceEnvironment.
/// With `keep`, also the messages' text.
#[derive(Default)]
pub struct Env {
    pub counts: [AtomicUsize; 5],
    pub keep: bool,
    pub messages: Mutex<Vec<String>>,
}

impl Env {
    pub fn count(&self, status: fmi3Status) -> usize {
        self.counts[status as usize].load(Ordering::Relaxed)
    }
    pub fn ptr(&self) -> fmi3InstanceEnvironment {
        self as *const Env as *mut c_void
    }
}

/// Extra coverage counters, read by libFuzzer from this linker section. The
/// FMU's own code is not instrumented when it is loaded from its release
/// library, so what the harness observes is fed back instead: which message
/// the FMU logged (which check refused a call), and which state each
/// operation left the instance in with which status.
#[used]
#[link_section = "__libfuzzer_extra_counters"]
static mut EXTRA: [u8; 8192] = [0; 8192];

pub fn feature(k: usize) {
    // SAFETY: libFuzzer runs one input at a time on this thread.
    unsafe {
        let c = &mut (*(&raw mut EXTRA))[k % 8192];
        *c = c.saturating_add(1);
    }
}

pub unsafe extern "C" fn logger(env: fmi3InstanceEnvironment, status: fmi3Status, category: fmi3String, message: fmi3String) {
    let env = &*(env as *const Env);
    assert!(!category.is_null() && !message.is_null());
    let text = CStr::from_ptr(message).to_bytes();
    assert!(!text.is_empty(), "empty log message");
    assert!((0..5).contains(&status), "log status {status}");
    env.counts[status as usize].fetch_add(1, Ordering::Relaxed);
    if env.keep {
        env.messages.lock().unwrap().push(String::from_utf8_lossy(text).into_owned());
    }
    // The message without its numbers names the check that spoke.
    let h = text.iter().filter(|b| !b.is_ascii_digit()).fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ b as u64).wrapping_mul(0x100_0000_01b3));
    feature(4096 + (h % 4096) as usize);
}

/// The FMI state an instance is in (the first payload byte of its serialized state).
pub fn mode(inst: fmi3Instance) -> u8 {
    snapshot(inst)[28]
}

pub fn instantiate(name: &str, env: &Env) -> fmi3Instance {
    instantiate_with(name, env, None)
}

/// An instance whose resources are in the folder `resources`.
pub fn instantiate_with(name: &str, env: &Env, resources: Option<&str>) -> fmi3Instance {
    let name = CString::new(name).unwrap();
    let token = CString::new(model().instantiation_token.as_str()).unwrap();
    let path = resources.map(|r| CString::new(r).unwrap());
    let path = path.as_ref().map_or(null(), |p| p.as_ptr());
    unsafe { fmi().fmi3InstantiateCoSimulation(name.as_ptr(), token.as_ptr(), path, false, false, false, false, null(), 0, env.ptr(), Some(logger), None) }
}

/// The whole state of `inst` as bytes (mode, times, parameters, simulator state).
pub fn snapshot(inst: fmi3Instance) -> Vec<u8> {
    let f = fmi();
    unsafe {
        let mut st = null_mut();
        assert_eq!(f.fmi3GetFMUState(inst, &mut st), OK);
        let mut n = 0;
        assert_eq!(f.fmi3SerializedFMUStateSize(inst, st, &mut n), OK);
        let mut b = vec![0u8; n];
        assert_eq!(f.fmi3SerializeFMUState(inst, st, b.as_mut_ptr(), n), OK);
        assert_eq!(f.fmi3FreeFMUState(inst, &mut st), OK);
        b
    }
}

pub fn get_u64(inst: fmi3Instance, r: u32) -> u64 {
    let mut x = 0u64;
    assert_eq!(unsafe { fmi().fmi3GetUInt64(inst, &r, 1, &mut x, 1) }, OK);
    x
}

pub fn time(inst: fmi3Instance) -> f64 {
    let mut t = f64::NAN;
    assert_eq!(unsafe { fmi().fmi3GetFloat64(inst, &vr("time"), 1, &mut t, 1) }, OK);
    assert!(t.is_finite(), "time {t}");
    t
}

/// Current number of values of `r` (0 for an unknown value reference).
pub fn size_of(inst: fmi3Instance, r: u32) -> usize {
    let Some(v) = model().variables.iter().find(|v| v.vr == r) else { return 0 };
    v.dims
        .iter()
        .map(|d| match *d {
            Dim::Fixed(n) => n,
            Dim::Param(p) => get_u64(inst, p),
        })
        .product::<u64>() as usize
}

/// Every output and calculated parameter, asserting that each read that
/// succeeds is finite; `None` when they cannot be computed (parameters the
/// solver refuses, reported as fmi3Error).
pub fn outputs(inst: fmi3Instance) -> Option<Vec<f64>> {
    let mut all = Vec::new();
    for name in ["time", "positions", "velocities", "modalCoordinates", "kineticEnergy", "potentialEnergy", "modeFrequencies"] {
        let r = vr(name);
        let n = size_of(inst, r);
        let mut x = vec![f64::NAN; n];
        let s = unsafe { fmi().fmi3GetFloat64(inst, &r, 1, x.as_mut_ptr(), n) };
        if s != OK {
            assert_eq!(s, ERROR, "{name}");
            return None;
        }
        assert!(x.iter().all(|y| y.is_finite()), "non-finite {name}: {x:?}");
        all.extend(x);
    }
    Some(all)
}

/// Runs `call` on a live instance and checks the outcome: never fmi3Fatal; a
/// refusal (fmi3Error, or fmi3Discard if `discard_ok`) is logged with its
/// status and leaves the instance byte for byte as it was.
pub fn checked(inst: fmi3Instance, env: &Env, what: &str, discard_ok: bool, call: &mut dyn FnMut() -> fmi3Status) -> fmi3Status {
    let before = snapshot(inst);
    let (errors, discards, warnings) = (env.count(ERROR), env.count(DISCARD), env.count(WARNING));
    let s = call();
    assert_ne!(s, FATAL, "{what}: fmi3Fatal");
    match s {
        OK => {}
        // A completed step whose forceResidual passed its limit: logged, the step taken.
        WARNING if what == "fmi3DoStep" => assert!(env.count(WARNING) > warnings, "{what}: fmi3Warning without a logged reason"),
        ERROR => assert!(env.count(ERROR) > errors, "{what}: fmi3Error without a logged error"),
        DISCARD if discard_ok => assert!(env.count(DISCARD) > discards, "{what}: fmi3Discard without a logged reason"),
        other => panic!("{what}: status {other}"),
    }
    if s != OK && s != WARNING {
        assert!(snapshot(inst) == before, "{what}: refused, but the instance changed");
    }
    s
}
