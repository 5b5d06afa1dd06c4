//! `cargo xtask report [--quick] [--out DIR] [--log] [--scene NAME]... [--variants-only]`:
//! runs the error-against-run-time study (examples/report.rs) in release
//! mode, then draws its plots with the project's Python environment
//! (`cargo xtask setup` makes it). `--log` prints every run as it ends;
//! `--scene` and `--variants-only` make a partial report, for trying it out.

use std::process::Command;

pub fn main(args: &[String]) -> Result<(), String> {
    let quick = args.iter().any(|a| a == "--quick");
    let out = args.iter().position(|a| a == "--out").and_then(|i| args.get(i + 1)).cloned().unwrap_or_else(|| "report".into());
    // What the study itself takes besides --quick and --out.
    let mut study_args = Vec::new();
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--log" | "--variants-only" => study_args.push(args[i].clone()),
            "--scene" => {
                study_args.extend(args.get(i..i + 2).ok_or("--scene takes a scene name")?.iter().cloned());
                i += 1;
            }
            _ => {}
        }
        i += 1;
    }
    run_with(quick, &out, &[], &study_args)
}

/// The study with `cargo_args` added to its `cargo run` (`cargo xtask test`
/// passes its own features, so the example reuses the test build).
pub fn run(quick: bool, out: &str, cargo_args: &[&str]) -> Result<(), String> {
    run_with(quick, out, cargo_args, &[])
}

fn run_with(quick: bool, out: &str, cargo_args: &[&str], study_args: &[String]) -> Result<(), String> {
    let date = Command::new("date").arg("-u").arg("+%Y-%m-%d").output().ok().and_then(|o| String::from_utf8(o.stdout).ok()).unwrap_or_default();
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| s.lines().find(|l| l.starts_with("model name")).map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string()))
        .unwrap_or_else(|| "unknown CPU".into());
    let root = crate::setup::root();
    // Built, then run: `cargo run` cannot take --workspace, which
    // `cargo xtask test` passes so that the build reuses the test build.
    let status = Command::new(crate::setup::cargo())
        .current_dir(&root)
        .args(["build", "--release", "--example", "report"])
        .args(cargo_args)
        .status()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if !status.success() {
        return Err("cargo build --example report failed".into());
    }
    let target = crate::setup::target_dir(&root);
    let mut cmd = Command::new(target.join("release/examples/report"));
    cmd.current_dir(&root);
    cmd.args(["--out", out]);
    if quick {
        cmd.arg("--quick");
    }
    cmd.args(study_args);
    cmd.env("REPORT_DATE", format!("{} on {cpu}", date.trim()));
    let status = cmd.status().map_err(|e| format!("cannot run the study: {e}"))?;
    if !status.success() {
        return Err("the study failed".into());
    }
    let python = crate::setup::python();
    if !python.exists() {
        return Err("no .venv: run `cargo xtask setup` first to draw the plots".into());
    }
    let status = Command::new(python)
        .current_dir(&root)
        .args(["xtask/plot_report.py", &format!("{out}/error_vs_runtime.csv"), out])
        .status()
        .map_err(|e| format!("cannot run python: {e}"))?;
    if !status.success() {
        return Err("plotting failed".into());
    }
    println!("report written to {out}/");
    Ok(())
}
