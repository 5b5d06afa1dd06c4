//! Time integration of M y'' + C y' = h(y) (`docs/method.md`, section 4),
//! written once against [`crate::physics::run::space::Space`]: every scheme works in every space.
//!
//! A scheme advances the [`crate::physics::run::state::State`] by one internal step dt; the simulator
//! splits communication steps into internal steps no longer than the
//! scheme's [`Scheme::stable_step`] and the internal step bound.

mod newmark_explicit;
mod newmark_implicit;
mod scheme;
mod trigonometric;

pub use newmark_explicit::NewmarkExplicit;
pub use newmark_implicit::NewmarkImplicit;
pub use scheme::{predict, Buffers, Scheme, EXPLICIT_SAFETY};
pub use trigonometric::{Propagator, Trigonometric};
