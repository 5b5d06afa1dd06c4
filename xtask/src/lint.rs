//! The `lint` stage of `cargo xtask test`: ruff over every Python file of the
//! repository (the rules in `ruff.toml`), and no Python file over
//! [`MAX_PYTHON_LINES`] lines.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::setup;

/// The longest a Python file may be.
pub const MAX_PYTHON_LINES: usize = 600;

/// Directories that hold no source of the project: build output, the venv,
/// run output, caches.
const SKIPPED_DIRS: [&str; 4] = ["target", "out", "__pycache__", "node_modules"];

/// Runs both checks (ruff installed first when missing); the error lists
/// what failed.
pub fn run(root: &Path) -> Result<(), String> {
    setup::python_tools(&["ruff"])?;
    let mut failures = Vec::new();
    let status = Command::new(setup::python())
        .current_dir(root)
        .args(["-m", "ruff", "check", "--no-cache", "--config", "ruff.toml", "."])
        .status()
        .map_err(|e| format!("cannot run ruff: {e}"))?;
    if !status.success() {
        failures.push(format!("ruff check found problems ({status}; `.venv/bin/ruff check --fix` fixes some)"));
    }
    let long = long_python_files(root)?;
    if !long.is_empty() {
        let list: Vec<String> = long.iter().map(|(p, n)| format!("{} ({n} lines)", p.display())).collect();
        eprintln!("Python files over {MAX_PYTHON_LINES} lines:\n  {}", list.join("\n  "));
        failures.push(format!("Python files over {MAX_PYTHON_LINES} lines: {}", list.join(", ")));
    } else {
        eprintln!("every Python file is at most {MAX_PYTHON_LINES} lines");
    }
    if failures.is_empty() {
        Ok(())
    } else {
        Err(failures.join("; "))
    }
}

/// Every `.py` file under `root` (hidden directories and [`SKIPPED_DIRS`]
/// left out) longer than [`MAX_PYTHON_LINES`], relative to `root`, with its
/// number of lines.
pub fn long_python_files(root: &Path) -> Result<Vec<(PathBuf, usize)>, String> {
    let mut long = Vec::new();
    let mut dirs = vec![root.to_path_buf()];
    while let Some(dir) = dirs.pop() {
        let entries = std::fs::read_dir(&dir).map_err(|e| format!("cannot list {}: {e}", dir.display()))?;
        for entry in entries {
            let path = entry.map_err(|e| e.to_string())?.path();
            let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            if path.is_dir() {
                if !name.starts_with('.') && !SKIPPED_DIRS.contains(&name.as_str()) {
                    dirs.push(path);
                }
            } else if name.ends_with(".py") {
                let text = std::fs::read_to_string(&path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
                let lines = text.lines().count();
                if lines > MAX_PYTHON_LINES {
                    long.push((path.strip_prefix(root).unwrap_or(&path).to_path_buf(), lines));
                }
            }
        }
    }
    long.sort();
    Ok(long)
}
