//! What the study runs: the steps, the variants of the basis and force
//! options, and every way of running one scene.

use modal_mass_spring::physics::*;

/// Output times are multiples of this; every co-simulation step divides it.
pub const FRAME: f64 = 0.05;
/// How much smaller than every error it measures the reference's own error
/// (against its run at half the step) must be. Where the trajectory itself is
/// sensitive, that own error stops shrinking with dt from some time on;
/// `error_resolved` is E over the window before that.
pub const REFERENCE_MARGIN: f64 = 10.0;
pub const STEPS: [(f64, &str); 4] = [(1.0 / 1000.0, "1/1000"), (1.0 / 240.0, "1/240"), (1.0 / 60.0, "1/60"), (1.0 / 20.0, "1/20")];
/// Index in [`STEPS`] of 1/60 s, the longest step of the large scenes' Newmark runs.
pub const STEP_60: usize = 2;
/// Relative error of the projected force the cubature variants ask for.
pub const CUBATURE_TOLERANCE: f64 = 0.01;

/// One way of building the modal basis and evaluating its force.
pub struct Variant {
    /// Name in the CSV and the plots.
    pub key: &'static str,
    /// Name in the report.
    pub label: &'static str,
    /// The basis and force choices (mode selection, static correction,
    /// linearization, force evaluation); each run sets its space, scheme,
    /// modes and step.
    pub settings: Settings,
}

/// Index of the paper's method in [`variants`].
pub const PAPER: usize = 0;
pub const LOAD: usize = 1;
pub const LOAD_STATIC: usize = 2;
pub const TRAINED: usize = 7;
pub const TRAINED_CUBATURE: usize = 8;

/// The paper's method first, then every other option the study compares with it.
pub fn variants() -> Vec<Variant> {
    use ForceEvaluation::{Cubature, Exact};
    use Linearization::{Equilibrium, Rest};
    use ModeSelection::{Load, Lowest, Trained};
    let v = |key, label, mode_selection, static_correction, linearization, force_evaluation| Variant {
        key,
        label,
        settings: Settings {
            mode_selection,
            static_correction,
            linearization,
            force_evaluation,
            cubature_tolerance: CUBATURE_TOLERANCE,
            ..Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, 0)
        },
    };
    vec![
        v("paper", "paper (lowest modes at rest)", Lowest, false, Rest, Exact),
        v("load", "load", Load, false, Rest, Exact),
        v("load+static", "load + static correction", Load, true, Rest, Exact),
        v("load+static@equilibrium", "load + static correction @ equilibrium", Load, true, Equilibrium, Exact),
        v("load+cubature", "load + cubature", Load, false, Rest, Cubature),
        v("load+static+cubature", "load + static correction + cubature", Load, true, Rest, Cubature),
        v("load+static@equilibrium+cubature", "load + static correction @ equilibrium + cubature", Load, true, Equilibrium, Cubature),
        v("trained", "trained (principal components of the training program)", Trained, false, Rest, Exact),
        v("trained+cubature", "trained + cubature", Trained, false, Rest, Cubature),
    ]
}

pub struct SceneCase {
    pub label: String,
    pub params: Grid,
    /// A load the scene turns to mid-run, outside what its training program ran.
    pub change: Option<Change>,
}

/// Gravity set to `gravity` at time `at_s` (from the first co-simulation
/// step that starts at or after it): a scene that leaves its program.
#[derive(Clone, Copy)]
pub struct Change {
    pub at_s: f64,
    pub gravity: [f64; 3],
}

/// When the scenes that leave their program turn their gravity [s].
pub const TURN_AT_S: f64 = 0.25;
/// The gravity they turn to: 9.81 m/s^2 in the sheet's plane, sideways.
pub const TURNED_GRAVITY: [f64; 3] = [9.81, 0.0, 0.0];

/// The error tolerances of the adaptive runs (the quick study's: the default only).
pub const TOLERANCES: [f64; 3] = [0.003, 0.01, 0.03];
/// The mode count an adaptive run reports its first vectors of (its basis is its own).
pub const ADAPTIVE_REPORTED: usize = 2;

/// The adaptive runs of a scene, as (step index, scheme, tolerance):
/// explicit Newmark at steps 1/240 and 1/60 (quick: 1/240, the default tolerance).
pub fn adaptive_grid(quick: bool) -> Vec<(usize, Integrator, f64)> {
    let (steps, tolerances): (&[usize], &[f64]) = if quick { (&[1], &[0.01]) } else { (&[1, STEP_60], &TOLERANCES) };
    tolerances.iter().flat_map(|&tol| steps.iter().map(move |&si| (si, Integrator::NewmarkExplicit, tol))).collect()
}

pub fn adaptive_solver(integrator: Integrator, error_tolerance: f64, max_internal_step: f64) -> Settings {
    Settings { max_internal_step, error_tolerance, ..Settings::new(Reduction::Adaptive, integrator, ADAPTIVE_REPORTED) }
}

pub struct Plan {
    pub solver: Settings,
    pub variant: usize,
    pub step: f64,
    pub step_label: String,
    pub note: String,
}

/// Implicit modal runs whose reduced tangent is costlier than this are not run.
pub const IMPLICIT_TANGENT_LIMIT: f64 = 5e7;

/// Why an implicit modal run is not run (its reduced tangent, Phi^T K(x)
/// Phi, costs about springs x r^2 x 30 flops per Newton iteration; beyond
/// IMPLICIT_TANGENT_LIMIT a single step takes seconds), or nothing.
pub fn tangent_note(integrator: Integrator, springs: usize, r: usize) -> String {
    if integrator == Integrator::NewmarkImplicit && (springs * r * r) as f64 > IMPLICIT_TANGENT_LIMIT {
        format!("not run: the reduced tangent needs springs x r^2 = {:.1e} > {IMPLICIT_TANGENT_LIMIT:.0e} per Newton iteration", (springs * r * r) as f64)
    } else {
        String::new()
    }
}

pub fn full_solver(integrator: Integrator, max_internal_step: f64) -> Settings {
    Settings { max_internal_step, ..Settings::new(Reduction::Full, integrator, 0) }
}

pub fn modal_solver(integrator: Integrator, n_modes: usize, max_internal_step: f64, v: &Variant) -> Settings {
    Settings { integrator, n_modes, max_internal_step, ..v.settings.clone() }
}

/// Scenes with more free DOFs than this get the variants' smallest grid.
pub const LARGE_DOFS: usize = 10_000;

/// The variants' grid in the full study, as (step index, scheme, modes kept):
/// explicit and trigonometric at every step with r = 1, 2, 4, ... 32 and
/// implicit at steps 1/60 and 1/20 up to r = 16. On large scenes (cloth
/// 100 x 100) a run with exact forces costs about as much as a full-space
/// one, and the equilibrium takes a minute to solve there: explicit at steps
/// 1/240 and 1/60, trigonometric at 1/240, 1/60 and 1/20, with r = 2, 8, 32
/// (at the equilibrium only r = 32; trained r = 8, 16, 32), implicit
/// only with cubature (its tangent visits the cubature set only), r = 2 and
/// 8 at step 1/60.
pub fn variant_grid(n: usize, v: &Variant) -> Vec<(usize, Integrator, usize)> {
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
        let at_equilibrium = v.settings.linearization == Linearization::Equilibrium;
        let cubature = v.settings.force_evaluation == ForceEvaluation::Cubature;
        let trained = v.settings.mode_selection == ModeSelection::Trained;
        let counts: &[usize] = match (at_equilibrium, cubature) {
            _ if trained => &[8, 16, 32],
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
        if cubature && !at_equilibrium && !trained {
            for r in [2, 8] {
                grid.push((STEP_60, NewmarkImplicit, r));
            }
        }
    }
    grid.retain(|&(_, _, r)| r < n);
    grid
}

/// Whether full space refuses `integrator` at set-up (a scheme that needs
/// the modal space's diagonal mass and stiffness, as the trigonometric one).
fn modal_only(scene: &Scene, integrator: Integrator) -> bool {
    Simulator::new(scene.clone(), &full_solver(integrator, 1.0), &Loads::physical(0)).is_err_and(|e| e.refuses_pairing())
}

/// Every way of running the scene `p` (`quick`: the CI's smaller grid;
/// `variants_only`: without the paper's modal grid; a scene that leaves
/// its program runs full space, the trained variants and adaptive only).
pub fn plan_scene(p: &Grid, variants: &[Variant], quick: bool, variants_only: bool, leaves_program: bool) -> Vec<Plan> {
    let variants_only = variants_only || leaves_program;
    let scene = p.build().unwrap();
    let n = scene.n_dofs();
    let mut mode_counts: Vec<usize> = std::iter::successors(Some(1usize), |r| Some(r * 2)).take_while(|&r| r < n).collect();
    // Beyond a quarter of the DOFs the basis needs the dense eigensolver;
    // of those, only all modes are run (set-up alone takes tens of
    // seconds at a few thousand DOFs).
    mode_counts.retain(|&r| r <= 64 || r * 16 <= n);
    if n <= setup::modes::MAX_DENSE_DOFS {
        mode_counts.push(n);
    }
    let springs = scene.springs.len();
    if quick {
        mode_counts.retain(|&r| r <= 8 || r == n);
    }
    let steps: &[(f64, &str)] = if quick { &STEPS[1..] } else { &STEPS };
    let large = n > LARGE_DOFS;
    let mut list = Vec::new();
    let paper = &variants[PAPER];
    // Every scheme; one that full space refuses (the trigonometric one needs
    // the modal space) runs in modal space only. On large scenes the paper's
    // grid runs the other schemes (Newmark) at steps up to 1/60 and the
    // modal-only ones at 1/60 and 1/20.
    let schemes: Vec<(Integrator, bool)> = Integrator::ALL.iter().map(|&i| (i, modal_only(&scene, i))).collect();
    for (si, &(h, label)) in steps.iter().enumerate() {
        let si = si + STEPS.len() - steps.len();
        for &(integrator, modal_only) in &schemes {
            if !modal_only {
                list.push(Plan { solver: full_solver(integrator, h), variant: PAPER, step: h, step_label: label.into(), note: String::new() });
            }
            if variants_only || (large && if modal_only { si < STEP_60 } else { si > STEP_60 }) {
                continue;
            }
            for &r in &mode_counts {
                let note = tangent_note(integrator, springs, r);
                list.push(Plan { solver: modal_solver(integrator, r, h, paper), variant: PAPER, step: h, step_label: label.into(), note });
            }
        }
    }
    // Full space, explicit, at internal steps below its largest stable one.
    let stable_dt = Simulator::new(scene, &full_solver(Integrator::NewmarkExplicit, 1.0), &Loads::physical(0)).unwrap().max_stable_step();
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
        variant_runs.push((1, Integrator::NewmarkExplicit, 32, TRAINED));
        variant_runs.push((1, Integrator::NewmarkExplicit, 32, TRAINED_CUBATURE));
    } else {
        for (v, variant) in variants.iter().enumerate().skip(1) {
            for (si, integrator, r) in variant_grid(n, variant) {
                variant_runs.push((si, integrator, r, v));
            }
        }
    }
    if leaves_program {
        variant_runs.retain(|&(_, _, _, v)| v == TRAINED || v == TRAINED_CUBATURE);
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
    for (si, integrator, tol) in adaptive_grid(quick) {
        let (h, label) = STEPS[si];
        list.push(Plan { solver: adaptive_solver(integrator, tol, h), variant: PAPER, step: h, step_label: label.into(), note: String::new() });
    }
    list
}

/// The run's method in the CSV.
pub fn method(s: &Settings) -> &'static str {
    match s.reduction {
        Reduction::Full => "full",
        Reduction::Modal => "modal",
        Reduction::Adaptive => "adaptive",
    }
}

/// The run's variant in the CSV ("full" and "adaptive" for those methods).
pub fn variant_key(plan: &Plan, variants: &[Variant]) -> &'static str {
    match plan.solver.reduction {
        Reduction::Modal => variants[plan.variant].key,
        _ => method(&plan.solver),
    }
}
