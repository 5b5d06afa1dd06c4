//! The error model of a reduced run (`docs/method.md`, section 10): an
//! estimate of how far the reduced trajectory x(t) = x* + Φ q(t) is from
//! the full-space one, computed as the run goes, without a reference.
//!
//! The full equations M x'' = f(x) (springs, gravity, point load) hold the
//! full trajectory; along the reduced one they leave the residual
//!
//! ```text
//! r = f(x) − M x'' = f(x) − M Φ Φᵀ f(x),
//! ```
//!
//! the force the basis cannot hold (M x'' = M Φ q'' and q'' = Φᵀ f since
//! Φᵀ M Φ = I). Linearized about the reduced trajectory, the error
//! e = x_full − x obeys
//!
//! ```text
//! M e'' + K e = r(t),   e(0) = 0, e'(0) = 0,
//! ```
//!
//! K the tangent stiffness at the state, tension only (a compressed
//! spring's negative geometric stiffness would make the linear model grow
//! without bound; the tension's holds a hanging sheet's error in check).
//! The model integrates this in full space with the trapezoidal rule
//! (Newmark, β = 1/4, γ = 1/2) at the communication step h, r held at its
//! value at the step's end and K taken at the step's end: a stiff part of
//! r (what the basis leaves out at high frequency) gives its static
//! response K⁻¹ r, a soft part (a load the basis cannot follow at all)
//! drives e as it would drive the sheet. One step costs the residual (one
//! pass over every spring, 2 n r for Φᵀ f and M Φ F), the tangent's
//! assembly, a numeric sparse Cholesky factorization of M + h²/4 K (the
//! symbolic analysis is done at set-up) and one solve.
//!
//! What it leaves out: the error of the coordinates the basis holds driven
//! by the coupling through the nonlinear forces (second order in e), the
//! inertial loads of a holder that accelerates or turns, the growth of an
//! error through springs that buckle (the sheet's sensitivity), and the
//! full space's own time-step error. Measured against the full-space run
//! on cloth 30 x 30 it follows E to within 10 % while the run stays in its
//! program (docs/method.md, section 10); K at rest instead overestimated
//! up to 3.4x in the program and 31x out of the plane, the plain tangent
//! (compression included) 60x.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, LltRef, SymbolicCholesky, SymmetricOrdering};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

use crate::physics::error::PhysicsError;
use crate::physics::run::stiffness::StiffnessPattern;
use crate::physics::vector_unit;

/// e, e', e'' of the error model: the part of an adaptive run's state that
/// estimates its error.
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorState {
    pub e: Vec<f64>,
    pub v: Vec<f64>,
    pub a: Vec<f64>,
}

impl ErrorState {
    pub fn zero(n: usize) -> Self {
        ErrorState { e: vec![0.0; n], v: vec![0.0; n], a: vec![0.0; n] }
    }

    /// Takes `other`'s values without allocating (the derived `clone_from` would).
    pub fn copy_from(&mut self, other: &ErrorState) {
        self.e.copy_from_slice(&other.e);
        self.v.copy_from_slice(&other.v);
        self.a.copy_from_slice(&other.a);
    }

    pub fn is_finite(&self) -> bool {
        self.e.iter().chain(&self.v).chain(&self.a).all(|x| x.is_finite())
    }

    /// The trapezoidal rule's predictor over `h`: e += h e' + h²/4 e''.
    pub fn predict(&mut self, h: f64) {
        let c = BETA * h * h;
        for ((e, v), a) in self.e.iter_mut().zip(&self.v).zip(&self.a) {
            *e += h * v + c * a;
        }
    }

    /// Its corrector with the new e'' = `a`: e += h²/4 a, e' += h/2 (e'' + a), e'' = a.
    pub fn correct(&mut self, h: f64, a: &[f64]) {
        let c = BETA * h * h;
        for (((e, v), old), new) in self.e.iter_mut().zip(&mut self.v).zip(&mut self.a).zip(a) {
            *e += c * new;
            *v += 0.5 * h * (*old + new);
            *old = *new;
        }
    }
}

/// The constant part of the error model and its scratch.
pub struct ErrorModel {
    mass: Vec<f64>,
    pattern: StiffnessPattern,
    stiffness: Vec<f64>,
    /// The stiffness given at set-up, and the slot positions of the last
    /// [`Self::relinearize`] (empty: the set-up's stiffness holds).
    initial: Vec<f64>,
    at: Vec<f64>,
    symbolic: SymbolicCholesky<usize>,
    matrix: Vec<f64>,
    l_values: Vec<f64>,
    mem: MemBuffer,
    /// The step size `l_values` is the factor of M + h²/4 K for (NaN: none yet).
    factored: f64,
    rhs: Vec<f64>,
}

/// Newmark's β of the trapezoidal rule.
pub const BETA: f64 = 0.25;

impl ErrorModel {
    /// The model of a scene with masses `mass` (free DOFs) and stiffness
    /// `stiffness` on `pattern`: the symbolic analysis, and every buffer.
    /// `slot_values`: the length of the slot positions it is linearized at.
    pub fn new(mass: &[f64], pattern: StiffnessPattern, stiffness: Vec<f64>, slot_values: usize) -> Result<Self, PhysicsError> {
        let n = mass.len();
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &pattern.col_ptr, None, &pattern.row_idx);
        let symbolic = factorize_symbolic_cholesky(sym, Side::Upper, SymmetricOrdering::Amd, Default::default())
            .map_err(|e| PhysicsError::LinearAlgebra { what: "sparse Cholesky analysis of the error model", detail: format!("{e:?}") })?;
        let req = StackReq::any_of(&[
            symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]);
        Ok(ErrorModel {
            mass: mass.to_vec(),
            matrix: vec![0.0; pattern.nnz()],
            l_values: vec![0.0; symbolic.len_val()],
            mem: MemBuffer::new(req),
            factored: f64::NAN,
            rhs: vec![0.0; n],
            symbolic,
            pattern,
            initial: stiffness.clone(),
            at: Vec::with_capacity(slot_values),
            stiffness,
        })
    }

    /// Factors M + h²/4 K for step `h`, unless it is factored for it.
    fn factor(&mut self, h: f64) -> Result<(), PhysicsError> {
        if self.factored == h {
            return Ok(());
        }
        let c = BETA * h * h;
        for (m, k) in self.matrix.iter_mut().zip(&self.stiffness) {
            *m = c * k;
        }
        for (k, &pos) in self.pattern.diag.iter().enumerate() {
            self.matrix[pos] += self.mass[k];
        }
        let n = self.mass.len();
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &self.pattern.col_ptr, None, &self.pattern.row_idx);
        let a = SparseColMatRef::new(sym, &self.matrix);
        let stack = MemStack::new(&mut self.mem);
        self.factored = f64::NAN;
        self.symbolic
            .factorize_numeric_llt(&mut self.l_values, a, Side::Upper, LltRegularization::default(), Par::Seq, stack, Default::default())
            .map_err(|e| PhysicsError::LinearAlgebra { what: "Cholesky factorization of the error model", detail: format!("{e:?}") })?;
        vector_unit::clean();
        self.factored = h;
        Ok(())
    }

    /// Advances `s` by `h` under the residual `r` (held over the step):
    /// a = (M + h²/4 K)⁻¹ (r − K (e + h e' + h²/4 e'')), e += h e' + h²/4 (e'' + a),
    /// e' += h/2 (e'' + a), e'' = a.
    pub fn advance(&mut self, s: &mut ErrorState, h: f64, r: &[f64]) -> Result<(), PhysicsError> {
        self.factor(h)?;
        // The predictor into s.e; K times it into rhs.
        s.predict(h);
        self.pattern.sym_matvec(&self.stiffness, &s.e, &mut self.rhs);
        for (x, rk) in self.rhs.iter_mut().zip(r) {
            *x = rk - *x;
        }
        let n = self.rhs.len();
        let stack = MemStack::new(&mut self.mem);
        LltRef::<usize, f64>::new(&self.symbolic, &self.l_values).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut self.rhs, n, 1),
            Par::Seq,
            stack,
        );
        vector_unit::clean();
        s.correct(h, &self.rhs);
        Ok(())
    }

    /// Linearizes the model at slot positions `x` of `scene`: K = K(x), the
    /// tangent there with the tension's geometric stiffness (which holds a
    /// hanging sheet's error in check) and without the negative one of
    /// compressed springs (which would make the linear model grow without
    /// bound); refactored at the next step.
    pub fn relinearize(&mut self, scene: &crate::physics::setup::scene::Scene, x: &[f64]) {
        self.at.clear();
        self.at.extend_from_slice(x);
        self.stiffness.fill(0.0);
        self.pattern.add_tangent_with(scene, x, 1.0, true, &mut self.stiffness);
        self.factored = f64::NAN;
    }

    /// Where the model was last linearized (slot positions; empty: at set-up).
    pub fn linearized_at(&self) -> &[f64] {
        &self.at
    }

    /// Linearized at `at` again (empty: the set-up's stiffness), as a run that was there.
    pub fn linearize_as(&mut self, scene: &crate::physics::setup::scene::Scene, at: &[f64]) {
        if at.is_empty() {
            self.stiffness.copy_from_slice(&self.initial);
            self.at.clear();
            self.factored = f64::NAN;
        } else {
            self.relinearize(scene, at);
        }
    }

    /// ‖e‖²_M.
    pub fn norm_sq(&self, s: &ErrorState) -> f64 {
        self.mass.iter().zip(&s.e).map(|(m, e)| m * e * e).sum()
    }
}
