//! The `fmi3*` C ABI: one short entry per function of the FMI 3.0 API.
//!
//! Each entry names its row of [`super::functions`]'s table and hands the
//! call to [`call`], which refuses a null, freed or foreign instance, checks
//! the state against the table (the one guard, [`Instance::guard`]), catches
//! any panic instead of unwinding into the importer, and runs the body on
//! the instance. Functions this FMU does not provide are refused with the
//! table's reason ([`refuse`]). Every signature is checked at compile time
//! against the `fmi3...TYPE` alias of the official headers (the `const _`
//! after it), and cbindgen writes the C header from this file.

#![allow(clippy::missing_safety_doc, clippy::too_many_arguments)]

use std::ffi::c_char;
use std::panic::{catch_unwind, AssertUnwindSafe};

use fmi_sys::fmi3::*;

use super::functions::Function as F;
use super::instance::Instance;
use super::variables::Type;
use super::{instantiate, registry, ERROR, FATAL};

fn panic_message(p: &Box<dyn std::any::Any + Send>) -> String {
    p.downcast_ref::<&str>().map(|s| s.to_string()).or_else(|| p.downcast_ref::<String>().cloned()).unwrap_or_else(|| "unknown panic".into())
}

/// Runs `body` on a live instance in a state where `f` is legal; a panic
/// poisons the instance and returns fmi3Fatal.
fn call(instance: fmi3Instance, f: F, body: impl FnOnce(&mut Instance) -> Result<fmi3Status, fmi3Status>) -> fmi3Status {
    let Some(inst) = (unsafe { registry::get(instance) }) else {
        // No instance, so no logger: the refusal goes to stderr.
        eprintln!("{}: {instance:p} is not a live instance of this FMU (NULL, freed, or not made by it); refused", f.name());
        return ERROR;
    };
    if inst.poisoned {
        return inst.log.fail(&format!("{}: the instance failed irrecoverably before; only fmi3FreeInstance is possible", f.name()));
    }
    match catch_unwind(AssertUnwindSafe(|| inst.guard(f).and_then(|()| body(inst)))) {
        Ok(Ok(s)) | Ok(Err(s)) => s,
        Err(p) => {
            let msg = panic_message(&p);
            // The borrow given to `body` ended with the unwind.
            if let Some(inst) = unsafe { registry::get(instance) } {
                inst.poisoned = true;
                inst.log.log(FATAL, &format!("{}: internal error: {msg}", f.name()));
            }
            FATAL
        }
    }
}

/// A function this FMU does not provide: refused with the table's reason.
fn refuse(instance: fmi3Instance, f: F) -> fmi3Status {
    call(instance, f, |_| unreachable!("{} is legal in no state", f.name()))
}

#[no_mangle]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    fmi3Version.as_ptr() as *const c_char
}
const _: fmi3GetVersionTYPE = Some(fmi3GetVersion);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetDebugLogging(
    instance: fmi3Instance,
    logging_on: fmi3Boolean,
    n_categories: usize,
    categories: *const fmi3String,
) -> fmi3Status {
    call(instance, F::SetDebugLogging, |inst| unsafe { inst.log.set(logging_on, n_categories, categories) })
}
const _: fmi3SetDebugLoggingTYPE = Some(fmi3SetDebugLogging);

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateModelExchange(
    _a: fmi3String,
    _b: fmi3String,
    _c: fmi3String,
    _d: fmi3Boolean,
    _e: fmi3Boolean,
    env: fmi3InstanceEnvironment,
    logger: fmi3LogMessageCallback,
) -> fmi3Instance {
    instantiate::refused(F::InstantiateModelExchange, env, logger)
}
const _: fmi3InstantiateModelExchangeTYPE = Some(fmi3InstantiateModelExchange);

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    name: fmi3String,
    token: fmi3String,
    resources: fmi3String,
    _a: fmi3Boolean,
    logging_on: fmi3Boolean,
    event_mode: fmi3Boolean,
    _b: fmi3Boolean,
    _c: *const fmi3ValueReference,
    n_required: usize,
    env: fmi3InstanceEnvironment,
    logger: fmi3LogMessageCallback,
    _d: fmi3IntermediateUpdateCallback,
) -> fmi3Instance {
    unsafe { instantiate::co_simulation(name, token, resources, logging_on, event_mode, n_required, env, logger) }
}
const _: fmi3InstantiateCoSimulationTYPE = Some(fmi3InstantiateCoSimulation);

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
    _a: fmi3String,
    _b: fmi3String,
    _c: fmi3String,
    _d: fmi3Boolean,
    _e: fmi3Boolean,
    env: fmi3InstanceEnvironment,
    logger: fmi3LogMessageCallback,
    _f: fmi3ClockUpdateCallback,
    _g: fmi3LockPreemptionCallback,
    _h: fmi3UnlockPreemptionCallback,
) -> fmi3Instance {
    instantiate::refused(F::InstantiateScheduledExecution, env, logger)
}
const _: fmi3InstantiateScheduledExecutionTYPE = Some(fmi3InstantiateScheduledExecution);

#[no_mangle]
pub unsafe extern "C" fn fmi3FreeInstance(instance: fmi3Instance) {
    let _ = catch_unwind(|| unsafe { registry::free(instance) });
}
const _: fmi3FreeInstanceTYPE = Some(fmi3FreeInstance);

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterInitializationMode(
    instance: fmi3Instance,
    _a: fmi3Boolean,
    _b: fmi3Float64,
    start: fmi3Float64,
    stop_defined: fmi3Boolean,
    stop: fmi3Float64,
) -> fmi3Status {
    call(instance, F::EnterInitializationMode, |inst| inst.enter_initialization_mode(start, stop_defined.then_some(stop)))
}
const _: fmi3EnterInitializationModeTYPE = Some(fmi3EnterInitializationMode);

#[no_mangle]
pub unsafe extern "C" fn fmi3ExitInitializationMode(instance: fmi3Instance) -> fmi3Status {
    call(instance, F::ExitInitializationMode, |inst| inst.exit_initialization_mode())
}
const _: fmi3ExitInitializationModeTYPE = Some(fmi3ExitInitializationMode);

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterEventMode(instance: fmi3Instance) -> fmi3Status {
    refuse(instance, F::EnterEventMode)
}
const _: fmi3EnterEventModeTYPE = Some(fmi3EnterEventMode);

#[no_mangle]
pub unsafe extern "C" fn fmi3Terminate(instance: fmi3Instance) -> fmi3Status {
    call(instance, F::Terminate, |inst| inst.terminate())
}
const _: fmi3TerminateTYPE = Some(fmi3Terminate);

#[no_mangle]
pub unsafe extern "C" fn fmi3Reset(instance: fmi3Instance) -> fmi3Status {
    call(instance, F::Reset, |inst| inst.reset())
}
const _: fmi3ResetTYPE = Some(fmi3Reset);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetFloat32(instance: fmi3Instance, vrs: *const fmi3ValueReference, n_vrs: usize, _a: *mut fmi3Float32, _b: usize) -> fmi3Status {
    call(instance, F::GetFloat32, |inst| unsafe { inst.no_variables(F::GetFloat32, "Float32", vrs, n_vrs) })
}
const _: fmi3GetFloat32TYPE = Some(fmi3GetFloat32);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetFloat32(instance: fmi3Instance, vrs: *const fmi3ValueReference, n_vrs: usize, _a: *const fmi3Float32, _b: usize) -> fmi3Status {
    call(instance, F::SetFloat32, |inst| unsafe { inst.no_variables(F::SetFloat32, "Float32", vrs, n_vrs) })
}
const _: fmi3SetFloat32TYPE = Some(fmi3SetFloat32);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetFloat64(
    instance: fmi3Instance,
    vrs: *const fmi3ValueReference,
    n_vrs: usize,
    values: *mut fmi3Float64,
    n_values: usize,
) -> fmi3Status {
    call(instance, F::GetFloat64, |inst| inst.get(F::GetFloat64, Type::Float64, vrs, n_vrs, values, n_values, |x| x))
}
const _: fmi3GetFloat64TYPE = Some(fmi3GetFloat64);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetFloat64(
    instance: fmi3Instance,
    vrs: *const fmi3ValueReference,
    n_vrs: usize,
    values: *const fmi3Float64,
    n_values: usize,
) -> fmi3Status {
    call(instance, F::SetFloat64, |inst| inst.set(F::SetFloat64, Type::Float64, vrs, n_vrs, values, n_values, Some))
}
const _: fmi3SetFloat64TYPE = Some(fmi3SetFloat64);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt8(instance: fmi3Instance, vrs: *const fmi3ValueReference, n_vrs: usize, _a: *mut fmi3Int8, _b: usize) -> fmi3Status {
    call(instance, F::GetInt8, |inst| unsafe { inst.no_variables(F::GetInt8, "Int8", vrs, n_vrs) })
}
const _: fmi3GetInt8TYPE = Some(fmi3GetInt8);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt8(instance: fmi3Instance, vrs: *const fmi3ValueReference, n_vrs: usize, _a: *const fmi3Int8, _b: usize) -> fmi3Status {
    call(instance, F::SetInt8, |inst| unsafe { inst.no_variables(F::SetInt8, "Int8", vrs, n_vrs) })
}
const _: fmi3SetInt8TYPE = Some(fmi3SetInt8);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetUInt8(instance: fmi3Instance, vrs: *const fmi3ValueReference, n_vrs: usize, _a: *mut fmi3UInt8, _b: usize) -> fmi3Status {
    call(instance, F::GetUInt8, |inst| unsafe { inst.no_variables(F::GetUInt8, "UInt8", vrs, n_vrs) })
}
const _: fmi3GetUInt8TYPE = Some(fmi3GetUInt8);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetUInt8(instance: fmi3Instance, vrs: *const fmi3ValueReference, n_vrs: usize, _a: *const fmi3UInt8, _b: usize) -> fmi3Status {
    call(instance, F::SetUInt8, |inst| unsafe { inst.no_variables(F::SetUInt8, "UInt8", vrs, n_vrs) })
}
const _: fmi3SetUInt8TYPE = Some(fmi3SetUInt8);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt16(instance: fmi3Instance, vrs: *const fmi3ValueReference, n_vrs: usize, _a: *mut fmi3Int16, _b: usize) -> fmi3Status {
    call(instance, F::GetInt16, |inst| unsafe { inst.no_variables(F::GetInt16, "Int16", vrs, n_vrs) })
}
const _: fmi3GetInt16TYPE = Some(fmi3GetInt16);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt16(instance: fmi3Instance, vrs: *const fmi3ValueReference, n_vrs: usize, _a: *const fmi3Int16, _b: usize) -> fmi3Status {
    call(instance, F::SetInt16, |inst| unsafe { inst.no_variables(F::SetInt16, "Int16", vrs, n_vrs) })
}
const _: fmi3SetInt16TYPE = Some(fmi3SetInt16);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetUInt16(instance: fmi3Instance, vrs: *const fmi3ValueReference, n_vrs: usize, _a: *mut fmi3UInt16, _b: usize) -> fmi3Status {
    call(instance, F::GetUInt16, |inst| unsafe { inst.no_variables(F::GetUInt16, "UInt16", vrs, n_vrs) })
}
const _: fmi3GetUInt16TYPE = Some(fmi3GetUInt16);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetUInt16(instance: fmi3Instance, vrs: *const fmi3ValueReference, n_vrs: usize, _a: *const fmi3UInt16, _b: usize) -> fmi3Status {
    call(instance, F::SetUInt16, |inst| unsafe { inst.no_variables(F::SetUInt16, "UInt16", vrs, n_vrs) })
}
const _: fmi3SetUInt16TYPE = Some(fmi3SetUInt16);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt32(instance: fmi3Instance, vrs: *const fmi3ValueReference, n_vrs: usize, _a: *mut fmi3Int32, _b: usize) -> fmi3Status {
    call(instance, F::GetInt32, |inst| unsafe { inst.no_variables(F::GetInt32, "Int32", vrs, n_vrs) })
}
const _: fmi3GetInt32TYPE = Some(fmi3GetInt32);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt32(instance: fmi3Instance, vrs: *const fmi3ValueReference, n_vrs: usize, _a: *const fmi3Int32, _b: usize) -> fmi3Status {
    call(instance, F::SetInt32, |inst| unsafe { inst.no_variables(F::SetInt32, "Int32", vrs, n_vrs) })
}
const _: fmi3SetInt32TYPE = Some(fmi3SetInt32);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetUInt32(instance: fmi3Instance, vrs: *const fmi3ValueReference, n_vrs: usize, _a: *mut fmi3UInt32, _b: usize) -> fmi3Status {
    call(instance, F::GetUInt32, |inst| unsafe { inst.no_variables(F::GetUInt32, "UInt32", vrs, n_vrs) })
}
const _: fmi3GetUInt32TYPE = Some(fmi3GetUInt32);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetUInt32(instance: fmi3Instance, vrs: *const fmi3ValueReference, n_vrs: usize, _a: *const fmi3UInt32, _b: usize) -> fmi3Status {
    call(instance, F::SetUInt32, |inst| unsafe { inst.no_variables(F::SetUInt32, "UInt32", vrs, n_vrs) })
}
const _: fmi3SetUInt32TYPE = Some(fmi3SetUInt32);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt64(
    instance: fmi3Instance,
    vrs: *const fmi3ValueReference,
    n_vrs: usize,
    values: *mut fmi3Int64,
    n_values: usize,
) -> fmi3Status {
    call(instance, F::GetInt64, |inst| inst.get(F::GetInt64, Type::Int64, vrs, n_vrs, values, n_values, |x| x as i64))
}
const _: fmi3GetInt64TYPE = Some(fmi3GetInt64);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt64(
    instance: fmi3Instance,
    vrs: *const fmi3ValueReference,
    n_vrs: usize,
    values: *const fmi3Int64,
    n_values: usize,
) -> fmi3Status {
    call(instance, F::SetInt64, |inst| {
        inst.set(F::SetInt64, Type::Int64, vrs, n_vrs, values, n_values, |x: i64| (x.unsigned_abs() <= 1 << 53).then_some(x as f64))
    })
}
const _: fmi3SetInt64TYPE = Some(fmi3SetInt64);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetUInt64(
    instance: fmi3Instance,
    vrs: *const fmi3ValueReference,
    n_vrs: usize,
    values: *mut fmi3UInt64,
    n_values: usize,
) -> fmi3Status {
    call(instance, F::GetUInt64, |inst| inst.get(F::GetUInt64, Type::UInt64, vrs, n_vrs, values, n_values, |x| x as u64))
}
const _: fmi3GetUInt64TYPE = Some(fmi3GetUInt64);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetUInt64(
    instance: fmi3Instance,
    vrs: *const fmi3ValueReference,
    n_vrs: usize,
    values: *const fmi3UInt64,
    n_values: usize,
) -> fmi3Status {
    call(instance, F::SetUInt64, |inst| inst.set(F::SetUInt64, Type::UInt64, vrs, n_vrs, values, n_values, |x: u64| (x <= 1 << 53).then_some(x as f64)))
}
const _: fmi3SetUInt64TYPE = Some(fmi3SetUInt64);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetBoolean(
    instance: fmi3Instance,
    vrs: *const fmi3ValueReference,
    n_vrs: usize,
    values: *mut fmi3Boolean,
    n_values: usize,
) -> fmi3Status {
    call(instance, F::GetBoolean, |inst| inst.get(F::GetBoolean, Type::Boolean, vrs, n_vrs, values, n_values, |x| x != 0.0))
}
const _: fmi3GetBooleanTYPE = Some(fmi3GetBoolean);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetBoolean(
    instance: fmi3Instance,
    vrs: *const fmi3ValueReference,
    n_vrs: usize,
    values: *const fmi3Boolean,
    n_values: usize,
) -> fmi3Status {
    // Read as bytes: a host may pass any non-zero value for true.
    let bytes = values as *const u8;
    call(instance, F::SetBoolean, |inst| inst.set(F::SetBoolean, Type::Boolean, vrs, n_vrs, bytes, n_values, |x: u8| Some(if x != 0 { 1.0 } else { 0.0 })))
}
const _: fmi3SetBooleanTYPE = Some(fmi3SetBoolean);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetString(instance: fmi3Instance, vrs: *const fmi3ValueReference, n_vrs: usize, _a: *mut fmi3String, _b: usize) -> fmi3Status {
    call(instance, F::GetString, |inst| unsafe { inst.no_variables(F::GetString, "String", vrs, n_vrs) })
}
const _: fmi3GetStringTYPE = Some(fmi3GetString);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetString(instance: fmi3Instance, vrs: *const fmi3ValueReference, n_vrs: usize, _a: *const fmi3String, _b: usize) -> fmi3Status {
    call(instance, F::SetString, |inst| unsafe { inst.no_variables(F::SetString, "String", vrs, n_vrs) })
}
const _: fmi3SetStringTYPE = Some(fmi3SetString);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetBinary(
    instance: fmi3Instance,
    vrs: *const fmi3ValueReference,
    n_vrs: usize,
    _a: *mut usize,
    _b: *mut fmi3Binary,
    _c: usize,
) -> fmi3Status {
    call(instance, F::GetBinary, |inst| unsafe { inst.no_variables(F::GetBinary, "Binary", vrs, n_vrs) })
}
const _: fmi3GetBinaryTYPE = Some(fmi3GetBinary);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetBinary(
    instance: fmi3Instance,
    vrs: *const fmi3ValueReference,
    n_vrs: usize,
    _a: *const usize,
    _b: *const fmi3Binary,
    _c: usize,
) -> fmi3Status {
    call(instance, F::SetBinary, |inst| unsafe { inst.no_variables(F::SetBinary, "Binary", vrs, n_vrs) })
}
const _: fmi3SetBinaryTYPE = Some(fmi3SetBinary);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetClock(instance: fmi3Instance, vrs: *const fmi3ValueReference, n_vrs: usize, _a: *mut fmi3Clock) -> fmi3Status {
    call(instance, F::GetClock, |inst| unsafe { inst.no_variables(F::GetClock, "Clock", vrs, n_vrs) })
}
const _: fmi3GetClockTYPE = Some(fmi3GetClock);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetClock(instance: fmi3Instance, vrs: *const fmi3ValueReference, n_vrs: usize, _a: *const fmi3Clock) -> fmi3Status {
    call(instance, F::SetClock, |inst| unsafe { inst.no_variables(F::SetClock, "Clock", vrs, n_vrs) })
}
const _: fmi3SetClockTYPE = Some(fmi3SetClock);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNumberOfVariableDependencies(instance: fmi3Instance, _a: fmi3ValueReference, _b: *mut usize) -> fmi3Status {
    refuse(instance, F::GetNumberOfVariableDependencies)
}
const _: fmi3GetNumberOfVariableDependenciesTYPE = Some(fmi3GetNumberOfVariableDependencies);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetVariableDependencies(
    instance: fmi3Instance,
    _a: fmi3ValueReference,
    _b: *mut usize,
    _c: *mut fmi3ValueReference,
    _d: *mut usize,
    _e: *mut fmi3DependencyKind,
    _f: usize,
) -> fmi3Status {
    refuse(instance, F::GetVariableDependencies)
}
const _: fmi3GetVariableDependenciesTYPE = Some(fmi3GetVariableDependencies);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetFMUState(instance: fmi3Instance, state: *mut fmi3FMUState) -> fmi3Status {
    call(instance, F::GetFMUState, |inst| unsafe { inst.store_state("fmi3GetFMUState", state, inst.capture()) })
}
const _: fmi3GetFMUStateTYPE = Some(fmi3GetFMUState);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetFMUState(instance: fmi3Instance, state: fmi3FMUState) -> fmi3Status {
    call(instance, F::SetFMUState, |inst| inst.restore(&inst.state_from_ptr("fmi3SetFMUState", state)?.clone()))
}
const _: fmi3SetFMUStateTYPE = Some(fmi3SetFMUState);

#[no_mangle]
pub unsafe extern "C" fn fmi3FreeFMUState(instance: fmi3Instance, state: *mut fmi3FMUState) -> fmi3Status {
    call(instance, F::FreeFMUState, |inst| unsafe { inst.free_state(state) })
}
const _: fmi3FreeFMUStateTYPE = Some(fmi3FreeFMUState);

#[no_mangle]
pub unsafe extern "C" fn fmi3SerializedFMUStateSize(instance: fmi3Instance, state: fmi3FMUState, size: *mut usize) -> fmi3Status {
    call(instance, F::SerializedFMUStateSize, |inst| unsafe { inst.serialized_size(state, size) })
}
const _: fmi3SerializedFMUStateSizeTYPE = Some(fmi3SerializedFMUStateSize);

#[no_mangle]
pub unsafe extern "C" fn fmi3SerializeFMUState(instance: fmi3Instance, state: fmi3FMUState, bytes: *mut fmi3Byte, size: usize) -> fmi3Status {
    call(instance, F::SerializeFMUState, |inst| unsafe { inst.serialize(state, bytes, size) })
}
const _: fmi3SerializeFMUStateTYPE = Some(fmi3SerializeFMUState);

#[no_mangle]
pub unsafe extern "C" fn fmi3DeserializeFMUState(instance: fmi3Instance, bytes: *const fmi3Byte, size: usize, state: *mut fmi3FMUState) -> fmi3Status {
    call(instance, F::DeserializeFMUState, |inst| unsafe { inst.deserialize(bytes, size, state) })
}
const _: fmi3DeserializeFMUStateTYPE = Some(fmi3DeserializeFMUState);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetDirectionalDerivative(
    instance: fmi3Instance,
    _a: *const fmi3ValueReference,
    _b: usize,
    _c: *const fmi3ValueReference,
    _d: usize,
    _e: *const fmi3Float64,
    _f: usize,
    _g: *mut fmi3Float64,
    _h: usize,
) -> fmi3Status {
    refuse(instance, F::GetDirectionalDerivative)
}
const _: fmi3GetDirectionalDerivativeTYPE = Some(fmi3GetDirectionalDerivative);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetAdjointDerivative(
    instance: fmi3Instance,
    _a: *const fmi3ValueReference,
    _b: usize,
    _c: *const fmi3ValueReference,
    _d: usize,
    _e: *const fmi3Float64,
    _f: usize,
    _g: *mut fmi3Float64,
    _h: usize,
) -> fmi3Status {
    refuse(instance, F::GetAdjointDerivative)
}
const _: fmi3GetAdjointDerivativeTYPE = Some(fmi3GetAdjointDerivative);

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterConfigurationMode(instance: fmi3Instance) -> fmi3Status {
    call(instance, F::EnterConfigurationMode, |inst| inst.enter_configuration_mode())
}
const _: fmi3EnterConfigurationModeTYPE = Some(fmi3EnterConfigurationMode);

#[no_mangle]
pub unsafe extern "C" fn fmi3ExitConfigurationMode(instance: fmi3Instance) -> fmi3Status {
    call(instance, F::ExitConfigurationMode, |inst| inst.exit_configuration_mode())
}
const _: fmi3ExitConfigurationModeTYPE = Some(fmi3ExitConfigurationMode);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetIntervalDecimal(
    instance: fmi3Instance,
    _a: *const fmi3ValueReference,
    _b: usize,
    _c: *mut fmi3Float64,
    _d: *mut fmi3IntervalQualifier,
) -> fmi3Status {
    refuse(instance, F::GetIntervalDecimal)
}
const _: fmi3GetIntervalDecimalTYPE = Some(fmi3GetIntervalDecimal);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetIntervalFraction(
    instance: fmi3Instance,
    _a: *const fmi3ValueReference,
    _b: usize,
    _c: *mut fmi3UInt64,
    _d: *mut fmi3UInt64,
    _e: *mut fmi3IntervalQualifier,
) -> fmi3Status {
    refuse(instance, F::GetIntervalFraction)
}
const _: fmi3GetIntervalFractionTYPE = Some(fmi3GetIntervalFraction);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetShiftDecimal(instance: fmi3Instance, _a: *const fmi3ValueReference, _b: usize, _c: *mut fmi3Float64) -> fmi3Status {
    refuse(instance, F::GetShiftDecimal)
}
const _: fmi3GetShiftDecimalTYPE = Some(fmi3GetShiftDecimal);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetShiftFraction(
    instance: fmi3Instance,
    _a: *const fmi3ValueReference,
    _b: usize,
    _c: *mut fmi3UInt64,
    _d: *mut fmi3UInt64,
) -> fmi3Status {
    refuse(instance, F::GetShiftFraction)
}
const _: fmi3GetShiftFractionTYPE = Some(fmi3GetShiftFraction);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetIntervalDecimal(instance: fmi3Instance, _a: *const fmi3ValueReference, _b: usize, _c: *const fmi3Float64) -> fmi3Status {
    refuse(instance, F::SetIntervalDecimal)
}
const _: fmi3SetIntervalDecimalTYPE = Some(fmi3SetIntervalDecimal);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetIntervalFraction(
    instance: fmi3Instance,
    _a: *const fmi3ValueReference,
    _b: usize,
    _c: *const fmi3UInt64,
    _d: *const fmi3UInt64,
) -> fmi3Status {
    refuse(instance, F::SetIntervalFraction)
}
const _: fmi3SetIntervalFractionTYPE = Some(fmi3SetIntervalFraction);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetShiftDecimal(instance: fmi3Instance, _a: *const fmi3ValueReference, _b: usize, _c: *const fmi3Float64) -> fmi3Status {
    refuse(instance, F::SetShiftDecimal)
}
const _: fmi3SetShiftDecimalTYPE = Some(fmi3SetShiftDecimal);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetShiftFraction(
    instance: fmi3Instance,
    _a: *const fmi3ValueReference,
    _b: usize,
    _c: *const fmi3UInt64,
    _d: *const fmi3UInt64,
) -> fmi3Status {
    refuse(instance, F::SetShiftFraction)
}
const _: fmi3SetShiftFractionTYPE = Some(fmi3SetShiftFraction);

#[no_mangle]
pub unsafe extern "C" fn fmi3EvaluateDiscreteStates(instance: fmi3Instance) -> fmi3Status {
    refuse(instance, F::EvaluateDiscreteStates)
}
const _: fmi3EvaluateDiscreteStatesTYPE = Some(fmi3EvaluateDiscreteStates);

#[no_mangle]
pub unsafe extern "C" fn fmi3UpdateDiscreteStates(
    instance: fmi3Instance,
    _a: *mut fmi3Boolean,
    _b: *mut fmi3Boolean,
    _c: *mut fmi3Boolean,
    _d: *mut fmi3Boolean,
    _e: *mut fmi3Boolean,
    _f: *mut fmi3Float64,
) -> fmi3Status {
    refuse(instance, F::UpdateDiscreteStates)
}
const _: fmi3UpdateDiscreteStatesTYPE = Some(fmi3UpdateDiscreteStates);

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterContinuousTimeMode(instance: fmi3Instance) -> fmi3Status {
    refuse(instance, F::EnterContinuousTimeMode)
}
const _: fmi3EnterContinuousTimeModeTYPE = Some(fmi3EnterContinuousTimeMode);

#[no_mangle]
pub unsafe extern "C" fn fmi3CompletedIntegratorStep(instance: fmi3Instance, _a: fmi3Boolean, _b: *mut fmi3Boolean, _c: *mut fmi3Boolean) -> fmi3Status {
    refuse(instance, F::CompletedIntegratorStep)
}
const _: fmi3CompletedIntegratorStepTYPE = Some(fmi3CompletedIntegratorStep);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetTime(instance: fmi3Instance, _a: fmi3Float64) -> fmi3Status {
    refuse(instance, F::SetTime)
}
const _: fmi3SetTimeTYPE = Some(fmi3SetTime);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetContinuousStates(instance: fmi3Instance, _a: *const fmi3Float64, _b: usize) -> fmi3Status {
    refuse(instance, F::SetContinuousStates)
}
const _: fmi3SetContinuousStatesTYPE = Some(fmi3SetContinuousStates);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetContinuousStateDerivatives(instance: fmi3Instance, _a: *mut fmi3Float64, _b: usize) -> fmi3Status {
    refuse(instance, F::GetContinuousStateDerivatives)
}
const _: fmi3GetContinuousStateDerivativesTYPE = Some(fmi3GetContinuousStateDerivatives);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetEventIndicators(instance: fmi3Instance, _a: *mut fmi3Float64, _b: usize) -> fmi3Status {
    refuse(instance, F::GetEventIndicators)
}
const _: fmi3GetEventIndicatorsTYPE = Some(fmi3GetEventIndicators);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetContinuousStates(instance: fmi3Instance, _a: *mut fmi3Float64, _b: usize) -> fmi3Status {
    refuse(instance, F::GetContinuousStates)
}
const _: fmi3GetContinuousStatesTYPE = Some(fmi3GetContinuousStates);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNominalsOfContinuousStates(instance: fmi3Instance, _a: *mut fmi3Float64, _b: usize) -> fmi3Status {
    refuse(instance, F::GetNominalsOfContinuousStates)
}
const _: fmi3GetNominalsOfContinuousStatesTYPE = Some(fmi3GetNominalsOfContinuousStates);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNumberOfEventIndicators(instance: fmi3Instance, _a: *mut usize) -> fmi3Status {
    refuse(instance, F::GetNumberOfEventIndicators)
}
const _: fmi3GetNumberOfEventIndicatorsTYPE = Some(fmi3GetNumberOfEventIndicators);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNumberOfContinuousStates(instance: fmi3Instance, _a: *mut usize) -> fmi3Status {
    refuse(instance, F::GetNumberOfContinuousStates)
}
const _: fmi3GetNumberOfContinuousStatesTYPE = Some(fmi3GetNumberOfContinuousStates);

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterStepMode(instance: fmi3Instance) -> fmi3Status {
    refuse(instance, F::EnterStepMode)
}
const _: fmi3EnterStepModeTYPE = Some(fmi3EnterStepMode);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetOutputDerivatives(
    instance: fmi3Instance,
    _a: *const fmi3ValueReference,
    _b: usize,
    _c: *const fmi3Int32,
    _d: *mut fmi3Float64,
    _e: usize,
) -> fmi3Status {
    refuse(instance, F::GetOutputDerivatives)
}
const _: fmi3GetOutputDerivativesTYPE = Some(fmi3GetOutputDerivatives);

#[no_mangle]
pub unsafe extern "C" fn fmi3DoStep(
    instance: fmi3Instance,
    t: fmi3Float64,
    h: fmi3Float64,
    _a: fmi3Boolean,
    event: *mut fmi3Boolean,
    terminate: *mut fmi3Boolean,
    early: *mut fmi3Boolean,
    last: *mut fmi3Float64,
) -> fmi3Status {
    call(instance, F::DoStep, |inst| unsafe { inst.do_step(t, h, event, terminate, early, last) })
}
const _: fmi3DoStepTYPE = Some(fmi3DoStep);

#[no_mangle]
pub unsafe extern "C" fn fmi3ActivateModelPartition(instance: fmi3Instance, _a: fmi3ValueReference, _b: fmi3Float64) -> fmi3Status {
    refuse(instance, F::ActivateModelPartition)
}
const _: fmi3ActivateModelPartitionTYPE = Some(fmi3ActivateModelPartition);
