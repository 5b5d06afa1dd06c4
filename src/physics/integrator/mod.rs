//! Time integration of M y'' + C y' = h(y) (`docs/method.md`, section 4),
//! written once against [`Space`]: every scheme works in every space.
//!
//! A scheme advances the [`State`] by one internal step dt; the simulator
//! splits communication steps into internal steps no longer than the
//! scheme's [`Scheme::stable_step`] and the internal step bound.

mod newmark_explicit;
mod newmark_implicit;

pub use newmark_explicit::NewmarkExplicit;
pub use newmark_implicit::NewmarkImplicit;

use super::engine::{Engine, Stepper};
use super::error::StepFailure;
use super::space::Space;
use super::state::{Loads, State};
pub use crate::options::Integrator;

/// Explicit steps are kept at this fraction of the stability limit 2 / omega.
pub const EXPLICIT_SAFETY: f64 = 0.9;

/// One integration scheme.
pub trait Scheme: Send + 'static {
    /// Longest internal step the scheme stays stable at, when the squared
    /// frequencies of the integrated system stay below `omega_sq_max`;
    /// `None` when stability sets no limit.
    fn stable_step(omega_sq_max: f64) -> Option<f64>;

    /// Advances `state` (not its time) by `dt`. On error `state` may hold
    /// anything; the caller restores its backup.
    fn step<S: Space>(space: &S, w: &mut S::Work, buf: &mut Buffers, loads: &Loads, state: &mut State, dt: f64) -> Result<(), StepFailure>;
}

/// Vectors of the generalized coordinates' length that a step works in.
pub struct Buffers {
    /// y at the end of the step (prediction, Newton iterate).
    pub y1: Vec<f64>,
    pub v1: Vec<f64>,
    pub a1: Vec<f64>,
    /// h(y1).
    pub h: Vec<f64>,
    /// Newton residual and update.
    pub r: Vec<f64>,
}

impl Buffers {
    pub fn new(n: usize) -> Self {
        Buffers { y1: vec![0.0; n], v1: vec![0.0; n], a1: vec![0.0; n], h: vec![0.0; n], r: vec![0.0; n] }
    }
}

/// The registry of schemes: binds `space` to the scheme `kind` names.
pub(crate) fn bind<S: Space>(space: S, kind: Integrator) -> Box<dyn Stepper> {
    match kind {
        Integrator::NewmarkExplicit => Box::new(Engine::<S, NewmarkExplicit>::new(space)),
        Integrator::NewmarkImplicit => Box::new(Engine::<S, NewmarkImplicit>::new(space)),
    }
}

/// Newmark predictor y1 = y + dt v + dt^2/2 a (exact for the explicit
/// scheme, the starting guess of the implicit one).
#[inline]
pub fn predict(y: &[f64], v: &[f64], a: &[f64], dt: f64, out: &mut [f64]) {
    let half_dt2 = 0.5 * dt * dt;
    for i in 0..out.len() {
        out[i] = y[i] + dt * v[i] + half_dt2 * a[i];
    }
}
