//! Set-up time of the modal space against the mesh size: the cloth-3d
//! scene on n x n nodes, 30 modes (by default), the lowest modes and the
//! modes ranked by their static response to gravity (`docs/method.md`,
//! section 3), each without and with the static correction. One line per
//! case.
//!
//! cargo run --release --example setup_vs_mesh -- [n...] [--modes r] [--lowest | --load] [--no-correction | --only-correction]
//!
//! Columns: `basis_s` is `basis::build` on its own (assembly of K, the
//! factorization of K − σM, the eigen or Ritz solution, Rayleigh–Ritz);
//! `setup_s` the whole simulator set-up on the same scene, which builds the
//! basis again; `other_s` = setup_s − basis_s, the rest of the set-up (the
//! force model, the step-size bound, the first outputs). `omega_1` is the
//! lowest kept angular frequency, to tell the cases apart.

use std::time::Instant;

use modal_mass_spring::physics::basis::{self, BasisOptions};
use modal_mass_spring::physics::{Integrator, ModeSelection, Reduction, Simulator, SolverParams};
use modal_mass_spring::scenes;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut sizes = Vec::new();
    let mut modes = 30;
    let mut corrections = vec![false, true];
    let mut selections = vec![ModeSelection::Lowest, ModeSelection::Load];
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--modes" => {
                i += 1;
                modes = args.get(i).and_then(|s| s.parse().ok()).expect("--modes takes a number");
            }
            "--no-correction" => corrections = vec![false],
            "--only-correction" => corrections = vec![true],
            "--lowest" => selections = vec![ModeSelection::Lowest],
            "--load" => selections = vec![ModeSelection::Load],
            s => sizes.push(s.parse::<usize>().unwrap_or_else(|_| panic!("{s}: sizes are numbers of nodes per side"))),
        }
        i += 1;
    }
    if sizes.is_empty() {
        sizes = vec![30, 50, 100, 200, 300];
    }
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!("cloth-3d, n x n nodes, {modes} modes, {threads} threads available");
    println!("{:>5} {:>8} {:>7} {:>10} {:>8} {:>8} {:>8} {:>10}", "n", "dofs", "select", "correction", "basis_s", "setup_s", "other_s", "omega_1");
    for &n in &sizes {
        for &selection in &selections {
            for &static_correction in &corrections {
                let mut solver = SolverParams::new(Reduction::Modal, Integrator::NewmarkExplicit, modes);
                solver.basis = BasisOptions { selection, static_correction, ..BasisOptions::default() };
                let setup = scenes::cloth(n, n).with_solver(solver);
                let select = match selection {
                    ModeSelection::Lowest => "lowest",
                    ModeSelection::Load => "load",
                };
                let correction = if static_correction { "static" } else { "none" };
                let scene = setup.grid.build().expect("cloth scene");
                let dofs = scene.n_dofs();
                let t0 = Instant::now();
                let built = basis::build(&scene, &setup.loads, modes, &setup.solver.basis);
                let basis_s = t0.elapsed().as_secs_f64();
                let omega_1 = match built {
                    Ok(b) => b.modes.frequencies()[0],
                    Err(e) => {
                        println!("{n:>5} {dofs:>8} {select:>7} {correction:>10} basis failed: {e}");
                        continue;
                    }
                };
                let t1 = Instant::now();
                let sim = Simulator::new(scene, &setup.solver, &setup.loads);
                let setup_s = t1.elapsed().as_secs_f64();
                match sim {
                    Ok(_) => println!("{n:>5} {dofs:>8} {select:>7} {correction:>10} {basis_s:>8.3} {setup_s:>8.3} {:>8.3} {omega_1:>10.6}", setup_s - basis_s),
                    Err(e) => println!("{n:>5} {dofs:>8} {select:>7} {correction:>10} set-up failed: {e}"),
                }
            }
        }
    }
}
