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
const STEPS: [(f64, &str); 4] = [(1.0 / 1000.0, "1/1000"), (1.0 / 240.0, "1/240"), (1.0 / 60.0, "1/60"), (1.0 / 20.0, "1/20")];
/// Index in [`STEPS`] of 1/60 s, the longest step of the large scenes' Newmark runs.
const STEP_60: usize = 2;
/// Relative error of the projected force the cubature variants ask for.
const CUBATURE_TOLERANCE: f64 = 0.01;

/// One way of building the modal basis and evaluating its force.
struct Variant {
    /// Name in the CSV and the plots.
    key: &'static str,
    /// Name in the report.
    label: &'static str,
    basis: BasisOptions,
    force: ForceOptions,
}

/// Index of the paper's method in [`variants`].
const PAPER: usize = 0;
const LOAD: usize = 1;
const LOAD_STATIC: usize = 2;

/// The paper's method first, then every other option the study compares with it.
fn variants() -> Vec<Variant> {
    use Linearization::{Equilibrium, Rest};
    use ModeSelection::{Load, Lowest};
    let basis = |selection, static_correction, linearization| BasisOptions { selection, static_correction, linearization, anchor_motion: false };
    let exact = ForceOptions { evaluation: ForceEvaluation::Exact, cubature_tolerance: CUBATURE_TOLERANCE };
    let cubature = ForceOptions { evaluation: ForceEvaluation::Cubature, cubature_tolerance: CUBATURE_TOLERANCE };
    let v = |key, label, basis, force| Variant { key, label, basis, force };
    vec![
        v("paper", "paper (lowest modes at rest)", basis(Lowest, false, Rest), exact.clone()),
        v("load", "load", basis(Load, false, Rest), exact.clone()),
        v("load+static", "load + static correction", basis(Load, true, Rest), exact.clone()),
        v("load+static@equilibrium", "load + static correction @ equilibrium", basis(Load, true, Equilibrium), exact),
        v("load+cubature", "load + cubature", basis(Load, false, Rest), cubature.clone()),
        v("load+static+cubature", "load + static correction + cubature", basis(Load, true, Rest), cubature.clone()),
        v("load+static@equilibrium+cubature", "load + static correction @ equilibrium + cubature", basis(Load, true, Equilibrium), cubature),
    ]
}

struct SceneCase {
    label: String,
    params: Grid,
}

struct Row {
    scene: String,
    dofs: usize,
    method: &'static str,
    /// Key of the variant ("full" in full space).
    variant: &'static str,
    integrator: &'static str,
    modes: usize,
    step: f64,
    step_label: String,
    internal_steps: usize,
    setup_s: f64,
    run_s_per_sim_s: f64,
    /// The same run's wall time without reading the node positions (a host
    /// that couples through the ports or reads the modal coordinates).
    step_s_per_sim_s: f64,
    error: f64,
    max_node_error: f64,
    stable: bool,
    /// E of this run against the full-space run with the same integrator and step.
    vs_full: f64,
    /// E over the output times up to `resolved_until_s` (see [`REFERENCE_MARGIN`]).
    error_resolved: f64,
    resolved_until_s: f64,
    /// Largest and mean `forceResidual` over the output times after t = 0.
    force_residual_max: f64,
    force_residual_mean: f64,
    /// Springs one force evaluation visits (every spring, or the cubature set).
    springs_visited: Option<usize>,
    note: String,
}

impl Row {
    /// A modal run that leaves modes out.
    fn leaves_out(&self) -> bool {
        self.method == "modal" && self.modes < self.dofs
    }
}

struct Trajectory {
    frames: Vec<Vec<f64>>,
    setup_s: f64,
    /// Wall time of each timed run [s].
    run_s: Vec<f64>,
    /// The same without the reads of the node positions [s].
    step_s: Vec<f64>,
    internal_steps: usize,
    force_residual_max: f64,
    force_residual_mean: f64,
    springs_visited: Option<usize>,
}

/// Implicit modal runs whose reduced tangent is costlier than this are not run.
const IMPLICIT_TANGENT_LIMIT: f64 = 5e7;

/// Runs over budget stop here; the report lists them as such (not as unstable).
const OVER_BUDGET: &str = "over the time budget";

/// Runs longer than this are timed once.
const TIME_ONCE_S: f64 = 2.0;

/// Springs one force evaluation of `sim` visits: every spring, or the cubature set.
fn springs_visited(sim: &Simulator) -> Option<usize> {
    Some(sim.cubature_springs())
}

/// A simulator set up once, the state it starts from, and the set-up's wall time.
struct Prepared {
    sim: Simulator,
    start: Snapshot,
    setup_s: f64,
}

fn set_up(p: &Grid, s: &SolverParams) -> Result<Prepared, PhysicsError> {
    let t0 = Instant::now();
    let sim = Simulator::new(p.build()?, s, &Loads::physical(s.n_modes))?;
    let setup_s = t0.elapsed().as_secs_f64();
    Ok(Prepared { start: sim.snapshot(), sim, setup_s })
}

/// Runs `repeats` times from the start of `prep`, co-simulation step `h`,
/// timing each run; a run longer than [`TIME_ONCE_S`] is not repeated.
/// Trajectories and `forceResidual` are those of the last run.
fn run(prep: &mut Prepared, h: f64, seconds: f64, budget_s: f64, repeats: usize) -> Result<Trajectory, String> {
    let sim = &mut prep.sim;
    let per_frame = (FRAME / h).round() as usize;
    let n_frames = (seconds / FRAME).round() as usize;
    let mut run_s = Vec::new();
    let mut step_s = Vec::new();
    let mut last = None;
    for _ in 0..repeats.max(1) {
        sim.restore(&prep.start).map_err(|e| e.to_string())?;
        let mut frames = Vec::with_capacity(n_frames + 1);
        frames.push(sim.positions().to_vec());
        let (mut internal_steps, mut fr_max, mut fr_sum, mut untimed, mut reading) = (0, 0.0f64, 0.0, 0.0, 0.0);
        let t1 = Instant::now();
        for _ in 0..n_frames {
            for _ in 0..per_frame {
                sim.do_step(h).map_err(|e| e.to_string())?;
                internal_steps += sim.internal_steps_last();
                if t1.elapsed().as_secs_f64() > budget_s {
                    return Err(format!("{OVER_BUDGET}: stopped after {budget_s} s of wall time at t = {:.3} s", sim.time()));
                }
            }
            let t3 = Instant::now();
            frames.push(sim.positions().to_vec());
            reading += t3.elapsed().as_secs_f64();
            // forceResidual visits every spring: read for the study, not timed.
            let t2 = Instant::now();
            let fr = sim.force_residual();
            untimed += t2.elapsed().as_secs_f64();
            fr_max = fr_max.max(fr);
            fr_sum += fr;
        }
        let elapsed = t1.elapsed().as_secs_f64() - untimed;
        run_s.push(elapsed);
        step_s.push(elapsed - reading);
        last = Some((frames, internal_steps / (per_frame * n_frames).max(1), fr_max, fr_sum / n_frames.max(1) as f64));
        if elapsed > TIME_ONCE_S {
            break;
        }
    }
    let (frames, internal_steps, force_residual_max, force_residual_mean) = last.unwrap();
    Ok(Trajectory {
        frames,
        setup_s: prep.setup_s,
        run_s,
        step_s,
        internal_steps,
        force_residual_max,
        force_residual_mean,
        springs_visited: springs_visited(sim),
    })
}

/// Sets up and runs.
fn simulate(p: &Grid, s: &SolverParams, h: f64, seconds: f64, budget_s: f64, repeats: usize) -> Result<Trajectory, String> {
    run(&mut set_up(p, s).map_err(|e| e.to_string())?, h, seconds, budget_s, repeats)
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

/// Ranks from 1, ties sharing their mean rank.
fn ranks(v: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..v.len()).collect();
    order.sort_by(|&a, &b| v[a].total_cmp(&v[b]));
    let mut r = vec![0.0; v.len()];
    let mut i = 0;
    while i < order.len() {
        let mut j = i;
        while j + 1 < order.len() && v[order[j + 1]] == v[order[i]] {
            j += 1;
        }
        for &k in &order[i..=j] {
            r[k] = (i + j) as f64 / 2.0 + 1.0;
        }
        i = j + 1;
    }
    r
}

/// Spearman's rank correlation (the Pearson correlation of the ranks), of
/// the values as the CSV has them (7 significant digits): runs that differ
/// by round-off (a sheet that does not move: E = 1, forceResidual = 1) tie.
fn spearman(x: &[f64], y: &[f64]) -> f64 {
    let csv = |v: &[f64]| v.iter().map(|a| format!("{a:.6e}").parse::<f64>().unwrap()).collect::<Vec<f64>>();
    let (rx, ry) = (ranks(&csv(x)), ranks(&csv(y)));
    let n = rx.len() as f64;
    let (mx, my) = (rx.iter().sum::<f64>() / n, ry.iter().sum::<f64>() / n);
    let cov: f64 = rx.iter().zip(&ry).map(|(a, b)| (a - mx) * (b - my)).sum();
    let vx: f64 = rx.iter().map(|a| (a - mx).powi(2)).sum();
    let vy: f64 = ry.iter().map(|b| (b - my).powi(2)).sum();
    cov / (vx * vy).sqrt()
}

struct Plan {
    solver: SolverParams,
    variant: usize,
    step: f64,
    step_label: String,
    note: String,
}

/// Why an implicit modal run is not run (its reduced tangent, Phi^T K(x)
/// Phi, costs about springs x r^2 x 30 flops per Newton iteration; beyond
/// IMPLICIT_TANGENT_LIMIT a single step takes seconds), or nothing.
fn tangent_note(integrator: Integrator, springs: usize, r: usize) -> String {
    if integrator == Integrator::NewmarkImplicit && (springs * r * r) as f64 > IMPLICIT_TANGENT_LIMIT {
        format!("not run: the reduced tangent needs springs x r^2 = {:.1e} > {IMPLICIT_TANGENT_LIMIT:.0e} per Newton iteration", (springs * r * r) as f64)
    } else {
        String::new()
    }
}

fn full_solver(integrator: Integrator, max_internal_step: f64) -> SolverParams {
    SolverParams {
        reduction: Reduction::Full,
        integrator,
        n_modes: 0,
        max_internal_step,
        substepping: true,
        basis: BasisOptions::default(),
        force: ForceOptions::default(),
    }
}

fn modal_solver(integrator: Integrator, n_modes: usize, max_internal_step: f64, v: &Variant) -> SolverParams {
    SolverParams { reduction: Reduction::Modal, integrator, n_modes, max_internal_step, substepping: true, basis: v.basis.clone(), force: v.force.clone() }
}

/// Scenes with more free DOFs than this get the variants' smallest grid.
const LARGE_DOFS: usize = 10_000;

/// The variants' grid in the full study, as (step index, scheme, modes kept):
/// explicit and trigonometric at every step with r = 1, 2, 4, ... 32 and
/// implicit at steps 1/60 and 1/20 up to r = 16. On large scenes (cloth
/// 100 x 100) a run with exact forces costs about as much as a full-space
/// one, and the equilibrium takes a minute to solve there: explicit at steps
/// 1/240 and 1/60, trigonometric at 1/240, 1/60 and 1/20, with r = 2, 8, 32
/// (at the equilibrium only r = 32), implicit
/// only with cubature (its tangent visits the cubature set only), r = 2 and
/// 8 at step 1/60.
fn variant_grid(n: usize, v: &Variant) -> Vec<(usize, Integrator, usize)> {
    use Integrator::{NewmarkExplicit, NewmarkImplicit, Trigonometric};
    let mut grid = Vec::new();
    if n <= LARGE_DOFS {
        for si in 0..STEPS.len() {
            for r in [1, 2, 4, 8, 16, 32] {
                grid.push((si, NewmarkExplicit, r));
                grid.push((si, Trigonometric, r));
            }
        }
        for si in STEP_60..STEPS.len() {
            for r in [1, 2, 4, 8, 16] {
                grid.push((si, NewmarkImplicit, r));
            }
        }
    } else {
        let at_equilibrium = v.basis.linearization == Linearization::Equilibrium;
        let cubature = v.force.evaluation == ForceEvaluation::Cubature;
        let counts: &[usize] = match (at_equilibrium, cubature) {
            (false, _) => &[2, 8, 32],
            (true, false) => &[32],
            (true, true) => &[32],
        };
        for si in 1..STEPS.len() {
            for &r in counts {
                if si <= STEP_60 && r <= 32 {
                    grid.push((si, NewmarkExplicit, r));
                }
                grid.push((si, Trigonometric, r));
            }
        }
        if cubature && !at_equilibrium {
            for r in [2, 8] {
                grid.push((STEP_60, NewmarkImplicit, r));
            }
        }
    }
    grid.retain(|&(_, _, r)| r < n);
    grid
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    let variants_only = args.iter().any(|a| a == "--variants-only");
    let log = args.iter().any(|a| a == "--log");
    let out = args.iter().position(|a| a == "--out").and_then(|i| args.get(i + 1)).cloned().unwrap_or_else(|| "report".into());
    let only: Vec<&String> = args.iter().enumerate().filter(|(i, _)| *i > 0 && args[i - 1] == "--scene").map(|(_, a)| a).collect();
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
        ["paper-2d-top-row", "paper-3d-sheet"].into_iter().map(|n| SceneCase { label: n.into(), params: scenes::canonical(n).unwrap().grid }).collect()
    } else {
        let mut c: Vec<SceneCase> = scenes::names().into_iter().map(|n| SceneCase { label: n.into(), params: scenes::canonical(n).unwrap().grid }).collect();
        c.push(SceneCase { label: "cloth-3d-100x100".into(), params: scenes::cloth(100, 100).grid });
        c
    };
    if !only.is_empty() {
        cases.retain(|c| only.iter().any(|o| **o == c.label));
    }
    std::fs::create_dir_all(&out).expect("cannot create the output folder");

    // Every way of running each scene.
    let mut plans: Vec<(usize, Vec<Plan>)> = Vec::new();
    for (ci, case) in cases.iter().enumerate() {
        let p = &case.params;
        let n = p.build().unwrap().n_dofs();
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
        let large = n > LARGE_DOFS;
        let mut list = Vec::new();
        let paper = &variants[PAPER];
        for (si, &(h, label)) in steps.iter().enumerate() {
            let si = si + STEPS.len() - steps.len();
            for integrator in [Integrator::NewmarkExplicit, Integrator::NewmarkImplicit, Integrator::Trigonometric] {
                // The trigonometric scheme needs the modal space; on large
                // scenes the paper's grid runs Newmark at steps up to 1/60
                // and the trigonometric scheme at 1/60 and 1/20.
                let trigonometric = integrator == Integrator::Trigonometric;
                if !trigonometric {
                    list.push(Plan { solver: full_solver(integrator, h), variant: PAPER, step: h, step_label: label.into(), note: String::new() });
                }
                if variants_only || (large && if trigonometric { si < STEP_60 } else { si > STEP_60 }) {
                    continue;
                }
                for &r in &mode_counts {
                    let note = tangent_note(integrator, springs, r);
                    list.push(Plan { solver: modal_solver(integrator, r, h, paper), variant: PAPER, step: h, step_label: label.into(), note });
                }
            }
        }
        // Full space, explicit, at internal steps below its largest stable one.
        let stable_dt = Simulator::new(p.build().unwrap(), &full_solver(Integrator::NewmarkExplicit, 1.0), &Loads::physical(0)).unwrap().max_stable_step();
        for frac in [0.5, 0.25] {
            list.push(Plan {
                solver: full_solver(Integrator::NewmarkExplicit, stable_dt * frac),
                variant: PAPER,
                step: 1.0 / 240.0,
                step_label: "1/240".into(),
                note: format!("internal step {frac} x the stable one"),
            });
        }
        // The other options, on a smaller grid; never with all modes (the
        // same space as full, whatever the basis options).
        let mut variant_runs: Vec<(usize, Integrator, usize, usize)> = Vec::new(); // (step index, scheme, r, variant)
        if quick {
            for v in 1..variants.len() {
                variant_runs.push((1, Integrator::NewmarkExplicit, 8, v));
                variant_runs.push((3, Integrator::Trigonometric, 8, v));
            }
            variant_runs.push((1, Integrator::NewmarkExplicit, 2, LOAD));
            // The runs of the fidelity targets (over the quick run's 0.5 s).
            variant_runs.push((0, Integrator::NewmarkExplicit, 8, LOAD_STATIC));
            variant_runs.push((0, Integrator::NewmarkExplicit, 2, LOAD));
            variant_runs.push((2, Integrator::Trigonometric, 16, LOAD_STATIC));
            variant_runs.push((3, Integrator::Trigonometric, 16, LOAD_STATIC));
        } else {
            for (v, variant) in variants.iter().enumerate().skip(1) {
                for (si, integrator, r) in variant_grid(n, variant) {
                    variant_runs.push((si, integrator, r, v));
                }
            }
        }
        for (si, integrator, r, v) in variant_runs {
            let (h, label) = STEPS[si];
            if r >= n {
                continue;
            }
            // Cubature's tangent is cheaper (its springs only); the rule
            // counts every spring until the simulator reports the set's size.
            let note = tangent_note(integrator, springs, r);
            list.push(Plan { solver: modal_solver(integrator, r, h, &variants[v]), variant: v, step: h, step_label: label.into(), note });
        }
        plans.push((ci, list));
    }
    let total: usize = plans.iter().map(|(_, l)| l.len() + 3).sum();
    let bar = ProgressBar::new(total as u64);
    bar.set_style(ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} {msg}").unwrap().progress_chars("=> "));

    let started = Instant::now();
    let mut rows: Vec<Row> = Vec::new();
    let mut reference_notes = String::new();
    for (ci, list) in plans {
        let case = &cases[ci];
        let p = &case.params;
        let n = p.build().unwrap().n_dofs();
        let reference_run = |dt: f64| simulate(p, &full_solver(Integrator::NewmarkExplicit, dt), dt, seconds, f64::INFINITY, 1);
        bar.set_message(format!("{}: reference", case.label));
        let reference_dt = reference_step(n);
        let reference = reference_run(reference_dt).expect("reference run failed");
        bar.inc(1);
        bar.set_message(format!("{}: reference at half the step", case.label));
        let halved = reference_run(reference_dt / 2.0).expect("reference check failed");
        bar.inc(1);
        bar.set_message(format!("{}: reference at a quarter of the step", case.label));
        let quartered = reference_run(reference_dt / 4.0).expect("reference check failed");
        bar.inc(1);
        let self_by_window = errors_by_window(&reference.frames, &halved.frames);
        let self_error = *self_by_window.last().unwrap();
        let halved_error = error(&halved.frames, &quartered.frames);
        let mut run_by_window: Vec<Vec<f64>> = Vec::new();
        let first = rows.len();
        // Full-space trajectories by (integrator, step), for the vs_full column.
        let mut full_runs: Vec<(Integrator, String, Vec<Vec<f64>>)> = Vec::new();
        // Full space first (the modal runs compare with it: vs_full); each
        // modal configuration is set up once for all its steps, with the
        // longest of them as its internal step bound. A shorter co-simulation
        // step h splits into the same internal steps as a simulator bounded
        // by h would take (dt_max only matters where it is below h), so the
        // runs are those of separate set-ups; only the refusal of a scheme too
        // stiff for its bound depends on it, and such a set-up is redone per step.
        let mut order: Vec<usize> = (0..list.len()).filter(|&i| list[i].solver.reduction == Reduction::Full).collect();
        let mut groups: Vec<((Integrator, usize, usize), Vec<usize>)> = Vec::new();
        for (i, plan) in list.iter().enumerate().filter(|(_, p)| p.solver.reduction == Reduction::Modal) {
            let key = (plan.solver.integrator, plan.solver.n_modes, plan.variant);
            match groups.iter_mut().find(|(k, _)| *k == key) {
                Some((_, g)) => g.push(i),
                None => groups.push((key, vec![i])),
            }
        }
        order.extend(groups.iter().flat_map(|(_, g)| g.iter().copied()));
        let mut slots: Vec<Option<(Row, Vec<f64>)>> = (0..list.len()).map(|_| None).collect();
        let mut prepared: Option<((Integrator, usize, usize), Result<Prepared, PhysicsError>)> = None;
        for &i in &order {
            let plan = &list[i];
            let s = &plan.solver;
            let modal = s.reduction == Reduction::Modal;
            let method = if modal { "modal" } else { "full" };
            let variant = if modal { variants[plan.variant].key } else { "full" };
            bar.set_message(format!("{}: {method} {variant} {} r={} step {}", case.label, s.integrator.name(), s.n_modes, plan.step_label));
            let result = if plan.note.starts_with("not run") {
                Err(plan.note.clone())
            } else if !modal {
                simulate(p, s, plan.step, seconds, budget_s, repeats)
            } else {
                let key = (s.integrator, s.n_modes, plan.variant);
                if prepared.as_ref().map(|(k, _)| *k) != Some(key) {
                    drop(prepared.take()); // frees the last configuration's basis first
                    let group = &groups.iter().find(|(k, _)| *k == key).unwrap().1;
                    let longest = group.iter().filter(|&&j| !list[j].note.starts_with("not run")).map(|&j| list[j].step).fold(plan.step, f64::max);
                    prepared = Some((key, set_up(p, &SolverParams { max_internal_step: longest, ..s.clone() })));
                }
                match &mut prepared.as_mut().unwrap().1 {
                    Ok(prep) => run(prep, plan.step, seconds, budget_s, repeats),
                    Err(PhysicsError::ExplicitTooStiff { .. }) => simulate(p, s, plan.step, seconds, budget_s, repeats),
                    Err(e) => Err(e.to_string()),
                }
            };
            bar.inc(1);
            let mut row = Row {
                scene: case.label.clone(),
                dofs: n,
                method,
                variant,
                integrator: s.integrator.name(),
                modes: if modal { s.n_modes } else { n },
                step: plan.step,
                step_label: plan.step_label.clone(),
                internal_steps: 0,
                setup_s: f64::NAN,
                run_s_per_sim_s: f64::NAN,
                step_s_per_sim_s: f64::NAN,
                error: f64::NAN,
                max_node_error: f64::NAN,
                stable: false,
                vs_full: f64::NAN,
                error_resolved: f64::NAN,
                resolved_until_s: f64::NAN,
                force_residual_max: f64::NAN,
                force_residual_mean: f64::NAN,
                springs_visited: None,
                note: plan.note.clone(),
            };
            let by_window = match result {
                Ok(t) => {
                    let by_window = errors_by_window(&t.frames, &reference.frames);
                    let e = *by_window.last().unwrap();
                    row.internal_steps = t.internal_steps;
                    row.setup_s = t.setup_s;
                    row.run_s_per_sim_s = median(t.run_s.iter().map(|r| r / seconds).collect());
                    row.step_s_per_sim_s = median(t.step_s.iter().map(|r| r / seconds).collect());
                    row.error = e;
                    row.max_node_error = max_node_error(&t.frames, &reference.frames, p.dim);
                    row.force_residual_max = t.force_residual_max;
                    row.force_residual_mean = t.force_residual_mean;
                    row.springs_visited = t.springs_visited;
                    row.stable = e.is_finite();
                    if method == "full" && plan.note.is_empty() {
                        full_runs.push((s.integrator, plan.step_label.clone(), t.frames));
                    } else if let Some((_, _, f)) = full_runs.iter().find(|(i, l, _)| *i == s.integrator && *l == plan.step_label) {
                        row.vs_full = error(&t.frames, f);
                    }
                    by_window
                }
                Err(e) => {
                    row.note = e.replace([',', '\n'], ";");
                    Vec::new()
                }
            };
            if log {
                bar.suspend(|| {
                    eprintln!(
                        "{} | {} | set-up {:.3} s | {:.3e} s / sim s | E {:.3e} | {:.1} s since start | {}",
                        row.scene,
                        describe(&row),
                        row.setup_s,
                        row.run_s_per_sim_s,
                        row.error,
                        started.elapsed().as_secs_f64(),
                        row.note
                    )
                });
            }
            slots[i] = Some((row, by_window));
        }
        drop(prepared);
        for (row, w) in slots.into_iter().map(Option::unwrap) {
            rows.push(row);
            run_by_window.push(w);
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
    let study = Study { rows: &rows, variants: &variants, quick, seconds, repeats, budget_s, wall_s: started.elapsed().as_secs_f64() };
    write_csv(&out, &rows);
    write_readme(&out, &study, &reference_notes);
}

fn write_csv(out: &str, rows: &[Row]) {
    let mut csv = String::from(
        "scene,method,integrator,modes,step,internal_steps,setup_s,run_s_per_sim_s,error,max_node_error,stable,vs_full,error_resolved,resolved_until_s,dofs,step_label,\
         variant,force_residual_max,force_residual_mean,springs_visited,step_s_per_sim_s,note\n",
    );
    for r in rows {
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{:.6e},{:.6e},{:.6e},{:.6e},{},{:.6e},{:.6e},{},{},{},{},{:.6e},{:.6e},{},{:.6e},{}",
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
            r.variant,
            r.force_residual_max,
            r.force_residual_mean,
            r.springs_visited.map(|s| s.to_string()).unwrap_or_default(),
            r.step_s_per_sim_s,
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

/// For a modal run: the fastest full-space run whose error (over the window
/// the reference resolves) is at most the modal run's, and the ratio of
/// their run times (> 1: modal is faster).
fn speedup<'a>(modal: &Row, rows: &[&'a Row]) -> Option<(&'a Row, f64)> {
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
fn best_leave_out<'a>(rows: &[&'a Row], limit: f64, keep: &dyn Fn(&Row) -> bool) -> Option<(&'a Row, Option<(&'a Row, f64)>)> {
    let candidates: Vec<&Row> = rows.iter().copied().filter(|r| r.leaves_out() && r.stable && r.error_resolved <= limit && keep(r)).collect();
    let matched = candidates.iter().filter_map(|&m| speedup(m, rows).map(|s| (m, s))).max_by(|a, b| a.1 .1.total_cmp(&b.1 .1));
    match matched {
        Some((m, s)) => Some((m, Some(s))),
        None => candidates.into_iter().min_by(|a, b| a.error_resolved.total_cmp(&b.error_resolved)).map(|m| (m, None)),
    }
}

/// Runs at or above this error are left out of the speed-up tables.
const USEFUL_ERROR: f64 = 0.5;
/// Error levels of the speed-up table.
const LEVELS: [f64; 5] = [USEFUL_ERROR, 0.1, 0.05, 0.02, 0.01];

fn describe(r: &Row) -> String {
    if r.method == "full" {
        format!("full {} step {}", r.integrator, r.step_label)
    } else {
        format!("modal {} {} r={} step {}", r.variant, r.integrator, r.modes, r.step_label)
    }
}

struct Study<'a> {
    rows: &'a [Row],
    variants: &'a [Variant],
    quick: bool,
    seconds: f64,
    repeats: usize,
    budget_s: f64,
    wall_s: f64,
}

/// One line of the targets table: what is measured, the goal, and whether it holds.
struct Target {
    what: String,
    goal: String,
    measured: String,
    met: Option<bool>,
}

/// The run of `variant` with `r` modes, `integrator` and step `step` (a label of [`STEPS`]) at E ≤ `limit`.
fn fidelity_target(rows: &[Row], scene: &str, variant: usize, variants: &[Variant], r: usize, integrator: Integrator, step: &str, limit: f64) -> Target {
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
fn speedup_target(rows: &[Row], scene: &str, limit: f64, goal: f64, what: String, keep: &dyn Fn(&Row) -> bool) -> Target {
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

fn write_readme(out: &str, study: &Study, reference_notes: &str) {
    let Study { rows, variants, quick, seconds, repeats, budget_s, wall_s } = *study;
    let mut md = String::new();
    let _ = writeln!(md, "# Error against run time\n");
    let _ = writeln!(
        md,
        "Generated by `cargo xtask report{}` on {} ({} cores) in {:.0} min of wall time. Simulated time {seconds} s per run, gravity \
         only, from rest; run time is the median of up to {repeats} run(s) from one set-up (runs over {TIME_ONCE_S} s timed once), \
         wall time per simulated second, set-up (assembly, eigen decomposition, equilibrium, cubature training) apart; a run still \
         going after {budget_s} s of wall time is stopped and listed as over budget. Error E is docs/method.md, section 6 against a \
         full-space explicit Newmark reference at a tiny step; output times every {FRAME} s. A run reads the node positions at every output \
         time, as a host that draws or couples them would, and nothing else: outputs nobody reads are not computed \
         (`forceResidual`, which visits every spring, is read at the output times for the study outside the timing). \
         `vs_full` in the CSV is E of a modal \
         run against the full-space run with the same integrator and step. Speed-ups, mode counts and targets judge E over the \
         window the reference resolves (`error_resolved`, see References; the whole run except on cloth-3d-100x100).\n",
        if quick { " --quick" } else { "" },
        std::env::var("REPORT_DATE").unwrap_or_else(|_| "an unstated date".into()),
        std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
        wall_s / 60.0
    );
    if quick {
        let _ = writeln!(md, "Quick report: short runs on two small scenes; the targets below are stated for the full report's 2 s runs.\n");
    }

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

    // Variants.
    let _ = writeln!(
        md,
        "\n## Variants\n\nThe paper's method keeps the lowest modes at rest and evaluates every spring each step \
         (`modeSelection = lowest`, no `staticCorrection`, `linearization = rest`, `forceEvaluation = exact`); it runs on the \
         whole grid of mode counts with explicit and implicit Newmark and the trigonometric scheme (docs/method.md, section 4; \
         modal space only) at every step (on cloth-3d-100x100 Newmark up to step 1/60, the trigonometric scheme at 1/60 and 1/20). The other options (docs/method.md, section 3) run beside it on a smaller grid{}, never with all modes:\n",
        if quick {
            " (quick: explicit at step 1/240 and trigonometric at step 1/20 with r = 8, load also with r = 2, and the runs of the \
             fidelity targets)"
        } else {
            " (explicit and trigonometric at every step with r = 1, 2, 4, … 32 and implicit at steps 1/60 and 1/20 up to r = 16; on \
             cloth-3d-100x100, where the equilibrium takes about a minute to solve and a run with exact forces costs about as much as \
             a full-space one, explicit at steps 1/240 and 1/60 and trigonometric at 1/240, 1/60 and 1/20 with r = 2, 8, 32 (at the \
             equilibrium r = 32 only), and implicit with cubature at the rest linearization, r = 2 and 8 \
             at step 1/60)"
        }
    );
    let _ = writeln!(md, "| variant (CSV) | modes | static correction | linearized at | force |\n|---|---|---|---|---|");
    for v in variants {
        let _ = writeln!(
            md,
            "| {} (`{}`) | {} | {} | {} | {} |",
            v.label,
            v.key,
            v.basis.selection.name(),
            if v.basis.static_correction { "yes" } else { "no" },
            v.basis.linearization.name(),
            match v.force.evaluation {
                ForceEvaluation::Exact => "every spring".to_string(),
                ForceEvaluation::Cubature => format!("cubature, tolerance {}", v.force.cubature_tolerance),
            }
        );
    }

    let _ = writeln!(
        md,
        "\n## References\n\nEach reference is checked against runs at half and a quarter of its step; the smallest error reported must \
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

    // Speed-up at equal error.
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
    for &scene in &scenes {
        let rs: Vec<&Row> = rows.iter().filter(|r| r.scene == scene).collect();
        for limit in LEVELS {
            match best_leave_out(&rs, limit, &|_| true) {
                None => {
                    let _ = writeln!(md, "| {scene} | {limit} | none | | | | | | |");
                }
                Some((m, None)) => {
                    let _ =
                        writeln!(md, "| {scene} | {limit} | {} | {:.2e} | {:.2e} | none as accurate | | | |", describe(m), m.error_resolved, m.run_s_per_sim_s);
                }
                Some((m, Some((f, ratio)))) => {
                    let _ = writeln!(
                        md,
                        "| {scene} | {limit} | {} | {:.2e} | {:.2e} | {} | {:.2e} | {:.2e} | {ratio:.2} |",
                        describe(m),
                        m.error_resolved,
                        m.run_s_per_sim_s,
                        describe(f),
                        f.error_resolved,
                        f.run_s_per_sim_s
                    );
                }
            }
        }
    }

    // Integrators side by side.
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
    for &scene in &scenes {
        let rs: Vec<&Row> = rows.iter().filter(|r| r.scene == scene).collect();
        for limit in [0.1, 0.05, 0.02, 0.01] {
            for integrator in [Integrator::NewmarkExplicit, Integrator::NewmarkImplicit, Integrator::Trigonometric] {
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
                            m.error_resolved,
                            m.internal_steps,
                            m.run_s_per_sim_s,
                            m.step_s_per_sim_s
                        );
                    }
                }
            }
        }
    }

    // Variants side by side.
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
    for &scene in &scenes {
        let rs: Vec<&Row> = rows.iter().filter(|r| r.scene == scene).collect();
        for v in variants {
            let vr: Vec<&Row> = rs.iter().copied().filter(|r| r.method == "modal" && r.variant == v.key).collect();
            if vr.is_empty() {
                continue;
            }
            let ran: Vec<&Row> = vr.iter().copied().filter(|r| !r.note.starts_with("not run")).collect();
            let failed = ran.iter().filter(|r| !r.stable).count();
            let best = vr.iter().filter(|r| r.stable).map(|r| r.error_resolved).fold(f64::INFINITY, f64::min);
            let fewest = |limit: f64| {
                vr.iter()
                    .filter(|r| r.stable && r.error_resolved <= limit)
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

    // forceResidual against E.
    let _ = writeln!(
        md,
        "\n## forceResidual against the true error\n\n`forceResidual` (docs/method.md, section 6) is read after every output frame \
         of every modal run; the CSV has its largest and mean value over the run (`force_residual_max`, `force_residual_mean`) \
         beside E. How well it ranks runs by their true error: Spearman's rank correlation between each and E, over the stable \
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
    let mut all_scenes: Vec<&str> = scenes.clone();
    all_scenes.push("all scenes");
    for &scene in &all_scenes {
        let rs: Vec<&Row> =
            rows.iter().filter(|r| (scene == "all scenes" || r.scene == scene) && r.leaves_out() && r.stable && r.force_residual_max.is_finite()).collect();
        let rho = |rs: &[&Row], f: &dyn Fn(&Row) -> f64| {
            if rs.len() < 3 {
                return "-".to_string();
            }
            let x: Vec<f64> = rs.iter().map(|r| f(r)).collect();
            let y: Vec<f64> = rs.iter().map(|r| r.error_resolved).collect();
            format!("{:.2}", spearman(&x, &y))
        };
        let fine: Vec<&Row> = rs.iter().copied().filter(|r| r.integrator == "newmark-explicit" && r.step_label == "1/1000").collect();
        let below = rs.iter().filter(|r| r.force_residual_max < 0.5).map(|r| r.error_resolved).fold(f64::NAN, f64::max);
        let above = rs.iter().filter(|r| r.force_residual_max > 0.9).map(|r| r.error_resolved).fold(f64::NAN, f64::min);
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

    // Set-up.
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
    for &scene in &scenes {
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

    // Per scene.
    for &scene in &scenes {
        let rs: Vec<&Row> = rows.iter().filter(|r| r.scene == scene).collect();
        let _ = writeln!(md, "## {scene}\n\n![{scene}]({scene}.png)\n\nPareto front (runs not beaten on both error and run time):\n");
        let _ = writeln!(
            md,
            "| method | variant | integrator | modes | step | internal steps | setup (s) | run s / sim s | E | forceResidual max | max node error (m) |\n\
             |---|---|---|---|---|---|---|---|---|---|---|"
        );
        for r in pareto(&rs) {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} | {:.3e} | {:.3e} | {:.3e} | {:.2} | {:.3e} |",
                r.method,
                r.variant,
                r.integrator,
                r.modes,
                r.step_label,
                r.internal_steps,
                r.setup_s,
                r.run_s_per_sim_s,
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
    let _ = writeln!(md, "All runs: `error_vs_runtime.csv`.");
    std::fs::write(format!("{out}/README.md"), md).expect("cannot write the report README");
}

fn short(integrator: &str) -> &str {
    integrator.strip_prefix("newmark-").unwrap_or(integrator)
}
