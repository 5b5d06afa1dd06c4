//! The stability matrix: every canonical scene across stiff and extreme
//! cases, with both Newmark integrators and both reductions, and the
//! trigonometric integrator in modal space, through the fmi3 C functions as
//! a host calls them.
//!
//! Every cell must end in one of three ways:
//! - **stable**: every step returned fmi3OK, every output stayed finite and
//!   the total energy (kinetic + elastic + gravity potential, undamped)
//!   stayed within ENERGY_BOUND of the largest kinetic energy of the run
//!   (measured from the last change of gravity);
//! - **refused**: a Set call or `fmi3ExitInitializationMode` returned
//!   fmi3Error with a logged message naming the parameter;
//! - **discarded**: a step returned fmi3Discard with a logged reason, and the
//!   outputs are bit for bit those of the last good step.
//!
//! The table goes to target/stability.md and must agree with the one in docs/stability.md
//! (outcome of each cell; the numbers after "·" may differ between machines).
//! `cargo xtask stability` runs this test with MMS_STABILITY_WRITE=1, which
//! writes the table into docs/stability.md instead of comparing.

mod extremes;

use crate::common;

use std::fmt::Write as _;
use std::sync::Mutex;

use common::*;
use extremes::{extremes, Extreme, DRIFT};
use fmi_sys::fmi3::*;
use modal_mass_spring::fmi::exports::*;
use modal_mass_spring::fmi::variables::vr;
use modal_mass_spring::measures::{trajectory_error, Masses};

/// Largest |E(t) - E(t0)| of a stable cell, relative to the largest kinetic
/// energy since t0 (t0: start, or the last change of gravity): the energy
/// never strays by more than the motion it has. Bounded, not small: the
/// central difference near its stability limit (omega dt up to 2 x 0.9)
/// shows an energy error of order (omega dt)^2 / 4 of the energy of the
/// highest excited mode, which stays bounded but is not small.
const ENERGY_BOUND: f64 = 1.0;
/// The same bound for the long undamped runs at internal steps of 1e-3 s,
/// where omega_max dt <= 0.2 in every scene: (omega dt)^2 / 4 = 1e-2.
const DRIFT_BOUND: f64 = 1e-2;
/// Floor of that kinetic energy, relative to the work gravity can do across
/// the sheet (total mass x |g| x height): where (almost) nothing moves, the
/// drift is round-off measured against round-off.
const ENERGY_FLOOR: f64 = 1e-6;

#[derive(Clone, Copy)]
struct SceneDef {
    name: &'static str,
    nx: u64,
    ny: u64,
    dim: u64,
    fixed: i64,
    aux: f64,
    /// Modes of the modal cells. 2D: the paper's 2. 3D: the lowest modes of
    /// a flat sheet are its out-of-plane cluster (one mode per free node, at
    /// sqrt(k_aux / m)), which in-plane loads do not excite; paper-3d-sheet
    /// keeps the 42 of them and the 16 lowest in-plane modes. cloth-3d keeps
    /// 16 modes of its 870-mode cluster: passing it would take more than 870
    /// modes, a dense eigen decomposition of 2610 DOFs per cell and implicit
    /// steps of r^2 per spring, so its modal cells move only under loads out
    /// of the plane (which the table shows).
    modes: u64,
}

const SCENES: [SceneDef; 4] = [
    SceneDef { name: "paper-2d-top-row", nx: 10, ny: 10, dim: 2, fixed: 1, aux: 0.0, modes: 2 },
    SceneDef { name: "paper-2d-top-corners", nx: 10, ny: 10, dim: 2, fixed: 2, aux: 0.0, modes: 2 },
    SceneDef { name: "paper-3d-sheet", nx: 7, ny: 7, dim: 3, fixed: 1, aux: 0.05, modes: 58 },
    SceneDef { name: "cloth-3d", nx: 30, ny: 30, dim: 3, fixed: 1, aux: 0.05, modes: 16 },
];

#[derive(Clone, Debug)]
enum Value {
    U(u64),
    I(i64),
    F(Vec<f64>),
    B(bool),
}

/// The variable names a refusal may name.
const PARAMETERS: &[&str] = &[
    "nx",
    "ny",
    "dimension",
    "nModes",
    "spacing",
    "nodeMass",
    "springStiffness",
    "shearSprings",
    "bendingSprings",
    "auxStiffness",
    "maxInternalStep",
    "fixedNodes",
    "reduction",
    "integrator",
    "gravity",
    "modeSelection",
    "staticCorrection",
    "linearization",
    "forceEvaluation",
    "cubatureTolerance",
    "trainingScale",
    "trainingTilt",
    "trainingTime",
    "trainingRangeLimit",
];

#[derive(Clone, Debug, PartialEq)]
enum Outcome {
    /// `warned`: the time of the step that returned fmi3Warning (forceResidual passed its limit).
    Stable {
        drift: f64,
        stretch: f64,
        warned: Option<f64>,
    },
    Refused {
        parameter: String,
        message: String,
    },
    Discarded {
        time: f64,
        message: String,
    },
    NotApplicable,
}

struct Cell {
    outcome: Outcome,
    /// Positions after every communication step, when compared.
    samples: Vec<Vec<f64>>,
    initial: Vec<f64>,
}

fn set(f: &Fmu, r: u32, v: &Value) -> fmi3Status {
    match v {
        Value::U(x) => f.set_u64(r, *x),
        Value::I(x) => f.set_i64(r, *x),
        Value::F(x) => f.set_f64(r, x),
        Value::B(x) => unsafe { fmi3SetBoolean(f.inst, &r, 1, x, 1) },
    }
}

fn refused(f: &Fmu, what: &str) -> Outcome {
    let message = f.log.0.lock().unwrap().iter().rev().find(|(s, _, _)| *s == ERROR).map(|(_, _, m)| m.clone()).unwrap_or_default();
    assert!(!message.is_empty(), "{what} refused without a logged error");
    // The first parameter named in the message (whole words only).
    let words: Vec<&str> = message.split(|c: char| !c.is_ascii_alphanumeric()).collect();
    let parameter = words.iter().find(|w| PARAMETERS.contains(w)).map(|w| w.to_string());
    let parameter = parameter.unwrap_or_else(|| panic!("{what}: the refusal names no parameter: {message}"));
    Outcome::Refused { parameter, message }
}

/// Largest relative elongation of a grid spring (horizontal and vertical neighbours).
fn stretch(p: &[f64], s: &SceneDef, nx: usize, spacing: f64) -> f64 {
    let d = s.dim as usize;
    let ny = p.len() / (nx * d);
    let node = |r: usize, c: usize| &p[(r * nx + c) * d..(r * nx + c + 1) * d];
    let dist = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt();
    let mut m = 0.0f64;
    for r in 0..ny {
        for c in 0..nx {
            if c + 1 < nx {
                m = m.max(dist(node(r, c), node(r, c + 1)) / spacing - 1.0);
            }
            if r + 1 < ny {
                m = m.max(dist(node(r, c), node(r + 1, c)) / spacing - 1.0);
            }
        }
    }
    m
}

fn run_cell(e: &Extreme, s: &SceneDef, modal: bool, integrator: i64) -> Cell {
    let na = Cell { outcome: Outcome::NotApplicable, samples: Vec::new(), initial: Vec::new() };
    if !(e.applies)(s) {
        return na;
    }
    use Value::*;
    let f = Fmu::named(&format!("{}-{}", s.name, e.label));
    let mut params = vec![
        (vr::NX, U(s.nx)),
        (vr::NY, U(s.ny)),
        (vr::DIMENSION, U(s.dim)),
        (vr::N_MODES, U(s.modes)),
        (vr::FIXED_NODES, I(s.fixed)),
        (vr::AUX_STIFFNESS, F(vec![s.aux])),
        (vr::REDUCTION, I(if modal { 1 } else { 2 })),
        (vr::INTEGRATOR, I(integrator)),
    ];
    params.extend((e.set)(s));
    for (r, v) in &params {
        if set(&f, *r, v) != OK {
            return Cell { outcome: refused(&f, "Set"), ..na };
        }
    }
    let (nx, _, _, r) = f.sizes();
    // Modal weights keep their start value 1 (resized with nModes).
    assert_eq!(unsafe { fmi3EnterInitializationMode(f.inst, false, 0.0, 0.0, false, 0.0) }, OK, "{:?}", f.messages());
    if unsafe { fmi3ExitInitializationMode(f.inst) } != OK {
        return Cell { outcome: refused(&f, "fmi3ExitInitializationMode"), ..na };
    }
    let spacing = f.f64s(vr::SPACING, 1)[0];
    let (_, ny, _, _) = f.sizes();
    let g_start = e.gravity.map_or_else(|| f.f64s(vr::GRAVITY, 3), |g| g(0.0).to_vec());
    let work = f.f64s(vr::NODE_MASS, 1)[0] * (nx * ny) as f64 * g_start.iter().map(|c| c * c).sum::<f64>().sqrt() * spacing * ny as f64;
    let energy = |f: &Fmu| f.f64s(vr::KINETIC_ENERGY, 1)[0] + f.f64s(vr::POTENTIAL_ENERGY, 1)[0];
    let initial = f.positions();
    let t_end = (e.t_end)(s, integrator == 2);
    let mut samples = Vec::new();
    let (mut e0, mut k_max, mut drift, mut max_stretch) = (energy(&f), 0.0f64, 0.0f64, 0.0f64);
    let mut warned = None;
    let mut gravity = e.gravity.map(|g| g(0.0));
    if let Some(g) = gravity {
        assert_eq!(f.set_f64(vr::GRAVITY, &g), OK);
        e0 = energy(&f);
    }
    let mut i = 0;
    while f.time() < t_end * (1.0 - 1e-12) {
        let t = f.time();
        if let Some(g) = e.gravity.map(|g| g(t)) {
            if Some(g) != gravity {
                assert_eq!(f.set_f64(vr::GRAVITY, &g), OK, "{:?}", f.messages());
                // The potential of gravity changes with it: energy is measured anew.
                gravity = Some(g);
                e0 = energy(&f);
                k_max = 0.0;
            }
        }
        let h = e.steps[i % e.steps.len()].min(t_end - t);
        i += 1;
        let before = f.outputs();
        let status = f.step(t, h);
        if status == DISCARD {
            assert_eq!(f.outputs(), before, "{} {}: a discarded step changed the outputs", s.name, e.label);
            let message = f.log.0.lock().unwrap().last().map(|(_, _, m)| m.clone()).unwrap_or_default();
            assert!(!message.is_empty(), "a discarded step logged no reason");
            return Cell { outcome: Outcome::Discarded { time: t, message }, samples, initial };
        }
        if status == WARNING {
            let message = f.log.0.lock().unwrap().last().map(|(_, _, m)| m.clone()).unwrap_or_default();
            assert!(message.contains("forceResidual"), "{} {}: a warning without its reason: {message}", s.name, e.label);
            assert!(warned.is_none(), "{} {}: warned twice", s.name, e.label);
            warned = Some(t);
        } else {
            assert_eq!(status, OK, "{} {} at t = {t}: {:?}", s.name, e.label, f.messages());
        }
        let p = f.positions();
        let v = f.f64s(vr::VELOCITIES, p.len());
        let q = f.f64s(vr::MODAL_COORDINATES, r);
        let k = f.f64s(vr::KINETIC_ENERGY, 1)[0];
        let en = energy(&f);
        assert!(p.iter().chain(&v).chain(&q).all(|x| x.is_finite()) && en.is_finite(), "{} {} at t = {t}: a non-finite output after fmi3OK", s.name, e.label);
        k_max = k_max.max(k);
        let scale = k_max.max(ENERGY_FLOOR * work);
        if scale > 0.0 {
            drift = drift.max((en - e0).abs() / scale);
        }
        if e.compare {
            max_stretch = max_stretch.max(stretch(&p, s, nx, spacing));
            samples.push(p);
        }
    }
    Cell { outcome: Outcome::Stable { drift, stretch: max_stretch, warned }, samples, initial }
}

fn short(o: &Outcome) -> String {
    match o {
        Outcome::Stable { .. } => "stable".into(),
        Outcome::Refused { parameter, .. } => format!("refused ({parameter})"),
        Outcome::Discarded { .. } => "discarded".into(),
        Outcome::NotApplicable => "—".into(),
    }
}

/// (modal, value of `integrator`, label, the full-space column a modal one is compared with).
const COLUMNS: [(bool, i64, &str, usize); 5] = [
    (true, 1, "modal, explicit", 2),
    (true, 2, "modal, implicit", 3),
    (false, 1, "full, explicit", 2),
    (false, 2, "full, implicit", 3),
    (true, 3, "modal, trigonometric", 2),
];

#[test]
fn stability_matrix() {
    let extremes = extremes();
    let mut jobs: Vec<(usize, usize, usize)> =
        (0..extremes.len()).flat_map(|e| (0..SCENES.len()).flat_map(move |s| (0..COLUMNS.len()).map(move |c| (e, s, c)))).collect();
    // The largest sheet's cells first (its set-ups take most of the time):
    // the threads end together instead of one running the last ones alone.
    jobs.sort_by_key(|&(_, s, _)| std::cmp::Reverse(SCENES[s].nx * SCENES[s].ny * SCENES[s].dim));
    let next = Mutex::new(0usize);
    let results: Mutex<Vec<Option<Cell>>> = Mutex::new((0..jobs.len()).map(|_| None).collect());
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| loop {
                let j = {
                    let mut n = next.lock().unwrap();
                    *n += 1;
                    *n - 1
                };
                let Some(&(e, s, c)) = jobs.get(j) else { break };
                let (modal, integrator, column, _) = COLUMNS[c];
                let clock = std::time::Instant::now();
                let cell = run_cell(&extremes[e], &SCENES[s], modal, integrator);
                let seconds = clock.elapsed().as_secs_f64();
                if seconds > 1.0 {
                    eprintln!("{seconds:6.1} s  {} / {} / {column}", extremes[e].label, SCENES[s].name);
                }
                results.lock().unwrap()[(e * SCENES.len() + s) * COLUMNS.len() + c] = Some(cell);
            });
        }
    });
    let cells: Vec<Cell> = results.into_inner().unwrap().into_iter().map(|c| c.unwrap()).collect();
    let cell = |e: usize, s: usize, c: usize| &cells[(e * SCENES.len() + s) * COLUMNS.len() + c];

    let mut table = String::new();
    let mut refusals = String::new();
    writeln!(table, "| extreme | scene | {} |", COLUMNS.map(|c| c.2).join(" | ")).unwrap();
    writeln!(table, "|---|---|{}", "---|".repeat(COLUMNS.len())).unwrap();
    for (ei, e) in extremes.iter().enumerate() {
        for (si, s) in SCENES.iter().enumerate() {
            let mut row = format!("| {} | {} |", e.label, s.name);
            for (c, &(modal, _, label, partner)) in COLUMNS.iter().enumerate() {
                let x = cell(ei, si, c);
                let mut text = short(&x.outcome);
                match &x.outcome {
                    Outcome::Stable { drift, stretch, warned } => {
                        text += &format!(" · drift {drift:.1e}");
                        if let Some(t) = warned {
                            text += &format!(" · forceResidual warning at {t:.2} s");
                        }
                        if e.compare {
                            text += &format!(" · stretch {:.0} %", stretch * 100.0);
                            let full = cell(ei, si, partner);
                            if modal && matches!(full.outcome, Outcome::Stable { .. }) {
                                text += &format!(" · E vs full {:.2}", trajectory_error(&x.samples, &full.samples, &full.initial, Masses::Equal));
                            }
                        }
                    }
                    Outcome::Discarded { time, .. } => text += &format!(" · at {time} s"),
                    _ => {}
                }
                if let Outcome::Refused { message, .. } | Outcome::Discarded { message, .. } = &x.outcome {
                    let line = format!("- {} / {} / {label}: {message}\n", e.label, s.name);
                    if !refusals.contains(message.as_str()) {
                        refusals += &line;
                    }
                }
                row += &format!(" {text} |");
            }
            writeln!(table, "{row}").unwrap();
        }
    }
    let out = format!("{table}\nMessages (the first cell of each):\n\n{refusals}");
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let target = std::env::var_os("CARGO_TARGET_DIR").map(std::path::PathBuf::from).unwrap_or(root.join("target"));
    std::fs::create_dir_all(&target).unwrap();
    std::fs::write(target.join("stability.md"), &out).unwrap();
    println!("{out}");

    // Every stable cell kept its energy bounded.
    for (j, c) in cells.iter().enumerate() {
        if let Outcome::Stable { drift, .. } = c.outcome {
            let (e, s, col) = jobs[j];
            let bound = if extremes[e].label == DRIFT { DRIFT_BOUND } else { ENERGY_BOUND };
            assert!(drift <= bound, "{} / {} / {}: energy drift {drift:e} of the largest kinetic energy", extremes[e].label, SCENES[s].name, COLUMNS[col].2);
        }
    }
    check_docs(root, &out);
}

const BEGIN: &str = "<!-- stability table: generated by tests/stability.rs (cargo xtask stability) -->";
const END: &str = "<!-- end of stability table -->";

/// The outcome words of every row (the numbers after "·" dropped).
fn outcomes(table: &str) -> Vec<String> {
    table
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| extreme"))
        .map(|l| l.split('|').map(|c| c.split('·').next().unwrap().trim()).collect::<Vec<_>>().join("|"))
        .collect()
}

fn check_docs(root: &std::path::Path, table: &str) {
    let path = root.join("docs/stability.md");
    let readme = std::fs::read_to_string(&path).unwrap();
    let section = readme.split_once(BEGIN).and_then(|(_, rest)| rest.split_once(END)).map(|(s, _)| s);
    if std::env::var_os("MMS_STABILITY_WRITE").is_some() {
        let (head, rest) = readme.split_once(BEGIN).expect("docs/stability.md has no stability table markers");
        let (_, tail) = rest.split_once(END).expect("docs/stability.md has no end marker of the stability table");
        std::fs::write(&path, format!("{head}{BEGIN}\n{table}{END}{tail}")).unwrap();
        return;
    }
    let section = section.expect("docs/stability.md has no stability table (run cargo xtask stability)");
    assert_eq!(
        outcomes(section),
        outcomes(table),
        "the stability table of docs/stability.md disagrees with this run (target/stability.md); run `cargo xtask stability`"
    );
}
