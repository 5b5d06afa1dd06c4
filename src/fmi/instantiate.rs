//! fmi3InstantiateCoSimulation (the only interface this FMU provides), and
//! the refusal of the other two. No instance exists yet, so messages go
//! straight to the host's callback.

use std::ffi::CStr;
use std::panic::catch_unwind;
use std::sync::Once;

use fmi_sys::fmi3::*;

use super::functions::Function;
use super::instance::Instance;
use super::logging::log_raw;
use super::params::Params;
use super::registry;
use super::variables::INSTANTIATION_TOKEN;
use crate::status::{ERROR, FATAL, OK};

/// Keeps this library in memory for the rest of the process, once: a host
/// that closes it (dlclose) and opens it again while instances live (Ecos
/// does, for a second instance of the same FMU file) would otherwise unload
/// it and with it every live instance, whose pointers the reopened library
/// would then refuse. The library asks the loader for itself again with
/// `RTLD_NODELETE` (and never closes that handle).
fn pin_library() {
    static PIN: Once = Once::new();
    PIN.call_once(|| unsafe {
        let mut info: libc::Dl_info = std::mem::zeroed();
        if libc::dladdr(pin_library as *const libc::c_void, &mut info) != 0 && !info.dli_fname.is_null() {
            libc::dlopen(info.dli_fname, libc::RTLD_NOW | libc::RTLD_NOLOAD | libc::RTLD_NODELETE);
        }
    });
}

/// Checks the arguments and makes an instance with the start values of
/// `resources/startValues.txt` (or the compiled ones).
///
/// # Safety
/// The three strings must each be NULL or a NUL-terminated C string.
#[allow(clippy::too_many_arguments)]
pub unsafe fn co_simulation(
    instance_name: fmi3String,
    token: fmi3String,
    resource_path: fmi3String,
    logging_on: bool,
    event_mode_used: bool,
    n_required_intermediate: usize,
    env: fmi3InstanceEnvironment,
    logger: fmi3LogMessageCallback,
) -> fmi3Instance {
    const F: &str = "fmi3InstantiateCoSimulation";
    pin_library();
    let result = catch_unwind(|| {
        let fail = |m: String| {
            log_raw(env, logger, ERROR, "logStatusError", &format!("{F}: {m}"));
            std::ptr::null_mut()
        };
        if token.is_null() {
            return fail("instantiationToken is NULL".into());
        }
        let token = unsafe { CStr::from_ptr(token) }.to_string_lossy();
        if token != INSTANTIATION_TOKEN {
            return fail(format!("instantiationToken {token} does not match this binary ({INSTANTIATION_TOKEN})"));
        }
        if event_mode_used {
            return fail(Function::EnterEventMode.legal().note.into());
        }
        if n_required_intermediate > 0 {
            return fail("this FMU provides no intermediate update (providesIntermediateUpdate = false)".into());
        }
        // The standard requires a non-empty name; messages are labelled with it.
        if instance_name.is_null() {
            return fail("instanceName is NULL".into());
        }
        let name = unsafe { CStr::from_ptr(instance_name) }.to_string_lossy().into_owned();
        if name.trim().is_empty() {
            return fail("instanceName is empty".into());
        }
        let dir = (!resource_path.is_null()).then(|| {
            let dir = unsafe { CStr::from_ptr(resource_path) }.to_string_lossy().into_owned();
            std::path::PathBuf::from(dir.strip_prefix("file://").unwrap_or(&dir))
        });
        let start = match &dir {
            None => Params::start(),
            Some(dir) => {
                let file = dir.join("startValues.txt");
                match std::fs::read_to_string(&file) {
                    Ok(text) => match Params::from_text(&text) {
                        Ok(p) => p,
                        Err(m) => return fail(format!("{}: {m}", file.display())),
                    },
                    // No file: the compiled start values are those of modelDescription.xml.
                    Err(_) => Params::start(),
                }
            }
        };
        let inst = Instance::new(env, logger, logging_on, start, dir.as_deref());
        inst.log.log(OK, &format!("instance \"{name}\" created"));
        registry::register(inst)
    });
    result.unwrap_or_else(|p| {
        let msg = p.downcast_ref::<&str>().map(|s| s.to_string()).or_else(|| p.downcast_ref::<String>().cloned()).unwrap_or_default();
        log_raw(env, logger, FATAL, "logStatusFatal", &format!("{F}: internal error: {msg}"));
        std::ptr::null_mut()
    })
}

/// Model Exchange and Scheduled Execution: refused, with the table's reason.
pub fn refused(f: Function, env: fmi3InstanceEnvironment, logger: fmi3LogMessageCallback) -> fmi3Instance {
    log_raw(env, logger, ERROR, "logStatusError", &format!("{}: {}", f.name(), f.legal().note));
    std::ptr::null_mut()
}
