//! One scene of the study: its reference (checked against runs at half and
//! a quarter of its step), every planned run measured against it, and the
//! window of time the reference resolves.

use std::fmt::Write as _;
use std::time::Instant;

use indicatif::ProgressBar;
use modal_mass_spring::measures::{max_node_error, median, trajectory_error, trajectory_errors_by_window, Masses};
use modal_mass_spring::physics::*;

use crate::fidelity::{coarse, deviation, twins, Twins};
use crate::plan::{full_solver, method, variant_key, Plan, SceneCase, Variant, FRAME, REFERENCE_MARGIN};
use crate::row::{describe, Row};
use crate::run::{run, set_up, simulate, Prepared};

/// A modal configuration set up once for all its steps: (scheme, modes, variant).
type Configuration = (Integrator, usize, usize);

/// What every scene's runs share.
pub struct Conditions<'a> {
    /// Simulated time of each run [s].
    pub seconds: f64,
    /// Timed runs per configuration (see [`crate::run::run`]).
    pub repeats: usize,
    /// Wall time one run may take before it is stopped [s].
    pub budget_s: f64,
    /// Print every run as it ends.
    pub log: bool,
    pub variants: &'a [Variant],
    pub bar: &'a ProgressBar,
    /// When the study started (for the log).
    pub started: Instant,
}

/// Runs the reference of `case` at `reference_dt(free DOFs)`, the scene's
/// twins and every run of `list`, appends a row per run to `rows` and the
/// reference's line of the References table to `notes`; returns the twins.
pub fn measure_scene(s: &Conditions, case: &SceneCase, list: Vec<Plan>, reference_dt: &dyn Fn(usize) -> f64, rows: &mut Vec<Row>, notes: &mut String) -> Twins {
    let Conditions { seconds, repeats, budget_s, log, variants, bar, started } = *s;
    let p = &case.params;
    let n = p.build().unwrap().n_dofs();
    let reference_dt = reference_dt(n);
    let change = case.change;
    let reference_run = |dt: f64| simulate(p, &full_solver(Integrator::NewmarkExplicit, dt), dt, seconds, f64::INFINITY, 1, change);
    bar.set_message(format!("{}: reference", case.label));
    let reference = reference_run(reference_dt).expect("reference run failed");
    bar.inc(1);
    bar.set_message(format!("{}: reference at half the step", case.label));
    let halved = reference_run(reference_dt / 2.0).expect("reference check failed");
    bar.inc(1);
    bar.set_message(format!("{}: reference at a quarter of the step", case.label));
    let quartered = reference_run(reference_dt / 4.0).expect("reference check failed");
    bar.inc(1);
    let self_by_window = trajectory_errors_by_window(&reference.frames, &halved.frames, &halved.frames[0], Masses::Equal);
    let self_error = *self_by_window.last().unwrap();
    let halved_error = trajectory_error(&halved.frames, &quartered.frames, &quartered.frames[0], Masses::Equal);
    bar.set_message(format!("{}: twins", case.label));
    let twins = twins(p, seconds, change, &|| bar.inc(1));
    let reference_coarse = coarse(p, &reference.frames, &reference.readings);
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
    let mut groups: Vec<(Configuration, Vec<usize>)> = Vec::new();
    for (i, plan) in list.iter().enumerate().filter(|(_, p)| p.solver.reduction == Reduction::Modal) {
        let key = (plan.solver.integrator, plan.solver.n_modes, plan.variant);
        match groups.iter_mut().find(|(k, _)| *k == key) {
            Some((_, g)) => g.push(i),
            None => groups.push((key, vec![i])),
        }
    }
    order.extend(groups.iter().flat_map(|(_, g)| g.iter().copied()));
    // Adaptive runs last, each set up for itself (its set-up reads its step bound).
    order.extend((0..list.len()).filter(|&i| list[i].solver.reduction == Reduction::Adaptive));
    // Each adaptive run's estimates at the output times, by its index in `list`.
    let mut estimates: Vec<(usize, Vec<f64>)> = Vec::new();
    let mut slots: Vec<Option<(Row, Vec<f64>)>> = (0..list.len()).map(|_| None).collect();
    let mut prepared: Option<(Configuration, Result<Prepared, PhysicsError>)> = None;
    for &i in &order {
        let plan = &list[i];
        let s = &plan.solver;
        let modal = s.reduction == Reduction::Modal;
        let (method, variant) = (method(s), variant_key(plan, variants));
        bar.set_message(format!("{}: {method} {variant} {} r={} step {}", case.label, s.integrator.name(), s.n_modes, plan.step_label));
        let result = if plan.note.starts_with("not run") {
            Err(plan.note.clone())
        } else if !modal {
            simulate(p, s, plan.step, seconds, budget_s, repeats, change)
        } else {
            let key = (s.integrator, s.n_modes, plan.variant);
            if prepared.as_ref().map(|(k, _)| *k) != Some(key) {
                drop(prepared.take()); // frees the last configuration's basis first
                let group = &groups.iter().find(|(k, _)| *k == key).unwrap().1;
                let longest = group.iter().filter(|&&j| !list[j].note.starts_with("not run")).map(|&j| list[j].step).fold(plan.step, f64::max);
                prepared = Some((key, set_up(p, &Settings { max_internal_step: longest, ..s.clone() })));
            }
            match &mut prepared.as_mut().unwrap().1 {
                Ok(prep) => run(prep, plan.step, seconds, budget_s, repeats, change),
                Err(PhysicsError::ExplicitTooStiff { .. }) => simulate(p, s, plan.step, seconds, budget_s, repeats, change),
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
            error_tolerance: if s.reduction == Reduction::Adaptive { s.error_tolerance } else { f64::NAN },
            error_estimate: f64::NAN,
            estimate_window: f64::NAN,
            reduced_fraction: f64::NAN,
            basis_size_end: None,
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
            error_window: f64::NAN,
            window_s: f64::NAN,
            predictable_until_s: twins.until_s.unwrap_or(f64::NAN),
            twin_floor: twins.floor,
            force_vs_twins: f64::NAN,
            bottom_vs_twins: f64::NAN,
            kinetic_vs_twins: f64::NAN,
            potential_vs_twins: f64::NAN,
        };
        let by_window = match result {
            Ok(t) => {
                let by_window = trajectory_errors_by_window(&t.frames, &reference.frames, &reference.frames[0], Masses::Equal);
                let e = *by_window.last().unwrap();
                row.internal_steps = t.internal_steps;
                row.setup_s = t.setup_s;
                row.run_s_per_sim_s = median(&mut t.run_s.iter().map(|r| r / seconds).collect::<Vec<f64>>());
                row.step_s_per_sim_s = median(&mut t.step_s.iter().map(|r| r / seconds).collect::<Vec<f64>>());
                row.error = e;
                row.max_node_error = max_node_error(&t.frames, &reference.frames, p.dim);
                row.force_residual_max = t.force_residual_max;
                row.force_residual_mean = t.force_residual_mean;
                row.springs_visited = t.springs_visited;
                if s.reduction == Reduction::Adaptive {
                    row.modes = t.setup_basis_size;
                    row.error_estimate = *t.estimates.last().unwrap();
                    row.reduced_fraction = t.reduced_fraction;
                    row.basis_size_end = Some(t.basis_size);
                    estimates.push((i, t.estimates));
                }
                row.stable = e.is_finite();
                let d = deviation(&coarse(p, &t.frames, &t.readings), &reference_coarse);
                [row.force_vs_twins, row.bottom_vs_twins, row.kinetic_vs_twins, row.potential_vs_twins] = std::array::from_fn(|o| d[o] / twins.spread[o]);
                if method == "full" && plan.note.is_empty() {
                    full_runs.push((s.integrator, plan.step_label.clone(), t.frames));
                } else if let Some((_, _, f)) = full_runs.iter().find(|(i, l, _)| *i == s.integrator && *l == plan.step_label) {
                    row.vs_full = trajectory_error(&t.frames, f, &f[0], Masses::Equal);
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
    // The headline window: up to the predictability horizon, within the resolved window.
    let window_s = twins.until_s.map_or(resolved_until_s, |t| t.min(resolved_until_s));
    let window = (window_s / FRAME).round() as usize;
    for (row, w) in rows[first..].iter_mut().zip(&run_by_window) {
        row.resolved_until_s = resolved_until_s;
        row.error_resolved = w.get(resolved - 1).copied().unwrap_or(f64::NAN);
        row.window_s = window_s;
        row.error_window = w.get(window).copied().unwrap_or(f64::NAN);
    }
    for (i, e) in &estimates {
        rows[first + i].estimate_window = e.get(window).copied().unwrap_or(f64::NAN);
    }
    let self_error_resolved = self_by_window[resolved - 1];
    let smallest = rows[first..].iter().filter(|r| r.stable).map(|r| r.error).fold(f64::INFINITY, f64::min);
    let smallest_resolved = smallest_by_window[resolved - 1];
    let _ = writeln!(
        notes,
        "| {} | {n} | {reference_dt} | {self_error:.2e} | {halved_error:.2e} | {smallest:.2e} | {:.0} | {resolved_until_s:.2} | {self_error_resolved:.2e} | {smallest_resolved:.2e} | {:.0} |",
        case.label,
        smallest / self_error,
        smallest_resolved / self_error_resolved
    );
    twins
}
