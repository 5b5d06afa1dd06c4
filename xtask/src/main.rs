//! Project tasks: `cargo xtask <task>`.
//!
//! - `fmu`    build the release library and package `target/fmu/ModalMassSpring.fmu`
//! - `run`    build the FMU and run the main job through fmpy (summary + plot)
//! - `test`   every test: Rust (cargo test) and Python (pytest + fmpy)
//! - `report` the error-against-run-time study into `report/` (`--quick`: small, for CI)
//! - `sweep`  a parameter sweep of FMU runs on Dask (python/sweep.py): CSV and plot in `out/sweep/`
//! - `setup`  install what the other tasks need (libclang, valgrind, Python venv with fmpy)
//! - `fmusim` build the reference FMI importer fmusim into `target/tools/fmusim`
//! - `fuzz`   the cargo-fuzz targets for a bounded time (`--seconds N`)
//! - `valgrind` leak check of instantiate/step/serialize/free cycles
//! - `stability` the stability matrix, its table written into docs/stability.md
//! - `docs`   the variable tables of the README, from modelDescription/variables.toml

#[path = "../../modelDescription/generate.rs"]
mod generate;
// Spec::model_description_xml, written with fmi-schema.
#[path = "../../modelDescription/generate/xml.rs"]
mod model_description_xml;

mod docs;
mod fmu;
mod fmusim;
mod fuzz;
mod report;
mod run;
mod setup;
mod stability;
mod sweep;
mod valgrind;

use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (task, rest) = match args.split_first() {
        Some((t, r)) => (t.as_str(), r),
        None => ("help", &[][..]),
    };
    let result = match task {
        "fmu" => fmu::main(rest),
        "run" => run::run(rest),
        "test" => run::test(rest),
        "report" => report::main(rest),
        "setup" => setup::main(rest),
        "fmusim" => fmusim::main(rest),
        "fuzz" => fuzz::main(rest),
        "valgrind" => valgrind::main(rest),
        "stability" => stability::main(rest),
        "sweep" => sweep::main(rest),
        "docs" => docs::main(rest),
        _ => {
            eprintln!("usage: cargo xtask <fmu|run|test|report|sweep|setup|fmusim|fuzz|valgrind|stability|docs> [options]");
            return ExitCode::from(2);
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask {task}: {e}");
            ExitCode::FAILURE
        }
    }
}
