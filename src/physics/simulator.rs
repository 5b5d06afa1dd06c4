//! The simulator: set-up (the space and scheme the settings name,
//! bound once), the communication step split into internal steps, the
//! checks that catch a diverging step, and the outputs.
//!
//! It holds the constant model (behind [`Stepper`]), the [`State`], the
//! [`Loads`], a backup of the state taken before every communication step,
//! and the [`Outputs`] of the last good step. The outputs that cost more
//! than the reduced state (node positions and velocities, the energy of
//! every spring, the force residual) are computed when first asked for
//! after a step and kept until the state changes: a host that reads only
//! some of them, or reads them less often than it steps, pays only for
//! those (`docs/method.md`, section 4).

use super::bake::SetupData;
use super::engine::{self, Outputs, Stepper};
use super::error::{positive, Expected, PhysicsError, Quantity, StepFailure};
use super::frame::cross;
use super::scene::Scene;
use super::settings::{Reduction, Settings};
use super::state::{Loads, Snapshot, State};

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
    engine: Box<dyn Stepper>,
    settings: Settings,
    state: State,
    loads: Loads,
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
        let mut engine = engine::build(scene, settings, loads, prebuilt)?;
        engine.apply_loads(loads);
        let mut state = State::at_rest(engine.layout().coordinates);
        engine.rest_coordinates(&mut state.y);
        // The sheet starts at rest wherever the anchor is.
        state.anchor[..dim].copy_from_slice(&loads.anchor[..dim]);
        engine.settle(loads, &mut state);
        let mut sim = Simulator {
            outputs: Outputs::new(engine.scene(), settings.n_modes),
            fresh: Fresh::default(),
            energy: 0.0,
            backup: state.clone(),
            state,
            engine,
            settings: settings.clone(),
            loads: loads.clone(),
            internal_steps_last: 0,
            free_mass,
            reach,
            spacing,
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
            omega_max: self.engine.omega_sq_bound(&self.loads).sqrt(),
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
        self.engine.stable_step(&self.loads).map_or(bound, |dt| bound.min(dt))
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
            rate[i] = (self.loads.anchor[i] - self.state.anchor[i]) / h;
            kick[i] = self.state.anchor_rate[i] - rate[i];
        }
        let kick_speed = kick.iter().map(|c| c * c).sum::<f64>().sqrt();
        if !kick_speed.is_finite() || kick_speed * dt > 0.5 * self.spacing {
            let cause = StepFailure::AnchorTooFast { speed: kick_speed, limit: 0.5 * self.spacing / dt, dt };
            return Err(PhysicsError::StepFailed { time: self.state.time, cause });
        }
        self.backup.copy_from(&self.state);
        if kick_speed > 0.0 {
            self.engine.translate_rates(&self.loads, &kick, &mut self.state);
            // The kick's kinetic energy is supplied, not grown.
            energy_before += self.free_mass * kick_speed * kick_speed * self.loads.weight_max().powi(2);
        }
        let mut result = Ok(());
        for _ in 0..steps {
            result = self.engine.step(&self.loads, &mut self.state, dt);
            if result.is_err() {
                break;
            }
        }
        if result.is_ok() {
            self.engine.finish(&self.loads, &self.state);
        }
        if let Err(cause) = result.and_then(|_| self.check_state(dt, energy_before)) {
            self.state.copy_from(&self.backup);
            self.engine.evaluate(&self.loads, &self.state);
            return Err(PhysicsError::StepFailed { time: self.state.time, cause });
        }
        self.internal_steps_last = steps;
        self.state.time += h;
        self.state.anchor[..d].copy_from_slice(&self.loads.anchor[..d]);
        self.state.anchor_rate = rate;
        self.refresh_outputs();
        Ok(())
    }

    /// Rejects non-finite states and kinetic energy that grew far beyond
    /// what the loads could supply.
    fn check_state(&self, dt: f64, energy_before: f64) -> Result<(), StepFailure> {
        if !self.state.y.iter().chain(&self.state.v).all(|z| z.is_finite()) {
            return Err(StepFailure::NonFinite { dt });
        }
        let kinetic = self.engine.kinetic_energy(&self.state);
        let g = self.loads.gravity.iter().map(|c| c * c).sum::<f64>().sqrt();
        // The point load does at most |f_p| times the reach on its node (`docs/method.md`, section 8).
        let point = self.loads.active_point_load(self.scene().dim).map_or(0.0, |f| f.iter().map(|c| c * c).sum::<f64>().sqrt());
        let supply = (self.free_mass * (g + 1.0) + point) * self.reach * self.loads.weight_max();
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
        self.outputs.kinetic = if c == [0.0; 3] {
            relative
        } else {
            let p = self.engine.momentum(&self.state);
            relative + (0..3).map(|i| c[i] * p[i] + 0.5 * self.free_mass * c[i] * c[i]).sum::<f64>()
        };
        self.engine.modal_coordinates(&self.state, &mut self.outputs.modal_coordinates);
        self.energy = relative + self.engine.model_energy(&self.loads, &self.state).abs();
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
    /// Node positions, `dim` per node in the scene's output order, held
    /// nodes included [m]. The modal space expands them from q when first
    /// asked after a step.
    pub fn positions(&mut self) -> &[f64] {
        if !self.fresh.positions {
            self.engine.node_positions(&self.state, &mut self.outputs);
            shift(&mut self.outputs.positions, &self.state.anchor, self.engine.scene().dim);
            self.fresh.positions = true;
        }
        &self.outputs.positions
    }
    /// Node velocities, same layout as positions [m/s].
    pub fn velocities(&mut self) -> &[f64] {
        if !self.fresh.velocities {
            self.engine.node_velocities(&self.state, &mut self.outputs);
            shift(&mut self.outputs.velocities, &self.state.anchor_rate, self.engine.scene().dim);
            self.fresh.velocities = true;
        }
        &self.outputs.velocities
    }
    /// Position of the load node (z 0 in 2D), if the node is in the scene
    /// [m]: read from the node positions when they are computed, else
    /// computed for this node alone.
    pub fn load_node_position(&mut self) -> Option<[f64; 3]> {
        let (node, d) = (self.loads.load_node.filter(|&n| n < self.scene().n_nodes)?, self.scene().dim);
        if self.fresh.positions {
            return Some(std::array::from_fn(|i| if i < d { self.outputs.positions[node * d + i] } else { 0.0 }));
        }
        let x = self.engine.node_position(&self.state, node);
        Some(std::array::from_fn(|i| if i < d { x[i] + self.state.anchor[i] } else { 0.0 }))
    }
    /// Velocity of the load node (z 0 in 2D), if the node is in the scene [m/s].
    pub fn load_node_velocity(&mut self) -> Option<[f64; 3]> {
        let (node, d) = (self.loads.load_node.filter(|&n| n < self.scene().n_nodes)?, self.scene().dim);
        if self.fresh.velocities {
            return Some(std::array::from_fn(|i| if i < d { self.outputs.velocities[node * d + i] } else { 0.0 }));
        }
        let v = self.engine.node_velocity(&self.state, node);
        Some(std::array::from_fn(|i| if i < d { v[i] + self.state.anchor_rate[i] } else { 0.0 }))
    }
    /// The force the sheet exerts on its holder, from the momentum balance
    /// of the free nodes (`docs/method.md`, section 8):
    /// F = m_free g + f_p - sum M z, z = y'' + M^-1 C y' of the motion the
    /// scheme integrates, so the damping's reaction is the holder's and, in
    /// 3D, so is what the auxiliary springs carry (their points ride with
    /// the holder). O(r) in the modal space; z is 0 in 2D [N].
    pub fn anchor_force(&mut self) -> [f64; 3] {
        if !self.fresh.anchor {
            let driven = self.engine.driven_momentum(&self.state);
            let (d, g, f) = (self.scene().dim, self.loads.gravity, self.point_load());
            self.outputs.anchor_force = std::array::from_fn(|i| if i < d { self.free_mass * g[i] + f[i] - driven[i] } else { 0.0 });
            self.fresh.anchor = true;
        }
        self.outputs.anchor_force
    }
    /// The torque the sheet exerts on its holder about the pivot, from the
    /// balance of angular momentum (`docs/method.md`, section 8):
    /// S x g + rho_p x f_p - sum m rho x z; only z in 2D. O(r^2) in the modal space [N m].
    pub fn anchor_torque(&mut self) -> [f64; 3] {
        if !self.fresh.torque {
            let (_, driven) = self.engine.moments(&self.state);
            let d = self.scene().dim;
            let g: [f64; 3] = std::array::from_fn(|i| if i < d { self.loads.gravity[i] } else { 0.0 });
            let mut t = cross(&driven.first, &g);
            let f = self.point_load();
            if let Some(node) = self.loads.load_node.filter(|_| f != [0.0; 3]) {
                let (x, pivot) = (self.engine.node_position(&self.state, node), self.scene().pivot());
                let arm = cross(&std::array::from_fn(|i| x[i] - pivot[i]), &f);
                t = std::array::from_fn(|i| t[i] + arm[i]);
            }
            let inertial = driven.angular();
            self.outputs.anchor_torque = std::array::from_fn(|i| if d == 3 || i == 2 { t[i] - inertial[i] } else { 0.0 });
            self.fresh.torque = true;
        }
        self.outputs.anchor_torque
    }
    /// The point load where it acts, on a free load node (z 0 in 2D), else 0 [N].
    fn point_load(&self) -> [f64; 3] {
        self.loads.point_force(self.scene()).map_or([0.0; 3], |(_, f)| std::array::from_fn(|i| f.get(i).copied().unwrap_or(0.0)))
    }
    /// Coordinates of the kept (modal) or reported (full) modes.
    pub fn modal_coordinates(&self) -> &[f64] {
        &self.outputs.modal_coordinates
    }
    /// omega_i of the kept or reported modes, ascending [rad/s].
    pub fn mode_frequencies(&self) -> &[f64] {
        self.engine.layout().frequencies
    }
    /// The spring force at generalized coordinates `y` as the space
    /// evaluates it: Phi^T f(x* + Phi y) in the modal space (every spring,
    /// or the cubature), f(x_rest + y) in full space. For diagnostics; the
    /// run is not affected.
    pub fn spring_force(&mut self, y: &[f64]) -> Result<Vec<f64>, PhysicsError> {
        let n = self.state.len();
        if y.len() != n {
            return Err(PhysicsError::SnapshotLength { len: y.len(), expected: n });
        }
        let mut out = vec![0.0; n];
        self.engine.spring_force(&self.loads, &self.state, y, &mut out);
        Ok(out)
    }
    /// The costly products of the set-up (modal space only), to store and
    /// pass to [`Self::with_setup`] later.
    pub fn setup_data(&self) -> Option<SetupData> {
        self.engine.setup_data()
    }
    /// Springs one force evaluation visits: every spring, or the cubature set.
    pub fn cubature_springs(&self) -> usize {
        self.engine.layout().springs
    }
    /// 1/2 v^T M v [J].
    pub fn kinetic_energy(&self) -> f64 {
        self.outputs.kinetic
    }
    /// Elastic energy of the springs plus gravitational energy relative to
    /// rest [J]: every spring, whatever the force model; computed when first
    /// asked after a step.
    pub fn potential_energy(&mut self) -> f64 {
        if !self.fresh.potential {
            // The anchor's displacement a moves every free node: -(m g + f_p) . a more.
            let (d, point) = (self.scene().dim, self.point_load());
            let shifted: f64 = (0..d).map(|i| (self.free_mass * self.loads.gravity[i] + point[i]) * self.state.anchor[i]).sum();
            self.outputs.potential = self.engine.potential_energy(&self.loads, &self.state) - shifted;
            self.fresh.potential = true;
        }
        self.outputs.potential
    }
    /// The part of the physical force the basis cannot represent, relative
    /// to the load (0 in full space); computed when first asked after a step.
    pub fn force_residual(&mut self) -> f64 {
        if !self.fresh.residual {
            self.outputs.force_residual = self.engine.force_residual(&self.loads, &self.state);
            self.fresh.residual = true;
        }
        self.outputs.force_residual
    }
    pub fn loads(&self) -> &Loads {
        &self.loads
    }
    pub fn settings(&self) -> &Settings {
        &self.settings
    }
    /// Internal steps taken by the last successful `do_step`.
    pub fn internal_steps_last(&self) -> usize {
        self.internal_steps_last
    }

    /// New loads, effective from now. The acceleration is recomputed at the
    /// current state, so a load change acts as a step input.
    pub fn set_loads(&mut self, loads: &Loads) -> Result<(), PhysicsError> {
        if *loads == self.loads {
            return Ok(());
        }
        loads.validate(self.settings.n_modes)?;
        loads.validate_on(self.scene())?;
        if loads.same_but_anchor(&self.loads) {
            // The anchor's target acts from the next step on; nothing moves now.
            self.loads.anchor = loads.anchor;
            return Ok(());
        }
        self.loads.clone_from(loads);
        self.engine.apply_loads(&self.loads);
        self.engine.settle(&self.loads, &mut self.state);
        self.refresh_outputs();
        Ok(())
    }

    /// The state and the loads: all a run needs to resume.
    pub fn snapshot(&self) -> Snapshot {
        Snapshot { state: self.state.clone(), loads: self.loads.clone() }
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
        self.loads.clone_from(&s.loads);
        self.engine.apply_loads(&self.loads);
        self.state.copy_from(&s.state);
        self.engine.evaluate(&self.loads, &self.state);
        self.refresh_outputs();
        Ok(())
    }
}

/// Adds the anchor's displacement (or velocity) `a` to every node of
/// `values` (`d` per node).
fn shift(values: &mut [f64], a: &[f64; 3], d: usize) {
    if a[..d].iter().any(|&x| x != 0.0) {
        for node in values.chunks_exact_mut(d) {
            for (x, ai) in node.iter_mut().zip(a) {
                *x += ai;
            }
        }
    }
}
