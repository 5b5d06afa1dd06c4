//! `cargo xtask sweep [--] [SWEEP ARGS...]`: a parameter sweep of FMU runs on
//! Dask (python/sweep.py, with the venv's Python). Installs what it needs
//! (`setup --for sweep`), builds `target/fmu/ModalMassSpring.fmu` (the FMU
//! the sweep runs unless its arguments name another), then passes every
//! argument to python/sweep.py (`--help` lists them).

use std::process::Command;

use crate::{fmu, setup};

pub fn main(args: &[String]) -> Result<(), String> {
    // `cargo xtask sweep -- ARGS` hands the `--` on.
    let args = match args.split_first() {
        Some((first, rest)) if first == "--" => rest,
        _ => args,
    };
    let root = setup::root();
    setup::install(setup::Purpose::Sweep)?;
    fmu::main(&[])?;
    let status = Command::new(setup::python())
        .current_dir(&root)
        .arg("python/sweep.py")
        .args(args)
        .status()
        .map_err(|e| format!("cannot run the venv's python: {e}"))?;
    if !status.success() {
        return Err(format!("the sweep failed ({status})"));
    }
    Ok(())
}
