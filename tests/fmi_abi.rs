//! The fmi3 C functions called directly (the rlib exports them): state
//! machine guards, argument and range checks, nValues, FMU state and its
//! serialization, unsupported functions.

#![allow(clippy::missing_safety_doc)]

use std::ffi::{c_char, CStr, CString};
use std::ptr::{null, null_mut};

use fmi_sys::fmi3::*;
use modal_mass_spring::fmi::exports::*;
use modal_mass_spring::fmi::variables::{vr, INSTANTIATION_TOKEN};

use crate::common;
use common::*;

#[test]
fn version_is_3_0() {
    let v = unsafe { CStr::from_ptr(fmi3GetVersion()) };
    assert_eq!(v.to_str().unwrap(), "3.0");
}

#[test]
fn instantiation_checks_token_name_and_interface() {
    let log = Box::<Log>::default();
    let env = log.env();
    let bad = CString::new("{not-the-token}").unwrap();
    let empty = CString::new("").unwrap();
    let blank = CString::new(" \t").unwrap();
    let good = CString::new(INSTANTIATION_TOKEN).unwrap();
    let name = CString::new("a").unwrap();
    let cs = |name: *const c_char, token: *const c_char, event_mode: bool, n_required: usize, logger: fmi3LogMessageCallback| unsafe {
        let required = [vr::POSITIONS];
        fmi3InstantiateCoSimulation(name, token, null(), false, false, event_mode, false, required.as_ptr(), n_required, env, logger, None)
    };
    let refused: [(&str, *const c_char, *const c_char, bool, usize); 8] = [
        ("wrong token", name.as_ptr(), bad.as_ptr(), false, 0),
        ("token of an empty string", name.as_ptr(), empty.as_ptr(), false, 0),
        ("NULL token", name.as_ptr(), null(), false, 0),
        ("NULL instance name", null(), good.as_ptr(), false, 0),
        ("empty instance name", empty.as_ptr(), good.as_ptr(), false, 0),
        ("blank instance name", blank.as_ptr(), good.as_ptr(), false, 0),
        ("Event Mode asked for", name.as_ptr(), good.as_ptr(), true, 0),
        ("intermediate variables asked for", name.as_ptr(), good.as_ptr(), false, 1),
    ];
    for (what, n, t, e, r) in refused {
        assert!(cs(n, t, e, r, Some(logger)).is_null(), "{what}");
        let logged = log.take();
        assert!(matches!(logged.as_slice(), [(ERROR, c, m)] if c == "logStatusError" && m.starts_with("fmi3InstantiateCoSimulation: ")), "{what}: {logged:?}");
        // Refused without a logger too, and without touching it.
        assert!(cs(n, t, e, r, None).is_null(), "{what} without logger");
    }
    // The logger is optional (nothing is logged then); intermediateUpdate is never called.
    let inst = cs(name.as_ptr(), good.as_ptr(), false, 0, None);
    assert!(!inst.is_null());
    unsafe { fmi3FreeInstance(inst) };

    log.0.lock().unwrap().clear();
    let me = unsafe { fmi3InstantiateModelExchange(null(), good.as_ptr(), null(), false, false, env, Some(logger)) };
    let se = unsafe { fmi3InstantiateScheduledExecution(null(), good.as_ptr(), null(), false, false, env, Some(logger), None, None, None) };
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
    // So is the smallest step there is.
    assert_eq!(f.step(f.time(), 5e-324), OK, "{:?}", f.messages());
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
    f.expect_error(f.set_i64(vr::FIXED_NODES, 4), "not an enumeration value");
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

#[test]
fn stop_time_is_enforced() {
    let f = Fmu::new();
    assert_eq!(unsafe { fmi3EnterInitializationMode(f.inst, false, 0.0, 0.0, true, 0.05) }, OK);
    assert_eq!(unsafe { fmi3ExitInitializationMode(f.inst) }, OK);
    f.run(4, 0.01);
    let before = f.snapshot();
    f.expect_error(f.step(f.time(), 0.02), "a step past stopTime");
    assert_eq!(f.snapshot(), before);
    // Up to stopTime, within the rounding of an importer's accumulated time.
    assert_eq!(f.step(f.time(), 0.01 + 1e-12), OK, "{:?}", f.messages());
    f.expect_error(f.step(f.time(), 1e-6), "any step once at stopTime");

    // stopTime before startTime, or NaN, is refused.
    let g = Fmu::new();
    g.expect_error(unsafe { fmi3EnterInitializationMode(g.inst, false, 0.0, 1.0, true, 0.5) }, "stop before start");
    g.expect_error(unsafe { fmi3EnterInitializationMode(g.inst, false, 0.0, 0.0, true, f64::NAN) }, "NaN stop");
    g.expect_error(unsafe { fmi3EnterInitializationMode(g.inst, false, 0.0, f64::INFINITY, false, 0.0) }, "infinite start");
    // Reset forgets the stop time.
    assert_eq!(unsafe { fmi3Reset(f.inst) }, OK);
    f.init();
    f.run(10, 0.01);
}

#[test]
fn a_step_that_cannot_be_done_is_discarded_and_the_state_kept() {
    let f = Fmu::new();
    // 1e9 internal steps for one communication step: refused, not attempted.
    assert_eq!(f.set_f64(vr::MAX_INTERNAL_STEP, &[1e-9]), OK);
    f.init();
    let before = f.snapshot();
    f.log.take();
    assert_eq!(f.step(0.0, 1.0), DISCARD);
    let logged = f.log.take();
    assert!(matches!(logged.as_slice(), [(DISCARD, c, m)] if c == "logStatusDiscard" && m.contains("internal steps")), "{logged:?}");
    assert_eq!(f.snapshot(), before, "the discarded step left the state as it was");
    // A shorter step goes through.
    assert_eq!(f.step(0.0, 1e-6), OK);
}

/// Every Get/Set type with a NULL array and a count > 0: refused, logged.
#[test]
fn null_arrays_with_counts_are_refused() {
    let f = Fmu::started();
    let before = f.snapshot();
    let r = [vr::KINETIC_ENERGY];
    let n = null_mut();
    unsafe {
        let calls: Vec<(&str, Box<dyn Fn() -> fmi3Status + '_>)> = vec![
            ("GetFloat64 values", Box::new(|| fmi3GetFloat64(f.inst, r.as_ptr(), 1, n as *mut f64, 1))),
            ("GetFloat64 vrs", Box::new(|| fmi3GetFloat64(f.inst, null(), 1, [0.0].as_mut_ptr(), 1))),
            ("SetFloat64 values", Box::new(|| fmi3SetFloat64(f.inst, &vr::DAMPING_ALPHA, 1, null(), 1))),
            ("SetFloat64 vrs", Box::new(|| fmi3SetFloat64(f.inst, null(), 1, [0.0].as_ptr(), 1))),
            ("GetUInt64", Box::new(|| fmi3GetUInt64(f.inst, &vr::NX, 1, null_mut(), 1))),
            ("SetUInt64", Box::new(|| fmi3SetUInt64(f.inst, &vr::NX, 1, null(), 1))),
            ("GetInt64", Box::new(|| fmi3GetInt64(f.inst, &vr::FIXED_NODES, 1, null_mut(), 1))),
            ("SetInt64", Box::new(|| fmi3SetInt64(f.inst, &vr::FIXED_NODES, 1, null(), 1))),
            ("GetBoolean", Box::new(|| fmi3GetBoolean(f.inst, &vr::SHEAR_SPRINGS, 1, null_mut(), 1))),
            ("SetBoolean", Box::new(|| fmi3SetBoolean(f.inst, &vr::SHEAR_SPRINGS, 1, null(), 1))),
            ("GetInt32 vrs", Box::new(|| fmi3GetInt32(f.inst, null(), 1, null_mut(), 1))),
            ("SetFloat32 vrs", Box::new(|| fmi3SetFloat32(f.inst, null(), 2, null(), 2))),
            ("SetDebugLogging", Box::new(|| fmi3SetDebugLogging(f.inst, true, 2, null()))),
            ("SetDebugLogging NULL category", Box::new(|| fmi3SetDebugLogging(f.inst, true, 1, [null()].as_ptr()))),
            ("GetFMUState", Box::new(|| fmi3GetFMUState(f.inst, null_mut()))),
            ("SetFMUState", Box::new(|| fmi3SetFMUState(f.inst, null_mut()))),
            ("FreeFMUState", Box::new(|| fmi3FreeFMUState(f.inst, null_mut()))),
            ("SerializedFMUStateSize state", Box::new(|| fmi3SerializedFMUStateSize(f.inst, null_mut(), &mut 0))),
            ("DeserializeFMUState bytes", Box::new(|| fmi3DeserializeFMUState(f.inst, null(), 10, &mut null_mut()))),
            ("DeserializeFMUState out", Box::new(|| fmi3DeserializeFMUState(f.inst, [0u8; 4].as_ptr(), 4, null_mut()))),
            ("DoStep outputs", Box::new(|| fmi3DoStep(f.inst, 0.0, 0.01, false, null_mut(), null_mut(), null_mut(), null_mut()))),
        ];
        for (what, call) in calls {
            f.expect_error(call(), what);
        }
        let st = f.get_state();
        f.expect_error(fmi3SerializedFMUStateSize(f.inst, st, null_mut()), "SerializedFMUStateSize size");
        f.expect_error(fmi3SerializeFMUState(f.inst, st, null_mut(), 10), "SerializeFMUState bytes");
        f.free_state(st);
    }
    assert_eq!(f.snapshot(), before);
}

/// nValues is compared with the sizes of the variables before the values
/// array is touched: a wrong count with a short (here: dangling) array is
/// refused without reading or writing it.
#[test]
fn n_values_is_checked_before_the_array_is_used() {
    let f = Fmu::started();
    let before = f.snapshot();
    let dangling = std::ptr::NonNull::<f64>::dangling().as_ptr();
    unsafe {
        for n in [0, 2, 199, 1 << 40, usize::MAX / 8, usize::MAX] {
            f.expect_error(fmi3GetFloat64(f.inst, &vr::KINETIC_ENERGY, 1, dangling, n), &format!("get nValues = {n}"));
            f.expect_error(fmi3SetFloat64(f.inst, &vr::DAMPING_ALPHA, 1, dangling, n), &format!("set nValues = {n}"));
        }
        f.expect_error(fmi3SetDebugLogging(f.inst, true, usize::MAX, [null()].as_ptr()), "nCategories");
        f.expect_error(fmi3GetInt32(f.inst, [vr::NX].as_ptr(), usize::MAX, null_mut(), 0), "nValueReferences");
    }
    assert_eq!(f.snapshot(), before);
}

/// Every range of the model description, through the setters: the bounds
/// are accepted, the next value beyond is refused, NaN and infinities too.
#[test]
fn ranges_are_enforced_by_the_setters() {
    use modal_mass_spring::fmi::variables::{Type, VARIABLES};
    let f = Fmu::new();
    for v in VARIABLES.iter().filter(|v| v.holds_value()) {
        let n = match v.vr {
            vr::GRAVITY => 3,
            vr::MODE_WEIGHTS => 2,
            _ => 1,
        };
        let mut tried = 0;
        let before = f.snapshot();
        match v.ty {
            Type::Float64 => {
                for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                    let mut x = f.f64s(v.vr, n);
                    x[n - 1] = bad;
                    f.expect_error(f.set_f64(v.vr, &x), &format!("{} = {bad}", v.name));
                    tried += 1;
                }
                let limits = [(v.min, v.min.map(f64::next_down)), (v.max, v.max.map(f64::next_up))];
                for (edge, beyond) in limits.into_iter().filter_map(|(e, b)| Some((e?, b?))) {
                    let x = f.f64s(v.vr, n);
                    let mut y = x.clone();
                    y[0] = beyond;
                    f.expect_error(f.set_f64(v.vr, &y), &format!("{} = {beyond:e}", v.name));
                    y[0] = edge;
                    assert_eq!(f.set_f64(v.vr, &y), OK, "{} = {edge:e}: {:?}", v.name, f.messages());
                    assert_eq!(f.set_f64(v.vr, &x), OK);
                    tried += 1;
                }
            }
            Type::UInt64 if !v.dims.is_empty() => {
                // holderOfNode, one per node: every value checked.
                let n = 100;
                let x: Vec<u64> = vec![0; n];
                for bad in [v.max.unwrap() as u64 + 1, u64::MAX] {
                    let mut y = x.clone();
                    y[n - 1] = bad;
                    f.expect_error(unsafe { fmi3SetUInt64(f.inst, &v.vr, 1, y.as_ptr(), n) }, &format!("{} = {bad}", v.name));
                }
                for good in [v.min.unwrap() as u64, v.max.unwrap() as u64, 0] {
                    let y = vec![good; n];
                    assert_eq!(unsafe { fmi3SetUInt64(f.inst, &v.vr, 1, y.as_ptr(), n) }, OK, "{} = {good}: {:?}", v.name, f.messages());
                }
                tried += 1;
            }
            Type::UInt64 => {
                let lo = v.min.unwrap() as u64;
                let hi = v.max.unwrap() as u64;
                let x = f.get_u64(v.vr);
                for bad in [lo - 1, hi + 1, 1 << 53, (1 << 53) + 1, u64::MAX] {
                    f.expect_error(f.set_u64(v.vr, bad), &format!("{} = {bad}", v.name));
                }
                // The load node is also checked against the grid (tests/point_load.rs):
                // of its range only the nodes of the grid that are free are accepted.
                let goods = if [vr::LOAD_ROW, vr::LOAD_COLUMN].contains(&v.vr) { vec![x] } else { vec![lo, hi, x] };
                for good in goods {
                    assert_eq!(f.set_u64(v.vr, good), OK, "{} = {good}: {:?}", v.name, f.messages());
                }
                tried += 1;
            }
            Type::Int64 => {
                for bad in [0, v.enum_values.iter().max().unwrap() + 1, -1, i64::MAX, i64::MIN] {
                    f.expect_error(f.set_i64(v.vr, bad), &format!("{} = {bad}", v.name));
                }
                tried += 1;
            }
            Type::Boolean => {
                // Any non-zero byte is true.
                let raw = [2u8];
                assert_eq!(unsafe { fmi3SetBoolean(f.inst, &v.vr, 1, raw.as_ptr() as *const bool, 1) }, OK);
                let mut b = false;
                assert_eq!(unsafe { fmi3GetBoolean(f.inst, &v.vr, 1, &mut b, 1) }, OK);
                assert!(b, "{}", v.name);
                let start = [v.start[0] != 0.0];
                assert_eq!(unsafe { fmi3SetBoolean(f.inst, &v.vr, 1, start.as_ptr(), 1) }, OK);
                tried += 1;
            }
        }
        assert!(tried > 0, "{}", v.name);
        assert_eq!(f.snapshot(), before, "{}: refused values changed the instance", v.name);
    }
}

#[test]
fn step_sizes_a_few_ulps_apart_give_the_same_trajectory() {
    // fmusim, started at t = 1 s, steps 0.01 s as differences of
    // communication points: 0.01000000000000001 s, one ulp above the default
    // maxInternalStep.
    let exact = Fmu::started();
    let shifted = Fmu::new();
    assert_eq!(unsafe { fmi3EnterInitializationMode(shifted.inst, false, 0.0, 1.0, false, 0.0) }, OK);
    assert_eq!(unsafe { fmi3ExitInitializationMode(shifted.inst) }, OK);
    for k in 0..200 {
        let (t0, t1) = (1.0 + k as f64 * 0.01, 1.0 + (k + 1) as f64 * 0.01);
        assert_eq!(shifted.step(t0, t1 - t0), OK, "{:?}", shifted.messages());
        assert_eq!(exact.step(exact.time(), 0.01), OK);
    }
    let (a, b) = (exact.positions(), shifted.positions());
    let diff = a.iter().zip(&b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    assert!(diff < 1e-12, "positions after 2 s differ by {diff:e} m");
    let energy = |f: &Fmu| f.f64s(vr::KINETIC_ENERGY, 1)[0] + f.f64s(vr::POTENTIAL_ENERGY, 1)[0];
    assert!((energy(&exact) - energy(&shifted)).abs() < 1e-12, "energies {} and {}", energy(&exact), energy(&shifted));
}
