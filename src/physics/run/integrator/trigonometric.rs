//! A filtered trigonometric (Gautschi-type) scheme for the modal equations
//! (`docs/method.md`, section 4). Every coordinate is a damped linear
//! oscillator driven by a load b_i, constant over the step, and the rest of
//! the force:
//!
//! ```text
//!     y_i'' + c_i y_i' + lambda_i y_i = b_i + e_i(y),    b_i + e_i(y) = g_i(y) = h_i(y) + lambda_i y_i = w_i r_i.
//! ```
//!
//! One step of length dt propagates the oscillator under b exactly and
//! gives e as two half kicks, evaluated at the filtered coordinates
//! phi y (a symmetric splitting, like the mollified impulse method of
//! García-Archilla, Sanz-Serna and Skeel):
//!
//! ```text
//!     v+ = v + dt/2 psi_1 e_n,                     e_n = e(phi y_n),
//!     y1 = A y + P v+ + I b,    v- = V_y y + V_v v+ + P b,
//!     v1 = v- + dt/2 psi_1 e_{n+1},                e_{n+1} = e(phi y1),
//! ```
//!
//! with s the oscillator's response to a unit rate (s(0) = 0, s'(0) = 1):
//! P = s(dt), A = s'(dt) + c s(dt), V_y = -lambda s(dt), V_v = s'(dt),
//! I = int_0^dt s; phi and psi_1 are functions of xi = dt sqrt(lambda)
//! ([`Propagator`]). Undamped, it is the two-step scheme
//!
//! ```text
//!     y_{n+1} - 2 cos(xi) y_n + y_{n-1} = dt^2 sinc^2(xi/2) (b + chi(xi) e(phi y_n))
//! ```
//!
//! in one-step form: Gautschi's filter, exact for the response to the load
//! (the static one included) at any dt, with chi = 1 near xi = 0 and
//! chi -> 0 at odd multiples of pi, where the rates of a symmetric one-step
//! form of Gautschi's filter on e would grow without bound. One force
//! evaluation per step.
//!
//! `state.a` keeps e_n for the step size in [`Buffers::filter_step`]; where
//! the step size differs (the first step, a change of loads or step size, a
//! restored state) the step evaluates it first.

use super::scheme::{Buffers, Scheme};
use crate::physics::error::{PhysicsError, StepFailure};
use crate::physics::run::space::{Diagonal, Space};
use crate::physics::run::state::State;

pub struct Trigonometric;

/// Per coordinate in [`Buffers::scheme`]: lambda, c and dt, and the
/// [`Propagator`] of the three, computed again only when one changes.
const CACHE: usize = 11;

/// The kicks integrate the rest of the force explicitly: like the
/// central difference, they follow a stiffness K of it while dt^2 K < 4.
/// A step along which the filtered rest is stiffer than that is refused.
pub const MAX_REST_STIFFNESS: f64 = 4.0;

/// Relative change of the coordinates along a step below which it is
/// round-off (a few thousand ulps), along which no stiffening is measured.
const REST_ROUND_OFF: f64 = 1e-12;

impl Scheme for Trigonometric {
    /// Exact on the linear part: the error of its nonlinear rest is not counted.
    const FREQUENCY_ERROR: f64 = 0.0;

    const SCRATCH: usize = CACHE;
    /// Its kicks take forces of the positions alone.
    const TURNS: bool = false;
    /// The step's evaluation is at phi y (in `buf.a1`); the outputs evaluate at y when read.
    const ENDS_AT_STATE: bool = false;

    /// The linear part is integrated exactly: no limit.
    fn stable_step(_omega_sq_max: f64) -> Option<f64> {
        None
    }

    fn check<S: Space>(space: &S, w: &S::Work) -> Result<(), PhysicsError> {
        match space.diagonal(w) {
            Some(_) => Ok(()),
            None => Err(PhysicsError::SchemeNeedsDiagonal { scheme: crate::physics::settings::Integrator::Trigonometric }),
        }
    }

    fn step<S: Space>(space: &S, w: &mut S::Work, buf: &mut Buffers, state: &mut State, dt: f64) -> Result<(), StepFailure> {
        if buf.filter_step != dt {
            // e_n at phi y_n for this step size.
            remainder(space, w, buf, &state.y, dt);
            state.a.copy_from_slice(&buf.v1);
            buf.filter_step = dt;
        }
        {
            let d = diagonal(space, w);
            for i in 0..state.y.len() {
                let p = cached(&mut buf.scheme[i * CACHE..(i + 1) * CACHE], d.stiffness[i], d.damping[i], dt);
                let kick = 0.5 * dt * p.kick;
                let (y, v, b) = (state.y[i], state.v[i] + kick * state.a[i], d.load[i]);
                buf.y1[i] = p.yy * y + p.yv * v + p.yg * b;
                buf.v1[i] = p.vy * y + p.vv * v + p.yv * b;
                buf.r[i] = 0.5 * dt * p.kick_end;
                buf.a1[i] = p.filter * buf.y1[i];
            }
        }
        space.force(&buf.a1, w, &mut buf.h);
        let d = diagonal(space, w);
        // The secant stiffness of the filtered rest along the step, |psi (e1 - e0)| / |y1 - y0|.
        let scale = space.layout().newton_scale;
        let (mut de, mut dy, mut size) = (0.0, 0.0, scale * scale);
        for i in 0..state.y.len() {
            let e = buf.h[i] + d.stiffness[i] * buf.a1[i] - d.load[i];
            // filter * kick (the cache's values 8 and 9) = sinc(xi) psi_1(xi).
            let psi = buf.scheme[i * CACHE + 8] * buf.scheme[i * CACHE + 9];
            de += (psi * (e - state.a[i])).powi(2);
            dy += (buf.y1[i] - state.y[i]).powi(2);
            size += buf.y1[i] * buf.y1[i];
            buf.v1[i] += buf.r[i] * e;
            state.a[i] = e;
        }
        // e depends on y alone: where y moved by round-off of its size or of
        // the scene's (at rest), so did e, and their ratio is no stiffness.
        if dt * dt * de.sqrt() > MAX_REST_STIFFNESS * dy.sqrt() && dy > REST_ROUND_OFF * REST_ROUND_OFF * size {
            return Err(StepFailure::RestTooStiff { stiffness: (de / dy).sqrt(), limit: MAX_REST_STIFFNESS / (dt * dt), dt });
        }
        std::mem::swap(&mut state.y, &mut buf.y1);
        std::mem::swap(&mut state.v, &mut buf.v1);
        Ok(())
    }

    /// e depends on the step size through the filter, which is not known
    /// yet: the next step evaluates it. The forces are left at `state.y`.
    fn settle<S: Space>(space: &S, w: &mut S::Work, buf: &mut Buffers, state: &mut State) {
        space.force(&state.y, w, &mut buf.h);
        buf.filter_step = f64::NAN;
    }

    /// e does not depend on the rates; the forces are still at `state.y`.
    fn settle_rates<S: Space>(_space: &S, _w: &mut S::Work, _buf: &mut Buffers, _state: &mut State) {}

    /// The motion the scheme integrates: at a fixed point of its step
    /// (y1 = y, v = 0) the exact propagator gives lambda I y = I b + P dt/2 psi_1 e,
    /// so its equations are y'' + c y' + lambda y = b + kappa e(phi y) with
    /// kappa = P dt psi_1 / (2 I) (chi(xi) undamped, 1 as dt -> 0), and
    /// y'' = b + kappa e_n - lambda y - c v, which is 0 at its rest. Before
    /// e_n is known for a step size (after a change of loads or a restored
    /// state): h(y) - c v, with the forces at y.
    fn acceleration<S: Space>(space: &S, w: &mut S::Work, buf: &mut Buffers, state: &State, out: &mut [f64]) {
        let dt = buf.filter_step;
        let d = diagonal(space, w);
        for i in 0..out.len() {
            let (lambda, c) = (d.stiffness[i], d.damping[i]);
            out[i] = if dt.is_finite() {
                let p = cached(&mut buf.scheme[i * CACHE..(i + 1) * CACHE], lambda, c, dt);
                let kappa = p.yv * dt * p.kick / (2.0 * p.yg);
                d.load[i] + kappa * state.a[i] - lambda * state.y[i] - c * state.v[i]
            } else {
                buf.h[i] - c * state.v[i]
            };
        }
    }
}

/// The propagator of (lambda, c, dt), from `cache` when it holds those.
fn cached(cache: &mut [f64], lambda: f64, c: f64, dt: f64) -> Propagator {
    if cache[0] == lambda && cache[1] == c && cache[2] == dt {
        return Propagator { yy: cache[3], yv: cache[4], yg: cache[5], vy: cache[6], vv: cache[7], filter: cache[8], kick: cache[9], kick_end: cache[10] };
    }
    let p = Propagator::new(lambda, c, dt);
    cache.copy_from_slice(&[lambda, c, dt, p.yy, p.yv, p.yg, p.vy, p.vv, p.filter, p.kick, p.kick_end]);
    p
}

fn diagonal<'a, S: Space>(space: &'a S, w: &'a S::Work) -> Diagonal<'a> {
    space.diagonal(w).expect("the trigonometric scheme is bound only to a space with a diagonal linear part (Scheme::check)")
}

/// e(phi y) = h(phi y) + lambda phi y - b into `buf.v1` (`buf.a1`: phi y).
fn remainder<S: Space>(space: &S, w: &mut S::Work, buf: &mut Buffers, y: &[f64], dt: f64) {
    {
        let d = diagonal(space, w);
        for ((a, yi), &lambda) in buf.a1.iter_mut().zip(y).zip(d.stiffness) {
            *a = sinc(xi(lambda, dt)) * yi;
        }
    }
    space.force(&buf.a1, w, &mut buf.h);
    let d = diagonal(space, w);
    for i in 0..y.len() {
        buf.v1[i] = buf.h[i] + d.stiffness[i] * buf.a1[i] - d.load[i];
    }
}

/// Where the rate filter psi_1 leaves Gautschi's: psi_1 = (psi / sinc) chi
/// with chi = 1 / (1 + EPSILON^2 tan^2(xi/2)). 0 would be Gautschi's filter
/// at every xi, with rates unbounded near odd multiples of pi; 1 is
/// sinc(xi), the mollified impulse method's. At 0.3, |psi_1| stays below 1.35
/// at every xi and chi within 1 % of 1 up to xi = 0.2 pi, 8 % at pi/2.
pub const EPSILON: f64 = 0.3;

/// One step of length dt of one coordinate: the exact step of
/// y'' + c y' + lambda y = b, b constant,
///
/// ```text
///     y1 = yy y + yv v + yg b,
///     v1 = vy y + vv v + yv b,
/// ```
///
/// and the filters of the rest of the force at xi = dt sqrt(lambda): it is
/// evaluated at `filter` y, filter = phi(xi) = sinc(xi), and kicks the rates
/// by dt/2 `kick` e, kick = psi_1(xi) = sinc(xi/2) cos(xi/2) / (cos^2(xi/2) + EPSILON^2 sin^2(xi/2)),
/// so that sinc(xi) psi_1(xi) = sinc^2(xi/2) chi(xi). Written with the
/// propagator's own P and I, dt/2 kick = P I / (P^2 + EPSILON^2 lambda I^2)
/// = chi I / P (undamped P^2 = 2 I cos^2(xi/2), lambda I^2 = 2 I sin^2(xi/2)).
/// Damped (c > 0), the kicks take that form, and the closing one
/// dt/2 `kick_end` = (P^2 - V_v I) P / (P^2 + EPSILON^2 lambda I^2): with a
/// constant rest e the step then keeps y'' + c y' + lambda y = b + kappa e,
/// kappa = P^2 / (P^2 + EPSILON^2 lambda I^2) (chi undamped), at zero rate
/// (the position update asks lambda I y = I b + P dt/2 kick e, the rate
/// update lambda P y = P b + (V_v kick + kick_end) dt/2 e), and neither
/// has a pole where the damped P vanishes. Undamped, P^2 = I (1 + V_v) and
/// kick_end = kick. Equal kicks of the undamped form would leave a damped
/// sheet at rest with a spurious rate, of order c dt^2 e.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Propagator {
    pub yy: f64,
    pub yv: f64,
    pub yg: f64,
    pub vy: f64,
    pub vv: f64,
    pub filter: f64,
    pub kick: f64,
    pub kick_end: f64,
}

impl Propagator {
    /// For stiffness `lambda` >= 0 [1/s^2], damping `c` >= 0 [1/s] and step `dt` > 0 [s].
    pub fn new(lambda: f64, c: f64, dt: f64) -> Self {
        let u = Unit::new(lambda * dt * dt, c * dt);
        let s = u.s * dt;
        let x = xi(lambda, dt);
        let (sin, cos) = (0.5 * x).sin_cos();
        let yg = u.i * dt * dt;
        let (kick, kick_end) = if c == 0.0 {
            let kick = sinc(0.5 * x) * cos / (cos * cos + EPSILON * EPSILON * sin * sin);
            (kick, kick)
        } else {
            let den = 0.5 * dt * (s * s + EPSILON * EPSILON * lambda * yg * yg);
            (s * yg / den, (s * s - u.ds * yg) * s / den)
        };
        Propagator { yy: u.yy, yv: s, yg, vy: -lambda * s, vv: u.ds, filter: sinc(x), kick, kick_end }
    }
}

/// The oscillator over a unit step in the time tau = t / dt:
/// Y'' + b Y' + a Y = f, a = lambda dt^2, b = c dt.
struct Unit {
    /// Y(1) from Y(0) = 0, Y'(0) = 1 (s / dt).
    s: f64,
    /// Y'(1) from the same (s').
    ds: f64,
    /// Y(1) from Y(0) = 1, Y'(0) = 0 (s' + c s).
    yy: f64,
    /// Y(1) from rest under f = 1 (I / dt^2).
    i: f64,
}

impl Unit {
    /// Three forms, each free of cancellation where it is used: a Taylor
    /// series for a short step (a <= 1, b <= 2), the two real decay rates
    /// for a strongly overdamped oscillator, and the damped sine and cosine
    /// otherwise.
    fn new(a: f64, b: f64) -> Self {
        let m = 0.5 * b;
        let z = a - m * m;
        if a <= 1.0 && b <= 2.0 {
            Self::series(a, b)
        } else if z < -0.25 {
            Self::overdamped(a, m, z)
        } else {
            Self::oscillating(a, m, z)
        }
    }

    /// Taylor series in tau of the solutions: (k + 2)(k + 1) y_{k+2} =
    /// [k = 0] f - b (k + 1) y_{k+1} - a y_k; the terms fall as 3^k / k!.
    fn series(a: f64, b: f64) -> Self {
        let (mut s0, mut s1) = (0.0f64, 1.0f64);
        let (mut f0, mut f1) = (0.0f64, 0.0f64);
        let (mut s, mut ds, mut i) = (1.0, 1.0, 0.0);
        for k in 0..64 {
            let kf = k as f64;
            let div = (kf + 2.0) * (kf + 1.0);
            let s2 = -(b * (kf + 1.0) * s1 + a * s0) / div;
            let f2 = (if k == 0 { 1.0 } else { 0.0 } - (b * (kf + 1.0) * f1 + a * f0)) / div;
            s += s2;
            ds += (kf + 2.0) * s2;
            i += f2;
            (s0, s1, f0, f1) = (s1, s2, f1, f2);
            if k >= 2 && (s0.abs() + s1.abs()) * (kf + 3.0) + f0.abs() + f1.abs() < 1e-18 {
                break;
            }
        }
        Unit { s, ds, yy: ds + b * s, i }
    }

    /// z = a - b^2/4 < -1/4: Y = combinations of e^{-r1 tau} and e^{-r2 tau},
    /// r1,2 = b/2 -+ sqrt(-z), r2 - r1 = 2 sqrt(-z) >= 1.
    fn overdamped(a: f64, m: f64, z: f64) -> Self {
        let q = (-z).sqrt();
        let r2 = m + q;
        let r1 = a / r2;
        let d = 2.0 * q;
        let (e1, e2) = ((-r1).exp(), (-r2).exp());
        // I = int_0^1 (e^{-r1 t} - e^{-r2 t}) / d dt = (phi1(r1) - phi1(r2)) / d,
        // = 1/a + (e2/r2 - e1/r1)/d once both rates reach 1.
        let i = if r1 < 1.0 { (phi1(r1) - phi1(r2)) / d } else { 1.0 / a + (e2 / r2 - e1 / r1) / d };
        Unit { s: (e1 - e2) / d, ds: (r2 * e2 - r1 * e1) / d, yy: (r2 * e1 - r1 * e2) / d, i }
    }

    /// z >= -1/4 and a > 3/4: Y = e^{-m tau} (cos, sin)(sqrt(z) tau) (cosh and
    /// sinh for z < 0), and a I = 1 - Y_yy(1) written as a sum of terms of one
    /// sign where z >= 0: (1 - (1 + m) e^{-m}) + m e^{-m} (1 - sigma) + e^{-m} (1 - gamma).
    fn oscillating(a: f64, m: f64, z: f64) -> Self {
        let e = (-m).exp();
        let (sigma, gamma, one_sigma, one_gamma) = if z.abs() < 0.5 {
            // sigma = sum (-z)^k / (2k+1)!, gamma = sum (-z)^k / (2k)!
            let (mut sigma, mut gamma, mut t_s, mut t_g) = (1.0, 1.0, 1.0, 1.0);
            let (mut one_sigma, mut one_gamma) = (0.0, 0.0);
            for k in 1..16 {
                let kf = k as f64;
                t_g *= -z / ((2.0 * kf - 1.0) * (2.0 * kf));
                t_s *= -z / ((2.0 * kf) * (2.0 * kf + 1.0));
                sigma += t_s;
                gamma += t_g;
                one_sigma -= t_s;
                one_gamma -= t_g;
            }
            (sigma, gamma, one_sigma, one_gamma)
        } else {
            let w = z.sqrt();
            let (sin, cos) = w.sin_cos();
            let half = (0.5 * w).sin();
            (sin / w, cos, 1.0 - sin / w, 2.0 * half * half)
        };
        let t1 = if m < 1.0 {
            // 1 - (1 + m) e^{-m} = sum_{k >= 2} (-1)^k (k - 1) m^k / k!
            let (mut sum, mut term) = (0.0, m);
            for k in 2..24 {
                let kf = k as f64;
                term *= -m / kf;
                sum -= (kf - 1.0) * term;
            }
            sum
        } else {
            1.0 - (1.0 + m) * e
        };
        Unit { s: e * sigma, ds: e * (gamma - m * sigma), yy: e * (gamma + m * sigma), i: (t1 + m * e * one_sigma + e * one_gamma) / a }
    }
}

/// xi = dt omega, the same bits wherever the filters are computed.
fn xi(lambda: f64, dt: f64) -> f64 {
    (lambda * dt * dt).sqrt()
}

/// (1 - e^{-x}) / x, 1 at 0.
fn phi1(x: f64) -> f64 {
    if x < 1e-5 {
        1.0 - x / 2.0 + x * x / 6.0
    } else {
        -(-x).exp_m1() / x
    }
}

/// sin x / x, 1 at 0.
pub(crate) fn sinc(x: f64) -> f64 {
    if x < 1e-4 {
        1.0 - x * x / 6.0
    } else {
        x.sin() / x
    }
}
