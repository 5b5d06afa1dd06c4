//! What changes while a scene runs, apart from what stays fixed after set-up.
//!
//! - [`State`]: the generalized coordinates of the space the equations live
//!   in (modal coordinates q, or full-space displacements u from the
//!   linearization point), their rates and the time;
//! - [`Loads`]: what the environment sets between steps (gravity, damping,
//!   mode weights);
//! - [`Snapshot`]: a state with its loads, all a run needs to resume. The
//!   simulator's backup before a step and the FMU state are snapshots.

use super::error::{non_negative, PhysicsError, Quantity};

/// Coordinates y, rates y' and accelerations y'' of the generalized
/// coordinates, and the time since the start of the run.
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    /// Time since the start of the run [s].
    pub time: f64,
    /// y: modal coordinates, or displacements of the free DOFs.
    pub y: Vec<f64>,
    /// y'.
    pub v: Vec<f64>,
    /// y''.
    pub a: Vec<f64>,
}

impl State {
    /// At rest at the linearization point, at time 0, with `n` coordinates.
    pub fn at_rest(n: usize) -> Self {
        State { time: 0.0, y: vec![0.0; n], v: vec![0.0; n], a: vec![0.0; n] }
    }

    /// Number of generalized coordinates.
    pub fn len(&self) -> usize {
        self.y.len()
    }

    pub fn is_empty(&self) -> bool {
        self.y.is_empty()
    }

    /// Copies `other` into `self` without allocating (same lengths).
    pub fn copy_from(&mut self, other: &State) {
        self.time = other.time;
        self.y.copy_from_slice(&other.y);
        self.v.copy_from_slice(&other.v);
        self.a.copy_from_slice(&other.a);
    }

    /// Every value is a finite number.
    pub fn is_finite(&self) -> bool {
        self.time.is_finite() && self.y.iter().chain(&self.v).chain(&self.a).all(|x| x.is_finite())
    }
}

/// Loads and gains that may change between communication steps.
#[derive(Clone, Debug, PartialEq)]
pub struct Loads {
    /// Gravitational acceleration [m/s^2]; z is ignored in 2D.
    pub gravity: [f64; 3],
    /// Rayleigh mass-proportional damping alpha [1/s].
    pub damping_alpha: f64,
    /// Rayleigh stiffness-proportional damping beta [s].
    pub damping_beta: f64,
    /// Gain w_i per mode (`docs/method.md`, section 3); one per mode kept
    /// or reported, used by the modal space only.
    pub mode_weights: Vec<f64>,
}

impl Loads {
    /// Earth gravity along -y, no damping, every weight 1 (the physical model).
    pub fn physical(n_modes: usize) -> Self {
        Loads { gravity: [0.0, -9.81, 0.0], damping_alpha: 0.0, damping_beta: 0.0, mode_weights: vec![1.0; n_modes] }
    }

    /// Largest weight, and at least 1: weights above 1 scale the stiffness
    /// the explicit integrator sees and the energy the loads can supply.
    pub fn weight_max(&self) -> f64 {
        self.mode_weights.iter().fold(1.0f64, |m, w| m.max(*w))
    }

    /// Refuses loads the solver cannot use, for `n_modes` modes.
    pub fn validate(&self, n_modes: usize) -> Result<(), PhysicsError> {
        if let Some(&g) = self.gravity.iter().find(|g| !g.is_finite()) {
            return Err(PhysicsError::Invalid { quantity: Quantity::Gravity, value: g, expected: super::error::Expected::Finite });
        }
        non_negative(Quantity::DampingAlpha, self.damping_alpha)?;
        non_negative(Quantity::DampingBeta, self.damping_beta)?;
        if self.mode_weights.len() != n_modes {
            return Err(PhysicsError::Length { quantity: Quantity::ModeWeights, len: self.mode_weights.len(), expected: n_modes });
        }
        self.mode_weights.iter().try_for_each(|&w| non_negative(Quantity::ModeWeights, w))
    }
}

/// A state with the loads acting on it.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    pub state: State,
    pub loads: Loads,
}
