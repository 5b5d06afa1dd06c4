//! Trajectory error (docs/method.md, section 6) and wall time of modal runs against
//! a full-space reference, on one scene.
//!
//! cargo run --release --example error_vs_runtime -- [scene] [seconds]
//!
//! Every integrator runs modal (2, 8 and all modes) and in full space, but
//! where the set-up refuses the space (the trigonometric scheme in full space).

mod common;

use common::error;
use std::time::Instant;

use modal_mass_spring::canonical_scenes;
use modal_mass_spring::physics::*;

struct Run {
    frames: Vec<Vec<f64>>,
    setup_s: f64,
    run_s: f64,
}

/// The solver settings of every run: `n_modes` modes, or full space for `None`.
fn solver(integrator: Integrator, n_modes: Option<usize>, max_internal_step: f64) -> Settings {
    let reduction = if n_modes.is_some() { Reduction::Modal } else { Reduction::Full };
    Settings { max_internal_step, ..Settings::new(reduction, integrator, n_modes.unwrap_or(0)) }
}

fn parse_args() -> Result<(String, f64), lexopt::Error> {
    use lexopt::prelude::*;
    let (mut name, mut seconds) = (None, None);
    let mut parser = lexopt::Parser::from_env();
    while let Some(arg) = parser.next()? {
        match arg {
            Value(v) if name.is_none() => name = Some(v.string()?),
            Value(v) if seconds.is_none() => seconds = Some(v.parse()?),
            _ => return Err(arg.unexpected()),
        }
    }
    Ok((name.unwrap_or_else(|| "paper-2d-top-row".into()), seconds.unwrap_or(2.0)))
}

fn simulate(p: &Grid, s: &Settings, h: f64, frame_every: usize, frames: usize) -> Result<Run, PhysicsError> {
    let t0 = Instant::now();
    let mut sim = Simulator::new(p.build()?, s, &Loads::physical(s.n_modes))?;
    let setup_s = t0.elapsed().as_secs_f64();
    let mut out = vec![sim.positions().to_vec()];
    let t1 = Instant::now();
    for _ in 0..frames {
        for _ in 0..frame_every {
            sim.do_step(h)?;
        }
        out.push(sim.positions().to_vec());
    }
    Ok(Run { frames: out, setup_s, run_s: t1.elapsed().as_secs_f64() })
}

fn main() {
    let (name, seconds) = parse_args().unwrap_or_else(|e| {
        eprintln!("error_vs_runtime: {e}\nusage: error_vs_runtime [scene] [seconds]");
        std::process::exit(2)
    });
    let name = name.as_str();
    let p = canonical_scenes::canonical(name).expect("unknown scene").grid;
    let n = p.build().unwrap().n_dofs();
    let frames = (seconds * 100.0).round() as usize; // output every 10 ms
    let full = |integrator, h: f64| solver(integrator, None, h);
    let reference_h = 1e-4;
    let reference = simulate(&p, &full(Integrator::NewmarkImplicit, reference_h), reference_h, 100, frames).unwrap();
    let half = simulate(&p, &full(Integrator::NewmarkImplicit, reference_h / 2.0), reference_h / 2.0, 200, frames).unwrap();
    let (ref_err, _) = error(&reference.frames, &half.frames, p.dim);
    println!("scene {name}, {seconds} s, {n} free DOFs; reference: full space, implicit Newmark, dt = {reference_h} s");
    println!("reference self-check: E(dt) vs E(dt/2) = {ref_err:.3e}");
    println!("{:<8} {:<18} {:>6} {:>9} {:>10} {:>12} {:>12} {:>14}", "method", "integrator", "modes", "step_s", "setup_s", "run_s/sim_s", "E", "max_node_m");
    let h = 0.01;
    let mut rows = vec![];
    for &integrator in Integrator::ALL {
        for r in [2, 8, n] {
            rows.push(solver(integrator, Some(r), h));
        }
        rows.push(full(integrator, h));
    }
    for s in rows {
        match simulate(&p, &s, h, 1, frames) {
            Ok(run) => {
                let (e, max_node) = error(&run.frames, &reference.frames, p.dim);
                let method = if s.reduction == Reduction::Modal { "modal" } else { "full" };
                let modes = if s.reduction == Reduction::Modal { s.n_modes } else { n };
                println!(
                    "{method:<8} {:<18} {modes:>6} {h:>9} {:>10.4} {:>12.4e} {e:>12.4e} {max_node:>14.4e}",
                    format!("{:?}", s.integrator),
                    run.setup_s,
                    run.run_s / seconds
                );
            }
            // A space the scheme cannot integrate: not a run.
            Err(e) if e.refuses_pairing() => {}
            Err(e) => println!("{:?} {:?} r={}: {e}", s.reduction, s.integrator, s.n_modes),
        }
    }
}
