//! The live instances of this process. A pointer the host passes is
//! dereferenced only if it is in here and carries the instance's magic, so
//! a freed, stale or foreign pointer is refused without touching the memory
//! it points to.

use std::collections::BTreeSet;
use std::sync::{Mutex, MutexGuard};

use fmi_sys::fmi3::fmi3Instance;

use super::instance::{Instance, INSTANCE_MAGIC};

static LIVE: Mutex<BTreeSet<usize>> = Mutex::new(BTreeSet::new());

fn live() -> MutexGuard<'static, BTreeSet<usize>> {
    // The set stays consistent even if a holder panicked: insert/remove are atomic.
    LIVE.lock().unwrap_or_else(|e| e.into_inner())
}

/// Hands `inst` to the host.
pub fn register(inst: Instance) -> fmi3Instance {
    let p = Box::into_raw(Box::new(inst)) as fmi3Instance;
    live().insert(p as usize);
    p
}

/// The instance behind `p`, if `p` is a live instance of this FMU.
///
/// # Safety
/// The instance must not be used from another thread at the same time
/// (FMI instances are not thread-safe; different instances are).
pub unsafe fn get<'a>(p: fmi3Instance) -> Option<&'a mut Instance> {
    if p.is_null() || !live().contains(&(p as usize)) {
        return None;
    }
    let inst = &mut *(p as *mut Instance);
    (inst.magic == INSTANCE_MAGIC).then_some(inst)
}

/// Frees a live instance and the FMU states it still owns; anything else is ignored.
///
/// # Safety
/// As for [`get`]; the pointer is invalid afterwards.
pub unsafe fn free(p: fmi3Instance) {
    if p.is_null() || !live().remove(&(p as usize)) {
        return;
    }
    let inst = &mut *(p as *mut Instance);
    inst.magic = 0;
    drop(Box::from_raw(p as *mut Instance));
}
