//! `cargo xtask stability`: runs the stability matrix (tests/stability.rs)
//! and writes its table into docs/stability.md, between the markers the test
//! checks on every other run.

use std::process::Command;

use crate::cli;

const USAGE: &str = "usage: cargo xtask stability (no options)";

pub fn main(args: &[String]) -> Result<(), String> {
    if cli::options(cli::no_arguments(args), USAGE)?.is_none() {
        return Ok(());
    }
    let status = Command::new(crate::setup::cargo())
        .current_dir(crate::setup::root())
        .args(["test", "--release", "--test", "suite", "stability::", "--", "--nocapture"])
        .env("MMS_STABILITY_WRITE", "1")
        .status()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if !status.success() {
        return Err("the stability matrix failed (docs/stability.md was written only if every cell passed its checks)".into());
    }
    println!("docs/stability.md: stability table written (the full output is in target/stability.md)");
    Ok(())
}
