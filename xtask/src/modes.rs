//! `cargo xtask modes [--scene NAME] [--set NAME=VALUE]... [--modes N]
//! [--mode-selection lowest|load|trained] [--linearization rest|equilibrium]
//! [--out DIR]`: the mode gallery of a scene. Builds and runs
//! examples/modes.rs (the modes, their frequencies, modeOutOfPlane and
//! modeSymmetry as the FMU computes them, as CSV), then draws DIR/modes.png
//! and writes DIR/modes.md with python/modes_gallery.py in the project's
//! Python environment (`cargo xtask setup` makes it).

use std::process::Command;

use crate::cli::{self, Long, ValueExt};
use crate::setup;

const USAGE: &str = "\
usage: cargo xtask modes [--scene NAME] [--set NAME=VALUE]... [--modes N]
                         [--mode-selection lowest|load|trained] [--linearization rest|equilibrium] [--out DIR]

  --scene NAME            a canonical scene (modelDescription/variables.toml); default the start values
  --set NAME=VALUE        a variable of the model description (repeatable), after the scene's values
  --modes N               nModes
  --mode-selection WHICH  modeSelection: lowest, load or trained
  --linearization WHERE   linearization: rest or equilibrium
  --out DIR               where modes.csv, shapes.csv, modes.png and modes.md go (default target/modes)";

/// The example's arguments and the output directory.
fn parse(args: &[String]) -> Result<Option<(Vec<String>, String)>, cli::Error> {
    let (mut pass, mut out) = (Vec::new(), "target/modes".to_string());
    let mut p = cli::parser(args);
    while let Some(arg) = p.next()? {
        let option = match &arg {
            Long("out") => {
                out = p.value()?.string()?;
                continue;
            }
            Long(name @ ("scene" | "set" | "modes" | "mode-selection" | "linearization")) => format!("--{name}"),
            arg if cli::is_help(arg) => return Ok(None),
            _ => return Err(arg.unexpected()),
        };
        pass.extend([option, p.value()?.string()?]);
    }
    Ok(Some((pass, out)))
}

pub fn main(args: &[String]) -> Result<(), String> {
    let Some((pass, out)) = cli::options(parse(args), USAGE)? else { return Ok(()) };
    let root = setup::root();
    let status = Command::new(setup::cargo())
        .current_dir(&root)
        .args(["build", "--release", "--example", "modes"])
        .status()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if !status.success() {
        return Err("cargo build --example modes failed".into());
    }
    let status = Command::new(setup::target_dir(&root).join("release/examples/modes"))
        .current_dir(&root)
        .args(&pass)
        .args(["--out", &out])
        .status()
        .map_err(|e| format!("cannot run the modes example: {e}"))?;
    if !status.success() {
        return Err("the modes example failed".into());
    }
    let python = setup::python();
    if !python.exists() {
        return Err("no .venv: run `cargo xtask setup` first to draw the gallery".into());
    }
    let status = Command::new(python).current_dir(&root).args(["python/modes_gallery.py", &out]).status().map_err(|e| format!("cannot run python: {e}"))?;
    if !status.success() {
        return Err("drawing the gallery failed".into());
    }
    Ok(())
}
