//! One FMU instance: the FMI state machine, argument checks, logging and the
//! generic Get/Set of the variable table. Model specifics are in [`super::model`].

use std::collections::BTreeSet;
use std::ffi::{CStr, CString};
use std::sync::{Mutex, MutexGuard};

use fmi_sys::fmi3::*;

use super::model::{computed, Computed, Params};
use super::variables::{index_of, Causality, Type, Variability, Variable, LOG_CATEGORIES, VARIABLES};
use crate::physics::{Simulator, Snapshot};

pub const OK: fmi3Status = fmi3Status_fmi3OK;
pub const WARNING: fmi3Status = fmi3Status_fmi3Warning;
pub const DISCARD: fmi3Status = fmi3Status_fmi3Discard;
pub const ERROR: fmi3Status = fmi3Status_fmi3Error;
pub const FATAL: fmi3Status = fmi3Status_fmi3Fatal;

/// Checked on every call so a stale or foreign pointer is refused, not used.
const INSTANCE_MAGIC: u64 = 0x4d4d_535f_494e_5354;
const STATE_MAGIC: u64 = 0x4d4d_535f_5354_4154;

/// Addresses of the live instances of this process. A pointer the host passes
/// is dereferenced only if it is in here, so a freed, stale or foreign
/// pointer is refused without touching the memory it points to.
static LIVE: Mutex<BTreeSet<usize>> = Mutex::new(BTreeSet::new());

fn live() -> MutexGuard<'static, BTreeSet<usize>> {
    // The set stays consistent even if a holder panicked: insert/remove are atomic.
    LIVE.lock().unwrap_or_else(|e| e.into_inner())
}

/// Two times within rounding of each other (communication points and stop
/// times accumulated differently by the importer).
pub fn same_time(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1.0)
}

/// States of the FMI 3.0 Co-Simulation state machine this FMU can be in
/// (no Event Mode, no intermediate update, no clocks).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Mode {
    Instantiated = 0,
    ConfigurationMode = 1,
    InitializationMode = 2,
    StepMode = 3,
    Terminated = 4,
}

impl Mode {
    pub const fn bit(self) -> u32 {
        1 << self as u32
    }
    pub fn from_u8(x: u8) -> Option<Mode> {
        [Mode::Instantiated, Mode::ConfigurationMode, Mode::InitializationMode, Mode::StepMode, Mode::Terminated].get(x as usize).copied()
    }
}

/// States in which each function may be called.
pub mod mask {
    use super::Mode::*;
    pub const ANY: u32 = Instantiated.bit() | ConfigurationMode.bit() | InitializationMode.bit() | StepMode.bit() | Terminated.bit();
    pub const ENTER_INITIALIZATION_MODE: u32 = Instantiated.bit();
    pub const EXIT_INITIALIZATION_MODE: u32 = InitializationMode.bit();
    pub const TERMINATE: u32 = StepMode.bit();
    pub const GET: u32 = ANY;
    pub const SET: u32 = Instantiated.bit() | ConfigurationMode.bit() | InitializationMode.bit() | StepMode.bit();
    pub const ENTER_CONFIGURATION_MODE: u32 = Instantiated.bit();
    pub const EXIT_CONFIGURATION_MODE: u32 = ConfigurationMode.bit();
    pub const DO_STEP: u32 = StepMode.bit();
}

/// A copy of everything an instance needs to resume (fmi3GetFMUState).
#[derive(Clone, Debug)]
pub struct FmuState {
    magic: u64,
    pub mode: Mode,
    pub start_time: f64,
    /// stopTime of fmi3EnterInitializationMode, if it was defined.
    pub stop_time: Option<f64>,
    pub params: Params,
    /// Present whenever the simulator was up to date with `params`.
    pub snapshot: Option<Snapshot>,
}

impl FmuState {
    pub fn new(mode: Mode, start_time: f64, stop_time: Option<f64>, params: Params, snapshot: Option<Snapshot>) -> Self {
        FmuState { magic: STATE_MAGIC, mode, start_time, stop_time, params, snapshot }
    }
}

pub struct Instance {
    magic: u64,
    env: fmi3InstanceEnvironment,
    logger: fmi3LogMessageCallback,
    logging_on: bool,
    categories: Vec<bool>,
    pub mode: Mode,
    /// Set after a panic: the instance may be inconsistent and only accepts FreeInstance.
    pub poisoned: bool,
    pub params: Params,
    /// Values restored by fmi3Reset: compiled start values or the FMU's resources/startValues.txt.
    start: Params,
    /// Built lazily; `None` or `stale` means parameters changed since.
    sim: Option<Simulator>,
    stale: bool,
    start_time: f64,
    stop_time: Option<f64>,
    /// FMU states made by this instance and not freed yet; only these are
    /// dereferenced, and fmi3FreeInstance frees those the host left.
    states: BTreeSet<usize>,
}

type R = Result<fmi3Status, fmi3Status>;

impl Instance {
    pub fn new(env: fmi3InstanceEnvironment, logger: fmi3LogMessageCallback, logging_on: bool, start: Params) -> Self {
        Instance {
            magic: INSTANCE_MAGIC,
            env,
            logger,
            logging_on,
            categories: vec![true; LOG_CATEGORIES.len()],
            mode: Mode::Instantiated,
            poisoned: false,
            params: start.clone(),
            start,
            sim: None,
            stale: true,
            start_time: 0.0,
            stop_time: None,
            states: BTreeSet::new(),
        }
    }

    /// The instance behind `p`, if `p` is a live instance of this FMU.
    ///
    /// # Safety
    /// The instance must not be used from another thread at the same time
    /// (FMI instances are not thread-safe; different instances are).
    pub unsafe fn from_ptr<'a>(p: fmi3Instance) -> Option<&'a mut Instance> {
        if p.is_null() || !live().contains(&(p as usize)) {
            return None;
        }
        let inst = &mut *(p as *mut Instance);
        (inst.magic == INSTANCE_MAGIC).then_some(inst)
    }

    pub fn into_raw(self) -> fmi3Instance {
        let p = Box::into_raw(Box::new(self)) as fmi3Instance;
        live().insert(p as usize);
        p
    }

    /// Frees a live instance and the FMU states it still owns; anything else is ignored.
    ///
    /// # Safety
    /// As for [`Instance::from_ptr`]; the pointer is invalid afterwards.
    pub unsafe fn free(p: fmi3Instance) {
        if p.is_null() || !live().remove(&(p as usize)) {
            return;
        }
        let inst = &mut *(p as *mut Instance);
        inst.magic = 0;
        drop(Box::from_raw(p as *mut Instance));
    }

    // ---- logging ---------------------------------------------------------

    pub fn log(&self, status: fmi3Status, message: &str) {
        let category = match status {
            OK => "logEvents",
            WARNING => "logStatusWarning",
            DISCARD => "logStatusDiscard",
            ERROR => "logStatusError",
            _ => "logStatusFatal",
        };
        // Failures (discarded steps, errors) always reach the host with their
        // reason; the rest only when asked for.
        let enabled = status >= DISCARD || (self.logging_on && (self.category_on(category) || self.category_on("logAll")));
        if enabled {
            log_raw(self.env, self.logger, status, category, message);
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

    pub fn guard(&self, function: &str, mask: u32) -> Result<(), fmi3Status> {
        if mask & self.mode.bit() == 0 {
            let allowed: Vec<String> = (0..5).filter_map(Mode::from_u8).filter(|m| mask & m.bit() != 0).map(|m| format!("{m:?}")).collect();
            return Err(self.fail(&format!("{function}: illegal call sequence: not allowed in {:?}, only in {}", self.mode, allowed.join(", "))));
        }
        Ok(())
    }

    pub fn set_debug_logging(&mut self, on: bool, n: usize, categories: *const fmi3String) -> R {
        if n > 0 && categories.is_null() {
            return Err(self.fail("fmi3SetDebugLogging: categories is NULL but nCategories > 0"));
        }
        if too_many::<fmi3String>(n) {
            return Err(self.fail(&format!("fmi3SetDebugLogging: nCategories = {n} cannot be an array size")));
        }
        let mut selected = Vec::new();
        for &c in unsafe { slice(categories, n) } {
            if c.is_null() {
                return Err(self.fail("fmi3SetDebugLogging: a category is NULL"));
            }
            let name = unsafe { CStr::from_ptr(c) }.to_string_lossy();
            match LOG_CATEGORIES.iter().position(|x| *x == name) {
                Some(i) => selected.push(i),
                None => return Err(self.fail(&format!("fmi3SetDebugLogging: unknown log category \"{name}\" (known: {})", LOG_CATEGORIES.join(", ")))),
            }
        }
        self.logging_on = on;
        if n == 0 {
            self.categories.iter_mut().for_each(|c| *c = on);
        } else {
            for i in selected {
                self.categories[i] = on;
            }
        }
        Ok(OK)
    }

    // ---- simulator -------------------------------------------------------

    /// Builds the simulator if parameters changed since the last build.
    fn ensure_sim(&mut self) -> R {
        if self.sim.is_none() || self.stale {
            match self.params.build() {
                Ok(sim) => {
                    self.log(OK, &format!("simulator set up: {} nodes in {}D, {} modes", sim.n_nodes(), sim.dimension(), sim.mode_frequencies().len()));
                    self.sim = Some(sim);
                    self.stale = false;
                }
                Err(e) => return Err(self.fail(&format!("cannot set up the simulator: {e}"))),
            }
        }
        Ok(OK)
    }

    pub fn time(&self) -> f64 {
        self.start_time + self.sim.as_ref().filter(|_| !self.stale).map_or(0.0, |s| s.time())
    }

    // ---- mode changes ------------------------------------------------------

    pub fn enter_initialization_mode(&mut self, start_time: f64, stop_time: Option<f64>) -> R {
        self.guard("fmi3EnterInitializationMode", mask::ENTER_INITIALIZATION_MODE)?;
        if !start_time.is_finite() {
            return Err(self.fail(&format!("fmi3EnterInitializationMode: startTime must be finite, got {start_time}")));
        }
        if let Some(stop) = stop_time {
            if stop.is_nan() || stop < start_time {
                return Err(self.fail(&format!("fmi3EnterInitializationMode: stopTime {stop} is before startTime {start_time}")));
            }
        }
        self.start_time = start_time;
        self.stop_time = stop_time;
        self.mode = Mode::InitializationMode;
        Ok(OK)
    }

    pub fn exit_initialization_mode(&mut self) -> R {
        self.guard("fmi3ExitInitializationMode", mask::EXIT_INITIALIZATION_MODE)?;
        self.ensure_sim()?;
        self.mode = Mode::StepMode;
        self.log(OK, "Step Mode");
        Ok(OK)
    }

    pub fn enter_configuration_mode(&mut self) -> R {
        if self.mode == Mode::StepMode {
            return Err(self.fail(
                "fmi3EnterConfigurationMode: the structural parameters are fixed, so there is no Reconfiguration Mode; \
                 use fmi3Reset to change them",
            ));
        }
        self.guard("fmi3EnterConfigurationMode", mask::ENTER_CONFIGURATION_MODE)?;
        self.mode = Mode::ConfigurationMode;
        Ok(OK)
    }

    pub fn exit_configuration_mode(&mut self) -> R {
        self.guard("fmi3ExitConfigurationMode", mask::EXIT_CONFIGURATION_MODE)?;
        self.mode = Mode::Instantiated;
        Ok(OK)
    }

    pub fn terminate(&mut self) -> R {
        self.guard("fmi3Terminate", mask::TERMINATE)?;
        self.mode = Mode::Terminated;
        Ok(OK)
    }

    pub fn reset(&mut self) -> R {
        self.mode = Mode::Instantiated;
        self.params = self.start.clone();
        self.sim = None;
        self.stale = true;
        self.start_time = 0.0;
        self.stop_time = None;
        Ok(OK)
    }

    #[allow(clippy::too_many_arguments)]
    pub fn do_step(
        &mut self,
        t: f64,
        h: f64,
        event_handling_needed: *mut bool,
        terminate_simulation: *mut bool,
        early_return: *mut bool,
        last_successful_time: *mut f64,
    ) -> R {
        self.guard("fmi3DoStep", mask::DO_STEP)?;
        if event_handling_needed.is_null() || terminate_simulation.is_null() || early_return.is_null() || last_successful_time.is_null() {
            return Err(self.fail("fmi3DoStep: an output argument is NULL"));
        }
        let now = self.time();
        unsafe {
            *event_handling_needed = false;
            *terminate_simulation = false;
            *early_return = false;
            *last_successful_time = now;
        }
        if !(h.is_finite() && h > 0.0) {
            return Err(self.fail(&format!("fmi3DoStep: communicationStepSize must be finite and positive, got {h}")));
        }
        if !t.is_finite() || !same_time(t, now) {
            return Err(self.fail(&format!("fmi3DoStep: currentCommunicationPoint {t} does not match the FMU time {now}")));
        }
        if let Some(stop) = self.stop_time {
            let end = now + h;
            if end > stop && !same_time(end, stop) {
                return Err(self.fail(&format!("fmi3DoStep: the step would end at {end}, past stopTime {stop}")));
            }
        }
        let sim = self.sim.as_mut().expect("Step Mode has a simulator");
        match sim.do_step(h) {
            Ok(()) => {
                let end = self.start_time + sim.time();
                unsafe { *last_successful_time = end };
                Ok(OK)
            }
            Err(e) => {
                self.log(DISCARD, &format!("fmi3DoStep: step from t = {now} by {h} s refused, state kept at t = {now}: {e}"));
                Err(DISCARD)
            }
        }
    }

    // ---- Get/Set -----------------------------------------------------------

    /// The value references of a Get/Set call, after the NULL and size checks
    /// of both arrays.
    ///
    /// # Safety
    /// `vrs` must point to `n_vrs` elements unless it is NULL or `n_vrs` is 0.
    unsafe fn value_references<'a, T>(&self, f: &str, vrs: *const u32, n_vrs: usize, values: *const T, n_values: usize) -> Result<&'a [u32], fmi3Status> {
        if n_vrs > 0 && vrs.is_null() {
            return Err(self.fail(&format!("{f}: valueReferences is NULL but nValueReferences = {n_vrs}")));
        }
        if n_values > 0 && values.is_null() {
            return Err(self.fail(&format!("{f}: values is NULL but nValues = {n_values}")));
        }
        if too_many::<u32>(n_vrs) || too_many::<T>(n_values) {
            return Err(self.fail(&format!("{f}: nValueReferences = {n_vrs} or nValues = {n_values} cannot be an array size")));
        }
        Ok(slice(vrs, n_vrs))
    }

    /// Looks up every value reference, checks its type and counts the values.
    fn resolve(&self, f: &str, ty: Type, vrs: &[u32], n_values: usize) -> Result<(), fmi3Status> {
        let mut total = 0usize;
        for &r in vrs {
            let Some(i) = index_of(r) else {
                return Err(self.fail(&format!("{f}: unknown value reference {r}")));
            };
            let v = &VARIABLES[i];
            if v.ty != ty {
                return Err(self.fail(&format!("{f}: {} (value reference {r}) is accessed with fmi3Get/Set{}", v.name, v.ty.name())));
            }
            total = total.saturating_add(self.params.size_of(v));
        }
        if total != n_values {
            return Err(self.fail(&format!("{f}: nValues = {n_values}, but the {} value references hold {total} values", vrs.len())));
        }
        Ok(())
    }

    /// # Safety
    /// `vrs` and `values` must point to `n_vrs` / `n_values` elements (or be null when that is 0).
    pub unsafe fn get<T>(&mut self, f: &str, ty: Type, vrs: *const u32, n_vrs: usize, values: *mut T, n_values: usize, conv: impl Fn(f64) -> T) -> R {
        self.guard(f, mask::GET)?;
        let vrs = self.value_references(f, vrs, n_vrs, values as *const T, n_values)?;
        // nValues is checked against the variables before `values` is touched.
        self.resolve(f, ty, vrs, n_values)?;
        let needs_sim = vrs.iter().any(|&r| {
            let v = &VARIABLES[index_of(r).unwrap()];
            !v.is_parameter() && v.causality != Causality::Independent
        });
        if needs_sim {
            self.ensure_sim()?;
        }
        let out = slice_mut(values, n_values);
        let mut k = 0;
        for &r in vrs {
            let i = index_of(r).unwrap();
            let v = &VARIABLES[i];
            let n = self.params.size_of(v);
            if v.is_parameter() {
                for (o, x) in out[k..k + n].iter_mut().zip(&self.params.values[i]) {
                    *o = conv(*x);
                }
            } else if v.causality == Causality::Independent {
                out[k] = conv(self.time());
            } else {
                match computed(self.sim.as_ref().unwrap(), r, self.start_time) {
                    Computed::Scalar(x) => out[k] = conv(x),
                    Computed::Array(a) => {
                        if a.len() != n {
                            return Err(self.fail(&format!("{f}: {} holds {} values, expected {n}", v.name, a.len())));
                        }
                        for (o, x) in out[k..k + n].iter_mut().zip(a) {
                            *o = conv(*x);
                        }
                    }
                }
            }
            k += n;
        }
        Ok(OK)
    }

    fn settable(&self, v: &Variable) -> Result<(), String> {
        let allowed = match (v.causality, v.variability) {
            (Causality::StructuralParameter, _) => Mode::Instantiated.bit() | Mode::ConfigurationMode.bit(),
            (Causality::Parameter, Variability::Fixed) => Mode::Instantiated.bit() | Mode::InitializationMode.bit(),
            (Causality::Parameter, Variability::Tunable) => Mode::Instantiated.bit() | Mode::InitializationMode.bit() | Mode::StepMode.bit(),
            _ => return Err(format!("{} is a {:?} and cannot be set", v.name, v.causality)),
        };
        if allowed & self.mode.bit() == 0 {
            return Err(format!("{} ({:?}, {:?}) cannot be set in {:?}", v.name, v.causality, v.variability, self.mode));
        }
        Ok(())
    }

    /// # Safety
    /// As for [`Instance::get`]. Either every value is stored or none.
    pub unsafe fn set<T: Copy + std::fmt::Debug>(
        &mut self,
        f: &str,
        ty: Type,
        vrs: *const u32,
        n_vrs: usize,
        values: *const T,
        n_values: usize,
        conv: impl Fn(T) -> Option<f64>,
    ) -> R {
        self.guard(f, mask::SET)?;
        let vrs = self.value_references(f, vrs, n_vrs, values, n_values)?;
        // nValues is checked against the variables before `values` is read.
        self.resolve(f, ty, vrs, n_values)?;
        let values = slice(values, n_values);
        let mut k = 0;
        for &r in vrs {
            let v = &VARIABLES[index_of(r).unwrap()];
            if let Err(m) = self.settable(v) {
                return Err(self.fail(&format!("{f}: {m}")));
            }
            let n = self.params.size_of(v);
            for (j, &raw) in values[k..k + n].iter().enumerate() {
                let x = conv(raw);
                if let Err(m) = check_value(v, x) {
                    let at = if v.dims.is_empty() { String::new() } else { format!("[{j}]") };
                    return Err(self.fail(&format!("{f}: {}{at} = {raw:?} refused: {m}", v.name)));
                }
            }
            k += n;
        }
        let old = self.params.clone();
        let mut k = 0;
        let mut structure = false;
        let mut tunable = false;
        for &r in vrs {
            let i = index_of(r).unwrap();
            let v = &VARIABLES[i];
            let n = old.size_of(v);
            for (dst, &raw) in self.params.values[i].iter_mut().zip(&values[k..k + n]) {
                *dst = conv(raw).unwrap();
            }
            structure |= v.causality == Causality::StructuralParameter;
            tunable |= v.variability == Variability::Tunable;
            k += n;
        }
        if structure {
            self.params.fit_arrays();
        }
        if self.params == old {
            return Ok(OK);
        }
        if self.mode == Mode::StepMode {
            // Only tunables get here; they act from the next step on.
            debug_assert!(tunable);
            let t = self.params.tunables();
            if let Err(e) = self.sim.as_mut().unwrap().set_tunables(&t) {
                self.params = old;
                return Err(self.fail(&format!("{f}: {e}")));
            }
        } else {
            self.stale = true;
        }
        Ok(OK)
    }

    // ---- FMU state -------------------------------------------------------

    pub fn capture(&self) -> FmuState {
        let snapshot = self.sim.as_ref().filter(|_| !self.stale).map(|s| s.snapshot());
        FmuState::new(self.mode, self.start_time, self.stop_time, self.params.clone(), snapshot)
    }

    /// The state behind `state` if this instance made it and has not freed it;
    /// anything else (NULL, freed, another instance's) is refused unread.
    pub fn state_from_ptr<'a>(&self, f: &str, state: fmi3FMUState) -> Result<&'a mut FmuState, fmi3Status> {
        if state.is_null() {
            return Err(self.fail(&format!("{f}: FMUState is NULL")));
        }
        if !self.states.contains(&(state as usize)) {
            return Err(self.fail(&format!("{f}: FMUState is not a live state of this instance (freed, or made by another one)")));
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
            return Err(self.fail(&format!("{f}: FMUState is NULL")));
        }
        if !(*out).is_null() {
            let existing = self.state_from_ptr(f, *out)?;
            *existing = s;
        } else {
            let p = Box::into_raw(Box::new(s)) as fmi3FMUState;
            self.states.insert(p as usize);
            *out = p;
        }
        Ok(OK)
    }

    /// # Safety
    /// `out` must be null or point to a readable and writable state pointer.
    pub unsafe fn free_state(&mut self, out: *mut fmi3FMUState) -> R {
        const F: &str = "fmi3FreeFMUState";
        if out.is_null() {
            return Err(self.fail(&format!("{F}: FMUState is NULL")));
        }
        if (*out).is_null() {
            return Ok(OK);
        }
        let s = self.state_from_ptr(F, *out)?;
        s.magic = 0;
        self.states.remove(&(*out as usize));
        drop(Box::from_raw(s as *mut FmuState));
        *out = std::ptr::null_mut();
        Ok(OK)
    }

    /// Makes `s` the current state; on error the instance is unchanged.
    pub fn restore(&mut self, s: &FmuState) -> R {
        let sim = match &s.snapshot {
            Some(snap) => {
                let reuse = self.sim.is_some() && !self.stale && self.params.same_fixed(&s.params);
                let mut sim = if reuse {
                    None
                } else {
                    match s.params.build() {
                        Ok(sim) => Some(sim),
                        Err(e) => return Err(self.fail(&format!("fmi3SetFMUState: cannot set up the simulator: {e}"))),
                    }
                };
                // Restoring in place must be undoable: the state may be refused after it.
                let prior = if reuse { self.sim.as_ref().map(|s| s.snapshot()) } else { None };
                let target = sim.as_mut().or(self.sim.as_mut()).unwrap();
                if let Err(e) = target.restore(snap) {
                    return Err(self.fail(&format!("fmi3SetFMUState: {e}")));
                }
                if !outputs_finite(target) {
                    if let Some(p) = prior {
                        let _ = target.restore(&p);
                    }
                    return Err(self.fail("fmi3SetFMUState: the state gives non-finite outputs (positions, velocities or energies)"));
                }
                sim
            }
            None => None,
        };
        if s.snapshot.is_some() {
            if let Some(sim) = sim {
                self.sim = Some(sim);
            }
            self.stale = false;
        } else {
            self.stale = true;
        }
        self.params = s.params.clone();
        self.mode = s.mode;
        self.start_time = s.start_time;
        self.stop_time = s.stop_time;
        Ok(OK)
    }

    pub fn structural(&self) -> Vec<(&'static str, f64)> {
        VARIABLES.iter().enumerate().filter(|(_, v)| v.causality == Causality::StructuralParameter).map(|(i, v)| (v.name, self.params.values[i][0])).collect()
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        for p in std::mem::take(&mut self.states) {
            // SAFETY: every address in `states` is a live Box<FmuState> made by `store_state`.
            let s = unsafe { &mut *(p as *mut FmuState) };
            s.magic = 0;
            drop(unsafe { Box::from_raw(p as *mut FmuState) });
        }
    }
}

/// Every output of the simulator is a finite number.
pub fn outputs_finite(sim: &Simulator) -> bool {
    [sim.positions(), sim.velocities(), sim.modal_coordinates(), &[sim.kinetic_energy(), sim.potential_energy()]]
        .iter()
        .all(|a| a.iter().all(|x| x.is_finite()))
}

/// Range checks from the model description; `None` means not representable.
pub fn check_value(v: &Variable, x: Option<f64>) -> Result<(), String> {
    let x = x.ok_or("out of the range this FMU can store")?;
    if !x.is_finite() {
        return Err("not finite".into());
    }
    if let Some(min) = v.min {
        if x < min {
            return Err(format!("below min = {min}"));
        }
    }
    if let Some(max) = v.max {
        if x > max {
            return Err(format!("above max = {max}"));
        }
    }
    if !v.enum_values.is_empty() && !v.enum_values.iter().any(|&e| e as f64 == x) {
        return Err(format!("not one of the enumeration values {:?}", v.enum_values));
    }
    Ok(())
}

/// Logs through the host's callback (also before an instance exists).
pub fn log_raw(env: fmi3InstanceEnvironment, logger: fmi3LogMessageCallback, status: fmi3Status, category: &str, message: &str) {
    if let Some(cb) = logger {
        let cat = CString::new(category).unwrap_or_default();
        let msg = CString::new(message.replace('\0', " ")).unwrap_or_default();
        unsafe { cb(env, status, cat.as_ptr(), msg.as_ptr()) };
    }
}

/// True if `n` elements of `T` cannot be one array in memory: such a count is
/// refused before it reaches `slice::from_raw_parts` (whose contract it breaks).
pub fn too_many<T>(n: usize) -> bool {
    n > isize::MAX as usize / std::mem::size_of::<T>().max(1)
}

/// Slice from a C array; a null pointer is fine when `n` is 0.
///
/// # Safety
/// Unless `n` is 0, `p` must point to `n` readable elements; callers check
/// `p` for NULL and `n` with [`too_many`] first.
pub unsafe fn slice<'a, T>(p: *const T, n: usize) -> &'a [T] {
    if n == 0 || p.is_null() || too_many::<T>(n) {
        &[]
    } else {
        std::slice::from_raw_parts(p, n)
    }
}

/// # Safety
/// As for [`slice`], writable.
pub unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> &'a mut [T] {
    if n == 0 || p.is_null() || too_many::<T>(n) {
        &mut []
    } else {
        std::slice::from_raw_parts_mut(p, n)
    }
}
