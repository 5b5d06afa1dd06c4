//! Set-up time of the modal space against the mesh size: the cloth-3d
//! scene on n x n nodes, 30 modes (by default), the lowest modes and the
//! modes ranked by their static response to gravity and the trained basis
//! (`docs/method.md`, section 3), each without and with the static correction. One line per
//! case.
//!
//! cargo run --release --example setup_vs_mesh -- [n...] [--modes r] [--lowest | --load | --trained] [--no-correction | --only-correction] [--cubature]
//!
//! Columns: `basis_s` is `basis::build` on its own (assembly of K, the
//! factorization of K − σM, the eigen or Ritz solution, Rayleigh–Ritz),
//! for a trained basis `trained_basis::train` (the training runs, the SVD,
//! Rayleigh–Ritz);
//! `setup_s` the whole simulator set-up on the same scene, which builds the
//! basis again; `other_s` = setup_s − basis_s, the rest of the set-up (the
//! force model, the step-size bound, the first outputs). `omega_1` is the
//! lowest kept angular frequency, to tell the cases apart. With
//! `--cubature` the set-up trains a cubature for the forces (section 4),
//! which `other_s` then holds.

use std::time::Instant;

use modal_mass_spring::canonical_scenes;
use modal_mass_spring::physics::setup::{basis, trained_basis};
use modal_mass_spring::physics::{ForceEvaluation, Integrator, ModeSelection, Reduction, Settings, Simulator};

struct Args {
    sizes: Vec<usize>,
    modes: usize,
    corrections: Vec<bool>,
    selections: Vec<ModeSelection>,
    cubature: bool,
}

fn parse_args() -> Result<Args, lexopt::Error> {
    use lexopt::prelude::*;
    let mut args = Args { sizes: Vec::new(), modes: 30, corrections: vec![false, true], selections: ModeSelection::ALL.to_vec(), cubature: false };
    let mut parser = lexopt::Parser::from_env();
    while let Some(arg) = parser.next()? {
        match arg {
            Long("modes") => args.modes = parser.value()?.parse()?,
            Long("no-correction") => args.corrections = vec![false],
            Long("only-correction") => args.corrections = vec![true],
            Long("lowest") => args.selections = vec![ModeSelection::Lowest],
            Long("load") => args.selections = vec![ModeSelection::Load],
            Long("trained") => args.selections = vec![ModeSelection::Trained],
            Long("cubature") => args.cubature = true,
            Value(v) => args.sizes.push(v.parse()?),
            _ => return Err(arg.unexpected()),
        }
    }
    if args.sizes.is_empty() {
        args.sizes = vec![30, 50, 100, 200, 300];
    }
    Ok(args)
}

/// The solver settings of every case.
fn solver(modes: usize, selection: ModeSelection, static_correction: bool, cubature: bool) -> Settings {
    let mut solver = Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, modes);
    solver.mode_selection = selection;
    solver.static_correction = static_correction;
    if cubature {
        solver.force_evaluation = ForceEvaluation::Cubature;
    }
    solver
}

fn main() {
    let Args { sizes, modes, corrections, selections, cubature } = parse_args().unwrap_or_else(|e| {
        eprintln!("setup_vs_mesh: {e} (sizes are numbers of nodes per side)");
        eprintln!("usage: setup_vs_mesh [n...] [--modes r] [--lowest | --load | --trained] [--no-correction | --only-correction] [--cubature]");
        std::process::exit(2)
    });
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let forces = if cubature { "cubature" } else { "exact" };
    println!("cloth-3d, n x n nodes, {modes} modes, {forces} forces, {threads} threads available");
    println!("{:>5} {:>8} {:>7} {:>10} {:>8} {:>8} {:>8} {:>10}", "n", "dofs", "select", "correction", "basis_s", "setup_s", "other_s", "omega_1");
    for &n in &sizes {
        for &selection in &selections {
            for &static_correction in &corrections {
                let setup = canonical_scenes::cloth(n, n).with_settings(solver(modes, selection, static_correction, cubature));
                let select = selection.name();
                let correction = if static_correction { "static" } else { "none" };
                let scene = setup.grid.build().expect("cloth scene");
                let dofs = scene.n_dofs();
                let t0 = Instant::now();
                // A trained basis is built by its training program (full-space runs, then the SVD).
                let built = match selection {
                    ModeSelection::Trained => trained_basis::train(scene.clone(), &setup.loads, &setup.settings).map(|d| d.basis),
                    _ => basis::build(&scene, &setup.loads, modes, &setup.settings).map(|b| b.modes),
                };
                let basis_s = t0.elapsed().as_secs_f64();
                let omega_1 = match built {
                    Ok(b) => b.frequencies()[0],
                    Err(e) => {
                        println!("{n:>5} {dofs:>8} {select:>7} {correction:>10} basis failed: {e}");
                        continue;
                    }
                };
                let t1 = Instant::now();
                let sim = Simulator::new(scene, &setup.settings, &setup.loads);
                let setup_s = t1.elapsed().as_secs_f64();
                match sim {
                    Ok(_) => println!("{n:>5} {dofs:>8} {select:>7} {correction:>10} {basis_s:>8.3} {setup_s:>8.3} {:>8.3} {omega_1:>10.6}", setup_s - basis_s),
                    Err(e) => println!("{n:>5} {dofs:>8} {select:>7} {correction:>10} set-up failed: {e}"),
                }
            }
        }
    }
}
