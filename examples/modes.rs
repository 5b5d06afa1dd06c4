//! The kept modes of a scene as data for a gallery (`cargo xtask modes`
//! draws it): sets up the simulator as the FMU does from the same variable
//! values and writes into DIR
//!
//! - `modes.csv`: per mode its number (from 1), omega [rad/s] (modeFrequencies),
//!   frequency [Hz], modeOutOfPlane, modeSymmetry and its class;
//! - `shapes.csv`: per mode and node (output order) the rest position and the
//!   rest position plus the mode's displacement, scaled so the node that moves
//!   most moves half a spacing (x, y, z; z 0 in 2D);
//! - `springs.csv`: the node pairs a spring joins (auxiliary springs left out);
//! - `scene.txt`: name, dimension, nx, ny.
//!
//! `cargo run --release --example modes -- [--scene NAME] [--set NAME=VALUE]... [--modes N]
//!  [--mode-selection lowest|load|trained] [--linearization rest|equilibrium] [--out DIR]`
//!
//! `--set` takes a variable of the model description by name (a number,
//! true or false), after the scene's values.

use std::fmt::Write as _;
use std::path::PathBuf;

use lexopt::prelude::*;
use modal_mass_spring::fmi::variables::{vr, Type, VARIABLES};
use modal_mass_spring::model::Params;
use modal_mass_spring::options::{Linearization, ModeSelection};

struct Options {
    scene: Option<String>,
    sets: Vec<(String, String)>,
    modes: Option<u64>,
    selection: Option<ModeSelection>,
    linearization: Option<Linearization>,
    out: PathBuf,
}

fn parse() -> Result<Options, lexopt::Error> {
    let mut o = Options { scene: None, sets: Vec::new(), modes: None, selection: None, linearization: None, out: "target/modes".into() };
    let mut p = lexopt::Parser::from_env();
    while let Some(arg) = p.next()? {
        match arg {
            Long("scene") => o.scene = Some(p.value()?.string()?),
            Long("set") => {
                let v = p.value()?.string()?;
                let (name, value) = v.split_once('=').ok_or_else(|| format!("--set {v}: NAME=VALUE expected"))?;
                o.sets.push((name.trim().into(), value.trim().into()));
            }
            Long("modes") => o.modes = Some(p.value()?.parse()?),
            Long("mode-selection") => {
                let v = p.value()?.string()?;
                o.selection = Some(*ModeSelection::ALL.iter().find(|m| m.name() == v).ok_or_else(|| format!("--mode-selection {v}: not a mode selection"))?);
            }
            Long("linearization") => {
                let v = p.value()?.string()?;
                o.linearization = Some(*Linearization::ALL.iter().find(|m| m.name() == v).ok_or_else(|| format!("--linearization {v}: not a linearization"))?);
            }
            Long("out") => o.out = p.value()?.string()?.into(),
            arg => return Err(arg.unexpected()),
        }
    }
    Ok(o)
}

/// The variable values the options describe.
fn params(o: &Options) -> Result<Params, String> {
    let mut p = match &o.scene {
        Some(name) => Params::canonical(name).ok_or_else(|| format!("no canonical scene {name}"))?,
        None => Params::start(),
    };
    for (name, value) in &o.sets {
        let v = VARIABLES.iter().find(|v| v.name == name).ok_or_else(|| format!("--set: no variable {name}"))?;
        let x = match (v.ty, value.as_str()) {
            (Type::Boolean, "true") => 1.0,
            (Type::Boolean, "false") => 0.0,
            _ => value.parse::<f64>().map_err(|e| format!("--set {name}={value}: {e}"))?,
        };
        let n = p.size_of(v);
        p.set(v.vr, &vec![x; n]);
        p.fit_arrays();
    }
    if let Some(r) = o.modes {
        p.set(vr::N_MODES, &[r as f64]);
    }
    if let Some(m) = o.selection {
        p.set(vr::MODE_SELECTION, &[m.value() as f64]);
    }
    if let Some(l) = o.linearization {
        p.set(vr::LINEARIZATION, &[l.value() as f64]);
    }
    p.fit_arrays();
    Ok(p)
}

fn main() -> Result<(), String> {
    let o = parse().map_err(|e| e.to_string())?;
    let p = params(&o)?;
    let sim = p.build().map_err(|e| e.to_string())?;
    let scene = sim.scene();
    let basis = sim.mode_shapes().ok_or("the set-up keeps no modes (nModes = 0)")?;
    let classes = sim.mode_classes();
    let (d, r, n) = (scene.dim, basis.r, scene.n_nodes);

    let mut table = String::from("mode,omega,frequency_hz,out_of_plane,symmetry,class\n");
    for (i, w) in sim.mode_frequencies().iter().enumerate() {
        let hz = w / (2.0 * std::f64::consts::PI);
        writeln!(table, "{},{w},{hz},{},{},{}", i + 1, classes.out_of_plane[i], classes.symmetry[i], classes.label(i)).unwrap();
    }

    // The modes on the grid as the FMU's modeShapes gives them: [mode][node][d].
    let grid = sim.mode_grid_shapes();
    let rest = |j: usize, a: usize| if a < d { scene.rest[scene.slot_of_node[j] * d + a] } else { 0.0 };
    let spacing = scene.springs.iter().map(|s| s.rest).filter(|&l| l > 0.0).fold(f64::INFINITY, f64::min);
    let mut shapes = String::from("mode,node,rest_x,rest_y,rest_z,x,y,z\n");
    for (i, phi) in grid.chunks(n * d).enumerate() {
        let largest = phi.chunks(d).map(|p| p.iter().map(|v| v * v).sum::<f64>().sqrt()).fold(0.0f64, f64::max);
        let scale = if largest > 0.0 { 0.5 * spacing / largest } else { 0.0 };
        for j in 0..n {
            let at = |a: usize| rest(j, a);
            let moved = |a: usize| at(a) + if a < d { scale * phi[j * d + a] } else { 0.0 };
            writeln!(shapes, "{},{j},{},{},{},{},{},{}", i + 1, at(0), at(1), at(2), moved(0), moved(1), moved(2)).unwrap();
        }
    }

    let mut node_of_slot = vec![usize::MAX; scene.rest.len() / d];
    for (j, &s) in scene.slot_of_node.iter().enumerate() {
        node_of_slot[s] = j;
    }
    let mut springs = String::from("a,b\n");
    for s in &scene.springs {
        let (a, b) = (node_of_slot[s.a], node_of_slot[s.b]);
        if a < n && b < n {
            writeln!(springs, "{a},{b}").unwrap();
        }
    }

    let name = o.scene.clone().unwrap_or_else(|| "custom".into());
    let info = format!("{name}\n{d}\n{}\n{}\n", p.count(vr::NX), p.count(vr::NY));
    std::fs::create_dir_all(&o.out).map_err(|e| format!("{}: {e}", o.out.display()))?;
    for (file, text) in [("modes.csv", &table), ("shapes.csv", &shapes), ("springs.csv", &springs), ("scene.txt", &info)] {
        let path = o.out.join(file);
        std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    println!("{r} modes of {name} written to {}", o.out.display());
    Ok(())
}
