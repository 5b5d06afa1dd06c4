//! The status codes of the FMI 3.0 C API, by their short names: what the
//! glue returns and what the model's messages are logged with.

use fmi_sys::fmi3::*;

pub const OK: fmi3Status = fmi3Status_fmi3OK;
pub const WARNING: fmi3Status = fmi3Status_fmi3Warning;
pub const DISCARD: fmi3Status = fmi3Status_fmi3Discard;
pub const ERROR: fmi3Status = fmi3Status_fmi3Error;
pub const FATAL: fmi3Status = fmi3Status_fmi3Fatal;
