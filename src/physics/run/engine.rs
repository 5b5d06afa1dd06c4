//! A space and a scheme bound together with their scratch: the one place
//! where the two meet. [`Engine`] is generic, so a step calls the space
//! without indirection; the simulator holds it behind the object-safe
//! [`Stepper`], chosen once at set-up by the registry [`build`] (which
//! space, which force model, which scheme, as the [`Settings`] name them).
//!
//! The dependencies run one way: the simulator uses this module; this
//! module uses the spaces and the schemes; the schemes use the spaces.

use std::marker::PhantomData;

use crate::physics::error::{PhysicsError, StepFailure};
use crate::physics::run::frame::{Frame, Moments};
use crate::physics::run::integrator::{Buffers, NewmarkExplicit, NewmarkImplicit, Scheme, Trigonometric};
use crate::physics::run::space::{Cubature, Exact, Full, Layout, Modal, Readout};
use crate::physics::run::state::{Loads, State};
use crate::physics::settings::{ForceEvaluation, Integrator, ModeSelection, Reduction, Settings};
use crate::physics::setup::cubature_training;
use crate::physics::setup::modes::ModalBasis;
use crate::physics::setup::scene::Scene;
use crate::physics::setup::setup_data::SetupData;
use crate::physics::setup::trained_basis;

/// The registry: builds the space `settings.reduction` names on `scene`
/// (with the force model `settings.force_evaluation` names in the modal
/// space) and binds it to the scheme `settings.integrator` names, or
/// refuses a pair the scheme cannot integrate. `loads` are those at
/// set-up: the basis options that depend on the loads use them.
/// `prebuilt` (modal space only) replaces the costly part of the set-up.
pub(crate) fn build(scene: Scene, settings: &Settings, loads: &Loads, prebuilt: Option<&SetupData>) -> Result<Box<dyn Stepper>, PhysicsError> {
    // A trained basis (and its cubature) comes from its training program unless it is stored.
    let trained_basis;
    let prebuilt = match prebuilt {
        None if settings.reduction == Reduction::Modal && settings.mode_selection == ModeSelection::Trained => {
            trained_basis = trained_basis::train(scene.clone(), loads, settings)?;
            Some(&trained_basis)
        }
        given => given,
    };
    match settings.reduction {
        Reduction::Modal => match settings.force_evaluation {
            ForceEvaluation::Exact => bind(Modal::<Exact>::new(scene, loads, settings, prebuilt)?, settings.integrator, loads),
            ForceEvaluation::Cubature => {
                // The spring set is trained on the exact reduced model unless it is stored.
                let trained;
                let prebuilt = match prebuilt {
                    Some(data) if data.cubature.is_some() => Some(data),
                    _ => {
                        trained = cubature_training::train(scene.clone(), loads, settings, prebuilt, None)?;
                        Some(&trained)
                    }
                };
                bind(Modal::<Cubature>::new(scene, loads, settings, prebuilt)?, settings.integrator, loads)
            }
        },
        Reduction::Full => bind(Full::new(scene, loads, settings)?, settings.integrator, loads),
    }
}

/// Binds `space` to the scheme `kind` names.
fn bind<S: Readout>(space: S, kind: Integrator, loads: &Loads) -> Result<Box<dyn Stepper>, PhysicsError> {
    Ok(match kind {
        Integrator::NewmarkExplicit => Box::new(Engine::<S, NewmarkExplicit>::new(space, loads)?),
        Integrator::NewmarkImplicit => Box::new(Engine::<S, NewmarkImplicit>::new(space, loads)?),
        Integrator::Trigonometric => Box::new(Engine::<S, Trigonometric>::new(space, loads)?),
    })
}

/// What the simulator asks of a bound space and scheme to step it; what it
/// reads from it is [`Probe`].
pub trait Stepper: Probe + Send {
    fn scene(&self) -> &Scene;
    /// Sizes and constants of the space.
    fn layout(&self) -> Layout<'_>;
    /// The costly products of the set-up, as data (modal space only).
    fn setup_data(&self) -> Option<SetupData>;
    /// The kept (modal) or reported (full) modes, if any.
    fn modes(&self) -> Option<&ModalBasis>;
    /// The loads of the run: the one place they live (in the space's work).
    fn loads(&self) -> &Loads;
    /// The loads, to change in place; [`Stepper::apply_loads`] then derives their terms.
    fn loads_mut(&mut self) -> &mut Loads;
    /// Longest stable internal step under the loads, if stability limits it.
    fn stable_step(&self) -> Option<f64>;
    /// Squared-frequency bound of the integrated system under the loads [1/s^2].
    fn omega_sq_bound(&self) -> f64;
    /// Derives the load terms of the space from the loads.
    fn apply_loads(&mut self);
    /// The coordinates of the scene at rest.
    fn rest_coordinates(&self, y: &mut [f64]);
    /// Evaluates the forces at `state.y` (positions and elastic energy
    /// follow it) and sets `state.a` as the scheme needs it (see
    /// [`Scheme::settle`]): at the start, and after a change of loads, which
    /// then acts as a step input.
    fn settle(&mut self, state: &mut State);
    /// Evaluates the forces at `state.y` only (after a restore, which
    /// brings its own accelerations).
    fn evaluate(&mut self, state: &State);
    /// One internal step of length `dt`.
    fn step(&mut self, state: &mut State, dt: f64) -> Result<(), StepFailure>;
    /// Adds the rates of a rigid translation with velocity `c` and of a
    /// rigid rotation about the pivot with angular velocity `spin` to
    /// `state.v` (see [`Space::add_translation_rate`],
    /// [`Space::add_rotation_rate`]) and sets `state.a` for the new rates
    /// (see [`Scheme::settle_rates`]).
    fn kick(&mut self, c: &[f64; 3], spin: &[f64; 3], state: &mut State);
    /// The holder's frame for what follows (see [`Space::turn`]).
    fn turn(&mut self, frame: &Frame);
    /// The scheme can integrate a turning holder (see [`Scheme::TURNS`]).
    fn turns(&self) -> bool;
}

/// What the simulator reads from a bound space at a state: the outputs,
/// and the energies and momentum its checks weigh.
pub trait Probe {
    /// The spring force at `y` in the space's coordinates (see
    /// [`Readout::spring_force`]); the forces at `state.y` are evaluated again after.
    fn spring_force(&mut self, state: &State, y: &[f64], out: &mut [f64]);
    /// Momentum of the free nodes per axis, relative to the anchor [kg m/s].
    fn momentum(&self, state: &State) -> [f64; 3];
    /// The mass moments of the rates at `state` (see [`Readout::moments`]).
    fn motion(&self, state: &State) -> Moments;
    /// Kinetic energy of `state` [J].
    fn kinetic_energy(&self, state: &State) -> f64;
    /// Potential energy of `state` as the force model sums it (see
    /// [`Readout::model_energy`]), for the step guard, at the coordinates of
    /// the last force evaluation (the state's, or the trigonometric scheme's
    /// filtered ones: see [`Scheme::ENDS_AT_STATE`]) [J].
    fn model_energy(&mut self, state: &State) -> f64;
    /// Coordinates of the kept or reported modes.
    fn modal_coordinates(&self, state: &State, out: &mut [f64]);
    /// Node positions of `state` (whose forces were evaluated last) into
    /// `out.positions`.
    fn node_positions(&mut self, state: &State, out: &mut Outputs);
    /// Node velocities of `state` into `out.velocities` (held nodes at 0).
    fn node_velocities(&mut self, state: &State, out: &mut Outputs);
    /// Position of one node of `state` (whose forces were evaluated last),
    /// without the others; z is 0 in 2D.
    fn node_position(&mut self, state: &State, node: usize) -> [f64; 3];
    /// Velocity of one node of `state` (0 for a held node); z is 0 in 2D.
    fn node_velocity(&self, state: &State, node: usize) -> [f64; 3];
    /// First mass moment of the free nodes about the pivot at `state.y`
    /// (see [`Readout::first_moment`]) [kg m].
    fn first_moment(&self, state: &State) -> [f64; 3];
    /// The rate of change of the free nodes' momentum relative to the
    /// holder, sum M y'' per axis, with y'' of the motion the scheme
    /// integrates at `state` (whose forces were evaluated last; see
    /// [`Scheme::acceleration`]) [N].
    fn momentum_rate(&mut self, state: &State) -> [f64; 3];
    /// The mass moments of y'' at `state`, y'' as above (see
    /// [`Readout::moments`]; those of the rates are [`Probe::motion`]).
    fn acceleration_moments(&mut self, state: &State) -> Moments;
    /// Elastic energy of every spring at `state` (whose forces were evaluated last) [J].
    fn elastic_energy(&mut self, state: &State) -> f64;
    /// Elastic energy of every spring plus gravity potential at `state` [J].
    fn potential_energy(&mut self, state: &State) -> f64;
    /// The force the space cannot represent at `state`, relative to the
    /// load, with gravity and the point load as given (see [`Readout::force_residual`]).
    fn force_residual(&mut self, gravity: &[f64; 3], point: &[f64; 3], state: &State) -> f64;
}

/// Everything a simulator reports after a step.
#[derive(Clone, Debug)]
pub struct Outputs {
    /// Node positions in output order, `dim` per node, held nodes included [m].
    pub positions: Vec<f64>,
    /// Node velocities, same layout [m/s].
    pub velocities: Vec<f64>,
    /// Node positions in the holder's frame, while it has turned [m].
    pub frame_positions: Vec<f64>,
    /// Velocities of the free DOFs.
    pub dof_velocities: Vec<f64>,
    /// Coordinates of the kept or reported modes.
    pub modal_coordinates: Vec<f64>,
    /// 1/2 v^T M v [J].
    pub kinetic: f64,
    /// Elastic energy plus gravity potential relative to rest [J].
    pub potential: f64,
    /// The part of the force the space cannot represent, relative to the load.
    pub force_residual: f64,
    /// The force the sheet exerts on its holder, from the momentum balance
    /// (`docs/method.md`, section 8) [N]; z is 0 in 2D.
    pub anchor_force: [f64; 3],
    /// The torque the sheet exerts on its holder about the pivot [N m].
    pub anchor_torque: [f64; 3],
}

impl Outputs {
    pub fn new(scene: &Scene, modes: usize) -> Self {
        let nodes = scene.n_nodes * scene.dim;
        Outputs {
            positions: vec![0.0; nodes],
            velocities: vec![0.0; nodes],
            frame_positions: vec![0.0; nodes],
            dof_velocities: vec![0.0; scene.n_dofs()],
            modal_coordinates: vec![0.0; modes],
            kinetic: 0.0,
            potential: 0.0,
            force_residual: 0.0,
            anchor_force: [0.0; 3],
            anchor_torque: [0.0; 3],
        }
    }
}

/// Space `S` integrated by scheme `I`.
pub struct Engine<S: Readout, I: Scheme> {
    space: S,
    work: S::Work,
    buffers: Buffers,
    /// y'' of the scheme's motion, for the holder's force and torque.
    acceleration: Vec<f64>,
    /// The forces of `work` are those at the state's coordinates (see [`Scheme::ENDS_AT_STATE`]).
    current: bool,
    scheme: PhantomData<I>,
}

impl<S: Readout, I: Scheme> Engine<S, I> {
    /// Binds `space` to the scheme, or refuses a space the scheme cannot integrate.
    pub fn new(space: S, loads: &Loads) -> Result<Self, PhysicsError> {
        let work = space.work(loads);
        I::check(&space, &work)?;
        let n = space.layout().coordinates;
        Ok(Engine { work, buffers: Buffers::new(n, I::SCRATCH), acceleration: vec![0.0; n], current: false, space, scheme: PhantomData })
    }

    /// The space the engine steps.
    pub fn space(&self) -> &S {
        &self.space
    }

    /// The forces of `work` at `state.y`, evaluated if the last step left them elsewhere.
    fn current(&mut self, state: &State) {
        if !self.current {
            self.space.force(&state.y, &mut self.work, &mut self.buffers.h);
            self.current = true;
        }
    }

    /// y'' of the scheme's motion at `state` into `self.acceleration`.
    fn accelerate(&mut self, state: &State) {
        I::acceleration(&self.space, &mut self.work, &mut self.buffers, state, &mut self.acceleration);
    }
}

impl<S: Readout, I: Scheme> Stepper for Engine<S, I> {
    fn scene(&self) -> &Scene {
        self.space.scene()
    }

    fn layout(&self) -> Layout<'_> {
        self.space.layout()
    }

    fn setup_data(&self) -> Option<SetupData> {
        self.space.setup_data()
    }

    fn modes(&self) -> Option<&ModalBasis> {
        self.space.modes()
    }

    fn loads(&self) -> &Loads {
        self.work.as_ref()
    }

    fn loads_mut(&mut self) -> &mut Loads {
        self.work.as_mut()
    }

    fn stable_step(&self) -> Option<f64> {
        I::stable_step(self.space.omega_sq_bound(&self.work))
    }

    fn omega_sq_bound(&self) -> f64 {
        self.space.omega_sq_bound(&self.work)
    }

    fn apply_loads(&mut self) {
        self.space.apply_loads(&mut self.work);
    }

    fn rest_coordinates(&self, y: &mut [f64]) {
        self.space.rest_coordinates(y);
    }

    fn settle(&mut self, state: &mut State) {
        I::settle(&self.space, &mut self.work, &mut self.buffers, state);
        self.current = true;
    }

    fn evaluate(&mut self, state: &State) {
        self.space.force(&state.y, &mut self.work, &mut self.buffers.h);
        self.current = true;
        // A restored state.a was derived for a step size the buffers do not know.
        self.buffers.filter_step = f64::NAN;
    }

    fn step(&mut self, state: &mut State, dt: f64) -> Result<(), StepFailure> {
        self.current = I::ENDS_AT_STATE;
        I::step(&self.space, &mut self.work, &mut self.buffers, state, dt)
    }

    fn kick(&mut self, c: &[f64; 3], spin: &[f64; 3], state: &mut State) {
        if *c != [0.0; 3] {
            self.space.add_translation_rate(&self.work, c, &mut state.v);
        }
        if *spin != [0.0; 3] {
            self.space.add_rotation_rate(&self.work, spin, &state.y, &mut state.v);
        }
        I::settle_rates(&self.space, &mut self.work, &mut self.buffers, state);
    }

    fn turn(&mut self, frame: &Frame) {
        self.space.turn(frame, &mut self.work);
    }

    fn turns(&self) -> bool {
        I::TURNS
    }
}

impl<S: Readout, I: Scheme> Probe for Engine<S, I> {
    fn spring_force(&mut self, state: &State, y: &[f64], out: &mut [f64]) {
        self.space.spring_force(y, &mut self.work, out);
        self.evaluate(state);
    }

    fn momentum(&self, state: &State) -> [f64; 3] {
        self.space.momentum(&state.v)
    }

    fn motion(&self, state: &State) -> Moments {
        self.space.moments(&state.y, &state.v)
    }

    fn kinetic_energy(&self, state: &State) -> f64 {
        self.space.kinetic_energy(&state.v)
    }

    fn model_energy(&mut self, state: &State) -> f64 {
        let at = if self.current { &state.y } else { &self.buffers.a1 };
        self.space.model_energy(at, &mut self.work)
    }

    fn modal_coordinates(&self, state: &State, out: &mut [f64]) {
        self.space.modal_coordinates(&state.y, out);
    }

    fn node_positions(&mut self, state: &State, out: &mut Outputs) {
        self.current(state);
        let scene = self.space.scene();
        let x = self.space.positions(&state.y, &mut self.work);
        match scene.dim {
            2 => to_node_order::<2>(&scene.slot_of_node, usize::MAX, x, &mut out.positions),
            _ => to_node_order::<3>(&scene.slot_of_node, usize::MAX, x, &mut out.positions),
        }
    }

    fn node_velocities(&mut self, state: &State, out: &mut Outputs) {
        let scene = self.space.scene();
        self.space.dof_velocities(&state.v, &mut out.dof_velocities);
        match scene.dim {
            2 => to_node_order::<2>(&scene.slot_of_node, scene.n_free, &out.dof_velocities, &mut out.velocities),
            _ => to_node_order::<3>(&scene.slot_of_node, scene.n_free, &out.dof_velocities, &mut out.velocities),
        }
    }

    fn node_position(&mut self, state: &State, node: usize) -> [f64; 3] {
        self.space.slot_position(&state.y, self.space.scene().slot_of_node[node], &mut self.work)
    }

    fn node_velocity(&self, state: &State, node: usize) -> [f64; 3] {
        let scene = self.space.scene();
        let slot = scene.slot_of_node[node];
        if slot < scene.n_free {
            self.space.slot_velocity(&state.v, slot)
        } else {
            [0.0; 3]
        }
    }

    fn first_moment(&self, state: &State) -> [f64; 3] {
        self.space.first_moment(&state.y)
    }

    fn momentum_rate(&mut self, state: &State) -> [f64; 3] {
        self.accelerate(state);
        self.space.momentum(&self.acceleration)
    }

    fn acceleration_moments(&mut self, state: &State) -> Moments {
        self.accelerate(state);
        self.space.moments(&state.y, &self.acceleration)
    }

    fn elastic_energy(&mut self, state: &State) -> f64 {
        self.current(state);
        self.space.elastic_energy(&state.y, &mut self.work)
    }

    fn potential_energy(&mut self, state: &State) -> f64 {
        self.current(state);
        self.space.elastic_energy(&state.y, &mut self.work) + self.space.gravity_potential(&state.y, &self.work)
    }

    fn force_residual(&mut self, gravity: &[f64; 3], point: &[f64; 3], state: &State) -> f64 {
        self.current(state);
        self.space.force_residual(gravity, point, &state.y, &mut self.work)
    }
}
/// Slot-ordered values into node order, for the nodes whose slot is below
/// `limit` (the free slots for velocities; every slot for positions); the
/// other nodes get 0 (held nodes have no velocity of their own: the
/// anchor's is added to every node afterwards). Fixed length `D` keeps each
/// copy a pair of moves instead of a `memmove` call.
fn to_node_order<const D: usize>(slot_of_node: &[usize], limit: usize, from: &[f64], to: &mut [f64]) {
    for (&slot, t) in slot_of_node.iter().zip(to.chunks_exact_mut(D)) {
        let t = <&mut [f64; D]>::try_from(t).expect("D values");
        if slot < limit {
            *t = *<&[f64; D]>::try_from(&from[slot * D..slot * D + D]).expect("D values");
        } else {
            *t = [0.0; D];
        }
    }
}
