//! The [`Space`] trait: what every space provides to the schemes and the
//! outputs, each method with the equation it computes; and [`Diagonal`],
//! the linear part of the equations where it is diagonal.

use crate::physics::error::PhysicsError;
use crate::physics::error::StepFailure;
use crate::physics::run::frame::{Frame, Moments};
use crate::physics::run::state::Loads;
use crate::physics::setup::modes::ModalBasis;
use crate::physics::setup::scene::Scene;
use crate::physics::setup::setup_data::{SetupData, TrainedRange};

/// The linear part of the equations when it is diagonal, as in the modal
/// space: h_i(y) = g_i(y) - lambda_i y_i and C = diag(c_i), so that every
/// coordinate is a damped linear oscillator y_i'' + c_i y_i' + lambda_i y_i = g_i(y)
/// driven by the rest, g_i = load_i + (a part that depends on y)
/// (`docs/method.md`, sections 3 and 4).
#[derive(Clone, Copy, Debug)]
pub struct Diagonal<'a> {
    /// lambda_i [1/s^2].
    pub stiffness: &'a [f64],
    /// c_i under the current loads [1/s].
    pub damping: &'a [f64],
    /// The part of g_i that does not depend on y, under the current loads.
    pub load: &'a [f64],
}

/// Sizes and constants of a space, fixed at set-up.
#[derive(Clone, Copy, Debug)]
pub struct Layout<'a> {
    /// The scene the space was built on.
    pub scene: &'a Scene,
    /// Number of generalized coordinates.
    pub coordinates: usize,
    /// Modes kept (`None` in full space, where every DOF is integrated).
    pub kept_modes: Option<usize>,
    /// Springs one force evaluation visits.
    pub springs: usize,
    /// Angular frequencies of the kept or reported modes at the linearization point, ascending [rad/s].
    pub frequencies: &'a [f64],
    /// Scale of y below which Newton updates count as converged.
    pub newton_scale: f64,
    /// The range a trained basis was trained for (modal space with a trained basis).
    pub trained: Option<&'a TrainedRange>,
}

/// What a space is, fixed at set-up: its scene, sizes and constants, the
/// modes it keeps or reports, where its coordinates start.
pub trait Constants {
    /// The scene the space was built on.
    fn scene(&self) -> &Scene;
    /// Sizes and constants of the space.
    fn layout(&self) -> Layout<'_>;
    /// The costly products of the set-up, as data (modal space only).
    fn setup_data(&self) -> Option<SetupData> {
        None
    }
    /// The kept (modal) or reported (full) modes, if any (in full space made
    /// when first asked for: [`Self::modes_made`]).
    fn modes(&self) -> Option<&ModalBasis> {
        None
    }
    /// Makes the modes where they are made when first asked for (the full
    /// space's reported modes), and says why they cannot be, if they cannot.
    fn modes_made(&self) -> Result<(), &PhysicsError> {
        Ok(())
    }
    /// The coordinates of the scene at rest, where every run starts (0
    /// unless the coordinates are measured from another point than rest).
    fn rest_coordinates(&self, y: &mut [f64]);
}

/// The equations of one space, as the schemes step them; see the module
/// documentation. What it is is [`Constants`]; what is read from its
/// coordinates is [`Readout`].
pub trait Space: Constants + Send + Sized + 'static {
    /// The loads of one run, the terms derived from them and the scratch:
    /// the one place a run's loads live (read through `as_ref`, changed
    /// through `as_mut` and then [`Space::apply_loads`]).
    type Work: Send + 'static + AsRef<Loads> + AsMut<Loads>;

    /// The work of a run under `loads`: the loads, their terms (all zero
    /// until [`Space::apply_loads`]) and scratch.
    fn work(&self, loads: &Loads) -> Self::Work;

    /// Derives the load terms (damping per coordinate, generalized gravity
    /// and point load) from the loads of `w`, once per load change.
    fn apply_loads(&self, w: &mut Self::Work);
    /// h(y) into `h`; leaves the slot positions and the elastic energy at y in `w`.
    fn force(&self, y: &[f64], w: &mut Self::Work, h: &mut [f64]);
    /// The velocity update of explicit Newmark: v1 from
    /// (M + dt/2 C) v1 = M (v + dt/2 a) + dt/2 h.
    fn explicit_velocity(&self, dt: f64, v: &[f64], a: &[f64], h: &[f64], w: &mut Self::Work, v1: &mut [f64]) -> Result<(), StepFailure>;
    /// a from M a = h - C v.
    fn acceleration(&self, v: &[f64], h: &[f64], w: &mut Self::Work, a: &mut [f64]);
    /// The Newmark predictor y1 = y + dt v + dt^2/2 a, then h(y1) into `h`
    /// (as [`Self::force`]); a space may fuse the two passes, to the same bits.
    #[allow(clippy::too_many_arguments)]
    fn predicted_force(&self, y: &[f64], v: &[f64], a: &[f64], dt: f64, y1: &mut [f64], w: &mut Self::Work, h: &mut [f64]) {
        let half_dt2 = 0.5 * dt * dt;
        for i in 0..y1.len() {
            y1[i] = y[i] + dt * v[i] + half_dt2 * a[i];
        }
        self.force(y1, w, h);
    }
    /// The end of an explicit Newmark step: v1 from
    /// [`Self::explicit_velocity`], then the new `a` from
    /// [`Self::acceleration`] at v1 (`a` holds the old one on entry); a
    /// space may fuse the two passes, to the same bits.
    fn explicit_rates(&self, dt: f64, v: &[f64], a: &mut [f64], h: &[f64], w: &mut Self::Work, v1: &mut [f64]) -> Result<(), StepFailure> {
        self.explicit_velocity(dt, v, a, h, w, v1)?;
        self.acceleration(v1, h, w, a);
        Ok(())
    }
    /// The Newmark residual r = -(M a + C v - h).
    fn residual(&self, v: &[f64], a: &[f64], h: &[f64], w: &mut Self::Work, r: &mut [f64]);
    /// Factors the Newton matrix c_m M + c_c C - dh/dy at the positions of
    /// the last [`Space::force`].
    fn factor(&self, c_m: f64, c_c: f64, w: &mut Self::Work) -> Result<(), StepFailure>;
    /// Solves with the last [`Space::factor`], in place.
    fn solve(&self, w: &mut Self::Work, rhs: &mut [f64]);
    /// Upper bound on the squared frequencies of the integrated system
    /// under the loads of `w`, in any state where no spring is compressed [1/s^2].
    fn omega_sq_bound(&self, w: &Self::Work) -> f64;
    /// The diagonal linear part of the equations under the loads of the
    /// last [`Space::apply_loads`], where there is one (the modal space: the
    /// modes' own springs lambda_i, their Rayleigh damping
    /// alpha + beta lambda_i and the weighted generalized load); `None` where
    /// the linear part couples the coordinates (full space). The weights act
    /// on g alone: g_i = h_i + lambda_i y_i is w_i r_i (`docs/method.md`, section 3).
    fn diagonal<'a>(&'a self, w: &'a Self::Work) -> Option<Diagonal<'a>>;
    /// Adds to the rates `v` those of a rigid translation of every free
    /// node with velocity `c` (z is 0 in 2D), each coordinate scaled by its
    /// weight like a load: the velocity kick of an anchor whose velocity
    /// changes by -c (`docs/method.md`, section 8).
    fn add_translation_rate(&self, w: &Self::Work, c: &[f64; 3], v: &mut [f64]);
    /// Adds to the rates `v` at coordinates `y` those of a rigid rotation of
    /// the free nodes about the pivot with angular velocity `c`, c x (x - X0),
    /// weighted like a load: the velocity kick of a holder whose spin
    /// changes by -c (`docs/method.md`, section 8).
    fn add_rotation_rate(&self, w: &Self::Work, c: &[f64; 3], y: &[f64], v: &mut [f64]);
    /// The holder has turned (`docs/method.md`, section 8): until the next
    /// [`Space::apply_loads`] the equations are those of its frame: gravity
    /// and the point load as `frame` turns them, the centrifugal force of
    /// its spin with the forces, its Coriolis force with the damping
    /// (in every method above that takes C). Called after
    /// [`Space::apply_loads`], and for every internal step while the holder turns.
    fn turn(&self, frame: &Frame, w: &mut Self::Work);
    /// The slot positions the force evaluations read (every slot, `dim`
    /// values each): the run writes the held slots of the holders that
    /// move on their own there ([`crate::physics::run::holders::place`]);
    /// the free slots are the space's to write.
    fn slots_mut<'w>(&self, w: &'w mut Self::Work) -> &'w mut [f64];
}

/// What is read from a space's coordinates: positions, velocities,
/// energies, momentum and the force it cannot represent (relative to the
/// anchor).
pub trait Readout: Space {
    /// The spring force alone in the space's coordinates (Phi^T f(x) in
    /// the modal space, as its force model evaluates it; f(x) in full space),
    /// for diagnostics: it overwrites what the last [`Space::force`] left in `w`.
    fn spring_force(&self, y: &[f64], w: &mut Self::Work, out: &mut [f64]);

    /// Slot positions at y, the coordinates of the last [`Space::force`].
    fn positions<'w>(&self, y: &[f64], w: &'w mut Self::Work) -> &'w [f64];
    /// Position of one slot at y, the coordinates of the last
    /// [`Space::force`] (`dim` values, z 0 in 2D): the same bits as
    /// [`Space::positions`] holds for it, at the cost of one slot.
    fn slot_position(&self, y: &[f64], slot: usize, w: &mut Self::Work) -> [f64; 3] {
        let d = self.scene().dim;
        let x = self.positions(y, w);
        std::array::from_fn(|i| if i < d { x[slot * d + i] } else { 0.0 })
    }
    /// Velocity of one free slot at rates v (z 0 in 2D): the same bits as
    /// [`Space::dof_velocities`] gives for it.
    fn slot_velocity(&self, v: &[f64], slot: usize) -> [f64; 3];
    /// Elastic energy of the springs at y, the coordinates of the last [`Space::force`] [J].
    fn elastic_energy(&self, y: &[f64], w: &mut Self::Work) -> f64;
    /// Potential of gravity and the point load relative to rest at y [J].
    fn gravity_potential(&self, y: &[f64], w: &Self::Work) -> f64;
    /// The potential energy whose gradient the space integrates, at y, the
    /// coordinates of the last [`Space::force`] [J]: elastic energy plus
    /// gravity potential, with the elastic part as the force model sums it
    /// (every spring; the cubature's weighted springs, which costs no more
    /// than one of its steps). The step guard weighs energy growth with it.
    fn model_energy(&self, y: &[f64], w: &mut Self::Work) -> f64 {
        self.elastic_energy(y, w) + self.gravity_potential(y, w)
    }
    /// 1/2 v^T M v in physical space [J].
    fn kinetic_energy(&self, v: &[f64]) -> f64;
    /// Momentum of the free nodes per axis, sum_k m_k v_k, at rates `v` [kg m/s].
    fn momentum(&self, v: &[f64]) -> [f64; 3];
    /// S = sum m_k (x_k - X0) over the free nodes at y, the first mass
    /// moment about the pivot in the holder's frame (O(r) in the modal space) [kg m].
    fn first_moment(&self, y: &[f64]) -> [f64; 3];
    /// The mass moments of the free nodes about the pivot at coordinates y
    /// and rates v (see [`Moments`]; O(r^2) in the modal space).
    fn moments(&self, y: &[f64], v: &[f64]) -> Moments;
    /// Velocities of the free DOFs.
    fn dof_velocities(&self, v: &[f64], out: &mut [f64]);
    /// Coordinates of the kept or reported modes at y.
    fn modal_coordinates(&self, y: &[f64], out: &mut [f64]);
    /// The part of the physical force at y the space cannot represent,
    /// relative to the load (`docs/method.md`, section 6), with gravity and
    /// the point load as `gravity` and `point` give them (in the holder's
    /// frame once it has turned); 0 in full space.
    fn force_residual(&self, gravity: &[f64; 3], point: &[f64; 3], y: &[f64], w: &mut Self::Work) -> f64;
}
