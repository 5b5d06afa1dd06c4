//! Project tasks: `cargo xtask TASK [OPTIONS]`. The tasks are listed in
//! [`TASKS`] (`cargo xtask --help`), each with its options
//! (`cargo xtask TASK --help`, parsed in `cli.rs` style with lexopt).

#[path = "../../modelDescription/generate.rs"]
mod generate;
// Spec::model_description_xml, written with fmi-schema.
#[path = "../../modelDescription/generate/xml.rs"]
mod model_description_xml;
// Spec::terminals_and_icons_xml, written with fmi-schema.
#[path = "../../modelDescription/generate/terminals.rs"]
mod terminals;

mod cli;
mod docs;
mod fmu;
mod fmusim;
mod fuzz;
mod lint;
mod modes;
mod report;
mod run;
mod setup;
mod ssp;
mod stability;
mod sweep;
mod valgrind;

use std::process::ExitCode;

use cli::{Value, ValueExt};

/// Every task: its name, its entry point and what it does (`cargo xtask --help`).
type Task = fn(&[String]) -> Result<(), String>;
const TASKS: [(&str, Task, &str); 15] = [
    ("fmu", fmu::main, "build the release library and package target/fmu/ModalMassSpring.fmu"),
    ("run", run::run, "build the FMU and run the main job through fmpy (summary + plot)"),
    ("test", run::test, "every test: Rust (cargo test) and Python (pytest + fmpy); --only STAGE,... for some"),
    ("report", report::main, "the error-against-run-time study into report/ (--quick: small, for CI)"),
    ("sweep", sweep::main, "a parameter sweep of FMU runs on Dask (python/sweep.py)"),
    ("setup", setup::main, "install what the other tasks need (libclang, valgrind, Python venv with fmpy)"),
    ("fmusim", fmusim::main, "build the reference FMI importer fmusim into target/tools/fmusim"),
    ("fuzz", fuzz::main, "the cargo-fuzz targets for a bounded time (--seconds N)"),
    ("valgrind", valgrind::main, "leak check of instantiate/step/serialize/free cycles"),
    ("stability", stability::main, "the stability matrix, its table written into docs/stability.md"),
    ("control", run::control, "the paper's control experiments (Figs. 7-9, a GIF) and control in 3D, through the FMU, into target/control"),
    ("modes", modes::main, "the mode gallery of a scene: shapes, frequencies and classes into target/modes (PNG, Markdown)"),
    ("docs", docs::main, "the variable tables of docs/variables.md, from modelDescription/variables.toml"),
    ("view", run::view, "the sheet live in a browser: one FMU instance per page, steered from the page (python/view.py)"),
    ("ssp", ssp::main, "the two-sheet chain of python/chain.py as an SSP 1.0 archive, target/ssp/chain.ssp"),
];

fn usage() -> String {
    let mut u = String::from("usage: cargo xtask TASK [OPTIONS]   (cargo xtask TASK --help: its options)\n\ntasks:\n");
    for (name, _, what) in TASKS {
        u.push_str(&format!("  {name:<10} {what}\n"));
    }
    u
}

/// The task and its arguments; `None` when the usage was asked for.
fn parse() -> Result<Option<(String, Vec<String>)>, cli::Error> {
    let mut p = lexopt::Parser::from_env();
    match p.next()? {
        Some(Value(task)) => Ok(Some((task.string()?, cli::rest(&mut p)?))),
        None => Err("no task given".into()),
        Some(arg) if cli::is_help(&arg) => Ok(None),
        Some(arg) => Err(arg.unexpected()),
    }
}

fn main() -> ExitCode {
    let (name, args) = match cli::options(parse(), &usage()) {
        Ok(Some(task)) => task,
        Ok(None) => return ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask: {e}");
            return ExitCode::from(2);
        }
    };
    let Some((_, task, _)) = TASKS.iter().find(|(n, _, _)| *n == name) else {
        eprintln!("xtask: unknown task {name}\n\n{}", usage());
        return ExitCode::from(2);
    };
    match task(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask {name}: {e}");
            ExitCode::FAILURE
        }
    }
}
