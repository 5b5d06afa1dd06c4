//! The residual of the full equations along the reduced motion, which
//! drives the error model of an adaptive run.

use super::{Modal, ModalWork, ReducedForce};

impl<F: ReducedForce> Modal<F> {
    /// The force the basis cannot hold at q, r = f - M Phi Phi^T f over the
    /// free DOFs, f = f_springs(x* + Phi q) + M g + f_p (every spring,
    /// whatever the force model), gravity and the point load as given: the
    /// residual of the full equations along the reduced motion, which drives
    /// the error model ([`crate::physics::run::error_model`]). One pass over
    /// every spring and 2 n r operations.
    pub fn residual_force(&self, gravity: &[f64; 3], point: &[f64; 3], q: &[f64], w: &mut ModalWork<F::Work>, out: &mut [f64]) {
        let mass = &self.scene.dof_mass;
        self.full_force(gravity, point, q, w, out);
        // F = Phi^T f (faer's product), then f -= M Phi F a column at a time.
        let big_f = &mut w.generalized_scratch;
        self.modes.project(out, big_f);
        for (col, fj) in self.modes.cols.chunks_exact(self.modes.basis.n).zip(big_f.iter()) {
            for ((o, p), m) in out.iter_mut().zip(col).zip(mass) {
                *o -= m * p * fj;
            }
        }
    }
}

impl<F: ReducedForce> Modal<F> {
    /// The full force f = f_springs(x* + Phi q) + M g + f_p at q into `out`
    /// (free DOFs, every spring), with ||f||^2_{M^-1} and |Phi^T f|^2: since
    /// Phi^T M Phi = I, the residual r = f - M Phi Phi^T f has
    /// ||r||^2_{M^-1} = ||f||^2_{M^-1} - |Phi^T f|^2, and a direction psi
    /// M-orthogonal to the basis sees psi^T r = psi^T f. One pass over every
    /// spring and faer's n r product.
    pub fn loaded_force(&self, gravity: &[f64; 3], point: &[f64; 3], q: &[f64], w: &mut ModalWork<F::Work>, out: &mut [f64]) -> (f64, f64) {
        self.full_force(gravity, point, q, w, out);
        let all = out.iter().zip(&self.inv_mass).map(|(f, m)| f * f * m).sum();
        let projected = &mut w.generalized_scratch;
        self.modes.project(out, projected);
        (all, projected.iter().map(|f| f * f).sum())
    }

    /// f = f_springs(x* + Phi q) + M g + f_p into `out` (free DOFs, every spring).
    fn full_force(&self, gravity: &[f64; 3], point: &[f64; 3], q: &[f64], w: &mut ModalWork<F::Work>, out: &mut [f64]) {
        let d = self.scene.dim;
        let mass = &self.scene.dof_mass;
        out.copy_from_slice(self.force.spring_forces(&self.scene, &self.modes, q, &mut w.force));
        for (k, o) in out.iter_mut().enumerate() {
            *o += mass[k] * gravity[k % d];
        }
        if let Some((dof, f)) = w.loads.point_force_as(point, &self.scene) {
            for (i, &fi) in f.iter().enumerate() {
                out[dof + i] += fi;
            }
        }
    }
}
