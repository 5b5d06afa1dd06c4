//! The `fmi3*` C ABI. One guard per function: a null or foreign instance is
//! refused, the FMI state is checked, and a panic is caught and reported
//! instead of unwinding into the importer. Every signature is checked at
//! compile time against the `fmi3...TYPE` aliases of the official headers.

#![allow(non_snake_case, clippy::missing_safety_doc, clippy::too_many_arguments)]

use std::ffi::{c_char, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};

use fmi_sys::fmi3::*;

use super::instance::{log_raw, mask, slice, too_many, Instance, ERROR, FATAL, OK};
use super::model::Params;
use super::serialize;
use super::variables::{index_of, Type, INSTANTIATION_TOKEN, VARIABLES};

fn panic_message(p: &Box<dyn std::any::Any + Send>) -> String {
    p.downcast_ref::<&str>().map(|s| s.to_string()).or_else(|| p.downcast_ref::<String>().cloned()).unwrap_or_else(|| "unknown panic".into())
}

/// Runs `body` on a valid instance; a panic poisons the instance and returns fmi3Fatal.
fn call(instance: fmi3Instance, f: &str, body: impl FnOnce(&mut Instance) -> Result<fmi3Status, fmi3Status>) -> fmi3Status {
    let Some(inst) = (unsafe { Instance::from_ptr(instance) }) else {
        return ERROR;
    };
    if inst.poisoned {
        return inst.fail(&format!("{f}: the instance failed irrecoverably before; only fmi3FreeInstance is possible"));
    }
    match catch_unwind(AssertUnwindSafe(|| body(inst))) {
        Ok(Ok(s)) | Ok(Err(s)) => s,
        Err(p) => {
            let msg = panic_message(&p);
            // The borrow given to `body` ended with the unwind.
            if let Some(inst) = unsafe { Instance::from_ptr(instance) } {
                inst.poisoned = true;
                inst.log(FATAL, &format!("{f}: internal error: {msg}"));
            }
            FATAL
        }
    }
}

fn unsupported(instance: fmi3Instance, f: &str, reason: &str) -> fmi3Status {
    call(instance, f, |inst| Err(inst.fail(&format!("{f}: {reason}"))))
}

const NO_ME: &str = "this FMU supports Co-Simulation only, not Model Exchange";
const NO_SE: &str = "this FMU supports Co-Simulation only, not Scheduled Execution";
const NO_CLOCKS: &str = "this FMU has no clocks";
const NO_EVENTS: &str = "this FMU has no Event Mode (hasEventMode = false)";

/// Get/Set of a type no variable of this FMU has: only an empty request succeeds.
fn no_variables(inst: &mut Instance, f: &str, type_name: &str, vrs: *const fmi3ValueReference, n: usize, mask: u32) -> Result<fmi3Status, fmi3Status> {
    inst.guard(f, mask)?;
    if n > 0 && vrs.is_null() {
        return Err(inst.fail(&format!("{f}: valueReferences is NULL")));
    }
    if too_many::<fmi3ValueReference>(n) {
        return Err(inst.fail(&format!("{f}: nValueReferences = {n} cannot be an array size")));
    }
    if let Some(&r) = unsafe { slice(vrs, n) }.first() {
        return Err(match index_of(r) {
            Some(i) => inst.fail(&format!("{f}: {} (value reference {r}) is a {}, not a {type_name}", VARIABLES[i].name, VARIABLES[i].ty.name())),
            None => inst.fail(&format!("{f}: unknown value reference {r}")),
        });
    }
    Ok(OK)
}

// ---- Common functions --------------------------------------------------------

#[no_mangle]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    fmi3Version.as_ptr() as *const c_char
}
const _: fmi3GetVersionTYPE = Some(fmi3GetVersion);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetDebugLogging(instance: fmi3Instance, loggingOn: fmi3Boolean, nCategories: usize, categories: *const fmi3String) -> fmi3Status {
    call(instance, "fmi3SetDebugLogging", |inst| inst.set_debug_logging(loggingOn, nCategories, categories))
}
const _: fmi3SetDebugLoggingTYPE = Some(fmi3SetDebugLogging);

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateModelExchange(
    _instanceName: fmi3String,
    _instantiationToken: fmi3String,
    _resourcePath: fmi3String,
    _visible: fmi3Boolean,
    _loggingOn: fmi3Boolean,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
) -> fmi3Instance {
    log_raw(instanceEnvironment, logMessage, ERROR, "logStatusError", &format!("fmi3InstantiateModelExchange: {NO_ME}"));
    std::ptr::null_mut()
}
const _: fmi3InstantiateModelExchangeTYPE = Some(fmi3InstantiateModelExchange);

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    instanceName: fmi3String,
    instantiationToken: fmi3String,
    resourcePath: fmi3String,
    _visible: fmi3Boolean,
    loggingOn: fmi3Boolean,
    eventModeUsed: fmi3Boolean,
    _earlyReturnAllowed: fmi3Boolean,
    _requiredIntermediateVariables: *const fmi3ValueReference,
    nRequiredIntermediateVariables: usize,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
    _intermediateUpdate: fmi3IntermediateUpdateCallback,
) -> fmi3Instance {
    let result = catch_unwind(|| {
        let fail = |m: String| {
            log_raw(instanceEnvironment, logMessage, ERROR, "logStatusError", &format!("fmi3InstantiateCoSimulation: {m}"));
            std::ptr::null_mut()
        };
        if instantiationToken.is_null() {
            return fail("instantiationToken is NULL".into());
        }
        let token = unsafe { CStr::from_ptr(instantiationToken) }.to_string_lossy();
        if token != INSTANTIATION_TOKEN {
            return fail(format!("instantiationToken {token} does not match this binary ({INSTANTIATION_TOKEN})"));
        }
        if eventModeUsed {
            return fail(NO_EVENTS.into());
        }
        if nRequiredIntermediateVariables > 0 {
            return fail("this FMU provides no intermediate update (providesIntermediateUpdate = false)".into());
        }
        // The standard requires a non-empty name; messages are labelled with it.
        if instanceName.is_null() {
            return fail("instanceName is NULL".into());
        }
        let name = unsafe { CStr::from_ptr(instanceName) }.to_string_lossy().into_owned();
        if name.trim().is_empty() {
            return fail("instanceName is empty".into());
        }
        let start = if resourcePath.is_null() {
            Params::start()
        } else {
            let dir = unsafe { CStr::from_ptr(resourcePath) }.to_string_lossy().into_owned();
            let dir = dir.strip_prefix("file://").unwrap_or(&dir).to_string();
            let file = std::path::Path::new(&dir).join("startValues.txt");
            match std::fs::read_to_string(&file) {
                Ok(text) => match Params::from_text(&text) {
                    Ok(p) => p,
                    Err(m) => return fail(format!("{}: {m}", file.display())),
                },
                // No file: the compiled start values are those of modelDescription.xml.
                Err(_) => Params::start(),
            }
        };
        let inst = Instance::new(instanceEnvironment, logMessage, loggingOn, start);
        inst.log(OK, &format!("instance \"{name}\" created"));
        inst.into_raw()
    });
    result.unwrap_or_else(|p| {
        log_raw(instanceEnvironment, logMessage, FATAL, "logStatusFatal", &format!("fmi3InstantiateCoSimulation: internal error: {}", panic_message(&p)));
        std::ptr::null_mut()
    })
}
const _: fmi3InstantiateCoSimulationTYPE = Some(fmi3InstantiateCoSimulation);

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
    _instanceName: fmi3String,
    _instantiationToken: fmi3String,
    _resourcePath: fmi3String,
    _visible: fmi3Boolean,
    _loggingOn: fmi3Boolean,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
    _clockUpdate: fmi3ClockUpdateCallback,
    _lockPreemption: fmi3LockPreemptionCallback,
    _unlockPreemption: fmi3UnlockPreemptionCallback,
) -> fmi3Instance {
    log_raw(instanceEnvironment, logMessage, ERROR, "logStatusError", &format!("fmi3InstantiateScheduledExecution: {NO_SE}"));
    std::ptr::null_mut()
}
const _: fmi3InstantiateScheduledExecutionTYPE = Some(fmi3InstantiateScheduledExecution);

#[no_mangle]
pub unsafe extern "C" fn fmi3FreeInstance(instance: fmi3Instance) {
    let _ = catch_unwind(|| unsafe { Instance::free(instance) });
}
const _: fmi3FreeInstanceTYPE = Some(fmi3FreeInstance);

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterInitializationMode(
    instance: fmi3Instance,
    _toleranceDefined: fmi3Boolean,
    _tolerance: fmi3Float64,
    startTime: fmi3Float64,
    stopTimeDefined: fmi3Boolean,
    stopTime: fmi3Float64,
) -> fmi3Status {
    call(instance, "fmi3EnterInitializationMode", |inst| inst.enter_initialization_mode(startTime, stopTimeDefined.then_some(stopTime)))
}
const _: fmi3EnterInitializationModeTYPE = Some(fmi3EnterInitializationMode);

#[no_mangle]
pub unsafe extern "C" fn fmi3ExitInitializationMode(instance: fmi3Instance) -> fmi3Status {
    call(instance, "fmi3ExitInitializationMode", |inst| inst.exit_initialization_mode())
}
const _: fmi3ExitInitializationModeTYPE = Some(fmi3ExitInitializationMode);

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterEventMode(instance: fmi3Instance) -> fmi3Status {
    unsupported(instance, "fmi3EnterEventMode", NO_EVENTS)
}
const _: fmi3EnterEventModeTYPE = Some(fmi3EnterEventMode);

#[no_mangle]
pub unsafe extern "C" fn fmi3Terminate(instance: fmi3Instance) -> fmi3Status {
    call(instance, "fmi3Terminate", |inst| inst.terminate())
}
const _: fmi3TerminateTYPE = Some(fmi3Terminate);

#[no_mangle]
pub unsafe extern "C" fn fmi3Reset(instance: fmi3Instance) -> fmi3Status {
    call(instance, "fmi3Reset", |inst| inst.reset())
}
const _: fmi3ResetTYPE = Some(fmi3Reset);

// ---- Getting and setting variable values ------------------------------------
#[no_mangle]
pub unsafe extern "C" fn fmi3GetFloat32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Float32,
    nValues: usize,
) -> fmi3Status {
    let _ = (values, nValues);
    call(instance, "fmi3GetFloat32", |inst| no_variables(inst, "fmi3GetFloat32", "Float32", valueReferences, nValueReferences, mask::GET))
}
const _: fmi3GetFloat32TYPE = Some(fmi3GetFloat32);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetFloat32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Float32,
    nValues: usize,
) -> fmi3Status {
    let _ = (values, nValues);
    call(instance, "fmi3SetFloat32", |inst| no_variables(inst, "fmi3SetFloat32", "Float32", valueReferences, nValueReferences, mask::SET))
}
const _: fmi3SetFloat32TYPE = Some(fmi3SetFloat32);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetFloat64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Float64,
    nValues: usize,
) -> fmi3Status {
    call(instance, "fmi3GetFloat64", |inst| inst.get("fmi3GetFloat64", Type::Float64, valueReferences, nValueReferences, values, nValues, |x| x))
}
const _: fmi3GetFloat64TYPE = Some(fmi3GetFloat64);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetFloat64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Float64,
    nValues: usize,
) -> fmi3Status {
    call(instance, "fmi3SetFloat64", |inst| inst.set("fmi3SetFloat64", Type::Float64, valueReferences, nValueReferences, values, nValues, |x: f64| Some(x)))
}
const _: fmi3SetFloat64TYPE = Some(fmi3SetFloat64);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt8(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Int8,
    nValues: usize,
) -> fmi3Status {
    let _ = (values, nValues);
    call(instance, "fmi3GetInt8", |inst| no_variables(inst, "fmi3GetInt8", "Int8", valueReferences, nValueReferences, mask::GET))
}
const _: fmi3GetInt8TYPE = Some(fmi3GetInt8);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt8(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Int8,
    nValues: usize,
) -> fmi3Status {
    let _ = (values, nValues);
    call(instance, "fmi3SetInt8", |inst| no_variables(inst, "fmi3SetInt8", "Int8", valueReferences, nValueReferences, mask::SET))
}
const _: fmi3SetInt8TYPE = Some(fmi3SetInt8);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetUInt8(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3UInt8,
    nValues: usize,
) -> fmi3Status {
    let _ = (values, nValues);
    call(instance, "fmi3GetUInt8", |inst| no_variables(inst, "fmi3GetUInt8", "UInt8", valueReferences, nValueReferences, mask::GET))
}
const _: fmi3GetUInt8TYPE = Some(fmi3GetUInt8);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetUInt8(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3UInt8,
    nValues: usize,
) -> fmi3Status {
    let _ = (values, nValues);
    call(instance, "fmi3SetUInt8", |inst| no_variables(inst, "fmi3SetUInt8", "UInt8", valueReferences, nValueReferences, mask::SET))
}
const _: fmi3SetUInt8TYPE = Some(fmi3SetUInt8);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt16(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Int16,
    nValues: usize,
) -> fmi3Status {
    let _ = (values, nValues);
    call(instance, "fmi3GetInt16", |inst| no_variables(inst, "fmi3GetInt16", "Int16", valueReferences, nValueReferences, mask::GET))
}
const _: fmi3GetInt16TYPE = Some(fmi3GetInt16);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt16(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Int16,
    nValues: usize,
) -> fmi3Status {
    let _ = (values, nValues);
    call(instance, "fmi3SetInt16", |inst| no_variables(inst, "fmi3SetInt16", "Int16", valueReferences, nValueReferences, mask::SET))
}
const _: fmi3SetInt16TYPE = Some(fmi3SetInt16);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetUInt16(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3UInt16,
    nValues: usize,
) -> fmi3Status {
    let _ = (values, nValues);
    call(instance, "fmi3GetUInt16", |inst| no_variables(inst, "fmi3GetUInt16", "UInt16", valueReferences, nValueReferences, mask::GET))
}
const _: fmi3GetUInt16TYPE = Some(fmi3GetUInt16);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetUInt16(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3UInt16,
    nValues: usize,
) -> fmi3Status {
    let _ = (values, nValues);
    call(instance, "fmi3SetUInt16", |inst| no_variables(inst, "fmi3SetUInt16", "UInt16", valueReferences, nValueReferences, mask::SET))
}
const _: fmi3SetUInt16TYPE = Some(fmi3SetUInt16);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Int32,
    nValues: usize,
) -> fmi3Status {
    let _ = (values, nValues);
    call(instance, "fmi3GetInt32", |inst| no_variables(inst, "fmi3GetInt32", "Int32", valueReferences, nValueReferences, mask::GET))
}
const _: fmi3GetInt32TYPE = Some(fmi3GetInt32);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Int32,
    nValues: usize,
) -> fmi3Status {
    let _ = (values, nValues);
    call(instance, "fmi3SetInt32", |inst| no_variables(inst, "fmi3SetInt32", "Int32", valueReferences, nValueReferences, mask::SET))
}
const _: fmi3SetInt32TYPE = Some(fmi3SetInt32);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetUInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3UInt32,
    nValues: usize,
) -> fmi3Status {
    let _ = (values, nValues);
    call(instance, "fmi3GetUInt32", |inst| no_variables(inst, "fmi3GetUInt32", "UInt32", valueReferences, nValueReferences, mask::GET))
}
const _: fmi3GetUInt32TYPE = Some(fmi3GetUInt32);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetUInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3UInt32,
    nValues: usize,
) -> fmi3Status {
    let _ = (values, nValues);
    call(instance, "fmi3SetUInt32", |inst| no_variables(inst, "fmi3SetUInt32", "UInt32", valueReferences, nValueReferences, mask::SET))
}
const _: fmi3SetUInt32TYPE = Some(fmi3SetUInt32);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Int64,
    nValues: usize,
) -> fmi3Status {
    call(instance, "fmi3GetInt64", |inst| inst.get("fmi3GetInt64", Type::Int64, valueReferences, nValueReferences, values, nValues, |x| x as i64))
}
const _: fmi3GetInt64TYPE = Some(fmi3GetInt64);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Int64,
    nValues: usize,
) -> fmi3Status {
    call(instance, "fmi3SetInt64", |inst| {
        inst.set("fmi3SetInt64", Type::Int64, valueReferences, nValueReferences, values, nValues, |x: i64| (x.unsigned_abs() <= 1 << 53).then_some(x as f64))
    })
}
const _: fmi3SetInt64TYPE = Some(fmi3SetInt64);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetUInt64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3UInt64,
    nValues: usize,
) -> fmi3Status {
    call(instance, "fmi3GetUInt64", |inst| inst.get("fmi3GetUInt64", Type::UInt64, valueReferences, nValueReferences, values, nValues, |x| x as u64))
}
const _: fmi3GetUInt64TYPE = Some(fmi3GetUInt64);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetUInt64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3UInt64,
    nValues: usize,
) -> fmi3Status {
    call(instance, "fmi3SetUInt64", |inst| {
        inst.set("fmi3SetUInt64", Type::UInt64, valueReferences, nValueReferences, values, nValues, |x: u64| (x <= 1 << 53).then_some(x as f64))
    })
}
const _: fmi3SetUInt64TYPE = Some(fmi3SetUInt64);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetBoolean(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Boolean,
    nValues: usize,
) -> fmi3Status {
    call(instance, "fmi3GetBoolean", |inst| inst.get("fmi3GetBoolean", Type::Boolean, valueReferences, nValueReferences, values, nValues, |x| x != 0.0))
}
const _: fmi3GetBooleanTYPE = Some(fmi3GetBoolean);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetBoolean(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Boolean,
    nValues: usize,
) -> fmi3Status {
    // Read as bytes: a host may pass any non-zero value for true.
    let bytes = values as *const u8;
    call(instance, "fmi3SetBoolean", |inst| {
        inst.set("fmi3SetBoolean", Type::Boolean, valueReferences, nValueReferences, bytes, nValues, |x: u8| Some(if x != 0 { 1.0 } else { 0.0 }))
    })
}
const _: fmi3SetBooleanTYPE = Some(fmi3SetBoolean);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetString(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3String,
    nValues: usize,
) -> fmi3Status {
    let _ = (values, nValues);
    call(instance, "fmi3GetString", |inst| no_variables(inst, "fmi3GetString", "String", valueReferences, nValueReferences, mask::GET))
}
const _: fmi3GetStringTYPE = Some(fmi3GetString);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetString(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3String,
    nValues: usize,
) -> fmi3Status {
    let _ = (values, nValues);
    call(instance, "fmi3SetString", |inst| no_variables(inst, "fmi3SetString", "String", valueReferences, nValueReferences, mask::SET))
}
const _: fmi3SetStringTYPE = Some(fmi3SetString);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetBinary(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    valueSizes: *mut usize,
    values: *mut fmi3Binary,
    nValues: usize,
) -> fmi3Status {
    let _ = (valueSizes, values, nValues);
    call(instance, "fmi3GetBinary", |inst| no_variables(inst, "fmi3GetBinary", "Binary", valueReferences, nValueReferences, mask::GET))
}
const _: fmi3GetBinaryTYPE = Some(fmi3GetBinary);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetBinary(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    valueSizes: *const usize,
    values: *const fmi3Binary,
    nValues: usize,
) -> fmi3Status {
    let _ = (valueSizes, values, nValues);
    call(instance, "fmi3SetBinary", |inst| no_variables(inst, "fmi3SetBinary", "Binary", valueReferences, nValueReferences, mask::SET))
}
const _: fmi3SetBinaryTYPE = Some(fmi3SetBinary);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetClock(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Clock,
) -> fmi3Status {
    let _ = values;
    call(instance, "fmi3GetClock", |inst| no_variables(inst, "fmi3GetClock", "Clock", valueReferences, nValueReferences, mask::GET))
}
const _: fmi3GetClockTYPE = Some(fmi3GetClock);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetClock(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Clock,
) -> fmi3Status {
    let _ = values;
    call(instance, "fmi3SetClock", |inst| no_variables(inst, "fmi3SetClock", "Clock", valueReferences, nValueReferences, mask::SET))
}
const _: fmi3SetClockTYPE = Some(fmi3SetClock);

// ---- Variable dependencies ----------------------------------------------------

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNumberOfVariableDependencies(
    instance: fmi3Instance,
    _valueReference: fmi3ValueReference,
    _nDependencies: *mut usize,
) -> fmi3Status {
    unsupported(instance, "fmi3GetNumberOfVariableDependencies", "variable dependencies are not provided (every output depends on every parameter)")
}
const _: fmi3GetNumberOfVariableDependenciesTYPE = Some(fmi3GetNumberOfVariableDependencies);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetVariableDependencies(
    instance: fmi3Instance,
    _dependent: fmi3ValueReference,
    _elementIndicesOfDependent: *mut usize,
    _independents: *mut fmi3ValueReference,
    _elementIndicesOfIndependents: *mut usize,
    _dependencyKinds: *mut fmi3DependencyKind,
    _nDependencies: usize,
) -> fmi3Status {
    unsupported(instance, "fmi3GetVariableDependencies", "variable dependencies are not provided (every output depends on every parameter)")
}
const _: fmi3GetVariableDependenciesTYPE = Some(fmi3GetVariableDependencies);

// ---- FMU state ---------------------------------------------------------------

#[no_mangle]
pub unsafe extern "C" fn fmi3GetFMUState(instance: fmi3Instance, FMUState: *mut fmi3FMUState) -> fmi3Status {
    call(instance, "fmi3GetFMUState", |inst| {
        inst.guard("fmi3GetFMUState", mask::ANY)?;
        let s = inst.capture();
        unsafe { inst.store_state("fmi3GetFMUState", FMUState, s) }
    })
}
const _: fmi3GetFMUStateTYPE = Some(fmi3GetFMUState);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetFMUState(instance: fmi3Instance, FMUState: fmi3FMUState) -> fmi3Status {
    call(instance, "fmi3SetFMUState", |inst| {
        inst.guard("fmi3SetFMUState", mask::ANY)?;
        let s = inst.state_from_ptr("fmi3SetFMUState", FMUState)?.clone();
        inst.restore(&s)
    })
}
const _: fmi3SetFMUStateTYPE = Some(fmi3SetFMUState);

#[no_mangle]
pub unsafe extern "C" fn fmi3FreeFMUState(instance: fmi3Instance, FMUState: *mut fmi3FMUState) -> fmi3Status {
    call(instance, "fmi3FreeFMUState", |inst| unsafe { inst.free_state(FMUState) })
}
const _: fmi3FreeFMUStateTYPE = Some(fmi3FreeFMUState);

#[no_mangle]
pub unsafe extern "C" fn fmi3SerializedFMUStateSize(instance: fmi3Instance, FMUState: fmi3FMUState, size: *mut usize) -> fmi3Status {
    call(instance, "fmi3SerializedFMUStateSize", |inst| {
        if size.is_null() {
            return Err(inst.fail("fmi3SerializedFMUStateSize: size is NULL"));
        }
        let s = inst.state_from_ptr("fmi3SerializedFMUStateSize", FMUState)?;
        unsafe { *size = serialize::encode(s).len() };
        Ok(OK)
    })
}
const _: fmi3SerializedFMUStateSizeTYPE = Some(fmi3SerializedFMUStateSize);

#[no_mangle]
pub unsafe extern "C" fn fmi3SerializeFMUState(instance: fmi3Instance, FMUState: fmi3FMUState, serializedState: *mut fmi3Byte, size: usize) -> fmi3Status {
    call(instance, "fmi3SerializeFMUState", |inst| {
        let s = inst.state_from_ptr("fmi3SerializeFMUState", FMUState)?;
        let bytes = serialize::encode(s);
        if serializedState.is_null() {
            return Err(inst.fail("fmi3SerializeFMUState: serializedState is NULL"));
        }
        if size != bytes.len() {
            return Err(inst.fail(&format!("fmi3SerializeFMUState: size is {size}, fmi3SerializedFMUStateSize gave {}", bytes.len())));
        }
        unsafe { std::ptr::copy_nonoverlapping(bytes.as_ptr(), serializedState, size) };
        Ok(OK)
    })
}
const _: fmi3SerializeFMUStateTYPE = Some(fmi3SerializeFMUState);

#[no_mangle]
pub unsafe extern "C" fn fmi3DeserializeFMUState(
    instance: fmi3Instance,
    serializedState: *const fmi3Byte,
    size: usize,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    call(instance, "fmi3DeserializeFMUState", |inst| {
        if serializedState.is_null() || FMUState.is_null() {
            return Err(inst.fail("fmi3DeserializeFMUState: serializedState or FMUState is NULL"));
        }
        if too_many::<fmi3Byte>(size) {
            return Err(inst.fail(&format!("fmi3DeserializeFMUState: size = {size} cannot be an array size")));
        }
        let bytes = unsafe { slice(serializedState, size) };
        let s = serialize::decode(bytes).map_err(|m| inst.fail(&format!("fmi3DeserializeFMUState: {m}")))?;
        let mine = inst.structural();
        let theirs: Vec<_> = mine.iter().map(|(n, _)| (*n, s.params.get(super::variables::VARIABLES.iter().find(|v| v.name == *n).unwrap().vr)[0])).collect();
        if mine != theirs {
            return Err(
                inst.fail(&format!("fmi3DeserializeFMUState: the state is from an instance with structural parameters {theirs:?}, this one has {mine:?}"))
            );
        }
        unsafe { inst.store_state("fmi3DeserializeFMUState", FMUState, s) }
    })
}
const _: fmi3DeserializeFMUStateTYPE = Some(fmi3DeserializeFMUState);

// ---- Partial derivatives -----------------------------------------------------

#[no_mangle]
pub unsafe extern "C" fn fmi3GetDirectionalDerivative(
    instance: fmi3Instance,
    _unknowns: *const fmi3ValueReference,
    _nUnknowns: usize,
    _knowns: *const fmi3ValueReference,
    _nKnowns: usize,
    _seed: *const fmi3Float64,
    _nSeed: usize,
    _sensitivity: *mut fmi3Float64,
    _nSensitivity: usize,
) -> fmi3Status {
    unsupported(instance, "fmi3GetDirectionalDerivative", "directional derivatives are not provided (providesDirectionalDerivatives = false)")
}
const _: fmi3GetDirectionalDerivativeTYPE = Some(fmi3GetDirectionalDerivative);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetAdjointDerivative(
    instance: fmi3Instance,
    _unknowns: *const fmi3ValueReference,
    _nUnknowns: usize,
    _knowns: *const fmi3ValueReference,
    _nKnowns: usize,
    _seed: *const fmi3Float64,
    _nSeed: usize,
    _sensitivity: *mut fmi3Float64,
    _nSensitivity: usize,
) -> fmi3Status {
    unsupported(instance, "fmi3GetAdjointDerivative", "adjoint derivatives are not provided (providesAdjointDerivatives = false)")
}
const _: fmi3GetAdjointDerivativeTYPE = Some(fmi3GetAdjointDerivative);

// ---- Configuration Mode ------------------------------------------------------

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterConfigurationMode(instance: fmi3Instance) -> fmi3Status {
    call(instance, "fmi3EnterConfigurationMode", |inst| inst.enter_configuration_mode())
}
const _: fmi3EnterConfigurationModeTYPE = Some(fmi3EnterConfigurationMode);

#[no_mangle]
pub unsafe extern "C" fn fmi3ExitConfigurationMode(instance: fmi3Instance) -> fmi3Status {
    call(instance, "fmi3ExitConfigurationMode", |inst| inst.exit_configuration_mode())
}
const _: fmi3ExitConfigurationModeTYPE = Some(fmi3ExitConfigurationMode);

// ---- Clocks ------------------------------------------------------------------

#[no_mangle]
pub unsafe extern "C" fn fmi3GetIntervalDecimal(
    instance: fmi3Instance,
    _valueReferences: *const fmi3ValueReference,
    _nValueReferences: usize,
    _intervals: *mut fmi3Float64,
    _qualifiers: *mut fmi3IntervalQualifier,
) -> fmi3Status {
    unsupported(instance, "fmi3GetIntervalDecimal", NO_CLOCKS)
}
const _: fmi3GetIntervalDecimalTYPE = Some(fmi3GetIntervalDecimal);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetIntervalFraction(
    instance: fmi3Instance,
    _valueReferences: *const fmi3ValueReference,
    _nValueReferences: usize,
    _counters: *mut fmi3UInt64,
    _resolutions: *mut fmi3UInt64,
    _qualifiers: *mut fmi3IntervalQualifier,
) -> fmi3Status {
    unsupported(instance, "fmi3GetIntervalFraction", NO_CLOCKS)
}
const _: fmi3GetIntervalFractionTYPE = Some(fmi3GetIntervalFraction);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetShiftDecimal(
    instance: fmi3Instance,
    _valueReferences: *const fmi3ValueReference,
    _nValueReferences: usize,
    _shifts: *mut fmi3Float64,
) -> fmi3Status {
    unsupported(instance, "fmi3GetShiftDecimal", NO_CLOCKS)
}
const _: fmi3GetShiftDecimalTYPE = Some(fmi3GetShiftDecimal);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetShiftFraction(
    instance: fmi3Instance,
    _valueReferences: *const fmi3ValueReference,
    _nValueReferences: usize,
    _counters: *mut fmi3UInt64,
    _resolutions: *mut fmi3UInt64,
) -> fmi3Status {
    unsupported(instance, "fmi3GetShiftFraction", NO_CLOCKS)
}
const _: fmi3GetShiftFractionTYPE = Some(fmi3GetShiftFraction);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetIntervalDecimal(
    instance: fmi3Instance,
    _valueReferences: *const fmi3ValueReference,
    _nValueReferences: usize,
    _intervals: *const fmi3Float64,
) -> fmi3Status {
    unsupported(instance, "fmi3SetIntervalDecimal", NO_CLOCKS)
}
const _: fmi3SetIntervalDecimalTYPE = Some(fmi3SetIntervalDecimal);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetIntervalFraction(
    instance: fmi3Instance,
    _valueReferences: *const fmi3ValueReference,
    _nValueReferences: usize,
    _counters: *const fmi3UInt64,
    _resolutions: *const fmi3UInt64,
) -> fmi3Status {
    unsupported(instance, "fmi3SetIntervalFraction", NO_CLOCKS)
}
const _: fmi3SetIntervalFractionTYPE = Some(fmi3SetIntervalFraction);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetShiftDecimal(
    instance: fmi3Instance,
    _valueReferences: *const fmi3ValueReference,
    _nValueReferences: usize,
    _shifts: *const fmi3Float64,
) -> fmi3Status {
    unsupported(instance, "fmi3SetShiftDecimal", NO_CLOCKS)
}
const _: fmi3SetShiftDecimalTYPE = Some(fmi3SetShiftDecimal);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetShiftFraction(
    instance: fmi3Instance,
    _valueReferences: *const fmi3ValueReference,
    _nValueReferences: usize,
    _counters: *const fmi3UInt64,
    _resolutions: *const fmi3UInt64,
) -> fmi3Status {
    unsupported(instance, "fmi3SetShiftFraction", NO_CLOCKS)
}
const _: fmi3SetShiftFractionTYPE = Some(fmi3SetShiftFraction);

#[no_mangle]
pub unsafe extern "C" fn fmi3EvaluateDiscreteStates(instance: fmi3Instance) -> fmi3Status {
    unsupported(instance, "fmi3EvaluateDiscreteStates", "discrete states are not provided (providesEvaluateDiscreteStates = false)")
}
const _: fmi3EvaluateDiscreteStatesTYPE = Some(fmi3EvaluateDiscreteStates);

#[no_mangle]
pub unsafe extern "C" fn fmi3UpdateDiscreteStates(
    instance: fmi3Instance,
    _discreteStatesNeedUpdate: *mut fmi3Boolean,
    _terminateSimulation: *mut fmi3Boolean,
    _nominalsOfContinuousStatesChanged: *mut fmi3Boolean,
    _valuesOfContinuousStatesChanged: *mut fmi3Boolean,
    _nextEventTimeDefined: *mut fmi3Boolean,
    _nextEventTime: *mut fmi3Float64,
) -> fmi3Status {
    unsupported(instance, "fmi3UpdateDiscreteStates", NO_EVENTS)
}
const _: fmi3UpdateDiscreteStatesTYPE = Some(fmi3UpdateDiscreteStates);

// ---- Model Exchange ----------------------------------------------------------

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterContinuousTimeMode(instance: fmi3Instance) -> fmi3Status {
    unsupported(instance, "fmi3EnterContinuousTimeMode", NO_ME)
}
const _: fmi3EnterContinuousTimeModeTYPE = Some(fmi3EnterContinuousTimeMode);

#[no_mangle]
pub unsafe extern "C" fn fmi3CompletedIntegratorStep(
    instance: fmi3Instance,
    _noSetFMUStatePriorToCurrentPoint: fmi3Boolean,
    _enterEventMode: *mut fmi3Boolean,
    _terminateSimulation: *mut fmi3Boolean,
) -> fmi3Status {
    unsupported(instance, "fmi3CompletedIntegratorStep", NO_ME)
}
const _: fmi3CompletedIntegratorStepTYPE = Some(fmi3CompletedIntegratorStep);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetTime(instance: fmi3Instance, _time: fmi3Float64) -> fmi3Status {
    unsupported(instance, "fmi3SetTime", NO_ME)
}
const _: fmi3SetTimeTYPE = Some(fmi3SetTime);

#[no_mangle]
pub unsafe extern "C" fn fmi3SetContinuousStates(instance: fmi3Instance, _continuousStates: *const fmi3Float64, _nContinuousStates: usize) -> fmi3Status {
    unsupported(instance, "fmi3SetContinuousStates", NO_ME)
}
const _: fmi3SetContinuousStatesTYPE = Some(fmi3SetContinuousStates);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetContinuousStateDerivatives(instance: fmi3Instance, _derivatives: *mut fmi3Float64, _nContinuousStates: usize) -> fmi3Status {
    unsupported(instance, "fmi3GetContinuousStateDerivatives", NO_ME)
}
const _: fmi3GetContinuousStateDerivativesTYPE = Some(fmi3GetContinuousStateDerivatives);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetEventIndicators(instance: fmi3Instance, _eventIndicators: *mut fmi3Float64, _nEventIndicators: usize) -> fmi3Status {
    unsupported(instance, "fmi3GetEventIndicators", NO_ME)
}
const _: fmi3GetEventIndicatorsTYPE = Some(fmi3GetEventIndicators);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetContinuousStates(instance: fmi3Instance, _continuousStates: *mut fmi3Float64, _nContinuousStates: usize) -> fmi3Status {
    unsupported(instance, "fmi3GetContinuousStates", NO_ME)
}
const _: fmi3GetContinuousStatesTYPE = Some(fmi3GetContinuousStates);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNominalsOfContinuousStates(instance: fmi3Instance, _nominals: *mut fmi3Float64, _nContinuousStates: usize) -> fmi3Status {
    unsupported(instance, "fmi3GetNominalsOfContinuousStates", NO_ME)
}
const _: fmi3GetNominalsOfContinuousStatesTYPE = Some(fmi3GetNominalsOfContinuousStates);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNumberOfEventIndicators(instance: fmi3Instance, _nEventIndicators: *mut usize) -> fmi3Status {
    unsupported(instance, "fmi3GetNumberOfEventIndicators", NO_ME)
}
const _: fmi3GetNumberOfEventIndicatorsTYPE = Some(fmi3GetNumberOfEventIndicators);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNumberOfContinuousStates(instance: fmi3Instance, _nContinuousStates: *mut usize) -> fmi3Status {
    unsupported(instance, "fmi3GetNumberOfContinuousStates", NO_ME)
}
const _: fmi3GetNumberOfContinuousStatesTYPE = Some(fmi3GetNumberOfContinuousStates);

// ---- Co-Simulation -----------------------------------------------------------

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterStepMode(instance: fmi3Instance) -> fmi3Status {
    unsupported(
        instance,
        "fmi3EnterStepMode",
        "Step Mode is entered from Event Mode, which this FMU does not have (hasEventMode = false); fmi3ExitInitializationMode enters Step Mode",
    )
}
const _: fmi3EnterStepModeTYPE = Some(fmi3EnterStepMode);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetOutputDerivatives(
    instance: fmi3Instance,
    _valueReferences: *const fmi3ValueReference,
    _nValueReferences: usize,
    _orders: *const fmi3Int32,
    _values: *mut fmi3Float64,
    _nValues: usize,
) -> fmi3Status {
    unsupported(instance, "fmi3GetOutputDerivatives", "output derivatives are not provided (maxOutputDerivativeOrder = 0)")
}
const _: fmi3GetOutputDerivativesTYPE = Some(fmi3GetOutputDerivatives);

#[no_mangle]
pub unsafe extern "C" fn fmi3DoStep(
    instance: fmi3Instance,
    currentCommunicationPoint: fmi3Float64,
    communicationStepSize: fmi3Float64,
    _noSetFMUStatePriorToCurrentPoint: fmi3Boolean,
    eventHandlingNeeded: *mut fmi3Boolean,
    terminateSimulation: *mut fmi3Boolean,
    earlyReturn: *mut fmi3Boolean,
    lastSuccessfulTime: *mut fmi3Float64,
) -> fmi3Status {
    call(instance, "fmi3DoStep", |inst| {
        inst.do_step(currentCommunicationPoint, communicationStepSize, eventHandlingNeeded, terminateSimulation, earlyReturn, lastSuccessfulTime)
    })
}
const _: fmi3DoStepTYPE = Some(fmi3DoStep);

// ---- Scheduled Execution -----------------------------------------------------

#[no_mangle]
pub unsafe extern "C" fn fmi3ActivateModelPartition(instance: fmi3Instance, _clockReference: fmi3ValueReference, _activationTime: fmi3Float64) -> fmi3Status {
    unsupported(instance, "fmi3ActivateModelPartition", NO_SE)
}
const _: fmi3ActivateModelPartitionTYPE = Some(fmi3ActivateModelPartition);
