//! The inner runs of an adaptive run: their settings, the modal run of a
//! basis, a run resumed from a state of the other one, and the mass-weighted
//! motion of the slots that scales the tolerance.

use crate::physics::error::PhysicsError;
use crate::physics::run::integrator::Scheme;
use crate::physics::run::simulator::Run;
use crate::physics::run::space::{Modal, Readout, ReducedForce};
use crate::physics::run::state::{Loads, State};
use crate::physics::settings::{ModeSelection, Reduction, Settings};
use crate::physics::setup::scene::Scene;
use crate::physics::setup::setup_data::SetupData;

/// The settings of an inner run: `reduction` on `n_modes` trained vectors.
pub(super) fn inner_settings(settings: &Settings, reduction: Reduction, n_modes: usize) -> Settings {
    Settings { reduction, n_modes, mode_selection: ModeSelection::Trained, ..settings.clone() }
}

/// The modal run of `data` under the host's `loads` (every weight 1).
pub(super) fn reduced_run<F: ReducedForce, R: Scheme>(
    scene: &Scene,
    settings: &Settings,
    loads: &Loads,
    data: &SetupData,
) -> Result<Run<Modal<F>, R>, PhysicsError> {
    let r = data.basis.r;
    let s = inner_settings(settings, Reduction::Modal, r);
    let l = Loads { mode_weights: vec![1.0; r], ..loads.clone() };
    Run::new(Modal::<F>::new(scene.clone(), &l, &s, Some(data))?, &s, &l)
}

/// Each slot's mass in the motion: a free node's; for a held node that of
/// the free nodes (the nodes of a grid all weigh the same); none for a slot
/// that is no node (an auxiliary spring's point), as E counts the nodes only.
pub(super) fn slot_masses(scene: &Scene) -> Vec<f64> {
    let typical = scene.dof_mass.first().copied().unwrap_or(1.0);
    let mut mass = vec![0.0; scene.rest.len() / scene.dim];
    for &s in &scene.slot_of_node {
        mass[s] = if s < scene.n_free { scene.dof_mass[s * scene.dim] } else { typical };
    }
    mass
}

/// Σ m |x − x0|² over the slots of dimension `d`.
pub(super) fn slot_motion(x: &[f64], start: &[f64], mass: &[f64], d: usize) -> f64 {
    x.chunks_exact(d).zip(start.chunks_exact(d)).zip(mass).map(|((a, b), m)| m * a.iter().zip(b).map(|(p, q)| (p - q).powi(2)).sum::<f64>()).sum()
}

impl<S: Readout, I: Scheme> Run<S, I> {
    /// Continues from `s` under the run's loads: its accelerations made
    /// those of the state with `settle` (a state from elsewhere), kept otherwise (a state of this run).
    pub(super) fn resume(&mut self, s: &State, settle: bool) {
        self.state.copy_from(s);
        self.resume_own(settle);
    }

    /// [`Self::resume`] from the state the run holds now.
    pub(super) fn resume_own(&mut self, settle: bool) {
        self.apply_loads();
        self.place_holders_now();
        if settle {
            self.settle_state();
        } else {
            self.evaluate_forces();
        }
        self.refresh_outputs();
    }
}
