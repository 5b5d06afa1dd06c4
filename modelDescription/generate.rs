//! Generator of everything derived from `variables.toml`, the one table of
//! the FMU's variables. Shared by `build.rs` (the Rust variable table and
//! enumerations), `cargo xtask fmu` (documentation/index.html,
//! resources/startValues.txt), `cargo xtask docs` (docs/variables.md's tables) and
//! `tests/fmi_model_description.rs`, all through this file, so the XML and
//! the value references of the binary cannot drift.
//!
//! One module per job: [`spec`] parses and checks the table, each other
//! module emits one file from a [`Spec`]. modelDescription.xml is written
//! by `generate/xml.rs` with the `fmi-schema` crate; the build script does
//! not have that crate, so the includers that write the XML (the xtask and
//! the test) include that file beside this one, as a module of their own.
//!
//! Needs the `serde` (derive) and `toml` crates in the including crate.

#![allow(dead_code)]

#[path = "generate/spec.rs"]
mod spec;
pub use spec::*;

#[path = "generate/html.rs"]
mod html;
#[path = "generate/readme.rs"]
mod readme;
// Not every includer writes the README.
#[allow(unused_imports)]
pub use readme::{README_BEGIN, README_END};
#[path = "generate/rust.rs"]
mod rust;
#[path = "generate/start_values.rs"]
mod start_values;
