//! The simulator: set-up (the space and scheme the settings name,
//! bound once), the communication step split into internal steps, the
//! checks that catch a diverging step, and the outputs (what a host reads,
//! in `outputs.rs`).
//!
//! It holds the constant model (behind [`Stepper`]), the [`State`], the
//! [`Loads`], a backup of the state taken before every communication step,
//! and the [`Outputs`] of the last good step. The outputs that cost more
//! than the reduced state (node positions and velocities, the energy of
//! every spring, the force residual) are computed when first asked for
//! after a step and kept until the state changes: a host that reads only
//! some of them, or reads them less often than it steps, pays only for
//! those (`docs/method.md`, section 4).

mod outputs;

use crate::physics::error::{positive, Expected, PhysicsError, Quantity, StepFailure};
use crate::physics::run::engine::{self, Outputs, Stepper};
use crate::physics::run::frame::{self, apply, apply_transposed, compose, cross, dot, into_frame, norm, planar, rotation, Frame};
use crate::physics::run::state::{Loads, Snapshot, State};
use crate::physics::settings::{Reduction, Settings};
use crate::physics::setup::scene::Scene;
use crate::physics::setup::setup_data::SetupData;

/// Internal steps one communication step may take before it is refused.
pub const MAX_INTERNAL_STEPS_PER_CALL: usize = 10_000_000;
/// Internal steps one internal step bound may be split into by a scheme's
/// stability limit before set-up refuses the scheme: beyond it the scene is
/// too stiff for it, unless the host asked for steps that short by lowering
/// the bound.
pub const MAX_STABLE_SUBSTEPS: f64 = 1e4;
/// Relative amount by which a communication step may exceed a whole number
/// of longest internal steps and still be split into that number. Masters
/// compute the same step size differently (fmpy sends 0.009999999999999787,
/// fmusim 0.01000000000000001 for 0.01 s after t = 1 s), a few ulps apart;
/// the number of internal steps must not depend on that. 1e-8 is far above
/// the ulp (2.2e-16) and above the round-off of a step computed as the
/// difference of two times up to t = 1e6 h, and far below anything that
/// changes stability (internal steps stay within 0.9 (1 + 1e-8) of the
/// explicit limit).
pub const STEP_COUNT_TOLERANCE: f64 = 1e-8;
/// Kinetic energy growth in one communication step, relative to the energy
/// at its start plus the work the loads can do across the scene, that is
/// taken as a blow-up.
const ENERGY_GROWTH_LIMIT: f64 = 1e6;

/// Internal steps of at most `dt_max` (up to [`STEP_COUNT_TOLERANCE`]) that make up `h`.
pub fn internal_step_count(h: f64, dt_max: f64) -> f64 {
    (h / dt_max * (1.0 - STEP_COUNT_TOLERANCE)).ceil().max(1.0)
}

/// Which of the costly outputs have been computed for the current state.
#[derive(Clone, Copy, Debug, Default)]
struct Fresh {
    positions: bool,
    /// The holder's force and torque.
    anchor: bool,
    torque: bool,
    velocities: bool,
    potential: bool,
    residual: bool,
}

pub struct Simulator {
    /// The space and scheme with their work, which holds the loads: the
    /// one place the physics reads them ([`Simulator::loads`]).
    engine: Box<dyn Stepper>,
    settings: Settings,
    state: State,
    /// The loads before the change in progress of [`Simulator::edit_loads`],
    /// kept to restore them if the change is refused (never read as the loads).
    spare: Loads,
    /// The state at the start of the current communication step, restored
    /// if it fails (the loads do not change within a step).
    backup: State,
    outputs: Outputs,
    /// Which of the costly outputs match the state.
    fresh: Fresh,
    /// Kinetic energy plus |potential energy as the force model sums it| of
    /// the state, for the blow-up guard of the next step [J].
    energy: f64,
    internal_steps_last: usize,
    /// Mass of the free nodes and the distance they can travel, for the blow-up bound.
    free_mass: f64,
    reach: f64,
    /// Shortest spring at rest (the grid spacing) [m], for the anchor's speed limit.
    spacing: f64,
    /// The pivot X0, how far from it the sheet can reach, and sum m (x_rest - X0).
    pivot: [f64; 3],
    arm: f64,
    rest_moment: [f64; 3],
    /// Gravity and the point load turned into the holder's frame at the
    /// state's orientation, while it has turned.
    local: FrameLoads,
}

/// Gravity and the point load in the holder's frame.
#[derive(Clone, Copy, Debug, Default)]
struct FrameLoads {
    gravity: [f64; 3],
    point_load: [f64; 3],
}

impl Simulator {
    /// Set-up: builds the space the settings names on `scene` (assembly,
    /// eigen decomposition, factorizations), binds its scheme and bounds
    /// its step. Refuses what it cannot run, naming the quantity.
    pub fn new(scene: Scene, settings: &Settings, loads: &Loads) -> Result<Self, PhysicsError> {
        Self::with_setup(scene, settings, loads, None)
    }

    /// [`Self::new`], with the costly part of a modal set-up taken from
    /// `prebuilt` (see [`SetupData`]) when given: the run is then bit for
    /// bit that of a simulator that computed it for the same parameters.
    pub fn with_setup(scene: Scene, settings: &Settings, loads: &Loads, prebuilt: Option<&SetupData>) -> Result<Self, PhysicsError> {
        scene.check()?;
        positive(Quantity::MaxInternalStep, settings.max_internal_step)?;
        if settings.reduction == Reduction::Modal && settings.n_modes == 0 {
            return Err(PhysicsError::Invalid { quantity: Quantity::Modes, value: 0.0, expected: Expected::AtLeast(1.0) });
        }
        loads.validate(settings.n_modes)?;
        loads.validate_on(&scene)?;
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
        let mut engine = engine::build(scene, settings, loads, prebuilt)?;
        engine.apply_loads();
        let mut state = State::at_rest(engine.layout().coordinates);
        engine.rest_coordinates(&mut state.y);
        // The sheet starts at rest wherever the anchor is and however the holder is turned.
        state.anchor[..dim].copy_from_slice(&loads.anchor[..dim]);
        state.rotation = planar(&loads.rotation, dim);
        let local = turn_loads(loads, &rotation(&state.rotation), dim);
        if state.rotation != [0.0; 3] {
            engine.turn(&Frame { gravity: local.gravity, load: local.point_load, spin: [0.0; 3] });
        }
        engine.settle(&mut state);
        let mut sim = Simulator {
            outputs: Outputs::new(engine.scene(), settings.n_modes),
            fresh: Fresh::default(),
            energy: 0.0,
            backup: state.clone(),
            state,
            engine,
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
        };
        sim.check_stable_step_cost()?;
        sim.refresh_outputs();
        Ok(sim)
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
            omega_max: self.engine.omega_sq_bound().sqrt(),
            stiffness_per_mass: self.engine.scene().stiffness_per_mass(),
            per_step,
            max_internal_step: self.settings.max_internal_step,
            limit: MAX_STABLE_SUBSTEPS,
            modes: self.engine.layout().kept_modes,
        })
    }

    /// Longest internal step: the internal step bound, and the scheme's
    /// stability limit under the current loads (weights above 1 scale the
    /// stiffness a mode sees).
    pub fn max_stable_step(&self) -> f64 {
        let bound = self.settings.max_internal_step;
        self.engine.stable_step().map_or(bound, |dt| bound.min(dt))
    }

    /// Advances by `h` seconds in equal internal steps no longer than
    /// [`Self::max_stable_step`]. On error the state is that of the start of the call.
    pub fn do_step(&mut self, h: f64) -> Result<(), PhysicsError> {
        positive(Quantity::StepSize, h)?;
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
        if (spin != [0.0; 3] || self.state.spin != [0.0; 3]) && !self.engine.turns() {
            return Err(PhysicsError::SchemeCannotTurn { scheme: self.settings.integrator });
        }
        let turn_rate = norm(&turn);
        if !turn_rate.is_finite() || turn_rate * self.arm * dt > 0.5 * self.spacing {
            let cause = StepFailure::TurnTooFast { rate: turn_rate, limit: 0.5 * self.spacing / (self.arm * dt), reach: self.arm, dt };
            return Err(PhysicsError::StepFailed { time: self.state.time, cause });
        }
        self.backup.copy_from(&self.state);
        let start = rotation(&self.state.rotation);
        if turning {
            self.engine.turn(&self.frame(&start, 0.0, &spin));
            kick = apply_transposed(&start, &kick);
        }
        if kick_speed > 0.0 || turn_rate > 0.0 {
            self.engine.kick(&kick, &turn, &mut self.state);
            // The kick's kinetic energy is supplied, not grown.
            energy_before += self.free_mass * (kick_speed + turn_rate * self.arm).powi(2) * self.loads().weight_max().powi(2);
        }
        let mut result = Ok(());
        for i in 0..steps {
            if spin != [0.0; 3] {
                // Gravity and the point load turn in the holder's frame: as they are at the step's end.
                self.engine.turn(&self.frame(&start, (i + 1) as f64 * dt, &spin));
            }
            result = self.engine.step(&mut self.state, dt);
            if result.is_err() {
                break;
            }
        }
        // A spinning frame can give the sheet the kinetic energy of its far end at the frame's speed.
        let spun = self.free_mass * (norm(&spin) * self.arm).powi(2) * self.loads().weight_max().powi(2);
        if let Err(cause) = result.and_then(|_| self.check_state(dt, energy_before + spun)) {
            self.state.copy_from(&self.backup);
            if turning {
                self.engine.apply_loads();
                if self.turned() {
                    self.engine.turn(&self.frame(&start, 0.0, &self.state.spin));
                }
            }
            self.engine.evaluate(&self.state);
            return Err(PhysicsError::StepFailed { time: self.state.time, cause });
        }
        self.internal_steps_last = steps;
        self.state.time += h;
        let target_anchor = self.loads().anchor;
        self.state.anchor[..d].copy_from_slice(&target_anchor[..d]);
        self.state.anchor_rate = rate;
        if turning {
            self.state.rotation = target;
            self.state.spin = spin;
            self.local = turn_loads(self.loads(), &rotation(&target), d);
        }
        self.refresh_outputs();
        Ok(())
    }

    /// The loads' terms of the space, in the holder's frame once it has turned.
    fn apply_loads(&mut self) {
        self.engine.apply_loads();
        if self.turned() {
            let d = self.scene().dim;
            self.local = turn_loads(self.loads(), &rotation(&self.state.rotation), d);
            let frame = Frame { gravity: self.local.gravity, load: self.local.point_load, spin: self.state.spin };
            self.engine.turn(&frame);
        }
    }

    /// Gravity and the point load as the sheet feels them: in the holder's
    /// frame once it has turned, else as set.
    fn felt_loads(&self) -> FrameLoads {
        if self.turned() {
            self.local
        } else {
            FrameLoads { gravity: self.loads().gravity, point_load: self.loads().point_load }
        }
    }

    /// The holder has left its rest orientation or turns.
    fn turned(&self) -> bool {
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
        let kinetic = self.engine.kinetic_energy(&self.state);
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
    fn refresh_outputs(&mut self) {
        self.fresh = Fresh::default();
        let relative = self.engine.kinetic_energy(&self.state);
        // In the ground's frame: 1/2 (v + c)^T M (v + c), c the anchor's velocity.
        let c = self.state.anchor_rate;
        self.outputs.kinetic = if self.turned() {
            // 1/2 sum m |c + R (v + w x rho)|^2 = 1/2 sum m |v|^2 + w . L + 1/2 (|w|^2 tr J - w^T J w)
            //   + c . R (P + w x S) + 1/2 m |c|^2, with the moments of the rates.
            let (r, w, m) = (rotation(&self.state.rotation), self.state.spin, self.engine.motion(&self.state));
            let j = &m.second;
            let inner = relative + dot(&w, &m.angular()) + 0.5 * (dot(&w, &w) * (j[0] + j[4] + j[8]) - dot(&w, &apply(j, &w)));
            let sw = cross(&w, &m.first);
            let frame = apply(&r, &std::array::from_fn(|i| m.momentum[i] + sw[i]));
            inner + dot(&c, &frame) + 0.5 * self.free_mass * dot(&c, &c)
        } else if c == [0.0; 3] {
            relative
        } else {
            let p = self.engine.momentum(&self.state);
            relative + (0..3).map(|i| c[i] * p[i] + 0.5 * self.free_mass * c[i] * c[i]).sum::<f64>()
        };
        self.engine.modal_coordinates(&self.state, &mut self.outputs.modal_coordinates);
        self.energy = relative + self.engine.model_energy(&self.state).abs();
    }

    /// The scene being simulated.
    pub fn scene(&self) -> &Scene {
        self.engine.scene()
    }
    /// Time since the start of the run [s].
    pub fn time(&self) -> f64 {
        self.state.time
    }
    /// Free degrees of freedom.
    pub fn n_dofs(&self) -> usize {
        self.scene().n_dofs()
    }
    /// The loads of the run, as the physics reads them.
    pub fn loads(&self) -> &Loads {
        self.engine.loads()
    }
    pub fn settings(&self) -> &Settings {
        &self.settings
    }
    /// Internal steps taken by the last successful `do_step`.
    pub fn internal_steps_last(&self) -> usize {
        self.internal_steps_last
    }

    /// New loads, effective from now (see [`Self::edit_loads`]).
    pub fn set_loads(&mut self, loads: &Loads) -> Result<(), PhysicsError> {
        self.edit_loads(|l| l.clone_from(loads))
    }

    /// Changes the loads in place, where the physics reads them, effective
    /// from now: all or nothing (refused loads are restored as they were).
    /// The acceleration is recomputed at the current state, so a load
    /// change acts as a step input; a change of the anchor's or the
    /// holder's targets alone acts from the next step on. Allocates
    /// nothing when the mode weights keep their number.
    pub fn edit_loads(&mut self, edit: impl FnOnce(&mut Loads)) -> Result<(), PhysicsError> {
        self.spare.clone_from(self.engine.loads());
        edit(self.engine.loads_mut());
        let loads = self.engine.loads();
        if *loads == self.spare {
            return Ok(());
        }
        let refused = loads.validate(self.settings.n_modes).and_then(|()| loads.validate_on(self.scene())).and_then(|()| {
            match !self.engine.turns() && planar(&loads.rotation, self.scene().dim) != self.state.rotation {
                true => Err(PhysicsError::SchemeCannotTurn { scheme: self.settings.integrator }),
                false => Ok(()),
            }
        });
        if let Err(e) = refused {
            std::mem::swap(self.engine.loads_mut(), &mut self.spare);
            return Err(e);
        }
        if loads.same_but_anchor(&self.spare) {
            // The anchor's and the holder's targets act from the next step on; nothing moves now.
            return Ok(());
        }
        self.apply_loads();
        self.engine.settle(&mut self.state);
        self.refresh_outputs();
        Ok(())
    }

    /// Moves the generalized coordinates by `dy` (displacements of the free
    /// DOFs in full space, modal coordinates in the modal space) and makes
    /// the accelerations those of the new positions, as at the start of a
    /// run: the start of a twin run a hair away from this one, which shows
    /// how far a scene is predictable (`docs/method.md`, section 6). On
    /// error nothing changes.
    pub fn displace(&mut self, dy: &[f64]) -> Result<(), PhysicsError> {
        if dy.len() != self.state.len() {
            return Err(PhysicsError::SnapshotLength { len: dy.len(), expected: self.state.len() });
        }
        if !dy.iter().all(|x| x.is_finite()) {
            return Err(PhysicsError::SnapshotNotFinite);
        }
        for (y, d) in self.state.y.iter_mut().zip(dy) {
            *y += d;
        }
        self.engine.settle(&mut self.state);
        self.refresh_outputs();
        Ok(())
    }

    /// [`Self::displace`] by a displacement `dy` of the free DOFs: in the
    /// modal space by its modal coordinates q = Phi^T M dy (the part the
    /// basis holds).
    pub fn displace_dofs(&mut self, dy: &[f64]) -> Result<(), PhysicsError> {
        if dy.len() != self.n_dofs() {
            return Err(PhysicsError::SnapshotLength { len: dy.len(), expected: self.n_dofs() });
        }
        let q = match (self.engine.layout().kept_modes, self.engine.modes()) {
            (Some(r), Some(basis)) => {
                let mut q = vec![0.0; r];
                basis.project_displacement(&self.engine.scene().dof_mass, dy, &mut q);
                q
            }
            _ => dy.to_vec(),
        };
        self.displace(&q)
    }

    /// The state and the loads: all a run needs to resume.
    pub fn snapshot(&self) -> Snapshot {
        Snapshot { state: self.state.clone(), loads: self.loads().clone() }
    }

    /// Resumes from a snapshot of a simulator of the same scene and settings.
    /// On error nothing changes.
    pub fn restore(&mut self, s: &Snapshot) -> Result<(), PhysicsError> {
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
        if !self.engine.turns() && (s.state.spin != [0.0; 3] || s.state.rotation != planar(&s.loads.rotation, self.scene().dim)) {
            return Err(PhysicsError::SchemeCannotTurn { scheme: self.settings.integrator });
        }
        self.engine.loads_mut().clone_from(&s.loads);
        self.state.copy_from(&s.state);
        self.apply_loads();
        self.engine.evaluate(&self.state);
        self.refresh_outputs();
        Ok(())
    }
}

/// Gravity and the point load of `loads` turned into the frame of orientation `r`.
fn turn_loads(loads: &Loads, r: &[f64; 9], d: usize) -> FrameLoads {
    FrameLoads { gravity: into_frame(r, &loads.gravity, d), point_load: into_frame(r, &loads.point_load, d) }
}
