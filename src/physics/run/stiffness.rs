//! Tangent stiffness (`docs/method.md`, section 2): a spring's D x D block,
//! the reduced tangent Phi^T K Phi, the sparsity and assembly of the
//! free-DOF stiffness matrix, and the step-size bound taken from it.
//!
//! Like the force kernels of [`crate::physics::run::forces`], every loop
//! walks the spring list once and is monomorphised on the dimension `D`.

use faer::linalg::matmul::matmul;
use faer::{Accum, MatMut, MatRef, Par};
use nalgebra::{SMatrix, SVector};

use crate::physics::setup::scene::{Scene, Spring};
use crate::physics::vector_unit;

/// Tangent stiffness block of one spring with vector d, K_e = k [ u u^T + (1 - l0/l)(I - u u^T) ],
/// u = d / l (`docs/method.md`, section 2).
#[inline]
pub fn block<const D: usize>(d: &[f64; D], k: f64, l0: f64) -> SMatrix<f64, D, D> {
    let d = SVector::<f64, D>::from(*d);
    let l = d.norm();
    let geo = 1.0 - l0 / l;
    // k [ (1 - geo) u u^T + geo I ] with u u^T = d d^T / l^2, entry by entry
    SMatrix::from_fn(|i, j| k * ((1.0 - geo) * (d[i] * d[j] / (l * l)) + if i == j { geo } else { 0.0 }))
}

/// [`block`] of spring `s` at slot positions `x`. `taut` replaces it by its
/// bound k I (every direction as stiff as the axis), used for step-size limits.
#[inline]
pub fn spring_block<const D: usize>(s: &Spring, x: &[f64], taut: bool) -> SMatrix<f64, D, D> {
    if taut {
        return SMatrix::from_diagonal_element(s.k);
    }
    block(&std::array::from_fn(|i| x[s.b * D + i] - x[s.a * D + i]), s.k, s.rest)
}

/// Adds the reduced tangent Phi^T K(x) Phi (r x r, column-major) to `kr`:
/// per spring, G^T K_e G with G = Phi_a - Phi_b (rows of the two ends).
/// `phi` is row-major `n_dofs x r`; `work` holds at least `6 r` values.
pub fn add_reduced_tangent(scene: &Scene, x: &[f64], phi: &[f64], r: usize, taut: bool, kr: &mut [f64], work: &mut [f64]) {
    match scene.dim {
        2 => reduced_tangent::<2>(scene, x, phi, r, taut, kr, work),
        _ => reduced_tangent::<3>(scene, x, phi, r, taut, kr, work),
    }
}

fn reduced_tangent<const D: usize>(scene: &Scene, x: &[f64], phi: &[f64], r: usize, taut: bool, kr: &mut [f64], work: &mut [f64]) {
    let n_free = scene.n_free;
    // G and K_e G, each D x r.
    let (g, rest) = work.split_at_mut(D * r);
    let kg = &mut rest[..D * r];
    for s in &scene.springs {
        let ke = spring_block::<D>(s, x, taut);
        for i in 0..D {
            for j in 0..r {
                let pa = if s.a < n_free { phi[(s.a * D + i) * r + j] } else { 0.0 };
                let pb = if s.b < n_free { phi[(s.b * D + i) * r + j] } else { 0.0 };
                g[i * r + j] = pa - pb;
            }
        }
        add_projected_block::<D>(&ke, g, r, kg, kr);
    }
}

/// The reduced taut stiffness Phi^T K_taut Phi (r x r, column-major) into
/// `kr`, K_taut the stiffness with every spring as k I (state-independent):
/// K_taut Phi a spring at a time (3 D r operations each: k (Phi_a - Phi_b)
/// to row a, its negative to row b), then Phi^T (K_taut Phi) by faer's
/// product. The same matrix as [`add_reduced_tangent`] with `taut`, in
/// D r instead of D r^2 operations per spring (on cloth 30 x 30 with 62
/// vectors about 40x faster); its round-off differs.
pub fn reduced_taut_stiffness(scene: &Scene, phi: &[f64], r: usize, kr: &mut [f64]) {
    let (d, n_free) = (scene.dim, scene.n_free);
    let n = n_free * d;
    let mut k_phi = vec![0.0; n * r];
    let mut g = vec![0.0; r];
    for s in &scene.springs {
        for i in 0..d {
            for (j, gj) in g.iter_mut().enumerate() {
                let pa = if s.a < n_free { phi[(s.a * d + i) * r + j] } else { 0.0 };
                let pb = if s.b < n_free { phi[(s.b * d + i) * r + j] } else { 0.0 };
                *gj = s.k * (pa - pb);
            }
            if s.a < n_free {
                k_phi[(s.a * d + i) * r..(s.a * d + i + 1) * r].iter_mut().zip(&g).for_each(|(o, g)| *o += g);
            }
            if s.b < n_free {
                k_phi[(s.b * d + i) * r..(s.b * d + i + 1) * r].iter_mut().zip(&g).for_each(|(o, g)| *o -= g);
            }
        }
    }
    let phi = MatRef::from_row_major_slice(&phi[..n * r], n, r);
    let k_phi = MatRef::from_row_major_slice(&k_phi, n, r);
    matmul(MatMut::from_column_major_slice_mut(&mut kr[..r * r], r, r), Accum::Replace, phi.transpose(), k_phi, 1.0, Par::Seq);
    vector_unit::clean();
}

/// kr += G^T K_e G for one spring's block K_e (D x D) and G = Phi_a - Phi_b
/// (D x r, row-major), with `kg` (D x r) as scratch for K_e G: the one
/// loop of every reduced tangent (all springs here, the cubature's
/// weighted ones in `space/modal/cubature.rs`).
#[inline]
pub fn add_projected_block<const D: usize>(ke: &SMatrix<f64, D, D>, g: &[f64], r: usize, kg: &mut [f64], kr: &mut [f64]) {
    for i in 0..D {
        for j in 0..r {
            kg[i * r + j] = (0..D).map(|m| ke[(i, m)] * g[m * r + j]).sum();
        }
    }
    for col in 0..r {
        for row in 0..r {
            kr[col * r + row] += (0..D).map(|i| g[i * r + row] * kg[i * r + col]).sum::<f64>();
        }
    }
}

/// Sparsity of the free-DOF stiffness matrix, upper triangle, CSC, with the
/// position of every spring's local entry in the value array precomputed so
/// numeric assembly is a scatter with no search and no allocation.
#[derive(Clone, Debug)]
pub struct StiffnessPattern {
    pub col_ptr: Vec<usize>,
    pub row_idx: Vec<usize>,
    /// Position of each diagonal entry.
    pub diag: Vec<usize>,
    /// Per spring, the positions of its entries of the upper triangle, in
    /// the order of [`upper_entries`]: the D(D+1)/2 of K_e at (a, a), the
    /// same at (b, b), the D^2 of -K_e between a and b; `usize::MAX` where
    /// an end is held.
    local: Vec<usize>,
}

/// The entries of one spring's local matrix [[Ke, -Ke], [-Ke, Ke]] in the
/// upper triangle, in the order `local` holds their positions: (block, i,
/// j) with block 0 = (a, a) and 1 = (b, b) for i <= j, 2 = between a and b
/// for every i, j. Each global entry a spring touches is one of them, once.
fn upper_entries<const D: usize>() -> impl Iterator<Item = (usize, usize, usize)> {
    let diagonal = move |block| (0..D).flat_map(move |i| (i..D).map(move |j| (block, i, j)));
    diagonal(0).chain(diagonal(1)).chain((0..D).flat_map(|i| (0..D).map(move |j| (2, i, j))))
}

const SKIP: usize = usize::MAX;

impl StiffnessPattern {
    pub fn new(scene: &Scene) -> Self {
        let n = scene.n_dofs();
        let d = scene.dim;
        let globals = |s: &Spring| -> Vec<Option<usize>> {
            (0..2 * d)
                .map(|p| {
                    let slot = if p < d { s.a } else { s.b };
                    (slot < scene.n_free).then(|| slot * d + p % d)
                })
                .collect()
        };
        // Column lists of the upper triangle, sorted and deduplicated.
        let mut cols: Vec<Vec<usize>> = (0..n).map(|c| vec![c]).collect();
        for s in &scene.springs {
            let g = globals(s);
            for &r in g.iter().flatten() {
                for &c in g.iter().flatten() {
                    if r < c {
                        cols[c].push(r);
                    }
                }
            }
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for c in cols.iter_mut() {
            c.sort_unstable();
            c.dedup();
            row_idx.extend_from_slice(c);
            col_ptr.push(row_idx.len());
        }
        let find = |r: usize, c: usize| col_ptr[c] + row_idx[col_ptr[c]..col_ptr[c + 1]].binary_search(&r).unwrap();
        let diag = (0..n).map(|c| find(c, c)).collect();
        let entries: Vec<(usize, usize, usize)> = if d == 2 { upper_entries::<2>().collect() } else { upper_entries::<3>().collect() };
        let mut local = Vec::with_capacity(scene.springs.len() * entries.len());
        for s in &scene.springs {
            let free = |slot: usize| slot < scene.n_free;
            for &(block, i, j) in &entries {
                let (p, q) = match block {
                    0 => (s.a, s.a),
                    1 => (s.b, s.b),
                    _ => (s.a, s.b),
                };
                local.push(if free(p) && free(q) {
                    let (r, c) = (p * d + i, q * d + j);
                    find(r.min(c), r.max(c))
                } else {
                    SKIP
                });
            }
        }
        StiffnessPattern { col_ptr, row_idx, diag, local }
    }

    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// Adds `scale` * K(x) (upper triangle) to `vals`.
    pub fn add_tangent(&self, scene: &Scene, x: &[f64], scale: f64, vals: &mut [f64]) {
        self.add_tangent_with(scene, x, scale, false, vals)
    }

    /// [`Self::add_tangent`]; with `tension_only` a compressed spring adds
    /// its axial stiffness alone (its geometric term k (1 - l0/l) (I - u u^T),
    /// negative in compression, left out), so K(x) stays positive semidefinite.
    pub fn add_tangent_with(&self, scene: &Scene, x: &[f64], scale: f64, tension_only: bool, vals: &mut [f64]) {
        match scene.dim {
            2 => self.add_tangent_d::<2>(scene, x, scale, tension_only, vals),
            _ => self.add_tangent_d::<3>(scene, x, scale, tension_only, vals),
        }
    }

    fn add_tangent_d<const D: usize>(&self, scene: &Scene, x: &[f64], scale: f64, tension_only: bool, vals: &mut [f64]) {
        // `local` in the order of `upper_entries`: (a, a), (b, b), then between a and b.
        let nd = D * (D + 1) / 2;
        for (s, local) in scene.springs.iter().zip(self.local.chunks_exact(2 * nd + D * D)) {
            let ke = if tension_only {
                let d: [f64; D] = std::array::from_fn(|i| x[s.b * D + i] - x[s.a * D + i]);
                let l = d.iter().map(|c| c * c).sum::<f64>().sqrt();
                block(&d, s.k, s.rest.min(l))
            } else {
                spring_block::<D>(s, x, false)
            };
            let (aa, rest) = local.split_at(nd);
            let (bb, ab) = rest.split_at(nd);
            let mut k = 0;
            for i in 0..D {
                for j in i..D {
                    let v = scale * ke[(i, j)];
                    for pos in [aa[k], bb[k]] {
                        if pos != SKIP {
                            vals[pos] += v;
                        }
                    }
                    k += 1;
                }
            }
            for i in 0..D {
                for j in 0..D {
                    let pos = ab[i * D + j];
                    if pos != SKIP {
                        vals[pos] += -scale * ke[(i, j)];
                    }
                }
            }
        }
    }

    /// y = A v for the symmetric matrix whose upper triangle is `vals`.
    pub fn sym_matvec(&self, vals: &[f64], v: &[f64], y: &mut [f64]) {
        y.fill(0.0);
        for c in 0..self.col_ptr.len() - 1 {
            for pos in self.col_ptr[c]..self.col_ptr[c + 1] {
                let r = self.row_idx[pos];
                y[r] += vals[pos] * v[c];
                if r != c {
                    y[c] += vals[pos] * v[r];
                }
            }
        }
    }
}

/// Upper bound on lambda_max(M^-1 K_taut) by Gershgorin on M^-1/2 K_taut M^-1/2,
/// where every spring acts as k I. Bounds the squared frequency of the
/// full-space model in any state where no spring is compressed.
pub fn omega_sq_bound_full(scene: &Scene) -> f64 {
    let d = scene.dim;
    let nf = scene.n_free;
    let m = |slot: usize| scene.dof_mass[slot * d];
    let mut row = vec![0.0; nf];
    for s in &scene.springs {
        if s.a < nf {
            row[s.a] += s.k / m(s.a);
        }
        if s.b < nf {
            row[s.b] += s.k / m(s.b);
        }
        if s.a < nf && s.b < nf {
            let off = s.k / (m(s.a) * m(s.b)).sqrt();
            row[s.a] += off;
            row[s.b] += off;
        }
    }
    row.into_iter().fold(0.0, f64::max)
}

/// The linearization at rest: the sparsity of the free-DOF stiffness and the
/// upper triangle of K0 = K(x*) on it.
pub fn linearize(scene: &Scene) -> (StiffnessPattern, Vec<f64>) {
    let pattern = StiffnessPattern::new(scene);
    let mut k0 = vec![0.0; pattern.nnz()];
    pattern.add_tangent(scene, &scene.rest, 1.0, &mut k0);
    (pattern, k0)
}
