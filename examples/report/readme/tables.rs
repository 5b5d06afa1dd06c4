//! The tables that compare runs: speed-up at equal error, the integrators
//! and the variants side by side, and `forceResidual` against E.

use std::fmt::Write as _;

use modal_mass_spring::measures::spearman;
use modal_mass_spring::options::Integrator;

use super::targets::{best_leave_out, LEVELS, USEFUL_ERROR};
use crate::plan::Variant;
use crate::row::{describe, sci7_text, short, Row};

/// The speed-up of the best leave-out run at each error level, per scene.
pub fn speedups(md: &mut String, rows: &[Row], scenes: &[&str]) {
    let _ = writeln!(md, "## Speed-up at equal error\n");
    let _ = writeln!(
        md,
        "Per scene and error level: of the leave-out runs (modal, fewer modes than DOFs, any variant) with E at most that \
         level, the one with the largest speed-up over the fastest full-space run at least as accurate; the ratio of their run \
         times, both measured in this report (above 1: the modal run is faster; below 1: it is slower by that factor). E < \
         {USEFUL_ERROR} is the loosest level: above it a run misses most of the motion (E = 1 is a sheet that does not move).\n"
    );
    let _ = writeln!(
        md,
        "| scene | E at most | best leave-out run | its E | its run s / sim s | fastest full-space run as accurate | its E | its run s / sim s | speed-up |\n\
         |---|---|---|---|---|---|---|---|---|"
    );
    for &scene in scenes {
        let rs: Vec<&Row> = rows.iter().filter(|r| r.scene == scene).collect();
        for limit in LEVELS {
            match best_leave_out(&rs, limit, &|_| true) {
                None => {
                    let _ = writeln!(md, "| {scene} | {limit} | none | | | | | | |");
                }
                Some((m, None)) => {
                    let _ =
                        writeln!(md, "| {scene} | {limit} | {} | {:.2e} | {:.2e} | none as accurate | | | |", describe(m), m.error_window, m.run_s_per_sim_s);
                }
                Some((m, Some((f, ratio)))) => {
                    let _ = writeln!(
                        md,
                        "| {scene} | {limit} | {} | {:.2e} | {:.2e} | {} | {:.2e} | {:.2e} | {ratio:.2} |",
                        describe(m),
                        m.error_window,
                        m.run_s_per_sim_s,
                        describe(f),
                        f.error_window,
                        f.run_s_per_sim_s
                    );
                }
            }
        }
    }
}

/// Per scene, error level and integrator: its best leave-out run (as in [`speedups`]).
pub fn integrators(md: &mut String, rows: &[Row], scenes: &[&str]) {
    let _ = writeln!(
        md,
        "\n## Integrators side by side\n\nPer scene and error level: for each integrator, of its leave-out runs (any variant, \
         mode count and step) with E at most that level, the one with the largest speed-up over the fastest full-space run at \
         least as accurate (as above). `internal` is the internal steps per communication step; `steps only` is the same run's \
         wall time without reading the node positions at the output times (a host that couples through the ports or reads \
         the modal coordinates), and its speed-up against the full-space run's own.\n"
    );
    let _ = writeln!(
        md,
        "| scene | E at most | integrator | best leave-out run | its E | internal | run s / sim s | steps only | fastest full-space run as accurate | speed-up | speed-up, steps only |\n\
         |---|---|---|---|---|---|---|---|---|---|---|"
    );
    for &scene in scenes {
        let rs: Vec<&Row> = rows.iter().filter(|r| r.scene == scene).collect();
        for limit in [0.1, 0.05, 0.02, 0.01] {
            for &integrator in Integrator::ALL {
                let name = integrator.name();
                match best_leave_out(&rs, limit, &|r| r.integrator == name) {
                    None => {
                        let _ = writeln!(md, "| {scene} | {limit} | {} | none | | | | | | | |", short(name));
                    }
                    Some((m, matched)) => {
                        let (full, ratio, steps) = match matched {
                            Some((f, ratio)) => (describe(f), format!("{ratio:.2}"), format!("{:.2}", f.step_s_per_sim_s / m.step_s_per_sim_s)),
                            None => ("none as accurate".into(), String::new(), String::new()),
                        };
                        let _ = writeln!(
                            md,
                            "| {scene} | {limit} | {} | {} | {:.2e} | {} | {:.2e} | {:.2e} | {full} | {ratio} | {steps} |",
                            short(name),
                            describe(m),
                            m.error_window,
                            m.internal_steps,
                            m.run_s_per_sim_s,
                            m.step_s_per_sim_s
                        );
                    }
                }
            }
        }
    }
}

/// Per scene and variant: its smallest E, the fewest modes and the best speed-up at two error levels.
pub fn variants(md: &mut String, rows: &[Row], variants: &[Variant], scenes: &[&str]) {
    let _ = writeln!(
        md,
        "\n## Variants side by side\n\nPer scene and variant: the smallest E of its runs, the fewest modes any of its runs (any \
         scheme and step) needs to reach E ≤ 0.05 and E ≤ 0.01, and its best speed-up at those levels as above (\"-\": none of \
         its runs reaches the level; the paper's method also runs with all modes, the others do not).\n"
    );
    let _ = writeln!(
        md,
        "| scene | variant | runs (failed) | smallest E | fewest modes, E ≤ 0.05 | fewest modes, E ≤ 0.01 | speed-up at E ≤ 0.05 | speed-up at E ≤ 0.01 | springs visited |\n\
         |---|---|---|---|---|---|---|---|---|"
    );
    for &scene in scenes {
        let rs: Vec<&Row> = rows.iter().filter(|r| r.scene == scene).collect();
        for v in variants {
            let vr: Vec<&Row> = rs.iter().copied().filter(|r| r.method == "modal" && r.variant == v.key).collect();
            if vr.is_empty() {
                continue;
            }
            let ran: Vec<&Row> = vr.iter().copied().filter(|r| !r.note.starts_with("not run")).collect();
            let failed = ran.iter().filter(|r| !r.stable).count();
            let best = vr.iter().filter(|r| r.stable).map(|r| r.error_window).fold(f64::INFINITY, f64::min);
            let fewest = |limit: f64| {
                vr.iter()
                    .filter(|r| r.stable && r.error_window <= limit)
                    .min_by(|a, b| a.modes.cmp(&b.modes).then(a.run_s_per_sim_s.total_cmp(&b.run_s_per_sim_s)))
                    .map(|r| format!("{}{} ({} {})", r.modes, if r.modes == r.dofs { " (all)" } else { "" }, short(r.integrator), r.step_label))
                    .unwrap_or_else(|| "-".into())
            };
            let gain = |limit: f64| match best_leave_out(&rs, limit, &|r| r.variant == v.key) {
                Some((m, Some((_, ratio)))) => format!("{ratio:.2} (r={} {} {})", m.modes, short(m.integrator), m.step_label),
                Some((_, None)) => "no full run as accurate".into(),
                None => "-".into(),
            };
            let springs: Vec<usize> = vr.iter().filter_map(|r| r.springs_visited).collect();
            let springs = match (springs.iter().min(), springs.iter().max()) {
                (Some(a), Some(b)) if a == b => format!("{a}"),
                (Some(a), Some(b)) => format!("{a} to {b}"),
                _ => "-".into(),
            };
            let _ = writeln!(
                md,
                "| {scene} | {} | {} ({failed}) | {} | {} | {} | {} | {} | {springs} |",
                v.label,
                ran.len(),
                if best.is_finite() { format!("{best:.2e}") } else { "-".into() },
                fewest(0.05),
                fewest(0.01),
                gain(0.05),
                gain(0.01)
            );
        }
    }
    let _ = writeln!(
        md,
        "\n`springs visited`: the springs one force evaluation visits, over the variant's runs that set up (every spring with exact \
         forces; with cubature the size of the set chosen at set-up)."
    );
}

/// How well `forceResidual` ranks runs by their true error.
pub fn force_residual(md: &mut String, rows: &[Row], scenes: &[&str]) {
    let _ = writeln!(
        md,
        "\n## forceResidual against the true error\n\n`forceResidual` (docs/method.md, section 6) is read after every output frame \
         of every modal run; the CSV has its largest and mean value over the run (`force_residual_max`, `force_residual_mean`) \
         beside E. How well it ranks runs by their true error (E over the window, `error_window`): Spearman's rank correlation between each and E, over the stable \
         leave-out runs of each scene (all variants, schemes and steps), and over the explicit ones at step 1/1000 alone, whose \
         error is nearly all the basis's (1 = same order, 0 = unrelated). The largest E among runs whose forceResidual stayed \
         below 0.5, and the smallest among runs where it passed 0.9 (the FMU's default warning level), say what a threshold on \
         it can promise.\n\n![forceResidual against E](force_residual.png)\n"
    );
    let _ = writeln!(
        md,
        "| scene | runs | ρ(max, E) | ρ(mean, E) | explicit 1/1000 runs | ρ(max, E) there | ρ(mean, E) there | largest E, max < 0.5 | smallest E, max > 0.9 |\n\
         |---|---|---|---|---|---|---|---|---|"
    );
    let mut all_scenes: Vec<&str> = scenes.to_vec();
    all_scenes.push("all scenes");
    for &scene in &all_scenes {
        let rs: Vec<&Row> =
            rows.iter().filter(|r| (scene == "all scenes" || r.scene == scene) && r.leaves_out() && r.stable && r.force_residual_max.is_finite()).collect();
        let rho = |rs: &[&Row], f: &dyn Fn(&Row) -> f64| {
            if rs.len() < 3 {
                return "-".to_string();
            }
            let x: Vec<f64> = rs.iter().map(|r| f(r)).collect();
            let y: Vec<f64> = rs.iter().map(|r| r.error_window).collect();
            format!("{:.2}", spearman(&as_in_csv(&x), &as_in_csv(&y)))
        };
        let fine: Vec<&Row> = rs.iter().copied().filter(|r| r.integrator == "newmark-explicit" && r.step_label == "1/1000").collect();
        let below = rs.iter().filter(|r| r.force_residual_max < 0.5).map(|r| r.error_window).fold(f64::NAN, f64::max);
        let above = rs.iter().filter(|r| r.force_residual_max > 0.9).map(|r| r.error_window).fold(f64::NAN, f64::min);
        let fmt = |x: f64| if x.is_finite() { format!("{x:.2e}") } else { "-".into() };
        let _ = writeln!(
            md,
            "| {scene} | {} | {} | {} | {} | {} | {} | {} | {} |",
            rs.len(),
            rho(&rs, &|r| r.force_residual_max),
            rho(&rs, &|r| r.force_residual_mean),
            fine.len(),
            rho(&fine, &|r| r.force_residual_max),
            rho(&fine, &|r| r.force_residual_mean),
            fmt(below),
            fmt(above)
        );
    }
}

/// The values as the CSV has them (7 significant digits): runs that differ
/// by round-off (a sheet that does not move: E = 1, forceResidual = 1) tie
/// in Spearman's rank correlation.
fn as_in_csv(v: &[f64]) -> Vec<f64> {
    v.iter().map(|&a| sci7_text(a).parse::<f64>().unwrap()).collect()
}
