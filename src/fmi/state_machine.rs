//! The FMI 3.0 Co-Simulation state machine this FMU implements (no Event
//! Mode, no intermediate update, no clocks): its states, and the calls that
//! move an instance between them. Which function is legal in which state is
//! [`super::functions`]'s table; the check is in [`Instance::guard`].

use super::functions::Function;
use super::instance::Instance;
use super::model::Model;
use super::OK;

/// States an instance can be in.
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
    pub const ALL: [Mode; 5] = [Mode::Instantiated, Mode::ConfigurationMode, Mode::InitializationMode, Mode::StepMode, Mode::Terminated];

    /// This state's bit in a mask of states.
    pub const fn bit(self) -> u32 {
        1 << self as u32
    }

    pub fn from_u8(x: u8) -> Option<Mode> {
        Mode::ALL.get(x as usize).copied()
    }
}

/// Masks of states.
pub mod mask {
    use super::Mode::*;
    pub const NONE: u32 = 0;
    pub const ANY: u32 = Instantiated.bit() | ConfigurationMode.bit() | InitializationMode.bit() | StepMode.bit() | Terminated.bit();
    pub const INSTANTIATED: u32 = Instantiated.bit();
    pub const CONFIGURATION: u32 = ConfigurationMode.bit();
    pub const INITIALIZATION: u32 = InitializationMode.bit();
    pub const STEP: u32 = StepMode.bit();
    /// Set: every state before Terminated.
    pub const SET: u32 = ANY & !Terminated.bit();
}

/// Two times within rounding of each other (communication points and stop
/// times accumulated differently by the importer).
pub fn same_time(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1.0)
}

type R = Result<fmi3Status, fmi3Status>;
use fmi_sys::fmi3::fmi3Status;

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
