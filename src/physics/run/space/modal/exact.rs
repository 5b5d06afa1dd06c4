//! The paper's force evaluation: every spring, in physical space
//! (`docs/method.md`, section 3, step 4). Expand q to the positions of all
//! free DOFs, evaluate the exact forces of every spring, project them onto
//! the kept modes. Its cost grows with the mesh, not with the modes.

use super::reduced::{ForceSetup, Modes, ReducedForce};
use crate::physics::error::PhysicsError;
use crate::physics::run::forces::{SpringForces, SpringScratch};
use crate::physics::run::stiffness::add_reduced_tangent;
use crate::physics::setup::scene::Scene;

/// Every spring, exactly.
pub struct Exact {
    springs: SpringForces,
}

/// Positions, forces and energy of the last evaluation, and the scratch of the tangent.
pub struct ExactWork {
    /// Slot positions.
    x: Vec<f64>,
    elastic: f64,
    /// Spring forces on the free DOFs.
    f: Vec<f64>,
    springs: SpringScratch,
    tangent: Vec<f64>,
}

impl ReducedForce for Exact {
    type Work = ExactWork;

    fn new(scene: &Scene, _modes: &Modes, _setup: &ForceSetup) -> Result<Self, PhysicsError> {
        Ok(Exact { springs: SpringForces::new(scene) })
    }

    fn work(&self, scene: &Scene, modes: &Modes) -> ExactWork {
        ExactWork {
            x: scene.rest.clone(),
            elastic: 0.0,
            f: vec![0.0; modes.basis.n],
            springs: self.springs.scratch(scene),
            tangent: vec![0.0; 6 * modes.basis.r],
        }
    }

    fn project(&self, scene: &Scene, modes: &Modes, q: &[f64], w: &mut ExactWork, out: &mut [f64]) {
        modes.expand(q, &mut w.x);
        w.f.fill(0.0);
        w.elastic = self.springs.add_to(scene, &w.x, &mut w.springs, &mut w.f);
        modes.project(&w.f, out);
    }

    fn add_tangent(&self, scene: &Scene, modes: &Modes, w: &mut ExactWork, kr: &mut [f64]) {
        add_reduced_tangent(scene, &w.x, &modes.basis.phi, modes.basis.r, false, kr, &mut w.tangent);
    }

    fn slots_mut<'w>(&self, w: &'w mut ExactWork) -> &'w mut [f64] {
        &mut w.x
    }

    /// The positions of the last evaluation, which was at `q`.
    fn positions<'w>(&self, _scene: &Scene, _modes: &Modes, _q: &[f64], w: &'w mut ExactWork) -> &'w [f64] {
        &w.x
    }

    fn elastic_energy(&self, _scene: &Scene, _modes: &Modes, _q: &[f64], w: &mut ExactWork) -> f64 {
        w.elastic
    }

    fn spring_forces<'w>(&self, _scene: &Scene, _modes: &Modes, _q: &[f64], w: &'w mut ExactWork) -> &'w [f64] {
        &w.f
    }
}
