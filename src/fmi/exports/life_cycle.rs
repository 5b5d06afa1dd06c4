//! The `fmi3*` entries of an instance's life: the version and debug
//! logging, the three Instantiate functions (only Co-Simulation is
//! provided) and FreeInstance, which do not go through [`call`]'s guard,
//! then Initialization Mode, Event Mode (refused), Terminate and Reset.

use std::ffi::c_char;
use std::panic::catch_unwind;

use fmi_sys::fmi3::*;

use crate::fmi::functions::Function as F;
use crate::fmi::guard::{call, refuse};
use crate::fmi::instantiate;
use crate::fmi::registry;

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
