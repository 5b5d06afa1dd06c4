//! `resources/startValues.txt`: the start values of one FMU as plain text,
//! read by the binary at instantiation.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use super::Spec;

impl Spec {
    /// `resources/startValues.txt`: one line per parameter, `name value...`,
    /// read by the binary at instantiation (importers need not apply the
    /// start values of modelDescription.xml themselves).
    pub fn start_values_text(&self, overrides: &BTreeMap<String, Vec<f64>>) -> Result<String, String> {
        let starts = self.starts(overrides)?;
        let mut t = String::from("# Start values of this FMU, generated with its modelDescription.xml\n");
        for v in self.variables.iter().filter(|v| v.has_start()) {
            let s: Vec<String> = starts[&v.name].iter().map(|x| format!("{x:?}")).collect();
            let _ = writeln!(t, "{} {}", v.name, s.join(" "));
        }
        Ok(t)
    }
}
