//! Argument parsing shared by every task, with lexopt: each task lists its
//! options in a usage text, `-h`/`--help` prints it, and an unknown option
//! or a bad value is an error that shows it.

use std::ffi::OsString;

pub use lexopt::prelude::*;
pub use lexopt::{Arg, Error};

/// A parser over a task's arguments (those after the task's name).
pub fn parser(args: &[String]) -> lexopt::Parser {
    lexopt::Parser::from_args(args.iter().cloned())
}

/// The outcome of a task's parser: its options, `Ok(None)` when it met
/// `-h`/`--help` (the usage is then printed and the task has nothing to do),
/// an error with the usage appended.
pub fn options<T>(parsed: Result<Option<T>, Error>, usage: &str) -> Result<Option<T>, String> {
    match parsed {
        Ok(Some(o)) => Ok(Some(o)),
        Ok(None) => {
            println!("{usage}");
            Ok(None)
        }
        Err(e) => Err(format!("{e}\n\n{usage}")),
    }
}

/// Whether `arg` asks for the usage.
pub fn is_help(arg: &Arg) -> bool {
    matches!(arg, Short('h') | Long("help"))
}

/// The next argument as given, not consumed (`None` at the end, or inside
/// a group of short options).
pub fn peek(p: &mut lexopt::Parser) -> Option<String> {
    p.try_raw_args()?.peek().map(|a| a.to_string_lossy().into_owned())
}

/// Every argument left, as given, for another program; a leading `--` is dropped.
pub fn rest(p: &mut lexopt::Parser) -> Result<Vec<String>, Error> {
    let mut raw = p.raw_args()?;
    if raw.peek().is_some_and(|a| a == "--") {
        raw.next();
    }
    raw.map(|a: OsString| a.into_string().map_err(Error::NonUnicodeValue)).collect()
}

/// Arguments handed on whole to another program (`run`, `sweep`): `None`
/// when the first is `-h`/`--help`, which the task answers itself
/// (`cargo xtask TASK -- --help` hands it on).
pub fn pass_through(args: &[String]) -> Result<Option<Vec<String>>, Error> {
    let mut p = parser(args);
    if peek(&mut p).is_some_and(|a| a == "-h" || a == "--help") {
        return Ok(None);
    }
    rest(&mut p).map(Some)
}

/// Ends a parser that takes no argument.
pub fn no_arguments(args: &[String]) -> Result<Option<()>, Error> {
    let mut p = parser(args);
    match p.next()? {
        None => Ok(Some(())),
        Some(arg) if is_help(&arg) => Ok(None),
        Some(arg) => Err(arg.unexpected()),
    }
}
