//! The return from full space: the basis grown from the stretch (or the
//! chosen one, with cubature forces), tested against the stretch's poses,
//! the state's velocity and the residual the error directions see; the
//! reduced run resumed at q = Φᵀ M (x − x*), q' = Φᵀ M v.

use super::runs::reduced_run;
use super::unseen::unseen_share_sq;
use super::{Adaptive, LONGEST_STRETCH};
use crate::physics::error::PhysicsError;
use crate::physics::run::integrator::Scheme;
use crate::physics::run::simulator::estimators::Estimator;
use crate::physics::run::simulator::{Run, Switch};
use crate::physics::run::space::{Constants, Modal, ReducedForce};
use crate::physics::run::state::Loads;
use crate::physics::setup::adaptive_basis::{self, CAP_FACTOR, GROWTH, PROJECTION_SHARE};
use crate::physics::setup::basis;
use crate::physics::setup::modes::ModalBasis;

impl<F: ReducedForce, R: Scheme, X: Scheme> Adaptive<F, R, X> {
    /// Grows the basis from the stretch and returns to it if it holds the
    /// state; else the next stretch is twice as long (see the module documentation).
    pub(super) fn try_return(&mut self) -> Result<(), PhysicsError> {
        if !self.reduces() || self.outside_program() {
            self.stretch = 0;
            return Ok(());
        }
        let scene = self.full.space.scene().clone();
        let size = self.chosen.data.basis.r;
        let count = ((GROWTH * size as f64).ceil() as usize).max(1);
        // With cubature forces the basis does not grow: the spring set is
        // trained for the chosen basis and its error directions, and on a
        // grown basis the reduced run leaves the physics within a few steps
        // (cloth 100 x 100: the force residual 6.6 times the load five steps after a return).
        let cubature = self.chosen.choice.error_set.is_some();
        let grown = if cubature {
            Vec::new()
        } else {
            let current = self.reduced.space.basis().clone();
            let new = adaptive_basis::new_directions(&scene, &current, self.seen(), count)?;
            let mut grown = self.grown.clone();
            grown.extend(new);
            let cap = (CAP_FACTOR * size).min(scene.n_dofs());
            while self.chosen.trained.len() + grown.len() > cap && !grown.is_empty() {
                grown.remove(0);
            }
            grown
        };
        // The basis must hold the stretch's poses and the state's velocity
        // (each to the projection share of the tolerance, of the motion and
        // of the velocity's own size). With cubature forces the basis is the
        // chosen one, tested before its run is made; a grown basis is tested
        // first on its span alone (the M-orthonormalized vectors), which is
        // cheap against making a basis and a run of it, failing only by more
        // than round-off (SPAN_SLACK), then on the basis made.
        let mass = &scene.dof_mass;
        let motion = self.motion_sq().max(self.chosen.choice.motion_scale.powi(2));
        let share_sq = (PROJECTION_SHARE * self.tolerance()).powi(2);
        let v = &self.full.state.v;
        let speed: f64 = (0..v.len()).map(|i| mass[i] * v[i] * v[i]).sum();
        let holds = |left: &dyn Fn(&[f64]) -> f64, slack: f64| -> bool {
            left(v) <= slack * share_sq * speed && self.seen().iter().all(|s| left(s) <= slack * share_sq * motion)
        };
        let span_holds = if cubature {
            let basis = &self.chosen.data.basis;
            holds(&|s| basis_left_out_sq(basis, mass, s), 1.0)
        } else {
            let vectors: Vec<Vec<f64>> = self.chosen.trained.iter().chain(&grown).cloned().collect();
            let span = basis::m_orthonormal_span(mass, &vectors, vectors.len());
            holds(&|s| basis::left_out_sq(mass, span.as_ref(), s), SPAN_SLACK)
        };
        if !span_holds {
            self.failed_return();
            return Ok(());
        }
        let mut reduced =
            if cubature { reduced_run(&scene, &self.chosen.settings, &self.loads, &self.chosen.data)? } else { self.grown_run(&grown, &self.loads)? };
        let basis = reduced.space.basis().clone();
        if !cubature && !holds(&|s| basis_left_out_sq(&basis, mass, s), 1.0) {
            self.failed_return();
            return Ok(());
        }
        // q = Φᵀ M (x − x*), q' = Φᵀ M v; what the basis leaves out is the return's error.
        let pose = self.pose();
        let r = basis.r;
        let mut s = reduced.state.clone();
        basis.project_displacement(mass, &pose, &mut s.y);
        basis.project_displacement(mass, &self.full.state.v, &mut s.v);
        s.copy_frame_from(&self.full.state);
        let (mut left, mut left_rate) = (pose.clone(), self.full.state.v.clone());
        for (i, (l, lr)) in left.iter_mut().zip(&mut left_rate).enumerate() {
            let row = &basis.phi[i * r..(i + 1) * r];
            *l -= row.iter().zip(&s.y).map(|(p, q)| p * q).sum::<f64>();
            *lr -= row.iter().zip(&s.v).map(|(p, q)| p * q).sum::<f64>();
        }
        reduced.resume(&s, true);
        // And the residual there must be one the error directions beside it see.
        let (mut built, mut share) = (None, 0.0);
        if let Some(set) = &self.chosen.choice.error_set {
            let mut model = Estimator::directions(&scene, &self.chosen, &basis, set);
            let u = unseen_share_sq(&mut reduced, &mut model, &mut self.residual);
            if u > self.unseen_limit_sq() {
                self.failed_return();
                return Ok(());
            }
            (built, share) = (Some(model), u);
        }
        self.error_from_twin();
        self.twin_live = false;
        self.carry_error(&basis, built, &left, &left_rate);
        self.rewind = s;
        self.reduced = reduced;
        self.kick_q = vec![0.0; self.reduced.space.basis().r];
        self.grown = grown;
        self.set_motion_reference();
        self.in_full = false;
        self.unseen_last = share;
        self.stretch = 0;
        self.estimate_soon();
        self.report_basis();
        self.switched(Switch::Return { time: self.full.state.time, vectors: self.reduced.space.basis().r });
        Ok(())
    }
}

impl<F: ReducedForce, R: Scheme, X: Scheme> Adaptive<F, R, X> {
    /// A return that did not take (or did not hold): the next stretch in
    /// full space is twice as long, at most [`LONGEST_STRETCH`].
    pub(super) fn failed_return(&mut self) {
        self.stretch = 0;
        self.stretch_target = (2 * self.stretch_target).min(LONGEST_STRETCH);
    }

    /// The modal run on the trained vectors and `grown` under `loads`;
    /// with none grown, on the set-up's basis itself (a basis made again
    /// from its own vectors spans the same space, but its vectors may come
    /// out turned or of opposite sign, and a state's modal coordinates,
    /// kept in the set-up's basis, would then place the sheet elsewhere).
    pub(super) fn grown_run(&self, grown: &[Vec<f64>], loads: &Loads) -> Result<Run<Modal<F>, R>, PhysicsError> {
        let scene = self.full.space.scene();
        if grown.is_empty() {
            return reduced_run(scene, &self.chosen.settings, loads, &self.chosen.data);
        }
        let vectors: Vec<Vec<f64>> = self.chosen.trained.iter().chain(grown).cloned().collect();
        let data = adaptive_basis::grown_setup(scene, &self.chosen, &vectors)?;
        reduced_run(scene, &self.chosen.settings, loads, &data)
    }
}

/// A span fails the return's test before a basis is made of it only where
/// what it leaves out passes the limit by this factor: the two ways of
/// computing it differ by round-off, and the basis made decides.
const SPAN_SLACK: f64 = 1.01;

/// ‖s − Φ Φᵀ M s‖²_M for the M-orthonormal `basis`, as the return has always measured it.
fn basis_left_out_sq(basis: &ModalBasis, mass: &[f64], s: &[f64]) -> f64 {
    let mut q = vec![0.0; basis.r];
    basis.project_displacement(mass, s, &mut q);
    (0..s.len()).map(|i| mass[i] * (s[i] - basis.phi[i * basis.r..(i + 1) * basis.r].iter().zip(&q).map(|(p, q)| p * q).sum::<f64>()).powi(2)).sum()
}
