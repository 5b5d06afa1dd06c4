//! The interface between the generic glue and the model it exports, in the
//! manner of the Modelica Reference FMUs' `model.h`: the glue checks calls,
//! states, types, sizes and ranges against the generated variable table and
//! stores the values ([`Params`]); the model says what the values mean, sets
//! itself up, steps, computes the outputs and words its own refusals. The
//! glue names no variable of the model and knows none of its rules.

use std::path::Path;

use super::logging::Logger;
use super::params::Params;
use crate::bytes::Reader;

/// Value of a variable that the model computes (an output, a calculated parameter).
pub enum Computed<'a> {
    Scalar(f64),
    Array(&'a [f64]),
    /// The value cannot be given, and why (the glue logs it and returns fmi3Error).
    Refused(String),
}

/// How a communication step ended that the model took.
pub enum StepEnd {
    Done,
    /// Taken, with a warning for the host (the glue logs it and returns fmi3Warning).
    Warning(String),
    /// Taken, with an event for the log (the glue logs it in the category
    /// logEvents when logging is on, and returns fmi3OK).
    Event(String),
}

/// A model the glue exports. Messages returned as `Err` are complete
/// sentences for the host; the glue prefixes the function's name.
pub trait Model {
    /// What an FMU state holds of the model beyond the values.
    type Snapshot: Clone + std::fmt::Debug;

    /// The model of a new instance; `resources` is the FMU's resources
    /// folder, if the host gave one.
    fn new(resources: Option<&Path>) -> Self;

    /// fmi3Reset: back to as new, keeping what was read from the resources.
    fn reset(&mut self);

    /// True if the model is set up for the current values.
    fn is_set_up(&self) -> bool;

    /// Set-up from the values `p` (before an output is read, at the end
    /// of initialization); what it did goes to `log`.
    fn set_up(&mut self, p: &Params, log: &Logger) -> Result<(), String>;

    /// The model's time since set-up, when set up.
    fn time(&self) -> Option<f64>;

    /// After the glue checked and stored the values of `vrs` in `p`, with
    /// `old` the values before: the model's own rules and checks, and with
    /// `running` (Step Mode) the new values passed to the running model. On
    /// `Err` the glue restores `old`: a Set stores all or nothing. Must not
    /// allocate when running.
    fn set(&mut self, p: &mut Params, old: &Params, vrs: &[u32], running: bool) -> Result<(), String>;

    /// The value of the computed variable `vr` (the model is set up);
    /// `time0` is the start time of the run. Must not allocate for a scalar
    /// in Step Mode.
    fn output(&mut self, vr: u32, time0: f64) -> Computed<'_>;

    /// One communication step of `h` (the model is set up); `Err` is why it
    /// was refused, the model's state kept at its start. Must not allocate
    /// when it returns [`StepEnd::Done`].
    fn do_step(&mut self, p: &Params, h: f64, time0: f64) -> Result<StepEnd, String>;

    /// The state to resume from, when set up.
    fn snapshot(&self) -> Option<Self::Snapshot>;

    /// Resumes from `snap` with the values `p` (`current` are the values now);
    /// without a snapshot the model sets up again on demand. On `Err`
    /// nothing changed.
    fn restore(&mut self, current: &Params, p: &Params, snap: Option<&Self::Snapshot>) -> Result<(), String>;

    /// Appends `s` to a serialized FMU state.
    fn write_snapshot(s: &Self::Snapshot, out: &mut Vec<u8>);

    /// Reads what [`Model::write_snapshot`] wrote, in serialized-state
    /// format `format` (the current one, or an older one still read).
    fn read_snapshot(r: &mut Reader, format: u32) -> Result<Self::Snapshot, String>;

    /// Refuses a deserialized snapshot that does not belong to the values `p`.
    fn check_snapshot(s: &Self::Snapshot, p: &Params) -> Result<(), String>;
}
