//! Where the equations of motion live (`docs/method.md`, sections 3 and 4).
//!
//! Every space integrates
//!
//! ```text
//!     M y'' + C y' = h(y)
//! ```
//!
//! in its own generalized coordinates y (f_p: the point load on its node,
//! `docs/method.md`, section 8):
//!
//! | space | y | M | C | h(y) |
//! |---|---|---|---|---|
//! | [`Modal`] | modal coordinates q, x = x* + Phi q | I | diag(alpha + beta lambda_i) | w_i (Phi^T (f(x) + M g + f_p))_i + (w_i - 1) lambda_i q_i |
//! | [`Full`] | displacements u of the free DOFs, x = x* + u | lumped masses | alpha M + beta K0 | f(x) + M g + f_p |
//!
//! A space value is the constant model of its equations, fixed after
//! set-up: the scene, the spring incidence, the basis or the sparsity and
//! symbolic factorization. [`Space::Work`] is everything one run writes: the
//! load terms derived from the current [`Loads`] and the scratch of force
//! evaluations and factorizations, allocated once by [`Space::work`] so
//! that stepping allocates nothing. The integrators
//! ([`crate::physics::run::integrator`]) are written once against this trait.

mod equations;
mod full;
mod modal;

pub use equations::{Constants, Diagonal, Layout, Readout, Space};
pub use full::Full;
pub use modal::{basis_bound, Candidate, Cubature, Exact, ForceSetup, Modal, Modes, ReducedForce};
