//! The error-against-run-time study (docs/method.md, section 6): every way of
//! running each scene, timed, and its trajectory error against a full-space
//! reference. Writes `error_vs_runtime.csv` and `README.md` into the output
//! folder; `cargo xtask report` runs it and draws the plots.
//!
//! cargo run --release --example report -- [--quick] [--out DIR]

use std::fmt::Write as _;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use modal_mass_spring::physics::*;
use modal_mass_spring::scenes;

/// Output times are multiples of this; every co-simulation step divides it.
const FRAME: f64 = 0.05;
/// How much smaller than every error it measures the reference's own error
/// (against its run at half the step) must be. Where the trajectory itself is
/// sensitive, that own error stops shrinking with dt from some time on;
/// `error_resolved` is E over the window before that.
const REFERENCE_MARGIN: f64 = 10.0;
const STEPS: [(f64, &str); 3] = [(1.0 / 1000.0, "1/1000"), (1.0 / 240.0, "1/240"), (1.0 / 60.0, "1/60")];

struct SceneCase {
    label: String,
    params: Grid,
}

struct Row {
    scene: String,
    dofs: usize,
    method: &'static str,
    integrator: &'static str,
    modes: usize,
    step: f64,
    step_label: String,
    internal_steps: usize,
    setup_s: f64,
    run_s_per_sim_s: f64,
    error: f64,
    max_node_error: f64,
    stable: bool,
    /// E of this run against the full-space run with the same integrator and step.
    vs_full: f64,
    /// E over the output times up to `resolved_until_s` (see [`REFERENCE_MARGIN`]).
    error_resolved: f64,
    resolved_until_s: f64,
    note: String,
}

struct Trajectory {
    frames: Vec<Vec<f64>>,
    setup_s: f64,
    run_s: f64,
    internal_steps: usize,
}

/// Implicit modal runs whose reduced tangent is costlier than this are not run.
const IMPLICIT_TANGENT_LIMIT: f64 = 5e7;

/// Runs over budget stop here; the report lists them as such (not as unstable).
const OVER_BUDGET: &str = "over the time budget";

fn simulate(p: &Grid, s: &SolverParams, h: f64, seconds: f64, budget_s: f64) -> Result<Trajectory, String> {
    let t0 = Instant::now();
    let mut sim = p.build().and_then(|scene| Simulator::new(scene, s, &Loads::physical(s.n_modes))).map_err(|e| e.to_string())?;
    let setup_s = t0.elapsed().as_secs_f64();
    let per_frame = (FRAME / h).round() as usize;
    let n_frames = (seconds / FRAME).round() as usize;
    let mut frames = Vec::with_capacity(n_frames + 1);
    frames.push(sim.positions().to_vec());
    let mut internal_steps = 0;
    let t1 = Instant::now();
    for _ in 0..n_frames {
        for _ in 0..per_frame {
            sim.do_step(h).map_err(|e| e.to_string())?;
            internal_steps += sim.internal_steps_last();
            if t1.elapsed().as_secs_f64() > budget_s {
                return Err(format!("{OVER_BUDGET}: stopped after {budget_s} s of wall time at t = {:.3} s", sim.time()));
            }
        }
        frames.push(sim.positions().to_vec());
    }
    Ok(Trajectory { frames, setup_s, run_s: t1.elapsed().as_secs_f64(), internal_steps: internal_steps / (per_frame * n_frames).max(1) })
}

/// E (docs/method.md, section 6; equal node masses cancel) over all output times.
fn error(run: &[Vec<f64>], reference: &[Vec<f64>]) -> f64 {
    errors_by_window(run, reference).last().copied().unwrap_or(f64::NAN)
}

/// The largest distance between a node and its reference position over all output times.
fn max_node_error(run: &[Vec<f64>], reference: &[Vec<f64>], d: usize) -> f64 {
    run.iter()
        .zip(reference)
        .flat_map(|(x, xr)| x.chunks_exact(d).zip(xr.chunks_exact(d)))
        .map(|(a, b)| a.iter().zip(b).map(|(p, q)| (p - q).powi(2)).sum::<f64>().sqrt())
        .fold(0.0, f64::max)
}

/// E over growing windows: element k - 1 is E over the first k output times
/// (NaN for k = 1, where the reference has not moved yet).
fn errors_by_window(run: &[Vec<f64>], reference: &[Vec<f64>]) -> Vec<f64> {
    let (mut num, mut den) = (0.0, 0.0);
    run.iter()
        .zip(reference)
        .map(|(x, xr)| {
            num += x.iter().zip(xr).map(|(a, b)| (a - b).powi(2)).sum::<f64>();
            den += xr.iter().zip(&reference[0]).map(|(a, b)| (a - b).powi(2)).sum::<f64>();
            (num / den).sqrt()
        })
        .collect()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

struct Plan {
    solver: SolverParams,
    step: f64,
    step_label: String,
    note: String,
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    let out = args.iter().position(|a| a == "--out").and_then(|i| args.get(i + 1)).cloned().unwrap_or_else(|| "report".into());
    // Quick mode (CI): small scenes, short runs, one repeat.
    let seconds = if quick { 0.5 } else { 2.0 };
    let repeats = if quick { 1 } else { 3 };
    let reference_dt = if quick { 2e-4 } else { 1e-4 };
    // Wall time one run may take before it is stopped and listed as over budget.
    let budget_s = if quick { 5.0 } else { 10.0 };
    let cases: Vec<SceneCase> = if quick {
        ["paper-2d-top-row", "paper-3d-sheet"].into_iter().map(|n| SceneCase { label: n.into(), params: scenes::canonical(n).unwrap().grid }).collect()
    } else {
        let mut c: Vec<SceneCase> = scenes::names().into_iter().map(|n| SceneCase { label: n.into(), params: scenes::canonical(n).unwrap().grid }).collect();
        c.push(SceneCase { label: "cloth-3d-100x100".into(), params: scenes::cloth(100, 100).grid });
        c
    };
    std::fs::create_dir_all(&out).expect("cannot create the output folder");

    // Every way of running each scene.
    let mut plans: Vec<(usize, Vec<Plan>)> = Vec::new();
    for (ci, case) in cases.iter().enumerate() {
        let p = &case.params;
        let n = p.build().unwrap().n_dofs();
        let full = |integrator, max_internal_step| SolverParams {
            reduction: Reduction::Full,
            integrator,
            n_modes: 0,
            max_internal_step,
            substepping: true,
            basis: BasisOptions::default(),
            force: ForceOptions::default(),
        };
        let mut mode_counts: Vec<usize> = std::iter::successors(Some(1usize), |r| Some(r * 2)).take_while(|&r| r < n).collect();
        // Beyond a quarter of the DOFs the basis needs the dense eigensolver;
        // of those, only all modes are run (set-up alone takes tens of
        // seconds at a few thousand DOFs).
        mode_counts.retain(|&r| r <= 64 || r * 16 <= n);
        if n <= modes::MAX_DENSE_DOFS {
            mode_counts.push(n);
        }
        let springs = p.build().unwrap().springs.len();
        if quick {
            mode_counts.retain(|&r| r <= 8 || r == n);
        }
        let steps: &[(f64, &str)] = if quick { &STEPS[1..] } else { &STEPS };
        let mut list = Vec::new();
        for &(h, label) in steps {
            for integrator in [Integrator::NewmarkExplicit, Integrator::NewmarkImplicit] {
                list.push(Plan { solver: full(integrator, h), step: h, step_label: label.into(), note: String::new() });
                for &r in &mode_counts {
                    let solver = SolverParams {
                        reduction: Reduction::Modal,
                        integrator,
                        n_modes: r,
                        max_internal_step: h,
                        substepping: true,
                        basis: BasisOptions::default(),
                        force: ForceOptions::default(),
                    };
                    // The implicit Newton matrix Phi^T K(x) Phi costs about
                    // springs x r^2 x 30 flops per iteration; beyond
                    // IMPLICIT_TANGENT_LIMIT a single step takes seconds.
                    let note = if integrator == Integrator::NewmarkImplicit && (springs * r * r) as f64 > IMPLICIT_TANGENT_LIMIT {
                        format!(
                            "not run: the reduced tangent needs springs x r^2 = {:.1e} > {IMPLICIT_TANGENT_LIMIT:.0e} per Newton iteration",
                            (springs * r * r) as f64
                        )
                    } else {
                        String::new()
                    };
                    list.push(Plan { solver, step: h, step_label: label.into(), note });
                }
            }
        }
        // Full space, explicit, at internal steps below its largest stable one.
        let stable_dt = Simulator::new(p.build().unwrap(), &full(Integrator::NewmarkExplicit, 1.0), &Loads::physical(0)).unwrap().max_stable_step();
        for frac in [0.5, 0.25] {
            list.push(Plan {
                solver: full(Integrator::NewmarkExplicit, stable_dt * frac),
                step: 1.0 / 240.0,
                step_label: "1/240".into(),
                note: format!("internal step {frac} x the stable one"),
            });
        }
        plans.push((ci, list));
    }
    let total: usize = plans.iter().map(|(_, l)| l.len() + 3).sum();
    let bar = ProgressBar::new(total as u64);
    bar.set_style(ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} {msg}").unwrap().progress_chars("=> "));

    let mut rows: Vec<Row> = Vec::new();
    let mut reference_notes = String::new();
    for (ci, list) in plans {
        let case = &cases[ci];
        let p = &case.params;
        let n = p.build().unwrap().n_dofs();
        let full = |integrator, max_internal_step| SolverParams {
            reduction: Reduction::Full,
            integrator,
            n_modes: 0,
            max_internal_step,
            substepping: true,
            basis: BasisOptions::default(),
            force: ForceOptions::default(),
        };
        bar.set_message(format!("{}: reference", case.label));
        let reference = simulate(p, &full(Integrator::NewmarkExplicit, reference_dt), reference_dt, seconds, f64::INFINITY).expect("reference run failed");
        bar.inc(1);
        bar.set_message(format!("{}: reference at half the step", case.label));
        let halved =
            simulate(p, &full(Integrator::NewmarkExplicit, reference_dt / 2.0), reference_dt / 2.0, seconds, f64::INFINITY).expect("reference check failed");
        bar.inc(1);
        bar.set_message(format!("{}: reference at a quarter of the step", case.label));
        let quartered =
            simulate(p, &full(Integrator::NewmarkExplicit, reference_dt / 4.0), reference_dt / 4.0, seconds, f64::INFINITY).expect("reference check failed");
        bar.inc(1);
        let self_by_window = errors_by_window(&reference.frames, &halved.frames);
        let self_error = *self_by_window.last().unwrap();
        let halved_error = error(&halved.frames, &quartered.frames);
        let mut run_by_window: Vec<Vec<f64>> = Vec::new();
        let first = rows.len();
        // Full-space trajectories by (integrator, step), for the vs_full column.
        let mut full_runs: Vec<(Integrator, String, Vec<Vec<f64>>)> = Vec::new();
        for plan in list {
            let s = &plan.solver;
            let method = if s.reduction == Reduction::Modal { "modal" } else { "full" };
            bar.set_message(format!("{}: {method} {} r={} step {}", case.label, s.integrator.name(), s.n_modes, plan.step_label));
            let mut times = Vec::new();
            let mut last = None;
            if plan.note.starts_with("not run") {
                last = Some(Err(plan.note.clone()));
            }
            for k in 0..if last.is_some() { 0 } else { repeats } {
                match simulate(p, s, plan.step, seconds, budget_s) {
                    Ok(t) => {
                        times.push(t.run_s / seconds);
                        // Runs longer than a few seconds are timed once.
                        let long = t.run_s > 2.0;
                        last = Some(Ok(t));
                        if long && k == 0 {
                            break;
                        }
                    }
                    Err(e) => {
                        last = Some(Err(e));
                        break;
                    }
                }
            }
            bar.inc(1);
            let mut row = Row {
                scene: case.label.clone(),
                dofs: n,
                method,
                integrator: s.integrator.name(),
                modes: if s.reduction == Reduction::Modal { s.n_modes } else { n },
                step: plan.step,
                step_label: plan.step_label.clone(),
                internal_steps: 0,
                setup_s: f64::NAN,
                run_s_per_sim_s: f64::NAN,
                error: f64::NAN,
                max_node_error: f64::NAN,
                stable: false,
                vs_full: f64::NAN,
                error_resolved: f64::NAN,
                resolved_until_s: f64::NAN,
                note: plan.note.clone(),
            };
            match last.unwrap() {
                Ok(t) => {
                    let by_window = errors_by_window(&t.frames, &reference.frames);
                    let e = *by_window.last().unwrap();
                    row.internal_steps = t.internal_steps;
                    row.setup_s = t.setup_s;
                    row.run_s_per_sim_s = median(times);
                    row.error = e;
                    row.max_node_error = max_node_error(&t.frames, &reference.frames, p.dim);
                    run_by_window.push(by_window);
                    row.stable = e.is_finite();
                    if method == "full" && plan.note.is_empty() {
                        full_runs.push((s.integrator, plan.step_label.clone(), t.frames));
                    } else if let Some((_, _, f)) = full_runs.iter().find(|(i, l, _)| *i == s.integrator && *l == plan.step_label) {
                        row.vs_full = error(&t.frames, f);
                    }
                }
                Err(e) => {
                    row.note = e.replace(',', ";");
                    run_by_window.push(Vec::new());
                }
            }
            rows.push(row);
        }
        // The longest window from t = 0 over which the reference's own error
        // stays REFERENCE_MARGIN below the smallest error of any run.
        let smallest_by_window: Vec<f64> = (0..self_by_window.len())
            .map(|k| rows[first..].iter().zip(&run_by_window).filter(|(r, _)| r.stable).map(|(_, w)| w[k]).fold(f64::INFINITY, f64::min))
            .collect();
        let resolved = (2..=self_by_window.len()).take_while(|&k| REFERENCE_MARGIN * self_by_window[k - 1] <= smallest_by_window[k - 1]).last().unwrap_or(1);
        let resolved_until_s = (resolved - 1) as f64 * FRAME;
        for (row, w) in rows[first..].iter_mut().zip(&run_by_window) {
            row.resolved_until_s = resolved_until_s;
            row.error_resolved = w.get(resolved - 1).copied().unwrap_or(f64::NAN);
        }
        let self_error_resolved = self_by_window[resolved - 1];
        let smallest = rows[first..].iter().filter(|r| r.stable).map(|r| r.error).fold(f64::INFINITY, f64::min);
        let smallest_resolved = smallest_by_window[resolved - 1];
        let _ = writeln!(
            reference_notes,
            "| {} | {n} | {reference_dt} | {self_error:.2e} | {halved_error:.2e} | {smallest:.2e} | {:.0} | {resolved_until_s:.2} | {self_error_resolved:.2e} | {smallest_resolved:.2e} | {:.0} |",
            case.label,
            smallest / self_error,
            smallest_resolved / self_error_resolved
        );
    }
    bar.finish_with_message("done");
    write_csv(&out, &rows);
    write_readme(&out, &rows, &reference_notes, quick, seconds, repeats, budget_s);
}

fn write_csv(out: &str, rows: &[Row]) {
    let mut csv = String::from("scene,method,integrator,modes,step,internal_steps,setup_s,run_s_per_sim_s,error,max_node_error,stable,vs_full,error_resolved,resolved_until_s,dofs,step_label,note\n");
    for r in rows {
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{:.6e},{:.6e},{:.6e},{:.6e},{},{:.6e},{:.6e},{},{},{},{}",
            r.scene,
            r.method,
            r.integrator,
            r.modes,
            r.step,
            r.internal_steps,
            r.setup_s,
            r.run_s_per_sim_s,
            r.error,
            r.max_node_error,
            r.stable,
            r.vs_full,
            r.error_resolved,
            r.resolved_until_s,
            r.dofs,
            r.step_label,
            r.note
        );
    }
    std::fs::write(format!("{out}/error_vs_runtime.csv"), csv).expect("cannot write the CSV");
}

/// The runs no other run beats on both error and run time.
fn pareto<'a>(rows: &[&'a Row]) -> Vec<&'a Row> {
    let mut front: Vec<&Row> = rows
        .iter()
        .copied()
        .filter(|a| {
            a.stable
                && !rows.iter().any(|b| {
                    b.stable && b.error <= a.error && b.run_s_per_sim_s <= a.run_s_per_sim_s && (b.error < a.error || b.run_s_per_sim_s < a.run_s_per_sim_s)
                })
        })
        .collect();
    front.sort_by(|a, b| a.run_s_per_sim_s.total_cmp(&b.run_s_per_sim_s));
    front
}

/// For a modal run: the fastest full-space run whose error is at most the
/// modal run's, and the ratio of their run times (> 1: modal is faster).
fn speedup<'a>(modal: &Row, rows: &[&'a Row]) -> Option<(&'a Row, f64)> {
    rows.iter()
        .copied()
        .filter(|f| f.method == "full" && f.stable && f.error <= modal.error)
        .min_by(|a, b| a.run_s_per_sim_s.total_cmp(&b.run_s_per_sim_s))
        .map(|f| (f, f.run_s_per_sim_s / modal.run_s_per_sim_s))
}

/// Runs at or above this error are left out of the speed-up table.
const USEFUL_ERROR: f64 = 0.5;

fn describe(r: &Row) -> String {
    format!("{} {} r={} step {}", r.method, r.integrator, r.modes, r.step_label)
}

fn write_readme(out: &str, rows: &[Row], reference_notes: &str, quick: bool, seconds: f64, repeats: usize, budget_s: f64) {
    let mut md = String::new();
    let _ = writeln!(md, "# Error against run time\n");
    let _ = writeln!(
        md,
        "Generated by `cargo xtask report{}` on {} ({} cores). Simulated time {seconds} s per run, gravity only, from rest; run time is \
         the median of up to {repeats} run(s) (runs over 2 s timed once), wall time per simulated second, set-up (assembly + eigen \
         decomposition) apart; a run still going after {budget_s} s of wall time is stopped and listed as over budget. Error E is \
         docs/method.md, section 6 against a full-space explicit Newmark reference at a tiny step; output times every {FRAME} s. \
         `vs_full` in the CSV is E of a modal run against the full-space run with the same integrator and step.\n",
        if quick { " --quick" } else { "" },
        std::env::var("REPORT_DATE").unwrap_or_else(|_| "an unstated date".into()),
        std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
    );
    let _ = writeln!(
        md,
        "## References\n\nEach reference is checked against runs at half and a quarter of its step; the smallest error reported must \
         stay at least {REFERENCE_MARGIN}x above its own. Where E(dt) against E(dt/2) does not shrink with the step (column 5 not \
         about a quarter of column 4), the trajectory itself is sensitive: a round-off-sized difference grows until it is as large \
         as the errors reported. The window \"resolved until\" is the longest from t = 0 over which the reference's own error \
         stays {REFERENCE_MARGIN}x below the smallest error of any run over the same window; `error_resolved` in the CSV is E \
         over that window.\n\n\
         | scene | free DOFs | reference dt (s) | E(dt) against E(dt/2) | E(dt/2) against E(dt/4) | smallest E reported | ratio | \
         resolved until (s) | E(dt) against E(dt/2) there | smallest E there | ratio there |\n|---|---|---|---|---|---|---|---|---|---|---|\n{reference_notes}"
    );
    let mut scenes: Vec<&str> = rows.iter().map(|r| r.scene.as_str()).collect();
    scenes.dedup();
    let _ = writeln!(md, "## Speed-up of the modal method\n");
    let _ = writeln!(
        md,
        "Per scene, for each modal run on the scene's Pareto front: the fastest full-space run reaching at least the same error, \
         and the ratio of run times (above 1: the modal run is faster; below 1: it is slower by that factor). A modal run that no \
         full-space run matches on error needs a smaller step or more modes than the study has. Modal runs with E of \
         {USEFUL_ERROR} or more miss most of the motion (E = 1 is a sheet that does not move) and are left out.\n"
    );
    let _ = writeln!(
        md,
        "| scene | modal run | E | run s / sim s | fastest full-space run at that error | its run s / sim s | speed-up |\n|---|---|---|---|---|---|---|"
    );
    for &scene in &scenes {
        let rs: Vec<&Row> = rows.iter().filter(|r| r.scene == scene).collect();
        let front: Vec<&Row> = pareto(&rs).into_iter().filter(|r| r.method == "modal" && r.error < USEFUL_ERROR).collect();
        if front.is_empty() {
            let best = rs.iter().filter(|r| r.method == "modal" && r.stable).min_by(|a, b| a.error.total_cmp(&b.error));
            let _ = writeln!(
                md,
                "| {scene} | no modal run with E below {USEFUL_ERROR} on the Pareto front{} | | | | | |",
                best.map(|b| format!(" (best modal: {}, E = {:.2e})", describe(b), b.error)).unwrap_or_default()
            );
        }
        for m in front {
            match speedup(m, &rs) {
                Some((f, ratio)) => {
                    let _ = writeln!(
                        md,
                        "| {scene} | {} | {:.2e} | {:.2e} | {} | {:.2e} | {ratio:.2} |",
                        describe(m),
                        m.error,
                        m.run_s_per_sim_s,
                        describe(f),
                        f.run_s_per_sim_s
                    );
                }
                None => {
                    let _ = writeln!(md, "| {scene} | {} | {:.2e} | {:.2e} | none as accurate | | |", describe(m), m.error, m.run_s_per_sim_s);
                }
            }
        }
    }
    let _ = writeln!(md, "\n## Set-up against mesh size\n\nAssembly plus eigen decomposition (modal) or sparse symbolic analysis (full), from the explicit runs at step 1/240 s.\n");
    let _ = writeln!(md, "| scene | free DOFs | full (s) | modal r = 8 (s) | modal, most modes run (s) |\n|---|---|---|---|---|");
    for &scene in &scenes {
        let pick = |f: &dyn Fn(&Row) -> bool| {
            rows.iter()
                .filter(|r| r.scene == scene && r.step_label == "1/240" && r.integrator == "newmark-explicit" && r.setup_s.is_finite() && f(r))
                .max_by_key(|r| r.modes)
        };
        let dofs = rows.iter().find(|r| r.scene == scene).map(|r| r.dofs).unwrap_or(0);
        let full = pick(&|r| r.method == "full" && r.note.is_empty());
        let r8 = pick(&|r| r.method == "modal" && r.modes == 8);
        let most = pick(&|r| r.method == "modal");
        let fmt = |r: Option<&Row>| r.map(|r| format!("{:.3e}", r.setup_s)).unwrap_or_else(|| "-".into());
        let _ = writeln!(
            md,
            "| {scene} | {dofs} | {} | {} | {} |",
            fmt(full),
            fmt(r8),
            most.map(|r| format!("{:.3e} (r = {})", r.setup_s, r.modes)).unwrap_or_else(|| "-".into())
        );
    }
    let _ = writeln!(md);
    for &scene in &scenes {
        let rs: Vec<&Row> = rows.iter().filter(|r| r.scene == scene).collect();
        let _ = writeln!(md, "## {scene}\n\n![{scene}]({scene}.png)\n\nPareto front (runs not beaten on both error and run time):\n");
        let _ = writeln!(md, "| method | integrator | modes | step | internal steps | setup (s) | run s / sim s | E | max node error (m) |\n|---|---|---|---|---|---|---|---|---|");
        for r in pareto(&rs) {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {:.3e} | {:.3e} | {:.3e} | {:.3e} |",
                r.method, r.integrator, r.modes, r.step_label, r.internal_steps, r.setup_s, r.run_s_per_sim_s, r.error, r.max_node_error
            );
        }
        let failed: Vec<String> = rs.iter().filter(|r| !r.stable).map(|r| format!("{}: {}", describe(r), r.note)).collect();
        if !failed.is_empty() {
            let _ = writeln!(md, "\nRuns that failed, were refused or went over budget:\n");
            for u in failed {
                let _ = writeln!(md, "- {u}");
            }
        }
        let _ = writeln!(md);
    }
    let _ = writeln!(md, "All runs: `error_vs_runtime.csv`.");
    std::fs::write(format!("{out}/README.md"), md).expect("cannot write the report README");
}
