//! `cargo xtask report [--quick] [--out DIR] [--log] [--scene NAME]... [--variants-only]`:
//! runs the error-against-run-time study (examples/report.rs) in release
//! mode, then draws its plots with the project's Python environment
//! (`cargo xtask setup` makes it). `--log` prints every run as it ends;
//! `--scene` and `--variants-only` make a partial report, for trying it out.

use std::process::Command;

use crate::cli::{self, Long, ValueExt};

const USAGE: &str = "\
usage: cargo xtask report [--quick] [--out DIR] [--log] [--scene NAME]... [--variants-only]

  --quick          the small study (CI)
  --out DIR        where the CSV and the plots go (default report)
  --log            print every run as it ends
  --scene NAME     only this scene (repeatable): a partial report
  --variants-only  only the variants of the study: a partial report";

struct Options {
    quick: bool,
    out: String,
    /// What the study itself takes besides --quick and --out.
    study_args: Vec<String>,
}

fn parse(args: &[String]) -> Result<Option<Options>, cli::Error> {
    let mut o = Options { quick: false, out: "report".into(), study_args: Vec::new() };
    let mut p = cli::parser(args);
    while let Some(arg) = p.next()? {
        match arg {
            Long("quick") => o.quick = true,
            Long("out") => o.out = p.value()?.string()?,
            Long("log") => o.study_args.push("--log".into()),
            Long("variants-only") => o.study_args.push("--variants-only".into()),
            Long("scene") => o.study_args.extend(["--scene".into(), p.value()?.string()?]),
            arg if cli::is_help(&arg) => return Ok(None),
            arg => return Err(arg.unexpected()),
        }
    }
    Ok(Some(o))
}

pub fn main(args: &[String]) -> Result<(), String> {
    let Some(o) = cli::options(parse(args), USAGE)? else { return Ok(()) };
    run_with(o.quick, &o.out, &o.study_args)
}

/// The study (`cargo xtask test` runs the quick one for pytest).
pub fn run(quick: bool, out: &str) -> Result<(), String> {
    run_with(quick, out, &[])
}

fn run_with(quick: bool, out: &str, study_args: &[String]) -> Result<(), String> {
    let date = Command::new("date").arg("-u").arg("+%Y-%m-%d").output().ok().and_then(|o| String::from_utf8(o.stdout).ok()).unwrap_or_default();
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| s.lines().find(|l| l.starts_with("model name")).map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string()))
        .unwrap_or_else(|| "unknown CPU".into());
    let root = crate::setup::root();
    // Built, then run (the binary is run with the study's arguments).
    let status = Command::new(crate::setup::cargo())
        .current_dir(&root)
        .args(["build", "--release", "--example", "report"])
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
