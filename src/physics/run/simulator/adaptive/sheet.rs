//! What the model and the tests use of an adaptive run: [`Steps`],
//! [`Reads`] and [`SetUp`], each answered by the run that steps now.

use super::{copy_loads, unweighted, Adaptive, CAP_FACTOR, KEPT_POSES, LONGEST_STRETCH};
use crate::physics::error::{positive, PhysicsError, Quantity};
use crate::physics::run::error_model::ErrorState;
use crate::physics::run::integrator::Scheme;
use crate::physics::run::simulator::estimators::Estimator;
use crate::physics::run::simulator::{FallBackCause, Reads, ReductionStatus, SetUp, Steps, Switch};
use crate::physics::run::space::ReducedForce;
use crate::physics::run::state::{AdaptivePart, Loads, Snapshot};
use crate::physics::settings::Settings;
use crate::physics::setup::mode_classes::ModeClasses;
use crate::physics::setup::modes::ModalBasis;
use crate::physics::setup::scene::Scene;
use crate::physics::setup::setup_data::SetupData;

impl<F: ReducedForce, R: Scheme, X: Scheme> Steps for Adaptive<F, R, X> {
    fn max_stable_step(&self) -> f64 {
        self.active().max_stable_step()
    }

    fn do_step(&mut self, h: f64) -> Result<(), PhysicsError> {
        positive(Quantity::StepSize, h)?;
        let before = self.tally.steps;
        self.step_either(h)?;
        // The internal steps this call took, in whichever runs took them (a return starts a new reduced run).
        self.last_steps = (self.tally.steps - before) as usize;
        Ok(())
    }

    fn scene(&self) -> &Scene {
        self.reduced.scene()
    }

    fn time(&self) -> f64 {
        self.active().time()
    }

    fn n_dofs(&self) -> usize {
        self.reduced.n_dofs()
    }

    fn loads(&self) -> &Loads {
        &self.loads
    }

    fn settings(&self) -> &Settings {
        &self.settings
    }

    fn internal_steps_last(&self) -> usize {
        self.last_steps
    }

    fn edit_loads(&mut self, edit: &mut dyn FnMut(&mut Loads)) -> Result<(), PhysicsError> {
        self.spare.clone_from(&self.loads);
        edit(&mut self.loads);
        let checked =
            self.loads.validate(self.settings.n_modes).and_then(|()| self.loads.validate_on(self.reduced.scene())).and_then(|()| unweighted(&self.loads));
        let caught_up = if checked.is_ok() { self.estimate_before_leaving() } else { None };
        let host = &self.loads;
        let applied =
            checked.and_then(|()| self.reduced.edit_loads(&mut |l| copy_loads(l, host))).and_then(|()| self.full.edit_loads(&mut |l| copy_loads(l, host)));
        if let Err(e) = applied {
            std::mem::swap(&mut self.loads, &mut self.spare);
            let host = &self.loads;
            // Both runs accept the loads they had.
            let _ = self.reduced.edit_loads(&mut |l| copy_loads(l, host));
            let _ = self.full.edit_loads(&mut |l| copy_loads(l, host));
            if let Some(kept) = caught_up {
                self.undo_estimate(kept);
            }
            return Err(e);
        }
        if !self.loads.same_but_anchor(&self.spare) {
            self.estimate_soon();
        }
        Ok(())
    }

    fn displace(&mut self, dy: &[f64]) -> Result<(), PhysicsError> {
        self.active_mut().displace(dy)?;
        self.coordinates_fresh = false;
        Ok(())
    }

    fn displace_dofs(&mut self, dy: &[f64]) -> Result<(), PhysicsError> {
        self.active_mut().displace_dofs(dy)?;
        self.coordinates_fresh = false;
        Ok(())
    }

    fn snapshot(&self) -> Snapshot {
        let mut s = self.active().snapshot();
        s.loads = self.loads.clone();
        // With the twin going on, its own state (e is its distance to the run).
        let error = match self.live_twin() {
            Some(t) => [t.state.y.clone(), t.state.v.clone(), t.state.a.clone()],
            None => [self.error.e.clone(), self.error.v.clone(), self.error.a.clone()],
        };
        s.adaptive = Some(Box::new(AdaptivePart {
            in_full: self.in_full,
            twin: self.live_twin().is_some(),
            error,
            sums: [self.tally.error_sq, self.tally.motion_sq, self.last_error_sq, self.last_motion_sq, self.since, self.unseen_last],
            counts: [self.tally.reduced_steps, self.tally.steps, self.gap, self.period, self.wait],
            stretch: [self.stretch as u64, self.stretch_target as u64, self.seen_next as u64],
            seen: self.seen().to_vec(),
            grown: self.grown.clone(),
            linearized: match &self.model {
                Estimator::Full(m) => m.linearized_at().to_vec(),
                Estimator::Directions(_) | Estimator::None => Vec::new(),
            },
        }));
        s
    }

    /// Resumes from a snapshot of an adaptive run of the same scene and
    /// settings, in the mode and on the basis it had: a basis grown
    /// otherwise than this run's is built again from the vectors (as the run
    /// that grew it did). All or nothing.
    fn restore(&mut self, s: &Snapshot) -> Result<(), PhysicsError> {
        let refuse = |why| Err(PhysicsError::AdaptiveState { why });
        let Some(part) = s.adaptive.as_deref() else {
            return refuse("it is not a state of an adaptive run");
        };
        let n = self.reduced.scene().n_dofs();
        let [stretch, target, next] = part.stretch.map(|c| usize::try_from(c).unwrap_or(usize::MAX));
        let cap = (CAP_FACTOR * self.chosen.data.basis.r).min(n);
        // The poses and grown vectors first (a basis is built from them); the error's length depends on that basis.
        if !part.seen.iter().chain(&part.grown).all(|v| v.len() == n)
            || part.seen.len() > KEPT_POSES
            || next >= KEPT_POSES
            || !(1..=LONGEST_STRETCH).contains(&target)
            || stretch > LONGEST_STRETCH
            || part.counts[2] == 0
            || part.counts[3] == 0
            || part.counts[0] > part.counts[1]
            || self.chosen.trained.len() + part.grown.len() > cap
            || part.sums.iter().any(|x| *x < 0.0)
            || (part.twin && !(part.in_full && self.reduces()))
        {
            return refuse("its adaptive part does not fit this scene (corrupt or of another set-up)");
        }
        s.loads.validate(self.settings.n_modes)?;
        // The basis the state grew to, built as the run that grew it built it.
        let mut rebuilt = None;
        if part.grown != self.grown {
            rebuilt = Some(self.grown_run(&part.grown, &s.loads)?);
        }
        // The error model beside that basis (in error directions it depends on the basis).
        let model = match (&rebuilt, &self.model) {
            (Some(run), Estimator::Directions(_)) => Some(Estimator::new(self.reduced.scene(), &self.chosen, run.space.basis())?.0),
            _ => None,
        };
        // In full space the error is over the free DOFs (twin.rs).
        let error_len = match model.as_ref().unwrap_or(&self.model) {
            _ if part.in_full => n,
            Estimator::Directions(m) => m.directions(),
            Estimator::Full(_) | Estimator::None => n,
        };
        let slot_values = self.reduced.scene().rest.len();
        if !part.fits(n, error_len) || !(part.linearized.is_empty() || part.linearized.len() == slot_values) {
            return refuse("its adaptive part does not fit this scene (corrupt or of another set-up)");
        }
        let inner = |weights: Vec<f64>| Snapshot { state: s.state.clone(), loads: Loads { mode_weights: weights, ..s.loads.clone() }, adaptive: None };
        if part.in_full {
            self.full.restore(&inner(Vec::new()))?;
        } else {
            let target = rebuilt.as_mut().unwrap_or(&mut self.reduced);
            let r = target.space.basis().r;
            target.restore(&inner(vec![1.0; r]))?;
        }
        if let Some(run) = rebuilt {
            self.reduced = run;
            self.rewind = self.reduced.state.clone();
            self.kick_q = vec![0.0; self.reduced.space.basis().r];
            self.grown = part.grown.clone();
            self.set_motion_reference();
            self.report_basis();
        }
        if let Some(model) = model {
            self.model = model;
        }
        if let Estimator::Full(m) = &mut self.model {
            m.linearize_as(self.reduced.scene(), &part.linearized);
        }
        self.in_full = part.in_full;
        let [e, v, a] = &part.error;
        self.error = ErrorState { e: e.clone(), v: v.clone(), a: a.clone() };
        self.spare_error = self.error.clone();
        self.no_error = false;
        self.twin_live = false;
        if self.carried.e.len() != n {
            self.carried = ErrorState::zero(n);
        }
        [self.tally.error_sq, self.tally.motion_sq, self.last_error_sq, self.last_motion_sq, self.since, self.unseen_last] = part.sums;
        [self.tally.reduced_steps, self.tally.steps, self.gap, self.period, self.wait] = part.counts;
        (self.stretch, self.stretch_target, self.seen_next) = (stretch, target, next);
        for (slot, pose) in self.seen.iter_mut().zip(&part.seen) {
            slot.copy_from_slice(pose);
        }
        self.seen_count = part.seen.len();
        copy_loads(&mut self.loads, &s.loads);
        self.loads.mode_weights.clone_from(&s.loads.mode_weights);
        self.loads.error_tolerance = s.loads.error_tolerance;
        if part.twin {
            // The loads the run accepted, and a twin of the fitting length: it cannot fail here.
            self.restore_twin(&part.error)?;
            self.spare_error = self.error.clone();
        }
        self.coordinates_fresh = false;
        Ok(())
    }
}

impl<F: ReducedForce, R: Scheme, X: Scheme> Reads for Adaptive<F, R, X> {
    fn positions(&mut self) -> &[f64] {
        self.active_mut().positions()
    }

    fn velocities(&mut self) -> &[f64] {
        self.active_mut().velocities()
    }

    fn load_node_position(&mut self) -> Option<[f64; 3]> {
        self.active_mut().load_node_position()
    }

    fn load_node_velocity(&mut self) -> Option<[f64; 3]> {
        self.active_mut().load_node_velocity()
    }

    fn anchor_force(&mut self) -> [f64; 3] {
        self.active_mut().anchor_force()
    }

    fn anchor_torque(&mut self) -> [f64; 3] {
        self.active_mut().anchor_torque()
    }

    fn holder_force(&mut self, k: usize) -> [f64; 3] {
        self.active_mut().holder_force(k)
    }

    fn holder_torque(&mut self, k: usize) -> [f64; 3] {
        self.active_mut().holder_torque(k)
    }

    fn kinetic_energy(&self) -> f64 {
        self.active().kinetic_energy()
    }

    fn potential_energy(&mut self) -> f64 {
        self.active_mut().potential_energy()
    }

    fn force_residual(&mut self) -> f64 {
        self.active_mut().force_residual()
    }

    fn modal_coordinates(&mut self) -> &[f64] {
        if !self.coordinates_fresh {
            self.report_coordinates();
            self.coordinates_fresh = true;
        }
        &self.coordinates
    }

    fn spring_force(&mut self, y: &[f64]) -> Result<Vec<f64>, PhysicsError> {
        self.active_mut().spring_force(y)
    }

    fn training_range(&self) -> f64 {
        self.active().training_range()
    }
}

impl<F: ReducedForce, R: Scheme, X: Scheme> SetUp for Adaptive<F, R, X> {
    fn mode_frequencies(&self) -> &[f64] {
        &self.frequencies
    }

    fn mode_shapes(&self) -> Option<&ModalBasis> {
        Some(&self.reported)
    }

    fn mode_classes(&self) -> ModeClasses {
        let mut c = self.reduced.mode_classes();
        c.out_of_plane.resize(self.reported.r, 0.0);
        c.symmetry.resize(self.reported.r, 0.0);
        c
    }

    fn mode_grid_shapes(&self) -> Vec<f64> {
        crate::physics::setup::mode_classes::grid_shapes(self.reduced.scene(), &self.reported)
    }

    /// What set-up chose (not the basis grown since): the trained basis with its adaptive section.
    fn setup_data(&self) -> Option<SetupData> {
        Some(self.chosen.stored())
    }

    fn cubature_springs(&self) -> usize {
        self.active().cubature_springs()
    }

    fn reduction_status(&self) -> ReductionStatus {
        ReductionStatus {
            error_estimate: self.tally.estimate(),
            reduced_fraction: self.tally.reduced_fraction(),
            basis_size: if self.in_full { self.reduced.n_dofs() } else { self.reduced.space.basis().r },
            chosen_size: self.chosen.data.basis.r,
            reduces: self.reduces(),
            why_full: self.why_full,
            error_directions: match &self.model {
                Estimator::Directions(m) => m.directions(),
                Estimator::Full(_) | Estimator::None => 0,
            },
            switches: self.switches,
            last_switch: self.last_switch,
        }
    }
}

impl<F: ReducedForce, R: Scheme, X: Scheme> Adaptive<F, R, X> {
    /// One communication step, reduced or in full space (see the module documentation).
    fn step_either(&mut self, h: f64) -> Result<(), PhysicsError> {
        // Any step, taken or failed, may move the state the coordinates are read from.
        self.coordinates_fresh = false;
        if self.in_full {
            return self.step_full(h);
        }
        if self.outside_program() {
            // A basis trained for other loads: full space from the start of the step.
            self.switched(Switch::FallBack { time: self.reduced.state.time, why: FallBackCause::OutsideProgram });
            self.lift();
            return self.step_full(h);
        }
        let due = self.wait + 1 >= self.gap.min(self.check_gap());
        if due {
            self.spare_error.copy_from(&self.error);
            self.spare_tally = self.tally;
        }
        self.kick_error(h);
        let (wait, since) = (self.wait, self.since);
        self.reduced.do_step(h)?;
        let steps = self.reduced.internal_steps_last as u64;
        self.tally.reduced_steps += steps;
        self.tally.steps += steps;
        self.wait += 1;
        self.since += h;
        if !due {
            self.held_reduced();
            return Ok(());
        }
        self.update_period(h);
        let estimated = self.estimate();
        let why = if estimated.is_ok() { self.fall_back_cause() } else { None };
        if estimated.is_ok() && why.is_none() {
            self.held_reduced();
            return Ok(());
        }
        // Undone, and taken again in full space from the lifted state.
        self.error.copy_from(&self.spare_error);
        self.tally = self.spare_tally;
        self.wait = wait;
        self.since = since;
        self.undo_reduced();
        estimated?;
        if let Some(why) = why {
            self.switched(Switch::FallBack { time: self.reduced.state.time, why });
        }
        self.shorter_than_the_stretch();
        self.lift();
        if let Err(e) = self.step_full(h) {
            self.in_full = false;
            self.twin_live = false;
            return Err(e);
        }
        Ok(())
    }
}

impl<F: ReducedForce, R: Scheme, X: Scheme> Adaptive<F, R, X> {
    /// Loads that leave the training program (`self.loads`, the ones before
    /// them in `spare`) make the next step fall back with the error
    /// estimated so far: the reduced steps since the last estimate are
    /// estimated first, under the loads they ran with (the reduced run's
    /// still), or the twin would start without the error they made (up to
    /// [`super::LONGEST_GAP`] steps of it). What the estimate changed, for
    /// [`Self::undo_estimate`] (the error's old value in `spare_error`); an
    /// estimate that fails leaves the run as it was.
    fn estimate_before_leaving(&mut self) -> Option<BeforeEstimate> {
        if self.in_full || !self.reduces() || self.wait == 0 || !self.outside_program() || self.outside(&self.spare) {
            return None;
        }
        self.spare_error.copy_from(&self.error);
        let kept = BeforeEstimate {
            tally: self.tally,
            counts: [self.wait, self.gap],
            sums: [self.since, self.last_error_sq, self.last_motion_sq, self.unseen_sq, self.unseen_last],
        };
        match self.estimate() {
            Ok(()) => Some(kept),
            Err(_) => {
                self.undo_estimate(kept);
                None
            }
        }
    }

    /// The run as it was before [`Self::estimate_before_leaving`].
    fn undo_estimate(&mut self, kept: BeforeEstimate) {
        self.error.copy_from(&self.spare_error);
        self.tally = kept.tally;
        [self.wait, self.gap] = kept.counts;
        [self.since, self.last_error_sq, self.last_motion_sq, self.unseen_sq, self.unseen_last] = kept.sums;
    }

    /// A reduced step held: counted in `stretch`, which counts the reduced
    /// steps since the return while the run is reduced (at most [`LONGEST_STRETCH`]).
    fn held_reduced(&mut self) {
        self.stretch = (self.stretch + 1).min(LONGEST_STRETCH);
    }

    /// Falling back after a return that held for fewer communication steps
    /// than the stretch in full space before it is asked to last: the return
    /// counts as failed, and the next stretch is twice as long. Without it a
    /// run whose basis keeps failing goes back and forth every few steps,
    /// paying for a basis and a run of it each time (cloth 30 x 30 at 1/240 s:
    /// 14x the full-space run's time).
    fn shorter_than_the_stretch(&mut self) {
        let returned = self.tally.steps > self.tally.reduced_steps;
        if returned && self.stretch < self.stretch_target {
            self.failed_return();
        }
    }
}

/// What an estimate changes besides the error ([`Adaptive::undo_estimate`];
/// the full-space error model's linearization point stays where the
/// estimate put it: every estimate linearizes again before it advances, so
/// no step reads it).
#[derive(Clone, Copy)]
struct BeforeEstimate {
    tally: super::Tally,
    counts: [u64; 2],
    sums: [f64; 5],
}
