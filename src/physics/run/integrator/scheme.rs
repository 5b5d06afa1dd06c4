//! What a scheme is: the [`Scheme`] trait every integrator implements
//! against [`Space`], the step's scratch vectors and the Newmark predictor
//! the Newmark schemes share.

use crate::physics::error::{PhysicsError, StepFailure};
use crate::physics::run::space::Space;
use crate::physics::run::state::State;

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
    fn step<S: Space>(space: &S, w: &mut S::Work, buf: &mut Buffers, state: &mut State, dt: f64) -> Result<(), StepFailure>;

    /// Values per coordinate the scheme keeps in [`Buffers::scheme`].
    const SCRATCH: usize = 0;

    /// The scheme's frequency error on a linear oscillator: its discrete
    /// frequency is ω (1 ± c (ω h)²) to leading order, and this is c. For
    /// Newmark with γ = 1/2 the three-level form reads
    /// Δ²y = h² (a_n + β Δ²a_n), against Δ²y = h² (a_n + h² a''/12) of the
    /// exact motion, so c = |1/12 − β| / 2: 1/24 for β = 0, 1/12 for β = 1/4.
    /// A mode j then drifts in phase by c ω_j³ h² t, a displacement error
    /// of c h² t ω_j² y'_j, which over every mode is e(t) ≈ c h² t |j(t)| with j = y⃛ the jerk
    /// (the step error an adaptive run adds to its estimate). 0 where the
    /// scheme is exact on the linear part (the trigonometric one).
    const FREQUENCY_ERROR: f64;

    /// The scheme integrates forces that depend on the rates other than
    /// through the damping, as the Coriolis force of a turning holder does.
    const TURNS: bool = true;

    /// Refuses, at set-up, a space the scheme cannot integrate.
    fn check<S: Space>(_space: &S, _w: &S::Work) -> Result<(), PhysicsError> {
        Ok(())
    }

    /// Makes `state.a` what the scheme's next step expects of a state with
    /// coordinates `state.y` and rates `state.v` under the loads of `w` (at the start,
    /// after a change of loads), and leaves the forces of `w` evaluated at
    /// `state.y`. Newmark: the acceleration, M a = h(y) - C v.
    fn settle<S: Space>(space: &S, w: &mut S::Work, buf: &mut Buffers, state: &mut State) {
        space.force(&state.y, w, &mut buf.h);
        space.acceleration(&state.v, &buf.h, w, &mut state.a);
    }

    /// The same after a change of the rates alone (the anchor's kick,
    /// `docs/method.md`, section 8), with the forces of `w` evaluated at `state.y`.
    fn settle_rates<S: Space>(space: &S, w: &mut S::Work, buf: &mut Buffers, state: &mut State) {
        Self::settle(space, w, buf, state);
    }

    /// The acceleration y'' of the motion the scheme integrates, at
    /// `state`, into `out`, with the forces of `w` evaluated at `state.y`
    /// (the holder's force and torque follow from it, `docs/method.md`,
    /// section 8). Newmark keeps it in `state.a`.
    fn acceleration<S: Space>(_space: &S, _w: &mut S::Work, _buf: &mut Buffers, state: &State, out: &mut [f64]) {
        out.copy_from_slice(&state.a);
    }

    /// The last force evaluation of a step is at the new coordinates, where
    /// the outputs read the forces (Newmark). Otherwise (the trigonometric
    /// scheme, whose last evaluation is at the filtered coordinates in
    /// `Buffers::a1`) the forces at the state are evaluated only when an
    /// output needs them, and the step guard weighs the potential energy at
    /// the coordinates of that last evaluation.
    const ENDS_AT_STATE: bool = true;
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
    /// The step size for which `state.a` holds what a scheme keeps there
    /// when that depends on the step size (the trigonometric scheme's
    /// filtered force); NaN when unknown, as after a restored state.
    pub filter_step: f64,
    /// [`Scheme::SCRATCH`] values per coordinate for the scheme's own use.
    pub scheme: Vec<f64>,
}

impl Buffers {
    /// For `n` coordinates and `scratch` values per coordinate of [`Buffers::scheme`].
    pub fn new(n: usize, scratch: usize) -> Self {
        Buffers {
            y1: vec![0.0; n],
            v1: vec![0.0; n],
            a1: vec![0.0; n],
            h: vec![0.0; n],
            r: vec![0.0; n],
            filter_step: f64::NAN,
            scheme: vec![f64::NAN; n * scratch],
        }
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
