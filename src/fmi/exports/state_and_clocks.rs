//! The `fmi3*` entries after the values, in the standard's order: variable
//! dependencies and partial derivatives (refused), the FMU state and its
//! serialization, Configuration Mode, and the clocks' intervals and
//! shifts and the discrete states (refused: this FMU has no clocks and
//! no events).

use fmi_sys::fmi3::*;

use crate::fmi::functions::Function as F;
use crate::fmi::guard::{call, refuse};

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
