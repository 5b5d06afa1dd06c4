//! `cargo xtask fmusim [--force]`: builds `target/tools/fmusim`, the
//! reference FMI importer of the Modelica Association's Reference-FMUs
//! (v0.0.39, vendored in `third_party/fmusim-0.0.39`), with gcc against
//! Debian's libraries (`cargo xtask setup` installs them: libsundials-dev,
//! libminizip-dev, zlib1g-dev, libxml2-dev).
//!
//! Each C file is compiled on its own (one at a time, a line per file), then
//! the objects are linked; no CMake and no download. `SUN_COMM_NULL` is
//! defined for Debian's SUNDIALS 6, whose headers lack it. Nothing is done
//! when the binary is newer than every file of the source tree.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::SystemTime;

use crate::cli::{self, Long};
use crate::setup::target_dir;

/// The vendored source tree, relative to the repository root.
pub const SOURCE_DIR: &str = "third_party/fmusim-0.0.39";

const VERSION: &str = "0.0.39";

/// Compiler flags of every translation unit (include paths relative to the source tree).
const CFLAGS: &[&str] = &["-O2", "-w", "-DSUN_COMM_NULL=NULL", "-Ifmusim", "-Iinclude", "-I/usr/include/libxml2", "-I/usr/include/minizip"];

/// Libraries linked in, in link order.
const LIBS: &[&str] =
    &["-lxml2", "-lminizip", "-lz", "-lsundials_cvode", "-lsundials_nvecserial", "-lsundials_sunmatrixdense", "-lsundials_sunlinsoldense", "-ldl", "-lm"];

/// The files of `src/` fmusim uses besides every C file of `fmusim/`.
const SHARED_SOURCES: &[&str] =
    &["src/FMI.c", "src/FMI1.c", "src/FMI2.c", "src/FMI3.c", "src/structured_variable_name.yy.c", "src/structured_variable_name.tab.c"];

/// Where the binary goes: `<target>/tools/fmusim`.
pub fn binary(root: &Path) -> PathBuf {
    target_dir(root).join("tools/fmusim")
}

pub fn main(args: &[String]) -> Result<(), String> {
    let Some(force) = cli::options(parse(args), USAGE)? else { return Ok(()) };
    let path = build(&crate::setup::root(), force)?;
    println!("{}", path.display());
    Ok(())
}

const USAGE: &str = "\
usage: cargo xtask fmusim [--force]

  --force  build again even if the binary is newer than its sources";

/// Whether to force the build.
fn parse(args: &[String]) -> Result<Option<bool>, cli::Error> {
    let mut force = false;
    let mut p = cli::parser(args);
    while let Some(arg) = p.next()? {
        match arg {
            Long("force") => force = true,
            arg if cli::is_help(&arg) => return Ok(None),
            arg => return Err(arg.unexpected()),
        }
    }
    Ok(Some(force))
}

/// The C files to compile, relative to the source tree, sorted.
fn sources(src: &Path) -> Result<Vec<PathBuf>, String> {
    let dir = src.join("fmusim");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "c"))
        .map(|p| p.strip_prefix(src).unwrap().to_path_buf())
        .collect();
    files.sort();
    files.extend(SHARED_SOURCES.iter().map(PathBuf::from));
    Ok(files)
}

/// The latest modification time of any file under `dir`.
fn newest(dir: &Path) -> Result<SystemTime, String> {
    let mut latest = SystemTime::UNIX_EPOCH;
    for entry in std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?.flatten() {
        let meta = entry.metadata().map_err(|e| format!("{}: {e}", entry.path().display()))?;
        let t = if meta.is_dir() { newest(&entry.path())? } else { meta.modified().map_err(|e| e.to_string())? };
        latest = latest.max(t);
    }
    Ok(latest)
}

fn run(cmd: &mut Command, what: &str) -> Result<(), String> {
    let status = cmd.status().map_err(|e| format!("cannot run gcc ({what}): {e}; `cargo xtask setup` installs it"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("{what} failed ({status}); its libraries come with `cargo xtask setup`"))
    }
}

/// Builds the binary unless it is newer than every source file (or `force`);
/// returns its path.
pub fn build(root: &Path, force: bool) -> Result<PathBuf, String> {
    let src = root.join(SOURCE_DIR);
    let out = binary(root);
    let sources_time = newest(&src)?;
    let up_to_date = std::fs::metadata(&out).and_then(|m| m.modified()).is_ok_and(|t| t > sources_time);
    if up_to_date && !force {
        eprintln!("fmusim: {} is up to date", out.display());
        return Ok(out);
    }
    let files = sources(&src)?;
    let objects_dir = target_dir(root).join("tools/fmusim-objects");
    std::fs::create_dir_all(&objects_dir).map_err(|e| format!("{}: {e}", objects_dir.display()))?;
    let version = format!("-DFMUSIM_VERSION=\"{VERSION}\"");
    let mut objects = Vec::new();
    for (i, file) in files.iter().enumerate() {
        eprintln!("fmusim: [{}/{}] gcc -c {}", i + 1, files.len(), file.display());
        // fmusim/X.c -> fmusim_X.o, src/X.c -> src_X.o
        let object = objects_dir.join(file.with_extension("o").to_string_lossy().replace('/', "_"));
        run(
            Command::new("gcc").current_dir(&src).args(CFLAGS).arg(&version).arg("-c").arg(file).arg("-o").arg(&object),
            &format!("gcc -c {}", file.display()),
        )?;
        objects.push(object);
    }
    eprintln!("fmusim: [link] {}", out.display());
    // Linked next to the target and renamed, so a reader never sees half a binary.
    let tmp = out.with_extension("part");
    run(Command::new("gcc").arg("-o").arg(&tmp).args(&objects).args(LIBS), "linking fmusim")?;
    std::fs::rename(&tmp, &out).map_err(|e| format!("{}: {e}", out.display()))?;
    Ok(out)
}
