//! Implicit Newmark (beta = 1/4, gamma = 1/2, average acceleration), with
//! Newton iterations on y1 (`docs/method.md`, section 4):
//!
//! ```text
//!     a1 = 4/dt^2 (y1 - y - dt v) - a,
//!     v1 = v + dt/2 (a + a1),
//!     R(y1) = M a1 + C v1 - h(y1) = 0,
//!     J = 4/dt^2 M + 2/dt C - dh/dy.
//! ```
//!
//! Unconditionally stable for the linear part; the Newton loop is the only
//! one in the core, every space provides its J through [`Space::factor`].

use super::scheme::{predict, Buffers, Scheme};
use crate::physics::error::StepFailure;
use crate::physics::run::space::Space;
use crate::physics::run::state::State;

/// Newton iterations before an implicit step is declared failed.
pub const MAX_NEWTON_ITERATIONS: usize = 30;
/// Newton stops when the update is below this fraction of the state's scale.
pub const NEWTON_TOLERANCE: f64 = 1e-11;

pub struct NewmarkImplicit;

impl Scheme for NewmarkImplicit {
    /// β = 1/4: |1/12 − 1/4| / 2.
    const FREQUENCY_ERROR: f64 = 1.0 / 12.0;

    fn stable_step(_omega_sq_max: f64) -> Option<f64> {
        None
    }

    fn step<S: Space>(space: &S, w: &mut S::Work, buf: &mut Buffers, state: &mut State, dt: f64) -> Result<(), StepFailure> {
        predict(&state.y, &state.v, &state.a, dt, &mut buf.y1);
        let c0 = 4.0 / (dt * dt);
        let c1 = 2.0 / dt;
        let mut done = false;
        for _ in 0..=MAX_NEWTON_ITERATIONS {
            space.force(&buf.y1, w, &mut buf.h);
            kinematics(state, &buf.y1, dt, &mut buf.v1, &mut buf.a1);
            if done {
                std::mem::swap(&mut state.y, &mut buf.y1);
                std::mem::swap(&mut state.v, &mut buf.v1);
                std::mem::swap(&mut state.a, &mut buf.a1);
                return Ok(());
            }
            space.residual(&buf.v1, &buf.a1, &buf.h, w, &mut buf.r);
            space.factor(c0, c1, w)?;
            space.solve(w, &mut buf.r);
            if !buf.r.iter().all(|d| d.is_finite()) {
                return Err(StepFailure::SingularNewton { dt });
            }
            for (y, d) in buf.y1.iter_mut().zip(&buf.r) {
                *y += d;
            }
            done = converged(&buf.r, &buf.y1, space.layout().newton_scale);
        }
        Err(StepFailure::NewtonNotConverged { iterations: MAX_NEWTON_ITERATIONS, dt })
    }
}

/// a1 and v1 from the current guess y1.
#[inline]
fn kinematics(s: &State, y1: &[f64], dt: f64, v1: &mut [f64], a1: &mut [f64]) {
    let c0 = 4.0 / (dt * dt);
    for i in 0..s.y.len() {
        a1[i] = c0 * (y1[i] - s.y[i] - dt * s.v[i]) - s.a[i];
        v1[i] = s.v[i] + 0.5 * dt * (s.a[i] + a1[i]);
    }
}

/// max |d_i| <= tol * max(max |y_i|, scale)
#[inline]
fn converged(delta: &[f64], y: &[f64], scale: f64) -> bool {
    let dmax = delta.iter().fold(0.0f64, |m, d| m.max(d.abs()));
    let ymax = y.iter().fold(scale, |m, v| m.max(v.abs()));
    dmax <= NEWTON_TOLERANCE * ymax
}
