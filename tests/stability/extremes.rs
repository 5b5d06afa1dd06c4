//! The rows of the stability matrix: each extreme case, the scenes it
//! applies to, what it sets and how long it runs.

use super::*;

/// One extreme: parameters set on top of the scene, then a run.
pub(super) struct Extreme {
    /// Row label in the table.
    pub(super) label: &'static str,
    /// Which scenes it applies to.
    pub(super) applies: fn(&SceneDef) -> bool,
    /// Parameters (value reference, value) set in the Instantiated state.
    pub(super) set: fn(&SceneDef) -> Vec<(u32, Value)>,
    /// Simulated time [s] for (scene, implicit Newmark).
    pub(super) t_end: fn(&SceneDef, bool) -> f64,
    /// Communication steps, used in turn [s].
    pub(super) steps: &'static [f64],
    /// Gravity from time t on, when it changes during the run.
    pub(super) gravity: Option<fn(f64) -> [f64; 3]>,
    /// Compare modal with full space (docs/method.md, section 6) and report the stretch.
    pub(super) compare: bool,
}

fn all(_: &SceneDef) -> bool {
    true
}
fn none(_: &SceneDef) -> Vec<(u32, Value)> {
    Vec::new()
}
fn one_second(_: &SceneDef, _: bool) -> f64 {
    1.0
}
fn fiftieth(_: &SceneDef, _: bool) -> f64 {
    0.02
}

/// The long undamped runs, bounded by DRIFT_BOUND.
pub(super) const DRIFT: &str = "energy drift, undamped, internal steps of 1e-3 s: 1e5 of them (paper-2d-top-row), 1e4 (other scenes), 1e3 (cloth-3d implicit)";

pub(super) fn extremes() -> Vec<Extreme> {
    use Value::*;
    vec![
        Extreme {
            label: "defaults (k 50 N/m, m 0.01 kg, g 9.81), 1 s at 0.01 s",
            applies: all,
            set: none,
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "springStiffness 1e-3 N/m (1e5 below default), 1 s",
            applies: all,
            set: |s| vec![(vr::SPRING_STIFFNESS, F(vec![1e-3])), (vr::AUX_STIFFNESS, F(vec![s.aux.min(1e-6)]))],
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "springStiffness 1e9 N/m, 0.02 s",
            applies: all,
            set: |_| vec![(vr::SPRING_STIFFNESS, F(vec![1e9]))],
            t_end: fiftieth,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "nodeMass 1e-6 kg, 0.02 s",
            applies: all,
            set: |_| vec![(vr::NODE_MASS, F(vec![1e-6]))],
            t_end: fiftieth,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "nodeMass 1e3 kg, 1 s",
            applies: all,
            set: |_| vec![(vr::NODE_MASS, F(vec![1e3]))],
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "k/m = 1e15 /s² (k 1e9, m 1e-6), 0.01 s",
            applies: all,
            set: |_| vec![(vr::SPRING_STIFFNESS, F(vec![1e9])), (vr::NODE_MASS, F(vec![1e-6]))],
            t_end: |_, _| 0.01,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "k/m = 1e-6 /s² (k 1e-3, m 1e3), 1 s",
            applies: all,
            set: |s| vec![(vr::SPRING_STIFFNESS, F(vec![1e-3])), (vr::NODE_MASS, F(vec![1e3])), (vr::AUX_STIFFNESS, F(vec![s.aux.min(1e-6)]))],
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme { label: "communication step 1e-6 s, 200 steps", applies: all, set: none, t_end: |_, _| 2e-4, steps: &[1e-6], gravity: None, compare: false },
        Extreme { label: "communication step 1 s, 2 steps", applies: all, set: none, t_end: |_, _| 2.0, steps: &[1.0], gravity: None, compare: false },
        Extreme {
            label: "steps changing at every call (1e-4 … 0.2 s), 1 s",
            applies: all,
            set: none,
            t_end: one_second,
            steps: &[1e-4, 0.03, 1e-3, 0.017, 0.2, 3e-6, 0.05],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "gravity 1e4 m/s² along −y (springs stretched far beyond 100 %), 0.5 s",
            applies: all,
            set: |_| vec![(vr::GRAVITY, F(vec![0.0, -1e4, 0.0]))],
            t_end: |_, _| 0.5,
            steps: &[0.01],
            gravity: None,
            compare: true,
        },
        Extreme {
            label: "gravity (7e3, 5e3, −5e3) m/s² (up, sideways, out of plane), 0.5 s",
            applies: all,
            set: |_| vec![(vr::GRAVITY, F(vec![7e3, 5e3, -5e3]))],
            t_end: |_, _| 0.5,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "gravity switched on and off every 0.25 s, 1 s",
            applies: all,
            set: none,
            t_end: one_second,
            steps: &[0.01],
            gravity: Some(|t| if ((t / 0.25 + 1e-9).floor() as i64) % 2 == 0 { [0.0, -9.81, 0.0] } else { [0.0; 3] }),
            compare: false,
        },
        Extreme {
            label: "large rotation: gravity (9.81, 0, 9.81) swings the sheet sideways (and out of plane in 3D), 2 s",
            applies: all,
            set: |_| vec![(vr::GRAVITY, F(vec![9.81, 0.0, 9.81]))],
            t_end: |_, _| 2.0,
            steps: &[0.01],
            gravity: None,
            compare: true,
        },
        Extreme {
            label: DRIFT,
            applies: all,
            set: |_| vec![(vr::MAX_INTERNAL_STEP, F(vec![1e-3]))],
            t_end: |s, implicit| match (s.name, implicit) {
                ("paper-2d-top-row", _) => 100.0,
                ("cloth-3d", true) => 1.0,
                _ => 10.0,
            },
            steps: &[1e-3],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "zero eigenvalues: 3D sheet without auxiliary springs (auxStiffness 0)",
            applies: |s| s.dim == 3,
            set: |_| vec![(vr::AUX_STIFFNESS, F(vec![0.0]))],
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "zero eigenvalues: no shear springs (shearSprings false)",
            applies: all,
            set: |_| vec![(vr::SHEAR_SPRINGS, B(false))],
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "no fixed node: fixedNodes 0 (there is no such item)",
            applies: all,
            set: |_| vec![(vr::FIXED_NODES, I(0))],
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "spacing 0 (coincident nodes)",
            applies: all,
            set: |_| vec![(vr::SPACING, F(vec![0.0]))],
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "spacing −0.1",
            applies: all,
            set: |_| vec![(vr::SPACING, F(vec![-0.1]))],
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "nx 1 (a hanging chain), 1 s",
            applies: all,
            set: |_| vec![(vr::NX, U(1))],
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "ny 1 (the fixed row alone)",
            applies: all,
            set: |_| vec![(vr::NY, U(1))],
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme { label: "nModes 0", applies: all, set: |_| vec![(vr::N_MODES, U(0))], t_end: one_second, steps: &[0.01], gravity: None, compare: false },
        Extreme {
            label: "nModes one more than the free DOFs",
            applies: all,
            set: |s| {
                let fixed = if s.fixed == 1 { s.nx } else { 2 };
                vec![(vr::N_MODES, U((s.nx * s.ny - fixed) * s.dim + 1))]
            },
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "modes of the loads with a static correction (modeSelection load, staticCorrection true), 1 s",
            applies: all,
            set: |_| vec![(vr::MODE_SELECTION, I(2)), (vr::STATIC_CORRECTION, B(true))],
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: true,
        },
        Extreme {
            label: "linearized at the equilibrium under gravity (linearization equilibrium, modeSelection load, staticCorrection true), 1 s",
            applies: all,
            set: |_| vec![(vr::LINEARIZATION, I(2)), (vr::MODE_SELECTION, I(2)), (vr::STATIC_CORRECTION, B(true))],
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: true,
        },
        Extreme {
            label: "two holders (nHolders 2, anchorMotion true), holder 2 set a fifth of the width out before initialization, 1 s",
            applies: all,
            set: |s| vec![(vr::N_HOLDERS, U(2)), (vr::ANCHOR_MOTION, B(true)), (vr::ANCHOR2_X, F(vec![0.1 * (s.nx - 1) as f64 / 5.0]))],
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: true,
        },
        Extreme {
            label: "two holders, holder 2 set half the width out and up (springs next to it stretched far beyond 100 %), 0.5 s",
            applies: all,
            set: |s| {
                let w = 0.1 * (s.nx - 1) as f64;
                vec![(vr::N_HOLDERS, U(2)), (vr::ANCHOR_MOTION, B(true)), (vr::ANCHOR2_X, F(vec![0.5 * w])), (vr::ANCHOR2_Y, F(vec![0.5 * w]))]
            },
            t_end: |_, _| 0.5,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "linearized at the equilibrium under gravity 1e4 m/s² along -y, 0.2 s",
            applies: all,
            set: |_| vec![(vr::LINEARIZATION, I(2)), (vr::GRAVITY, F(vec![0.0, -1e4, 0.0]))],
            t_end: |_, _| 0.2,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "cubature forces on modes of the loads with a static correction (forceEvaluation cubature, cubatureTolerance 0.01), 1 s",
            applies: all,
            set: |_| vec![(vr::FORCE_EVALUATION, I(2)), (vr::MODE_SELECTION, I(2)), (vr::STATIC_CORRECTION, B(true))],
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: true,
        },
        Extreme {
            label: "cubature forces linearized at the equilibrium (forceEvaluation cubature, linearization equilibrium, modeSelection load, staticCorrection true), 1 s",
            applies: all,
            set: |_| vec![(vr::FORCE_EVALUATION, I(2)), (vr::LINEARIZATION, I(2)), (vr::MODE_SELECTION, I(2)), (vr::STATIC_CORRECTION, B(true))],
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: true,
        },
        Extreme {
            label: "cubature forces under gravity 1e4 m/s² along -y (forceEvaluation cubature), 0.2 s",
            applies: all,
            set: |_| vec![(vr::FORCE_EVALUATION, I(2)), (vr::GRAVITY, F(vec![0.0, -1e4, 0.0]))],
            t_end: |_, _| 0.2,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "cubature at the tightest tolerance (forceEvaluation cubature, cubatureTolerance 1e-6)",
            applies: all,
            set: |_| vec![(vr::FORCE_EVALUATION, I(2)), (vr::CUBATURE_TOLERANCE, F(vec![1e-6]))],
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "trained basis (modeSelection trained), 1 s",
            applies: all,
            set: |_| vec![(vr::MODE_SELECTION, I(3))],
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: true,
        },
        Extreme {
            label: "cubature forces on a trained basis (modeSelection trained, forceEvaluation cubature), 1 s",
            applies: all,
            set: |_| vec![(vr::MODE_SELECTION, I(3)), (vr::FORCE_EVALUATION, I(2))],
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: true,
        },
        Extreme {
            label: "trained basis under gravity 1e4 m/s² along -y (modeSelection trained), 0.2 s",
            applies: all,
            set: |_| vec![(vr::MODE_SELECTION, I(3)), (vr::GRAVITY, F(vec![0.0, -1e4, 0.0]))],
            t_end: |_, _| 0.2,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "cubature forces on a trained basis under gravity 1e4 m/s² along -y (modeSelection trained, forceEvaluation cubature), 0.2 s",
            applies: all,
            set: |_| vec![(vr::MODE_SELECTION, I(3)), (vr::FORCE_EVALUATION, I(2)), (vr::GRAVITY, F(vec![0.0, -1e4, 0.0]))],
            t_end: |_, _| 0.2,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "modes of the loads without a load (modeSelection load, gravity 0)",
            applies: all,
            set: |_| vec![(vr::MODE_SELECTION, I(2)), (vr::GRAVITY, F(vec![0.0, 0.0, 0.0]))],
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
        Extreme {
            label: "trained basis without a load (modeSelection trained, gravity 0)",
            applies: all,
            set: |_| vec![(vr::MODE_SELECTION, I(3)), (vr::GRAVITY, F(vec![0.0, 0.0, 0.0]))],
            t_end: one_second,
            steps: &[0.01],
            gravity: None,
            compare: false,
        },
    ]
}
