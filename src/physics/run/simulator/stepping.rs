//! A run's set-up, its step, load changes and snapshots: [`Run::new`],
//! the helpers that call the space and the scheme, and [`Steps`].

use std::marker::PhantomData;

use super::{internal_step_count, turn_loads, FrameLoads, Fresh, Outputs, Run, Steps};
use super::{ENERGY_GROWTH_LIMIT, MAX_INTERNAL_STEPS_PER_CALL, MAX_STABLE_SUBSTEPS};
use crate::physics::error::{positive, PhysicsError, Quantity, StepFailure};
use crate::physics::run::frame::{self, apply, apply_transposed, compose, cross, dot, into_frame, norm, planar, rotation, Frame, Moments};
use crate::physics::run::holders::{self, Placement};
use crate::physics::run::integrator::{Buffers, Scheme};
use crate::physics::run::space::Readout;
use crate::physics::run::state::{Loads, Motion, Snapshot, State, OTHER_HOLDERS};
use crate::physics::settings::Settings;
use crate::physics::setup::scene::Scene;
use crate::physics::vector_unit;

impl<S: Readout, I: Scheme> Run<S, I> {
    /// Binds `space` to the scheme under `loads` (or refuses a space the
    /// scheme cannot integrate), starts the sheet at rest wherever the
    /// anchor is and however the holder is turned, and bounds its step.
    pub fn new(space: S, settings: &Settings, loads: &Loads) -> Result<Self, PhysicsError> {
        let work = space.work(loads);
        I::check(&space, &work)?;
        let scene = space.scene();
        let (free_mass, reach) = (scene.free_mass(), scene.reach());
        let spacing = scene.springs.iter().map(|s| s.rest).filter(|&l| l > 0.0).fold(f64::INFINITY, f64::min);
        let dim = scene.dim;
        let pivot = scene.pivot();
        let slots = scene.rest.chunks_exact(dim);
        let arm = slots.clone().map(|x| (0..dim).map(|i| (x[i] - pivot[i]).powi(2)).sum::<f64>().sqrt()).fold(0.0, f64::max) + reach;
        let mut rest_moment = [0.0; 3];
        for (k, x) in slots.take(scene.n_free).enumerate() {
            for i in 0..dim {
                rest_moment[i] += scene.dof_mass[k * dim] * (x[i] - pivot[i]);
            }
        }
        let n = space.layout().coordinates;
        let mut state = State::at_rest(n);
        space.rest_coordinates(&mut state.y);
        // The sheet starts at rest wherever the anchor is and however the holder is turned.
        state.anchor[..dim].copy_from_slice(&loads.anchor[..dim]);
        state.rotation = planar(&loads.rotation, dim);
        for (m, p) in state.holders.iter_mut().zip(&loads.holders) {
            m.anchor[..dim].copy_from_slice(&p.anchor[..dim]);
            m.rotation = planar(&p.rotation, dim);
        }
        let holder_ends = scene.moving_holders().iter().map(|h| holders::spring_ends(scene, h)).collect();
        let holder_arms = scene
            .moving_holders()
            .iter()
            .map(|h| {
                let far = |&s: &usize| (0..dim).map(|i| (scene.rest[s * dim + i] - h.pivot[i]).powi(2)).sum::<f64>().sqrt();
                h.slots.iter().map(far).fold(0.0, f64::max)
            })
            .collect();
        // (holder, node) for every node of a holder that moves on its own, through a slot -> holder map.
        let mut holder_of_slot = vec![usize::MAX; scene.rest.len() / dim];
        for (j, h) in scene.moving_holders().iter().enumerate() {
            h.slots.iter().for_each(|&s| holder_of_slot[s] = j);
        }
        let mut holder_nodes: Vec<(usize, usize)> =
            scene.slot_of_node.iter().enumerate().filter(|&(_, &s)| holder_of_slot[s] != usize::MAX).map(|(node, &s)| (holder_of_slot[s], node)).collect();
        holder_nodes.sort_by_key(|&(j, _)| j);
        let local = turn_loads(loads, &rotation(&state.rotation), dim);
        let mut run = Run {
            outputs: Outputs::new(scene, settings.n_modes),
            fresh: Fresh::default(),
            energy: 0.0,
            backup: state.clone(),
            state,
            buffers: Buffers::new(n, I::SCRATCH),
            acceleration: vec![0.0; n],
            current: false,
            work,
            space,
            settings: settings.clone(),
            spare: loads.clone(),
            internal_steps_last: 0,
            free_mass,
            reach,
            spacing,
            pivot,
            arm,
            rest_moment,
            local,
            holder_ends,
            holder_arms,
            holder_nodes,
            scheme: PhantomData,
        };
        run.space.apply_loads(&mut run.work);
        run.place_holders_now();
        run.start_at_static_response()?;
        if run.state.rotation != [0.0; 3] {
            run.space.turn(&Frame { gravity: local.gravity, load: local.point_load, spin: [0.0; 3] }, &mut run.work);
        }
        run.settle_state();
        run.check_stable_step_cost()?;
        run.refresh_outputs();
        Ok(run)
    }

    /// The motion of the first holder (the frame) in the state, with the
    /// anchor's velocity `rate` and the spin `spin` over the coming step.
    fn first_motion(&self, rate: [f64; 3], spin: [f64; 3]) -> Motion {
        Motion { anchor: self.state.anchor, anchor_rate: rate, rotation: self.state.rotation, spin }
    }

    /// Places the slots of the holders that move on their own where
    /// `others` put them `tau` after the state's time, in the frame where
    /// `first` puts the first holder then (`docs/method.md`, section 9);
    /// the forces of the work are no longer those of the state.
    fn place_holders(&mut self, first: &Motion, others: &[Motion; OTHER_HOLDERS], tau: f64) {
        let moving = self.space.scene().moving_holders().len();
        if moving == 0 {
            return;
        }
        let at: [Placement; OTHER_HOLDERS] = std::array::from_fn(|j| Placement::after(&others[j], tau));
        holders::place(self.space.scene(), &Placement::after(first, tau), &at[..moving], self.space.slots_mut(&mut self.work));
        self.current = false;
    }

    /// [`Self::place_holders`] at the state.
    pub(super) fn place_holders_now(&mut self) {
        let (first, others) = (self.first_motion(self.state.anchor_rate, self.state.spin), self.state.holders);
        self.place_holders(&first, &others, 0.0);
    }

    /// Starts the sheet at rest where the holders' static pull puts it when
    /// a holder other than the first is away from its place relative to the
    /// first: the linear static response at rest (see
    /// [`crate::physics::setup::basis::static_response`]), as the space holds it.
    fn start_at_static_response(&mut self) -> Result<(), PhysicsError> {
        let scene = self.space.scene();
        let d = scene.dim;
        let x = self.space.slots_mut(&mut self.work);
        let away = scene.moving_holders().iter().flat_map(|h| &h.slots).any(|&s| (0..d).any(|i| x[s * d + i] != scene.rest[s * d + i]));
        if !away {
            return Ok(());
        }
        let x = x.to_vec();
        let u = crate::physics::setup::basis::static_response(self.space.scene(), &x)?;
        if u.iter().all(|&c| c == 0.0) {
            return Ok(());
        }
        let dy = self.coordinates_of(&u);
        for (y, d) in self.state.y.iter_mut().zip(&dy) {
            *y += d;
        }
        Ok(())
    }

    /// The space's coordinates of a displacement `u` of the free DOFs: its
    /// modal coordinates Phi^T M u (the part the basis holds), or u itself in full space.
    fn coordinates_of(&self, u: &[f64]) -> Vec<f64> {
        // Full space keeps no modes (its reported ones are not asked for here).
        match self.space.layout().kept_modes.and_then(|r| self.space.modes().map(|b| (r, b))) {
            Some((r, basis)) => {
                let mut q = vec![0.0; r];
                basis.project_displacement(&self.space.scene().dof_mass, u, &mut q);
                q
            }
            None => u.to_vec(),
        }
    }

    /// The space the run steps.
    pub fn space(&self) -> &S {
        &self.space
    }

    /// Evaluates the forces at the state and sets `state.a` as the scheme
    /// needs it (see [`Scheme::settle`]): at the start, and after a change
    /// of loads, which then acts as a step input.
    pub(super) fn settle_state(&mut self) {
        I::settle(&self.space, &mut self.work, &mut self.buffers, &mut self.state);
        self.current = true;
    }

    /// Evaluates the forces at the state only (after a restore, which
    /// brings its own accelerations).
    pub(super) fn evaluate_forces(&mut self) {
        self.space.force(&self.state.y, &mut self.work, &mut self.buffers.h);
        self.current = true;
        // A restored state.a was derived for a step size the buffers do not know.
        self.buffers.filter_step = f64::NAN;
    }

    /// One internal step of length `dt`.
    fn step_internal(&mut self, dt: f64) -> Result<(), StepFailure> {
        self.current = I::ENDS_AT_STATE;
        I::step(&self.space, &mut self.work, &mut self.buffers, &mut self.state, dt)
    }

    /// Adds the rates of a rigid translation with velocity `c` and of a
    /// rigid rotation about the pivot with angular velocity `spin` to the
    /// state's rates (see [`crate::physics::run::space::Space::add_translation_rate`],
    /// [`crate::physics::run::space::Space::add_rotation_rate`]) and sets
    /// `state.a` for the new rates (see [`Scheme::settle_rates`]).
    fn kick_rates(&mut self, c: &[f64; 3], spin: &[f64; 3]) {
        if *c != [0.0; 3] {
            self.space.add_translation_rate(&self.work, c, &mut self.state.v);
        }
        if *spin != [0.0; 3] {
            self.space.add_rotation_rate(&self.work, spin, &self.state.y, &mut self.state.v);
        }
        I::settle_rates(&self.space, &mut self.work, &mut self.buffers, &mut self.state);
    }

    /// The forces of the work at the state, evaluated if the last step left them elsewhere.
    pub(super) fn forces_current(&mut self) {
        if !self.current {
            self.space.force(&self.state.y, &mut self.work, &mut self.buffers.h);
            self.current = true;
        }
    }

    /// Potential energy of the state as the force model sums it (see
    /// [`Readout::model_energy`]), for the step guard, at the coordinates of
    /// the last force evaluation (the state's, or the trigonometric scheme's
    /// filtered ones: see [`Scheme::ENDS_AT_STATE`]) [J].
    fn model_energy_now(&mut self) -> f64 {
        let at = if self.current { &self.state.y } else { &self.buffers.a1 };
        self.space.model_energy(at, &mut self.work)
    }

    /// y'' of the scheme's motion at the state, into `self.acceleration`.
    fn accelerate(&mut self) {
        I::acceleration(&self.space, &mut self.work, &mut self.buffers, &self.state, &mut self.acceleration);
    }

    /// The rate of change of the free nodes' momentum relative to the
    /// holder, sum M y'' per axis, with y'' of the motion the scheme
    /// integrates (see [`Scheme::acceleration`]) [N].
    pub(super) fn momentum_rate_now(&mut self) -> [f64; 3] {
        self.accelerate();
        self.space.momentum(&self.acceleration)
    }

    /// The mass moments of y'' at the state, y'' as above (see [`Readout::moments`]).
    pub(super) fn acceleration_moments_now(&mut self) -> Moments {
        self.accelerate();
        self.space.moments(&self.state.y, &self.acceleration)
    }

    /// Refuses a scheme whose stability limit would split every internal
    /// step bound into more than [`MAX_STABLE_SUBSTEPS`] internal steps,
    /// saying what sets the limit and what would lift it.
    fn check_stable_step_cost(&self) -> Result<(), PhysicsError> {
        if !self.settings.substepping {
            return Ok(());
        }
        let dt = self.max_stable_step();
        let per_step = self.settings.max_internal_step / dt;
        if per_step <= MAX_STABLE_SUBSTEPS {
            return Ok(());
        }
        Err(PhysicsError::ExplicitTooStiff {
            stable_step: dt,
            omega_max: self.space.omega_sq_bound(&self.work).sqrt(),
            stiffness_per_mass: self.space.scene().stiffness_per_mass(),
            per_step,
            max_internal_step: self.settings.max_internal_step,
            limit: MAX_STABLE_SUBSTEPS,
            modes: self.space.layout().kept_modes,
        })
    }

    /// The loads' terms of the space, in the holder's frame once it has turned.
    pub(super) fn apply_loads(&mut self) {
        self.space.apply_loads(&mut self.work);
        if self.turned() {
            let d = self.scene().dim;
            self.local = turn_loads(self.loads(), &rotation(&self.state.rotation), d);
            let frame = Frame { gravity: self.local.gravity, load: self.local.point_load, spin: self.state.spin };
            self.space.turn(&frame, &mut self.work);
        }
    }

    /// Gravity and the point load as the sheet feels them: in the holder's
    /// frame once it has turned, else as set.
    pub(super) fn felt_loads(&self) -> FrameLoads {
        if self.turned() {
            self.local
        } else {
            FrameLoads { gravity: self.loads().gravity, point_load: self.loads().point_load }
        }
    }

    /// The holder has left its rest orientation or turns.
    pub(super) fn turned(&self) -> bool {
        self.state.rotation != [0.0; 3] || self.state.spin != [0.0; 3]
    }

    /// The holder's frame `tau` after the orientation `start`, turning at `spin`.
    fn frame(&self, start: &[f64; 9], tau: f64, spin: &[f64; 3]) -> Frame {
        let r = if tau == 0.0 || *spin == [0.0; 3] { *start } else { compose(start, &rotation(&spin.map(|w| w * tau))) };
        let d = self.scene().dim;
        Frame { gravity: into_frame(&r, &self.loads().gravity, d), load: into_frame(&r, &self.loads().point_load, d), spin: *spin }
    }

    /// Rejects non-finite states and kinetic energy that grew far beyond
    /// what the loads could supply.
    fn check_state(&self, dt: f64, energy_before: f64) -> Result<(), StepFailure> {
        if !self.state.y.iter().chain(&self.state.v).all(|z| z.is_finite()) {
            return Err(StepFailure::NonFinite { dt });
        }
        let kinetic = self.space.kinetic_energy(&self.state.v);
        let g = self.loads().gravity.iter().map(|c| c * c).sum::<f64>().sqrt();
        // The point load does at most |f_p| times the reach on its node (`docs/method.md`, section 8).
        let point = self.loads().active_point_load(self.scene().dim).map_or(0.0, |f| f.iter().map(|c| c * c).sum::<f64>().sqrt());
        let supply = (self.free_mass * (g + 1.0) + point) * self.reach * self.loads().weight_max();
        if !(kinetic <= ENERGY_GROWTH_LIMIT * (energy_before + supply)) {
            return Err(StepFailure::EnergyGrowth { kinetic, before: energy_before, dt });
        }
        Ok(())
    }

    /// After every change of the state or the loads: the cheap outputs and
    /// the guard's energy now, the costly ones when asked for.
    pub(super) fn refresh_outputs(&mut self) {
        self.fresh = Fresh::default();
        let relative = self.space.kinetic_energy(&self.state.v);
        // In the ground's frame: 1/2 (v + c)^T M (v + c), c the anchor's velocity.
        let c = self.state.anchor_rate;
        self.outputs.kinetic = if self.turned() {
            // 1/2 sum m |c + R (v + w x rho)|^2 = 1/2 sum m |v|^2 + w . L + 1/2 (|w|^2 tr J - w^T J w)
            //   + c . R (P + w x S) + 1/2 m |c|^2, with the moments of the rates.
            let (r, w, m) = (rotation(&self.state.rotation), self.state.spin, self.space.moments(&self.state.y, &self.state.v));
            let j = &m.second;
            let inner = relative + dot(&w, &m.angular()) + 0.5 * (dot(&w, &w) * (j[0] + j[4] + j[8]) - dot(&w, &apply(j, &w)));
            let sw = cross(&w, &m.first);
            let frame = apply(&r, &std::array::from_fn(|i| m.momentum[i] + sw[i]));
            inner + dot(&c, &frame) + 0.5 * self.free_mass * dot(&c, &c)
        } else if c == [0.0; 3] {
            relative
        } else {
            let p = self.space.momentum(&self.state.v);
            relative + (0..3).map(|i| c[i] * p[i] + 0.5 * self.free_mass * c[i] * c[i]).sum::<f64>()
        };
        self.energy = relative + self.model_energy_now().abs();
    }
}

impl<S: Readout, I: Scheme> Steps for Run<S, I> {
    fn max_stable_step(&self) -> f64 {
        let bound = self.settings.max_internal_step;
        I::stable_step(self.space.omega_sq_bound(&self.work)).map_or(bound, |dt| bound.min(dt))
    }

    fn do_step(&mut self, h: f64) -> Result<(), PhysicsError> {
        positive(Quantity::StepSize, h)?;
        // Set-up, a restore or a read may have run faer's kernels since the last step.
        vector_unit::clean();
        let dt_max = self.max_stable_step();
        let steps = if self.settings.substepping { internal_step_count(h, dt_max) } else { 1.0 };
        if steps > MAX_INTERNAL_STEPS_PER_CALL as f64 {
            return Err(PhysicsError::TooManyInternalSteps { h, steps, dt: dt_max, limit: MAX_INTERNAL_STEPS_PER_CALL });
        }
        let steps = steps as usize;
        let dt = h / steps as f64;
        let mut energy_before = self.energy;
        // The anchor moves linearly to its target over the step: its
        // velocity changes by `kick` now, and the free nodes, whose absolute
        // velocity cannot jump, get -kick relative to it (`docs/method.md`, section 8).
        let d = self.scene().dim;
        let (mut rate, mut kick) = ([0.0; 3], [0.0; 3]);
        for i in 0..d {
            rate[i] = (self.loads().anchor[i] - self.state.anchor[i]) / h;
            kick[i] = self.state.anchor_rate[i] - rate[i];
        }
        let kick_speed = kick.iter().map(|c| c * c).sum::<f64>().sqrt();
        if !kick_speed.is_finite() || kick_speed * dt > 0.5 * self.spacing {
            let cause = StepFailure::AnchorTooFast { speed: kick_speed, limit: 0.5 * self.spacing / dt, dt };
            return Err(PhysicsError::StepFailed { time: self.state.time, cause });
        }
        // The holder turns at a constant rate to its target over the step:
        // its spin changes by -turn now, and the free nodes get turn x rho relative to it.
        let target = planar(&self.loads().rotation, d);
        let spin = frame::spin(&self.state.rotation, &target, h);
        let turn: [f64; 3] = std::array::from_fn(|i| self.state.spin[i] - spin[i]);
        let turning = self.turned() || spin != [0.0; 3];
        if (spin != [0.0; 3] || self.state.spin != [0.0; 3]) && !I::TURNS {
            return Err(PhysicsError::SchemeCannotTurn { scheme: self.settings.integrator });
        }
        let turn_rate = norm(&turn);
        if !turn_rate.is_finite() || turn_rate * self.arm * dt > 0.5 * self.spacing {
            let cause = StepFailure::TurnTooFast { rate: turn_rate, limit: 0.5 * self.spacing / (self.arm * dt), reach: self.arm, dt };
            return Err(PhysicsError::StepFailed { time: self.state.time, cause });
        }
        // Every other holder moves linearly and turns at a constant rate to its target too;
        // the free nodes keep their velocity and follow through the springs.
        let moving = self.scene().moving_holders().len();
        let mut others = self.state.holders;
        let mut relative = moving > 0 && (rate != [0.0; 3] || spin != [0.0; 3]);
        let mut pushed = 0.0f64;
        for (j, m) in others.iter_mut().enumerate().take(moving) {
            let target = self.loads().holders[j];
            let new_rate: [f64; 3] = std::array::from_fn(|i| if i < d { (target.anchor[i] - m.anchor[i]) / h } else { 0.0 });
            let new_spin = frame::spin(&m.rotation, &planar(&target.rotation, d), h);
            let change = |a: &[f64; 3], b: &[f64; 3]| norm(&std::array::from_fn(|i| a[i] - b[i]));
            let speed = change(&new_rate, &m.anchor_rate) + change(&new_spin, &m.spin) * self.holder_arms[j];
            if !speed.is_finite() || speed * dt > 0.5 * self.spacing {
                let cause = StepFailure::HolderTooFast { holder: j + 2, speed, limit: 0.5 * self.spacing / dt, dt };
                return Err(PhysicsError::StepFailed { time: self.state.time, cause });
            }
            m.anchor_rate = new_rate;
            m.spin = new_spin;
            relative |= new_rate != [0.0; 3] || new_spin != [0.0; 3];
            pushed = pushed.max(norm(&new_rate) + norm(&new_spin) * self.holder_arms[j]);
        }
        let first = self.first_motion(rate, spin);
        let (mut first_end, mut others_end) = (first, others);
        first_end.anchor[..d].copy_from_slice(&self.loads().anchor[..d]);
        first_end.rotation = target;
        for (j, m) in others_end.iter_mut().enumerate().take(moving) {
            m.anchor[..d].copy_from_slice(&self.loads().holders[j].anchor[..d]);
            m.rotation = planar(&self.loads().holders[j].rotation, d);
        }
        self.backup.copy_from(&self.state);
        let start = rotation(&self.state.rotation);
        if turning {
            let frame = self.frame(&start, 0.0, &spin);
            self.space.turn(&frame, &mut self.work);
            kick = apply_transposed(&start, &kick);
        }
        if kick_speed > 0.0 || turn_rate > 0.0 {
            self.kick_rates(&kick, &turn);
            // The kick's kinetic energy is supplied, not grown.
            energy_before += self.free_mass * (kick_speed + turn_rate * self.arm).powi(2) * self.loads().weight_max().powi(2);
        }
        let mut result = Ok(());
        for i in 0..steps {
            if spin != [0.0; 3] {
                // Gravity and the point load turn in the holder's frame: as they are at the step's end.
                let frame = self.frame(&start, (i + 1) as f64 * dt, &spin);
                self.space.turn(&frame, &mut self.work);
            }
            if relative {
                // The holders as they are at the step's end: the last one exactly at their targets.
                if i + 1 == steps {
                    self.place_holders(&first_end, &others_end, 0.0);
                } else {
                    self.place_holders(&first, &others, (i + 1) as f64 * dt);
                }
            }
            result = self.step_internal(dt);
            if result.is_err() {
                break;
            }
        }
        // A spinning frame can give the sheet the kinetic energy of its far end at the frame's speed.
        // A spinning frame can give the sheet the kinetic energy of its far end at the frame's
        // speed; a holder moving on its own, that of its speed (and of the springs it stretches).
        let spun = self.free_mass * ((norm(&spin) * self.arm).powi(2) + pushed.powi(2)) * self.loads().weight_max().powi(2);
        if let Err(cause) = result.and_then(|_| self.check_state(dt, energy_before + spun)) {
            self.state.copy_from(&self.backup);
            if relative {
                self.place_holders_now();
            }
            if turning {
                self.space.apply_loads(&mut self.work);
                if self.turned() {
                    let frame = self.frame(&start, 0.0, &self.state.spin);
                    self.space.turn(&frame, &mut self.work);
                }
            }
            self.evaluate_forces();
            return Err(PhysicsError::StepFailed { time: self.state.time, cause });
        }
        self.internal_steps_last = steps;
        self.state.time += h;
        let target_anchor = self.loads().anchor;
        self.state.anchor[..d].copy_from_slice(&target_anchor[..d]);
        self.state.anchor_rate = rate;
        for (m, end) in self.state.holders.iter_mut().zip(&others_end).take(moving) {
            *m = *end;
        }
        if turning {
            self.state.rotation = target;
            self.state.spin = spin;
            self.local = turn_loads(self.loads(), &rotation(&target), d);
        }
        self.refresh_outputs();
        Ok(())
    }

    fn scene(&self) -> &Scene {
        self.space.scene()
    }

    fn time(&self) -> f64 {
        self.state.time
    }

    fn n_dofs(&self) -> usize {
        self.scene().n_dofs()
    }

    fn loads(&self) -> &Loads {
        self.work.as_ref()
    }

    fn settings(&self) -> &Settings {
        &self.settings
    }

    fn internal_steps_last(&self) -> usize {
        self.internal_steps_last
    }

    fn edit_loads(&mut self, edit: &mut dyn FnMut(&mut Loads)) -> Result<(), PhysicsError> {
        self.spare.clone_from(self.work.as_ref());
        edit(self.work.as_mut());
        let loads = self.work.as_ref();
        if *loads == self.spare {
            return Ok(());
        }
        let mut refused = loads.validate(self.settings.n_modes).and_then(|()| loads.validate_on(self.scene()));
        if refused.is_ok() && !I::TURNS && planar(&loads.rotation, self.scene().dim) != self.state.rotation {
            refused = Err(PhysicsError::SchemeCannotTurn { scheme: self.settings.integrator });
        }
        if let Err(e) = refused {
            std::mem::swap(self.work.as_mut(), &mut self.spare);
            return Err(e);
        }
        if loads.same_but_anchor(&self.spare) {
            // The anchor's and the holder's targets act from the next step on; nothing moves now.
            return Ok(());
        }
        self.apply_loads();
        self.settle_state();
        self.refresh_outputs();
        Ok(())
    }

    fn displace(&mut self, dy: &[f64]) -> Result<(), PhysicsError> {
        if dy.len() != self.state.len() {
            return Err(PhysicsError::SnapshotLength { len: dy.len(), expected: self.state.len() });
        }
        if !dy.iter().all(|x| x.is_finite()) {
            return Err(PhysicsError::SnapshotNotFinite);
        }
        for (y, d) in self.state.y.iter_mut().zip(dy) {
            *y += d;
        }
        self.settle_state();
        self.refresh_outputs();
        Ok(())
    }

    fn displace_dofs(&mut self, dy: &[f64]) -> Result<(), PhysicsError> {
        if dy.len() != self.n_dofs() {
            return Err(PhysicsError::SnapshotLength { len: dy.len(), expected: self.n_dofs() });
        }
        let q = self.coordinates_of(dy);
        self.displace(&q)
    }

    fn snapshot(&self) -> Snapshot {
        Snapshot { state: self.state.clone(), loads: self.loads().clone(), adaptive: None }
    }

    fn restore(&mut self, s: &Snapshot) -> Result<(), PhysicsError> {
        let n = self.state.len();
        for len in [s.state.y.len(), s.state.v.len(), s.state.a.len()] {
            if len != n {
                return Err(PhysicsError::SnapshotLength { len, expected: n });
            }
        }
        if !s.state.is_finite() {
            return Err(PhysicsError::SnapshotNotFinite);
        }
        s.loads.validate(self.settings.n_modes)?;
        s.loads.validate_on(self.scene())?;
        if !I::TURNS && (s.state.spin != [0.0; 3] || s.state.rotation != planar(&s.loads.rotation, self.scene().dim)) {
            return Err(PhysicsError::SchemeCannotTurn { scheme: self.settings.integrator });
        }
        self.work.as_mut().clone_from(&s.loads);
        self.state.copy_from(&s.state);
        self.apply_loads();
        self.place_holders_now();
        self.evaluate_forces();
        self.refresh_outputs();
        Ok(())
    }
}
