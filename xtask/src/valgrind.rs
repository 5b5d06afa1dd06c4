//! `cargo xtask valgrind [CYCLES]`: the `fmi_cycles` example (instantiate,
//! configure, step, FMU states, serialization, refused calls, free, over and
//! over, through the C functions) under
//! `valgrind --leak-check=full --error-exitcode=1`; fails on any leak or
//! invalid memory access.

use std::process::Command;

use crate::cli::{self, Value, ValueExt};
use crate::setup;

pub const DEFAULT_CYCLES: &str = "12";

pub fn main(args: &[String]) -> Result<(), String> {
    let Some(cycles) = cli::options(parse(args), USAGE)? else { return Ok(()) };
    run(&cycles)
}

const USAGE: &str = "\
usage: cargo xtask valgrind [CYCLES]

  CYCLES  instantiate/step/serialize/free cycles (default 12)";

fn parse(args: &[String]) -> Result<Option<String>, cli::Error> {
    let mut cycles = None;
    let mut p = cli::parser(args);
    while let Some(arg) = p.next()? {
        match arg {
            Value(n) if cycles.is_none() => cycles = Some(n.parse::<u32>()?.to_string()),
            arg if cli::is_help(&arg) => return Ok(None),
            arg => return Err(arg.unexpected()),
        }
    }
    Ok(Some(cycles.unwrap_or_else(|| DEFAULT_CYCLES.to_string())))
}

/// `cycles` cycles under valgrind (the example built in the release profile).
pub fn run(cycles: &str) -> Result<(), String> {
    let root = setup::root();
    if Command::new("valgrind").arg("--version").output().is_err() {
        return Err("valgrind is not installed (cargo xtask setup installs it)".into());
    }
    // The release profile, as the FMU is built (and with no second build of faer).
    let out = Command::new(setup::cargo())
        .current_dir(&root)
        .args(["build", "--release", "--example", "fmi_cycles", "--message-format=json-render-diagnostics"])
        .output()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if !out.status.success() {
        return Err(format!("cargo build --example fmi_cycles failed:\n{}", String::from_utf8_lossy(&out.stderr)));
    }
    let exe = String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter(|l| l.contains("\"name\":\"fmi_cycles\"") && l.contains("\"executable\":\""))
        .find_map(|l| Some(l.split("\"executable\":\"").nth(1)?.split('"').next()?.to_string()))
        .ok_or("cargo did not report the fmi_cycles executable")?;
    let status = Command::new("valgrind")
        .args(["--leak-check=full", "--show-leak-kinds=definite,indirect,possible", "--errors-for-leak-kinds=definite,indirect,possible"])
        .args(["--error-exitcode=1", "--quiet"])
        .arg(&exe)
        .arg(cycles)
        .status()
        .map_err(|e| format!("cannot run valgrind: {e}"))?;
    if !status.success() {
        return Err(format!("valgrind found leaks or memory errors in fmi_cycles ({status})"));
    }
    println!("valgrind: fmi_cycles, {cycles} cycles: no leaks, no memory errors");
    Ok(())
}
