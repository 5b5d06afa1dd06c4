//! What a modal run writes: the loads (the one place they live), the
//! terms derived from them, and the scratch of force evaluations, Newton
//! and the turning holder's terms, allocated once at set-up.

use faer::dyn_stack::MemBuffer;
use faer::Mat;

use crate::physics::run::state::Loads;

/// Load terms and scratch of a modal run.
pub struct ModalWork<W> {
    /// c_i = alpha + beta lambda_i.
    pub(super) damping: Vec<f64>,
    /// The loads of the run: the one place its mode weights w_i, gravity,
    /// point load and damping live.
    pub(super) loads: Loads,
    /// Phi^T (M g + f_p): gravity and the point load.
    pub(super) gravity: Vec<f64>,
    /// w_i (Phi^T (M g + f_p))_i: the part of w_i r_i that does not depend on q.
    pub(super) weighted_load: Vec<f64>,
    /// -(M g + f_p)^T (x* - x_rest): the potential of the loads at q = 0.
    pub(super) gravity_offset: f64,
    /// What the force model writes.
    pub(super) force: W,
    /// Reduced tangent Phi^T K(x) Phi (column-major).
    pub(super) kr: Vec<f64>,
    /// F = Phi^T (f + M g) of the last force evaluation, before the weights (for the error indicator).
    pub(super) generalized: Vec<f64>,
    /// Phi^T f of [`super::Modal::residual_force`].
    pub(super) generalized_scratch: Vec<f64>,
    /// ||M g + f_p||^2 in the M^-1 norm, the load's scale of the error indicator.
    pub(super) load_scale: f64,
    /// Newton matrix, LU-factored in place, with its row permutation.
    pub(super) jac: Mat<f64>,
    pub(super) perm: Vec<usize>,
    pub(super) perm_inv: Vec<usize>,
    pub(super) mem: MemBuffer,
    /// The holder's frame has left its rest orientation ([`Space::turn`]).
    pub(super) turning: bool,
    pub(super) spin: [f64; 3],
    /// The centrifugal force c0 + Kc q and the Coriolis matrix Gamma of the spin (see [`Inertia::spin_terms`]).
    pub(super) centrifugal: Vec<f64>,
    pub(super) spin_stiffness: Vec<f64>,
    pub(super) coriolis: Vec<f64>,
    /// I (1 + dt/2 c) + dt/2 W Gamma, LU-factored, for the explicit velocity update while turning, and its dt (NaN: stale).
    pub(super) velocity: Mat<f64>,
    pub(super) velocity_perm: Vec<usize>,
    pub(super) velocity_perm_inv: Vec<usize>,
    pub(super) velocity_dt: f64,
}

impl<W> AsRef<Loads> for ModalWork<W> {
    fn as_ref(&self) -> &Loads {
        &self.loads
    }
}

impl<W> AsMut<Loads> for ModalWork<W> {
    fn as_mut(&mut self) -> &mut Loads {
        &mut self.loads
    }
}
