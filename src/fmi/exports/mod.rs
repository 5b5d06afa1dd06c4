//! The `fmi3*` C ABI: one short entry per function of the FMI 3.0 API.
//!
//! Each entry names its row of [`super::functions`]'s table and hands the
//! call to [`super::guard::call`], which refuses a null, freed or foreign instance, checks
//! the state against the table (the one guard, `Instance::guard`), catches
//! any panic instead of unwinding into the importer, and runs the body on
//! the instance. Functions this FMU does not provide are refused with the
//! table's reason ([`super::guard::refuse`]). Every signature is checked at compile time
//! against the `fmi3...TYPE` alias of the official headers (the `const _`
//! after it), and cbindgen writes the C header from this module and its
//! children, which hold the entries by the standard's groups, in its order.

#![allow(clippy::missing_safety_doc, clippy::too_many_arguments)]

// The groups in the standard's order, which cbindgen keeps in the C header
// (the blank lines keep rustfmt from sorting them).
mod life_cycle;

mod get_set;

mod state_and_clocks;

mod interfaces;

pub use get_set::*;
pub use interfaces::*;
pub use life_cycle::*;
pub use state_and_clocks::*;
