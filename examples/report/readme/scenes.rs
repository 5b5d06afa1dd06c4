//! The set-up table and each scene's section (its Pareto front and the
//! runs that failed).

use std::fmt::Write as _;

use crate::plan::Variant;
use crate::row::{describe, Row};

/// Set-up time against the mesh size, per scene.
pub fn setup(md: &mut String, rows: &[Row], variants: &[Variant], scenes: &[&str]) {
    let _ = writeln!(
        md,
        "\n## Set-up against mesh size\n\nAssembly plus eigen decomposition (modal; with the load variants also the load-dependent \
         Ritz vectors or every mode, the static correction, the equilibrium and the cubature training) or sparse symbolic analysis \
         (full), in seconds, from the explicit runs at step 1/240 s; the variants at r = 8.\n"
    );
    let _ = write!(md, "| scene | free DOFs | full |");
    for v in variants {
        let _ = write!(md, " {}, r = 8 |", v.key);
    }
    let _ = writeln!(md, " paper, most modes run |\n|---|---|---|{}---|", "---|".repeat(variants.len()));
    for &scene in scenes {
        let pick = |f: &dyn Fn(&Row) -> bool| {
            rows.iter()
                .filter(|r| r.scene == scene && r.step_label == "1/240" && r.integrator == "newmark-explicit" && r.setup_s.is_finite() && f(r))
                .max_by_key(|r| r.modes)
        };
        let dofs = rows.iter().find(|r| r.scene == scene).map(|r| r.dofs).unwrap_or(0);
        let fmt = |r: Option<&Row>| r.map(|r| format!("{:.3e}", r.setup_s)).unwrap_or_else(|| "-".into());
        let _ = write!(md, "| {scene} | {dofs} | {} |", fmt(pick(&|r| r.method == "full" && r.note.is_empty())));
        for v in variants {
            let _ = write!(md, " {} |", fmt(pick(&|r| r.method == "modal" && r.variant == v.key && r.modes == 8)));
        }
        let most = pick(&|r| r.method == "modal" && r.variant == "paper");
        let _ = writeln!(md, " {} |", most.map(|r| format!("{:.3e} (r = {})", r.setup_s, r.modes)).unwrap_or_else(|| "-".into()));
    }
    let _ = writeln!(md);
}

/// Per scene: its plot, its Pareto front and its failed runs.
pub fn per_scene(md: &mut String, rows: &[Row], scenes: &[&str]) {
    for &scene in scenes {
        let rs: Vec<&Row> = rows.iter().filter(|r| r.scene == scene).collect();
        let _ = writeln!(
            md,
            "## {scene}\n\n![{scene}]({scene}.png)\n\nPareto front (runs not beaten on both E over the window and run time; the whole run's E beside it):\n"
        );
        let _ = writeln!(
            md,
            "| method | variant | integrator | modes | step | internal steps | setup (s) | run s / sim s | E | whole-run E | forceResidual max | max node error (m) |\n\
             |---|---|---|---|---|---|---|---|---|---|---|---|"
        );
        for r in pareto(&rs) {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} | {:.3e} | {:.3e} | {:.3e} | {:.3e} | {:.2} | {:.3e} |",
                r.method,
                r.variant,
                r.integrator,
                r.modes,
                r.step_label,
                r.internal_steps,
                r.setup_s,
                r.run_s_per_sim_s,
                r.error_window,
                r.error,
                r.force_residual_max,
                r.max_node_error
            );
        }
        // Failures grouped by their message (set-up errors repeat across steps).
        let mut failed: Vec<(&str, Vec<String>)> = Vec::new();
        for r in rs.iter().filter(|r| !r.stable) {
            match failed.iter_mut().find(|(note, _)| *note == r.note) {
                Some((_, runs)) => runs.push(describe(r)),
                None => failed.push((&r.note, vec![describe(r)])),
            }
        }
        if !failed.is_empty() {
            let _ = writeln!(md, "\nRuns that failed, were refused or went over budget:\n");
            for (note, runs) in failed {
                let _ = writeln!(md, "- {}: {note}", runs.join(", "));
            }
        }
        let _ = writeln!(md);
    }
}

/// The runs no other run beats on both E over the window and run time.
fn pareto<'a>(rows: &[&'a Row]) -> Vec<&'a Row> {
    let mut front: Vec<&Row> = rows
        .iter()
        .copied()
        .filter(|a| {
            a.stable
                && !rows.iter().any(|b| {
                    b.stable
                        && b.error_window <= a.error_window
                        && b.run_s_per_sim_s <= a.run_s_per_sim_s
                        && (b.error_window < a.error_window || b.run_s_per_sim_s < a.run_s_per_sim_s)
                })
        })
        .collect();
    front.sort_by(|a, b| a.run_s_per_sim_s.total_cmp(&b.run_s_per_sim_s));
    front
}
