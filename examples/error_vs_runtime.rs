//! Trajectory error (docs/method.md, section 6) and wall time of modal runs against
//! a full-space reference, on one scene.
//!
//! cargo run --release --example error_vs_runtime -- [scene] [seconds]

mod common;

use common::error;
use std::time::Instant;

use modal_mass_spring::physics::*;
use modal_mass_spring::scenes;

struct Run {
    frames: Vec<Vec<f64>>,
    setup_s: f64,
    run_s: f64,
}

fn simulate(p: &Grid, s: &SolverParams, h: f64, frame_every: usize, frames: usize) -> Result<Run, PhysicsError> {
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
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map(String::as_str).unwrap_or("paper-2d-top-row");
    let seconds: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(2.0);
    let p = scenes::canonical(name).expect("unknown scene").grid;
    let n = p.build().unwrap().n_dofs();
    let frames = (seconds * 100.0).round() as usize; // output every 10 ms
    let full = |integrator, h: f64| SolverParams {
        reduction: Reduction::Full,
        integrator,
        n_modes: 0,
        max_internal_step: h,
        substepping: true,
        basis: BasisOptions::default(),
        force: ForceOptions::default(),
    };
    let reference_h = 1e-4;
    let reference = simulate(&p, &full(Integrator::NewmarkImplicit, reference_h), reference_h, 100, frames).unwrap();
    let half = simulate(&p, &full(Integrator::NewmarkImplicit, reference_h / 2.0), reference_h / 2.0, 200, frames).unwrap();
    let (ref_err, _) = error(&reference.frames, &half.frames, p.dim);
    println!("scene {name}, {seconds} s, {n} free DOFs; reference: full space, implicit Newmark, dt = {reference_h} s");
    println!("reference self-check: E(dt) vs E(dt/2) = {ref_err:.3e}");
    println!("{:<8} {:<18} {:>6} {:>9} {:>10} {:>12} {:>12} {:>14}", "method", "integrator", "modes", "step_s", "setup_s", "run_s/sim_s", "E", "max_node_m");
    let h = 0.01;
    let mut rows = vec![];
    for integrator in [Integrator::NewmarkExplicit, Integrator::NewmarkImplicit] {
        for r in [2, 8, n] {
            rows.push(SolverParams {
                reduction: Reduction::Modal,
                integrator,
                n_modes: r,
                max_internal_step: h,
                substepping: true,
                basis: BasisOptions::default(),
                force: ForceOptions::default(),
            });
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
            Err(e) => println!("{:?} {:?} r={}: {e}", s.reduction, s.integrator, s.n_modes),
        }
    }
}
