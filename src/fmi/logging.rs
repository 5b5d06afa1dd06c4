//! Logging through the host's callback: statuses map to the log categories
//! of the model description, failures always reach the host, the rest only
//! when `fmi3SetDebugLogging` asked for them.

use std::ffi::{CStr, CString};

use fmi_sys::fmi3::*;

use super::ptr;
use super::variables::LOG_CATEGORIES;
use crate::status::{DISCARD, ERROR, OK, WARNING};

/// The host's callback and the categories it switched on.
pub struct Logger {
    env: fmi3InstanceEnvironment,
    callback: fmi3LogMessageCallback,
    on: bool,
    categories: Vec<bool>,
}

impl Logger {
    pub fn new(env: fmi3InstanceEnvironment, callback: fmi3LogMessageCallback, on: bool) -> Self {
        Logger { env, callback, on, categories: vec![true; LOG_CATEGORIES.len()] }
    }

    /// Logs `message` with `status` in the category of that status.
    pub fn log(&self, status: fmi3Status, message: &str) {
        let category = match status {
            OK => "logEvents",
            WARNING => "logStatusWarning",
            DISCARD => "logStatusDiscard",
            ERROR => "logStatusError",
            _ => "logStatusFatal",
        };
        // Every status but fmi3OK (warnings, discarded steps, errors) reaches
        // the host with its reason; the rest only when asked for.
        let enabled = status >= WARNING || (self.on && (self.category_on(category) || self.category_on("logAll")));
        if enabled {
            log_raw(self.env, self.callback, status, category, message);
        }
    }

    fn category_on(&self, name: &str) -> bool {
        LOG_CATEGORIES.iter().position(|c| *c == name).is_some_and(|i| self.categories[i])
    }

    /// Logs `message` as an error and returns fmi3Error.
    pub fn fail(&self, message: &str) -> fmi3Status {
        self.log(ERROR, message);
        ERROR
    }

    /// fmi3SetDebugLogging: `n` categories (all when 0) switched to `on`.
    ///
    /// # Safety
    /// `categories` must point to `n` C strings unless it is NULL or `n` is 0.
    pub unsafe fn set(&mut self, on: bool, n: usize, categories: *const fmi3String) -> Result<fmi3Status, fmi3Status> {
        const F: &str = "fmi3SetDebugLogging";
        if n > 0 && categories.is_null() {
            return Err(self.fail(&format!("{F}: categories is NULL but nCategories > 0")));
        }
        if ptr::too_many::<fmi3String>(n) {
            return Err(self.fail(&format!("{F}: nCategories = {n} cannot be an array size")));
        }
        let mut selected = Vec::new();
        for &c in ptr::slice(categories, n) {
            if c.is_null() {
                return Err(self.fail(&format!("{F}: a category is NULL")));
            }
            let name = CStr::from_ptr(c).to_string_lossy();
            match LOG_CATEGORIES.iter().position(|x| *x == name) {
                Some(i) => selected.push(i),
                None => return Err(self.fail(&format!("{F}: unknown log category \"{name}\" (known: {})", LOG_CATEGORIES.join(", ")))),
            }
        }
        self.on = on;
        if n == 0 {
            self.categories.iter_mut().for_each(|c| *c = on);
        } else {
            for i in selected {
                self.categories[i] = on;
            }
        }
        Ok(OK)
    }
}

/// Logs through the host's callback (also before an instance exists).
/// `env` is handed back to the callback untouched; both come from the host,
/// which vouched for them at instantiation.
#[allow(clippy::not_unsafe_ptr_arg_deref)]
pub fn log_raw(env: fmi3InstanceEnvironment, callback: fmi3LogMessageCallback, status: fmi3Status, category: &str, message: &str) {
    if let Some(cb) = callback {
        let cat = CString::new(category).unwrap_or_default();
        let msg = CString::new(message.replace('\0', " ")).unwrap_or_default();
        unsafe { cb(env, status, cat.as_ptr(), msg.as_ptr()) };
    }
}
