//! The `fmi3*` entries of one interface each: Model Exchange (refused),
//! Co-Simulation (Step Mode refused, the output derivatives refused, the
//! communication step) and Scheduled Execution (refused).

use fmi_sys::fmi3::*;

use crate::fmi::functions::Function as F;
use crate::fmi::guard::{call, refuse};

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
