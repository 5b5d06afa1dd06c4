//! The one guard every `fmi3*` export goes through ([`call`]): a null,
//! freed or foreign instance is refused without touching it, the state is
//! checked against [`super::functions`]'s table, and a panic poisons the
//! instance and returns fmi3Fatal instead of unwinding into the importer.

use std::panic::{catch_unwind, AssertUnwindSafe};

use fmi_sys::fmi3::*;

use super::functions::Function as F;
use super::instance::Instance;
use super::registry;
use crate::status::{ERROR, FATAL};

fn panic_message(p: &Box<dyn std::any::Any + Send>) -> String {
    p.downcast_ref::<&str>().map(|s| s.to_string()).or_else(|| p.downcast_ref::<String>().cloned()).unwrap_or_else(|| "unknown panic".into())
}

/// Runs `body` on a live instance in a state where `f` is legal; a panic
/// poisons the instance and returns fmi3Fatal.
pub(crate) fn call(instance: fmi3Instance, f: F, body: impl FnOnce(&mut Instance) -> Result<fmi3Status, fmi3Status>) -> fmi3Status {
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
pub(crate) fn refuse(instance: fmi3Instance, f: F) -> fmi3Status {
    call(instance, f, |_| unreachable!("{} is legal in no state", f.name()))
}
