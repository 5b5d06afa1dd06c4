//! The simulator: set-up (assembly, eigen decomposition, step-size limits)
//! and the co-simulation step split into internal Newmark steps.

use faer::Side;

use super::forces::{add_reduced_tangent, omega_sq_bound_full, StiffnessPattern};
use super::full::FullSolver;
use super::modal::ModalSolver;
use super::modes::ModalBasis;
use super::params::*;
use super::scene::Scene;

/// Why a scene was refused or a step failed. The message names the parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct SimError {
    pub message: String,
}

impl std::fmt::Display for SimError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}
impl std::error::Error for SimError {}

fn err<T>(message: String) -> Result<T, SimError> {
    Err(SimError { message })
}

/// Everything needed to resume a run: time, integrator state, tunables.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    pub time: f64,
    /// Integrator state [y, y', y''] (modal coordinates or full-space
    /// displacements); its length is checked on restore.
    pub state: Vec<f64>,
    pub tunables: Tunables,
}

/// Explicit steps are kept at this fraction of the stability limit 2 / omega.
pub const EXPLICIT_SAFETY: f64 = 0.9;
/// Internal steps one communication step may take before it is refused.
pub const MAX_INTERNAL_STEPS_PER_CALL: usize = 10_000_000;
/// Explicit internal steps one `maxInternalStep` may be split into before
/// set-up refuses the explicit integrator: beyond it the scene is too stiff
/// for it (the implicit integrator takes `maxInternalStep` in one step), unless
/// the host asked for steps that short by lowering `maxInternalStep`.
pub const MAX_EXPLICIT_SUBSTEPS: f64 = 1e4;
/// Above this many modes the explicit limit uses the full-space bound instead
/// of the eigenvalues of the reduced taut stiffness.
const DENSE_BOUND_MODES: usize = 64;
/// Kinetic energy growth in one communication step, relative to the energy
/// at its start plus the work gravity can do across the sheet, that is taken
/// as a blow-up.
const ENERGY_GROWTH_LIMIT: f64 = 1e6;

enum Model {
    Modal(ModalSolver),
    Full(FullSolver),
}

pub struct Simulator {
    scene: Scene,
    solver: SolverParams,
    tunables: Tunables,
    model: Model,
    /// Modes reported by a full-space run (`n_modes` > 0).
    reported_basis: Option<ModalBasis>,
    frequencies: Vec<f64>,
    /// Squared-frequency bound of the integrated system with unit weights.
    omega_sq_bound: f64,
    time: f64,
    internal_steps_last: usize,
    positions: Vec<f64>,
    velocities: Vec<f64>,
    dof_velocities: Vec<f64>,
    modal_coordinates: Vec<f64>,
    kinetic: f64,
    potential: f64,
    /// State at the start of the current step, restored if it fails.
    backup: Vec<f64>,
    /// Largest distance a node can fall (sheet diagonal plus one spacing) for the blow-up bound.
    fall_scale: f64,
    total_mass: f64,
}

impl Simulator {
    /// Set-up: assembles the scene and its stiffness at rest, decomposes it when
    /// modes are needed, and bounds the explicit step. Refuses parameters it
    /// cannot run, naming them.
    pub fn new(scene_params: &SceneParams, solver: &SolverParams, tunables: &Tunables) -> Result<Self, SimError> {
        let scene = Scene::build(scene_params)?;
        if !(solver.max_internal_step.is_finite() && solver.max_internal_step > 0.0) {
            return err(format!("maxInternalStep must be finite and positive, got {}", solver.max_internal_step));
        }
        if scene.n_dofs() == 0 {
            return err(format!(
                "ny = {} (nx = {}) leaves no free node under fixedNodes: the scene has no free degree of freedom; \
                 it needs ny >= 2 (or nx >= 3 with top-corners)",
                scene_params.ny, scene_params.nx
            ));
        }
        if solver.reduction == Reduction::Modal && solver.n_modes == 0 {
            return err("nModes must be at least 1 with reduction = modal".into());
        }
        validate_tunables(tunables, solver.n_modes)?;
        let n = scene.n_dofs();
        let pattern = StiffnessPattern::new(&scene);
        let mut k0 = vec![0.0; pattern.nnz()];
        pattern.add_tangent(&scene, &scene.rest, 1.0, &mut k0);
        let basis = if solver.n_modes > 0 { Some(ModalBasis::lowest(&scene, &pattern, &k0, solver.n_modes)?) } else { None };
        let frequencies = basis.as_ref().map(|b| b.frequencies()).unwrap_or_default();
        let total_mass: f64 = scene.dof_mass.iter().step_by(scene.dim).sum();
        let length_scale = scene.rest.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let fall_scale = ((scene.nx as f64).hypot(scene.ny as f64) + 1.0) * scene_params.spacing;
        let (model, reported_basis, omega_sq_bound) = match solver.reduction {
            Reduction::Modal => {
                let basis = basis.expect("modal reduction has modes");
                let bound = if basis.r <= DENSE_BOUND_MODES { taut_reduced_bound(&scene, &basis)? } else { omega_sq_bound_full(&scene) };
                let q_scale = total_mass.sqrt() * length_scale.max(f64::MIN_POSITIVE);
                (Model::Modal(ModalSolver::new(&scene, basis, tunables, q_scale)), None, bound)
            }
            Reduction::Full => {
                let bound = omega_sq_bound_full(&scene);
                (Model::Full(FullSolver::new(&scene, pattern, k0, tunables)?), basis, bound)
            }
        };
        let r = solver.n_modes;
        let mut sim = Simulator {
            positions: vec![0.0; scene.n_nodes * scene.dim],
            velocities: vec![0.0; scene.n_nodes * scene.dim],
            dof_velocities: vec![0.0; n],
            modal_coordinates: vec![0.0; r],
            backup: vec![
                0.0;
                3 * match &model {
                    Model::Modal(m) => m.q.len(),
                    Model::Full(f) => f.u.len(),
                }
            ],
            scene,
            solver: solver.clone(),
            tunables: tunables.clone(),
            model,
            reported_basis,
            frequencies,
            omega_sq_bound,
            time: 0.0,
            internal_steps_last: 0,
            kinetic: 0.0,
            potential: 0.0,
            fall_scale,
            total_mass,
        };
        sim.check_explicit_cost(scene_params)?;
        sim.refresh_outputs();
        Ok(sim)
    }

    /// Refuses an explicit run whose stability limit would split every
    /// `maxInternalStep` into more than MAX_EXPLICIT_SUBSTEPS internal steps,
    /// naming what sets the limit and what would lift it.
    fn check_explicit_cost(&self, p: &SceneParams) -> Result<(), SimError> {
        if self.solver.integrator != Integrator::NewmarkExplicit || !self.solver.substepping {
            return Ok(());
        }
        let dt = self.max_stable_step();
        let per_step = self.solver.max_internal_step / dt;
        if per_step <= MAX_EXPLICIT_SUBSTEPS {
            return Ok(());
        }
        let kept = match self.model {
            Model::Modal(_) => format!("the {} kept modes", self.solver.n_modes),
            Model::Full(_) => "full space".to_string(),
        };
        err(format!(
            "integrator = newmark-explicit is stable here only with internal steps of {dt:.3e} s \
             (highest frequency {:.3e} rad/s of {kept}, springStiffness / nodeMass = {:.3e} 1/s^2), \
             {per_step:.2e} of them per maxInternalStep = {} s (limit {MAX_EXPLICIT_SUBSTEPS:e}): \
             use integrator = newmark-implicit, fewer modes (nModes), \
             or set maxInternalStep to {:.3e} s or less to accept steps that short",
            self.omega_sq_bound.sqrt(),
            p.spring_stiffness.max(p.aux_stiffness) / p.node_mass,
            self.solver.max_internal_step,
            dt * MAX_EXPLICIT_SUBSTEPS,
        ))
    }

    /// Largest internal step: `maxInternalStep`, and for the explicit
    /// integrator EXPLICIT_SAFETY * 2 / omega_bound, where omega_bound bounds
    /// the frequencies of the integrated system in any state without
    /// compressed springs (weights above 1 scale the bound up).
    pub fn max_stable_step(&self) -> f64 {
        let mut dt = self.solver.max_internal_step;
        if self.solver.integrator == Integrator::NewmarkExplicit {
            let w_max = match self.model {
                Model::Modal(_) => self.tunables.mode_weights.iter().fold(1.0f64, |m, w| m.max(*w)),
                Model::Full(_) => 1.0,
            };
            let omega = (w_max * self.omega_sq_bound).sqrt();
            if omega > 0.0 {
                dt = dt.min(EXPLICIT_SAFETY * 2.0 / omega);
            }
        }
        dt
    }

    /// Advances by `h` seconds in equal internal steps no longer than
    /// [`Self::max_stable_step`]. On error the state is that of the start of the call.
    pub fn do_step(&mut self, h: f64) -> Result<(), SimError> {
        if !(h.is_finite() && h > 0.0) {
            return err(format!("communication step size must be finite and positive, got {h}"));
        }
        let steps = if self.solver.substepping { (h / self.max_stable_step()).ceil().max(1.0) } else { 1.0 };
        if steps > MAX_INTERNAL_STEPS_PER_CALL as f64 {
            return err(format!(
                "a step of {h:e} s needs {steps:e} internal steps of at most {:e} s (limit {MAX_INTERNAL_STEPS_PER_CALL}); \
                 use the implicit integrator, fewer modes or a shorter communication step",
                self.max_stable_step()
            ));
        }
        let steps = steps as usize;
        let dt = h / steps as f64;
        let energy_before = self.kinetic + self.potential.abs();
        self.save_backup();
        let scene = &self.scene;
        let mut result = Ok(());
        for _ in 0..steps {
            result = match (&mut self.model, self.solver.integrator) {
                (Model::Modal(m), Integrator::NewmarkExplicit) => m.step_explicit(scene, dt),
                (Model::Modal(m), Integrator::NewmarkImplicit) => m.step_implicit(scene, dt),
                (Model::Full(f), Integrator::NewmarkExplicit) => f.step_explicit(scene, dt),
                (Model::Full(f), Integrator::NewmarkImplicit) => f.step_implicit(scene, dt),
            };
            if result.is_err() {
                break;
            }
        }
        let result = result.and_then(|_| self.check_state(dt, energy_before));
        if let Err(e) = result {
            self.restore_backup();
            return Err(SimError { message: format!("step from t = {} s failed: {}", self.time, e.message) });
        }
        self.internal_steps_last = steps;
        self.time += h;
        self.refresh_outputs();
        Ok(())
    }

    /// Rejects non-finite states and kinetic energy that grew far beyond what
    /// the loads could supply.
    fn check_state(&mut self, dt: f64, energy_before: f64) -> Result<(), SimError> {
        let (y, v) = match &self.model {
            Model::Modal(m) => (&m.q, &m.qd),
            Model::Full(f) => (&f.u, &f.v),
        };
        if !y.iter().chain(v.iter()).all(|z| z.is_finite()) {
            return err(format!("the state became non-finite (internal step {dt:e} s); the integration diverged"));
        }
        let kinetic = self.kinetic_now();
        let g = self.tunables.gravity.iter().map(|c| c * c).sum::<f64>().sqrt();
        let w_max = self.tunables.mode_weights.iter().fold(1.0f64, |m, w| m.max(*w));
        let supply = self.total_mass * (g + 1.0) * self.fall_scale * w_max;
        if !(kinetic <= ENERGY_GROWTH_LIMIT * (energy_before + supply)) {
            return err(format!(
                "kinetic energy grew to {kinetic:e} J from {energy_before:e} J in one step (internal step {dt:e} s); the integration diverged"
            ));
        }
        Ok(())
    }

    fn kinetic_now(&self) -> f64 {
        match &self.model {
            Model::Modal(m) => m.kinetic_energy(),
            Model::Full(f) => 0.5 * f.v.iter().zip(&self.scene.dof_mass).map(|(v, m)| m * v * v).sum::<f64>(),
        }
    }

    fn save_backup(&mut self) {
        let (y, v, a) = match &self.model {
            Model::Modal(m) => (&m.q, &m.qd, &m.qdd),
            Model::Full(f) => (&f.u, &f.v, &f.a),
        };
        let m = y.len();
        let (b0, rest) = self.backup.split_at_mut(m);
        let (b1, b2) = rest.split_at_mut(m);
        b0.copy_from_slice(y);
        b1.copy_from_slice(v);
        b2.copy_from_slice(a);
    }

    fn restore_backup(&mut self) {
        let backup = std::mem::take(&mut self.backup);
        self.set_state_parts(&backup);
        self.backup = backup;
        match &mut self.model {
            Model::Modal(m) => m.refresh_positions(&self.scene),
            Model::Full(f) => f.refresh_positions(&self.scene),
        }
    }

    fn state_parts(&self) -> (&[f64], &[f64], &[f64]) {
        match &self.model {
            Model::Modal(m) => (&m.q, &m.qd, &m.qdd),
            Model::Full(f) => (&f.u, &f.v, &f.a),
        }
    }

    fn set_state_parts(&mut self, s: &[f64]) {
        let (y, v, a) = match &mut self.model {
            Model::Modal(m) => (&mut m.q, &mut m.qd, &mut m.qdd),
            Model::Full(f) => (&mut f.u, &mut f.v, &mut f.a),
        };
        let m = y.len();
        y.copy_from_slice(&s[..m]);
        v.copy_from_slice(&s[m..2 * m]);
        a.copy_from_slice(&s[2 * m..3 * m]);
    }

    /// Positions, velocities, modal coordinates and energies from the state.
    fn refresh_outputs(&mut self) {
        let d = self.scene.dim;
        self.kinetic = self.kinetic_now();
        let (x, elastic, gravity_potential) = match &self.model {
            Model::Modal(m) => {
                m.dof_velocities(&mut self.dof_velocities);
                self.modal_coordinates.copy_from_slice(&m.q);
                (&m.x, m.elastic, m.gravity_potential())
            }
            Model::Full(f) => {
                self.dof_velocities.copy_from_slice(&f.v);
                if let Some(b) = &self.reported_basis {
                    b.project_displacement(&self.scene.dof_mass, &f.u, &mut self.modal_coordinates);
                }
                let g = &self.tunables.gravity;
                let work: f64 =
                    f.u.chunks_exact(d).zip(self.scene.dof_mass.chunks_exact(d)).map(|(u, m)| (0..d).map(|i| m[i] * g[i] * u[i]).sum::<f64>()).sum();
                (&f.x, f.elastic, -work)
            }
        };
        let nf = self.scene.n_free;
        let order = &self.scene.slot_of_node;
        match d {
            2 => to_node_order::<2>(order, nf, x, &self.dof_velocities, &mut self.positions, &mut self.velocities),
            _ => to_node_order::<3>(order, nf, x, &self.dof_velocities, &mut self.positions, &mut self.velocities),
        }
        self.potential = elastic + gravity_potential;
    }

    pub fn time(&self) -> f64 {
        self.time
    }
    pub fn n_nodes(&self) -> usize {
        self.scene.n_nodes
    }
    pub fn dimension(&self) -> usize {
        self.scene.dim
    }
    /// Free degrees of freedom.
    pub fn n_dofs(&self) -> usize {
        self.scene.n_dofs()
    }
    /// Node positions, `n_nodes x dimension`, node order of METHOD.md, fixed nodes included [m].
    pub fn positions(&self) -> &[f64] {
        &self.positions
    }
    /// Node velocities, same layout as positions [m/s].
    pub fn velocities(&self) -> &[f64] {
        &self.velocities
    }
    /// Coordinates of the kept (modal) or reported (full) modes.
    pub fn modal_coordinates(&self) -> &[f64] {
        &self.modal_coordinates
    }
    /// omega_i of the kept or reported modes, ascending [rad/s].
    pub fn mode_frequencies(&self) -> &[f64] {
        &self.frequencies
    }
    /// 1/2 v^T M v [J].
    pub fn kinetic_energy(&self) -> f64 {
        self.kinetic
    }
    /// Elastic energy of the springs plus gravitational energy relative to rest [J].
    pub fn potential_energy(&self) -> f64 {
        self.potential
    }
    pub fn tunables(&self) -> &Tunables {
        &self.tunables
    }
    pub fn solver(&self) -> &SolverParams {
        &self.solver
    }
    /// Internal steps taken by the last successful `do_step`.
    pub fn internal_steps_last(&self) -> usize {
        self.internal_steps_last
    }

    /// New loads and gains, effective from now. The acceleration is
    /// recomputed at the current state, so a load change acts as a step input.
    pub fn set_tunables(&mut self, t: &Tunables) -> Result<(), SimError> {
        if *t == self.tunables {
            return Ok(());
        }
        validate_tunables(t, self.solver.n_modes)?;
        self.tunables.clone_from(t);
        match &mut self.model {
            Model::Modal(m) => {
                m.set_tunables(&self.scene, t);
                m.reset_acceleration(&self.scene);
            }
            Model::Full(f) => {
                f.set_tunables(&self.scene, t);
                f.reset_acceleration(&self.scene);
            }
        }
        self.refresh_outputs();
        Ok(())
    }

    pub fn snapshot(&self) -> Snapshot {
        let (y, v, a) = self.state_parts();
        Snapshot { time: self.time, state: [y, v, a].concat(), tunables: self.tunables.clone() }
    }

    /// Resumes from a snapshot of a simulator of the same scene and solver.
    pub fn restore(&mut self, s: &Snapshot) -> Result<(), SimError> {
        if s.state.len() != self.backup.len() {
            return err(format!("snapshot holds {} state values, this scene needs {}", s.state.len(), self.backup.len()));
        }
        if !s.time.is_finite() || !s.state.iter().all(|v| v.is_finite()) {
            return err("snapshot holds non-finite values".into());
        }
        validate_tunables(&s.tunables, self.solver.n_modes)?;
        self.tunables.clone_from(&s.tunables);
        match &mut self.model {
            Model::Modal(m) => m.set_tunables(&self.scene, &s.tunables),
            Model::Full(f) => f.set_tunables(&self.scene, &s.tunables),
        }
        self.set_state_parts(&s.state);
        self.time = s.time;
        match &mut self.model {
            Model::Modal(m) => m.refresh_positions(&self.scene),
            Model::Full(f) => f.refresh_positions(&self.scene),
        }
        self.refresh_outputs();
        Ok(())
    }
}

/// Slot-ordered positions and free-DOF velocities into node order. Fixed
/// length `D` keeps each copy a pair of moves instead of a `memmove` call.
fn to_node_order<const D: usize>(slot_of_node: &[usize], n_free: usize, x: &[f64], v: &[f64], positions: &mut [f64], velocities: &mut [f64]) {
    for ((&slot, p), vel) in slot_of_node.iter().zip(positions.chunks_exact_mut(D)).zip(velocities.chunks_exact_mut(D)) {
        let xs: &[f64; D] = x[slot * D..slot * D + D].try_into().expect("D values");
        *<&mut [f64; D]>::try_from(p).expect("D values") = *xs;
        if slot < n_free {
            let vs: &[f64; D] = v[slot * D..slot * D + D].try_into().expect("D values");
            *<&mut [f64; D]>::try_from(vel).expect("D values") = *vs;
        }
    }
}

fn validate_tunables(t: &Tunables, n_modes: usize) -> Result<(), SimError> {
    if !t.gravity.iter().all(|g| g.is_finite()) {
        return err(format!("gravity must be finite, got {:?}", t.gravity));
    }
    if !(t.damping_alpha.is_finite() && t.damping_alpha >= 0.0) {
        return err(format!("dampingAlpha must be finite and non-negative, got {}", t.damping_alpha));
    }
    if !(t.damping_beta.is_finite() && t.damping_beta >= 0.0) {
        return err(format!("dampingBeta must be finite and non-negative, got {}", t.damping_beta));
    }
    if t.mode_weights.len() != n_modes {
        return err(format!("modeWeights has {} values, nModes is {n_modes}", t.mode_weights.len()));
    }
    if let Some(w) = t.mode_weights.iter().find(|w| !(w.is_finite() && **w >= 0.0)) {
        return err(format!("modeWeights must be finite and non-negative, got {w}"));
    }
    Ok(())
}

/// lambda_max(Phi^T K_taut Phi): bound on the squared frequencies of the
/// reduced system in any state without compressed springs.
fn taut_reduced_bound(scene: &Scene, basis: &ModalBasis) -> Result<f64, SimError> {
    let r = basis.r;
    let mut kr = vec![0.0; r * r];
    let mut work = vec![0.0; 6 * r];
    add_reduced_tangent(scene, &scene.rest, &basis.phi, r, true, &mut kr, &mut work);
    let m = faer::Mat::<f64>::from_fn(r, r, |i, j| kr[j * r + i]);
    let ev = m.self_adjoint_eigenvalues(Side::Lower).map_err(|e| SimError { message: format!("eigenvalues of the reduced stiffness failed: {e:?}") })?;
    Ok(ev.last().copied().unwrap_or(0.0).max(0.0))
}
