//! The `fmi3*` C ABI: one short entry per function of the FMI 3.0 API.
//!
//! Each entry names its row of [`super::functions`]'s table and hands the
//! call to [`call`], which refuses a null, freed or foreign instance, checks
//! the state against the table (the one guard, [`Instance::guard`]), catches
//! any panic instead of unwinding into the importer, and runs the body on
//! the instance. Functions this FMU does not provide are refused with the
//! table's reason ([`refuse`]). Every signature is checked at compile time
//! against the `fmi3...TYPE` alias of the official headers (the `const _`
//! after it), and cbindgen writes the C header from this module and its
//! children, which hold the entries by the standard's groups, in its order.

#![allow(clippy::missing_safety_doc, clippy::too_many_arguments)]

use std::panic::{catch_unwind, AssertUnwindSafe};

use fmi_sys::fmi3::*;

use super::functions::Function as F;
use super::instance::Instance;
use super::{registry, ERROR, FATAL};

// The groups in the standard's order, which cbindgen keeps in the C header
// (the blank lines keep rustfmt from sorting them).
mod life_cycle;

mod get_set;

mod state_and_clocks;

mod interfaces;

pub use get_set::*;
pub use interfaces::*;
pub use life_cycle::*;
pub use state_and_clocks::*;

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
