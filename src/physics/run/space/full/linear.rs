//! The full space's linear systems: C v with Rayleigh damping, the sparse
//! Cholesky factorization of M c_m + C c_k (+ K c_k, or + dt M [Omega]x when
//! the frame turns), and the velocity update with the Coriolis term.

use faer::dyn_stack::MemStack;
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Par, Side};

use super::{Full, FullWork, SKIP};
use crate::physics::error::StepFailure;
use crate::physics::run::frame::{cross, dot};
use crate::physics::run::space::equations::Space;
use crate::physics::vector_unit;

impl Full {
    /// cv = C v = alpha M v + beta K0 v.
    pub(super) fn damping_times(&self, v: &[f64], w: &mut FullWork) {
        let mass = &self.scene.dof_mass;
        if w.beta != 0.0 {
            self.pattern.sym_matvec(&self.k0, v, &mut w.cv);
            for k in 0..v.len() {
                w.cv[k] = w.alpha * mass[k] * v[k] + w.beta * w.cv[k];
            }
        } else {
            for k in 0..v.len() {
                w.cv[k] = w.alpha * mass[k] * v[k];
            }
        }
    }

    /// Factorizes `c_m M + c_k K0 (+ K(x) if tangent)` into `w.l_values`.
    pub(super) fn factorize(&self, c_m: f64, c_k: f64, tangent: bool, w: &mut FullWork) -> Result<(), StepFailure> {
        for (m, k) in w.matrix.iter_mut().zip(&self.k0) {
            *m = c_k * k;
        }
        for (k, &pos) in self.pattern.diag.iter().enumerate() {
            w.matrix[pos] += c_m * self.scene.dof_mass[k];
        }
        if tangent {
            self.pattern.add_tangent(&self.scene, &w.x, 1.0, &mut w.matrix);
        }
        self.factorize_matrix(w)
    }

    /// The Newton matrix c_m M + c_k K0 + K(x) - m (Omega^2 I - Omega Omega^T) per node.
    pub(super) fn factorize_with_spin(&self, c_m: f64, c_k: f64, spin: &[f64; 3], w: &mut FullWork) -> Result<(), StepFailure> {
        if *spin == [0.0; 3] {
            return self.factorize(c_m, c_k, true, w);
        }
        for (m, k) in w.matrix.iter_mut().zip(&self.k0) {
            *m = c_k * k;
        }
        let (d, w2) = (self.scene.dim, dot(spin, spin));
        for (k, &pos) in self.pattern.diag.iter().enumerate() {
            let i = k % d;
            w.matrix[pos] += c_m * self.scene.dof_mass[k] - self.scene.dof_mass[k] * (w2 - spin[i] * spin[i]);
        }
        for (k, pairs) in self.node_pairs.iter().enumerate() {
            let m = self.scene.dof_mass[3 * k];
            for (&pos, (a, b)) in pairs.iter().zip([(0, 1), (0, 2), (1, 2)]) {
                if pos != SKIP {
                    w.matrix[pos] += m * spin[a] * spin[b];
                }
            }
        }
        self.pattern.add_tangent(&self.scene, &w.x, 1.0, &mut w.matrix);
        self.factorize_matrix(w)
    }

    /// Factorizes `w.matrix` into `w.l_values`: LL^T, else LDL^T.
    pub(super) fn factorize_matrix(&self, w: &mut FullWork) -> Result<(), StepFailure> {
        let n = self.scene.n_dofs();
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &self.pattern.col_ptr, None, &self.pattern.row_idx);
        let a = SparseColMatRef::new(sym, &w.matrix);
        let stack = MemStack::new(&mut w.mem);
        let llt = self.symbolic.factorize_numeric_llt(&mut w.l_values, a, Side::Upper, LltRegularization::default(), Par::Seq, stack, Default::default());
        w.indefinite = llt.is_err();
        vector_unit::clean();
        if !w.indefinite {
            return Ok(());
        }
        // Springs in compression have negative transverse stiffness; with
        // stiff springs it can outweigh M / (beta dt^2). Newton still
        // converges on the indefinite matrix: factor it as LDL^T.
        let stack = MemStack::new(&mut w.mem);
        let regularization = LdltRegularization { dynamic_regularization_signs: None, dynamic_regularization_delta: 0.0, dynamic_regularization_epsilon: 0.0 };
        self.symbolic
            .factorize_numeric_ldlt(&mut w.l_values, a, Side::Upper, regularization, Par::Seq, stack, Default::default())
            .map(|_| vector_unit::clean())
            .map_err(|_| StepFailure::Buckled)
    }
}

impl Full {
    /// Adds s 2 (Omega x v) per node to `out`, times m_k when `mass`.
    pub(super) fn add_coriolis(&self, v: &[f64], spin: [f64; 3], s: f64, mass: bool, out: &mut [f64]) {
        let d = self.scene.dim;
        for (k, o) in out.chunks_exact_mut(d).enumerate() {
            let vel: [f64; 3] = std::array::from_fn(|i| if i < d { v[k * d + i] } else { 0.0 });
            let c = cross(&spin, &vel);
            let m = if mass { self.scene.dof_mass[k * d] } else { 1.0 };
            for i in 0..d {
                o[i] += s * 2.0 * m * c[i];
            }
        }
    }

    /// Solves (M + dt/2 C + dt M [Omega]x) v1 = rhs, `v1` holding rhs on entry.
    pub(super) fn coriolis_velocity(&self, dt: f64, w: &mut FullWork, v1: &mut [f64]) -> Result<(), StepFailure> {
        let (d, spin) = (self.scene.dim, w.spin);
        let mass = &self.scene.dof_mass;
        if w.beta == 0.0 {
            // Per node m ((1 + dt/2 alpha) I + [dt Omega]x) v = b: with a = 1 + dt/2 alpha, s = dt Omega, c = b / m,
            // v = (a^2 c - a (s x c) + (s . c) s) / (a (a^2 + |s|^2)).
            let a = 1.0 + 0.5 * dt * w.alpha;
            let s: [f64; 3] = std::array::from_fn(|i| dt * spin[i]);
            let den = a * (a * a + dot(&s, &s));
            for (k, vk) in v1.chunks_exact_mut(d).enumerate() {
                let c: [f64; 3] = std::array::from_fn(|i| if i < d { vk[i] / mass[k * d] } else { 0.0 });
                let (sc, along) = (cross(&s, &c), dot(&s, &c));
                for i in 0..d {
                    vk[i] = (a * a * c[i] - a * sc[i] + along * s[i]) / den;
                }
            }
            return Ok(());
        }
        // v1 = (M + dt/2 C)^-1 (rhs - dt M (Omega x v1)), from v1 = 0.
        let key = (dt, w.alpha, w.beta);
        if w.explicit_factor != Some(key) {
            w.explicit_factor = None;
            self.factorize(1.0 + 0.5 * dt * w.alpha, 0.5 * dt * w.beta, false, w)?;
            w.explicit_factor = Some(key);
        }
        w.rhs.copy_from_slice(v1);
        w.previous.fill(0.0);
        for _ in 0..MAX_CORIOLIS_ITERATIONS {
            v1.copy_from_slice(&w.rhs);
            // rhs - dt M (Omega x previous)
            self.add_coriolis(&w.previous, spin, -0.5 * dt, true, v1);
            self.solve(w, v1);
            let change = v1.iter().zip(&w.previous).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            let size = v1.iter().fold(0.0f64, |m, a| m.max(a.abs()));
            w.previous.copy_from_slice(v1);
            if change <= 1e-13 * size {
                return Ok(());
            }
        }
        Err(StepFailure::CoriolisNotConverged { turn: dt * dot(&spin, &spin).sqrt(), dt })
    }
}

/// Iterates of the Coriolis velocity update before a step is refused.
const MAX_CORIOLIS_ITERATIONS: usize = 100;
