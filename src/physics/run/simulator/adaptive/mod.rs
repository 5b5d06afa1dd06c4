//! The adaptive reduction ([`Reduction::Adaptive`], `docs/method.md`, section 10): a reduced run
//! and a full-space run of the same scene, one of them stepping, with the
//! error model between them.
//!
//! - Reduced: each communication step is taken in the modal space; the
//!   error model advances under the residual at the step's end
//!   ([`crate::physics::run::error_model`]) and the estimate of E counts
//!   the step. Where the estimated error of the state, relative to how far
//!   the sheet has moved (at least the RMS motion of its training program),
//!   passes [`FALL_BACK`] times the tolerance, the step is undone and taken
//!   again in full space from the lifted state x = x* + Φ q, v = Φ q': the
//!   run falls back inside the step; so it does, with the error model in
//!   error directions, where the residual force outside them passes its
//!   limit ([`UNSEEN_PER_TOLERANCE`]): the model cannot see the error that
//!   force drives. Loads outside the training program
//!   (gravity scaled or turned beyond it, a point load it did not run)
//!   fall back before the step: the basis was not trained for them.
//! - Full: the error carried from the reduced stretch moves on as the
//!   distance between the run and a twin of it started that error away
//!   ([`twin`]; full space adds none). Every communication step keeps the
//!   displacement it reached; after a stretch of [`STRETCH`] steps (doubled
//!   after each return that fails) the directions the stretch saw that the
//!   basis does not hold join it ([`adaptive_basis`]; with cubature forces
//!   the basis stays as chosen, its cubature being trained for it); if the grown basis
//!   holds the stretch's poses and the state's velocity to the projection
//!   share of the tolerance (and the loads are back in the program), the run returns to a modal space of the grown basis
//!   at q = Φᵀ M (x − x*), q' = Φᵀ M v, and the error model takes the part
//!   of the state the basis leaves out as the error of the return.
//!
//! The host's mode weights do not act: the run approximates the physics,
//! and its basis changes as it grows (as in full space, they act with
//! the modal reduction only).

mod estimate;
mod returns;
mod runs;
mod sheet;
mod twin;
mod unseen;

use runs::{inner_settings, reduced_run, slot_masses, slot_motion};

use super::{FallBackCause, Reads, Run, SetUp, Steps, Switch};
use faer::linalg::matmul::matmul;
use faer::{Accum, MatMut, MatRef, Par};

use crate::physics::error::{Expected, PhysicsError, Quantity};
use crate::physics::run::error_model::ErrorState;
use crate::physics::run::frame::dot;
use crate::physics::run::integrator::Scheme;
use crate::physics::run::simulator::estimators::Estimator;
use crate::physics::run::space::{Constants, Full, Modal, Readout, ReducedForce};
use crate::physics::run::state::{Loads, State};
use crate::physics::settings::{Reduction, Settings};
use crate::physics::setup::adaptive_basis::{full_throughout, Chosen, FullThroughout, CAP_FACTOR};
use crate::physics::setup::modes::ModalBasis;
use crate::physics::setup::scene::Scene;

/// The run falls back when the estimated error of the state passes this
/// share of the tolerance times the distance the sheet has moved (at least
/// its training program's motion).
pub const FALL_BACK: f64 = 0.4;
/// The run falls back where the part of the residual force the error
/// directions do not see passes [`UNSEEN_FLOOR`] of the load (in the M⁻¹
/// norm), or this many tolerances of it where that is more: the error model
/// cannot estimate the error that part drives. Measured (`docs/method.md`,
/// section 10): on cloth 100 x 100 the reduced run's error grows 20× in
/// 0.3 s after the share reaches 0.21–0.27 (at tolerances 0.01 and 0.03;
/// at most 0.11 while it holds E ≤ 0.005); on cloth 30 x 30 at 0.05 runs
/// hold E ≤ 0.017 with shares of 0.2–0.8 (a coarse tolerance is a small
/// basis, which leaves more of the force out).
pub const UNSEEN_PER_TOLERANCE: f64 = 6.0;
/// See [`UNSEEN_PER_TOLERANCE`].
pub const UNSEEN_FLOOR: f64 = 0.15;
/// Where the unseen share at a check passes this part of its limit, the
/// next estimate and check come sooner than the longest gap: after the
/// longest gap times (1 − ρ) / (1 − `UNSEEN_WATCH`), ρ the share over its
/// limit (at least one step; [`Adaptive::check_gap`]).
pub const UNSEEN_WATCH: f64 = 0.5;
/// Communication steps of the first stretch in full space before the run tries to return.
pub const STRETCH: usize = 4;
/// The longest stretch, in communication steps, and the most poses a stretch keeps.
pub const LONGEST_STRETCH: usize = 256;
/// One estimate costs about this many passes over every spring.
pub const ESTIMATE_COST: f64 = 10.0;
/// The estimates cost at most this share of the springs the steps visit.
pub const ESTIMATE_SHARE: f64 = 0.25;
/// The longest gap between two estimates, in communication steps.
pub const LONGEST_GAP: u64 = 32;
/// The longest gap between two estimates in simulated time [s] (32 steps
/// of 0.01 s): with steps of 1/60 s the unseen force's check came 0.53 s
/// apart, and on cloth 100 x 100 the run fell back at 1.05 s instead of
/// 0.82 s, with E 0.0098 at 1.5 s against 0.0016 (`docs/method.md`, section 10).
pub const LONGEST_GAP_SECONDS: f64 = 0.32;
/// The most poses of a stretch in full space kept for the basis to grow by.
pub const KEPT_POSES: usize = 32;

/// What the estimate of E counts: sums over the communication points.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Tally {
    /// Σ ‖ê_k‖²_M and Σ ‖x_k − x_0‖²_M.
    pub error_sq: f64,
    pub motion_sq: f64,
    /// Internal steps taken reduced, and in all.
    pub reduced_steps: u64,
    pub steps: u64,
}

impl Tally {
    /// The estimated E of the run so far.
    pub fn estimate(&self) -> f64 {
        if self.motion_sq > 0.0 {
            (self.error_sq / self.motion_sq).sqrt()
        } else {
            0.0
        }
    }

    /// The share of internal steps taken reduced (1 before the first).
    pub fn reduced_fraction(&self) -> f64 {
        if self.steps > 0 {
            self.reduced_steps as f64 / self.steps as f64
        } else {
            1.0
        }
    }
}

/// A reduced run with modal space `Modal<F>` and scheme `R`, its full-space twin with scheme `X`.
pub struct Adaptive<F: ReducedForce, R: Scheme, X: Scheme> {
    reduced: Run<Modal<F>, R>,
    full: Run<Full, X>,
    in_full: bool,
    /// Internal steps the last communication step took.
    last_steps: usize,
    /// Why the reduced model cannot pay, if it cannot ([`full_throughout`]): then full space throughout.
    why_full: Option<FullThroughout>,
    chosen: Chosen,
    /// The vectors grown so far, oldest first.
    grown: Vec<Vec<f64>>,
    model: Estimator,
    error: ErrorState,
    spare_error: ErrorState,
    tally: Tally,
    spare_tally: Tally,
    residual: Vec<f64>,
    /// The estimate's schedule: communication steps between estimates now
    /// (1 after every change, doubling up to `period`), steps and time since the last one.
    gap: u64,
    period: u64,
    wait: u64,
    since: f64,
    /// ‖e‖²_M and Σ m |x − x0|² at the last estimate, which stand for the steps until the next.
    last_error_sq: f64,
    last_motion_sq: f64,
    /// The last estimate's unseen residual, squared, over the load squared
    /// (0: not measured; see [`UNSEEN_PER_TOLERANCE`]), and that of the last
    /// check that measured it (0: none since set-up or the last fall-back),
    /// which sets how soon the next check comes ([`Self::check_gap`]).
    unseen_sq: f64,
    unseen_last: f64,
    /// Slot positions at the start and each slot's mass, for the motion;
    /// Φᵀ M (x* − x0) and ‖x* − x0‖²_M over the free DOFs, for the motion of
    /// a reduced state, ‖Φ q + x* − x0‖²_M = |q|² + 2 qᵀ Φᵀ M (x* − x0) + ‖x* − x0‖²_M.
    start: Vec<f64>,
    slot_mass: Vec<f64>,
    motion_reference: Vec<f64>,
    motion_offset: f64,
    /// The stretch in full space: its poses (displacements from x*), its length and the length it should reach.
    seen: Vec<Vec<f64>>,
    seen_count: usize,
    seen_next: usize,
    stretch: usize,
    /// The state the full-space run takes on a fall-back, and the reduced run's state to undo a step to.
    lifted: State,
    rewind: State,
    /// The full-space run that moves a carried error on (where the run
    /// reduces) and its state ([`twin`]); in error directions, the error
    /// over the free DOFs while in full space, or the one in directions.
    twin: Option<Box<Run<Full, X>>>,
    /// The twin goes on beside the run in full space from its own state,
    /// and e is its distance to the run, not kept in `error` ([`twin`]).
    twin_live: bool,
    carried: ErrorState,
    /// In full space, a look found no error carried: none comes back there
    /// (the twin from x + 0 is the run), so the next looks are skipped
    /// until a fall-back or a restored state.
    no_error: bool,
    /// Φᵀ M Δc of a holder's kick (see [`Self::kick_error`]).
    kick_q: Vec<f64>,
    stretch_target: usize,
    settings: Settings,
    /// Gravity and the point load at set-up, about which the training program varies them.
    setup_gravity: [f64; 3],
    setup_point_load: [f64; 3],
    /// The host's loads, with its mode weights.
    loads: Loads,
    spare: Loads,
    /// The first `settings.n_modes` vectors of the basis (zero columns beyond it), and their coordinates.
    reported: ModalBasis,
    /// The same vectors one after another (k x n row-major), for Φᵀ M u as k dot products.
    reported_rows: Vec<f64>,
    frequencies: Vec<f64>,
    coordinates: Vec<f64>,
    /// `coordinates` are those of the state (computed when first read after a change).
    coordinates_fresh: bool,
    /// Fall-backs and returns so far, and the last (for the host's log; not part of the state).
    switches: u64,
    last_switch: Switch,
}

/// Mode weights act on a fixed basis: an adaptive run refuses any but 1.
pub(super) fn unweighted(loads: &Loads) -> Result<(), PhysicsError> {
    match loads.mode_weights.iter().find(|w| **w != 1.0) {
        Some(&value) => Err(PhysicsError::Invalid { quantity: Quantity::ModeWeights, value, expected: Expected::OneInAdaptive }),
        None => Ok(()),
    }
}

/// `dst` takes every load of `src` but the mode weights.
fn copy_loads(dst: &mut Loads, src: &Loads) {
    dst.gravity = src.gravity;
    dst.point_load = src.point_load;
    dst.load_node = src.load_node;
    dst.anchor = src.anchor;
    dst.rotation = src.rotation;
    dst.holders = src.holders;
    dst.damping_alpha = src.damping_alpha;
    dst.damping_beta = src.damping_beta;
}

impl<F: ReducedForce, R: Scheme, X: Scheme> Adaptive<F, R, X> {
    /// Set-up: the basis chosen for the tolerance ([`adaptive_basis::choose`],
    /// or rebuilt from stored set-up data by [`adaptive_basis::choose_from`]),
    /// the reduced run on it, the full-space run and the error model.
    pub fn new(scene: Scene, settings: &Settings, loads: &Loads, chosen: Chosen) -> Result<Self, PhysicsError> {
        unweighted(loads)?;
        let full_settings = inner_settings(settings, Reduction::Full, 0);
        let full_loads = Loads { mode_weights: Vec::new(), ..loads.clone() };
        let full = Run::new(Full::new(scene.clone(), &full_loads, &full_settings)?, &full_settings, &full_loads)?;
        let reduced = reduced_run(&scene, &chosen.settings, loads, &chosen.data)?;
        let why_full = full_throughout(&scene, &chosen);
        let (model, error) = match why_full {
            Some(_) => (Estimator::None, ErrorState::zero(scene.n_dofs())),
            None => Estimator::new(&scene, &chosen, &chosen.data.basis)?,
        };
        let n = scene.n_dofs();
        let slot_mass = slot_masses(&scene);
        let mut run = Adaptive {
            reduced,
            full,
            in_full: false,
            last_steps: 0,
            why_full,
            grown: Vec::new(),
            model,
            spare_error: error.clone(),
            error,
            tally: Tally::default(),
            spare_tally: Tally::default(),
            residual: vec![0.0; n],
            gap: 1,
            period: 1,
            wait: 0,
            since: 0.0,
            last_error_sq: 0.0,
            last_motion_sq: 0.0,
            unseen_sq: 0.0,
            unseen_last: 0.0,
            start: Vec::new(),
            slot_mass,
            motion_reference: Vec::new(),
            motion_offset: 0.0,
            seen: vec![vec![0.0; n]; KEPT_POSES],
            seen_count: 0,
            seen_next: 0,
            stretch: 0,
            lifted: State::at_rest(n),
            rewind: State::at_rest(0),
            twin: None,
            twin_live: false,
            carried: ErrorState::zero(n),
            no_error: false,
            kick_q: Vec::new(),
            stretch_target: STRETCH,
            settings: settings.clone(),
            setup_gravity: loads.gravity,
            setup_point_load: if loads.load_node.is_some() { loads.point_load } else { [0.0; 3] },
            loads: loads.clone(),
            spare: loads.clone(),
            reported: ModalBasis { n, r: settings.n_modes, lambda: vec![0.0; settings.n_modes], phi: vec![0.0; n * settings.n_modes] },
            reported_rows: vec![0.0; n * settings.n_modes],
            frequencies: vec![0.0; settings.n_modes],
            coordinates: vec![0.0; settings.n_modes],
            coordinates_fresh: false,
            chosen,
            switches: 0,
            last_switch: Switch::None,
        };
        run.start = run.reduced.space.positions(&run.reduced.state.y, &mut run.reduced.work).to_vec();
        run.reduced.current = false;
        run.set_motion_reference();
        run.rewind = run.reduced.state.clone();
        run.kick_q = vec![0.0; run.reduced.space.basis().r];
        if run.reduces() {
            run.twin = Some(twin::make_twin(&run.full, settings, loads)?);
        } else {
            run.lift();
        }
        run.report_basis();
        Ok(run)
    }

    fn active(&self) -> &dyn super::Sheet {
        if self.in_full {
            &self.full
        } else {
            &self.reduced
        }
    }

    fn active_mut(&mut self) -> &mut dyn super::Sheet {
        if self.in_full {
            &mut self.full
        } else {
            &mut self.reduced
        }
    }

    /// The first `settings.n_modes` vectors of the current basis, zero beyond it.
    fn report_basis(&mut self) {
        let b = self.reduced.space.basis();
        let (n, k) = (b.n, self.reported.r);
        self.reported.lambda.fill(0.0);
        self.reported.phi.fill(0.0);
        self.reported_rows.fill(0.0);
        for j in 0..k.min(b.r) {
            self.reported.lambda[j] = b.lambda[j];
            for i in 0..n {
                self.reported.phi[i * k + j] = b.phi[i * b.r + j];
                self.reported_rows[j * n + i] = b.phi[i * b.r + j];
            }
        }
        for (f, l) in self.frequencies.iter_mut().zip(&self.reported.lambda) {
            *f = l.max(0.0).sqrt();
        }
    }

    /// The coordinates of the state in the reported vectors: the reduced
    /// run's own, or Φᵀ M (x − x*) of the full-space state (M (x − x*) into
    /// the residual's scratch, then faer's matrix-vector product over the
    /// vectors as rows: k dot products of length n, where the columns of
    /// Φᵀ, k long, made it 13 % of a run in full space on cloth 30 x 30 at k = 2);
    /// when the host reads them, not after every step.
    fn report_coordinates(&mut self) {
        let k = self.coordinates.len();
        if !self.in_full {
            let q = self.reduced.modal_coordinates();
            let m = k.min(q.len());
            self.coordinates[..m].copy_from_slice(&q[..m]);
            self.coordinates[m..].fill(0.0);
            return;
        }
        let mass = &self.full.space.scene().dof_mass;
        let point = &self.chosen.data.point;
        let u = &self.full.state.y;
        let rest = &self.full.space.scene().rest;
        let n = u.len();
        let mu = &mut self.residual[..n];
        for (i, m) in mu.iter_mut().enumerate() {
            *m = mass[i] * (u[i] + rest[i] - point[i]);
        }
        let phi_t = MatRef::from_row_major_slice(&self.reported_rows, k, n);
        let out = MatMut::from_column_major_slice_mut(&mut self.coordinates, k, 1);
        matmul(out, Accum::Replace, phi_t, MatRef::from_column_major_slice(mu, n, 1), 1.0, Par::Seq);
        crate::physics::vector_unit::clean();
    }

    /// Φᵀ M (x* − x0) and ‖x* − x0‖²_M of the reduced run's basis (after set-up and each new basis).
    fn set_motion_reference(&mut self) {
        let (b, point) = (self.reduced.space.basis(), &self.reduced.space.modes().point);
        let mass = &self.reduced.space.scene().dof_mass;
        let gap: Vec<f64> = (0..b.n).map(|i| point[i] - self.start[i]).collect();
        let mut q = vec![0.0; b.r];
        b.project_displacement(mass, &gap, &mut q);
        self.motion_reference = q;
        self.motion_offset = gap.iter().zip(mass).map(|(g, m)| m * g * g).sum();
    }

    /// Σ m |x − x0|² over every node at the active run's positions.
    fn motion_sq(&mut self) -> f64 {
        let d = self.reduced.space.scene().dim;
        let x = if self.in_full {
            self.full.space.positions(&self.full.state.y, &mut self.full.work)
        } else {
            self.reduced.current = false;
            self.reduced.space.positions(&self.reduced.state.y, &mut self.reduced.work)
        };
        slot_motion(x, &self.start, &self.slot_mass, d)
    }

    /// The longest gap between estimates: one estimate (a spring pass, the
    /// tangent's assembly, a factorization and a solve: about
    /// [`ESTIMATE_COST`] passes over every spring) costs at most
    /// [`ESTIMATE_SHARE`] of the springs the steps between visit, and
    /// at most [`LONGEST_GAP`] steps of `h` and [`LONGEST_GAP_SECONDS`] apart.
    fn update_period(&mut self, h: f64) {
        let all = self.reduced.scene().springs.len() as f64;
        let visited = if self.in_full {
            all * self.full.internal_steps_last.max(1) as f64
        } else {
            (self.reduced.cubature_springs() * self.reduced.internal_steps_last.max(1)) as f64
        };
        self.period = ((ESTIMATE_COST * all / (ESTIMATE_SHARE * visited)).ceil() as u64).clamp(1, LONGEST_GAP);
        // And at most LONGEST_GAP_SECONDS apart, whatever the step.
        let in_time = ((LONGEST_GAP_SECONDS / h * (1.0 + 1e-9)).floor() as u64).max(1);
        self.period = self.period.min(in_time);
    }

    /// The reduced model can pay ([`full_throughout`]).
    fn reduces(&self) -> bool {
        self.why_full.is_none()
    }

    /// The communication steps to the next check of the unseen residual
    /// while its last share ρ (of its limit) passes [`UNSEEN_WATCH`]:
    /// max(1, ⌊period (1 − ρ) / (1 − UNSEEN_WATCH)⌋); else none sooner
    /// than the estimates' own schedule (`u64::MAX`). A share growing
    /// towards the limit is checked the more often the nearer it is.
    fn check_gap(&self) -> u64 {
        let rho = (self.unseen_last / self.unseen_limit_sq()).sqrt();
        if !(rho > UNSEEN_WATCH) {
            return u64::MAX;
        }
        ((self.period as f64 * (1.0 - rho).max(0.0) / (1.0 - UNSEEN_WATCH)).floor() as u64).max(1)
    }

    /// Estimates from the next step on again 1, 2, 4, ... steps apart (after a change).
    fn estimate_soon(&mut self) {
        self.gap = 1;
    }

    /// The loads are outside the training program the basis was trained
    /// on: gravity scaled beyond 1 ± the program's scale s of the set-up
    /// gravity or turned from it by more than its tilt, or a point load the
    /// program did not run (one where set-up had none; one turned from the
    /// set-up's or larger than 1 + s times it), with a
    /// hundredth of slack for round-off.
    fn outside_program(&self) -> bool {
        self.outside(&self.loads)
    }

    /// Whether `loads` are outside the training program ([`Self::outside_program`]).
    fn outside(&self, loads: &Loads) -> bool {
        let t = &self.settings.training;
        let slack = 0.01;
        let angle = |a: &[f64; 3], b: &[f64; 3]| -> f64 {
            let n = (dot(a, a) * dot(b, b)).sqrt();
            if n > 0.0 {
                (dot(a, b) / n).clamp(-1.0, 1.0).acos()
            } else {
                0.0
            }
        };
        let (g0, g) = (&self.setup_gravity, &loads.gravity);
        let n0 = dot(g0, g0).sqrt();
        if n0 > 0.0 {
            let scale = dot(g, g).sqrt() / n0;
            if scale < (1.0 - t.scale) * (1.0 - slack) || scale > (1.0 + t.scale) * (1.0 + slack) || angle(g0, g) > t.tilt * (1.0 + slack) + 1e-9 {
                return true;
            }
        }
        let d = self.reduced.space.scene().dim;
        let planar = |p: &[f64; 3]| -> [f64; 3] { std::array::from_fn(|i| if i < d { p[i] } else { 0.0 }) };
        let (p0, p) = (planar(&self.setup_point_load), planar(&loads.point_load));
        let (m0, m) = (dot(&p0, &p0).sqrt(), dot(&p, &p).sqrt());
        m > 0.0 && (m0 == 0.0 || m > (1.0 + t.scale) * (1.0 + slack) * m0 || angle(&p0, &p) > 1e-6)
    }

    /// The error E the run may reach now: the one the host's loads give,
    /// else the one it was set up for, which chose its basis.
    fn tolerance(&self) -> f64 {
        self.loads.error_tolerance.unwrap_or(self.settings.error_tolerance)
    }

    /// The square of the unseen residual's limit ([`UNSEEN_PER_TOLERANCE`], [`UNSEEN_FLOOR`]).
    fn unseen_limit_sq(&self) -> f64 {
        UNSEEN_FLOOR.max(UNSEEN_PER_TOLERANCE * self.tolerance()).powi(2)
    }

    /// Why the last estimate makes the run fall back, if it does: the
    /// residual the error model does not see has passed its limit, or the
    /// estimated error of the state its share of the tolerance (a NaN falls back).
    fn fall_back_cause(&self) -> Option<FallBackCause> {
        let limit_sq = self.unseen_limit_sq();
        if !(self.unseen_sq <= limit_sq) {
            return Some(FallBackCause::Unseen { share: self.unseen_sq.sqrt(), limit: limit_sq.sqrt() });
        }
        let motion = self.last_motion_sq.max(self.chosen.choice.motion_scale.powi(2));
        let limit = FALL_BACK * self.tolerance();
        (!(self.last_error_sq <= limit.powi(2) * motion)).then(|| FallBackCause::Error { estimate: (self.last_error_sq / motion).sqrt(), limit })
    }

    /// Counts a fall-back or a return.
    fn switched(&mut self, switch: Switch) {
        self.switches += 1;
        self.last_switch = switch;
    }

    /// The reduced run's state undone to the start of its last step.
    fn undo_reduced(&mut self) {
        self.rewind.copy_from(&self.reduced.backup);
        self.reduced.resume(&self.rewind, false);
    }

    /// The full-space run takes the reduced run's state: x = x* + Φ q, v = Φ q'.
    fn lift(&mut self) {
        // Full space's coordinates are the displacements from rest, u = x - x_rest.
        let s = &mut self.lifted;
        let x = self.reduced.space.positions(&self.reduced.state.y, &mut self.reduced.work);
        let rest = &self.reduced.space.scene().rest;
        for (k, y) in s.y.iter_mut().enumerate() {
            *y = x[k] - rest[k];
        }
        self.reduced.space.dof_velocities(&self.reduced.state.v, &mut s.v);
        s.a.fill(0.0);
        s.copy_frame_from(&self.reduced.state);
        self.full.resume(&self.lifted, true);
        self.in_full = true;
        self.unseen_last = 0.0;
        self.seen_count = 0;
        self.seen_next = 0;
        self.stretch = 0;
        self.estimate_soon();
        self.error_into_full();
        self.no_error = false;
    }

    fn step_full(&mut self, h: f64) -> Result<(), PhysicsError> {
        // Whether an error is carried, looked at once a step (a pass over 3 n
        // values) until none is; a run that never reduces never carries one.
        let carrying = self.reduces() && !self.no_error && self.carries_error();
        self.no_error = !carrying;
        self.step_full_carrying(h, carrying)?;
        self.tally.steps += self.full.internal_steps_last as u64;
        self.wait += 1;
        self.since += h;
        if self.wait >= self.gap || carrying {
            // Full space adds no error; the error carried moves on with the
            // twin, which knows it at every step (an estimate costs O(n) here).
            self.update_period(h);
            self.estimate()?;
        }
        self.stretch += 1;
        if !self.reduces() {
            // A run that never returns keeps no poses and no stretch.
            self.stretch = 0;
            return Ok(());
        }
        // The pose into the oldest of the kept ones.
        let slot = &mut self.seen[self.seen_next];
        let rest = &self.full.space.scene().rest;
        for (i, (p, u)) in slot.iter_mut().zip(&self.full.state.y).enumerate() {
            *p = u + rest[i] - self.chosen.data.point[i];
        }
        self.seen_next = (self.seen_next + 1) % KEPT_POSES;
        self.seen_count = (self.seen_count + 1).min(KEPT_POSES);
        if self.stretch >= self.stretch_target {
            self.try_return()?;
        }
        Ok(())
    }

    /// The full-space state's displacement from the linearization point x*.
    fn pose(&self) -> Vec<f64> {
        let rest = &self.full.space.scene().rest;
        self.full.state.y.iter().enumerate().map(|(i, u)| u + rest[i] - self.chosen.data.point[i]).collect()
    }

    /// The poses of the stretch kept so far.
    fn seen(&self) -> &[Vec<f64>] {
        &self.seen[..self.seen_count]
    }
}
