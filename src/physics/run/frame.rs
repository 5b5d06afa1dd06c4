//! The holder's frame and the mass moments of the sheet in it
//! (`docs/method.md`, section 8).
//!
//! The sheet is integrated in the frame of its holder: a slot at x in that
//! frame is at X = p + R (x - X0) in the ground's, with X0 the pivot (the
//! rest position of node 0), p = X0 + a the pivot carried by the anchor's
//! translation a, and R the holder's orientation. Whatever the space, the
//! forces and torques the sheet exerts on its holder follow from a few mass
//! moments of the free nodes about the pivot ([`Moments`]), which the modal
//! space computes from invariants of its basis without expanding a node.
//! `place` and `ground_velocity` carry the outputs from the holder's frame
//! into the ground's; `into_frame` turns a ground-frame load into it.
//!
//! Vectors have 3 components (z = 0 in 2D); 3 x 3 tensors are row-major.

/// Mass moments of the free nodes about the pivot, at positions x and
/// rates v, rho_k = x_k - X0 (in the holder's frame):
///
/// ```text
///     S = sum m_k rho_k,            J = sum m_k rho_k (x) rho_k,
///     P = sum m_k v_k,              N = sum m_k v_k (x) rho_k,
///     L = sum m_k rho_k x v_k  (read from N: L_c = eps_cab N_ba).
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Moments {
    /// S [kg m].
    pub first: [f64; 3],
    /// J [kg m^2].
    pub second: [f64; 9],
    /// P [kg m/s].
    pub momentum: [f64; 3],
    /// N [kg m^2/s].
    pub flux: [f64; 9],
}

impl Moments {
    /// L = sum m_k rho_k x v_k, the antisymmetric part of N.
    pub fn angular(&self) -> [f64; 3] {
        let n = &self.flux;
        [n[7] - n[5], n[2] - n[6], n[3] - n[1]]
    }
}

/// a x b.
#[inline]
pub fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// a . b.
#[inline]
pub fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// A b for a row-major 3 x 3 tensor A.
#[inline]
pub fn apply(a: &[f64; 9], b: &[f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| a[3 * i] * b[0] + a[3 * i + 1] * b[1] + a[3 * i + 2] * b[2])
}

/// Adds s (u (x) w) to the row-major tensor `t`.
#[inline]
pub fn add_outer(t: &mut [f64; 9], s: f64, u: &[f64; 3], w: &[f64; 3]) {
    for i in 0..3 {
        for j in 0..3 {
            t[3 * i + j] += s * u[i] * w[j];
        }
    }
}

/// The holder's frame as the equations in it need it at one instant:
/// gravity and the point load turned into it, R^T g and R^T f_p, and its
/// angular velocity Omega in its own axes (constant over a communication step).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Frame {
    pub gravity: [f64; 3],
    pub load: [f64; 3],
    pub spin: [f64; 3],
}

/// R(theta), row-major: the rotation by |theta| about theta / |theta| (Rodrigues; the identity at 0).
pub fn rotation(theta: &[f64; 3]) -> [f64; 9] {
    if *theta == [0.0; 3] {
        return IDENTITY;
    }
    let r = nalgebra::Rotation3::from_scaled_axis(nalgebra::Vector3::from(*theta));
    let m = r.matrix();
    std::array::from_fn(|k| m[(k / 3, k % 3)])
}

/// The 3 x 3 identity, row-major.
pub const IDENTITY: [f64; 9] = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];

/// R^T b.
#[inline]
pub fn apply_transposed(r: &[f64; 9], b: &[f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| r[i] * b[0] + r[3 + i] * b[1] + r[6 + i] * b[2])
}

/// A B.
pub fn compose(a: &[f64; 9], b: &[f64; 9]) -> [f64; 9] {
    std::array::from_fn(|k| {
        let (i, j) = (k / 3, k % 3);
        a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j]
    })
}

/// The holder's angular velocity in its own axes over a step of `h` from
/// orientation R(theta0) to R(theta1), constant over the step: Omega with
/// R(theta0) exp(h [Omega]x) = R(theta1). About a fixed axis (theta0 and
/// theta1 parallel, always in 2D) it is (theta1 - theta0) / h, so a turn of
/// more than half a revolution in one step keeps its sense and size;
/// otherwise the rotation vector of R(theta0)^T R(theta1), at most pi / h.
pub fn spin(theta0: &[f64; 3], theta1: &[f64; 3], h: f64) -> [f64; 3] {
    if cross(theta0, theta1) == [0.0; 3] {
        return std::array::from_fn(|i| (theta1[i] - theta0[i]) / h);
    }
    let (r0, r1) = (rotation(theta0), rotation(theta1));
    let m: [f64; 9] = std::array::from_fn(|k| {
        let (i, j) = (k / 3, k % 3);
        r0[i] * r1[j] + r0[3 + i] * r1[3 + j] + r0[6 + i] * r1[6 + j]
    });
    let rel = nalgebra::Rotation3::from_matrix_unchecked(nalgebra::Matrix3::from_row_slice(&m));
    let w = rel.scaled_axis();
    [w[0] / h, w[1] / h, w[2] / h]
}

/// |v|.
#[inline]
pub fn norm(v: &[f64; 3]) -> f64 {
    dot(v, v).sqrt()
}

/// A rotation vector as the scene can turn: about z alone in 2D.
pub(super) fn planar(theta: &[f64; 3], d: usize) -> [f64; 3] {
    if d == 2 {
        [0.0, 0.0, theta[2]]
    } else {
        *theta
    }
}

/// R^T v for a ground-frame vector `v` of the scene's dimension (z ignored in 2D).
pub(super) fn into_frame(r: &[f64; 9], v: &[f64; 3], d: usize) -> [f64; 3] {
    apply_transposed(r, &std::array::from_fn(|i| if i < d { v[i] } else { 0.0 }))
}

/// X0 + a + R (x - X0): a position `x` in the frame of a holder at
/// orientation `r` and displacement `a`, in the ground's.
pub(super) fn place(pivot: &[f64; 3], a: &[f64; 3], r: &[f64; 9], x: &[f64]) -> [f64; 3] {
    let d = x.len();
    let rho: [f64; 3] = std::array::from_fn(|i| if i < d { x[i] - pivot[i] } else { 0.0 });
    let p = apply(r, &rho);
    std::array::from_fn(|i| if i < d { pivot[i] + a[i] + p[i] } else { 0.0 })
}

/// c + R (v + w x (x - X0)): a velocity `v` at `x` in the frame of a holder
/// at orientation `r` moving at c and turning at w, in the ground's.
pub(super) fn ground_velocity(pivot: &[f64; 3], c: &[f64; 3], w: &[f64; 3], r: &[f64; 9], v: &[f64], x: &[f64]) -> [f64; 3] {
    let d = x.len();
    let rho: [f64; 3] = std::array::from_fn(|i| if i < d { x[i] - pivot[i] } else { 0.0 });
    let spun = cross(w, &rho);
    let u = apply(r, &std::array::from_fn(|i| if i < d { v[i] } else { 0.0 } + spun[i]));
    std::array::from_fn(|i| if i < d { c[i] + u[i] } else { 0.0 })
}
