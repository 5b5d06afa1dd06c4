//! Explicit Newmark (beta = 0, gamma = 1/2), the paper's scheme
//! (`docs/method.md`, section 4):
//!
//! ```text
//!     y1 = y + dt v + dt^2/2 a,
//!     (M + dt/2 C) v1 = M (v + dt/2 a) + dt/2 h(y1),
//!     M a1 = h(y1) - C v1.
//! ```
//!
//! One force evaluation per step; stable while dt omega_max < 2 (undamped).

use super::scheme::{Buffers, Scheme, EXPLICIT_SAFETY};
use crate::physics::error::StepFailure;
use crate::physics::run::space::Space;
use crate::physics::run::state::State;

pub struct NewmarkExplicit;

impl Scheme for NewmarkExplicit {
    /// β = 0: |1/12 − 0| / 2.
    const FREQUENCY_ERROR: f64 = 1.0 / 24.0;

    /// EXPLICIT_SAFETY of the limit 2 / omega_max.
    fn stable_step(omega_sq_max: f64) -> Option<f64> {
        let omega = omega_sq_max.sqrt();
        (omega > 0.0).then(|| EXPLICIT_SAFETY * 2.0 / omega)
    }

    fn step<S: Space>(space: &S, w: &mut S::Work, buf: &mut Buffers, state: &mut State, dt: f64) -> Result<(), StepFailure> {
        space.predicted_force(&state.y, &state.v, &state.a, dt, &mut buf.y1, w, &mut buf.h);
        space.explicit_rates(dt, &state.v, &mut state.a, &buf.h, w, &mut buf.v1)?;
        std::mem::swap(&mut state.v, &mut buf.v1);
        std::mem::swap(&mut state.y, &mut buf.y1);
        Ok(())
    }
}
