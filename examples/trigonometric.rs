//! The trigonometric scheme measured (docs/method.md, sections 4 and 6):
//! trajectory error E against a full-space reference at one internal step
//! per communication step, beside both Newmark schemes at the same
//! communication step, and the energy of a long undamped run.
//!
//! cargo run --release --example trigonometric -- [seconds] [--drift STEPS]
//!
//! The reference is the study's: full space, explicit Newmark at 1e-4 s,
//! checked against its run at half the step. E is that of the study (node
//! masses are equal and cancel), over the output times of every
//! communication step from t = 0 to `seconds` (2 s by default).

mod common;

use common::error;
use std::time::Instant;

use modal_mass_spring::canonical_scenes;
use modal_mass_spring::physics::*;

const REFERENCE_DT: f64 = 1e-4;

struct Run {
    frames: Vec<Vec<f64>>,
    run_s: f64,
    internal_steps: usize,
}

fn solver(reduction: Reduction, integrator: Integrator, n_modes: usize, max_internal_step: f64) -> Settings {
    let settings = Settings { max_internal_step, ..Settings::new(reduction, integrator, n_modes) };
    if reduction == Reduction::Modal {
        // Load modes with a static correction, at rest.
        Settings { mode_selection: ModeSelection::Load, static_correction: true, ..settings }
    } else {
        settings
    }
}

/// Node positions after every communication step `h` (frames every `every` steps), from t = 0 to `seconds`.
fn simulate(p: &Grid, s: &Settings, h: f64, every: usize, seconds: f64) -> Result<Run, PhysicsError> {
    let mut sim = Simulator::new(p.build()?, s, &Loads::physical(s.n_modes))?;
    let n = (seconds / h).round() as usize;
    let mut frames = vec![sim.positions().to_vec()];
    let mut internal_steps = 0;
    let t0 = Instant::now();
    for k in 1..=n {
        sim.do_step(h)?;
        internal_steps += sim.internal_steps_last();
        if k % every == 0 {
            frames.push(sim.positions().to_vec());
        }
    }
    Ok(Run { frames, run_s: t0.elapsed().as_secs_f64() / seconds, internal_steps: internal_steps / n })
}

fn compare(scene: &str, h: f64, modes: &[usize], seconds: f64) {
    let p = canonical_scenes::canonical(scene).expect("canonical scene").grid;
    let d = p.dim;
    let every_ref = (h / REFERENCE_DT).round() as usize;
    let full = |dt: f64| solver(Reduction::Full, Integrator::NewmarkExplicit, 0, dt);
    let reference = simulate(&p, &full(REFERENCE_DT), REFERENCE_DT, every_ref, seconds).expect("reference");
    let halved = simulate(&p, &full(REFERENCE_DT / 2.0), REFERENCE_DT / 2.0, 2 * every_ref, seconds).expect("reference at half the step");
    println!(
        "\n{scene}: communication step {h} s, output every step, {seconds} s; reference E(dt) against E(dt/2) = {:.2e}",
        error(&reference.frames, &halved.frames, d).0
    );
    println!("| modes | integrator | internal steps per step | E | largest node error (m) | run time (s/s) |\n|---|---|---|---|---|---|");
    for &r in modes {
        // The scheme measured here first, then every other one.
        let others = Integrator::ALL.iter().copied().filter(|&i| i != Integrator::Trigonometric);
        for integrator in std::iter::once(Integrator::Trigonometric).chain(others) {
            match simulate(&p, &solver(Reduction::Modal, integrator, r, h), h, 1, seconds) {
                Ok(run) => {
                    let (e, node) = error(&run.frames, &reference.frames, d);
                    println!("| {r} | {} | {} | {e:.4} | {node:.2e} | {:.2e} |", integrator.name(), run.internal_steps, run.run_s);
                }
                Err(e) => println!("| {r} | {} | — | failed: {e} | | |", integrator.name()),
            }
        }
    }
}

/// Energy (kinetic + potential) of an undamped run of `steps` communication
/// steps: its largest distance from the start, relative to the largest
/// kinetic energy, over the first and the last tenth of the run.
fn drift(scene: &str, r: usize, h: f64, steps: usize) {
    let p = canonical_scenes::canonical(scene).expect("canonical scene").grid;
    let s = solver(Reduction::Modal, Integrator::Trigonometric, r, h);
    let mut sim = Simulator::new(p.build().unwrap(), &s, &Loads::physical(r)).unwrap();
    let e0 = sim.kinetic_energy() + sim.potential_energy();
    let (mut k_max, mut first, mut last, mut all) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for k in 0..steps {
        sim.do_step(h).unwrap();
        let kinetic = sim.kinetic_energy();
        let e = kinetic + sim.potential_energy();
        k_max = k_max.max(kinetic);
        let dev = (e - e0).abs();
        all = all.max(dev);
        if k < steps / 10 {
            first = first.max(dev);
        }
        if k >= steps - steps / 10 {
            last = last.max(dev);
        }
    }
    println!(
        "\n{scene}, {r} modes (load + static correction), trigonometric, undamped, {steps} steps of {h} s ({} s): largest kinetic energy {k_max:.4e} J; \
         largest |E(t) - E(0)| / that: {:.3e} over the first tenth, {:.3e} over the last tenth, {:.3e} over the run",
        steps as f64 * h,
        first / k_max,
        last / k_max,
        all / k_max
    );
}

fn parse_args() -> Result<(f64, usize), lexopt::Error> {
    use lexopt::prelude::*;
    let (mut seconds, mut drift_steps) = (None, 10_000);
    let mut parser = lexopt::Parser::from_env();
    while let Some(arg) = parser.next()? {
        match arg {
            Long("drift") => drift_steps = parser.value()?.parse()?,
            Value(v) if seconds.is_none() => seconds = Some(v.parse()?),
            _ => return Err(arg.unexpected()),
        }
    }
    Ok((seconds.unwrap_or(2.0), drift_steps))
}

fn main() {
    let (seconds, drift_steps) = parse_args().unwrap_or_else(|e| {
        eprintln!("trigonometric: {e}\nusage: trigonometric [seconds] [--drift STEPS]");
        std::process::exit(2)
    });
    compare("paper-2d-top-row", 0.02, &[16], seconds);
    compare("paper-3d-sheet", 0.05, &[8, 16], seconds);
    drift("paper-2d-top-row", 16, 0.02, drift_steps);
    drift("paper-3d-sheet", 16, 0.05, drift_steps);
}
