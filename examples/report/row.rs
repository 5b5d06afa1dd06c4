//! One run of the study: a row of `error_vs_runtime.csv`, whose header is
//! the field names below in their order.

use serde::{Serialize, Serializer};

/// A run as the CSV has it. Floats are written with 7 significant digits
/// (`{:.6e}`), the step and the window in Rust's shortest form.
#[derive(Serialize)]
pub struct Row {
    pub scene: String,
    pub method: &'static str,
    pub integrator: &'static str,
    pub modes: usize,
    #[serde(serialize_with = "shortest")]
    pub step: f64,
    pub internal_steps: usize,
    #[serde(serialize_with = "sci7")]
    pub setup_s: f64,
    #[serde(serialize_with = "sci7")]
    pub run_s_per_sim_s: f64,
    #[serde(serialize_with = "sci7")]
    pub error: f64,
    #[serde(serialize_with = "sci7")]
    pub max_node_error: f64,
    pub stable: bool,
    /// E of this run against the full-space run with the same integrator and step.
    #[serde(serialize_with = "sci7")]
    pub vs_full: f64,
    /// E over the output times up to `resolved_until_s` (see [`crate::plan::REFERENCE_MARGIN`]).
    #[serde(serialize_with = "sci7")]
    pub error_resolved: f64,
    #[serde(serialize_with = "shortest")]
    pub resolved_until_s: f64,
    pub dofs: usize,
    pub step_label: String,
    /// Key of the variant ("full" in full space).
    pub variant: &'static str,
    /// Largest and mean `forceResidual` over the output times after t = 0.
    #[serde(serialize_with = "sci7")]
    pub force_residual_max: f64,
    #[serde(serialize_with = "sci7")]
    pub force_residual_mean: f64,
    /// Springs one force evaluation visits (every spring, or the cubature set).
    pub springs_visited: Option<usize>,
    /// The same run's wall time without reading the node positions (a host
    /// that couples through the ports or reads the modal coordinates).
    #[serde(serialize_with = "sci7")]
    pub step_s_per_sim_s: f64,
    pub note: String,
    /// E over [0, `window_s`]: the headline E of the run (see [`crate::fidelity`]).
    #[serde(serialize_with = "sci7")]
    pub error_window: f64,
    /// The shorter of the scene's predictability horizon and the window the
    /// reference resolves [s].
    #[serde(serialize_with = "shortest")]
    pub window_s: f64,
    /// The scene's predictability horizon T_p (NaN: the twins stay within
    /// [`crate::fidelity::PREDICTABLE_E`] over the whole run) [s].
    #[serde(serialize_with = "shortest")]
    pub predictable_until_s: f64,
    /// The scene's twins' largest E over the whole run.
    #[serde(serialize_with = "sci7")]
    pub twin_floor: f64,
    /// Per coarse observable ([`crate::fidelity::OBSERVABLES`]): the run's
    /// deviation from the reference over the whole run, over the twins' spread.
    #[serde(serialize_with = "sci7")]
    pub force_vs_twins: f64,
    #[serde(serialize_with = "sci7")]
    pub bottom_vs_twins: f64,
    #[serde(serialize_with = "sci7")]
    pub kinetic_vs_twins: f64,
    #[serde(serialize_with = "sci7")]
    pub potential_vs_twins: f64,
    /// Adaptive runs (NaN or empty for the others): the error tolerance;
    /// `errorEstimate` at the end of the run and at the end of the window
    /// (the estimate of `error` and of `error_window`); the share of
    /// internal steps taken reduced; the basis size at the end (`modes`:
    /// at set-up; the free DOFs while in full space).
    #[serde(serialize_with = "shortest")]
    pub error_tolerance: f64,
    #[serde(serialize_with = "sci7")]
    pub error_estimate: f64,
    #[serde(serialize_with = "sci7")]
    pub estimate_window: f64,
    #[serde(serialize_with = "sci7")]
    pub reduced_fraction: f64,
    pub basis_size_end: Option<usize>,
}

impl Row {
    /// The run's deviations from the reference over the twins' spread, in
    /// the order of [`crate::fidelity::OBSERVABLES`].
    pub fn vs_twins(&self) -> [f64; 4] {
        [self.force_vs_twins, self.bottom_vs_twins, self.kinetic_vs_twins, self.potential_vs_twins]
    }

    /// A modal run that leaves modes out.
    pub fn leaves_out(&self) -> bool {
        self.method == "modal" && self.modes < self.dofs
    }
}

/// The precision of the CSV: 7 significant digits.
pub fn sci7_text(x: f64) -> String {
    format!("{x:.6e}")
}

fn sci7<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(&sci7_text(*x))
}

fn shortest<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(&x.to_string())
}

/// Writes `error_vs_runtime.csv` into `out`.
pub fn write_csv(out: &str, rows: &[Row]) -> Result<(), csv::Error> {
    let mut w = csv::Writer::from_path(format!("{out}/error_vs_runtime.csv"))?;
    for r in rows {
        w.serialize(r)?;
    }
    w.flush()?;
    Ok(())
}

pub fn describe(r: &Row) -> String {
    if r.method == "full" {
        format!("full {} step {}", r.integrator, r.step_label)
    } else if r.method == "adaptive" {
        format!("adaptive tol {} {} step {}", r.error_tolerance, r.integrator, r.step_label)
    } else {
        format!("modal {} {} r={} step {}", r.variant, r.integrator, r.modes, r.step_label)
    }
}

pub fn short(integrator: &str) -> &str {
    integrator.strip_prefix("newmark-").unwrap_or(integrator)
}
