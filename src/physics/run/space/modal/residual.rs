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
        let (d, r) = (self.scene.dim, self.modes.basis.r);
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
        let phi = &self.modes.basis.phi;
        let big_f = &mut w.generalized_scratch;
        big_f.fill(0.0);
        for (k, &fk) in out.iter().enumerate() {
            for (fj, p) in big_f.iter_mut().zip(&phi[k * r..(k + 1) * r]) {
                *fj += p * fk;
            }
        }
        for (k, o) in out.iter_mut().enumerate() {
            *o -= mass[k] * phi[k * r..(k + 1) * r].iter().zip(big_f.iter()).map(|(p, f)| p * f).sum::<f64>();
        }
    }
}
