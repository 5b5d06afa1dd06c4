//! The inertia invariants of a basis: the mass moments of the free nodes
//! as polynomials in the modal coordinates, computed once at set-up so
//! that [`Moments`] at a state cost O(r^2) and no node is expanded (the
//! floating-frame terms of modal flexible bodies; `docs/method.md`,
//! section 8).
//!
//! With s_k = x*_k - X0 (the linearization point about the pivot) and
//! phi_jk the rows of mode j at node k,
//!
//! ```text
//!     S0 = sum m_k s_k,              J0 = sum m_k s_k (x) s_k,
//!     T_j = sum m_k phi_jk,          G_j = sum m_k phi_jk (x) s_k,
//!     H_ij = sum m_k phi_ik (x) phi_jk,
//! ```
//!
//! (tr H_ij = delta_ij, Phi^T M Phi = I), and at coordinates q, rates v (rho = s + Phi q):
//!
//! ```text
//!     S = S0 + sum_j T_j q_j,        J = J0 + sum_j q_j (G_j + G_j^T) + sum_ij q_i q_j H_ij,
//!     P = sum_j T_j v_j,             N = sum_j v_j G_j + sum_ij v_i q_j H_ij.
//! ```

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, Par};

use super::reduced::Modes;
use crate::physics::run::frame::{add_outer, apply, dot, Moments};
use crate::physics::setup::scene::Scene;

/// The invariants of one basis; see the module documentation.
pub struct Inertia {
    first: [f64; 3],
    second: [f64; 9],
    /// T_j, r x 3: also the modal rates of a unit rigid translation, Phi^T M e_i.
    translation: Vec<f64>,
    /// G_j, r x 9.
    spread: Vec<f64>,
    /// H_ij, r x r x 9.
    pair: Vec<f64>,
}

impl Inertia {
    pub fn new(scene: &Scene, modes: &Modes) -> Self {
        let (n, r, d) = (modes.basis.n, modes.basis.r, scene.dim);
        let pivot = scene.pivot();
        let nodes = n / d;
        let (mut first, mut second) = ([0.0; 3], [0.0; 9]);
        let mut translation = vec![0.0; r * 3];
        let mut spread = vec![0.0; r * 9];
        for k in 0..nodes {
            let m = scene.dof_mass[k * d];
            let s: [f64; 3] = std::array::from_fn(|a| if a < d { modes.point[k * d + a] - pivot[a] } else { 0.0 });
            for a in 0..3 {
                first[a] += m * s[a];
            }
            add_outer(&mut second, m, &s, &s);
            for (j, col) in modes.cols.chunks_exact(n).enumerate() {
                let phi: [f64; 3] = std::array::from_fn(|a| if a < d { col[k * d + a] } else { 0.0 });
                for a in 0..3 {
                    translation[j * 3 + a] += m * phi[a];
                }
                let g: &mut [f64; 9] = (&mut spread[j * 9..j * 9 + 9]).try_into().expect("9 values");
                add_outer(g, m, &phi, &s);
            }
        }
        // H_ab = Phi_a^T M Phi_b per pair of axes, Phi_a the rows of axis a (nodes x r).
        let axis =
            |a: usize, weighted: bool| Mat::from_fn(nodes, r, |k, j| modes.cols[j * n + k * d + a] * if weighted { scene.dof_mass[k * d + a] } else { 1.0 });
        let mut pair = vec![0.0; r * r * 9];
        let mut h = Mat::<f64>::zeros(r, r);
        for a in 0..d {
            let phi_a = axis(a, false);
            for b in 0..d {
                matmul(h.as_mut(), Accum::Replace, phi_a.transpose(), axis(b, true).as_ref(), 1.0, Par::Seq);
                for i in 0..r {
                    for j in 0..r {
                        pair[(i * r + j) * 9 + a * 3 + b] = h[(i, j)];
                    }
                }
            }
        }
        Inertia { first, second, translation, spread, pair }
    }

    /// T_j (3 values): the modal rates of a unit rigid translation along each axis.
    pub fn translation(&self, j: usize) -> &[f64] {
        &self.translation[j * 3..j * 3 + 3]
    }

    /// P = sum_j T_j v_j, O(r).
    pub fn momentum(&self, v: &[f64]) -> [f64; 3] {
        let mut p = [0.0; 3];
        for (vj, t) in v.iter().zip(self.translation.chunks_exact(3)) {
            for i in 0..3 {
                p[i] += t[i] * vj;
            }
        }
        p
    }

    /// S = S0 + sum_j T_j q_j, O(r).
    pub fn first_moment(&self, q: &[f64]) -> [f64; 3] {
        let p = self.momentum(q);
        std::array::from_fn(|i| self.first[i] + p[i])
    }

    /// Every moment at coordinates q and rates v, O(r^2).
    pub fn moments(&self, q: &[f64], v: &[f64]) -> Moments {
        let r = q.len();
        let mut m = Moments { first: self.first_moment(q), second: self.second, momentum: self.momentum(v), flux: [0.0; 9] };
        for (j, g) in self.spread.chunks_exact(9).enumerate() {
            for a in 0..3 {
                for b in 0..3 {
                    m.second[3 * a + b] += q[j] * (g[3 * a + b] + g[3 * b + a]);
                    m.flux[3 * a + b] += v[j] * g[3 * a + b];
                }
            }
        }
        for i in 0..r {
            for j in 0..r {
                let (qq, vq) = (q[i] * q[j], v[i] * q[j]);
                let h = &self.pair[(i * r + j) * 9..(i * r + j) * 9 + 9];
                for c in 0..9 {
                    m.second[c] += qq * h[c];
                    m.flux[c] += vq * h[c];
                }
            }
        }
        m
    }

    /// The terms of a holder turning at Omega (`docs/method.md`, section 8):
    /// the generalized centrifugal force Phi^T M (Omega^2 rho - Omega (Omega . rho)) = c0 + Kc q,
    ///
    /// ```text
    ///     c0_j = Omega^2 tr G_j - Omega^T G_j Omega,    Kc_ji = Omega^2 tr H_ji - Omega^T H_ji Omega,
    /// ```
    ///
    /// and the Coriolis matrix Gamma, -2 Phi^T M (Omega x Phi q') = -Gamma q',
    /// Gamma_ji = 2 Omega . B_ij with B_ij = sum m phi_ik x phi_jk (skew). `kc` and
    /// `gamma` are r x r, row j holding the forces on mode j.
    pub fn spin_terms(&self, spin: &[f64; 3], c0: &mut [f64], kc: &mut [f64], gamma: &mut [f64]) {
        let r = c0.len();
        let w2 = dot(spin, spin);
        let quad = |t: &[f64]| w2 * (t[0] + t[4] + t[8]) - dot(spin, &apply(t.try_into().expect("9 values"), spin));
        for (j, g) in self.spread.chunks_exact(9).enumerate() {
            c0[j] = quad(g);
        }
        for j in 0..r {
            for i in 0..r {
                kc[j * r + i] = quad(&self.pair[(j * r + i) * 9..(j * r + i) * 9 + 9]);
                gamma[j * r + i] = 2.0 * dot(spin, &skew(&self.pair[(i * r + j) * 9..(i * r + j) * 9 + 9]));
            }
        }
    }

    /// (Phi^T M (c x rho))_j at coordinates q: the modal rate of mode j in a
    /// rigid rotation with angular velocity c about the pivot,
    /// c . (A_j + sum_i q_i B_ij) with A_j = sum m s_k x phi_jk (the skew part of G_j), O(r).
    pub fn rotation_rate(&self, j: usize, c: &[f64; 3], q: &[f64]) -> f64 {
        let r = q.len();
        let mut arm = skew_swapped(&self.spread[j * 9..j * 9 + 9]);
        for (i, qi) in q.iter().enumerate() {
            let b = skew(&self.pair[(i * r + j) * 9..(i * r + j) * 9 + 9]);
            for a in 0..3 {
                arm[a] += qi * b[a];
            }
        }
        dot(c, &arm)
    }
}

/// For T = sum m u (x) w (row-major), sum m u x w.
fn skew(t: &[f64]) -> [f64; 3] {
    [t[5] - t[7], t[6] - t[2], t[1] - t[3]]
}

/// For T = sum m u (x) w (row-major), sum m w x u.
fn skew_swapped(t: &[f64]) -> [f64; 3] {
    let s = skew(t);
    [-s[0], -s[1], -s[2]]
}
