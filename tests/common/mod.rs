//! An FMU instance driven through the fmi3 C functions (the rlib exports
//! them), with a logger that records every message.

#![allow(dead_code, clippy::missing_safety_doc)]

use std::ffi::{c_void, CStr, CString};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::ptr::{null, null_mut};
use std::sync::Mutex;
use std::time::SystemTime;

use fmi_sys::fmi3::*;
use modal_mass_spring::fmi::exports::*;
use modal_mass_spring::fmi::serialize;
use modal_mass_spring::fmi::state_machine::Mode;
use modal_mass_spring::fmi::variables::{vr, INSTANTIATION_TOKEN};

pub const OK: fmi3Status = fmi3Status_fmi3OK;
pub const WARNING: fmi3Status = fmi3Status_fmi3Warning;
pub const DISCARD: fmi3Status = fmi3Status_fmi3Discard;
pub const ERROR: fmi3Status = fmi3Status_fmi3Error;
pub const FATAL: fmi3Status = fmi3Status_fmi3Fatal;

/// Collects log messages; passed as instanceEnvironment.
#[derive(Default)]
pub struct Log(pub Mutex<Vec<(fmi3Status, String, String)>>);

impl Log {
    pub fn env(&self) -> fmi3InstanceEnvironment {
        self as *const Log as *mut c_void
    }
    pub fn take(&self) -> Vec<(fmi3Status, String, String)> {
        std::mem::take(&mut *self.0.lock().unwrap())
    }
}

pub unsafe extern "C" fn logger(env: fmi3InstanceEnvironment, status: fmi3Status, category: fmi3String, message: fmi3String) {
    let log = &*(env as *const Log);
    let s = |p: fmi3String| CStr::from_ptr(p).to_string_lossy().into_owned();
    log.0.lock().unwrap().push((status, s(category), s(message)));
}

pub struct Fmu {
    pub inst: fmi3Instance,
    pub log: Box<Log>,
}

// Each test thread owns its instances; the FMU allows instances on different threads.
unsafe impl Send for Fmu {}

impl Fmu {
    pub fn new() -> Fmu {
        Fmu::named("test")
    }

    pub fn named(name: &str) -> Fmu {
        Fmu::with_resources(name, None)
    }

    /// An instance whose resources folder is `resources` (a path; `file://`
    /// is optional), with logging on when it has one.
    pub fn with_resources(name: &str, resources: Option<&str>) -> Fmu {
        let log = Box::<Log>::default();
        let name = CString::new(name).unwrap();
        let token = CString::new(INSTANTIATION_TOKEN).unwrap();
        let dir = resources.map(|r| CString::new(r).unwrap());
        let dir_ptr = dir.as_ref().map_or(null(), |d| d.as_ptr());
        let inst = unsafe {
            fmi3InstantiateCoSimulation(
                name.as_ptr(),
                token.as_ptr(),
                dir_ptr,
                false,
                resources.is_some(),
                false,
                false,
                null(),
                0,
                log.env(),
                Some(logger),
                None,
            )
        };
        assert!(!inst.is_null(), "{:?}", log.take());
        Fmu { inst, log }
    }

    /// Instantiated -> Initialization Mode -> Step Mode.
    pub fn started() -> Fmu {
        let f = Fmu::new();
        f.init();
        f
    }

    pub fn init(&self) {
        assert_eq!(unsafe { fmi3EnterInitializationMode(self.inst, false, 0.0, 0.0, false, 0.0) }, OK);
        assert_eq!(unsafe { fmi3ExitInitializationMode(self.inst) }, OK, "{:?}", self.messages());
    }

    pub fn messages(&self) -> Vec<String> {
        self.log.0.lock().unwrap().iter().map(|(_, c, m)| format!("[{c}] {m}")).collect()
    }

    /// `status` is fmi3Error and the last message logged names `needle` (the log is then cleared).
    pub fn refused(&self, status: fmi3Status, needle: &str) {
        let last = self.messages().last().cloned().unwrap_or_default();
        assert!(last.contains(needle), "{needle:?} not in {last:?}");
        self.expect_error(status, needle);
    }

    /// `status` is fmi3Error and an error was logged (the log is then cleared).
    pub fn expect_error(&self, status: fmi3Status, what: &str) {
        assert_eq!(status, ERROR, "{what}");
        let last = self.log.0.lock().unwrap().last().cloned();
        assert!(matches!(last, Some((ERROR, _, _))), "{what}: no error logged");
        self.log.0.lock().unwrap().clear();
    }

    pub fn get_f64(&self, r: u32, n: usize) -> (fmi3Status, Vec<f64>) {
        let mut v = vec![f64::NAN; n];
        let s = unsafe { fmi3GetFloat64(self.inst, &r, 1, v.as_mut_ptr(), n) };
        (s, v)
    }

    pub fn f64s(&self, r: u32, n: usize) -> Vec<f64> {
        let (s, v) = self.get_f64(r, n);
        assert_eq!(s, OK, "{:?}", self.messages());
        v
    }

    pub fn set_f64(&self, r: u32, v: &[f64]) -> fmi3Status {
        unsafe { fmi3SetFloat64(self.inst, &r, 1, v.as_ptr(), v.len()) }
    }

    pub fn get_u64(&self, r: u32) -> u64 {
        let mut x = 0u64;
        assert_eq!(unsafe { fmi3GetUInt64(self.inst, &r, 1, &mut x, 1) }, OK);
        x
    }

    pub fn set_u64(&self, r: u32, v: u64) -> fmi3Status {
        unsafe { fmi3SetUInt64(self.inst, &r, 1, &v, 1) }
    }

    pub fn set_i64(&self, r: u32, v: i64) -> fmi3Status {
        unsafe { fmi3SetInt64(self.inst, &r, 1, &v, 1) }
    }

    pub fn time(&self) -> f64 {
        self.get_f64(vr::TIME, 1).1[0]
    }

    pub fn step(&self, t: f64, h: f64) -> fmi3Status {
        let (mut a, mut b, mut c, mut last) = (true, true, true, f64::NAN);
        let s = unsafe { fmi3DoStep(self.inst, t, h, false, &mut a, &mut b, &mut c, &mut last) };
        if s == OK || s == WARNING {
            assert!(!a && !b && !c);
            assert!((last - (t + h)).abs() < 1e-12, "lastSuccessfulTime {last}");
        }
        s
    }

    /// `n` steps of `h`, each of which must complete (fmi3OK, or fmi3Warning
    /// when forceResidual passes its limit).
    pub fn run(&self, n: usize, h: f64) {
        for _ in 0..n {
            let t = self.time();
            let s = self.step(t, h);
            assert!(s == OK || s == WARNING, "{s}: {:?}", self.messages());
        }
    }

    /// Sizes (nx, ny, dimension, nModes).
    pub fn sizes(&self) -> (usize, usize, usize, usize) {
        let g = |r| self.get_u64(r) as usize;
        (g(vr::NX), g(vr::NY), g(vr::DIMENSION), g(vr::N_MODES))
    }

    pub fn positions(&self) -> Vec<f64> {
        let (nx, ny, d, _) = self.sizes();
        self.f64s(vr::POSITIONS, nx * ny * d)
    }

    /// Every output and the time, as bits: equal means bit for bit the same.
    pub fn outputs(&self) -> Vec<u64> {
        let (nx, ny, d, r) = self.sizes();
        let mut all = vec![self.time()];
        all.extend(self.f64s(vr::POSITIONS, nx * ny * d));
        all.extend(self.f64s(vr::VELOCITIES, nx * ny * d));
        all.extend(self.f64s(vr::MODAL_COORDINATES, r));
        all.extend(self.f64s(vr::KINETIC_ENERGY, 1));
        all.extend(self.f64s(vr::POTENTIAL_ENERGY, 1));
        bits(&all)
    }

    pub fn get_state(&self) -> fmi3FMUState {
        let mut st: fmi3FMUState = null_mut();
        assert_eq!(unsafe { fmi3GetFMUState(self.inst, &mut st) }, OK, "{:?}", self.messages());
        assert!(!st.is_null());
        st
    }

    pub fn free_state(&self, mut st: fmi3FMUState) {
        assert_eq!(unsafe { fmi3FreeFMUState(self.inst, &mut st) }, OK);
    }

    pub fn serialize(&self, st: fmi3FMUState) -> Vec<u8> {
        let mut n = 0usize;
        assert_eq!(unsafe { fmi3SerializedFMUStateSize(self.inst, st, &mut n) }, OK);
        let mut b = vec![0u8; n];
        assert_eq!(unsafe { fmi3SerializeFMUState(self.inst, st, b.as_mut_ptr(), n) }, OK);
        b
    }

    /// The whole state of the instance as bytes (mode, times, parameters,
    /// simulator state), through the C functions.
    pub fn snapshot(&self) -> Vec<u8> {
        let st = self.get_state();
        let b = self.serialize(st);
        self.free_state(st);
        b
    }

    /// The FMI state the instance is in.
    pub fn mode(&self) -> Mode {
        serialize::decode(&self.snapshot()).unwrap().mode
    }

    pub fn deserialize(&self, b: &[u8]) -> (fmi3Status, fmi3FMUState) {
        let mut st: fmi3FMUState = null_mut();
        let s = unsafe { fmi3DeserializeFMUState(self.inst, b.as_ptr(), b.len(), &mut st) };
        (s, st)
    }

    /// Takes the FMU state now, runs `continue_run` from it, then restores
    /// it by fmi3SetFMUState and through serialization: each continuation
    /// must return the same values as the first.
    #[allow(dead_code)]
    pub fn assert_resumes(&self, continue_run: impl Fn(&Fmu) -> Vec<u64>) {
        let st = self.get_state();
        let bytes = self.serialize(st);
        let first = continue_run(self);
        assert_eq!(unsafe { fmi3SetFMUState(self.inst, st) }, OK);
        assert_eq!(continue_run(self), first, "get/set");
        let (status, st2) = self.deserialize(&bytes);
        assert_eq!(status, OK);
        assert_eq!(unsafe { fmi3SetFMUState(self.inst, st2) }, OK);
        assert_eq!(continue_run(self), first, "serialize/deserialize");
        self.free_state(st);
        self.free_state(st2);
    }
}

impl Drop for Fmu {
    fn drop(&mut self) {
        unsafe { fmi3FreeInstance(self.inst) };
    }
}

pub fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn newest(dir: &Path) -> SystemTime {
    let mut t = SystemTime::UNIX_EPOCH;
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        let m = if p.is_dir() { newest(&p) } else { e.metadata().unwrap().modified().unwrap() };
        t = t.max(m);
    }
    t
}

/// target/fmu/ModalMassSpring.fmu (release build), made with `cargo xtask
/// fmu` when it is missing or older than the sources; one test at a time
/// (the tests of the binary run in parallel and would build it together).
pub fn packed_fmu() -> PathBuf {
    static BUILDING: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _one_at_a_time = BUILDING.lock().unwrap_or_else(|e| e.into_inner());
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let target = std::env::var_os("CARGO_TARGET_DIR").map(PathBuf::from).unwrap_or(root.join("target"));
    let fmu = target.join("fmu/ModalMassSpring.fmu");
    let sources = ["src", "modelDescription", "xtask/src"].iter().map(|d| newest(&root.join(d))).max().unwrap();
    let fresh = std::fs::metadata(&fmu).and_then(|m| m.modified()).is_ok_and(|t| t >= sources);
    if !fresh {
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
        let status = Command::new(cargo).current_dir(root).args(["xtask", "fmu"]).status();
        assert!(status.is_ok_and(|s| s.success()), "{} is missing or stale and `cargo xtask fmu` failed; run it by hand to see why", fmu.display());
    }
    fmu
}
