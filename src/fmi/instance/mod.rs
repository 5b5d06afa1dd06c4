//! One FMU instance, in one place: what it holds, its model set up on
//! demand from the parameter values, and the communication step (here);
//! the transitions between states and the guard (`transitions.rs`),
//! Get/Set (`get_set.rs`) and FMU states (`fmu_states.rs`). The pieces
//! they use (the state machine's states, the range checks, the byte
//! format, the logger) live beside this folder and know nothing of an
//! instance; the registry of live instances imports this one, not the
//! other way round.

use std::path::Path;

use fmi_sys::fmi3::*;

mod fmu_states;
mod get_set;
mod transitions;

use crate::fmi::fmu_state::OwnedStates;
use crate::fmi::logging::Logger;
use crate::fmi::model::{Model, StepEnd};
use crate::fmi::params::Params;
use crate::fmi::state_machine::{same_time, Mode};
use crate::fmi::variables::{Causality, VARIABLES};
use crate::status::{DISCARD, OK, WARNING};
use crate::TheModel;

/// What a call on an instance returns: its status, or the status of its refusal.
type R = Result<fmi3Status, fmi3Status>;

/// Carried by every live instance and checked on every call (see [`crate::fmi::registry`]).
pub const INSTANCE_MAGIC: u64 = 0x4d4d_535f_494e_5354;

pub struct Instance {
    pub(crate) magic: u64,
    pub log: Logger,
    pub mode: Mode,
    /// Set after a panic: the instance may be inconsistent and only accepts FreeInstance.
    pub poisoned: bool,
    /// Values of every parameter and input.
    pub params: Params,
    /// The values before the Set in progress, kept in place so that a Set
    /// that is refused restores them without allocating.
    pub(crate) before_set: Params,
    /// Values restored by fmi3Reset: compiled start values or the FMU's resources/startValues.txt.
    pub(crate) start: Params,
    /// The model: its set-up, state and rules.
    pub(crate) model: TheModel,
    pub(crate) start_time: f64,
    pub(crate) stop_time: Option<f64>,
    /// FMU states made by this instance and not freed yet.
    pub(crate) states: OwnedStates,
}

impl Instance {
    pub fn new(env: fmi3InstanceEnvironment, logger: fmi3LogMessageCallback, logging_on: bool, start: Params, resources: Option<&Path>) -> Self {
        Instance {
            magic: INSTANCE_MAGIC,
            log: Logger::new(env, logger, logging_on),
            mode: Mode::Instantiated,
            poisoned: false,
            params: start.clone(),
            before_set: start.clone(),
            start,
            model: TheModel::new(resources),
            start_time: 0.0,
            stop_time: None,
            states: OwnedStates::default(),
        }
    }

    /// Sets the model up if parameters changed since the last set-up.
    pub(crate) fn ensure_set_up(&mut self) -> R {
        if !self.model.is_set_up() {
            if let Err(m) = self.model.set_up(&self.params, &self.log) {
                return Err(self.log.fail(&m));
            }
        }
        Ok(OK)
    }

    /// The FMU's time: the start time plus the model's.
    pub fn time(&self) -> f64 {
        self.start_time + self.model.time().unwrap_or(0.0)
    }

    /// fmi3DoStep: one communication step; a step the model refuses is
    /// discarded with the state kept at its start.
    ///
    /// # Safety
    /// The four output pointers must each be NULL or writable.
    #[allow(clippy::too_many_arguments)]
    pub unsafe fn do_step(
        &mut self,
        t: f64,
        h: f64,
        event_handling_needed: *mut bool,
        terminate_simulation: *mut bool,
        early_return: *mut bool,
        last_successful_time: *mut f64,
    ) -> R {
        const F: &str = "fmi3DoStep";
        if event_handling_needed.is_null() || terminate_simulation.is_null() || early_return.is_null() || last_successful_time.is_null() {
            return Err(self.log.fail(&format!("{F}: an output argument is NULL")));
        }
        let now = self.time();
        unsafe {
            *event_handling_needed = false;
            *terminate_simulation = false;
            *early_return = false;
            *last_successful_time = now;
        }
        if !(h.is_finite() && h > 0.0) {
            return Err(self.log.fail(&format!("{F}: communicationStepSize must be finite and positive, got {h}")));
        }
        if !t.is_finite() || !same_time(t, now) {
            return Err(self.log.fail(&format!("{F}: currentCommunicationPoint {t} does not match the FMU time {now}")));
        }
        if let Some(stop) = self.stop_time {
            let end = now + h;
            if end > stop && !same_time(end, stop) {
                return Err(self.log.fail(&format!("{F}: the step would end at {end}, past stopTime {stop}")));
            }
        }
        match self.model.do_step(&self.params, h, self.start_time) {
            Ok(end) => {
                unsafe { *last_successful_time = self.time() };
                match end {
                    StepEnd::Done => Ok(OK),
                    StepEnd::Warning(m) => {
                        self.log.log(WARNING, &format!("{F}: {m}"));
                        Ok(WARNING)
                    }
                    StepEnd::Event(m) => {
                        self.log.log(OK, &format!("{F}: {m}"));
                        Ok(OK)
                    }
                }
            }
            Err(why) => {
                self.log.log(DISCARD, &format!("{F}: step from t = {now} by {h} s refused, state kept at t = {now}: {why}"));
                Err(DISCARD)
            }
        }
    }

    /// Name and value of every structural parameter.
    pub fn structural(&self) -> Vec<(&'static str, f64)> {
        VARIABLES.iter().enumerate().filter(|(_, v)| v.causality == Causality::StructuralParameter).map(|(i, v)| (v.name, self.params.values[i][0])).collect()
    }
}
