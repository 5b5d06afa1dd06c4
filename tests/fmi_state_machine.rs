//! The FMI 3.0 Co-Simulation state machine, table-driven through the C
//! functions: every function of the FMU in every state (Instantiated,
//! Configuration Mode, Initialization Mode, Step Mode, Terminated, and
//! Instantiated again after fmi3Reset), then every variable set in every
//! state by its causality and variability.
//!
//! The expected states come from the standard (the state machine of
//! chapter 2.3 and 4.2, as guarded per function in the Reference FMUs'
//! fmi3Functions.c), with the FMU's two documented extensions: structural
//! parameters may also be set in Instantiated, and variables may be read in
//! every state. A refused call must return fmi3Error, log an error that names
//! the function and says why, and leave the whole instance state unchanged
//! (compared as serialized bytes).

#![allow(clippy::missing_safety_doc)]

use crate::common;

use std::ptr::{null, null_mut};

use common::*;
use fmi_sys::fmi3::*;
use modal_mass_spring::fmi::exports::*;
use modal_mass_spring::fmi::state_machine::Mode;
use modal_mass_spring::fmi::variables::{vr, Causality, Type, Variability, VARIABLES};

/// The states a test instance is driven into; `Reset` is Instantiated reached through fmi3Reset.
#[derive(Clone, Copy, Debug, PartialEq)]
enum At {
    Instantiated,
    Configuration,
    Initialization,
    Step,
    Terminated,
    Reset,
}

const ALL_STATES: [At; 6] = [At::Instantiated, At::Configuration, At::Initialization, At::Step, At::Terminated, At::Reset];

impl At {
    /// Letter used in the tables below.
    fn letter(self) -> char {
        match self {
            At::Instantiated => 'I',
            At::Configuration => 'C',
            At::Initialization => 'N',
            At::Step => 'S',
            At::Terminated => 'T',
            At::Reset => 'R',
        }
    }

    fn mode(self) -> Mode {
        match self {
            At::Instantiated | At::Reset => Mode::Instantiated,
            At::Configuration => Mode::ConfigurationMode,
            At::Initialization => Mode::InitializationMode,
            At::Step => Mode::StepMode,
            At::Terminated => Mode::Terminated,
        }
    }

    /// A fresh instance in this state (Step Mode and later after a few steps).
    fn instance(self) -> Fmu {
        let f = Fmu::new();
        unsafe {
            match self {
                At::Instantiated => {}
                At::Configuration => assert_eq!(fmi3EnterConfigurationMode(f.inst), OK),
                At::Initialization => assert_eq!(fmi3EnterInitializationMode(f.inst, false, 0.0, 0.0, false, 0.0), OK),
                At::Step | At::Terminated | At::Reset => {
                    f.init();
                    f.run(3, 0.01);
                    match self {
                        At::Terminated => assert_eq!(fmi3Terminate(f.inst), OK),
                        At::Reset => assert_eq!(fmi3Reset(f.inst), OK),
                        _ => {}
                    }
                }
            }
        }
        assert_eq!(f.mode(), self.mode());
        f.log.take();
        f
    }
}

/// One function of the FMU, called with valid arguments.
struct Row {
    name: &'static str,
    /// States (letters of [`At::letter`]) in which the call succeeds.
    allowed: &'static str,
    /// State after a successful call; `None`: unchanged.
    next: Option<Mode>,
    call: fn(&Fmu) -> fmi3Status,
}

const fn row(name: &'static str, allowed: &'static str, next: Option<Mode>, call: fn(&Fmu) -> fmi3Status) -> Row {
    Row { name, allowed, next, call }
}

const EVERY: &str = "ICNSTR";
const NONE: &str = "";

fn with_state(f: &Fmu, body: impl FnOnce(fmi3FMUState) -> fmi3Status) -> fmi3Status {
    let st = f.get_state();
    let s = body(st);
    f.free_state(st);
    s
}

fn rows() -> Vec<Row> {
    use Mode::*;
    let mut r = vec![
        row("fmi3SetDebugLogging", EVERY, None, |f| unsafe { fmi3SetDebugLogging(f.inst, true, 0, null()) }),
        row("fmi3EnterInitializationMode", "IR", Some(InitializationMode), |f| unsafe { fmi3EnterInitializationMode(f.inst, false, 0.0, 0.0, true, 10.0) }),
        row("fmi3ExitInitializationMode", "N", Some(StepMode), |f| unsafe { fmi3ExitInitializationMode(f.inst) }),
        // No tunable structural parameters, so no Reconfiguration Mode from Step Mode.
        row("fmi3EnterConfigurationMode", "IR", Some(ConfigurationMode), |f| unsafe { fmi3EnterConfigurationMode(f.inst) }),
        row("fmi3ExitConfigurationMode", "C", Some(Instantiated), |f| unsafe { fmi3ExitConfigurationMode(f.inst) }),
        row("fmi3Terminate", "S", Some(Terminated), |f| unsafe { fmi3Terminate(f.inst) }),
        row("fmi3Reset", EVERY, Some(Instantiated), |f| unsafe { fmi3Reset(f.inst) }),
        row("fmi3DoStep", "S", None, |f| f.step(f.time(), 0.01)),
        // Reads: parameters, the independent variable, outputs, calculated parameters.
        row("fmi3GetFloat64", EVERY, None, |f| f.get_f64(vr::GRAVITY, 3).0),
        row("fmi3GetFloat64", EVERY, None, |f| f.get_f64(vr::TIME, 1).0),
        row("fmi3GetFloat64", EVERY, None, |f| f.get_f64(vr::KINETIC_ENERGY, 1).0),
        row("fmi3GetFloat64", EVERY, None, |f| f.get_f64(vr::MODE_FREQUENCIES, 2).0),
        row("fmi3GetUInt64", EVERY, None, |f| unsafe {
            let mut x = 0u64;
            fmi3GetUInt64(f.inst, &vr::NX, 1, &mut x, 1)
        }),
        row("fmi3GetInt64", EVERY, None, |f| unsafe {
            let mut x = 0i64;
            fmi3GetInt64(f.inst, &vr::FIXED_NODES, 1, &mut x, 1)
        }),
        row("fmi3GetBoolean", EVERY, None, |f| unsafe {
            let mut x = false;
            fmi3GetBoolean(f.inst, &vr::SHEAR_SPRINGS, 1, &mut x, 1)
        }),
        // Writes, by causality and variability (more in `every_variable_in_every_state`).
        row("fmi3SetFloat64", "INSR", None, |f| f.set_f64(vr::DAMPING_ALPHA, &[0.25])),
        row("fmi3SetFloat64", "INR", None, |f| f.set_f64(vr::SPACING, &[0.11])),
        row("fmi3SetUInt64", "ICR", None, |f| f.set_u64(vr::NX, 6)),
        row("fmi3SetInt64", "INR", None, |f| f.set_i64(vr::FIXED_NODES, 2)),
        row("fmi3SetBoolean", "INR", None, |f| unsafe { fmi3SetBoolean(f.inst, &vr::BENDING_SPRINGS, 1, &true, 1) }),
        // Types without variables: an empty request is a valid call.
        row("fmi3GetInt32", EVERY, None, |f| unsafe { fmi3GetInt32(f.inst, null(), 0, null_mut(), 0) }),
        row("fmi3SetInt32", "ICNSR", None, |f| unsafe { fmi3SetInt32(f.inst, null(), 0, null(), 0) }),
        row("fmi3GetString", EVERY, None, |f| unsafe { fmi3GetString(f.inst, null(), 0, null_mut(), 0) }),
        row("fmi3SetString", "ICNSR", None, |f| unsafe { fmi3SetString(f.inst, null(), 0, null(), 0) }),
        // FMU state: every state (super state FMU State Setable).
        row("fmi3GetFMUState", EVERY, None, |f| unsafe {
            let mut st = null_mut();
            let s = fmi3GetFMUState(f.inst, &mut st);
            f.free_state(st);
            s
        }),
        row("fmi3SetFMUState", EVERY, None, |f| with_state(f, |st| unsafe { fmi3SetFMUState(f.inst, st) })),
        row("fmi3FreeFMUState", EVERY, None, |f| unsafe {
            let mut st = f.get_state();
            fmi3FreeFMUState(f.inst, &mut st)
        }),
        row("fmi3SerializedFMUStateSize", EVERY, None, |f| {
            with_state(f, |st| unsafe {
                let mut n = 0;
                fmi3SerializedFMUStateSize(f.inst, st, &mut n)
            })
        }),
        row("fmi3SerializeFMUState", EVERY, None, |f| {
            with_state(f, |st| unsafe {
                let mut n = 0;
                fmi3SerializedFMUStateSize(f.inst, st, &mut n);
                let mut b = vec![0u8; n];
                fmi3SerializeFMUState(f.inst, st, b.as_mut_ptr(), n)
            })
        }),
        row("fmi3DeserializeFMUState", EVERY, None, |f| {
            let blob = f.snapshot();
            let (s, st) = f.deserialize(&blob);
            f.free_state(st);
            s
        }),
    ];
    // Interfaces and features this FMU does not have: refused in every state.
    let unsupported: [Row; 24] = [
        row("fmi3EnterEventMode", NONE, None, |f| unsafe { fmi3EnterEventMode(f.inst) }),
        row("fmi3EnterStepMode", NONE, None, |f| unsafe { fmi3EnterStepMode(f.inst) }),
        row("fmi3UpdateDiscreteStates", NONE, None, |f| unsafe {
            let (mut a, mut b, mut c, mut d, mut e, mut t) = (false, false, false, false, false, 0.0);
            fmi3UpdateDiscreteStates(f.inst, &mut a, &mut b, &mut c, &mut d, &mut e, &mut t)
        }),
        row("fmi3EvaluateDiscreteStates", NONE, None, |f| unsafe { fmi3EvaluateDiscreteStates(f.inst) }),
        row("fmi3EnterContinuousTimeMode", NONE, None, |f| unsafe { fmi3EnterContinuousTimeMode(f.inst) }),
        row("fmi3CompletedIntegratorStep", NONE, None, |f| unsafe {
            let (mut a, mut b) = (false, false);
            fmi3CompletedIntegratorStep(f.inst, false, &mut a, &mut b)
        }),
        row("fmi3SetTime", NONE, None, |f| unsafe { fmi3SetTime(f.inst, 0.0) }),
        row("fmi3SetContinuousStates", NONE, None, |f| unsafe { fmi3SetContinuousStates(f.inst, [0.0].as_ptr(), 1) }),
        row("fmi3GetContinuousStateDerivatives", NONE, None, |f| unsafe { fmi3GetContinuousStateDerivatives(f.inst, [0.0].as_mut_ptr(), 1) }),
        row("fmi3GetEventIndicators", NONE, None, |f| unsafe { fmi3GetEventIndicators(f.inst, [0.0].as_mut_ptr(), 1) }),
        row("fmi3GetContinuousStates", NONE, None, |f| unsafe { fmi3GetContinuousStates(f.inst, [0.0].as_mut_ptr(), 1) }),
        row("fmi3GetNominalsOfContinuousStates", NONE, None, |f| unsafe { fmi3GetNominalsOfContinuousStates(f.inst, [0.0].as_mut_ptr(), 1) }),
        row("fmi3GetNumberOfEventIndicators", NONE, None, |f| unsafe { fmi3GetNumberOfEventIndicators(f.inst, &mut 0) }),
        row("fmi3GetNumberOfContinuousStates", NONE, None, |f| unsafe { fmi3GetNumberOfContinuousStates(f.inst, &mut 0) }),
        row("fmi3GetDirectionalDerivative", NONE, None, |f| unsafe {
            fmi3GetDirectionalDerivative(f.inst, &vr::KINETIC_ENERGY, 1, &vr::GRAVITY, 1, &1.0, 1, &mut 0.0, 1)
        }),
        row("fmi3GetAdjointDerivative", NONE, None, |f| unsafe {
            fmi3GetAdjointDerivative(f.inst, &vr::KINETIC_ENERGY, 1, &vr::GRAVITY, 1, &1.0, 1, &mut 0.0, 1)
        }),
        row("fmi3GetOutputDerivatives", NONE, None, |f| unsafe { fmi3GetOutputDerivatives(f.inst, &vr::KINETIC_ENERGY, 1, &1, &mut 0.0, 1) }),
        row("fmi3GetNumberOfVariableDependencies", NONE, None, |f| unsafe { fmi3GetNumberOfVariableDependencies(f.inst, vr::POSITIONS, &mut 0) }),
        row("fmi3GetVariableDependencies", NONE, None, |f| unsafe {
            fmi3GetVariableDependencies(f.inst, vr::POSITIONS, null_mut(), null_mut(), null_mut(), null_mut(), 0)
        }),
        row("fmi3GetClock", NONE, None, |f| unsafe { fmi3GetClock(f.inst, &vr::TIME, 1, &mut false) }),
        row("fmi3SetClock", NONE, None, |f| unsafe { fmi3SetClock(f.inst, &vr::TIME, 1, &true) }),
        row("fmi3GetIntervalDecimal", NONE, None, |f| unsafe { fmi3GetIntervalDecimal(f.inst, &vr::TIME, 1, &mut 0.0, &mut 0) }),
        row("fmi3SetIntervalDecimal", NONE, None, |f| unsafe { fmi3SetIntervalDecimal(f.inst, &vr::TIME, 1, &0.0) }),
        row("fmi3ActivateModelPartition", NONE, None, |f| unsafe { fmi3ActivateModelPartition(f.inst, 0, 0.0) }),
    ];
    r.extend(unsupported);
    r
}

/// A refused call: fmi3Error, an error logged that names the function and
/// gives a reason, and nothing changed.
fn assert_refused(f: &Fmu, before: &[u8], status: fmi3Status, function: &str, what: &str) {
    assert_eq!(status, ERROR, "{what}: expected fmi3Error, log {:?}", f.messages());
    let logged = f.log.take();
    let last = logged.last().unwrap_or_else(|| panic!("{what}: nothing logged"));
    assert_eq!(last.0, ERROR, "{what}: {last:?}");
    let reason = last.2.strip_prefix(&format!("{function}: ")).unwrap_or_else(|| panic!("{what}: message does not name {function}: {}", last.2));
    assert!(reason.len() > 10, "{what}: no reason given: {}", last.2);
    assert_eq!(f.snapshot(), before, "{what}: the refused call changed the instance");
}

#[test]
fn every_function_in_every_state() {
    let mut cells = 0;
    for row in rows() {
        for at in ALL_STATES {
            let f = at.instance();
            let before = f.snapshot();
            let status = (row.call)(&f);
            let what = format!("{} in {at:?}", row.name);
            if row.allowed.contains(at.letter()) {
                assert_eq!(status, OK, "{what}: {:?}", f.messages());
                assert!(f.log.take().iter().all(|m| m.0 == OK), "{what}: logged a problem");
                assert_eq!(f.mode(), row.next.unwrap_or(at.mode()), "{what}: state afterwards");
            } else {
                assert_refused(&f, &before, status, row.name, &what);
            }
            cells += 1;
        }
    }
    assert_eq!(cells, rows().len() * ALL_STATES.len());
}

/// Value of `v` in `f` (booleans 0/1), through the getter of its type.
fn current(f: &Fmu, r: u32, ty: Type, n: usize) -> Vec<f64> {
    unsafe {
        match ty {
            Type::Float64 => f.f64s(r, n),
            Type::UInt64 => {
                let mut x = vec![0u64; n];
                assert_eq!(fmi3GetUInt64(f.inst, &r, 1, x.as_mut_ptr(), n), OK);
                x.iter().map(|&v| v as f64).collect()
            }
            Type::Int64 => {
                let mut x = vec![0i64; n];
                assert_eq!(fmi3GetInt64(f.inst, &r, 1, x.as_mut_ptr(), n), OK);
                x.iter().map(|&v| v as f64).collect()
            }
            Type::Boolean => {
                let mut x = vec![false; n];
                assert_eq!(fmi3GetBoolean(f.inst, &r, 1, x.as_mut_ptr(), n), OK);
                x.iter().map(|&v| v as u8 as f64).collect()
            }
        }
    }
}

fn set(f: &Fmu, r: u32, ty: Type, x: &[f64]) -> fmi3Status {
    let n = x.len();
    unsafe {
        match ty {
            Type::Float64 => fmi3SetFloat64(f.inst, &r, 1, x.as_ptr(), n),
            Type::UInt64 => fmi3SetUInt64(f.inst, &r, 1, x.iter().map(|&v| v as u64).collect::<Vec<_>>().as_ptr(), n),
            Type::Int64 => fmi3SetInt64(f.inst, &r, 1, x.iter().map(|&v| v as i64).collect::<Vec<_>>().as_ptr(), n),
            Type::Boolean => fmi3SetBoolean(f.inst, &r, 1, x.iter().map(|&v| v != 0.0).collect::<Vec<_>>().as_ptr(), n),
        }
    }
}

/// Number of values of the variable with value reference `r` in `f`.
fn size(f: &Fmu, r: u32) -> usize {
    let (nx, ny, d, modes) = f.sizes();
    match r {
        vr::POSITIONS | vr::VELOCITIES => nx * ny * d,
        vr::MODAL_COORDINATES | vr::MODE_FREQUENCIES | vr::MODE_WEIGHTS | vr::MODE_OUT_OF_PLANE | vr::MODE_SYMMETRY => modes,
        vr::GRAVITY => 3,
        vr::MODE_SHAPES => modes * nx * ny * d,
        vr::SPRING_NEIGHBOURS => nx * ny * 6,
        vr::HOLDER_OF_NODE => nx * ny,
        _ => 1,
    }
}

#[test]
fn every_variable_in_every_state() {
    for v in VARIABLES {
        // Where the standard lets each kind of variable be set.
        let allowed = match (v.causality, v.variability) {
            (Causality::StructuralParameter, _) => "ICR",
            (Causality::Parameter, Variability::Fixed) => "INR",
            (Causality::Parameter, Variability::Tunable) => "INSR",
            // Inputs (FMI 3.0 Co-Simulation state machine): Instantiated, Initialization Mode, Step Mode
            // (Event and Intermediate Update Mode, which this FMU has not, aside).
            (Causality::Input, Variability::Continuous) => "INSR",
            (Causality::Independent | Causality::Output | Causality::CalculatedParameter, _) => NONE,
            other => panic!("{}: no rule for {other:?}", v.name),
        };
        let function = format!("fmi3Set{}", v.ty.name());
        for at in ALL_STATES {
            let f = at.instance();
            let x = current(&f, v.vr, v.ty, size(&f, v.vr));
            f.log.take();
            let before = f.snapshot();
            // Its own value: only the state decides.
            let status = set(&f, v.vr, v.ty, &x);
            let what = format!("{} = {x:?} in {at:?}", v.name);
            if allowed.contains(at.letter()) {
                assert_eq!(status, OK, "{what}: {:?}", f.messages());
                assert_eq!(f.snapshot(), before, "{what}: setting the same value changed the state");
            } else {
                assert_refused(&f, &before, status, &function, &what);
            }
        }
    }
}

#[test]
fn a_freed_instance_is_refused() {
    let f = Fmu::started();
    let stale = f.inst;
    drop(f);
    unsafe {
        assert_eq!(fmi3DoStep(stale, 0.0, 0.01, false, &mut false, &mut false, &mut false, &mut 0.0), ERROR);
        assert_eq!(fmi3Reset(stale), ERROR);
        assert_eq!(fmi3GetFloat64(stale, &vr::TIME, 1, &mut 0.0, 1), ERROR);
        let mut st = null_mut();
        assert_eq!(fmi3GetFMUState(stale, &mut st), ERROR);
        assert!(st.is_null());
        fmi3FreeInstance(stale); // a second free is ignored
    }
}
