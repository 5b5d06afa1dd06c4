//! The error-against-run-time study (METHOD.md section 6): every way of
//! running each scene, timed, and its trajectory error against a full-space
//! reference. Writes `error_vs_runtime.csv` and `README.md` into the output
//! folder; `cargo xtask report` runs it and draws the plots.
//!
//! cargo run --release --example report -- [--quick] [--out DIR]

use std::fmt::Write as _;
use std::time::Instant;

use modal_mass_spring::physics::*;

/// Output times are multiples of this; every co-simulation step divides it.
const FRAME: f64 = 0.05;
const STEPS: [(f64, &str); 3] = [(1.0 / 1000.0, "1/1000"), (1.0 / 240.0, "1/240"), (1.0 / 60.0, "1/60")];

struct SceneCase {
    label: String,
    params: SceneParams,
}

struct Row {
    scene: String,
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
    note: String,
}

struct Trajectory {
    frames: Vec<Vec<f64>>,
    setup_s: f64,
    run_s: f64,
    internal_steps: usize,
}

fn integrator_name(i: Integrator) -> &'static str {
    match i {
        Integrator::NewmarkExplicit => "newmark-explicit",
        Integrator::NewmarkImplicit => "newmark-implicit",
    }
}

fn simulate(p: &SceneParams, s: &SolverParams, h: f64, seconds: f64) -> Result<Trajectory, SimError> {
    let t0 = Instant::now();
    let mut sim = Simulator::new(p, s, &Tunables::physical(s.n_modes))?;
    let setup_s = t0.elapsed().as_secs_f64();
    let per_frame = (FRAME / h).round() as usize;
    let n_frames = (seconds / FRAME).round() as usize;
    let mut frames = Vec::with_capacity(n_frames + 1);
    frames.push(sim.positions().to_vec());
    let mut internal_steps = 0;
    let t1 = Instant::now();
    for _ in 0..n_frames {
        for _ in 0..per_frame {
            sim.do_step(h)?;
            internal_steps += sim.internal_steps_last();
        }
        frames.push(sim.positions().to_vec());
    }
    Ok(Trajectory { frames, setup_s, run_s: t1.elapsed().as_secs_f64(), internal_steps: internal_steps / (per_frame * n_frames).max(1) })
}

/// E (METHOD.md section 6; equal node masses cancel) and the largest node distance error.
fn error(run: &[Vec<f64>], reference: &[Vec<f64>], d: usize) -> (f64, f64) {
    let (mut num, mut den, mut max_node) = (0.0, 0.0, 0.0f64);
    for (x, xr) in run.iter().zip(reference) {
        for i in 0..x.len() / d {
            let e2: f64 = (0..d).map(|c| (x[i * d + c] - xr[i * d + c]).powi(2)).sum();
            num += e2;
            max_node = max_node.max(e2.sqrt());
            den += (0..d).map(|c| (xr[i * d + c] - reference[0][i * d + c]).powi(2)).sum::<f64>();
        }
    }
    ((num / den).sqrt(), max_node)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    let out = args.iter().position(|a| a == "--out").and_then(|i| args.get(i + 1)).cloned().unwrap_or_else(|| "report".into());
    let seconds = if quick { 0.5 } else { 2.0 };
    let repeats = if quick { 1 } else { 3 };
    let reference_dt = if quick { 2e-4 } else { 1e-4 };
    let mut cases: Vec<SceneCase> = if quick {
        vec!["paper-2d-top-row", "paper-3d-sheet"].into_iter().map(|n| SceneCase { label: n.into(), params: SceneParams::canonical(n).unwrap() }).collect()
    } else {
        SCENE_NAMES[..3].iter().map(|n| SceneCase { label: (*n).into(), params: SceneParams::canonical(n).unwrap() }).collect()
    };
    if !quick {
        for size in [30, 100] {
            cases.push(SceneCase { label: format!("cloth-3d-{size}x{size}"), params: SceneParams::grid(size, size, 3, FixedNodes::TopRow) });
        }
    }
    std::fs::create_dir_all(&out).expect("cannot create the output folder");
    let mut rows: Vec<Row> = Vec::new();
    let mut reference_notes = String::new();
    for case in &cases {
        let p = &case.params;
        let n = scene::Scene::build(p).unwrap().n_dofs();
        let full = |integrator, max_internal_step| SolverParams { reduction: Reduction::Full, integrator, n_modes: 0, max_internal_step, substepping: true };
        eprintln!("[{}] reference: full space, explicit Newmark, dt = {reference_dt} s", case.label);
        let reference = simulate(p, &full(Integrator::NewmarkExplicit, reference_dt), reference_dt, seconds).expect("reference run failed");
        let halved = simulate(p, &full(Integrator::NewmarkExplicit, reference_dt / 2.0), reference_dt / 2.0, seconds).expect("reference check failed");
        let (self_error, _) = error(&reference.frames, &halved.frames, p.dimension);
        let _ = writeln!(reference_notes, "| {} | {n} | {reference_dt} | {self_error:.2e} |", case.label);

        // Every way of running the scene.
        let mut plans: Vec<(SolverParams, f64, String, String)> = Vec::new();
        let mut mode_counts: Vec<usize> = std::iter::successors(Some(1usize), |r| Some(r * 2)).take_while(|&r| r < n).collect();
        mode_counts.push(n);
        // Quick mode (CI): two steps and at most 8 modes besides all of them.
        if quick {
            mode_counts.retain(|&r| r <= 8 || r == n);
        }
        let steps: &[(f64, &str)] = if quick { &STEPS[1..] } else { &STEPS };
        for &(h, label) in steps {
            for integrator in [Integrator::NewmarkExplicit, Integrator::NewmarkImplicit] {
                plans.push((full(integrator, h), h, label.into(), String::new()));
                for &r in &mode_counts {
                    // The implicit reduced tangent costs O(springs r^2) per Newton iteration:
                    // beyond 64 modes only the largest step is run.
                    if integrator == Integrator::NewmarkImplicit && r > 64 && h < 1.0 / 60.0 {
                        continue;
                    }
                    plans.push((SolverParams { reduction: Reduction::Modal, integrator, n_modes: r, max_internal_step: h, substepping: true }, h, label.into(), String::new()));
                }
            }
        }
        // Full space explicit at smaller internal steps than its largest stable one.
        for frac in [0.5, 0.25] {
            let sim = Simulator::new(p, &full(Integrator::NewmarkExplicit, 1.0), &Tunables::physical(0)).unwrap();
            let dt = sim.max_stable_step() * frac;
            plans.push((full(Integrator::NewmarkExplicit, dt), 1.0 / 240.0, "1/240".into(), format!("internal step {frac} x stable")));
        }
        let total = plans.len();
        for (k, (s, h, label, note)) in plans.into_iter().enumerate() {
            let method = if s.reduction == Reduction::Modal { "modal" } else { "full" };
            eprintln!("[{}] {}/{total} {method} {} r={} step={label}", case.label, k + 1, integrator_name(s.integrator), s.n_modes);
            let mut times = Vec::new();
            let mut last = None;
            for _ in 0..repeats {
                match simulate(p, &s, h, seconds) {
                    Ok(t) => {
                        times.push(t.run_s / seconds);
                        last = Some(Ok(t));
                    }
                    Err(e) => {
                        last = Some(Err(e));
                        break;
                    }
                }
            }
            let modes = if s.reduction == Reduction::Modal { s.n_modes } else { n };
            let mut row = Row {
                scene: case.label.clone(),
                method,
                integrator: integrator_name(s.integrator),
                modes,
                step: h,
                step_label: label,
                internal_steps: 0,
                setup_s: f64::NAN,
                run_s_per_sim_s: f64::NAN,
                error: f64::NAN,
                max_node_error: f64::NAN,
                stable: false,
                note,
            };
            match last.unwrap() {
                Ok(t) => {
                    let (e, m) = error(&t.frames, &reference.frames, p.dimension);
                    row.internal_steps = t.internal_steps;
                    row.setup_s = t.setup_s;
                    row.run_s_per_sim_s = median(times);
                    row.error = e;
                    row.max_node_error = m;
                    row.stable = e.is_finite();
                }
                Err(e) => row.note = e.message.replace(',', ";"),
            }
            rows.push(row);
        }
    }
    write_csv(&out, &rows);
    write_readme(&out, &rows, &reference_notes, quick, seconds, repeats);
}

fn write_csv(out: &str, rows: &[Row]) {
    let mut csv = String::from("scene,method,integrator,modes,step,internal_steps,setup_s,run_s_per_sim_s,error,max_node_error,stable,step_label,note\n");
    for r in rows {
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{:.6e},{:.6e},{:.6e},{:.6e},{},{},{}",
            r.scene, r.method, r.integrator, r.modes, r.step, r.internal_steps, r.setup_s, r.run_s_per_sim_s, r.error, r.max_node_error, r.stable, r.step_label, r.note
        );
    }
    std::fs::write(format!("{out}/error_vs_runtime.csv"), csv).expect("cannot write the CSV");
}

/// The runs no other run beats on both error and run time.
fn pareto<'a>(rows: &[&'a Row]) -> Vec<&'a Row> {
    let mut front: Vec<&Row> = rows
        .iter()
        .copied()
        .filter(|a| a.stable && !rows.iter().any(|b| b.stable && b.error <= a.error && b.run_s_per_sim_s < a.run_s_per_sim_s && (b.error < a.error || b.run_s_per_sim_s < a.run_s_per_sim_s)))
        .collect();
    front.sort_by(|a, b| a.run_s_per_sim_s.partial_cmp(&b.run_s_per_sim_s).unwrap());
    front
}

fn write_readme(out: &str, rows: &[Row], reference_notes: &str, quick: bool, seconds: f64, repeats: usize) {
    let mut md = String::new();
    let _ = writeln!(md, "# Error against run time\n");
    let _ = writeln!(
        md,
        "Generated by `cargo xtask report{}` on {} ({} cores). Simulated time {seconds} s per run; run time is the median of {repeats} run(s), \
         wall time per simulated second, set-up (assembly + eigen decomposition) apart. Error E is METHOD.md section 6 against a full-space \
         explicit Newmark reference at a tiny step; output times every {FRAME} s.\n",
        if quick { " --quick" } else { "" },
        std::env::var("REPORT_DATE").unwrap_or_else(|_| "an unstated date".into()),
        std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
    );
    let _ = writeln!(md, "## References\n\n| scene | free DOFs | reference dt (s) | E(dt) against E(dt/2) |\n|---|---|---|---|\n{reference_notes}");
    let mut scenes: Vec<&str> = rows.iter().map(|r| r.scene.as_str()).collect();
    scenes.dedup();
    for scene in scenes {
        let rs: Vec<&Row> = rows.iter().filter(|r| r.scene == scene).collect();
        let _ = writeln!(md, "## {scene}\n\nPareto front (runs not beaten on both error and run time):\n");
        let _ = writeln!(md, "| method | integrator | modes | step | internal steps | setup (s) | run s / sim s | E | max node error (m) |\n|---|---|---|---|---|---|---|---|---|");
        for r in pareto(&rs) {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {:.3e} | {:.3e} | {:.3e} | {:.3e} |",
                r.method, r.integrator, r.modes, r.step_label, r.internal_steps, r.setup_s, r.run_s_per_sim_s, r.error, r.max_node_error
            );
        }
        let unstable: Vec<String> = rs.iter().filter(|r| !r.stable).map(|r| format!("{} {} r={} step {}: {}", r.method, r.integrator, r.modes, r.step_label, r.note)).collect();
        if !unstable.is_empty() {
            let _ = writeln!(md, "\nRuns that failed or were refused:\n");
            for u in unstable {
                let _ = writeln!(md, "- {u}");
            }
        }
        let _ = writeln!(md);
    }
    let _ = writeln!(md, "All runs: `error_vs_runtime.csv`.");
    std::fs::write(format!("{out}/README.md"), md).expect("cannot write the report README");
}
