//! What the full space reports: spring forces, positions, energies,
//! momenta and moments, read from y = u and its rate.

use super::{Full, FullWork};
use crate::physics::run::frame::{add_outer, Moments};
use crate::physics::run::space::equations::Readout;

impl Readout for Full {
    fn spring_force(&self, u: &[f64], w: &mut FullWork, out: &mut [f64]) {
        for k in 0..u.len() {
            w.x[k] = self.scene.rest[k] + u[k];
        }
        out.fill(0.0);
        w.elastic = self.springs.add_to(&self.scene, &w.x, &mut w.springs, out);
    }

    fn positions<'w>(&self, _u: &[f64], w: &'w mut FullWork) -> &'w [f64] {
        &w.x
    }

    fn elastic_energy(&self, _u: &[f64], w: &mut FullWork) -> f64 {
        w.elastic
    }

    /// -(M g)^T u, summed node by node, and -f_p^T u at the load node.
    fn gravity_potential(&self, u: &[f64], w: &FullWork) -> f64 {
        let d = self.scene.dim;
        let loads = &w.loads;
        let g = &loads.gravity;
        let work: f64 = u.chunks_exact(d).zip(self.scene.dof_mass.chunks_exact(d)).map(|(u, m)| (0..d).map(|i| m[i] * g[i] * u[i]).sum::<f64>()).sum();
        match loads.point_force(&self.scene) {
            Some((dof, f)) => -work - f.iter().zip(&u[dof..dof + d]).map(|(f, u)| f * u).sum::<f64>(),
            None => -work,
        }
    }

    fn kinetic_energy(&self, v: &[f64]) -> f64 {
        0.5 * v.iter().zip(&self.scene.dof_mass).map(|(v, m)| m * v * v).sum::<f64>()
    }

    fn slot_velocity(&self, v: &[f64], slot: usize) -> [f64; 3] {
        let d = self.scene.dim;
        std::array::from_fn(|i| if i < d { v[slot * d + i] } else { 0.0 })
    }

    fn momentum(&self, v: &[f64]) -> [f64; 3] {
        let (d, mut p) = (self.scene.dim, [0.0; 3]);
        for (k, (vk, m)) in v.iter().zip(&self.scene.dof_mass).enumerate() {
            p[k % d] += m * vk;
        }
        p
    }

    fn first_moment(&self, u: &[f64]) -> [f64; 3] {
        let (d, pivot, mut s) = (self.scene.dim, self.scene.pivot(), [0.0; 3]);
        for (k, (uk, m)) in u.iter().zip(&self.scene.dof_mass).enumerate() {
            s[k % d] += m * (self.scene.rest[k] + uk - pivot[k % d]);
        }
        s
    }

    /// Node by node, rho = x_rest + u - X0.
    fn moments(&self, u: &[f64], v: &[f64]) -> Moments {
        let (d, pivot) = (self.scene.dim, self.scene.pivot());
        let mut out = Moments::default();
        for (k, m) in self.scene.dof_mass.iter().step_by(d).enumerate() {
            let rho: [f64; 3] = std::array::from_fn(|i| if i < d { self.scene.rest[k * d + i] + u[k * d + i] - pivot[i] } else { 0.0 });
            let vel: [f64; 3] = std::array::from_fn(|i| if i < d { v[k * d + i] } else { 0.0 });
            for i in 0..3 {
                out.first[i] += m * rho[i];
                out.momentum[i] += m * vel[i];
            }
            add_outer(&mut out.second, *m, &rho, &rho);
            add_outer(&mut out.flux, *m, &vel, &rho);
        }
        out
    }

    fn dof_velocities(&self, v: &[f64], out: &mut [f64]) {
        out.copy_from_slice(v);
    }

    /// Every force is represented: 0.
    fn force_residual(&self, _gravity: &[f64; 3], _point: &[f64; 3], _u: &[f64], _w: &mut FullWork) -> f64 {
        0.0
    }

    /// q = Phi^T M (x - x*) on the reported modes (made when first asked
    /// for; 0 where they cannot be, which [`Constants::modes_made`] says).
    fn modal_coordinates(&self, u: &[f64], out: &mut [f64]) {
        if let Some(Ok(r)) = self.reported() {
            match &r.offset {
                None => r.modes.project_displacement(&self.scene.dof_mass, u, out),
                Some(offset) => {
                    let d: Vec<f64> = u.iter().zip(offset).map(|(a, b)| a + b).collect();
                    r.modes.project_displacement(&self.scene.dof_mass, &d, out);
                }
            }
        }
    }
}
