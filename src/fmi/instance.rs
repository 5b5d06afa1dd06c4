//! One FMU instance: what it holds, its simulator built on demand from the
//! parameter values, and the communication step. The other jobs on an
//! instance live in their own modules: states and transitions in
//! [`super::state_machine`], Get/Set in [`super::values`], FMU states in
//! [`super::fmu_state`], messages in [`super::logging`].

use fmi_sys::fmi3::*;

use super::fmu_state::OwnedStates;
use super::logging::Logger;
use super::model::Params;
use super::registry::INSTANCE_MAGIC;
use super::state_machine::{same_time, Mode};
use super::variables::{vr, Causality, VARIABLES};
use super::{DISCARD, OK, WARNING};
use crate::physics::Simulator;

type R = Result<fmi3Status, fmi3Status>;

pub struct Instance {
    pub(super) magic: u64,
    pub log: Logger,
    pub mode: Mode,
    /// Set after a panic: the instance may be inconsistent and only accepts FreeInstance.
    pub poisoned: bool,
    /// Values of every parameter and input.
    pub params: Params,
    /// Values restored by fmi3Reset: compiled start values or the FMU's resources/startValues.txt.
    pub(super) start: Params,
    /// Built lazily; `None` or `stale` means parameters changed since.
    pub(super) sim: Option<Simulator>,
    pub(super) stale: bool,
    pub(super) start_time: f64,
    pub(super) stop_time: Option<f64>,
    /// FMU states made by this instance and not freed yet.
    pub(super) states: OwnedStates,
    /// forceResidual passed forceResidualLimit once, and the host was told.
    pub(super) residual_warned: bool,
    /// The FMU's `resources/setup.bin`, if it has one.
    pub(super) baked: Option<Vec<u8>>,
    /// The host set loadColumn; until then it follows the middle of the row (nx / 2).
    pub(super) load_column_chosen: bool,
}

impl Instance {
    pub fn new(env: fmi3InstanceEnvironment, logger: fmi3LogMessageCallback, logging_on: bool, start: Params) -> Self {
        Instance {
            magic: INSTANCE_MAGIC,
            log: Logger::new(env, logger, logging_on),
            mode: Mode::Instantiated,
            poisoned: false,
            params: start.clone(),
            start,
            sim: None,
            stale: true,
            start_time: 0.0,
            stop_time: None,
            states: OwnedStates::default(),
            residual_warned: false,
            baked: None,
            load_column_chosen: false,
        }
    }

    /// Builds the simulator if parameters changed since the last build.
    pub(super) fn ensure_sim(&mut self) -> R {
        if self.sim.is_none() || self.stale {
            let prebuilt = self.baked.as_ref().and_then(|bytes| match super::bake::read(bytes, &self.params) {
                Ok(data) => Some(data),
                Err(why) => {
                    self.log.log(WARNING, &format!("resources/{} not used, set-up computed: {why}", super::bake::FILE));
                    None
                }
            });
            let built = match (&prebuilt, self.params.build_with(prebuilt.as_ref())) {
                (Some(_), Ok(sim)) => {
                    self.log.log(OK, &format!("set-up taken from resources/{}", super::bake::FILE));
                    Ok(sim)
                }
                (Some(_), Err(e)) => {
                    self.log.log(WARNING, &format!("resources/{} not used, set-up computed: {e}", super::bake::FILE));
                    self.params.build()
                }
                (None, result) => result,
            };
            match built {
                Ok(sim) => {
                    self.log
                        .log(OK, &format!("simulator set up: {} nodes in {}D, {} modes", sim.scene().n_nodes, sim.scene().dim, sim.mode_frequencies().len()));
                    self.sim = Some(sim);
                    self.stale = false;
                }
                Err(e) => return Err(self.log.fail(&format!("cannot set up the simulator: {}", super::messages::describe(&e, &self.params)))),
            }
        }
        Ok(OK)
    }

    /// The FMU's time: the start time plus the simulator's.
    pub fn time(&self) -> f64 {
        self.start_time + self.sim.as_ref().filter(|_| !self.stale).map_or(0.0, |s| s.time())
    }

    /// fmi3DoStep: one communication step; a step the simulator refuses is
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
        let sim = self.sim.as_mut().expect("Step Mode has a simulator");
        match sim.do_step(h) {
            Ok(()) => {
                let end = self.start_time + sim.time();
                unsafe { *last_successful_time = end };
                // The check costs one pass over every spring; a limit of 0 turns it off.
                let limit = self.params.scalar(vr::FORCE_RESIDUAL_LIMIT);
                let residual = if self.residual_warned || limit <= 0.0 { 0.0 } else { sim.force_residual() };
                if residual > limit {
                    self.residual_warned = true;
                    self.log.log(
                        WARNING,
                        &format!(
                            "{F}: at t = {end} forceResidual = {residual:.3} passed forceResidualLimit = {limit}: the modal basis holds \
                             too little of the force at this state; the results may leave the full-space model (more modes, \
                             modeSelection = load, or reduction = full)"
                        ),
                    );
                    return Ok(WARNING);
                }
                Ok(OK)
            }
            Err(e) => {
                let why = super::messages::describe(&e, &self.params);
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
