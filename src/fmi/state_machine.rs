//! The FMI 3.0 Co-Simulation state machine this FMU implements (no Event
//! Mode, no intermediate update, no clocks): its states, and the calls that
//! move an instance between them. Which function is legal in which state is
//! [`super::functions`]'s table; the check is in `Instance::guard` (`instance/transitions.rs`).

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
