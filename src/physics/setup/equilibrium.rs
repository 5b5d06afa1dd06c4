//! The static equilibrium of a scene under its loads (`docs/method.md`,
//! sections 3 and 8): the positions x of the free DOFs where the springs
//! carry the load, f(x) + M g + f_p = 0 (gravity and the point load; M g
//! stands for both below).
//!
//! Newton's method on the full space, K(x) Δx = f(x) + s M g, with the load
//! applied in increments s (0 → 1, halved when a Newton solve fails, doubled
//! when one succeeds) and a backtracking line search on the total potential
//! energy (an equilibrium is a stationary point of it, a stable one a
//! minimum). Where K(x) is singular or indefinite (a flat 3D sheet without
//! auxiliary springs has no stiffness out of its plane at rest; compressed
//! springs have negative transverse stiffness), or where the Newton step
//! does not lower the energy, the matrix is shifted by μ M, μ growing
//! (Levenberg-Marquardt), which turns the step towards steepest descent.
//!
//! An equilibrium is kept only if it is stable: K(x) must have no negative
//! eigenvalue. A flat sheet hanging under gravity in its own plane has
//! compressed springs across it, whose negative transverse stiffness makes
//! the flat equilibrium unstable out of the plane (it buckles); Newton from
//! the flat rest state, which feels no force out of the plane, would stay
//! on it. So when K(x) is indefinite, the equilibrium is pushed along the
//! eigenvector of the most negative eigenvalue (by a hundredth of the
//! scene's smallest spring length, towards +z where it points out of the
//! plane) and Newton starts again, until the equilibrium it finds is stable.

use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::Side;

use crate::physics::error::PhysicsError;
use crate::physics::run::forces::SpringForces;
use crate::physics::run::stiffness::StiffnessPattern;
use crate::physics::setup::scene::Scene;

/// Newton iterations in all, over every load increment: a buckling cloth
/// of 30 x 30 nodes takes about 400, the paper's scenes 5 to 30.
const MAX_ITERATIONS: usize = 600;
/// Smallest load increment tried before giving up.
const MIN_INCREMENT: f64 = 1.0 / 4096.0;
/// Converged when the largest residual force is below this fraction of the
/// largest load on a DOF.
const TOLERANCE: f64 = 1e-10;
/// Unstable equilibria left along their most negative mode before giving up.
const MAX_BUCKLINGS: usize = 8;
/// Eigenvalues of M⁻¹ K above this fraction of its largest diagonal entry
/// (in magnitude) count as zero, not negative.
const ZERO_EIGENVALUE: f64 = 1e-10;

/// Slot positions at the equilibrium of `scene` under the external `load`
/// on its free DOFs (M g plus the point load, [`crate::physics::setup::basis::external_load`];
/// the rest positions when the load is zero).
pub fn equilibrium(scene: &Scene, pattern: &StiffnessPattern, load: &[f64]) -> Result<Vec<f64>, PhysicsError> {
    let load = load.to_vec();
    let scale = load.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    if scale == 0.0 {
        return Ok(scene.rest.clone());
    }
    let mut solver = Newton { scene, pattern, springs: SpringForces::new(scene), load, tolerance: TOLERANCE * scale, iterations: 0 };
    let mut x = scene.rest.clone();
    let (mut s, mut ds): (f64, f64) = (0.0, 1.0);
    while s < 1.0 {
        let target = (s + ds).min(1.0);
        let mut trial = x.clone();
        match solver.solve(&mut trial, target) {
            Ok(()) => {
                x = trial;
                s = target;
                ds = (2.0 * ds).min(1.0);
            }
            Err(residual) => {
                ds /= 2.0;
                if ds < MIN_INCREMENT {
                    return Err(PhysicsError::NoEquilibrium { load_fraction: s, residual: residual / scale });
                }
            }
        }
    }
    let push = 1e-2 * scene.springs.iter().fold(f64::INFINITY, |m, sp| m.min(sp.rest));
    for _ in 0..MAX_BUCKLINGS {
        let Some(mode) = unstable_mode(scene, pattern, &x) else {
            return Ok(x);
        };
        let mut trial = x.clone();
        for (xi, vi) in trial.iter_mut().zip(&mode) {
            *xi += push * vi;
        }
        solver.solve(&mut trial, 1.0).map_err(|residual| PhysicsError::NoEquilibrium { load_fraction: 1.0, residual: residual / scale })?;
        x = trial;
    }
    Err(PhysicsError::UnstableEquilibrium)
}

/// The eigenvector of the most negative eigenvalue of M⁻¹ K(x), scaled to a
/// largest entry of 1 and turned towards +z (or +y in 2D), if K(x) has a
/// negative eigenvalue; by inverse iteration with K + μ M, μ just large
/// enough for the factor to exist.
fn unstable_mode(scene: &Scene, pattern: &StiffnessPattern, x: &[f64]) -> Option<Vec<f64>> {
    let n = scene.n_dofs();
    let mass = &scene.dof_mass;
    let mut k = vec![0.0; pattern.nnz()];
    pattern.add_tangent(scene, x, 1.0, &mut k);
    let diag_max = pattern.diag.iter().enumerate().fold(0.0f64, |m, (i, &p)| m.max(k[p] / mass[i])).max(f64::MIN_POSITIVE);
    let sym = SymbolicSparseColMatRef::new_checked(n, n, &pattern.col_ptr, None, &pattern.row_idx);
    let shifted = |mu: f64| {
        let mut v = k.clone();
        for (i, &p) in pattern.diag.iter().enumerate() {
            v[p] += mu * mass[i];
        }
        SparseColMatRef::new(sym, &v).sp_cholesky(Side::Upper).ok()
    };
    // Positive semi-definite up to round-off: stable.
    let tol = ZERO_EIGENVALUE * diag_max;
    if shifted(tol).is_some() {
        return None;
    }
    let mut mu = tol;
    let llt = loop {
        mu *= 4.0;
        if let Some(f) = shifted(mu) {
            break f;
        }
        if mu > 1e3 * diag_max {
            return None;
        }
    };
    // Inverse iteration: (K + mu M)^-1 M amplifies the smallest eigenvalue most.
    let mut v: Vec<f64> = (0..n).map(|i| 1.0 + 0.01 * ((i * 7919) % 101) as f64).collect();
    for _ in 0..200 {
        let mut w = faer::Col::<f64>::from_fn(n, |i| mass[i] * v[i]);
        faer::linalg::solvers::Solve::solve_in_place(&llt, w.as_mat_mut());
        let norm = w.iter().fold(0.0f64, |m, a| m.max(a.abs()));
        if !(norm > 0.0 && norm.is_finite()) {
            return None;
        }
        v = w.iter().map(|a| a / norm).collect();
    }
    let d = scene.dim;
    let axis = d - 1;
    let lean: f64 = v.iter().skip(axis).step_by(d).sum();
    if lean < 0.0 {
        v.iter_mut().for_each(|a| *a = -*a);
    }
    Some(v)
}

struct Newton<'a> {
    scene: &'a Scene,
    pattern: &'a StiffnessPattern,
    springs: SpringForces,
    load: Vec<f64>,
    tolerance: f64,
    /// Newton iterations so far, over every load increment.
    iterations: usize,
}

impl Newton<'_> {
    /// The residual f(x) + s M g into `r`, its largest entry, and the total
    /// potential energy (springs, and gravity relative to rest) at x.
    fn evaluate(&self, x: &[f64], s: f64, r: &mut [f64]) -> (f64, f64) {
        for (rk, lk) in r.iter_mut().zip(&self.load) {
            *rk = s * lk;
        }
        let mut scratch = self.springs.scratch(self.scene);
        let elastic = self.springs.add_to(self.scene, x, &mut scratch, r);
        let work: f64 = self.load.iter().zip(x).zip(&self.scene.rest).map(|((l, xi), x0)| s * l * (xi - x0)).sum();
        (r.iter().fold(0.0f64, |m, v| m.max(v.abs())), elastic - work)
    }

    /// Newton on the slot positions `x` (free DOFs first) at load fraction
    /// `s`, each step (K + μ M) Δ = f + s M g with μ = 0 where that factors
    /// and lowers the potential energy along Δ, μ raised (Levenberg-Marquardt)
    /// where not; the largest residual force when it does not converge.
    fn solve(&mut self, x: &mut [f64], s: f64) -> Result<(), f64> {
        let (scene, pattern) = (self.scene, self.pattern);
        let n = scene.n_dofs();
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &pattern.col_ptr, None, &pattern.row_idx);
        let mut r = vec![0.0; n];
        let (mut norm, mut energy) = self.evaluate(x, s, &mut r);
        let mut k = vec![0.0; pattern.nnz()];
        let mut trial_r = vec![0.0; n];
        let mut trial = x.to_vec();
        while self.iterations < MAX_ITERATIONS {
            if !norm.is_finite() {
                return Err(norm);
            }
            if norm <= self.tolerance {
                return Ok(());
            }
            self.iterations += 1;
            k.fill(0.0);
            pattern.add_tangent(scene, x, 1.0, &mut k);
            let diag_max = pattern.diag.iter().enumerate().fold(0.0f64, |m, (i, &p)| m.max(k[p] / scene.dof_mass[i])).max(f64::MIN_POSITIVE);
            let mut mu = 0.0;
            let accepted = 'damping: loop {
                let mut shifted = k.clone();
                for (i, &p) in pattern.diag.iter().enumerate() {
                    shifted[p] += mu * scene.dof_mass[i];
                }
                if let Ok(llt) = SparseColMatRef::new(sym, &shifted).sp_cholesky(Side::Upper) {
                    let mut delta = faer::Col::<f64>::from_fn(n, |i| r[i]);
                    faer::linalg::solvers::Solve::solve_in_place(&llt, delta.as_mat_mut());
                    // Descent along delta: dE = -r . delta < 0 for a positive definite factor.
                    let slope = -(0..n).map(|i| r[i] * delta[i]).sum::<f64>();
                    if slope < 0.0 && delta.iter().all(|v| v.is_finite()) {
                        let mut alpha = 1.0;
                        while alpha >= 1.0 / 16.0 {
                            trial.copy_from_slice(x);
                            for i in 0..n {
                                trial[i] += alpha * delta[i];
                            }
                            let (trial_norm, trial_energy) = self.evaluate(&trial, s, &mut trial_r);
                            // Armijo; near convergence, where the energy changes below its
                            // round-off, a smaller residual.
                            let flat = (trial_energy - energy).abs() <= 1e-12 * energy.abs().max(f64::MIN_POSITIVE);
                            if trial_energy <= energy + 1e-4 * alpha * slope || (flat && trial_norm < norm) || trial_norm <= self.tolerance {
                                norm = trial_norm;
                                energy = trial_energy;
                                break 'damping true;
                            }
                            alpha /= 2.0;
                        }
                    }
                }
                mu = if mu == 0.0 { 1e-8 * diag_max } else { mu * 10.0 };
                if mu > 1e8 * diag_max {
                    break false;
                }
            };
            if !accepted {
                return Err(norm);
            }
            x.copy_from_slice(&trial);
            r.copy_from_slice(&trial_r);
        }
        if norm <= self.tolerance {
            Ok(())
        } else {
            Err(norm)
        }
    }
}
