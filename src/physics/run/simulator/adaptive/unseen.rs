//! The residual force an adaptive run's error directions do not see
//! (`docs/method.md`, section 10, "The force the error directions do not see").

use crate::physics::run::error_directions::DirectionModel;
use crate::physics::run::integrator::Scheme;
use crate::physics::run::simulator::Run;
use crate::physics::run::space::{Constants, Modal, ReducedForce};

/// The part of the reduced run's residual force the error directions of
/// `model` do not see, squared, over the load's squared size (M⁻¹ norms;
/// 0 without gravity or a point load): ‖r‖² − |Ψᵀ r|² = ‖f‖² − |Φᵀ f|² −
/// |Ψᵀ f|² (Ψᵀ M Φ = 0), one pass over every spring and n (r + k)
/// operations (see [`super::UNSEEN_PER_TOLERANCE`]).
pub(super) fn unseen_share_sq<F: ReducedForce, R: Scheme>(run: &mut Run<Modal<F>, R>, model: &mut DirectionModel, force: &mut [f64]) -> f64 {
    let felt = run.felt_loads();
    let (all, held) = run.space.loaded_force(&felt.gravity, &felt.point_load, &run.state.y, &mut run.work, force);
    run.current = false;
    let seen = model.seen_sq(force);
    let scene = run.space.scene();
    let d = scene.dim;
    let mut load_sq: f64 = scene.dof_mass.iter().enumerate().map(|(k, m)| m * felt.gravity[k % d].powi(2)).sum();
    if let Some((dof, f)) = run.work.as_ref().point_force_as(&felt.point_load, scene) {
        load_sq += f.iter().map(|p| p * p).sum::<f64>() / scene.dof_mass[dof];
    }
    if load_sq > 0.0 {
        (all - held - seen).max(0.0) / load_sq
    } else {
        0.0
    }
}
