//! The adaptive runs (`reduction = adaptive`, docs/method.md, section 10):
//! per scene, tolerance and step, E against the tolerance, the estimate
//! against E, the share of steps taken reduced, and the run time against
//! the best fixed reduced setting and the fastest full-space run that
//! meet the same tolerance.

use std::fmt::Write as _;

use crate::row::{describe, Row};

/// The bounds the estimate is held to: at least a third of E, at most
/// three times it or a tenth of the tolerance where E is smaller.
pub fn within_bounds(r: &Row, estimate: f64, e: f64) -> bool {
    estimate >= e / 3.0 && (estimate <= 3.0 * e || estimate <= r.error_tolerance / 10.0)
}

/// The fastest stable run of `rows` that `keep` keeps with E over the window at most `limit`.
fn fastest<'a>(rows: &[&'a Row], limit: f64, keep: &dyn Fn(&Row) -> bool) -> Option<&'a Row> {
    rows.iter().copied().filter(|r| r.stable && keep(r) && r.error_window <= limit).min_by(|a, b| a.run_s_per_sim_s.total_cmp(&b.run_s_per_sim_s))
}

pub fn section(md: &mut String, rows: &[Row], scenes: &[&str]) {
    if !rows.iter().any(|r| r.method == "adaptive") {
        return;
    }
    let _ = writeln!(
        md,
        "\n## Adaptive runs\n\n`reduction = adaptive` with `errorTolerance` = tol (docs/method.md, section 10): the FMU sizes its basis \
         for the tolerance, estimates E as it runs (`errorEstimate`), takes the steps in full space where the estimate says the \
         reduced model would break the tolerance and returns with a grown basis. Per run: E over the window and the whole run's E \
         with the estimate at the same time (the estimate is within bounds when it is at least E/3 and at most 3E, or at most \
         tol/10 where E is smaller); the share of internal steps taken reduced (`reducedFraction`); the basis size at set-up and at \
         the end (the free DOFs while in full space); run time against the fastest fixed reduced run of this report (any variant, \
         scheme, step and mode count) and the fastest full-space run with E over the window at most tol (above 1: the adaptive run is \
         slower by that factor / faster by that factor). Scenes named `-turned` turn their gravity sideways in the sheet's plane at \
         t = {} s, outside what any training program ran.\n",
        crate::plan::TURN_AT_S
    );
    let _ = writeln!(
        md,
        "| scene | tol | step | E | estimate | within bounds | whole-run E | estimate | within bounds | reduced | basis | run s / sim s | \
         fastest fixed reduced run with E ≤ tol | adaptive time / its time | fastest full-space run with E ≤ tol | its time / adaptive time |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    let yes = |b: bool| if b { "yes" } else { "**no**" };
    for &scene in scenes {
        let rs: Vec<&Row> = rows.iter().filter(|r| r.scene == scene).collect();
        for a in rs.iter().filter(|r| r.method == "adaptive") {
            if !a.stable {
                let _ = writeln!(md, "| {scene} | {} | {} | failed: {} |||||||||||||", a.error_tolerance, a.step_label, a.note);
                continue;
            }
            let tol = a.error_tolerance;
            let fixed = fastest(&rs, tol, &|r| r.leaves_out());
            let full = fastest(&rs, tol, &|r| r.method == "full");
            let vs = |r: Option<&Row>, adaptive_over: bool| match r {
                None => "none | |".to_string(),
                Some(r) => {
                    let ratio = if adaptive_over { a.run_s_per_sim_s / r.run_s_per_sim_s } else { r.run_s_per_sim_s / a.run_s_per_sim_s };
                    format!("{} ({:.2e} s/s) | {ratio:.2} |", describe(r), r.run_s_per_sim_s)
                }
            };
            let _ = writeln!(
                md,
                "| {scene} | {tol} | {} | {:.2e} | {:.2e} | {} | {:.2e} | {:.2e} | {} | {:.0} % | {} → {} | {:.2e} | {} {}",
                a.step_label,
                a.error_window,
                a.estimate_window,
                yes(within_bounds(a, a.estimate_window, a.error_window)),
                a.error,
                a.error_estimate,
                yes(within_bounds(a, a.error_estimate, a.error)),
                100.0 * a.reduced_fraction,
                a.modes,
                a.basis_size_end.map_or("-".into(), |b| b.to_string()),
                a.run_s_per_sim_s,
                vs(fixed, true),
                vs(full, false)
            );
        }
    }
    let _ = writeln!(md, "\nThe estimate against E for every adaptive run: `adaptive_estimate.png`.\n");
}
