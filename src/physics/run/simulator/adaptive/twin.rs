//! The error carried into full space, moved on by a twin of the full-space
//! run (`docs/method.md`, section 10).
//!
//! On a fall-back the run continues from the lifted state x, x' while the
//! full-space trajectory it approximates is at x + e, x' + e', e the error
//! the model estimated for the reduced stretch. Full space adds no error of
//! its own; the one carried moves on as two full-space trajectories that
//! start e apart do:
//!
//! ```text
//! e(t + h) = S_h(x + e, x' + e') − S_h(x, x'),
//! ```
//!
//! S_h the full-space step. The twin starts at x + e on the fall-back and
//! then goes on from its own state beside the run, each taking every
//! communication step; e is their distance, formed only where it is needed
//! (‖e‖²_M for the estimate, e, e', e'' on a return). An FMU state taken in
//! full space with an error carried holds the twin's own state (format 11),
//! so a restored run goes on bit for bit: the run's state plus e would give
//! the twin back bit for bit in 1 of 424 steps (cloth 30 x 30). A state of
//! format 10 or older holds e: the twin is made again at x + e from it, as
//! after its own failed step. It
//! follows the growth of an error in a swing the linearized model cannot
//! (a compressed spring's negative stiffness, which the error model leaves
//! out, drives it), in part: cloth 30 x 30 with gravity turned sideways at
//! 0.25 s (1/240 s steps, as the study's `cloth-3d-turned`): at 0.67 s the
//! estimate reads 0.27 of E (the linearized model's 0.09); the error carried
//! at the turn is half the true one and points elsewhere, and the swing
//! grows the true one 50x, the twin's 21x.
//! Cost: one more full-space step per communication step while an error is
//! carried, and n operations for ‖e‖²_M; nothing while none is (a run that
//! falls back from its first step, as on loads outside its program).
//! Making the twin again from x + e at every step and e of all three
//! vectors after it (before format 11) cost a pass over every spring and
//! 15 n memory operations more: on cloth 100 x 100 (canonical load, damped,
//! 2 s of 1/240 s steps, falling back near 1 s) the run took 0.58 s against
//! 0.40 s now and 0.24-0.27 s for full space alone.

use super::{copy_loads, inner_settings, Adaptive};
use crate::physics::error::PhysicsError;
use crate::physics::run::error_model::ErrorState;
use crate::physics::run::integrator::Scheme;
use crate::physics::run::simulator::estimators::Estimator;
use crate::physics::run::simulator::{Run, Steps};
use crate::physics::run::space::{Constants, Full, ReducedForce};
use crate::physics::run::state::{Loads, State};
use crate::physics::settings::{Reduction, Settings};

impl<F: ReducedForce, R: Scheme, X: Scheme> Adaptive<F, R, X> {
    /// An error is carried (the twin goes on beside the run, or any of e, e', e'' is not zero).
    pub(super) fn carries_error(&self) -> bool {
        self.twin_live || self.error.e.iter().chain(&self.error.v).chain(&self.error.a).any(|x| *x != 0.0)
    }

    /// On a fall-back, after the run took the lifted state: the error
    /// carried, over the free DOFs (in error directions, Ψ z and Ψ z'), and
    /// the twin at x + e, x' + e', its accelerations made as the run's are,
    /// so its steps start as the run's do; the twin goes on from there (e
    /// is then their distance, formed where it is needed).
    pub(super) fn error_into_full(&mut self) {
        self.twin_live = false;
        if let Estimator::Directions(m) = &self.model {
            let n = self.full.state.y.len();
            if self.carried.e.len() != n {
                self.carried = ErrorState::zero(n);
            }
            let c = &mut self.carried;
            m.error_into(&self.error, &mut c.e, &mut c.v);
            c.a.fill(0.0);
            // The error in directions is kept in `carried` until the return.
            std::mem::swap(&mut self.error, &mut self.carried);
        }
        self.twin_live = self.carries_error() && self.twin_at(true).is_ok();
    }

    /// ‖e‖²_M over the free DOFs (the error in full space, whatever the
    /// model): with the twin going on, of e = x_twin − x, else of the e kept.
    pub(super) fn full_error_sq(&self) -> f64 {
        let mass = &self.full.space.scene().dof_mass;
        match self.live_twin() {
            Some(t) => mass.iter().zip(&t.state.y).zip(&self.full.state.y).map(|((m, t), x)| m * (t - x) * (t - x)).sum(),
            None => mass.iter().zip(&self.error.e).map(|(m, e)| m * e * e).sum(),
        }
    }

    /// The twin, where it goes on beside the run (e is then its distance to the run, not kept).
    pub(super) fn live_twin(&self) -> Option<&Run<Full, X>> {
        self.twin.as_deref().filter(|_| self.twin_live)
    }

    /// e, e', e'' = the twin's state less the run's, where the twin goes on
    /// (before the error leaves full space: a return).
    pub(super) fn error_from_twin(&mut self) {
        if let Some(twin) = self.twin.as_deref().filter(|_| self.twin_live) {
            error_between(&twin.state, &self.full.state, &mut self.error);
        }
    }

    /// One communication step of `h` in full space with the error carried
    /// (`carrying`, [`Self::carries_error`]): the run's step and the twin's.
    /// The twin goes on from its own state; where it does not (after a
    /// serialized state of format 10 or older, or its own failed step) it
    /// is made again at the run's state plus e first. The run's step failing
    /// leaves the run and the twin at the step's start; the twin's failing
    /// leaves e as it was at the step's start, and the next step makes the
    /// twin again from it.
    pub(super) fn step_full_carrying(&mut self, h: f64, carrying: bool) -> Result<(), PhysicsError> {
        if !carrying {
            return self.full.do_step(h);
        }
        if !self.twin_live {
            let twin_moved = self.twin_at(false).and_then(|twin| twin.do_step(h)).is_ok();
            self.full.do_step(h)?;
            self.twin_live = twin_moved;
            return Ok(());
        }
        self.full.do_step(h)?;
        let host = &self.loads;
        if let Some(twin) = self.twin.as_deref_mut() {
            let moved = twin.edit_loads(&mut |l| copy_loads(l, host)).and_then(|()| twin.do_step(h));
            if moved.is_err() {
                // Both at the step's start: the twin back where it was, the run's start kept in its backup.
                error_between(&twin.state, &self.full.backup, &mut self.error);
                self.twin_live = false;
            }
        }
        Ok(())
    }

    /// The twin at the run's state plus the error, under the host's loads,
    /// resumed there: its accelerations made those of its state with
    /// `settle`, else x'' + e''.
    fn twin_at(&mut self, settle: bool) -> Result<&mut Run<Full, X>, PhysicsError> {
        let Some(twin) = self.twin.as_deref_mut() else {
            return Err(PhysicsError::AdaptiveState { why: "a run that never reduces carries no error" });
        };
        let host = &self.loads;
        twin.edit_loads(&mut |l| copy_loads(l, host))?;
        let (s, e) = (&self.full.state, &self.error);
        let t = &mut twin.state;
        t.copy_from(s);
        t.y.iter_mut().zip(&e.e).for_each(|(y, e)| *y += e);
        t.v.iter_mut().zip(&e.v).for_each(|(v, e)| *v += e);
        t.a.iter_mut().zip(&e.a).for_each(|(a, e)| *a += e);
        twin.resume_own(settle);
        Ok(twin)
    }

    /// A restored twin (a serialized state of format 11 in full space with
    /// an error carried): its y, y', y'' `twin`, the rest of its state the
    /// run's, under the host's loads, resumed there; e is its distance to the run.
    pub(super) fn restore_twin(&mut self, twin_state: &[Vec<f64>; 3]) -> Result<(), PhysicsError> {
        let Some(twin) = self.twin.as_deref_mut() else {
            return Err(PhysicsError::AdaptiveState { why: "a run that never reduces has no twin to restore" });
        };
        let host = &self.loads;
        twin.edit_loads(&mut |l| copy_loads(l, host))?;
        let t = &mut twin.state;
        t.copy_from(&self.full.state);
        t.y.copy_from_slice(&twin_state[0]);
        t.v.copy_from_slice(&twin_state[1]);
        t.a.copy_from_slice(&twin_state[2]);
        twin.resume_own(false);
        error_between(&twin.state, &self.full.state, &mut self.error);
        self.twin_live = true;
        Ok(())
    }
}

/// e, e', e'' = `twin` less `run`, DOF by DOF.
fn error_between(twin: &State, run: &State, e: &mut ErrorState) {
    for (d, (t, s)) in [(&mut e.e, (&twin.y, &run.y)), (&mut e.v, (&twin.v, &run.v)), (&mut e.a, (&twin.a, &run.a))] {
        d.iter_mut().zip(t.iter().zip(s.iter())).for_each(|(d, (t, s))| *d = t - s);
    }
}

/// The twin of a run's full-space run (a run that reduces has one from set-up:
/// a fall-back allocates nothing).
pub(super) fn make_twin<X: Scheme>(full: &Run<Full, X>, settings: &Settings, loads: &Loads) -> Result<Box<Run<Full, X>>, PhysicsError> {
    let settings = inner_settings(settings, Reduction::Full, 0);
    let loads = Loads { mode_weights: Vec::new(), ..loads.clone() };
    Ok(Box::new(Run::new(Full::new(full.space.scene().clone(), &loads, &settings)?, &settings, &loads)?))
}
