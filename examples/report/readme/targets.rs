//! The targets table, and the selections of runs it and the speed-up
//! tables share.

use std::fmt::Write as _;

use modal_mass_spring::physics::Integrator;

use crate::plan::{Variant, LOAD, LOAD_STATIC};
use crate::row::{describe, short, Row};

/// For a modal run: the fastest full-space run whose error (over the window
/// the reference resolves) is at most the modal run's, and the ratio of
/// their run times (> 1: modal is faster).
pub fn speedup<'a>(modal: &Row, rows: &[&'a Row]) -> Option<(&'a Row, f64)> {
    rows.iter()
        .copied()
        .filter(|f| f.method == "full" && f.stable && f.error_resolved <= modal.error_resolved)
        .min_by(|a, b| a.run_s_per_sim_s.total_cmp(&b.run_s_per_sim_s))
        .map(|f| (f, f.run_s_per_sim_s / modal.run_s_per_sim_s))
}

/// The best leave-out run of `rows` (those `keep` accepts) with an error
/// (over the resolved window) of at most `limit`: the one with the largest
/// speed-up over the fastest full-space run at least as accurate; if no
/// full-space run is as accurate as any of them, the most accurate, unmatched.
pub fn best_leave_out<'a>(rows: &[&'a Row], limit: f64, keep: &dyn Fn(&Row) -> bool) -> Option<(&'a Row, Option<(&'a Row, f64)>)> {
    let candidates: Vec<&Row> = rows.iter().copied().filter(|r| r.leaves_out() && r.stable && r.error_resolved <= limit && keep(r)).collect();
    let matched = candidates.iter().filter_map(|&m| speedup(m, rows).map(|s| (m, s))).max_by(|a, b| a.1 .1.total_cmp(&b.1 .1));
    match matched {
        Some((m, s)) => Some((m, Some(s))),
        None => candidates.into_iter().min_by(|a, b| a.error_resolved.total_cmp(&b.error_resolved)).map(|m| (m, None)),
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

/// The run of `variant` with `r` modes, `integrator` and step `step` (a label of [`STEPS`]) at E ≤ `limit`.
pub fn fidelity_target(rows: &[Row], scene: &str, variant: usize, variants: &[Variant], r: usize, integrator: Integrator, step: &str, limit: f64) -> Target {
    let v = &variants[variant];
    let steps = if step == "1/1000" { "1 ms steps".to_string() } else { format!("step {step} s") };
    let what = format!("{scene}: {}, r = {r}, {}, {steps}", v.label, short(integrator.name()));
    let goal = format!("E ≤ {limit}");
    let row = rows.iter().find(|x| x.scene == scene && x.variant == v.key && x.modes == r && x.integrator == integrator.name() && x.step_label == step);
    match row {
        None => Target { what, goal, measured: "not in this report".into(), met: None },
        Some(x) if !x.stable => Target { what, goal, measured: format!("failed: {}", x.note), met: Some(false) },
        Some(x) => Target { what, goal, measured: format!("E = {:.3}", x.error_resolved), met: Some(x.error_resolved <= limit) },
    }
}

/// The best leave-out run of `scene` that `keep` accepts at E ≤ `limit` against
/// the fastest full-space run at least as accurate (run times as `time` gives them).
pub fn speedup_target(rows: &[Row], scene: &str, limit: f64, goal: f64, what: String, keep: &dyn Fn(&Row) -> bool) -> Target {
    let rs: Vec<&Row> = rows.iter().filter(|r| r.scene == scene).collect();
    let goal_text = format!("speed-up ≥ {goal}");
    if rs.is_empty() {
        return Target { what, goal: goal_text, measured: "not in this report".into(), met: None };
    }
    match best_leave_out(&rs, limit, keep) {
        None => Target { what, goal: goal_text, measured: format!("no such leave-out run with E ≤ {limit}"), met: Some(false) },
        Some((m, None)) => {
            Target { what, goal: goal_text, measured: format!("{} (E = {:.2e}): no full-space run as accurate", describe(m), m.error_resolved), met: None }
        }
        Some((m, Some((f, ratio)))) => Target {
            what,
            goal: goal_text,
            measured: format!(
                "{ratio:.1}x: {} (E = {:.2e}, {:.2e} s/s) against {} (E = {:.2e}, {:.2e} s/s); without reading the positions {:.1}x",
                describe(m),
                m.error_resolved,
                m.run_s_per_sim_s,
                describe(f),
                f.error_resolved,
                f.run_s_per_sim_s,
                f.step_s_per_sim_s / m.step_s_per_sim_s
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
    let targets = vec![
        fidelity_target(rows, "paper-2d-top-row", LOAD_STATIC, variants, 8, Integrator::NewmarkExplicit, "1/1000", 0.02),
        fidelity_target(rows, "paper-2d-top-corners", LOAD_STATIC, variants, 8, Integrator::NewmarkExplicit, "1/1000", 0.02),
        fidelity_target(rows, "paper-3d-sheet", LOAD_STATIC, variants, 8, Integrator::NewmarkExplicit, "1/1000", 0.05),
        fidelity_target(rows, "paper-3d-sheet", LOAD, variants, 2, Integrator::NewmarkExplicit, "1/1000", 0.1),
        fidelity_target(rows, "paper-2d-top-row", LOAD_STATIC, variants, 16, Integrator::Trigonometric, "1/60", 0.008),
        fidelity_target(rows, "paper-3d-sheet", LOAD_STATIC, variants, 8, Integrator::Trigonometric, "1/20", 0.15),
        fidelity_target(rows, "paper-3d-sheet", LOAD_STATIC, variants, 16, Integrator::Trigonometric, "1/20", 0.15),
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
            format!(
                "{cloth} over the window the reference resolves: best leave-out run (E < {USEFUL_ERROR}) against the fastest full-space run at least as accurate"
            ),
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
            format!("{cloth} at E ≤ 0.01 over the window the reference resolves: best leave-out run with cubature against the fastest full-space run at least as accurate"),
            &|r| r.variant.ends_with("cubature"),
        ),
    ];
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
