//! Newmark-beta coefficients shared by the modal and full-space solvers.
//!
//! Both solve M y'' + C y' = h(y) with M diagonal: the identity in modal
//! coordinates, the lumped masses in full space.
//!
//! Explicit (beta = 0, gamma = 1/2):
//!   y_{n+1} = y_n + dt v_n + dt^2/2 a_n,
//!   (M + dt/2 C) v_{n+1} = M (v_n + dt/2 a_n) + dt/2 h(y_{n+1}),
//!   M a_{n+1} = h(y_{n+1}) - C v_{n+1}.
//! Implicit (beta = 1/4, gamma = 1/2), Newton on y_{n+1}:
//!   a_{n+1} = 4/dt^2 (y_{n+1} - y_n - dt v_n) - a_n,
//!   v_{n+1} = v_n + dt/2 (a_n + a_{n+1}),
//!   R = M a_{n+1} + C v_{n+1} - h(y_{n+1}),
//!   J = 4/dt^2 M + 2/dt C - dh/dy.

/// Newton iterations before an implicit step is declared failed.
pub const MAX_NEWTON_ITERATIONS: usize = 30;
/// Newton stops when the update is below this fraction of the state's scale.
pub const NEWTON_TOLERANCE: f64 = 1e-11;

/// Predictor y_{n+1} = y_n + dt v_n + dt^2/2 a_n (exact for the explicit scheme,
/// the starting guess of the implicit one).
#[inline]
pub fn predict(y: &[f64], v: &[f64], a: &[f64], dt: f64, out: &mut [f64]) {
    let half_dt2 = 0.5 * dt * dt;
    for i in 0..out.len() {
        out[i] = y[i] + dt * v[i] + half_dt2 * a[i];
    }
}

/// Implicit Newmark kinematics: a_{n+1} and v_{n+1} from the current guess y_{n+1}.
#[inline]
pub fn implicit_kinematics(y: &[f64], v: &[f64], a: &[f64], y_new: &[f64], dt: f64, v_new: &mut [f64], a_new: &mut [f64]) {
    let c0 = 4.0 / (dt * dt);
    for i in 0..y.len() {
        a_new[i] = c0 * (y_new[i] - y[i] - dt * v[i]) - a[i];
        v_new[i] = v[i] + 0.5 * dt * (a[i] + a_new[i]);
    }
}

/// max |d_i| <= tol * max(max |y_i|, scale)
#[inline]
pub fn converged(delta: &[f64], y: &[f64], scale: f64) -> bool {
    let dmax = delta.iter().fold(0.0f64, |m, d| m.max(d.abs()));
    let ymax = y.iter().fold(scale, |m, v| m.max(v.abs()));
    dmax <= NEWTON_TOLERANCE * ymax
}
