//! `cargo xtask setup [--for run|sweep|view|test]`: installs what a task needs,
//! and only what is missing, so it is cheap to run again.
//!
//! - Debian packages, through apt-get (`apt-get update` once, only when
//!   something has to be installed): `libclang-dev` (bindgen in `fmi-sys`)
//!   to build the FMU; for the tests also `libxml2-dev` (XSD validation in
//!   `fmi-rs`), `valgrind` (`cargo xtask valgrind`), `libclang-rt-dev`
//!   (the libFuzzer runtime `cargo xtask fuzz` links) and what the reference
//!   importer fmusim is built with (`cargo xtask fmusim`): `gcc`,
//!   `libsundials-dev`, `libminizip-dev`, `zlib1g-dev` and `libxml2-dev`;
//!   `libtbb12`, which Ecos's library (ecospy) links; Chromium and its
//!   driver, the browser the view's tests drive headless (with selenium).
//! - The Python environment `.venv` in the repository root: fmpy, numpy and
//!   matplotlib to run the main job; dask.distributed for parameter sweeps
//!   (`cargo xtask sweep`, python/sweep.py); aiohttp for the live view's
//!   server (`cargo xtask view`, python/view.py); for the tests pytest and
//!   fmu-manipulation-toolbox (its `fmucontainer` is one of the co-simulation
//!   masters `tests/python/test_chain.py` runs the FMU under) and ecospy
//!   (the Ecos co-simulation engine, `tests/python/test_ecos.py`); ruff,
//!   the Python linter of the `lint` stage (xtask/src/lint.rs).
//! - For the live view, its page's three.js and lil-gui from the npm
//!   registry into target/view-assets/ (python/viewing/assets.py: pinned
//!   versions checked against their sha512s).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use crate::cli::{self, Long, ValueExt};

/// What the installation is for; each purpose needs what the ones before it need.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Purpose {
    /// Build the FMU and run the main job (`cargo xtask run`, `cargo xtask fmu`).
    Run,
    /// Also parameter sweeps on Dask (`cargo xtask sweep`).
    Sweep,
    /// Also the live view in a browser (`cargo xtask view`).
    View,
    /// Everything `cargo xtask test` runs: also fuzzing, valgrind, the XSD check and pytest.
    Test,
}

/// Debian packages: (package, the first purpose that needs it).
const DEBIAN_PACKAGES: &[(&str, Purpose)] = &[
    ("libclang-dev", Purpose::Run),
    ("libxml2-dev", Purpose::Test),
    ("valgrind", Purpose::Test),
    ("libclang-rt-dev", Purpose::Test),
    // fmusim (xtask/src/fmusim.rs); libxml2-dev above too
    ("gcc", Purpose::Test),
    ("libsundials-dev", Purpose::Test),
    ("libminizip-dev", Purpose::Test),
    ("zlib1g-dev", Purpose::Test),
    // ecospy's libecosc.so (Ecos, tests/python/test_ecos.py)
    ("libtbb12", Purpose::Test),
    // the browser the view's tests drive headless (tests/python/test_view.py)
    ("chromium", Purpose::Test),
    ("chromium-driver", Purpose::Test),
];

/// Python packages: (distribution name as pip knows it, requirement to
/// install, the first purpose that needs it). A requirement `NAME==V` is also
/// installed over another version. fmpy is the version the tests are written
/// against; dask and distributed are released together, so one pin holds both
/// (`distributed` is checked: it comes only with the extra).
const PYTHON_PACKAGES: &[(&str, &str, Purpose)] = &[
    ("fmpy", "fmpy==0.3.32", Purpose::Run),
    ("numpy", "numpy", Purpose::Run),
    ("matplotlib", "matplotlib", Purpose::Run),
    ("distributed", "dask[distributed]==2026.8.0", Purpose::Sweep),
    // the live view's server (static files and websockets on one port); its
    // page's three.js and lil-gui come from the npm registry (page_assets)
    ("aiohttp", "aiohttp==3.14.5", Purpose::View),
    ("selenium", "selenium==4.51.0", Purpose::Test),
    ("pytest", "pytest", Purpose::Test),
    ("fmu_manipulation_toolbox", "fmu_manipulation_toolbox==2.0", Purpose::Test),
    ("ecospy", "ecospy==0.7.2", Purpose::Test),
    // the rules it checks change between versions: pinned, like a toolchain
    ("ruff", "ruff==0.17.6", Purpose::Test),
];

pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

/// The cargo running this xtask (falls back to the one on PATH).
pub fn cargo() -> String {
    std::env::var("CARGO").unwrap_or_else(|_| "cargo".into())
}

/// Cargo's target directory: `CARGO_TARGET_DIR` (relative to the workspace
/// root when relative) or `target/`.
pub fn target_dir(root: &Path) -> PathBuf {
    match std::env::var_os("CARGO_TARGET_DIR").map(PathBuf::from) {
        Some(p) if p.is_absolute() => p,
        Some(p) => root.join(p),
        None => root.join("target"),
    }
}

/// The venv's Python interpreter.
pub fn python() -> PathBuf {
    root().join(".venv/bin/python")
}

/// Prints the `--help` of a script of the project's Python, if the venv
/// can run it (the options of the tasks that hand their arguments on).
pub fn python_help(script: &str) {
    let out = Command::new(python()).current_dir(root()).args([script, "--help"]).output();
    if let Some(out) = out.ok().filter(|o| o.status.success()) {
        println!("\n{script}:\n{}", String::from_utf8_lossy(&out.stdout));
    }
}

pub fn main(args: &[String]) -> Result<(), String> {
    let Some(purpose) = cli::options(parse(args), USAGE)? else { return Ok(()) };
    install(purpose)
}

const USAGE: &str = "\
usage: cargo xtask setup [--for run|sweep|view|test]

  --for run    what building the FMU and the main job need
  --for sweep  also parameter sweeps on Dask
  --for view   also the live view in a browser
  --for test   also everything the tests need (the default)";

fn parse(args: &[String]) -> Result<Option<Purpose>, cli::Error> {
    let mut purpose = Purpose::Test;
    let mut p = cli::parser(args);
    while let Some(arg) = p.next()? {
        match arg {
            Long("for") => {
                purpose = match p.value()?.string()?.as_str() {
                    "run" => Purpose::Run,
                    "sweep" => Purpose::Sweep,
                    "view" => Purpose::View,
                    "test" => Purpose::Test,
                    other => return Err(format!("--for {other}: one of run, sweep, view, test").into()),
                }
            }
            arg if cli::is_help(&arg) => return Ok(None),
            arg => return Err(arg.unexpected()),
        }
    }
    Ok(Some(purpose))
}

/// Installs what `purpose` needs and is missing.
pub fn install(purpose: Purpose) -> Result<(), String> {
    debian_packages(purpose)?;
    venv()?;
    python_packages(purpose)?;
    if purpose >= Purpose::View {
        page_assets()?;
    }
    Ok(())
}

/// The live view's page libraries, three.js and lil-gui, from the npm
/// registry into target/view-assets/ (python/viewing/assets.py: pinned
/// versions, each tarball checked against its pinned sha512; nothing done
/// when they are there).
fn page_assets() -> Result<(), String> {
    let status = Command::new(python())
        .current_dir(root())
        .args(["python/viewing/assets.py"])
        .stdout(Stdio::null())
        .status()
        .map_err(|e| format!("cannot run python/viewing/assets.py: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("the live view's page libraries could not be fetched ({status}); see above"))
    }
}

fn wanted<T: Copy>(list: &[(T, Purpose)], purpose: Purpose) -> Vec<T> {
    list.iter().filter(|(_, needed_from)| purpose >= *needed_from).map(|(x, _)| *x).collect()
}

fn debian_installed(pkg: &str) -> bool {
    Command::new("dpkg-query")
        .args(["-W", "-f=${Status}", pkg])
        .stderr(Stdio::null())
        .output()
        .map(|o| o.status.success() && String::from_utf8_lossy(&o.stdout).contains("install ok installed"))
        .unwrap_or(false)
}

fn is_root() -> bool {
    Command::new("id").arg("-u").output().map(|o| String::from_utf8_lossy(&o.stdout).trim() == "0").unwrap_or(false)
}

fn debian_packages(purpose: Purpose) -> Result<(), String> {
    let missing: Vec<&str> = wanted(DEBIAN_PACKAGES, purpose).into_iter().filter(|p| !debian_installed(p)).collect();
    if missing.is_empty() {
        return Ok(());
    }
    if Command::new("apt-get").arg("--version").stdout(Stdio::null()).status().is_err() {
        return Err(format!("missing system packages {} and no apt-get to install them", missing.join(" ")));
    }
    install_debian(&missing)
}

/// `apt-get update` (once per run of the task) and `apt-get install` of `packages`.
fn install_debian(packages: &[&str]) -> Result<(), String> {
    static UPDATED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);
    eprintln!("setup: installing {} with apt-get", packages.join(" "));
    // As root apt-get runs directly; otherwise through sudo (non-interactive).
    let apt = |args: &[&str]| -> Result<(), String> {
        let mut cmd = if is_root() {
            Command::new("apt-get")
        } else {
            let mut c = Command::new("sudo");
            c.args(["-n", "apt-get"]);
            c
        };
        cmd.args(args).env("DEBIAN_FRONTEND", "noninteractive");
        let status = cmd.status().map_err(|e| format!("cannot run apt-get: {e}"))?;
        if status.success() {
            Ok(())
        } else {
            Err(format!("apt-get {} failed ({status})", args.join(" ")))
        }
    };
    if !UPDATED.swap(true, std::sync::atomic::Ordering::SeqCst) {
        apt(&["update", "-q"])?;
    }
    let mut install = vec!["install", "-y", "-q", "--no-install-recommends"];
    install.extend(packages);
    apt(&install)?;
    Ok(())
}

fn venv() -> Result<(), String> {
    let py = python();
    if py.exists() && Command::new(&py).args(["-m", "pip", "--version"]).stdout(Stdio::null()).status().map(|s| s.success()).unwrap_or(false) {
        return Ok(());
    }
    let dir = root().join(".venv");
    eprintln!("setup: creating {}", dir.display());
    let make = || -> Result<bool, String> {
        Command::new("python3")
            .args(["-m", "venv", "--clear"])
            .arg(&dir)
            .status()
            .map(|s| s.success())
            .map_err(|e| format!("cannot run python3 (Python 3 is needed): {e}"))
    };
    if make()? {
        return Ok(());
    }
    // Debian's own python3 keeps venv and ensurepip in the package python3-venv.
    if Command::new("apt-get").arg("--version").stdout(Stdio::null()).status().is_ok() && !debian_installed("python3-venv") {
        install_debian(&["python3-venv"])?;
        if make()? {
            return Ok(());
        }
    }
    Err(format!("python3 -m venv {} failed; on Debian the venv module is in the package python3-venv", dir.display()))
}

/// Installed version of each distribution, as the venv's Python sees it.
fn installed_version(dist: &str) -> Option<String> {
    let code = format!("import importlib.metadata as m\ntry:\n    print(m.version({dist:?}))\nexcept m.PackageNotFoundError:\n    pass\n");
    let out = Command::new(python()).args(["-c", &code]).output().ok()?;
    let v = String::from_utf8_lossy(&out.stdout).trim().to_string();
    (out.status.success() && !v.is_empty()).then_some(v)
}

fn python_packages(purpose: Purpose) -> Result<(), String> {
    pip_install_missing(PYTHON_PACKAGES.iter().filter(|(_, _, needed_from)| purpose >= *needed_from))
}

/// The venv (made when missing) with the packages `dists` of
/// [`PYTHON_PACKAGES`] (installed when missing): what one stage of the tests
/// needs when `--only` leaves the setup out.
pub fn python_tools(dists: &[&str]) -> Result<(), String> {
    venv()?;
    pip_install_missing(PYTHON_PACKAGES.iter().filter(|(dist, _, _)| dists.contains(dist)))
}

/// `pip install` of those of `packages` that are missing or at another
/// version than their pin.
fn pip_install_missing<'a>(packages: impl Iterator<Item = &'a (&'a str, &'a str, Purpose)>) -> Result<(), String> {
    let mut missing = Vec::new();
    for (dist, req, _) in packages {
        let pinned = req.split_once("==").map(|(_, v)| v);
        match installed_version(dist) {
            Some(v) if pinned.is_none_or(|p| v == p) => {}
            _ => missing.push(*req),
        }
    }
    if missing.is_empty() {
        return Ok(());
    }
    eprintln!("setup: pip install {}", missing.join(" "));
    let status = Command::new(python())
        .args(["-m", "pip", "install", "--disable-pip-version-check", "-q"])
        .args(&missing)
        .status()
        .map_err(|e| format!("cannot run pip: {e}"))?;
    if !status.success() {
        return Err(format!("pip install {} failed", missing.join(" ")));
    }
    Ok(())
}
