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
//! S_h the full-space step. The twin takes that step from x + e each
//! communication step (rebuilt from the run's state and e, so a restored
//! FMU state goes on bit for bit), and the difference is the new e. Between
//! its own steps the twin is only set to x + e: its forces are not evaluated
//! there again, as no Newmark step reads the forces at its start (the
//! trigonometric scheme evaluates its filtered force there anyway), and its
//! step guard weighs the energy its own last step ended with (x + e up to
//! round-off); after a fall-back, a restore or a failed step it is resumed
//! in full once (forces and energy at x + e). It
//! follows the growth of an error in a swing the linearized model cannot
//! (a compressed spring's negative stiffness, which the error model leaves
//! out, drives it), in part: cloth 30 x 30 with gravity turned sideways at
//! 0.25 s (1/240 s steps, as the study's `cloth-3d-turned`): at 0.67 s the
//! estimate reads 0.27 of E (the linearized model's 0.09); the error carried
//! at the turn is half the true one and points elsewhere, and the swing
//! grows the true one 50x, the twin's 21x.
//! Cost: one more full-space step per communication step while an error is
//! carried (and 6 n additions to set the twin); nothing while none is
//! (a run that falls back from its first step, as on loads outside its program).

use super::{copy_loads, inner_settings, Adaptive};
use crate::physics::error::PhysicsError;
use crate::physics::run::error_model::ErrorState;
use crate::physics::run::integrator::Scheme;
use crate::physics::run::simulator::estimators::Estimator;
use crate::physics::run::simulator::{Run, Steps};
use crate::physics::run::space::{Constants, Full, ReducedForce};
use crate::physics::run::state::Loads;
use crate::physics::settings::{Reduction, Settings};

impl<F: ReducedForce, R: Scheme, X: Scheme> Adaptive<F, R, X> {
    /// An error is carried (any of e, e', e'' is not zero).
    pub(super) fn carries_error(&self) -> bool {
        self.error.e.iter().chain(&self.error.v).chain(&self.error.a).any(|x| *x != 0.0)
    }

    /// On a fall-back, after the run took the lifted state: the error
    /// carried, over the free DOFs (in error directions, Ψ z and Ψ z'), and
    /// e'' = x''(x + e, x' + e') − x''(x, x'), both accelerations made the
    /// same way, so the twin's steps start as the run's do.
    pub(super) fn error_into_full(&mut self) {
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
        if self.carries_error() && self.twin_at(true).is_ok() {
            if let Some(twin) = self.twin.as_deref() {
                for (i, a) in self.error.a.iter_mut().enumerate() {
                    *a = twin.state.a[i] - self.full.state.a[i];
                }
            }
        }
    }

    /// ‖e‖²_M over the free DOFs (the error in full space, whatever the model).
    pub(super) fn full_error_sq(&self) -> f64 {
        let mass = &self.full.space.scene().dof_mass;
        mass.iter().zip(&self.error.e).map(|(m, e)| m * e * e).sum()
    }

    /// One communication step of `h` in full space with the error carried
    /// (`carrying`, [`Self::carries_error`]): the twin's step from the state plus e, the run's own, and e the
    /// difference. The twin failing leaves e as it was; the run's own
    /// failing leaves the run and e at the step's start.
    pub(super) fn step_full_carrying(&mut self, h: f64, carrying: bool) -> Result<(), PhysicsError> {
        if !carrying {
            return self.full.do_step(h);
        }
        let twin_moved = self.twin_at(false).and_then(|twin| twin.do_step(h)).is_ok();
        self.twin_fresh = twin_moved;
        self.full.do_step(h)?;
        if let (true, Some(twin)) = (twin_moved, self.twin.as_deref()) {
            let (t, s) = (&twin.state, &self.full.state);
            for (i, e) in self.error.e.iter_mut().enumerate() {
                *e = t.y[i] - s.y[i];
            }
            for (i, v) in self.error.v.iter_mut().enumerate() {
                *v = t.v[i] - s.v[i];
            }
            for (i, a) in self.error.a.iter_mut().enumerate() {
                *a = t.a[i] - s.a[i];
            }
        }
        Ok(())
    }

    /// The twin at the run's state plus the error, under
    /// the host's loads; its accelerations made those of its state with
    /// `settle`, else x'' + e''. Right after its own step (`twin_fresh`)
    /// only its state is set ([`Run::resume_near`]), else it is resumed in full.
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
        if settle || !self.twin_fresh {
            twin.resume_own(settle);
        } else {
            twin.resume_near();
        }
        Ok(twin)
    }
}

/// The twin of a run's full-space run (a run that reduces has one from set-up:
/// a fall-back allocates nothing).
pub(super) fn make_twin<X: Scheme>(full: &Run<Full, X>, settings: &Settings, loads: &Loads) -> Result<Box<Run<Full, X>>, PhysicsError> {
    let settings = inner_settings(settings, Reduction::Full, 0);
    let loads = Loads { mode_weights: Vec::new(), ..loads.clone() };
    Ok(Box::new(Run::new(Full::new(full.space.scene().clone(), &loads, &settings)?, &settings, &loads)?))
}
