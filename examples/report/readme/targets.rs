//! The targets table, and the selections of runs it and the speed-up
//! tables share.

use std::fmt::Write as _;

use modal_mass_spring::physics::Integrator;

use crate::plan::{Variant, LOAD, LOAD_STATIC, TRAINED, TRAINED_CUBATURE};
use crate::row::{describe, short, Row};

/// What a speed-up compares: the run time with the positions read at every
/// output time, or the steps alone.
#[derive(Clone, Copy, PartialEq)]
pub enum Cost {
    Run,
    Steps,
}

impl Cost {
    fn of(self, r: &Row) -> f64 {
        match self {
            Cost::Run => r.run_s_per_sim_s,
            Cost::Steps => r.step_s_per_sim_s,
        }
    }
}

/// For a modal run: the fastest full-space run whose error (over the
/// window, `error_window`) is at most the modal run's, and the ratio of their
/// run times as `cost` names them (> 1: modal is faster).
fn speedup_by<'a>(modal: &Row, rows: &[&'a Row], cost: Cost) -> Option<(&'a Row, f64)> {
    rows.iter()
        .copied()
        .filter(|f| f.method == "full" && f.stable && f.error_window <= modal.error_window)
        .min_by(|a, b| cost.of(a).total_cmp(&cost.of(b)))
        .map(|f| (f, cost.of(f) / cost.of(modal)))
}

/// The best leave-out run of `rows` (those `keep` accepts) with an error
/// (over the window, `error_window`) of at most `limit`: the one with the largest
/// speed-up over the fastest full-space run at least as accurate; if no
/// full-space run is as accurate as any of them, the most accurate, unmatched.
pub fn best_leave_out<'a>(rows: &[&'a Row], limit: f64, keep: &dyn Fn(&Row) -> bool) -> Option<(&'a Row, Option<(&'a Row, f64)>)> {
    best_leave_out_by(rows, limit, keep, Cost::Run)
}

/// [`best_leave_out`] by the run times `cost` names.
fn best_leave_out_by<'a>(rows: &[&'a Row], limit: f64, keep: &dyn Fn(&Row) -> bool, cost: Cost) -> Option<(&'a Row, Option<(&'a Row, f64)>)> {
    let candidates: Vec<&Row> = rows.iter().copied().filter(|r| r.leaves_out() && r.stable && r.error_window <= limit && keep(r)).collect();
    let matched = candidates.iter().filter_map(|&m| speedup_by(m, rows, cost).map(|s| (m, s))).max_by(|a, b| a.1 .1.total_cmp(&b.1 .1));
    match matched {
        Some((m, s)) => Some((m, Some(s))),
        None => candidates.into_iter().min_by(|a, b| a.error_window.total_cmp(&b.error_window)).map(|m| (m, None)),
    }
}

/// Runs at or above this error are left out of the speed-up tables.
pub const USEFUL_ERROR: f64 = 0.5;
/// Error levels of the speed-up table.
pub const LEVELS: [f64; 5] = [USEFUL_ERROR, 0.1, 0.05, 0.02, 0.01];

/// One line of the targets table: what is measured, the goal, and whether it holds.
pub struct Target {
    what: String,
    goal: String,
    measured: String,
    met: Option<bool>,
}

/// A fidelity target: the run of the variant at index `variant` with `modes`
/// modes, `integrator` and the step labelled `step` (of [`crate::plan::STEPS`])
/// reaches E ≤ `limit` over the window.
pub struct Fidelity {
    pub scene: &'static str,
    pub variant: usize,
    pub modes: usize,
    pub integrator: Integrator,
    pub step: &'static str,
    pub limit: f64,
}

/// The fidelity targets (the runs of the quick study's plan include them).
pub const FIDELITY: [Fidelity; 9] = {
    use Integrator::{NewmarkExplicit, Trigonometric};
    const fn f(scene: &'static str, variant: usize, modes: usize, integrator: Integrator, step: &'static str, limit: f64) -> Fidelity {
        Fidelity { scene, variant, modes, integrator, step, limit }
    }
    [
        f("paper-2d-top-row", LOAD_STATIC, 8, NewmarkExplicit, "1/1000", 0.02),
        f("paper-2d-top-corners", LOAD_STATIC, 8, NewmarkExplicit, "1/1000", 0.02),
        f("paper-3d-sheet", LOAD_STATIC, 8, NewmarkExplicit, "1/1000", 0.05),
        f("paper-3d-sheet", LOAD, 2, NewmarkExplicit, "1/1000", 0.1),
        f("paper-2d-top-row", LOAD_STATIC, 16, Trigonometric, "1/60", 0.008),
        f("paper-3d-sheet", LOAD_STATIC, 8, Trigonometric, "1/20", 0.15),
        f("paper-3d-sheet", LOAD_STATIC, 16, Trigonometric, "1/20", 0.15),
        // Trained on the scene's own program; the cubature within 1.5x of exact forces.
        f("cloth-3d", TRAINED, 32, NewmarkExplicit, "1/240", 0.005),
        f("cloth-3d", TRAINED_CUBATURE, 32, NewmarkExplicit, "1/240", 0.0075),
    ]
};

impl Fidelity {
    /// The run of this target in `rows`, if the report has it.
    pub fn run<'a>(&self, rows: &'a [Row], variants: &[Variant]) -> Option<&'a Row> {
        let (key, name) = (variants[self.variant].key, self.integrator.name());
        rows.iter().find(|x| x.scene == self.scene && x.variant == key && x.modes == self.modes && x.integrator == name && x.step_label == self.step)
    }

    fn target(&self, rows: &[Row], variants: &[Variant]) -> Target {
        let steps = if self.step == "1/1000" { "1 ms steps".to_string() } else { format!("step {} s", self.step) };
        let what = format!("{}: {}, r = {}, {}, {steps}", self.scene, variants[self.variant].label, self.modes, short(self.integrator.name()));
        let goal = format!("E ≤ {}", self.limit);
        match self.run(rows, variants) {
            None => Target { what, goal, measured: "not in this report".into(), met: None },
            Some(x) if !x.stable => Target { what, goal, measured: format!("failed: {}", x.note), met: Some(false) },
            Some(x) => Target {
                what,
                goal,
                measured: format!("E = {:.3} over {:.2} s (whole run {:.3})", x.error_window, x.window_s, x.error),
                met: Some(x.error_window <= self.limit),
            },
        }
    }
}

/// The best leave-out run of `scene` that `keep` accepts at E ≤ `limit` against
/// the fastest full-space run at least as accurate (run times as `time` gives them).
pub fn speedup_target(rows: &[Row], scene: &str, limit: f64, goal: f64, what: String, keep: &dyn Fn(&Row) -> bool) -> Target {
    speedup_target_by(rows, scene, limit, goal, what, keep, Cost::Run)
}

/// [`speedup_target`] judged by the run times `cost` names (the other shown beside).
fn speedup_target_by(rows: &[Row], scene: &str, limit: f64, goal: f64, what: String, keep: &dyn Fn(&Row) -> bool, cost: Cost) -> Target {
    let rs: Vec<&Row> = rows.iter().filter(|r| r.scene == scene).collect();
    let goal_text = format!("speed-up ≥ {goal}{}", if cost == Cost::Steps { " (steps only)" } else { "" });
    if rs.is_empty() {
        return Target { what, goal: goal_text, measured: "not in this report".into(), met: None };
    }
    match best_leave_out_by(&rs, limit, keep, cost) {
        None => Target { what, goal: goal_text, measured: format!("no such leave-out run with E ≤ {limit}"), met: Some(false) },
        Some((m, None)) => {
            Target { what, goal: goal_text, measured: format!("{} (E = {:.2e}): no full-space run as accurate", describe(m), m.error_window), met: None }
        }
        Some((m, Some((f, ratio)))) => Target {
            what,
            goal: goal_text,
            measured: format!(
                "{ratio:.1}x: {} (E = {:.2e}, {:.2e} s/s) against {} (E = {:.2e}, {:.2e} s/s); {} {:.1}x",
                describe(m),
                m.error_window,
                cost.of(m),
                describe(f),
                f.error_window,
                cost.of(f),
                if cost == Cost::Run { "without reading the positions" } else { "with the positions read every output time" },
                if cost == Cost::Run { f.step_s_per_sim_s / m.step_s_per_sim_s } else { f.run_s_per_sim_s / m.run_s_per_sim_s }
            ),
            met: Some(ratio >= goal),
        },
    }
}

/// The targets table: each fidelity and speed-up goal, what this report
/// measures for it and whether it is met.
pub fn section(md: &mut String, rows: &[Row], variants: &[Variant]) {
    // Targets.
    let cloth = "cloth-3d-100x100";
    let mut targets: Vec<Target> = FIDELITY.iter().map(|f| f.target(rows, variants)).collect();
    targets.extend([
        speedup_target(
            rows,
            "paper-2d-top-row",
            0.01,
            10.0,
            "paper-2d-top-row at E ≤ 0.01: best leave-out run against the fastest full-space run at least as accurate".into(),
            &|_| true,
        ),
        speedup_target(
            rows,
            cloth,
            USEFUL_ERROR,
            100.0,
            format!("{cloth} over the window: best leave-out run (E < {USEFUL_ERROR}) against the fastest full-space run at least as accurate"),
            &|_| true,
        ),
        speedup_target(
            rows,
            "paper-2d-top-row",
            0.01,
            10.0,
            "paper-2d-top-row at E ≤ 0.01: best leave-out run with cubature against the fastest full-space run at least as accurate".into(),
            &|r| r.variant.ends_with("cubature"),
        ),
        speedup_target(
            rows,
            cloth,
            0.01,
            100.0,
            format!("{cloth} at E ≤ 0.01 over the window: best leave-out run with cubature against the fastest full-space run at least as accurate"),
            &|r| r.variant.ends_with("cubature"),
        ),
        speedup_target_by(
            rows,
            cloth,
            USEFUL_ERROR,
            300.0,
            format!("{cloth} over the window: best trained run against the fastest full-space run at least as accurate"),
            &|r| r.variant.starts_with("trained"),
            Cost::Steps,
        ),
        speedup_target(
            rows,
            cloth,
            USEFUL_ERROR,
            30.0,
            format!("{cloth} over the window, the positions read 20 times a simulated second: best trained run against the fastest full-space run at least as accurate"),
            &|r| r.variant.starts_with("trained"),
        ),
    ]);
    let _ = writeln!(md, "## Targets\n\n| target | goal | measured | |\n|---|---|---|---|");
    for t in &targets {
        let verdict = match t.met {
            Some(true) => "met",
            Some(false) => "missed",
            None => "-",
        };
        let _ = writeln!(md, "| {} | {} | {} | {verdict} |", t.what, t.goal, t.measured);
    }
}
