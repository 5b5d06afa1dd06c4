//! The trajectory error E (docs/method.md, section 6) and the largest node
//! distance error of a run against a reference, both read from CSV files,
//! computed by `modal_mass_spring::measures`: what another implementation
//! checks itself against.
//!
//! cargo run --release --example trajectory_error -- RUN.csv REFERENCE.csv --start X0.csv --dim D [--masses M.csv]
//!
//! RUN and REFERENCE have one row per output time, the flattened node
//! positions (D per node), comma-separated, no header and no time column;
//! X0 is one row, x(0); M one row, one mass per node (equal masses when
//! left out). Prints one line of JSON, `{"E": .., "max_node_error": ..,
//! "E_by_window": [..]}` (E over the first 1, 2, ... output times), each
//! number with 17 significant digits.

use std::path::PathBuf;

use modal_mass_spring::measures::{max_node_error, trajectory_error, trajectory_errors_by_window, Masses};

struct Args {
    run: PathBuf,
    reference: PathBuf,
    start: PathBuf,
    dim: usize,
    masses: Option<PathBuf>,
}

const USAGE: &str = "usage: trajectory_error RUN.csv REFERENCE.csv --start X0.csv --dim D [--masses M.csv]";

fn parse_args() -> Result<Args, lexopt::Error> {
    use lexopt::prelude::*;
    let (mut files, mut start, mut dim, mut masses) = (Vec::new(), None, None, None);
    let mut parser = lexopt::Parser::from_env();
    while let Some(arg) = parser.next()? {
        match arg {
            Long("start") => start = Some(PathBuf::from(parser.value()?)),
            Long("dim") => dim = Some(parser.value()?.parse()?),
            Long("masses") => masses = Some(PathBuf::from(parser.value()?)),
            Value(v) if files.len() < 2 => files.push(PathBuf::from(v)),
            _ => return Err(arg.unexpected()),
        }
    }
    let [run, reference]: [PathBuf; 2] = files.try_into().map_err(|_| lexopt::Error::from("RUN.csv and REFERENCE.csv are both needed"))?;
    let start = start.ok_or("--start X0.csv is needed")?;
    let dim = dim.ok_or("--dim D is needed")?;
    if dim == 0 {
        return Err("--dim must be at least 1".into());
    }
    Ok(Args { run, reference, start, dim, masses })
}

/// The rows of a headerless CSV file of numbers.
fn read_rows(path: &PathBuf) -> Result<Vec<Vec<f64>>, String> {
    let context = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    let mut reader = csv::ReaderBuilder::new().has_headers(false).trim(csv::Trim::All).from_path(path).map_err(|e| context(&e))?;
    reader.records().map(|record| record.map_err(|e| context(&e))?.iter().map(|field| field.parse::<f64>().map_err(|e| context(&e))).collect()).collect()
}

/// The single row of a CSV file.
fn read_row(path: &PathBuf) -> Result<Vec<f64>, String> {
    match <[Vec<f64>; 1]>::try_from(read_rows(path)?) {
        Ok([row]) => Ok(row),
        Err(rows) => Err(format!("{}: one row expected, {} found", path.display(), rows.len())),
    }
}

fn measure(args: &Args) -> Result<(f64, f64, Vec<f64>), String> {
    let run = read_rows(&args.run)?;
    let reference = read_rows(&args.reference)?;
    let start = read_row(&args.start)?;
    let masses = args.masses.as_ref().map(read_row).transpose()?;
    if run.len() != reference.len() {
        return Err(format!("{} output times in the run, {} in the reference", run.len(), reference.len()));
    }
    let n = start.len();
    if n % args.dim != 0 {
        return Err(format!("x(0) has {n} coordinates, not a multiple of --dim {}", args.dim));
    }
    if let Some(row) = run.iter().chain(&reference).find(|row| row.len() != n) {
        return Err(format!("a row of {} coordinates, where x(0) has {n}", row.len()));
    }
    let masses = match &masses {
        Some(m) if m.len() != n / args.dim => return Err(format!("{} masses for {} nodes", m.len(), n / args.dim)),
        Some(m) => Masses::PerNode { masses: m, dim: args.dim },
        None => Masses::Equal,
    };
    Ok((
        trajectory_error(&run, &reference, &start, masses),
        max_node_error(&run, &reference, args.dim),
        trajectory_errors_by_window(&run, &reference, &start, masses),
    ))
}

/// `{:e}`: the shortest digits that parse back to the same f64 (at most 17
/// significant ones); NaN and the infinities as Python's json module writes them.
fn json_number(x: f64) -> String {
    match x {
        x if x.is_nan() => "NaN".into(),
        f64::INFINITY => "Infinity".into(),
        f64::NEG_INFINITY => "-Infinity".into(),
        x => format!("{x:e}"),
    }
}

fn main() {
    let args = parse_args().unwrap_or_else(|e| {
        eprintln!("trajectory_error: {e}\n{USAGE}");
        std::process::exit(2)
    });
    match measure(&args) {
        Ok((e, max_node, windows)) => {
            let windows: Vec<String> = windows.into_iter().map(json_number).collect();
            println!("{{\"E\": {}, \"max_node_error\": {}, \"E_by_window\": [{}]}}", json_number(e), json_number(max_node), windows.join(", "))
        }
        Err(e) => {
            eprintln!("trajectory_error: {e}");
            std::process::exit(1)
        }
    }
}
