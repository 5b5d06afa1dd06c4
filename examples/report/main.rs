//! The error-against-run-time study (docs/method.md, section 6): every way of
//! running each scene, timed, and its trajectory error against a full-space
//! reference. The paper's method (the lowest modes at rest, every spring) runs
//! on the whole grid of mode counts, schemes and steps; the other basis and
//! force options (modes chosen by the load, the static correction, the
//! linearization at the equilibrium, cubature) run beside it on a smaller
//! grid. Writes `error_vs_runtime.csv` and `README.md` into the output
//! folder; `cargo xtask report` runs it and draws the plots.
//!
//! cargo run --release --example report -- [--quick] [--out DIR] [--scene NAME]... [--variants-only] [--log]
//!
//! `--scene` (repeatable) keeps only the scenes named; `--variants-only`
//! leaves out the paper's modal grid (full space and the variants stay).
//! Both are for trying the study out: the report they write is partial.
//! `--log` prints every run as it ends (set-up and run time, E).

mod fidelity;
mod measure;
mod plan;
mod readme;
mod row;
mod run;

use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use modal_mass_spring::canonical_scenes;

use measure::{measure_scene, Conditions};
use plan::{plan_scene, variants, SceneCase, LARGE_DOFS};
use readme::{write_readme, Study};
use row::{write_csv, Row};

/// The canonical scene `name` with its gravity turned sideways mid-run
/// ([`plan::TURN_AT_S`], [`plan::TURNED_GRAVITY`]): it leaves what its
/// training program ran.
fn turned(name: &str) -> SceneCase {
    SceneCase {
        label: format!("{name}-turned"),
        params: canonical_scenes::canonical(name).unwrap().grid,
        change: Some(plan::Change { at_s: plan::TURN_AT_S, gravity: plan::TURNED_GRAVITY }),
    }
}

/// The command line.
struct Args {
    quick: bool,
    variants_only: bool,
    log: bool,
    out: String,
    /// Scenes to keep (all when empty).
    only: Vec<String>,
}

fn parse_args() -> Result<Args, lexopt::Error> {
    use lexopt::prelude::*;
    let mut args = Args { quick: false, variants_only: false, log: false, out: "report".into(), only: Vec::new() };
    let mut parser = lexopt::Parser::from_env();
    while let Some(arg) = parser.next()? {
        match arg {
            Long("quick") => args.quick = true,
            Long("variants-only") => args.variants_only = true,
            Long("log") => args.log = true,
            Long("out") => args.out = parser.value()?.string()?,
            Long("scene") => args.only.push(parser.value()?.string()?),
            _ => return Err(arg.unexpected()),
        }
    }
    Ok(args)
}

fn main() {
    let Args { quick, variants_only, log, out, only } = parse_args().unwrap_or_else(|e| {
        eprintln!("report: {e}\nusage: report [--quick] [--out DIR] [--scene NAME]... [--variants-only] [--log]");
        std::process::exit(2)
    });
    // Quick mode (CI): small scenes, short runs, one repeat.
    let seconds = if quick { 0.5 } else { 2.0 };
    let repeats = if quick { 1 } else { 3 };
    // The trigonometric scheme with all modes at 1 ms steps is exact for the
    // linear part and comes within 1e-5 of the reference: the small scenes'
    // references take steps of 25 µs (own error about 1e-7). On large scenes
    // the trajectory's own sensitivity bounds what any reference resolves
    // (see References) and no run comes that close: 100 µs.
    let reference_step = |n: usize| match (quick, n > LARGE_DOFS) {
        (true, _) => 5e-5,
        (false, false) => 2.5e-5,
        (false, true) => 1e-4,
    };
    // Wall time one run may take before it is stopped and listed as over budget.
    let budget_s = if quick { 5.0 } else { 10.0 };
    let variants = variants();
    let mut cases: Vec<SceneCase> = if quick {
        ["paper-2d-top-row", "paper-3d-sheet"]
            .into_iter()
            .map(|n| SceneCase { label: n.into(), params: canonical_scenes::canonical(n).unwrap().grid, change: None })
            .chain([turned("cloth-3d")])
            .collect()
    } else {
        let mut c: Vec<SceneCase> = canonical_scenes::names()
            .into_iter()
            .map(|n| SceneCase { label: n.into(), params: canonical_scenes::canonical(n).unwrap().grid, change: None })
            .collect();
        c.push(SceneCase { label: "cloth-3d-100x100".into(), params: canonical_scenes::cloth(100, 100).grid, change: None });
        c.push(turned("cloth-3d"));
        c
    };
    if !only.is_empty() {
        cases.retain(|c| only.contains(&c.label));
    }
    std::fs::create_dir_all(&out).expect("cannot create the output folder");

    // Every way of running each scene.
    let plans: Vec<Vec<plan::Plan>> = cases.iter().map(|case| plan_scene(&case.params, &variants, quick, variants_only, case.change.is_some())).collect();
    // Each scene's runs, its reference and its two checks, the twins' base run and the twins.
    let total: usize = plans.iter().map(|l| l.len() + 4 + fidelity::TWIN_SEEDS.len()).sum();
    let bar = ProgressBar::new(total as u64);
    bar.set_style(ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} {msg}").unwrap().progress_chars("=> "));

    let started = Instant::now();
    let conditions = Conditions { seconds, repeats, budget_s, log, variants: &variants, bar: &bar, started };
    let mut rows: Vec<Row> = Vec::new();
    let mut reference_notes = String::new();
    let mut twins = Vec::new();
    for (case, list) in cases.iter().zip(plans) {
        twins.push((case.label.clone(), measure_scene(&conditions, case, list, &reference_step, &mut rows, &mut reference_notes)));
    }
    bar.finish_with_message("done");
    let study = Study { rows: &rows, twins: &twins, variants: &variants, quick, seconds, repeats, budget_s, wall_s: started.elapsed().as_secs_f64() };
    write_csv(&out, &rows).expect("cannot write the CSV");
    write_readme(&out, &study, &reference_notes);
}
