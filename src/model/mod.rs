//! The model this FMU exports, beside the generic FMI layer [`crate::fmi`]
//! (as the Modelica Reference FMUs keep each model's `model.c` beside their
//! generic `fmi3Functions.c`): what the variables of
//! `modelDescription/variables.toml` mean to [`crate::physics`], and the
//! model's own rules, behind the [`Model`] interface the glue calls.
//!
//! - [`to_physics`]: values -> grid, solver settings, loads, load node, a twin's start; the canonical scenes;
//! - [`messages`]: physics errors as messages naming the variables;
//! - [`bake`]: the baked set-up in `resources/setup.bin`;
//! - [`state_bytes`]: the simulator's part of a serialized FMU state;
//! - here: set-up, the Set rules (the load node's default column, its
//!   check, loads passed to the running simulator), the outputs, the step
//!   and when it warns about forceResidual.

pub mod bake;
pub mod messages;
mod state_bytes;
pub mod to_physics;

use std::path::Path;

use crate::bytes::Reader;
use crate::fmi::logging::Logger;
use crate::fmi::model::{Computed, Model, StepEnd};
use crate::fmi::variables::{index_of, vr, Causality, VARIABLES};
use crate::physics::{FullThroughout, ModeClasses, Simulator, Snapshot};
use crate::status::{OK, WARNING};

pub use crate::fmi::params::Params;
use to_physics::HOLDER_OUTPUTS;

/// The mass-spring sheet of the model description, as one instance runs it.
pub struct MassSpring {
    /// Built on demand; `None` or `stale` means the values changed since.
    sim: Option<Simulator>,
    stale: bool,
    /// The FMU's `resources/setup.bin`, if it has one.
    baked: Option<Vec<u8>>,
    /// forceResidual passed forceResidualLimit once, and the host was told.
    residual_warned: bool,
    /// The residual check is due after the next step (a new simulator, new
    /// loads, a restored state); the steps taken since the last check, and
    /// the steps to the next one, doubled after every check up to [`residual_period`].
    residual_due: bool,
    residual_wait: u64,
    residual_gap: u64,
    /// Springs the checks since the last change visited (see [`WARM_UP_VISITS`]).
    residual_spent: u64,
    /// trainingRange passed trainingRangeLimit once, and the host was told.
    range_warned: bool,
    /// The host set loadColumn; until then it follows the middle of the row (nx / 2).
    load_column_chosen: bool,
    /// The springs between nodes (see [`MassSpring::spring_neighbours`]), made when first read.
    springs: Option<Vec<f64>>,
    /// modeOutOfPlane and modeSymmetry, made when first read.
    classes: Option<ModeClasses>,
    /// modeShapes, made when first read.
    shapes: Option<Vec<f64>>,
}

impl Model for MassSpring {
    type Snapshot = Snapshot;

    fn new(resources: Option<&Path>) -> Self {
        MassSpring {
            sim: None,
            stale: true,
            baked: resources.and_then(|dir| std::fs::read(dir.join(bake::FILE)).ok()),
            residual_warned: false,
            residual_due: true,
            residual_wait: 0,
            residual_gap: 1,
            residual_spent: 0,
            range_warned: false,
            load_column_chosen: false,
            springs: None,
            classes: None,
            shapes: None,
        }
    }

    fn reset(&mut self) {
        self.sim = None;
        self.stale = true;
        self.residual_warned = false;
        self.residual_due = true;
        self.range_warned = false;
        self.load_column_chosen = false;
        self.springs = None;
        self.classes = None;
        self.shapes = None;
    }

    fn is_set_up(&self) -> bool {
        self.sim.is_some() && !self.stale
    }

    fn set_up(&mut self, p: &Params, log: &Logger) -> Result<(), String> {
        let prebuilt = self.baked.as_ref().and_then(|bytes| match bake::read(bytes, p) {
            Ok(data) => Some(data),
            Err(why) => {
                log.log(WARNING, &format!("resources/{} not used, set-up computed: {why}", bake::FILE));
                None
            }
        });
        let built = match (&prebuilt, p.build_with(prebuilt.as_ref())) {
            (Some(_), Ok(sim)) => {
                log.log(OK, &format!("set-up taken from resources/{}", bake::FILE));
                Ok(sim)
            }
            (Some(_), Err(e)) => {
                log.log(WARNING, &format!("resources/{} not used, set-up computed: {e}", bake::FILE));
                p.build()
            }
            (None, result) => result,
        };
        match built {
            Ok(sim) => {
                // (Full space makes the modes it reports when they are first read.)
                log.log(OK, &format!("simulator set up: {} nodes in {}D, {} modes", sim.scene().n_nodes, sim.scene().dim, sim.settings().n_modes));
                if sim.settings().reduction == crate::options::Reduction::Adaptive {
                    let status = sim.reduction_status();
                    let (springs, all) = (sim.cubature_springs(), sim.scene().springs.len());
                    let forces = if springs < all { format!("cubature forces ({springs} of {all} springs)") } else { "exact forces".to_string() };
                    let model = match status.error_directions {
                        0 => "the error model in full space".to_string(),
                        k => format!("the error model in {k} directions beyond the basis, on a cubature"),
                    };
                    let chosen = format!(
                        "reduction = adaptive: a trained basis of {} vectors chosen for errorTolerance = {} (its held-out snapshots' projection error within a quarter of it)",
                        status.chosen_size,
                        sim.settings().error_tolerance
                    );
                    let n = sim.n_dofs();
                    match status.why_full {
                        None => log.log(OK, &format!("{chosen}, {forces}, {model}")),
                        Some(FullThroughout::FewDofs) => log.log(
                            OK,
                            &format!(
                                "{chosen}; on {n} free DOFs a basis pays with at most one vector per {} of them: full space throughout",
                                crate::physics::ADAPTIVE_DOFS_PER_VECTOR
                            ),
                        ),
                        Some(FullThroughout::ExactForces) => log.log(
                            OK,
                            &format!(
                                "{chosen}; with its error directions it passes the {} vectors a cubature is trained for, and with exact forces on {all} springs a reduced step costs what a full-space step does: full space throughout",
                                crate::physics::ADAPTIVE_JOINT_CUBATURE_MODES
                            ),
                        ),
                    }
                }
                self.installed(sim);
                Ok(())
            }
            Err(e) => Err(format!("cannot set up the simulator: {}", messages::describe(&e, p))),
        }
    }

    fn time(&self) -> Option<f64> {
        self.sim.as_ref().filter(|_| !self.stale).map(|s| s.time())
    }

    fn set(&mut self, p: &mut Params, old: &Params, vrs: &[u32], running: bool) -> Result<(), String> {
        let chooses_column = vrs.contains(&vr::LOAD_COLUMN);
        if !chooses_column && !self.load_column_chosen && vrs.contains(&vr::NX) {
            p.follow_middle_column();
        }
        if p == old {
            self.load_column_chosen |= chooses_column;
            return Ok(());
        }
        // The load node is checked against the grid when it is chosen.
        if vrs.iter().any(|&r| r == vr::LOAD_ROW || r == vr::LOAD_COLUMN) {
            if let Some(why) = p.load_node_problem() {
                return Err(format!("refused: {why}"));
            }
        }
        self.load_column_chosen |= chooses_column;
        if running {
            // Only tunables and inputs get here; they act from the next step on.
            let sim = self.sim.as_mut().expect("Step Mode has a simulator");
            // Written where the physics reads them, all or nothing; errorTolerance
            // once set between steps (at set-up it chose the basis, and the run follows it).
            let tolerance = vrs.contains(&vr::ERROR_TOLERANCE).then(|| p.scalar(vr::ERROR_TOLERANCE));
            sim.edit_loads(&mut |loads| {
                p.fill_loads(loads);
                if tolerance.is_some() {
                    loads.error_tolerance = tolerance;
                }
            })
            .map_err(|e| messages::describe(&e, p))?;
            // New parameters (gravity turned sideways, weights, damping) are checked after the
            // next step; the inputs a master sets every step (the point load, the holder) are not,
            // or the check would run after every step of a coupled run.
            if vrs.iter().any(|&r| index_of(r).is_some_and(|i| VARIABLES[i].causality != Causality::Input)) {
                self.residual_due = true;
            }
        } else {
            self.stale = true;
        }
        Ok(())
    }

    fn output(&mut self, r: u32, time0: f64) -> Computed<'_> {
        if r == vr::SPRING_NEIGHBOURS {
            return Computed::Array(self.spring_neighbours());
        }
        if matches!(r, vr::MODE_OUT_OF_PLANE | vr::MODE_SYMMETRY | vr::MODE_SHAPES | vr::MODAL_COORDINATES | vr::MODE_FREQUENCIES) {
            // Full space makes the modes it reports when first asked for.
            let sim = self.sim.as_ref().expect("outputs are read from a simulator");
            if let Err(e) = sim.modes_made() {
                return Computed::Refused(format!("the nModes = {} reported modes cannot be made: {e}", sim.settings().n_modes));
            }
        }
        if r == vr::MODE_OUT_OF_PLANE || r == vr::MODE_SYMMETRY {
            let sim = self.sim.as_ref().expect("outputs are read from a simulator");
            let classes = self.classes.get_or_insert_with(|| sim.mode_classes());
            return Computed::Array(if r == vr::MODE_OUT_OF_PLANE { &classes.out_of_plane } else { &classes.symmetry });
        }
        if r == vr::MODE_SHAPES {
            let sim = self.sim.as_ref().expect("outputs are read from a simulator");
            let shapes = self.shapes.get_or_insert_with(|| sim.mode_grid_shapes());
            return Computed::Array(shapes);
        }
        let sim = self.sim.as_mut().expect("outputs are read from a simulator");
        match r {
            vr::TIME => Computed::Scalar(time0 + sim.time()),
            vr::POSITIONS => Computed::Array(sim.positions()),
            vr::VELOCITIES => Computed::Array(sim.velocities()),
            vr::MODAL_COORDINATES => Computed::Array(sim.modal_coordinates()),
            vr::KINETIC_ENERGY => Computed::Scalar(sim.kinetic_energy()),
            vr::POTENTIAL_ENERGY => Computed::Scalar(sim.potential_energy()),
            vr::MODE_FREQUENCIES => Computed::Array(sim.mode_frequencies()),
            vr::FORCE_RESIDUAL => Computed::Scalar(sim.force_residual()),
            vr::TRAINING_RANGE => Computed::Scalar(sim.training_range()),
            vr::CUBATURE_SPRINGS => Computed::Scalar(sim.cubature_springs() as f64),
            vr::ERROR_ESTIMATE => Computed::Scalar(sim.reduction_status().error_estimate),
            vr::REDUCED_FRACTION => Computed::Scalar(sim.reduction_status().reduced_fraction),
            vr::BASIS_SIZE => Computed::Scalar(sim.reduction_status().basis_size as f64),
            vr::LOAD_NODE_X | vr::LOAD_NODE_Y | vr::LOAD_NODE_Z => Computed::Scalar(component(sim.load_node_position(), (r - vr::LOAD_NODE_X) as usize)),
            vr::LOAD_NODE_V_X | vr::LOAD_NODE_V_Y | vr::LOAD_NODE_V_Z => {
                Computed::Scalar(component(sim.load_node_velocity(), (r - vr::LOAD_NODE_V_X) as usize))
            }
            _ => {
                let (k, i) = HOLDER_OUTPUTS
                    .iter()
                    .enumerate()
                    .find_map(|(k, vrs)| vrs.iter().position(|&v| v == r).map(|i| (k, i)))
                    .unwrap_or_else(|| unreachable!("value reference {r} is not computed"));
                Computed::Scalar(if i < 3 { sim.holder_force(k)[i] } else { sim.holder_torque(k)[i - 3] })
            }
        }
    }

    fn do_step(&mut self, p: &Params, h: f64, time0: f64) -> Result<StepEnd, String> {
        let sim = self.sim.as_mut().expect("Step Mode has a simulator");
        let adaptive = sim.settings().reduction == crate::options::Reduction::Adaptive;
        let switches = if adaptive { sim.reduction_status().switches } else { 0 };
        if let Err(e) = sim.do_step(h) {
            return Err(messages::describe(&e, p));
        }
        // An adaptive run's fall-back or return (at most one a step) goes to the log.
        let event = if adaptive {
            let status = sim.reduction_status();
            (status.switches != switches).then(|| messages::switch(&status, time0))
        } else {
            None
        };
        // The trained range costs r operations; a limit of 0 turns it off.
        let range_limit = p.scalar(vr::TRAINING_RANGE_LIMIT);
        if !self.range_warned && range_limit > 0.0 {
            let distance = sim.training_range();
            if distance > range_limit {
                self.range_warned = true;
                let end = time0 + sim.time();
                let warning = format!(
                    "at t = {end} trainingRange = {distance:.3} passed trainingRangeLimit = {range_limit}: the run has left the \
                     positions the trained basis was trained on (gravity, point load or holder motion outside the training \
                     program); the results may leave the full-space model (widen trainingScale or trainingTilt, or bake the \
                     basis for these loads)"
                );
                // A switch in the same step is said with it.
                return Ok(StepEnd::Warning(match event {
                    Some(e) => format!("{warning}; {e}"),
                    None => warning,
                }));
            }
        }
        // A check costs one pass over every spring; a limit of 0 turns it off.
        // An adaptive run watches its own error and falls back to full space
        // itself (forceResidual is still computed when read).
        let limit = p.scalar(vr::FORCE_RESIDUAL_LIMIT);
        if adaptive {
            return Ok(event.map_or(StepEnd::Done, StepEnd::Event));
        }
        if self.residual_warned || limit <= 0.0 {
            return Ok(StepEnd::Done);
        }
        self.residual_wait += 1;
        if self.residual_due {
            // After a change the scene leaves the basis soonest: checks 1, 2, 4, ... steps apart.
            self.residual_gap = 1;
            self.residual_spent = 0;
        } else if self.residual_wait < self.residual_gap {
            return Ok(StepEnd::Done);
        }
        self.residual_due = false;
        self.residual_wait = 0;
        // The warm-up's checks visit at most WARM_UP_VISITS springs; then the period's spacing.
        let springs = sim.scene().springs.len() as u64;
        self.residual_spent += springs;
        let period = residual_period(sim);
        self.residual_gap = if self.residual_spent + springs > WARM_UP_VISITS { period } else { (2 * self.residual_gap).min(period) };
        let residual = sim.force_residual();
        if residual > limit {
            self.residual_warned = true;
            let end = time0 + sim.time();
            return Ok(StepEnd::Warning(format!(
                "at t = {end} forceResidual = {residual:.3} passed forceResidualLimit = {limit}: the modal basis holds \
                 too little of the force at this state; the results may leave the full-space model (more modes, \
                 modeSelection = load, or reduction = full)"
            )));
        }
        Ok(StepEnd::Done)
    }

    fn snapshot(&self) -> Option<Snapshot> {
        self.sim.as_ref().filter(|_| !self.stale).map(|s| s.snapshot())
    }

    fn restore(&mut self, current: &Params, p: &Params, snap: Option<&Snapshot>) -> Result<(), String> {
        let Some(snap) = snap else {
            self.stale = true;
            return Ok(());
        };
        let reuse = self.is_set_up() && current.same_fixed(p);
        let mut sim = if reuse {
            None
        } else {
            match p.build() {
                Ok(sim) => Some(sim),
                Err(e) => return Err(format!("cannot set up the simulator: {}", messages::describe(&e, p))),
            }
        };
        // Restoring in place must be undoable: the state may be refused after it.
        let prior = if reuse { self.sim.as_ref().map(|s| s.snapshot()) } else { None };
        let target = sim.as_mut().or(self.sim.as_mut()).unwrap();
        if let Err(e) = target.restore(snap) {
            return Err(messages::describe(&e, p));
        }
        if !outputs_finite(target) {
            if let Some(prior) = prior {
                let _ = target.restore(&prior);
            }
            return Err("the state gives non-finite outputs (positions, velocities or energies)".into());
        }
        if let Some(sim) = sim {
            self.installed(sim);
        }
        self.stale = false;
        // A restored state is checked after the next step.
        self.residual_due = true;
        self.residual_wait = 0;
        Ok(())
    }

    fn write_snapshot(s: &Snapshot, out: &mut Vec<u8>) {
        state_bytes::write(s, out)
    }

    fn read_snapshot(r: &mut Reader, format: u32) -> Result<Snapshot, String> {
        state_bytes::read(r, format)
    }

    fn check_snapshot(s: &Snapshot, p: &Params) -> Result<(), String> {
        if s.loads != p.loads() {
            return Err("the simulator's loads differ from the parameters".into());
        }
        Ok(())
    }
}

/// The share of a run's cost the residual check may take.
pub const RESIDUAL_CHECK_SHARE: f64 = 0.1;

/// The checks 1, 2, 4, ... steps apart after a change visit at most this
/// many springs in all (about 1.5 ms of spring passes); where the next one
/// would pass it, the checks go on [`residual_period`] apart. On the small
/// sheets, whose warnings the warm-up catches early (the stability matrix,
/// cloth 30 x 30: 4 263 springs a check), it is the whole doubling; on
/// cloth 300 x 300 (448 000 springs, 5-6 ms a check) it is the first check
/// alone: a 30 s run of it at 0.01 s steps costs 1.29x the check-off
/// run instead of 4x (`cargo bench --bench step -- residual_run`).
pub const WARM_UP_VISITS: u64 = 1 << 18;

/// Communication steps between two residual checks, once the scene has
/// run a while since its last change: a check visits every spring once, a
/// step the springs of its force evaluations (every spring, or the
/// cubature set, per internal step); checking every `period` steps keeps
/// the check's share at [`RESIDUAL_CHECK_SHARE`] of the steps' own spring
/// visits. 1 where the steps visit every spring anyway. After a change the
/// checks come 1, 2, 4, ... steps apart up to it: about log2(period) more
/// checks per change.
pub fn residual_period(sim: &Simulator) -> u64 {
    let all = sim.scene().springs.len() as f64;
    let visited = (sim.cubature_springs() * sim.internal_steps_last().max(1)) as f64;
    if visited >= all {
        1
    } else {
        (all / (RESIDUAL_CHECK_SHARE * visited)).ceil() as u64
    }
}

impl MassSpring {
    /// Makes `sim`, set up from `p`, the current simulator.
    fn installed(&mut self, sim: Simulator) {
        self.sim = Some(sim);
        self.stale = false;
        self.springs = None;
        self.classes = None;
        self.shapes = None;
        self.residual_due = true;
        self.residual_wait = 0;
    }

    /// The springs between two nodes of the scene (auxiliary springs, tied
    /// to a point off the sheet, left out): for every node i in output
    /// order, the nodes j > i a spring joins it to, ascending, then n (no
    /// node) up to [`MAX_SPRINGS_PER_NODE`] places.
    fn spring_neighbours(&mut self) -> &[f64] {
        let sim = self.sim.as_ref().expect("outputs are read from a simulator");
        self.springs.get_or_insert_with(|| {
            let scene = sim.scene();
            let n = scene.n_nodes;
            let mut node_of_slot = vec![usize::MAX; scene.rest.len() / scene.dim];
            for (node, &slot) in scene.slot_of_node.iter().enumerate() {
                node_of_slot[slot] = node;
            }
            let mut ends: Vec<Vec<usize>> = vec![Vec::new(); n];
            for s in &scene.springs {
                let (a, b) = (node_of_slot[s.a], node_of_slot[s.b]);
                if a != usize::MAX && b != usize::MAX {
                    ends[a.min(b)].push(a.max(b));
                }
            }
            let mut out = vec![n as f64; n * MAX_SPRINGS_PER_NODE];
            for (i, mut js) in ends.into_iter().enumerate() {
                js.sort_unstable();
                // The grid starts at most MAX_SPRINGS_PER_NODE springs at a node.
                for (o, j) in out[i * MAX_SPRINGS_PER_NODE..(i + 1) * MAX_SPRINGS_PER_NODE].iter_mut().zip(js) {
                    *o = j as f64;
                }
            }
            out
        })
    }
}

/// Springs the grid starts at one node, to the nodes of higher index: the
/// next in its row, the one below, two diagonals, two bending springs.
pub const MAX_SPRINGS_PER_NODE: usize = 6;

/// Component `i` of a node vector (z is 0 in 2D); NaN when there is no
/// such node (set-up refuses a load node outside the grid).
fn component(v: Option<[f64; 3]>, i: usize) -> f64 {
    v.map_or(f64::NAN, |v| v[i])
}

/// Every output of the simulator is a finite number.
pub fn outputs_finite(sim: &mut Simulator) -> bool {
    let finite = |a: &[f64]| a.iter().all(|x| x.is_finite());
    // The modal coordinates are not read here: they are finite with the
    // positions (Φᵀ M (x − x*) in full space, x = x* + Φ q in the modal
    // space), and full space makes its reported modes only when they are read.
    finite(sim.positions()) && finite(sim.velocities()) && sim.kinetic_energy().is_finite() && sim.potential_energy().is_finite()
}
