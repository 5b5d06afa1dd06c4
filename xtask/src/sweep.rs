//! `cargo xtask sweep [--] [SWEEP ARGS...]`: a parameter sweep of FMU runs on
//! Dask (python/sweep.py, with the venv's Python). Installs what it needs
//! (`setup --for sweep`), builds `target/fmu/ModalMassSpring.fmu` (the FMU
//! the sweep runs unless its arguments name another), then passes every
//! argument to python/sweep.py (`--help` lists them).

use std::process::Command;

use crate::{cli, fmu, setup};

const USAGE: &str = "\
usage: cargo xtask sweep [--] [SWEEP ARGS...]

Installs what the sweep needs, builds target/fmu/ModalMassSpring.fmu and
passes every argument to python/sweep.py (`cargo xtask sweep -- --help`
shows them all).";

pub fn main(args: &[String]) -> Result<(), String> {
    let Some(args) = cli::options(cli::pass_through(args), USAGE)? else {
        setup::python_help("python/sweep.py");
        return Ok(());
    };
    let root = setup::root();
    setup::install(setup::Purpose::Sweep)?;
    fmu::main(&[])?;
    let status = Command::new(setup::python())
        .current_dir(&root)
        .arg("python/sweep.py")
        .args(&args)
        .status()
        .map_err(|e| format!("cannot run the venv's python: {e}"))?;
    if !status.success() {
        return Err(format!("the sweep failed ({status})"));
    }
    Ok(())
}
