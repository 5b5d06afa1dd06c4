//! FMU states (fmi3Get/Set/FreeFMUState): a copy of everything an instance
//! needs to resume, owned by the instance that made it. Only states this
//! instance made and has not freed are dereferenced; the rest are refused
//! unread. Their byte format is [`super::serialize`].

use std::collections::BTreeSet;

use fmi_sys::fmi3::{fmi3FMUState, fmi3Status};

use super::instance::Instance;
use super::model::Model;
use super::params::Params;
use super::state_machine::Mode;
use super::{TheModel, OK};

/// The model's part of an FMU state.
pub type Snapshot = <TheModel as Model>::Snapshot;

type R = Result<fmi3Status, fmi3Status>;

const STATE_MAGIC: u64 = 0x4d4d_535f_5354_4154;

/// A copy of everything an instance needs to resume (fmi3GetFMUState).
#[derive(Clone, Debug)]
pub struct FmuState {
    magic: u64,
    pub mode: Mode,
    pub start_time: f64,
    /// stopTime of fmi3EnterInitializationMode, if it was defined.
    pub stop_time: Option<f64>,
    /// Values of every parameter and input.
    pub params: Params,
    /// The model's state, whenever it was set up for `params`.
    pub snapshot: Option<Snapshot>,
}

impl FmuState {
    pub fn new(mode: Mode, start_time: f64, stop_time: Option<f64>, params: Params, snapshot: Option<Snapshot>) -> Self {
        FmuState { magic: STATE_MAGIC, mode, start_time, stop_time, params, snapshot }
    }
}

/// The FMU states an instance made and has not freed; dropping it frees them.
#[derive(Default)]
pub struct OwnedStates(BTreeSet<usize>);

impl Drop for OwnedStates {
    fn drop(&mut self) {
        for p in std::mem::take(&mut self.0) {
            // SAFETY: every address in here is a live Box<FmuState> made by `store_state`.
            let s = unsafe { &mut *(p as *mut FmuState) };
            s.magic = 0;
            drop(unsafe { Box::from_raw(p as *mut FmuState) });
        }
    }
}

impl Instance {
    pub fn capture(&self) -> FmuState {
        FmuState::new(self.mode, self.start_time, self.stop_time, self.params.clone(), self.model.snapshot())
    }

    /// The state behind `state` if this instance made it and has not freed it;
    /// anything else (NULL, freed, another instance's) is refused unread.
    pub fn state_from_ptr<'a>(&self, f: &str, state: fmi3FMUState) -> Result<&'a mut FmuState, fmi3Status> {
        if state.is_null() {
            return Err(self.log.fail(&format!("{f}: FMUState is NULL")));
        }
        if !self.states.0.contains(&(state as usize)) {
            return Err(self.log.fail(&format!("{f}: FMUState is not a live state of this instance (freed, or made by another one)")));
        }
        // SAFETY: addresses in `states` are live Box<FmuState>s owned by this instance.
        let s = unsafe { &mut *(state as *mut FmuState) };
        debug_assert_eq!(s.magic, STATE_MAGIC);
        Ok(s)
    }

    /// Stores `s` in `*out`, reusing the state already there.
    ///
    /// # Safety
    /// `out` must be null or point to writable memory for one pointer.
    pub unsafe fn store_state(&mut self, f: &str, out: *mut fmi3FMUState, s: FmuState) -> R {
        if out.is_null() {
            return Err(self.log.fail(&format!("{f}: FMUState is NULL")));
        }
        if !(*out).is_null() {
            let existing = self.state_from_ptr(f, *out)?;
            *existing = s;
        } else {
            let p = Box::into_raw(Box::new(s)) as fmi3FMUState;
            self.states.0.insert(p as usize);
            *out = p;
        }
        Ok(OK)
    }

    /// # Safety
    /// `out` must be null or point to a readable and writable state pointer.
    pub unsafe fn free_state(&mut self, out: *mut fmi3FMUState) -> R {
        const F: &str = "fmi3FreeFMUState";
        if out.is_null() {
            return Err(self.log.fail(&format!("{F}: FMUState is NULL")));
        }
        if (*out).is_null() {
            return Ok(OK);
        }
        let s = self.state_from_ptr(F, *out)?;
        s.magic = 0;
        self.states.0.remove(&(*out as usize));
        drop(Box::from_raw(s as *mut FmuState));
        *out = std::ptr::null_mut();
        Ok(OK)
    }

    /// Makes `s` the current state; on error the instance is unchanged.
    pub fn restore(&mut self, s: &FmuState) -> R {
        const F: &str = "fmi3SetFMUState";
        if let Err(m) = self.model.restore(&self.params, &s.params, s.snapshot.as_ref()) {
            return Err(self.log.fail(&format!("{F}: {m}")));
        }
        self.params = s.params.clone();
        self.mode = s.mode;
        self.start_time = s.start_time;
        self.stop_time = s.stop_time;
        Ok(OK)
    }
}
