//! The fmi3 C functions called directly (the rlib exports them): state
//! machine guards, argument and range checks, nValues, FMU state and its
//! serialization, unsupported functions.

#![allow(clippy::missing_safety_doc)]

use std::ffi::{c_char, c_void, CStr, CString};
use std::ptr::{null, null_mut};
use std::sync::Mutex;

use fmi_sys::fmi3::*;
use modal_mass_spring::fmi::exports::*;
use modal_mass_spring::fmi::variables::{vr, INSTANTIATION_TOKEN};

const OK: fmi3Status = fmi3Status_fmi3OK;
const ERROR: fmi3Status = fmi3Status_fmi3Error;

/// Collects log messages; passed as instanceEnvironment.
#[derive(Default)]
struct Log(Mutex<Vec<(fmi3Status, String, String)>>);

unsafe extern "C" fn logger(env: fmi3InstanceEnvironment, status: fmi3Status, category: fmi3String, message: fmi3String) {
    let log = &*(env as *const Log);
    let s = |p: fmi3String| CStr::from_ptr(p).to_string_lossy().into_owned();
    log.0.lock().unwrap().push((status, s(category), s(message)));
}

struct Fmu {
    inst: fmi3Instance,
    log: Box<Log>,
}

impl Fmu {
    fn new() -> Fmu {
        let log = Box::<Log>::default();
        let name = CString::new("test").unwrap();
        let token = CString::new(INSTANTIATION_TOKEN).unwrap();
        let inst = unsafe {
            fmi3InstantiateCoSimulation(
                name.as_ptr(),
                token.as_ptr(),
                null(),
                false,
                false,
                false,
                false,
                null(),
                0,
                &*log as *const Log as *mut c_void,
                Some(logger),
                None,
            )
        };
        assert!(!inst.is_null());
        Fmu { inst, log }
    }

    /// Instantiated -> Initialization Mode -> Step Mode.
    fn started() -> Fmu {
        let f = Fmu::new();
        f.init();
        f
    }

    fn init(&self) {
        assert_eq!(unsafe { fmi3EnterInitializationMode(self.inst, false, 0.0, 0.0, false, 0.0) }, OK);
        assert_eq!(unsafe { fmi3ExitInitializationMode(self.inst) }, OK, "{:?}", self.messages());
    }

    fn messages(&self) -> Vec<String> {
        self.log.0.lock().unwrap().iter().map(|(_, c, m)| format!("[{c}] {m}")).collect()
    }

    /// `status` is fmi3Error and an error was logged (the log is then cleared).
    fn expect_error(&self, status: fmi3Status, what: &str) {
        assert_eq!(status, ERROR, "{what}");
        let last = self.log.0.lock().unwrap().last().cloned();
        assert!(matches!(last, Some((ERROR, _, _))), "{what}: no error logged");
        self.log.0.lock().unwrap().clear();
    }

    fn get_f64(&self, r: u32, n: usize) -> (fmi3Status, Vec<f64>) {
        let mut v = vec![f64::NAN; n];
        let s = unsafe { fmi3GetFloat64(self.inst, &r, 1, v.as_mut_ptr(), n) };
        (s, v)
    }

    fn set_f64(&self, r: u32, v: &[f64]) -> fmi3Status {
        unsafe { fmi3SetFloat64(self.inst, &r, 1, v.as_ptr(), v.len()) }
    }

    fn set_u64(&self, r: u32, v: u64) -> fmi3Status {
        unsafe { fmi3SetUInt64(self.inst, &r, 1, &v, 1) }
    }

    fn set_i64(&self, r: u32, v: i64) -> fmi3Status {
        unsafe { fmi3SetInt64(self.inst, &r, 1, &v, 1) }
    }

    fn time(&self) -> f64 {
        self.get_f64(vr::TIME, 1).1[0]
    }

    fn step(&self, t: f64, h: f64) -> fmi3Status {
        let (mut a, mut b, mut c, mut last) = (true, true, true, f64::NAN);
        let s = unsafe { fmi3DoStep(self.inst, t, h, false, &mut a, &mut b, &mut c, &mut last) };
        if s == OK {
            assert!(!a && !b && !c);
            assert!((last - (t + h)).abs() < 1e-12, "lastSuccessfulTime {last}");
        }
        s
    }

    fn run(&self, n: usize, h: f64) {
        for _ in 0..n {
            let t = self.time();
            assert_eq!(self.step(t, h), OK, "{:?}", self.messages());
        }
    }

    fn positions(&self) -> Vec<f64> {
        let (s, p) = self.get_f64(vr::POSITIONS, 200);
        assert_eq!(s, OK, "{:?}", self.messages());
        p
    }

    fn get_state(&self) -> fmi3FMUState {
        let mut st: fmi3FMUState = null_mut();
        assert_eq!(unsafe { fmi3GetFMUState(self.inst, &mut st) }, OK);
        assert!(!st.is_null());
        st
    }

    fn serialize(&self, st: fmi3FMUState) -> Vec<u8> {
        let mut n = 0usize;
        assert_eq!(unsafe { fmi3SerializedFMUStateSize(self.inst, st, &mut n) }, OK);
        let mut b = vec![0u8; n];
        assert_eq!(unsafe { fmi3SerializeFMUState(self.inst, st, b.as_mut_ptr(), n) }, OK);
        b
    }

    fn deserialize(&self, b: &[u8]) -> (fmi3Status, fmi3FMUState) {
        let mut st: fmi3FMUState = null_mut();
        let s = unsafe { fmi3DeserializeFMUState(self.inst, b.as_ptr(), b.len(), &mut st) };
        (s, st)
    }
}

impl Drop for Fmu {
    fn drop(&mut self) {
        unsafe { fmi3FreeInstance(self.inst) };
    }
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

#[test]
fn version_is_3_0() {
    let v = unsafe { CStr::from_ptr(fmi3GetVersion()) };
    assert_eq!(v.to_str().unwrap(), "3.0");
}

#[test]
fn instantiation_checks_token_and_interface() {
    let log = Box::<Log>::default();
    let env = &*log as *const Log as *mut c_void;
    let bad = CString::new("{not-the-token}").unwrap();
    let good = CString::new(INSTANTIATION_TOKEN).unwrap();
    let cs = |token: *const c_char, event_mode: bool, logger: fmi3LogMessageCallback| unsafe {
        fmi3InstantiateCoSimulation(null(), token, null(), false, false, event_mode, false, null(), 0, env, logger, None)
    };
    assert!(cs(bad.as_ptr(), false, Some(logger)).is_null());
    assert!(cs(null(), false, Some(logger)).is_null());
    assert!(cs(good.as_ptr(), true, Some(logger)).is_null(), "no Event Mode");
    assert_eq!(log.0.lock().unwrap().len(), 3, "each refusal is logged");
    // A null instance name and a null logger are fine.
    let inst = cs(good.as_ptr(), false, None);
    assert!(!inst.is_null());
    unsafe { fmi3FreeInstance(inst) };

    log.0.lock().unwrap().clear();
    let me = unsafe { fmi3InstantiateModelExchange(null(), good.as_ptr(), null(), false, false, env, Some(logger)) };
    let se = unsafe {
        fmi3InstantiateScheduledExecution(null(), good.as_ptr(), null(), false, false, env, Some(logger), None, None, None)
    };
    assert!(me.is_null() && se.is_null());
    assert_eq!(log.0.lock().unwrap().len(), 2);
}

#[test]
fn null_instance_is_refused() {
    unsafe {
        assert_eq!(fmi3EnterInitializationMode(null_mut(), false, 0.0, 0.0, false, 0.0), ERROR);
        assert_eq!(fmi3DoStep(null_mut(), 0.0, 0.1, false, null_mut(), null_mut(), null_mut(), null_mut()), ERROR);
        fmi3FreeInstance(null_mut());
        let mut junk = [0u64; 16];
        assert_eq!(fmi3Terminate(junk.as_mut_ptr() as fmi3Instance), ERROR, "foreign pointer");
    }
}

#[test]
fn state_machine_guards() {
    let f = Fmu::new();
    f.expect_error(f.step(0.0, 0.01), "DoStep in Instantiated");
    f.expect_error(unsafe { fmi3ExitInitializationMode(f.inst) }, "ExitInitializationMode in Instantiated");
    f.expect_error(unsafe { fmi3Terminate(f.inst) }, "Terminate in Instantiated");
    f.expect_error(unsafe { fmi3ExitConfigurationMode(f.inst) }, "ExitConfigurationMode in Instantiated");

    assert_eq!(unsafe { fmi3EnterInitializationMode(f.inst, false, 0.0, 0.0, false, 0.0) }, OK);
    f.expect_error(unsafe { fmi3EnterInitializationMode(f.inst, false, 0.0, 0.0, false, 0.0) }, "twice");
    f.expect_error(f.set_u64(vr::NX, 5), "structural parameter in Initialization Mode");
    f.expect_error(unsafe { fmi3EnterConfigurationMode(f.inst) }, "Configuration Mode from Initialization Mode");
    assert_eq!(unsafe { fmi3ExitInitializationMode(f.inst) }, OK);

    f.expect_error(f.set_f64(vr::SPACING, &[0.2]), "fixed parameter in Step Mode");
    f.expect_error(f.set_u64(vr::NX, 5), "structural parameter in Step Mode");
    f.expect_error(f.set_f64(vr::KINETIC_ENERGY, &[1.0]), "output");
    f.expect_error(f.set_f64(vr::TIME, &[1.0]), "independent variable");
    f.expect_error(unsafe { fmi3EnterConfigurationMode(f.inst) }, "no Reconfiguration Mode");
    f.expect_error(unsafe { fmi3EnterStepMode(f.inst) }, "EnterStepMode");
    f.expect_error(unsafe { fmi3EnterEventMode(f.inst) }, "EnterEventMode");
    assert_eq!(f.set_f64(vr::DAMPING_ALPHA, &[0.5]), OK, "tunable in Step Mode");

    assert_eq!(f.step(0.0, 0.01), OK);
    assert_eq!(unsafe { fmi3Terminate(f.inst) }, OK);
    f.expect_error(f.step(0.01, 0.01), "DoStep after Terminate");
    assert_eq!(f.get_f64(vr::KINETIC_ENERGY, 1).0, OK, "outputs readable when terminated");

    assert_eq!(unsafe { fmi3Reset(f.inst) }, OK);
    assert_eq!(f.get_f64(vr::DAMPING_ALPHA, 1), (OK, vec![0.0]), "Reset restores start values");
    assert_eq!(f.set_u64(vr::NX, 5), OK, "Instantiated again");
    f.init();
    assert_eq!(f.time(), 0.0);
}

#[test]
fn do_step_arguments() {
    let f = Fmu::started();
    f.expect_error(f.step(0.5, 0.01), "wrong communication point");
    f.expect_error(f.step(0.0, 0.0), "zero step");
    f.expect_error(f.step(0.0, -0.01), "negative step");
    f.expect_error(f.step(0.0, f64::NAN), "NaN step");
    f.expect_error(f.step(0.0, f64::INFINITY), "infinite step");
    f.expect_error(f.step(f64::NAN, 0.01), "NaN time");
    let s = unsafe { fmi3DoStep(f.inst, 0.0, 0.01, false, null_mut(), null_mut(), null_mut(), null_mut()) };
    f.expect_error(s, "null outputs");
    assert_eq!(f.time(), 0.0, "refused steps do not advance");
    let p0 = f.positions();
    f.run(20, 0.01);
    assert!((f.time() - 0.2).abs() < 1e-12);
    // Communication points accumulated differently by the importer are accepted.
    assert_eq!(f.step(0.2 + 1e-14, 0.01), OK);
    let p = f.positions();
    assert!(p.iter().all(|x| x.is_finite()));
    // Bottom-left node (row 9, col 0) falls; the top row stays fixed.
    assert!(p[180 + 1] < p0[180 + 1] - 1e-3, "sags: {} vs {}", p[181], p0[181]);
    assert_eq!(&p[..20], &p0[..20]);
}

#[test]
fn n_values_must_match_the_array_sizes() {
    let f = Fmu::started();
    assert_eq!(f.get_f64(vr::POSITIONS, 200).0, OK);
    f.expect_error(f.get_f64(vr::POSITIONS, 199).0, "too few");
    f.expect_error(f.get_f64(vr::POSITIONS, 201).0, "too many");
    f.expect_error(f.set_f64(vr::GRAVITY, &[0.0, -1.0]), "2 of 3 gravity values");
    assert_eq!(f.get_f64(vr::GRAVITY, 3).1, vec![0.0, -9.81, 0.0], "nothing stored");
    let vrs = [vr::KINETIC_ENERGY, vr::MODE_WEIGHTS, vr::GRAVITY];
    let mut v = [0.0; 6];
    assert_eq!(unsafe { fmi3GetFloat64(f.inst, vrs.as_ptr(), 3, v.as_mut_ptr(), 6) }, OK);
    assert_eq!(&v[1..], &[1.0, 1.0, 0.0, -9.81, 0.0]);
    f.expect_error(unsafe { fmi3GetFloat64(f.inst, vrs.as_ptr(), 3, v.as_mut_ptr(), 5) }, "sum of sizes");
    f.expect_error(unsafe { fmi3GetFloat64(f.inst, null(), 1, v.as_mut_ptr(), 1) }, "null vrs");
    f.expect_error(unsafe { fmi3GetFloat64(f.inst, vrs.as_ptr(), 1, null_mut(), 1) }, "null values");
    assert_eq!(unsafe { fmi3GetFloat64(f.inst, null(), 0, null_mut(), 0) }, OK, "empty request");
}

#[test]
fn values_are_checked_before_they_are_stored() {
    let f = Fmu::new();
    f.expect_error(f.set_f64(vr::DAMPING_ALPHA, &[-1.0]), "below min");
    f.expect_error(f.set_f64(vr::DAMPING_BETA, &[f64::NAN]), "NaN");
    f.expect_error(f.set_f64(vr::GRAVITY, &[0.0, f64::INFINITY, 0.0]), "Inf");
    f.expect_error(f.set_f64(vr::SPACING, &[0.0]), "spacing must be positive");
    f.expect_error(f.set_u64(vr::DIMENSION, 4), "above max");
    f.expect_error(f.set_u64(vr::NX, 0), "below min");
    f.expect_error(f.set_i64(vr::FIXED_NODES, 3), "not an enumeration value");
    f.expect_error(f.set_f64(999, &[1.0]), "unknown value reference");
    f.expect_error(f.set_i64(vr::GRAVITY, 1), "wrong type");
    let mut x = 0u64;
    f.expect_error(unsafe { fmi3GetUInt64(f.inst, &vr::GRAVITY, 1, &mut x, 1) }, "wrong type on get");
    let mut i = 0i32;
    f.expect_error(unsafe { fmi3GetInt32(f.inst, &vr::NX, 1, &mut i, 1) }, "no Int32 variables");
    f.init();
    assert_eq!(f.get_f64(vr::DAMPING_ALPHA, 1).1, vec![0.0]);
    assert_eq!(f.get_f64(vr::GRAVITY, 3).1, vec![0.0, -9.81, 0.0]);
    assert_eq!(f.set_i64(vr::FIXED_NODES, 2), ERROR);
    let mut e = 0i64;
    assert_eq!(unsafe { fmi3GetInt64(f.inst, &vr::FIXED_NODES, 1, &mut e, 1) }, OK);
    assert_eq!(e, 1);
    let on = [1u8, 0u8];
    let r = [vr::SHEAR_SPRINGS];
    assert_eq!(unsafe { fmi3SetBoolean(f.inst, r.as_ptr(), 1, on.as_ptr() as *const bool, 1) }, ERROR, "fixed in Step Mode");
}

#[test]
fn structural_parameters_resize_arrays() {
    let f = Fmu::new();
    assert_eq!(unsafe { fmi3EnterConfigurationMode(f.inst) }, OK);
    assert_eq!(f.set_u64(vr::N_MODES, 4), OK);
    assert_eq!(f.set_u64(vr::NX, 6), OK);
    assert_eq!(unsafe { fmi3ExitConfigurationMode(f.inst) }, OK);
    assert_eq!(f.get_f64(vr::MODE_WEIGHTS, 4), (OK, vec![1.0; 4]));
    assert_eq!(f.set_f64(vr::MODE_WEIGHTS, &[1.0, 0.0, 2.0, 1.0]), OK);
    assert_eq!(unsafe { fmi3EnterInitializationMode(f.inst, false, 0.0, 0.0, false, 0.0) }, OK);
    // Outputs in Initialization Mode: the simulator is set up on demand.
    let (s, w) = f.get_f64(vr::MODE_FREQUENCIES, 4);
    assert_eq!(s, OK, "{:?}", f.messages());
    assert!(w.windows(2).all(|p| p[0] <= p[1]) && w[0] > 0.0);
    assert_eq!(f.get_f64(vr::POSITIONS, 6 * 10 * 2).0, OK);
    f.expect_error(f.get_f64(vr::POSITIONS, 200).0, "old size");
    assert_eq!(unsafe { fmi3ExitInitializationMode(f.inst) }, OK);
    f.run(10, 0.01);
    let (_, q) = f.get_f64(vr::MODAL_COORDINATES, 4);
    assert_eq!(q[1], 0.0, "a weight of 0 keeps its mode at rest");
    assert!(q[0] != 0.0);
}

#[test]
fn simulator_errors_are_reported() {
    let f = Fmu::new();
    // 10 x 10 in 2D with the top row fixed has 180 free DOFs.
    assert_eq!(f.set_u64(vr::N_MODES, 500), OK);
    assert_eq!(unsafe { fmi3EnterInitializationMode(f.inst, false, 0.0, 0.0, false, 0.0) }, OK);
    f.expect_error(unsafe { fmi3ExitInitializationMode(f.inst) }, "too many modes");
    // Still in Initialization Mode, where nModes cannot be changed: Reset it is.
    f.expect_error(f.set_u64(vr::N_MODES, 2), "structural in Initialization Mode");
    assert_eq!(unsafe { fmi3Reset(f.inst) }, OK);
    f.init();
}

#[test]
fn tunables_act_between_steps() {
    let a = Fmu::started();
    let b = Fmu::started();
    a.run(5, 0.01);
    b.run(5, 0.01);
    assert_eq!(bits(&a.positions()), bits(&b.positions()));
    assert_eq!(b.set_f64(vr::GRAVITY, &[0.0, 0.0, 0.0]), OK);
    assert_eq!(b.get_f64(vr::GRAVITY, 3).1, vec![0.0; 3]);
    a.run(5, 0.01);
    b.run(5, 0.01);
    assert_ne!(bits(&a.positions()), bits(&b.positions()));
    b.expect_error(b.set_f64(vr::MODE_WEIGHTS, &[1.0, -1.0]), "negative weight");
}

#[test]
fn fmu_state_round_trip() {
    let f = Fmu::started();
    f.run(10, 0.01);
    let st = f.get_state();
    f.run(10, 0.01);
    let a = f.positions();
    assert_eq!(unsafe { fmi3SetFMUState(f.inst, st) }, OK);
    assert!((f.time() - 0.1).abs() < 1e-12);
    f.run(10, 0.01);
    assert_eq!(bits(&f.positions()), bits(&a));

    // The state holds tunables too.
    assert_eq!(f.set_f64(vr::GRAVITY, &[1.0, 0.0, 0.0]), OK);
    assert_eq!(unsafe { fmi3SetFMUState(f.inst, st) }, OK);
    assert_eq!(f.get_f64(vr::GRAVITY, 3).1, vec![0.0, -9.81, 0.0]);

    // Overwriting an existing state in place, then freeing.
    let mut st2 = st;
    assert_eq!(unsafe { fmi3GetFMUState(f.inst, &mut st2) }, OK);
    assert_eq!(st2, st);
    assert_eq!(unsafe { fmi3FreeFMUState(f.inst, &mut st2) }, OK);
    assert!(st2.is_null());
    assert_eq!(unsafe { fmi3FreeFMUState(f.inst, &mut st2) }, OK, "freeing NULL is fine");
    f.expect_error(unsafe { fmi3SetFMUState(f.inst, null_mut()) }, "null state");
}

#[test]
fn serialized_state_resumes_in_a_second_instance() {
    let f = Fmu::started();
    assert_eq!(f.set_f64(vr::DAMPING_BETA, &[0.001]), OK);
    f.run(7, 0.01);
    let st = f.get_state();
    let blob = f.serialize(st);
    f.run(13, 0.01);
    let a = f.positions();

    let g = Fmu::new(); // Instantiated: the state carries its mode.
    let (s, st2) = g.deserialize(&blob);
    assert_eq!(s, OK, "{:?}", g.messages());
    assert_eq!(unsafe { fmi3SetFMUState(g.inst, st2) }, OK, "{:?}", g.messages());
    assert_eq!(g.get_f64(vr::DAMPING_BETA, 1).1, vec![0.001]);
    g.run(13, 0.01);
    assert_eq!(bits(&g.positions()), bits(&a));
    // Serializing the deserialized state gives the same bytes.
    assert_eq!(g.serialize(st2), blob);
}

#[test]
fn corrupted_or_foreign_blobs_are_refused() {
    let f = Fmu::started();
    f.run(3, 0.01);
    let st = f.get_state();
    let blob = f.serialize(st);
    let mut n = 0usize;
    assert_eq!(unsafe { fmi3SerializedFMUStateSize(f.inst, st, &mut n) }, OK);
    let mut short = vec![0u8; n - 1];
    f.expect_error(unsafe { fmi3SerializeFMUState(f.inst, st, short.as_mut_ptr(), n - 1) }, "buffer size");

    for i in [0, 9, 15, 25, 40, blob.len() / 2, blob.len() - 1] {
        let mut bad = blob.clone();
        bad[i] ^= 0x10;
        let (s, p) = f.deserialize(&bad);
        f.expect_error(s, &format!("flipped byte {i}"));
        assert!(p.is_null());
    }
    f.expect_error(f.deserialize(&blob[..blob.len() - 8]).0, "truncated");
    f.expect_error(f.deserialize(&[]).0, "empty");
    let mut longer = blob.clone();
    longer.push(0);
    f.expect_error(f.deserialize(&longer).0, "trailing byte");

    // A blob from an instance with another structure.
    let g = Fmu::new();
    assert_eq!(g.set_u64(vr::NX, 4), OK);
    let gst = g.get_state();
    let other = g.serialize(gst);
    f.expect_error(f.deserialize(&other).0, "different nx");

    // The instance is unchanged by all this.
    let t = f.time();
    f.run(1, 0.01);
    assert!(f.time() > t);
}

#[test]
fn unsupported_functions_return_error() {
    let f = Fmu::started();
    let mut n = 0usize;
    let mut x = 0.0;
    let mut b = false;
    unsafe {
        f.expect_error(fmi3GetNumberOfContinuousStates(f.inst, &mut n), "ME");
        f.expect_error(fmi3GetNumberOfEventIndicators(f.inst, &mut n), "ME");
        f.expect_error(fmi3SetTime(f.inst, 0.0), "ME");
        f.expect_error(fmi3EnterContinuousTimeMode(f.inst), "ME");
        f.expect_error(fmi3CompletedIntegratorStep(f.inst, false, &mut b, &mut b), "ME");
        f.expect_error(fmi3GetDirectionalDerivative(f.inst, null(), 0, null(), 0, null(), 0, &mut x, 0), "derivatives");
        f.expect_error(fmi3GetAdjointDerivative(f.inst, null(), 0, null(), 0, null(), 0, &mut x, 0), "derivatives");
        f.expect_error(fmi3GetNumberOfVariableDependencies(f.inst, vr::POSITIONS, &mut n), "dependencies");
        f.expect_error(fmi3GetIntervalDecimal(f.inst, null(), 0, &mut x, null_mut()), "clocks");
        f.expect_error(fmi3UpdateDiscreteStates(f.inst, &mut b, &mut b, &mut b, &mut b, &mut b, &mut x), "events");
        f.expect_error(fmi3EvaluateDiscreteStates(f.inst), "events");
        f.expect_error(fmi3ActivateModelPartition(f.inst, 0, 0.0), "SE");
        f.expect_error(fmi3GetOutputDerivatives(f.inst, &vr::KINETIC_ENERGY, 1, &1, &mut x, 1), "derivatives");
        let mut c = false;
        f.expect_error(fmi3GetClock(f.inst, &vr::TIME, 1, &mut c), "no clocks");
        let mut s: fmi3String = null();
        f.expect_error(fmi3GetString(f.inst, &vr::TIME, 1, &mut s, 1), "no strings");
    }
}

#[test]
fn debug_logging_categories() {
    let f = Fmu::new();
    let events = CString::new("logEvents").unwrap();
    let unknown = CString::new("logNothing").unwrap();
    let cats = [events.as_ptr()];
    assert_eq!(unsafe { fmi3SetDebugLogging(f.inst, true, 1, cats.as_ptr()) }, OK);
    f.log.0.lock().unwrap().clear();
    f.init();
    assert!(f.messages().iter().any(|m| m.starts_with("[logEvents]")), "{:?}", f.messages());
    let bad = [unknown.as_ptr()];
    f.expect_error(unsafe { fmi3SetDebugLogging(f.inst, true, 1, bad.as_ptr()) }, "unknown category");
    assert_eq!(unsafe { fmi3SetDebugLogging(f.inst, false, 0, null()) }, OK);
}
