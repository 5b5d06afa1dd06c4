//! `cargo xtask run`, `cargo xtask control` and `cargo xtask test`.
//!
//! - `run [--out PNG] [--stop-time S]`: setup, build `target/fmu/ModalMassSpring.fmu`,
//!   then the main job `python/main_job.py` (fmpy simulates the default scene,
//!   prints a summary and writes `out/default_scene.png`).
//! - `control [--figure NAMES] [--out DIR]`: the same, then `python/control.py`
//!   (the paper's control experiments and control in 3D through the FMU).
//! - `test [--only STAGE[,STAGE...]] [PYTEST ARGS...]`: setup, build the
//!   default FMU and one scene-baked FMU per canonical scene into
//!   `target/fmu/`, `cargo fmt --check`, the Python lint (ruff with
//!   `ruff.toml`, no Python file over 600 lines), each fuzz target for FUZZ_SECONDS,
//!   `cargo test --release --workspace` (with the XSD validation of the model
//!   description and the soak run of a million steps), the quick study, the
//!   reference importer fmusim (`target/tools/fmusim`), pytest on
//!   `tests/python` with the venv's Python and the valgrind leak check.
//!   Every stage runs (CI); the task fails if any fails. `--only` runs the
//!   stages named, for a quick loop, and what pytest needs of the others.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use crate::cli::{self, Long, ValueExt};
use crate::setup::{cargo, target_dir};
use crate::{fmu, fmusim, fuzz, lint, setup, valgrind};

/// Packages and features of every cargo build of the test stage: the same
/// for the tests, the quick study and the valgrind example, so each builds
/// on the others (features are unified over the packages a build selects).
const TEST_CARGO_ARGS: [&str; 3] = ["--workspace", "--features", "modal_mass_spring/xsd"];

/// Fuzzing time per target in `cargo xtask test` (CI): bounded, see docs/robustness.md.
const FUZZ_SECONDS: u64 = 30;

fn fmu_dir(root: &Path) -> PathBuf {
    target_dir(root).join("fmu")
}

/// The canonical scenes: the `[scenes.NAME]` tables of modelDescription/variables.toml.
fn scene_names(root: &Path) -> Result<Vec<String>, String> {
    let path = root.join("modelDescription/variables.toml");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let names: Vec<String> =
        text.lines().filter_map(|l| l.trim().strip_prefix("[scenes.")?.strip_suffix(']').map(|s| s.trim_matches('"').to_string())).collect();
    if names.is_empty() {
        return Err(format!("no [scenes.NAME] table in {}", path.display()));
    }
    Ok(names)
}

fn step(title: &str) {
    eprintln!("\n==> {title}");
}

const RUN_USAGE: &str = "\
usage: cargo xtask run [--] [MAIN JOB ARGS...]

Installs what it needs, builds target/fmu/ModalMassSpring.fmu and runs
python/main_job.py on it with every argument (`cargo xtask run -- --help`
shows them all), e.g. --stop-time S, --out PNG.";

pub fn run(args: &[String]) -> Result<(), String> {
    fmu_job(args, RUN_USAGE, "python/main_job.py", "main job")
}

const CONTROL_USAGE: &str = "\
usage: cargo xtask control [--] [--figure fig7,fig8,fig9,3d | all] [--out DIR]

Installs what it needs, builds target/fmu/ModalMassSpring.fmu and runs
python/control.py on it: the paper's Figs. 7, 8 (with its GIF) and 9 and the
control of the 3D sheet by mode class, through the FMU, as pictures and
numbers.txt in DIR (default target/control; docs/control/ holds the
committed ones: --out docs/control). docs/control.md explains them.";

pub fn control(args: &[String]) -> Result<(), String> {
    fmu_job(args, CONTROL_USAGE, "python/control.py", "control figures")
}

const VIEW_USAGE: &str = "\
usage: cargo xtask view [--] [--scene NAME] [--set NAME=VALUE ...] [--port P] [--fps F] [--no-open]

Installs what it needs (aiohttp; the page's three.js and lil-gui come from
the npm registry on first use), builds target/fmu/ModalMassSpring.fmu and
runs python/view.py on it: a server on 127.0.0.1 that runs one FMU instance
per browser page in real time, draws the sheet and lets the page steer it
(mode weights and classes, gravity, damping, the holders, the load node).
docs/view.md explains the page.";

pub fn view(args: &[String]) -> Result<(), String> {
    let Some(args) = cli::options(cli::pass_through(args), VIEW_USAGE)? else {
        setup::python_help("python/view.py");
        return Ok(());
    };
    step("setup: what the view needs");
    setup::install(setup::Purpose::View)?;
    python_on_fmu(&args, "python/view.py", "view")
}

/// Setup, the default FMU, then `script FMU ARGS...` in the venv's Python.
fn fmu_job(args: &[String], usage: &str, script: &str, what: &str) -> Result<(), String> {
    let Some(args) = cli::options(cli::pass_through(args), usage)? else {
        setup::python_help(script);
        return Ok(());
    };
    step("setup: what building and running need");
    setup::install(setup::Purpose::Run)?;
    python_on_fmu(&args, script, what)
}

/// The default FMU built, then `script FMU ARGS...` in the venv's Python.
fn python_on_fmu(args: &[String], script: &str, what: &str) -> Result<(), String> {
    let root = setup::root();
    step("cargo xtask fmu");
    fmu::main(&[])?;
    let fmu = fmu_dir(&root).join("ModalMassSpring.fmu");
    step(&format!("{what}: {script}"));
    let status =
        Command::new(setup::python()).current_dir(&root).arg(script).arg(&fmu).args(args).status().map_err(|e| format!("cannot run the venv's python: {e}"))?;
    if !status.success() {
        return Err(format!("the {what} failed ({status})"));
    }
    Ok(())
}

/// fmi-rs's `schema` feature (XSD validation in the tests) links libxml2
/// statically from its build directory, and its build script downloads and
/// builds libxml2 from GitHub when that directory is missing. Where the
/// download fails, the system's libxml2 (Debian's libxml2-dev, installed by
/// setup) is linked into that directory and the build retried.
fn prepare_xsd(root: &Path, test_args: &[&str]) -> Result<(), String> {
    let build = || Command::new(cargo()).current_dir(root).args(test_args).arg("--no-run").status().map_err(|e| format!("cannot run cargo: {e}"));
    if build()?.success() {
        return Ok(());
    }
    let system_lib = ["/usr/lib/x86_64-linux-gnu/libxml2.a", "/usr/lib/libxml2.a"]
        .into_iter()
        .map(Path::new)
        .find(|p| p.exists())
        .ok_or("the test build failed, and there is no system libxml2.a to link fmi-rs's XSD support against (apt-get install libxml2-dev)")?;
    let build_dir = target_dir(root).join("release/build");
    let entries = std::fs::read_dir(&build_dir).map_err(|e| format!("{}: {e}", build_dir.display()))?;
    for entry in entries.flatten() {
        let out = entry.path().join("out");
        if !entry.file_name().to_string_lossy().starts_with("fmi-rs-") || !out.is_dir() || out.join("libxml2").exists() {
            continue;
        }
        eprintln!("xtask: linking the system libxml2 into {}", out.display());
        std::fs::create_dir_all(out.join("libxml2/include")).map_err(|e| e.to_string())?;
        std::fs::create_dir_all(out.join("libxml2/lib")).map_err(|e| e.to_string())?;
        std::os::unix::fs::symlink("/usr/include/libxml2", out.join("libxml2/include/libxml2")).map_err(|e| e.to_string())?;
        std::os::unix::fs::symlink(system_lib, out.join("libxml2/lib/libxml2.a")).map_err(|e| e.to_string())?;
    }
    if build()?.success() {
        Ok(())
    } else {
        Err("the tests do not build".into())
    }
}

const TEST_USAGE: &str = "\
usage: cargo xtask test [--only STAGE[,STAGE...]] [--] [PYTEST ARGS...]

Every stage, in this order (CI runs them all):
  setup     cargo xtask setup (what the tests need)
  fmu       the default FMU and one FMU per canonical scene, into target/fmu/
  fmt       cargo fmt --check
  lint      ruff check of every Python file (ruff.toml), none over 600 lines
            (installs ruff into .venv when missing)
  fuzz      each fuzz target for 30 s
  rust      cargo test --release --workspace --features xsd
  report    cargo xtask report --quick, into target/report-quick/
  fmusim    the reference importer, into target/tools/fmusim
  python    pytest tests/python (with PYTEST ARGS)
  valgrind  cargo xtask valgrind

  --only STAGE,...  run only these stages; python also builds the FMUs and
                    fmusim when out of date and the quick report when missing.
                    Without setup, run `cargo xtask setup` once beforehand.
Arguments after the options (or after --) go to pytest.";

/// The stages of `cargo xtask test`, in the order they run.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Stage {
    Setup,
    Fmu,
    Fmt,
    Lint,
    Fuzz,
    Rust,
    Report,
    Fmusim,
    Python,
    Valgrind,
}

const STAGES: [(&str, Stage); 10] = [
    ("setup", Stage::Setup),
    ("fmu", Stage::Fmu),
    ("fmt", Stage::Fmt),
    ("lint", Stage::Lint),
    ("fuzz", Stage::Fuzz),
    ("rust", Stage::Rust),
    ("report", Stage::Report),
    ("fmusim", Stage::Fmusim),
    ("python", Stage::Python),
    ("valgrind", Stage::Valgrind),
];

impl Stage {
    fn name(self) -> &'static str {
        STAGES.iter().find(|(_, s)| *s == self).map_or("?", |(n, _)| n)
    }
}

struct TestOptions {
    /// The stages `--only` names; `None`: every stage.
    only: Option<Vec<Stage>>,
    pytest: Vec<String>,
}

/// `--only` (and `-h`) first; the first other argument starts pytest's.
fn parse_test(args: &[String]) -> Result<Option<TestOptions>, cli::Error> {
    let mut only: Option<Vec<Stage>> = None;
    let mut p = cli::parser(args);
    while cli::peek(&mut p).is_some_and(|a| ["-h", "--help", "--only"].contains(&a.as_str()) || a.starts_with("--only=")) {
        match p.next()? {
            Some(Long("only")) => {
                let list = p.value()?.string()?;
                for name in list.split(',').map(str::trim) {
                    let stage = STAGES.iter().find(|(n, _)| *n == name).map(|(_, s)| *s);
                    let known: Vec<&str> = STAGES.iter().map(|(n, _)| *n).collect();
                    let stage = stage.ok_or(format!("--only: unknown stage {name:?} (stages: {})", known.join(", ")))?;
                    only.get_or_insert_with(Vec::new).push(stage);
                }
            }
            _ => return Ok(None),
        }
    }
    Ok(Some(TestOptions { only, pytest: cli::rest(&mut p)? }))
}

pub fn test(args: &[String]) -> Result<(), String> {
    let Some(o) = cli::options(parse_test(args), TEST_USAGE)? else { return Ok(()) };
    let selected = |stage: Stage| o.only.as_ref().is_none_or(|only| only.contains(&stage));
    let partial = o.only.is_some();
    let root = setup::root();
    let report_dir = target_dir(&root).join("report-quick");
    // What pytest needs of the other stages, when `--only` leaves them out:
    // fresh FMUs, an up-to-date fmusim (both cheap when nothing changed) and
    // the quick report (only when it is missing: it takes minutes).
    let python = selected(Stage::Python);
    let needed = |stage: Stage| {
        let for_python = python
            && match stage {
                Stage::Fmu | Stage::Fmusim => true,
                Stage::Report => !report_dir.join("error_vs_runtime.csv").exists(),
                _ => false,
            };
        if !selected(stage) && for_python {
            eprintln!("\nxtask test: running {} as well, which python needs", stage.name());
        }
        selected(stage) || for_python
    };
    // Every build of the library in the stages below (the FMUs, the fuzz
    // targets' library, the examples, the FMUs pytest builds) is then one:
    // the examples' (see fmu::WITH_EXAMPLES). Only the Rust tests, with the
    // xsd feature, compile it once more.
    std::env::set_var(fmu::WITH_EXAMPLES, "1");
    let mut times: Vec<(&str, f64)> = Vec::new();
    let mut clock = Instant::now();
    let mut lap = |name: &'static str, times: &mut Vec<(&str, f64)>| {
        times.push((name, clock.elapsed().as_secs_f64()));
        clock = Instant::now();
    };
    if selected(Stage::Setup) {
        step("setup");
        setup::install(setup::Purpose::Test)?;
        lap("setup", &mut times);
    }

    if needed(Stage::Fmu) {
        step("cargo xtask fmu (default and every canonical scene)");
        fmu::main(&[])?;
        for scene in scene_names(&root)? {
            fmu::main(&["--scene".to_string(), scene])?;
        }
        lap("FMUs", &mut times);
    }

    let mut failures = Vec::new();

    if selected(Stage::Fmt) {
        step("cargo fmt --check (rustfmt.toml)");
        let rustfmt = Command::new(cargo()).args(["fmt", "--version"]).output().is_ok_and(|o| o.status.success());
        if rustfmt {
            for dir in [root.clone(), root.join("fuzz")] {
                let status =
                    Command::new(cargo()).current_dir(&dir).args(["fmt", "--all", "--check"]).status().map_err(|e| format!("cannot run cargo fmt: {e}"))?;
                if !status.success() {
                    failures.push(format!("formatting differs from rustfmt in {} (run `cargo fmt --all` there)", dir.display()));
                }
            }
        } else {
            eprintln!("rustfmt is not installed: formatting not checked");
        }
        lap("fmt", &mut times);
    }

    if selected(Stage::Lint) {
        step(&format!("lint: ruff check (ruff.toml), Python files at most {} lines", lint::MAX_PYTHON_LINES));
        if let Err(e) = lint::run(&root) {
            failures.push(format!("lint: {e}"));
        }
        lap("lint", &mut times);
    }

    // Right after the FMU build: the fuzz targets load its library as it is
    // (the test build below compiles the crate with other features).
    if selected(Stage::Fuzz) {
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
    }

    if selected(Stage::Rust) {
        step("cargo test --release --workspace --features xsd");
        // Release profile: the FMUs above already built every dependency in it,
        // so the tests compile only themselves (the dev profile would build faer
        // a second time, most of CI's time).
        let test_args = ["test", "--release", TEST_CARGO_ARGS[0], TEST_CARGO_ARGS[1], TEST_CARGO_ARGS[2]];
        prepare_xsd(&root, &test_args)?;
        let status = Command::new(cargo()).current_dir(&root).args(test_args).status().map_err(|e| format!("cannot run cargo: {e}"))?;
        if !status.success() {
            failures.push(format!("cargo test ({status})"));
        }
        lap("cargo test", &mut times);
    }

    if needed(Stage::Report) {
        step("cargo xtask report --quick");
        // As the examples pytest runs are built, not as the tests: one more build of the library, not two.
        if let Err(e) = crate::report::run(true, &report_dir.display().to_string()) {
            failures.push(format!("report --quick: {e}"));
        }
        lap("report --quick", &mut times);
    }

    // tests/python/test_fmusim.py runs the FMU in the reference importer;
    // on CI a missing binary fails those tests.
    let mut fmusim = None;
    if needed(Stage::Fmusim) {
        step("cargo xtask fmusim");
        match fmusim::build(&root, false) {
            Ok(path) => fmusim = Some(path),
            Err(e) => failures.push(format!("fmusim: {e}")),
        }
        lap("fmusim", &mut times);
    }

    if python {
        step("pytest tests/python");
        let mut pytest = Command::new(setup::python());
        if let Some(path) = &fmusim {
            pytest.env("MMS_FMUSIM", path);
        }
        let status = pytest
            .current_dir(&root)
            .env("MMS_FMU_DIR", fmu_dir(&root))
            .env("MMS_REPORT_DIR", &report_dir)
            .args(["-m", "pytest", "tests/python", "-ra", "-p", "no:cacheprovider"])
            .args(&o.pytest)
            .status()
            .map_err(|e| format!("cannot run the venv's python (`cargo xtask setup` makes it): {e}"))?;
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
    }

    if selected(Stage::Valgrind) {
        step("valgrind: cargo xtask valgrind");
        if let Err(e) = valgrind::run(valgrind::DEFAULT_CYCLES) {
            failures.push(e);
        }
        lap("valgrind", &mut times);
    }

    let summary: Vec<String> = times.iter().map(|(n, t)| format!("{n} {t:.0} s")).collect();
    eprintln!("\ntimes: {}", summary.join(", "));

    if !failures.is_empty() {
        Err(format!("failed: {}", failures.join("; ")))
    } else if partial {
        let names: Vec<&str> = STAGES.iter().filter(|(_, s)| selected(*s)).map(|(_, s)| s.name()).collect();
        eprintln!("\npassed: {} (--only)", names.join(", "));
        Ok(())
    } else {
        eprintln!("\nall tests passed (cargo test, pytest with fmpy and fmusim, valgrind, fuzzing, the Python lint)");
        Ok(())
    }
}
