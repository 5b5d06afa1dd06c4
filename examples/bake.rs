//! Bakes the set-up of an FMU's start values (used by `cargo xtask fmu --bake`).
//!
//! cargo run --release --example bake -- resources/startValues.txt resources/setup.bin

use std::time::Instant;

use modal_mass_spring::model::{bake, Params};

/// The two paths of the command line.
fn parse_args() -> Result<(String, String), lexopt::Error> {
    use lexopt::prelude::*;
    let mut paths = Vec::new();
    let mut parser = lexopt::Parser::from_env();
    while let Some(arg) = parser.next()? {
        match arg {
            Value(v) if paths.len() < 2 => paths.push(v.string()?),
            _ => return Err(arg.unexpected()),
        }
    }
    let [start, out]: [String; 2] = paths.try_into().map_err(|_| "START_VALUES_TXT and OUT_BIN are both needed")?;
    Ok((start, out))
}

fn main() {
    let (start, out) = &parse_args().unwrap_or_else(|e| {
        eprintln!("bake: {e}\nusage: bake START_VALUES_TXT OUT_BIN");
        std::process::exit(2)
    });
    let text = std::fs::read_to_string(start).unwrap_or_else(|e| panic!("{start}: {e}"));
    let params = Params::from_text(&text).unwrap_or_else(|e| panic!("{start}: {e}"));
    let t = Instant::now();
    let sim = params.build().unwrap_or_else(|e| panic!("set-up failed: {e}"));
    let computed = t.elapsed().as_secs_f64();
    match bake::write(&params, &sim) {
        Some(bytes) => {
            std::fs::write(out, &bytes).unwrap_or_else(|e| panic!("{out}: {e}"));
            let t = Instant::now();
            let data = bake::read(&bytes, &params).expect("a bake reads back");
            let _ = params.build_with(Some(&data)).expect("a bake sets up");
            println!(
                "bake: set-up computed in {computed:.3} s, from the bake in {:.3} s; {} ({} bytes, {} springs per force evaluation)",
                t.elapsed().as_secs_f64(),
                out,
                bytes.len(),
                sim.cubature_springs()
            );
        }
        None => println!("bake: full space has no costly set-up to bake; {out} not written"),
    }
}
