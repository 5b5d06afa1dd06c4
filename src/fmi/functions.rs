//! The table of the exported `fmi3*` functions: the states each is legal
//! in, or why this FMU does not provide it. [`super::exports`] writes one
//! short entry per function that names its row here; the check against
//! the table is [`super::instance::Instance::guard`], in one place.

use super::state_machine::mask::*;

/// Where a function may be called, and what a refusal adds.
#[derive(Clone, Copy, Debug)]
pub struct Legal {
    /// Mask of [`super::state_machine::Mode`] bits; [`NONE`] for a function this FMU does not provide.
    pub states: u32,
    /// Why the function is not provided, or a note on the states it is refused in.
    pub note: &'static str,
}

const fn only(states: u32) -> Legal {
    Legal { states, note: "" }
}

const fn noted(states: u32, note: &'static str) -> Legal {
    Legal { states, note }
}

const fn unsupported(reason: &'static str) -> Legal {
    Legal { states: NONE, note: reason }
}

const NO_ME: &str = "this FMU supports Co-Simulation only, not Model Exchange";
const NO_SE: &str = "this FMU supports Co-Simulation only, not Scheduled Execution";
const NO_CLOCKS: &str = "this FMU has no clocks";
const NO_EVENTS: &str = "this FMU has no Event Mode (hasEventMode = false)";
const NO_DEPENDENCIES: &str = "variable dependencies are not provided (every output depends on every parameter)";

macro_rules! functions {
    ($($name:ident: $legal:expr;)*) => {
        /// Every function of the FMI 3.0 C API.
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum Function {
            $($name,)*
        }

        impl Function {
            pub const ALL: &'static [Function] = &[$(Function::$name),*];

            /// The C name, `fmi3...`.
            pub const fn name(self) -> &'static str {
                match self {
                    $(Function::$name => concat!("fmi3", stringify!($name)),)*
                }
            }

            pub const fn legal(self) -> Legal {
                match self {
                    $(Function::$name => $legal,)*
                }
            }
        }
    };
}

functions! {
    // Common functions; GetVersion, the Instantiate functions and FreeInstance take no instance.
    GetVersion: only(ANY);
    SetDebugLogging: only(ANY);
    InstantiateModelExchange: unsupported(NO_ME);
    InstantiateCoSimulation: only(ANY);
    InstantiateScheduledExecution: unsupported(NO_SE);
    FreeInstance: only(ANY);
    EnterInitializationMode: only(INSTANTIATED);
    ExitInitializationMode: only(INITIALIZATION);
    EnterEventMode: unsupported(NO_EVENTS);
    Terminate: only(STEP);
    Reset: only(ANY);
    // Values: read in every state (parameters, outputs and the time are
    // always defined), written until Terminated (each variable's own
    // states are checked by its causality and variability).
    GetFloat32: only(ANY);
    GetFloat64: only(ANY);
    GetInt8: only(ANY);
    GetUInt8: only(ANY);
    GetInt16: only(ANY);
    GetUInt16: only(ANY);
    GetInt32: only(ANY);
    GetUInt32: only(ANY);
    GetInt64: only(ANY);
    GetUInt64: only(ANY);
    GetBoolean: only(ANY);
    GetString: only(ANY);
    GetBinary: only(ANY);
    GetClock: only(ANY);
    SetFloat32: only(SET);
    SetFloat64: only(SET);
    SetInt8: only(SET);
    SetUInt8: only(SET);
    SetInt16: only(SET);
    SetUInt16: only(SET);
    SetInt32: only(SET);
    SetUInt32: only(SET);
    SetInt64: only(SET);
    SetUInt64: only(SET);
    SetBoolean: only(SET);
    SetString: only(SET);
    SetBinary: only(SET);
    SetClock: only(SET);
    GetNumberOfVariableDependencies: unsupported(NO_DEPENDENCIES);
    GetVariableDependencies: unsupported(NO_DEPENDENCIES);
    // FMU state: every state.
    GetFMUState: only(ANY);
    SetFMUState: only(ANY);
    FreeFMUState: only(ANY);
    SerializedFMUStateSize: only(ANY);
    SerializeFMUState: only(ANY);
    DeserializeFMUState: only(ANY);
    GetDirectionalDerivative: unsupported("directional derivatives are not provided (providesDirectionalDerivatives = false)");
    GetAdjointDerivative: unsupported("adjoint derivatives are not provided (providesAdjointDerivatives = false)");
    EnterConfigurationMode: noted(
        INSTANTIATED,
        "the structural parameters are fixed after initialization, so there is no Reconfiguration Mode; use fmi3Reset to change them"
    );
    ExitConfigurationMode: only(CONFIGURATION);
    GetIntervalDecimal: unsupported(NO_CLOCKS);
    GetIntervalFraction: unsupported(NO_CLOCKS);
    GetShiftDecimal: unsupported(NO_CLOCKS);
    GetShiftFraction: unsupported(NO_CLOCKS);
    SetIntervalDecimal: unsupported(NO_CLOCKS);
    SetIntervalFraction: unsupported(NO_CLOCKS);
    SetShiftDecimal: unsupported(NO_CLOCKS);
    SetShiftFraction: unsupported(NO_CLOCKS);
    EvaluateDiscreteStates: unsupported("discrete states are not provided (providesEvaluateDiscreteStates = false)");
    UpdateDiscreteStates: unsupported(NO_EVENTS);
    // Model Exchange
    EnterContinuousTimeMode: unsupported(NO_ME);
    CompletedIntegratorStep: unsupported(NO_ME);
    SetTime: unsupported(NO_ME);
    SetContinuousStates: unsupported(NO_ME);
    GetContinuousStateDerivatives: unsupported(NO_ME);
    GetEventIndicators: unsupported(NO_ME);
    GetContinuousStates: unsupported(NO_ME);
    GetNominalsOfContinuousStates: unsupported(NO_ME);
    GetNumberOfEventIndicators: unsupported(NO_ME);
    GetNumberOfContinuousStates: unsupported(NO_ME);
    // Co-Simulation
    EnterStepMode: unsupported(
        "Step Mode is entered from Event Mode, which this FMU does not have (hasEventMode = false); fmi3ExitInitializationMode enters Step Mode"
    );
    GetOutputDerivatives: unsupported("output derivatives are not provided (maxOutputDerivativeOrder = 0)");
    DoStep: only(STEP);
    // Scheduled Execution
    ActivateModelPartition: unsupported(NO_SE);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_covers_the_standard_once() {
        assert_eq!(Function::ALL.len(), 75);
        let mut names: Vec<&str> = Function::ALL.iter().map(|f| f.name()).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), 75);
        // Every function this FMU does not provide says why.
        for f in Function::ALL {
            assert!(f.legal().states != NONE || !f.legal().note.is_empty(), "{}", f.name());
        }
    }
}
