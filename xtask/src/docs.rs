//! `cargo xtask docs`: writes docs/variables.md's tables of the variables, the
//! enumerations and the canonical scenes from modelDescription/variables.toml,
//! between the markers `tests/fmi_model_description.rs` checks.

use crate::cli;
use crate::generate::{self, README_BEGIN, README_END};

const USAGE: &str = "usage: cargo xtask docs (no options)";

pub fn main(args: &[String]) -> Result<(), String> {
    if cli::options(cli::no_arguments(args), USAGE)?.is_none() {
        return Ok(());
    }
    let root = crate::setup::root();
    let spec = generate::load(&root.join("modelDescription/variables.toml"))?;
    let path = root.join("docs/variables.md");
    let readme = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let (head, rest) = readme.split_once(README_BEGIN).ok_or(format!("docs/variables.md has no line {README_BEGIN}"))?;
    let (_, tail) = rest.split_once(README_END).ok_or(format!("docs/variables.md has no line {README_END}"))?;
    let new = format!("{head}{README_BEGIN}\n{}{README_END}{tail}", spec.readme_tables());
    if new != readme {
        std::fs::write(&path, new).map_err(|e| format!("{}: {e}", path.display()))?;
        println!("docs/variables.md: variable tables written");
    } else {
        println!("docs/variables.md: variable tables up to date");
    }
    Ok(())
}
