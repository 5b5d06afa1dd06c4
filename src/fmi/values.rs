//! Value access: fmi3Get/Set of every type, marshalled between the host's
//! arrays and the variable table, with the NULL, size, type, state and
//! range checks. A Set stores every value or none.

use super::state_machine::Mode;
use super::variables::{Causality, Variability, Variable};

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

/// The states a variable of this causality and variability may be set in
/// (FMI 3.0, section 2.3.3 and the Co-Simulation state machine), with the
/// FMU's extension that structural parameters may also be set in
/// Instantiated. `None`: never (outputs, calculated parameters, the time).
pub fn settable_in(causality: Causality, variability: Variability) -> Option<u32> {
    use Mode::*;
    match (causality, variability) {
        (Causality::StructuralParameter, _) => Some(Instantiated.bit() | ConfigurationMode.bit()),
        (Causality::Parameter, Variability::Fixed) => Some(Instantiated.bit() | InitializationMode.bit()),
        (Causality::Parameter, Variability::Tunable) => Some(Instantiated.bit() | InitializationMode.bit() | StepMode.bit()),
        (Causality::Input, _) => Some(Instantiated.bit() | InitializationMode.bit() | StepMode.bit()),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inputs_are_settable_where_fmi3_allows() {
        let states = settable_in(Causality::Input, Variability::Continuous).unwrap();
        for m in Mode::ALL {
            let allowed = matches!(m, Mode::Instantiated | Mode::InitializationMode | Mode::StepMode);
            assert_eq!(states & m.bit() != 0, allowed, "{m:?}");
        }
        assert_eq!(settable_in(Causality::Output, Variability::Continuous), None);
        assert_eq!(settable_in(Causality::CalculatedParameter, Variability::Fixed), None);
        assert_eq!(settable_in(Causality::Independent, Variability::Continuous), None);
    }
}
