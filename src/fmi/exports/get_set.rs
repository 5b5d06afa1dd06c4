//! The `fmi3Get*` and `fmi3Set*` entries of variable values, one pair per
//! type in the standard's order; the types this FMU has no variables of
//! accept only an empty request.

use fmi_sys::fmi3::*;

use crate::fmi::functions::Function as F;
use crate::fmi::guard::call;
use crate::fmi::variables::Type;

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
