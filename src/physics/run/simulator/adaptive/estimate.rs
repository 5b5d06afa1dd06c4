//! The estimate of an adaptive run, a holder's kicks in its error model
//! and the error a return carries ([`crate::physics::run::simulator::estimators`]).

use super::unseen::unseen_share_sq;
use super::{slot_motion, Adaptive};
use crate::physics::error::PhysicsError;
use crate::physics::run::error_directions::DirectionModel;
use crate::physics::run::error_model::ErrorState;
use crate::physics::run::integrator::Scheme;
use crate::physics::run::simulator::estimators::Estimator;
use crate::physics::run::simulator::Steps;
use crate::physics::run::space::{Constants, Readout, ReducedForce, Space};
use crate::physics::setup::modes::ModalBasis;

impl<F: ReducedForce, R: Scheme, X: Scheme> Adaptive<F, R, X> {
    /// The estimate over the `since` seconds since the last one: the error
    /// model's step under the residual at the state, at the tangent there
    /// (in full space: the error the twin moved on, [`super::twin`]);
    /// its ‖e‖² and the motion stand for the `wait` communication steps since the last estimate.
    pub(super) fn estimate(&mut self) -> Result<(), PhysicsError> {
        self.unseen_sq = 0.0;
        let watching = self.check_gap() < self.period;
        let d = self.reduced.space.scene().dim;
        // The motion from the slot positions the estimate has anyway.
        let mut motion = None;
        match &mut self.model {
            // In full space no error is added: the twin moves a carried one on (twin.rs).
            _ if self.in_full => {}
            Estimator::None => {}
            Estimator::Full(model) => {
                let felt = self.reduced.felt_loads();
                let q = &self.reduced.state.y;
                self.reduced.space.residual_force(&felt.gravity, &felt.point_load, q, &mut self.reduced.work, &mut self.residual);
                self.reduced.current = false;
                let x = self.reduced.space.positions(&self.reduced.state.y, &mut self.reduced.work);
                motion = Some(slot_motion(x, &self.start, &self.slot_mass, d));
                model.relinearize(self.reduced.space.scene(), x);
                model.advance(&mut self.error, self.since, &self.residual)?;
            }
            Estimator::Directions(model) => {
                let felt = self.reduced.felt_loads();
                // Once per longest gap between estimates (a pass over every spring,
                // about 3 full-space steps on cloth 100 x 100), and at each
                // estimate while its last share is near its limit (check_gap).
                if self.gap >= self.period || watching {
                    self.unseen_sq = unseen_share_sq(&mut self.reduced, model, &mut self.residual);
                    self.unseen_last = self.unseen_sq;
                }
                let space = &self.reduced.space;
                let scene = space.scene();
                let point = self.reduced.work.as_ref().point_force_as(&felt.point_load, scene).map(|(dof, f)| {
                    let mut p = [0.0; 3];
                    p[..f.len()].copy_from_slice(f);
                    (dof, p, f.len())
                });
                // The sampled springs' ends and the motion from q, without expanding x.
                let q = &self.reduced.state.y;
                let slots = space.slots_mut(&mut self.reduced.work);
                model.ends_modal(scene, space.basis(), &space.modes().point, q, slots);
                let n = space.basis().n;
                let free: f64 = q.iter().zip(&self.motion_reference).map(|(q, b)| q * q + 2.0 * q * b).sum::<f64>() + self.motion_offset;
                let held = slot_motion(&slots[n..], &self.start[n..], &self.slot_mass[n / d..], d);
                motion = Some(free.max(0.0) + held);
                let point = point.as_ref().map(|(dof, p, d)| (*dof, &p[..*d]));
                model.linearize(scene, Some((&felt.gravity, point)));
                model.advance(&mut self.error, self.since)?;
            }
        }
        self.last_error_sq = if self.in_full { self.full_error_sq() } else { self.model.norm_sq(&self.error) };
        self.last_motion_sq = match motion {
            Some(m) => m,
            None => self.motion_sq(),
        };
        let w = self.wait as f64;
        // The step error adds to the reduction's (independent of it, in square).
        self.tally.error_sq += w * (self.last_error_sq + self.step_error_sq());
        self.tally.motion_sq += w * self.last_motion_sq;
        self.wait = 0;
        self.since = 0.0;
        self.gap = (2 * self.gap).min(self.period);
        Ok(())
    }

    /// ‖e_h‖²_M of the scheme's own step error at the state (see
    /// [`Scheme::FREQUENCY_ERROR`]): e_h = c h_i² t j with h_i the internal
    /// step, t the time since the start and j the jerk over the last
    /// communication step, (a − a_start) / h: in full space with the mass
    /// of each DOF, in the modal space as |j| (the basis is M-orthonormal).
    /// Measured against full space at an eighth of the stable step (cloth 30 x 30,
    /// 0.6 s, explicit and implicit, 1/240 s and 0.01 s, four loads): 1.1 to 2.5x
    /// the step error of full space.
    pub(super) fn step_error_sq(&self) -> f64 {
        let (c, state, start, internal, mass) = if self.in_full {
            (X::FREQUENCY_ERROR, &self.full.state, &self.full.backup, self.full.internal_steps_last, Some(&self.full.space.scene().dof_mass))
        } else {
            (R::FREQUENCY_ERROR, &self.reduced.state, &self.reduced.backup, self.reduced.internal_steps_last, None)
        };
        let h = state.time - start.time;
        if c == 0.0 || !(h > 0.0) || internal == 0 {
            return 0.0;
        }
        let jerk_sq: f64 = match mass {
            Some(m) => state.a.iter().zip(&start.a).zip(m).map(|((a, b), m)| m * (a - b).powi(2)).sum::<f64>(),
            None => state.a.iter().zip(&start.a).map(|(a, b)| (a - b).powi(2)).sum::<f64>(),
        } / (h * h);
        let hi = h / internal as f64;
        (c * hi * hi * state.time).powi(2) * jerk_sq
    }

    /// The holder's translation changes its velocity at the start of a step
    /// (it moves at a constant rate to its target): every free node gets
    /// -Δc relative to it in full space, the reduced run only the part Φ Φᵀ M
    /// of that its basis holds. The rest, -(I - Φ Φᵀ M) Δc, is an error of
    /// the velocity, added to the error model's e' (a turning holder's
    /// kicks are not counted). O(n r) when the holder's velocity changes.
    pub(super) fn kick_error(&mut self, h: f64) {
        let d = self.reduced.scene().dim;
        let s = &self.reduced.state;
        let kick: [f64; 3] = std::array::from_fn(|i| if i < d { s.anchor_rate[i] - (self.loads.anchor[i] - s.anchor[i]) / h } else { 0.0 });
        if kick == [0.0; 3] || s.rotation != [0.0; 3] {
            return;
        }
        if let Estimator::Directions(m) = &self.model {
            // In the error directions, Ψᵀ M Φ = 0: the kick's part there is Ψᵀ M kick.
            m.add_uniform_velocity(&mut self.error, &kick);
            return;
        }
        let b = self.reduced.space.basis();
        let mass = &self.reduced.scene().dof_mass;
        // q = Φᵀ M u for u = Δc on every free node.
        self.kick_q.fill(0.0);
        for i in 0..b.n {
            let mu = mass[i] * kick[i % d];
            for (q, p) in self.kick_q.iter_mut().zip(&b.phi[i * b.r..(i + 1) * b.r]) {
                *q += p * mu;
            }
        }
        for i in 0..b.n {
            let held: f64 = b.phi[i * b.r..(i + 1) * b.r].iter().zip(&self.kick_q).map(|(p, q)| p * q).sum();
            self.error.v[i] -= kick[i % d] - held;
        }
    }

    /// On a return to `basis`: the error carried plus the part of the state
    /// the basis leaves out (`left`, `left_rate` over the free DOFs) become
    /// the error model's state beside it; `built`, the direction model of
    /// `basis` where the return made it already (it is one pass over every spring).
    pub(super) fn carry_error(&mut self, basis: &ModalBasis, built: Option<DirectionModel>, left: &[f64], left_rate: &[f64]) {
        match &mut self.model {
            Estimator::Full(_) | Estimator::None => {
                self.error.e.iter_mut().zip(left).for_each(|(e, l)| *e += l);
                self.error.v.iter_mut().zip(left_rate).for_each(|(e, l)| *e += l);
                self.error.a.fill(0.0);
            }
            Estimator::Directions(_) => {
                // Over the free DOFs in full space (twin.rs), where a return starts;
                // `carried` takes them back, for the next fall-back.
                let n = left.len();
                let old = std::mem::replace(&mut self.error, ErrorState::zero(0));
                let (mut e, mut v) = if old.e.len() == n { (old.e.clone(), old.v.clone()) } else { (vec![0.0; n], vec![0.0; n]) };
                self.carried = if old.e.len() == n { old } else { ErrorState::zero(n) };
                e.iter_mut().zip(left).for_each(|(e, l)| *e += l);
                v.iter_mut().zip(left_rate).for_each(|(e, l)| *e += l);
                let model = built.unwrap_or_else(|| {
                    let set = self.chosen.choice.error_set.as_ref().expect("a direction model has a spring set");
                    Estimator::directions(self.full.space.scene(), &self.chosen, basis, set)
                });
                self.error = ErrorState::zero(model.directions());
                model.add(&mut self.error, &e, &v);
                self.model = Estimator::Directions(model);
            }
        }
        self.spare_error = self.error.clone();
    }
}
