//! `cargo xtask run` and `cargo xtask test`.
//!
//! - `run [--out PNG] [--stop-time S]`: setup, build `target/fmu/ModalMassSpring.fmu`,
//!   then the main job `python/main_job.py` (fmpy simulates the default scene,
//!   prints a summary and writes `out/default_scene.png`).
//! - `test [PYTEST ARGS...]`: setup, build the default FMU and one scene-baked FMU
//!   per canonical scene into `target/fmu/`, run `cargo test --workspace`
//!   (the soak run of a million steps included), pytest on `tests/python` with
//!   the venv's Python, the valgrind leak check, and each fuzz target for
//!   FUZZ_SECONDS. Every stage always runs; the task fails if any fails.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use crate::{fmu, fuzz, setup, valgrind};

/// Fuzzing time per target in `cargo xtask test` (CI): bounded, see README.
const FUZZ_SECONDS: u64 = 30;

fn target_dir(root: &Path) -> PathBuf {
    match std::env::var_os("CARGO_TARGET_DIR").map(PathBuf::from) {
        Some(p) if p.is_absolute() => p,
        Some(p) => root.join(p),
        None => root.join("target"),
    }
}

fn fmu_dir(root: &Path) -> PathBuf {
    target_dir(root).join("fmu")
}

/// The canonical scenes: the `[scenes.NAME]` tables of modelDescription/variables.toml.
fn scene_names(root: &Path) -> Result<Vec<String>, String> {
    let path = root.join("modelDescription/variables.toml");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let names: Vec<String> = text
        .lines()
        .filter_map(|l| l.trim().strip_prefix("[scenes.")?.strip_suffix(']').map(|s| s.trim_matches('"').to_string()))
        .collect();
    if names.is_empty() {
        return Err(format!("no [scenes.NAME] table in {}", path.display()));
    }
    Ok(names)
}

fn cargo() -> String {
    std::env::var("CARGO").unwrap_or_else(|_| "cargo".into())
}

fn step(title: &str) {
    eprintln!("\n==> {title}");
}

pub fn run(args: &[String]) -> Result<(), String> {
    let root = setup::root();
    step("setup");
    setup::main(&[])?;
    step("cargo xtask fmu");
    fmu::main(&[])?;
    let fmu = fmu_dir(&root).join("ModalMassSpring.fmu");
    step("main job: python/main_job.py");
    let status = Command::new(setup::python())
        .current_dir(&root)
        .arg("python/main_job.py")
        .arg(&fmu)
        .args(args)
        .status()
        .map_err(|e| format!("cannot run the venv's python: {e}"))?;
    if !status.success() {
        return Err(format!("the main job failed ({status})"));
    }
    Ok(())
}

pub fn test(args: &[String]) -> Result<(), String> {
    let root = setup::root();
    let mut times: Vec<(&str, f64)> = Vec::new();
    let mut clock = Instant::now();
    let mut lap = |name: &'static str, times: &mut Vec<(&str, f64)>| {
        times.push((name, clock.elapsed().as_secs_f64()));
        clock = Instant::now();
    };
    step("setup");
    setup::main(&[])?;
    lap("setup", &mut times);

    step("cargo xtask fmu (default and every canonical scene)");
    fmu::main(&[])?;
    for scene in scene_names(&root)? {
        fmu::main(&["--scene".to_string(), scene])?;
    }
    lap("FMUs", &mut times);

    let mut failures = Vec::new();

    step("cargo test --workspace");
    let status = Command::new(cargo())
        .current_dir(&root)
        .args(["test", "--workspace"])
        .status()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if !status.success() {
        failures.push(format!("cargo test ({status})"));
    }
    lap("cargo test", &mut times);

    step("pytest tests/python");
    let status = Command::new(setup::python())
        .current_dir(&root)
        .env("MMS_FMU_DIR", fmu_dir(&root))
        .args(["-m", "pytest", "tests/python", "-ra", "-p", "no:cacheprovider"])
        .args(args)
        .status()
        .map_err(|e| format!("cannot run the venv's python: {e}"))?;
    // pytest: 0 all passed, 1 some failed, 2 interrupted, 3 internal error,
    // 4 usage error, 5 no test collected (a failure here: the suite must run).
    match status.code() {
        Some(0) => {}
        Some(1) => failures.push("pytest: some tests failed".into()),
        Some(5) => failures.push("pytest collected no test".into()),
        Some(c) => failures.push(format!("pytest did not complete (exit code {c})")),
        None => failures.push(format!("pytest was killed ({status})")),
    }
    lap("pytest", &mut times);

    step("valgrind: cargo xtask valgrind");
    if let Err(e) = valgrind::main(&[]) {
        failures.push(e);
    }
    lap("valgrind", &mut times);

    step(&format!("fuzzing: cargo xtask fuzz --seconds {FUZZ_SECONDS}"));
    let targets: Vec<String> = Vec::new();
    match fuzz::run(&targets, FUZZ_SECONDS, false) {
        Ok(reports) => {
            for r in reports {
                eprintln!("fuzz {}: {} executions in {:.0} s, no crash", r.target, r.runs, r.seconds);
            }
        }
        Err(e) => failures.push(e),
    }
    lap("fuzz", &mut times);

    let summary: Vec<String> = times.iter().map(|(n, t)| format!("{n} {t:.0} s")).collect();
    eprintln!("\ntimes: {}", summary.join(", "));

    if failures.is_empty() {
        eprintln!("\nall tests passed (cargo test, pytest, valgrind, fuzzing)");
        Ok(())
    } else {
        Err(format!("failed: {}", failures.join("; ")))
    }
}
