//! `cargo xtask fuzz [--seconds N] [--linked] [TARGET...]`: runs the
//! cargo-fuzz targets of `fuzz/` for N seconds each (default 30) and reports
//! the executions; fails on any crash, sanitizer report or failed check.
//!
//! - Installs cargo-fuzz (`cargo install cargo-fuzz --locked`) if missing and
//!   runs it with RUSTC_BOOTSTRAP=1 (it needs nightly flags).
//! - By default the targets load the FMU's release library
//!   (`target/release/libmodal_mass_spring.so`, built here if needed) with
//!   AddressSanitizer in the harness: a build of seconds. `--linked` builds
//!   the FMU crate into the targets, coverage-instrumented, without a
//!   sanitizer (an ASan build of faer takes far longer): minutes to build,
//!   deeper runs.
//! - Links the system libFuzzer (Debian's libclang-rt-dev) when present,
//!   instead of compiling libFuzzer's C++ sources.
//! - The `bake` target bakes its scenes at start with the crate's `bake`
//!   example (built here, its path passed as MMS_BAKE_EXAMPLE), so its valid
//!   bakes come from the same build as the library they are loaded into.
//! - Inputs that fail are left in `fuzz/artifacts/TARGET/`; the corpus grows
//!   in `fuzz/corpus/TARGET/` from the seeds in `fuzz/seeds/TARGET/`.

use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::Instant;

use crate::cli::{self, Long, Value, ValueExt};
use crate::setup;
use crate::setup::{cargo, target_dir};

const TARGETS: &[&str] = &["deserialize", "call_sequence", "bake"];
const DEFAULT_SECONDS: u64 = 30;

pub struct Report {
    pub target: String,
    pub runs: u64,
    pub seconds: f64,
}

const USAGE: &str = "\
usage: cargo xtask fuzz [--seconds N] [--linked] [TARGET...]

  --seconds N  fuzzing time per target (default 30)
  --linked     build the FMU crate into the targets, coverage-instrumented,
               without a sanitizer (minutes to build, deeper runs)
  TARGET       deserialize, call_sequence, bake (default: every target)";

struct Options {
    seconds: u64,
    linked: bool,
    targets: Vec<String>,
}

fn parse(args: &[String]) -> Result<Option<Options>, cli::Error> {
    let mut o = Options { seconds: DEFAULT_SECONDS, linked: false, targets: Vec::new() };
    let mut p = cli::parser(args);
    while let Some(arg) = p.next()? {
        match arg {
            Long("seconds") => o.seconds = p.value()?.parse()?,
            Long("linked") => o.linked = true,
            Value(t) => {
                let t = t.string()?;
                if !TARGETS.contains(&t.as_str()) {
                    return Err(format!("unknown target {t} (targets: {})", TARGETS.join(", ")).into());
                }
                o.targets.push(t);
            }
            arg if cli::is_help(&arg) => return Ok(None),
            arg => return Err(arg.unexpected()),
        }
    }
    Ok(Some(o))
}

pub fn main(args: &[String]) -> Result<(), String> {
    let Some(o) = cli::options(parse(args), USAGE)? else { return Ok(()) };
    let reports = run(&o.targets, o.seconds, o.linked)?;
    for r in &reports {
        println!("fuzz {}: {} executions in {:.0} s, no crash", r.target, r.runs, r.seconds);
    }
    Ok(())
}

fn ensure_cargo_fuzz() -> Result<(), String> {
    let ok = Command::new(cargo()).args(["fuzz", "--version"]).stdout(Stdio::null()).stderr(Stdio::null()).status();
    if ok.map(|s| s.success()).unwrap_or(false) {
        return Ok(());
    }
    eprintln!("fuzz: installing cargo-fuzz");
    let status = Command::new(cargo()).args(["install", "cargo-fuzz", "--locked"]).status().map_err(|e| format!("cannot run cargo install: {e}"))?;
    if !status.success() {
        return Err("cargo install cargo-fuzz --locked failed".into());
    }
    Ok(())
}

/// The libFuzzer runtime of the system's clang, if installed.
fn system_libfuzzer() -> Option<PathBuf> {
    let mut found: Vec<PathBuf> = std::fs::read_dir("/usr/lib")
        .ok()?
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().starts_with("llvm-"))
        .flat_map(|e| std::fs::read_dir(e.path().join("lib/clang")).into_iter().flatten().flatten())
        .map(|v| v.path().join("lib/linux/libclang_rt.fuzzer-x86_64.a"))
        .filter(|p| p.exists())
        .collect();
    found.sort();
    found.pop()
}

/// Builds the `bake` example (the writer of resources/setup.bin); its path.
fn build_bake_example(root: &std::path::Path) -> Result<PathBuf, String> {
    let status =
        Command::new(cargo()).current_dir(root).args(["build", "--release", "--example", "bake"]).status().map_err(|e| format!("cannot run cargo: {e}"))?;
    if !status.success() {
        return Err("cargo build --release --example bake failed".into());
    }
    Ok(target_dir(root).join("release/examples/bake"))
}

/// Executions and seconds from libFuzzer's "Done 12345 runs in 30 second(s)".
fn executions(log: &str) -> Option<(u64, f64)> {
    log.lines().rev().find_map(|l| {
        let w: Vec<&str> = l.strip_prefix("Done ")?.split_whitespace().collect();
        Some((w.first()?.parse().ok()?, w.get(3)?.parse().ok()?))
    })
}

/// Runs `targets` (every target when empty) for `seconds` each.
pub fn run(targets: &[String], seconds: u64, linked: bool) -> Result<Vec<Report>, String> {
    let all: Vec<String> = TARGETS.iter().map(|t| t.to_string()).collect();
    let targets = if targets.is_empty() { &all[..] } else { targets };
    let root = setup::root();
    let fuzz = root.join("fuzz");
    ensure_cargo_fuzz()?;
    let library = if linked { target_dir(&root).join("release/libmodal_mass_spring.so") } else { crate::fmu::build_library(&root)? };
    let (sanitizer, features): (&str, &[&str]) = if linked { ("none", &["--features", "linked"]) } else { ("address", &[]) };
    let bake_example = if targets.iter().any(|t| t == "bake") { Some(build_bake_example(&root)?) } else { None };
    let libfuzzer = system_libfuzzer();
    let mut reports = Vec::new();
    for t in targets {
        let corpus = fuzz.join("corpus").join(t);
        std::fs::create_dir_all(&corpus).map_err(|e| format!("{}: {e}", corpus.display()))?;
        let seeds = fuzz.join("seeds").join(t);
        let mut cmd = Command::new(cargo());
        cmd.current_dir(&fuzz)
            .env("RUSTC_BOOTSTRAP", "1")
            .env("MMS_FMU_LIBRARY", &library)
            .args(["fuzz", "run", "--sanitizer", sanitizer])
            .args(features)
            .arg(t)
            .arg(&corpus);
        if seeds.is_dir() {
            cmd.arg(&seeds);
        }
        // A step is at most 0.1 s of model time; anything near the timeout is a hang.
        cmd.args(["--", &format!("-max_total_time={seconds}"), "-timeout=20", "-max_len=4096", "-print_final_stats=1"]);
        if let Some(example) = &bake_example {
            cmd.env("MMS_BAKE_EXAMPLE", example);
        }
        if let Some(lib) = &libfuzzer {
            cmd.env("CUSTOM_LIBFUZZER_PATH", lib);
        }
        eprintln!("\n==> fuzz {t} ({seconds} s{})", if linked { ", linked" } else { "" });
        let start = Instant::now();
        let out = cmd.stderr(Stdio::piped()).output().map_err(|e| format!("cannot run cargo fuzz: {e}"))?;
        let log = String::from_utf8_lossy(&out.stderr);
        let tail: Vec<&str> = log.lines().rev().take(60).collect::<Vec<_>>().into_iter().rev().collect();
        if !out.status.success() {
            eprintln!("{}", tail.join("\n"));
            return Err(format!("fuzz target {t} failed ({}); the input is in fuzz/artifacts/{t}/", out.status));
        }
        let (runs, fuzzing) = executions(&log).ok_or_else(|| format!("fuzz target {t}: no execution count in its output:\n{}", tail.join("\n")))?;
        let stats: Vec<&str> = log.lines().filter(|l| l.starts_with("stat::")).collect();
        eprintln!("{}", stats.join("\n"));
        eprintln!("fuzz {t}: {runs} executions in {fuzzing:.0} s of fuzzing ({:.0} s with the build), no crash", start.elapsed().as_secs_f64());
        reports.push(Report { target: t.clone(), runs, seconds: fuzzing });
    }
    Ok(reports)
}
