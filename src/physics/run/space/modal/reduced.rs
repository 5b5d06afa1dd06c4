//! What a reduced force model is: the [`ReducedForce`] trait, what its
//! set-up is given ([`ForceSetup`]) and the kept modes it works with
//! ([`Modes`]); and the bound on the reduced system's frequencies.

use faer::linalg::matmul::matmul;
use faer::{Accum, MatMut, MatRef, Par, Side};

use crate::physics::error::PhysicsError;
use crate::physics::run::state::Loads;
use crate::physics::run::stiffness::reduced_taut_stiffness;
use crate::physics::settings::Settings;
use crate::physics::setup::modes::ModalBasis;
use crate::physics::setup::scene::Scene;
use crate::physics::setup::setup_data::SpringSet;
use crate::physics::vector_unit;

/// How the modal space evaluates the projected spring force Phi^T f(x* + Phi q)
/// and its tangent Phi^T K(x) Phi: every spring ([`super::Exact`]), or a model that
/// leaves out what the kept modes do not need. A model is constant after
/// set-up; its `Work` holds what one evaluation writes.
pub trait ReducedForce: Send + Sized + 'static {
    type Work: Send + 'static;
    /// Set-up on `scene` for the kept `modes`.
    fn new(scene: &Scene, modes: &Modes, setup: &ForceSetup) -> Result<Self, PhysicsError>;
    fn work(&self, scene: &Scene, modes: &Modes) -> Self::Work;
    /// Phi^T f_springs(x* + Phi q) into `out` (r values).
    fn project(&self, scene: &Scene, modes: &Modes, q: &[f64], w: &mut Self::Work, out: &mut [f64]);
    /// Adds Phi^T K(x) Phi (r x r, column-major) at the last [`Self::project`] to `kr`.
    fn add_tangent(&self, scene: &Scene, modes: &Modes, w: &mut Self::Work, kr: &mut [f64]);
    /// The slot positions the evaluations read, whose held slots the run
    /// places (see [`crate::physics::run::space::Space::slots_mut`]).
    fn slots_mut<'w>(&self, w: &'w mut Self::Work) -> &'w mut [f64];
    /// Slot positions at `q`, the coordinates of the last [`Self::project`].
    fn positions<'w>(&self, scene: &Scene, modes: &Modes, q: &[f64], w: &'w mut Self::Work) -> &'w [f64];
    /// Elastic energy of every spring at `q`, the coordinates of the last [`Self::project`] [J].
    fn elastic_energy(&self, scene: &Scene, modes: &Modes, q: &[f64], w: &mut Self::Work) -> f64;
    /// The elastic energy whose negative gradient [`Self::project`] returns,
    /// at `q`, the coordinates of the last [`Self::project`] [J]; the energy
    /// of every spring unless the model sums fewer.
    fn model_energy(&self, scene: &Scene, modes: &Modes, q: &[f64], w: &mut Self::Work) -> f64 {
        self.elastic_energy(scene, modes, q, w)
    }
    /// The exact spring forces of every spring on the free DOFs at `q`, the
    /// coordinates of the last [`Self::project`] (for the error indicator).
    fn spring_forces<'w>(&self, scene: &Scene, modes: &Modes, q: &[f64], w: &'w mut Self::Work) -> &'w [f64];
    /// Springs one evaluation visits.
    fn springs(&self, scene: &Scene) -> usize {
        scene.springs.len()
    }
    /// The springs and weights the model uses, if it chose them at set-up.
    fn spring_set(&self) -> Option<SpringSet> {
        None
    }
    /// A bound on the squared frequencies of the model's own stiffness when
    /// it differs from Phi^T K_taut Phi (taken as the larger of the two).
    fn taut_bound(&self, _scene: &Scene, _modes: &Modes) -> Option<f64> {
        None
    }
}

/// What a force model's set-up may use besides the scene and the modes.
pub struct ForceSetup<'a> {
    /// The loads at set-up.
    pub loads: &'a Loads,
    /// The set-up's settings (the cubature's tolerance, whether the anchor will move).
    pub settings: &'a Settings,
    /// Squared-frequency bound of the reduced system with every spring (1/s^2).
    pub omega_sq_bound: f64,
    /// A stored set of springs and weights to use instead of computing one.
    pub prebuilt: Option<&'a SpringSet>,
}

/// The kept modes, in the two layouts the loops want, and the point x*
/// they are measured from.
pub struct Modes {
    pub basis: ModalBasis,
    /// Phi column-major (each mode contiguous), for the expand and project loops.
    pub cols: Vec<f64>,
    /// Slot positions x* (the rest positions, or the equilibrium).
    pub point: Vec<f64>,
    /// x* is the rest positions.
    pub at_rest: bool,
}

impl Modes {
    pub fn new(basis: ModalBasis, point: Vec<f64>, at_rest: bool) -> Self {
        let (n, r) = (basis.n, basis.r);
        let cols = (0..r).flat_map(|j| (0..n).map(move |k| (k, j))).map(|(k, j)| basis.phi[k * r + j]).collect();
        Modes { basis, cols, point, at_rest }
    }

    /// Phi as an n x r matrix (column-major).
    fn phi(&self) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.cols, self.basis.n, self.basis.r)
    }

    /// x = x* + Phi q over the free DOFs (the first n values of the slot
    /// positions `x`, whose other slots stay as they are), one mode at a
    /// time (a free slot alone is summed in the same order, so its bits are these).
    pub fn expand(&self, q: &[f64], x: &mut [f64]) {
        let n = self.basis.n;
        x[..n].copy_from_slice(&self.point[..n]);
        for (col, qj) in self.cols.chunks_exact(n).zip(q) {
            for (xk, p) in x[..n].iter_mut().zip(col) {
                *xk += p * qj;
            }
        }
    }

    /// Phi^T f for a force `f` on the free DOFs, by faer's matrix-vector
    /// product (its SIMD kernel: 3x the plain dot products on cloth 30 x 30).
    pub fn project(&self, f: &[f64], out: &mut [f64]) {
        let r = self.basis.r;
        let dst = MatMut::from_column_major_slice_mut(&mut out[..r], r, 1);
        matmul(dst, Accum::Replace, self.phi().transpose(), MatRef::from_column_major_slice(&f[..self.basis.n], self.basis.n, 1), 1.0, Par::Seq);
        vector_unit::clean();
    }

    /// Phi v for modal rates `v`, one mode at a time (as [`Self::expand`]).
    pub fn expand_rates(&self, v: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        for (col, vj) in self.cols.chunks_exact(self.basis.n).zip(v) {
            for (o, p) in out.iter_mut().zip(col) {
                *o += p * vj;
            }
        }
    }
}

/// lambda_max(Phi^T K_taut Phi): bound on the squared frequencies of the
/// reduced system in any state without compressed springs.
pub fn taut_reduced_bound(scene: &Scene, basis: &ModalBasis) -> Result<f64, PhysicsError> {
    let r = basis.r;
    let mut kr = vec![0.0; r * r];
    reduced_taut_stiffness(scene, &basis.phi, r, &mut kr);
    let m = faer::Mat::<f64>::from_fn(r, r, |i, j| kr[j * r + i]);
    let ev = m
        .self_adjoint_eigenvalues(Side::Lower)
        .map_err(|e| PhysicsError::LinearAlgebra { what: "eigenvalues of the reduced stiffness", detail: format!("{e:?}") })?;
    Ok(ev.last().copied().unwrap_or(0.0).max(0.0))
}
