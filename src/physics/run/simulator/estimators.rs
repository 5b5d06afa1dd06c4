//! The error model an adaptive run keeps (`docs/method.md`, section 10):
//! in full space beside exact forces ([`ErrorModel`]), in error directions
//! on a cubature beside cubature forces ([`DirectionModel`]).

use crate::physics::error::PhysicsError;
use crate::physics::run::error_directions::{error_directions, DirectionModel};
use crate::physics::run::error_model::{ErrorModel, ErrorState};
use crate::physics::setup::adaptive_basis::Chosen;
use crate::physics::setup::modes::ModalBasis;
use crate::physics::setup::scene::Scene;
use crate::physics::setup::setup_data::SpringSet;

/// The error model an adaptive run keeps.
pub enum Estimator {
    /// M e'' + K e = r in full space (exact forces).
    Full(ErrorModel),
    /// The same in the error directions beside the basis, on the error model's cubature.
    Directions(DirectionModel),
    /// None: a run in full space throughout ([`crate::physics::setup::adaptive_basis::full_throughout`])
    /// adds no error of its own (on cloth 100 x 100 the full-space model's
    /// sparse analysis took 55 ms at set-up, and a process making only it
    /// peaked at 37 MB).
    None,
}

impl Estimator {
    /// The model for `chosen` beside `basis`, and its zero state.
    pub fn new(scene: &Scene, chosen: &Chosen, basis: &ModalBasis) -> Result<(Self, ErrorState), PhysicsError> {
        Ok(match &chosen.choice.error_set {
            None => (
                Estimator::Full(ErrorModel::new(&scene.dof_mass, chosen.pattern.clone(), chosen.stiffness.clone(), scene.rest.len())?),
                ErrorState::zero(scene.n_dofs()),
            ),
            Some(set) => {
                let model = Self::directions(scene, chosen, basis, set);
                let k = model.directions();
                (Estimator::Directions(model), ErrorState::zero(k))
            }
        })
    }

    pub fn directions(scene: &Scene, chosen: &Chosen, basis: &ModalBasis, set: &SpringSet) -> DirectionModel {
        let directions = error_directions(&scene.dof_mass, basis, &chosen.choice.error_directions);
        DirectionModel::new(scene, &directions, set, &chosen.data.point)
    }

    /// ‖e‖²_M of `s`.
    pub fn norm_sq(&self, s: &ErrorState) -> f64 {
        match self {
            Estimator::Full(m) => m.norm_sq(s),
            Estimator::Directions(_) => s.e.iter().map(|z| z * z).sum(),
            Estimator::None => 0.0,
        }
    }
}
