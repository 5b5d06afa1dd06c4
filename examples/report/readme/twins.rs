//! How far each scene is predictable (its twins), and the runs' coarse
//! observables against the twins' spread.

use std::fmt::Write as _;

use super::targets::{best_leave_out, FIDELITY, LEVELS};
use crate::fidelity::{Twins, AVERAGE_S, OBSERVABLES, PREDICTABLE_E, SPREAD_MULTIPLE, TWIN_KICK, TWIN_SEEDS, TWIN_STEP};
use crate::plan::Variant;
use crate::row::{describe, Row};

fn sci(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.2e}")
    } else {
        "-".into()
    }
}

/// The runs the targets and the speed-up tables name: each fidelity
/// target's run, and per scene and error level the best leave-out run and
/// the full-space run it is compared with.
fn named_runs<'a>(rows: &'a [Row], variants: &[Variant], scenes: &[&str]) -> Vec<&'a Row> {
    let mut named: Vec<&Row> = FIDELITY.iter().filter_map(|f| f.run(rows, variants)).filter(|r| r.stable).collect();
    for &scene in scenes {
        let rs: Vec<&Row> = rows.iter().filter(|r| r.scene == scene).collect();
        for limit in LEVELS {
            if let Some((m, matched)) = best_leave_out(&rs, limit, &|_| true) {
                named.push(m);
                named.extend(matched.map(|(f, _)| f));
            }
        }
    }
    let mut unique: Vec<&Row> = Vec::new();
    for r in named {
        if !unique.iter().any(|u| std::ptr::eq(*u, r)) {
            unique.push(r);
        }
    }
    unique.sort_by_key(|r| scenes.iter().position(|&s| s == r.scene));
    unique
}

/// The predictability table, the named runs' observables against the
/// twins' spread, and per scene how many runs stay within
/// [`SPREAD_MULTIPLE`] of it.
pub fn section(md: &mut String, rows: &[Row], twins: &[(String, Twins)], variants: &[Variant], scenes: &[&str]) {
    let _ = writeln!(
        md,
        "\n## Predictability and coarse observables\n\nCloth is chaotic: a run started a hair away parts from the canonical \
         one within the run, so its E over the whole run measures the scene as much as the model. Per scene, {} twins \
         (full space, explicit Newmark at {TWIN_STEP} s steps, each free node moved {TWIN_KICK:e} m in a direction drawn \
         from a fixed seed) are measured against the same run undisturbed. T_p is the first output time at which a twin's \
         E over [0, T_p] reaches {PREDICTABLE_E:e} (\"-\": none within the run); the twins' floor is their largest E over \
         the whole run, as close as any model can come to the reference there. The headline E of every run (`error_window`; \
         the targets, the speed-ups, the Pareto fronts and forceResidual's correlation judge it) is E over [0, window], the \
         window the shorter of T_p and the window the reference resolves (References). Past T_p a run is judged by coarse \
         observables over the whole run: the holder's force (the `anchorForce` output), the bottom row's mean position and \
         the kinetic and potential energy, each the mean of its values at the output times in windows of {AVERAGE_S} s; a \
         run's deviation is the largest distance between its window means and the reference's, the twins' spread the \
         largest such distance between a twin and its undisturbed run.\n",
        TWIN_SEEDS.len()
    );
    let _ = write!(md, "| scene | T_p (s) | twins' floor | resolved until (s) | window (s) | set by |");
    for (name, unit) in OBSERVABLES {
        let _ = write!(md, " spread: {name} ({unit}) |");
    }
    let _ = writeln!(md, " twins' wall time (s) |\n|---|---|---|---|---|---|{}---|", "---|".repeat(OBSERVABLES.len()));
    for (scene, t) in twins {
        let Some(r) = rows.iter().find(|r| &r.scene == scene) else { continue };
        let by = match t.until_s {
            Some(tp) if tp <= r.resolved_until_s => "T_p",
            Some(_) => "the reference",
            None => "the reference (no T_p)",
        };
        let _ = write!(
            md,
            "| {scene} | {} | {} | {:.2} | {:.2} | {by} |",
            t.until_s.map_or("-".into(), |x| format!("{x:.2}")),
            sci(t.floor),
            r.resolved_until_s,
            r.window_s
        );
        for s in t.spread {
            let _ = write!(md, " {} |", sci(s));
        }
        let _ = writeln!(md, " {:.2} |", t.wall_s);
    }

    let _ = writeln!(
        md,
        "\nThe runs the targets and the speed-up tables name: E over the window and over the whole run beside the twins' \
         floor, and each observable's deviation from the reference over the twins' spread (≤ {SPREAD_MULTIPLE}: as close \
         to the reference as a run started {TWIN_KICK:e} m away, within that factor; on a scene without T_p the spread is \
         round-off and the window E judges).\n"
    );
    let _ = write!(md, "| scene | run | E over the window | whole-run E | twins' floor |");
    for (name, _) in OBSERVABLES {
        let _ = write!(md, " {name} / spread |");
    }
    let _ = writeln!(md, "\n|---|---|---|---|---|{}", "---|".repeat(OBSERVABLES.len()));
    for r in named_runs(rows, variants, scenes) {
        let _ = write!(md, "| {} | {} | {} | {} | {} |", r.scene, describe(r), sci(r.error_window), sci(r.error), sci(r.twin_floor));
        for x in r.vs_twins() {
            let _ = write!(md, " {} |", sci(x));
        }
        let _ = writeln!(md);
    }

    let _ = writeln!(
        md,
        "\nPer scene: of the stable runs (all methods, variants, schemes and steps), how many stay within {SPREAD_MULTIPLE}x \
         the twins' spread on each observable and on all four.\n"
    );
    let _ = write!(md, "| scene | stable runs |");
    for (name, _) in OBSERVABLES {
        let _ = write!(md, " {name} |");
    }
    let _ = writeln!(md, " all four | all four, leave-out runs |\n|---|---|{}---|---|", "---|".repeat(OBSERVABLES.len()));
    for &scene in scenes {
        let stable: Vec<&Row> = rows.iter().filter(|r| r.scene == scene && r.stable).collect();
        let within = |r: &Row, o: usize| r.vs_twins()[o] <= SPREAD_MULTIPLE;
        let all = |r: &Row| (0..OBSERVABLES.len()).all(|o| within(r, o));
        let _ = write!(md, "| {scene} | {} |", stable.len());
        for o in 0..OBSERVABLES.len() {
            let _ = write!(md, " {} |", stable.iter().filter(|r| within(r, o)).count());
        }
        let leave_out = stable.iter().filter(|r| r.leaves_out()).count();
        let _ = writeln!(md, " {} | {} of {leave_out} |", stable.iter().filter(|r| all(r)).count(), stable.iter().filter(|r| r.leaves_out() && all(r)).count());
    }
}
