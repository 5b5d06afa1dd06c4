//! The calls that move an instance between the states of
//! [`crate::fmi::state_machine`], and the guard that checks every call
//! against [`crate::fmi::functions`]'s table.

use fmi_sys::fmi3::fmi3Status;

use super::{Instance, R};
use crate::fmi::functions::Function;
use crate::fmi::model::Model;
use crate::fmi::state_machine::{mask, Mode};
use crate::status::OK;

impl Instance {
    /// Refuses `f` unless the table allows it in the current state,
    /// logging why: the one place where states are checked.
    pub fn guard(&self, f: Function) -> Result<(), fmi3Status> {
        let legal = f.legal();
        if legal.states & self.mode.bit() != 0 {
            return Ok(());
        }
        if legal.states == mask::NONE {
            return Err(self.log.fail(&format!("{}: {}", f.name(), legal.note)));
        }
        let allowed: Vec<String> = Mode::ALL.iter().filter(|m| legal.states & m.bit() != 0).map(|m| format!("{m:?}")).collect();
        let note = if legal.note.is_empty() { String::new() } else { format!(" ({})", legal.note) };
        Err(self.log.fail(&format!("{}: illegal call sequence: not allowed in {:?}, only in {}{note}", f.name(), self.mode, allowed.join(", "))))
    }

    pub fn enter_initialization_mode(&mut self, start_time: f64, stop_time: Option<f64>) -> R {
        const F: &str = "fmi3EnterInitializationMode";
        if !start_time.is_finite() {
            return Err(self.log.fail(&format!("{F}: startTime must be finite, got {start_time}")));
        }
        if let Some(stop) = stop_time {
            if stop.is_nan() || stop < start_time {
                return Err(self.log.fail(&format!("{F}: stopTime {stop} is before startTime {start_time}")));
            }
        }
        self.start_time = start_time;
        self.stop_time = stop_time;
        self.mode = Mode::InitializationMode;
        Ok(OK)
    }

    pub fn exit_initialization_mode(&mut self) -> R {
        self.ensure_set_up()?;
        self.mode = Mode::StepMode;
        self.log.log(OK, "Step Mode");
        Ok(OK)
    }

    pub fn enter_configuration_mode(&mut self) -> R {
        self.mode = Mode::ConfigurationMode;
        Ok(OK)
    }

    pub fn exit_configuration_mode(&mut self) -> R {
        self.mode = Mode::Instantiated;
        Ok(OK)
    }

    pub fn terminate(&mut self) -> R {
        self.mode = Mode::Terminated;
        Ok(OK)
    }

    /// Back to Instantiated with the start values.
    pub fn reset(&mut self) -> R {
        self.mode = Mode::Instantiated;
        self.params = self.start.clone();
        self.model.reset();
        self.start_time = 0.0;
        self.stop_time = None;
        Ok(OK)
    }
}
