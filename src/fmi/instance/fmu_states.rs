//! FMU states on an instance (fmi3Get/Set/FreeFMUState, their
//! serialization): only states this instance made and has not freed are
//! dereferenced; the rest are refused unread. What a state holds is
//! [`crate::fmi::fmu_state`], its byte format [`crate::fmi::serialize`].

use fmi_sys::fmi3::{fmi3FMUState, fmi3Status};

use super::{Instance, R};
use crate::fmi::fmu_state::{FmuState, STATE_MAGIC};
use crate::fmi::model::Model;
use crate::fmi::ptr::{slice, too_many};
use crate::fmi::serialize::{decode, encode};
use crate::fmi::variables::VARIABLES;
use crate::status::OK;

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

impl Instance {
    /// fmi3SerializedFMUStateSize.
    ///
    /// # Safety
    /// `size` must be NULL or writable.
    pub unsafe fn serialized_size(&self, state: fmi3FMUState, size: *mut usize) -> R {
        const F: &str = "fmi3SerializedFMUStateSize";
        if size.is_null() {
            return Err(self.log.fail(&format!("{F}: size is NULL")));
        }
        let s = self.state_from_ptr(F, state)?;
        *size = encode(s).len();
        Ok(OK)
    }

    /// fmi3SerializeFMUState: exactly the size fmi3SerializedFMUStateSize gave.
    ///
    /// # Safety
    /// `out` must be NULL or point to `size` writable bytes.
    pub unsafe fn serialize(&self, state: fmi3FMUState, out: *mut u8, size: usize) -> R {
        const F: &str = "fmi3SerializeFMUState";
        let s = self.state_from_ptr(F, state)?;
        let bytes = encode(s);
        if out.is_null() {
            return Err(self.log.fail(&format!("{F}: serializedState is NULL")));
        }
        if size != bytes.len() {
            return Err(self.log.fail(&format!("{F}: size is {size}, fmi3SerializedFMUStateSize gave {}", bytes.len())));
        }
        std::ptr::copy_nonoverlapping(bytes.as_ptr(), out, size);
        Ok(OK)
    }

    /// fmi3DeserializeFMUState: a state of an instance with the same
    /// structural parameters, checked through and through before it is kept.
    ///
    /// # Safety
    /// `bytes` must be NULL or point to `size` readable bytes; `out` NULL or a
    /// readable and writable state pointer.
    pub unsafe fn deserialize(&mut self, bytes: *const u8, size: usize, out: *mut fmi3FMUState) -> R {
        const F: &str = "fmi3DeserializeFMUState";
        if bytes.is_null() || out.is_null() {
            return Err(self.log.fail(&format!("{F}: serializedState or FMUState is NULL")));
        }
        if too_many::<u8>(size) {
            return Err(self.log.fail(&format!("{F}: size = {size} cannot be an array size")));
        }
        let s = decode(slice(bytes, size)).map_err(|m| self.log.fail(&format!("{F}: {m}")))?;
        let mine = self.structural();
        let theirs: Vec<_> = mine.iter().map(|(n, _)| (*n, s.params.values[VARIABLES.iter().position(|v| v.name == *n).unwrap()][0])).collect();
        if mine != theirs {
            return Err(self.log.fail(&format!("{F}: the state is from an instance with structural parameters {theirs:?}, this one has {mine:?}")));
        }
        self.store_state(F, out, s)
    }
}
