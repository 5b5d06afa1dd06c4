//! Trained bases against the modal ones, judged where a cloth is
//! predictable (`docs/method.md`, sections 3 and 6): E over [0, 0.5 s] and
//! [0, 1 s] against the full-space run under the same loads, on the
//! canonical loads and on loads inside the training range that the program
//! did not run (set after set-up), with exact and cubature forces, and the
//! trainingRange indicator; then the set-up cost and the run time.
//!
//! `cargo run --release --example trained -- [--nx N] [--modes R]... [--seconds T] [--training-time T] [--variant NAME]...`

use std::time::Instant;

use modal_mass_spring::canonical_scenes::{self, Setup};
use modal_mass_spring::measures::{trajectory_errors_by_window, Masses};
use modal_mass_spring::physics::*;

const H: f64 = 0.01;

struct Run {
    frames: Vec<Vec<f64>>,
    start: Vec<f64>,
    setup_s: f64,
    run_s: f64,
    range: f64,
    springs: usize,
}

/// Gravity 9.81 m/s^2 scaled by `scale`, tilted by `x_deg` about x and `z_deg` about z.
fn gravity(scale: f64, x_deg: f64, z_deg: f64) -> [f64; 3] {
    let (a, b) = (x_deg.to_radians(), z_deg.to_radians());
    // g = -9.81 e_y turned about z by b, then about x by a.
    let g = [9.81 * b.sin(), -9.81 * b.cos(), 0.0];
    let g = [g[0], g[1] * a.cos(), g[1] * a.sin()];
    [scale * g[0], scale * g[1], scale * g[2]]
}

fn run(setup: &Setup, g: [f64; 3], seconds: f64) -> Run {
    let t0 = Instant::now();
    let mut sim = setup.simulator().unwrap_or_else(|e| panic!("{e}"));
    let setup_s = t0.elapsed().as_secs_f64();
    let start = sim.positions().to_vec();
    let loads = Loads { gravity: g, ..sim.loads().clone() };
    sim.set_loads(&loads).unwrap();
    let steps = (seconds / H).round() as usize;
    let mut frames = Vec::with_capacity(steps);
    let mut range: f64 = 0.0;
    let t1 = Instant::now();
    for _ in 0..steps {
        sim.do_step(H).unwrap_or_else(|e| panic!("{e}"));
        frames.push(sim.positions().to_vec());
        range = range.max(sim.training_range());
    }
    Run { frames, start, setup_s, run_s: t1.elapsed().as_secs_f64(), range, springs: sim.cubature_springs() }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let value = |name: &str| args.iter().position(|a| a == name).map(|i| args[i + 1].clone());
    let nx: usize = value("--nx").map_or(30, |v| v.parse().unwrap());
    let seconds: f64 = value("--seconds").map_or(1.0, |v| v.parse().unwrap());
    let training_time: f64 = value("--training-time").map_or(TrainingProgram::default().time, |v| v.parse().unwrap());
    let modes: Vec<usize> = {
        let m: Vec<usize> = args.iter().enumerate().filter(|(_, a)| *a == "--modes").map(|(i, _)| args[i + 1].parse().unwrap()).collect();
        if m.is_empty() {
            vec![16, 32]
        } else {
            m
        }
    };
    let only: Vec<String> = args.iter().enumerate().filter(|(_, a)| *a == "--variant").map(|(i, _)| args[i + 1].clone()).collect();
    let base = canonical_scenes::cloth(nx, nx);
    let cases = [
        ("canonical", gravity(1.0, 0.0, 0.0)),
        ("0.85 g tilted 10 deg in x and z", gravity(0.85, 10.0, 10.0)),
        ("1.5 g tilted 45 deg", gravity(1.5, 45.0, 0.0)),
    ];
    let full = Settings::new(Reduction::Full, Integrator::NewmarkExplicit, 0);
    println!("cloth {nx} x {nx}, steps of {H} s, E over [0, 0.5 s] / [0, 1 s] / the whole run against full space under the same loads");
    let references: Vec<Run> = cases.iter().map(|(_, g)| run(&base.with_settings(full.clone()), *g, seconds)).collect();
    println!("full space: set-up {:.3} s, run {:.3} s per simulated s", references[0].setup_s, references[0].run_s / seconds);
    let half = (0.5 / H).round() as usize - 1;
    let one = ((1.0 / H).round() as usize - 1).min((seconds / H).round() as usize - 1);
    for &r in &modes {
        for (name, selection, correction, force) in [
            ("trained", ModeSelection::Trained, false, ForceEvaluation::Exact),
            ("trained+static", ModeSelection::Trained, true, ForceEvaluation::Exact),
            ("trained+cubature", ModeSelection::Trained, false, ForceEvaluation::Cubature),
            ("load+static", ModeSelection::Load, true, ForceEvaluation::Exact),
        ] {
            if !only.is_empty() && !only.iter().any(|o| o == name) {
                continue;
            }
            let settings = Settings {
                mode_selection: selection,
                static_correction: correction,
                force_evaluation: force,
                training: TrainingProgram { time: training_time, ..TrainingProgram::default() },
                ..Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, r)
            };
            let setup = base.with_settings(settings);
            for ((case, g), reference) in cases.iter().zip(&references) {
                let m = run(&setup, *g, seconds);
                let e = trajectory_errors_by_window(&m.frames, &reference.frames, &m.start, Masses::Equal);
                println!(
                    "r = {r:2} {name:17} {case:32} E {:.4} / {:.4} / {:.4} (whole run)  range {:6.2}  springs {:5}  set-up {:7.3} s  run {:.4} s/s ({:.1}x full)",
                    e[half.min(e.len() - 1)],
                    e[one],
                    e[e.len() - 1],
                    m.range,
                    m.springs,
                    m.setup_s,
                    m.run_s / seconds,
                    reference.run_s / m.run_s,
                );
            }
        }
    }
}
