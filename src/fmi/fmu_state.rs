//! FMU states (fmi3Get/Set/FreeFMUState): a copy of everything an instance
//! needs to resume, owned by the instance that made it. Only states this
//! instance made and has not freed are dereferenced; the rest are refused
//! unread. Their byte format is [`super::serialize`].

use std::collections::BTreeSet;

use super::model::Model;
use super::params::Params;
use super::state_machine::Mode;
use crate::TheModel;

/// The model's part of an FMU state.
pub type Snapshot = <TheModel as Model>::Snapshot;

pub(crate) const STATE_MAGIC: u64 = 0x4d4d_535f_5354_4154;

/// A copy of everything an instance needs to resume (fmi3GetFMUState).
#[derive(Clone, Debug)]
pub struct FmuState {
    pub(crate) magic: u64,
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
pub struct OwnedStates(pub(crate) BTreeSet<usize>);

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
