//! Spring forces (`docs/method.md`, section 2, paper eq. 1), elastic energy
//! and tangent stiffness.
//!
//! Every kernel walks the spring list once and is monomorphised on the
//! dimension `D`: the geometry of a spring (its vector, the sums at a node,
//! its D x D stiffness block) is nalgebra's fixed-size `SVector` and
//! `SMatrix`, so the inner loops have fixed length. What is fixed after
//! set-up (incidence lists, stiffnesses, sparsity) is apart from the scratch
//! a force evaluation writes ([`SpringScratch`]).

use nalgebra::{SMatrix, SVector};

use crate::physics::setup::scene::{Scene, Spring};

/// Exact spring forces on the free DOFs (paper eq. 1), in passes over flat
/// arrays so that each loop is independent per spring or per node:
///
/// 1. `geometry`: per spring (a, b), d = x_b - x_a and l^2 = |d|^2 (gathers);
/// 2. `tension`: per spring, t = k (l - l0) / l and the energy 1/2 k (l - l0)^2
///    on contiguous arrays, so the compiler issues packed square roots and
///    divisions (the divider bounds the whole kernel), then g = t d in place
///    of d;
/// 3. `gather`: per free slot, f += sum of g over the springs starting there
///    - sum of g over the springs ending there.
///
/// Scattering each spring straight into f instead chains every update of a
/// node through memory and keeps the divider scalar; it measured about twice
/// as slow on the 2D paper scene. The incidence lists are made once per
/// scene, the per-spring buffers once per simulator ([`SpringScratch`]).
pub struct SpringForces {
    /// For free slot `s`: `springs[offsets[2s]..offsets[2s + 1]]` start there,
    /// `springs[offsets[2s + 1]..offsets[2s + 2]]` end there.
    offsets: Vec<u32>,
    springs: Vec<u32>,
    /// Per spring: stiffness, rest length (copied from the scene, flat,
    /// padded to whole lanes with k = 0, l0 = 0).
    stiffness: Vec<f64>,
    rest: Vec<f64>,
}

/// What one force evaluation writes per spring: d, then g (`D` values each);
/// |d|^2 (padding lanes 1); t.
pub struct SpringScratch {
    g: Vec<f64>,
    length_sq: Vec<f64>,
    tension: Vec<f64>,
}

/// Lanes of the tension loop; four partial energy sums keep it vectorizable.
const LANES: usize = 4;

impl SpringForces {
    pub fn new(scene: &Scene) -> Self {
        let nf = scene.n_free;
        let ns = scene.springs.len();
        // Counting sort of the (slot, end) pairs into 2 nf buckets.
        let bucket = |slot: usize, end: usize| 2 * slot + end;
        let mut count = vec![0u32; 2 * nf + 1];
        for s in &scene.springs {
            for (end, slot) in [s.a, s.b].into_iter().enumerate() {
                if slot < nf {
                    count[bucket(slot, end) + 1] += 1;
                }
            }
        }
        for i in 0..2 * nf {
            count[i + 1] += count[i];
        }
        let offsets = count.clone();
        let mut springs = vec![0u32; offsets[2 * nf] as usize];
        for (i, s) in scene.springs.iter().enumerate() {
            for (end, slot) in [s.a, s.b].into_iter().enumerate() {
                if slot < nf {
                    let b = bucket(slot, end);
                    springs[count[b] as usize] = i as u32;
                    count[b] += 1;
                }
            }
        }
        let padded = ns.div_ceil(LANES) * LANES;
        let mut stiffness: Vec<f64> = scene.springs.iter().map(|s| s.k).collect();
        let mut rest: Vec<f64> = scene.springs.iter().map(|s| s.rest).collect();
        stiffness.resize(padded, 0.0);
        rest.resize(padded, 0.0);
        SpringForces { offsets, springs, stiffness, rest }
    }

    /// Buffers for [`Self::add_to`] on `scene`.
    pub fn scratch(&self, scene: &Scene) -> SpringScratch {
        let padded = self.stiffness.len();
        SpringScratch { g: vec![0.0; scene.springs.len() * scene.dim], length_sq: vec![1.0; padded], tension: vec![0.0; padded] }
    }

    /// Adds the spring forces at slot positions `x` to `f` (the free DOFs)
    /// and returns the elastic energy sum 1/2 k (l - l0)^2.
    pub fn add_to(&self, scene: &Scene, x: &[f64], scratch: &mut SpringScratch, f: &mut [f64]) -> f64 {
        match scene.dim {
            2 => self.add_to_d::<2>(scene, x, scratch, f),
            _ => self.add_to_d::<3>(scene, x, scratch, f),
        }
    }

    fn add_to_d<const D: usize>(&self, scene: &Scene, x: &[f64], scratch: &mut SpringScratch, f: &mut [f64]) -> f64 {
        let SpringScratch { g: gs, length_sq: length_sqs, tension: tensions } = scratch;
        // geometry
        for ((s, d), l2) in scene.springs.iter().zip(gs.chunks_exact_mut(D)).zip(length_sqs.iter_mut()) {
            let diff = point::<D>(x, s.b) - point::<D>(x, s.a);
            d.copy_from_slice(diff.as_slice());
            *l2 = diff.norm_squared();
        }
        // tension
        let mut energy = [0.0; LANES];
        let (tension, _) = tensions.as_chunks_mut::<LANES>();
        let (length_sq, _) = length_sqs.as_chunks::<LANES>();
        let (stiffness, _) = self.stiffness.as_chunks::<LANES>();
        let (rest, _) = self.rest.as_chunks::<LANES>();
        for (((t, l2), k), l0) in tension.iter_mut().zip(length_sq).zip(stiffness).zip(rest) {
            let l: [f64; LANES] = std::array::from_fn(|i| l2[i].sqrt());
            let stretch: [f64; LANES] = std::array::from_fn(|i| l[i] - l0[i]);
            let force: [f64; LANES] = std::array::from_fn(|i| k[i] * stretch[i]);
            *t = std::array::from_fn(|i| force[i] / l[i]);
            for i in 0..LANES {
                energy[i] += 0.5 * force[i] * stretch[i];
            }
        }
        for (g, t) in gs.as_chunks_mut::<D>().0.iter_mut().zip(tensions.iter()) {
            *g = (SVector::from(*g) * *t).into();
        }
        // gather
        let sum = |springs: &[u32]| -> SVector<f64, D> {
            let mut acc = SVector::<f64, D>::zeros();
            for &s in springs {
                acc += point::<D>(gs, s as usize);
            }
            acc
        };
        for (slot, fs) in f[..scene.n_free * D].chunks_exact_mut(D).enumerate() {
            let o = &self.offsets[2 * slot..2 * slot + 3];
            let starts = sum(&self.springs[o[0] as usize..o[1] as usize]);
            let stops = sum(&self.springs[o[1] as usize..o[2] as usize]);
            let fs: &mut [f64; D] = fs.try_into().expect("D values");
            *fs = (SVector::from(*fs) + (starts - stops)).into();
        }
        energy.iter().sum()
    }
}

/// Elastic energy alone (no forces).
pub fn elastic_energy(scene: &Scene, x: &[f64]) -> f64 {
    let d = scene.dim;
    scene
        .springs
        .iter()
        .map(|s| {
            let l = (0..d).map(|i| (x[s.b * d + i] - x[s.a * d + i]).powi(2)).sum::<f64>().sqrt();
            0.5 * s.k * (l - s.rest).powi(2)
        })
        .sum()
}

/// The force of one spring on its end a, k (l - l0) / l d, for the spring
/// vector d = x_b - x_a of length l (`docs/method.md`, section 2); 0 for a
/// spring of zero length, whose direction is undefined. The spring loop of
/// [`SpringForces::add_to`] computes the same, lane by lane.
#[inline]
pub fn pull<const D: usize>(d: &[f64; D], k: f64, l0: f64) -> [f64; D] {
    let l = d.iter().map(|c| c * c).sum::<f64>().sqrt();
    if l > 0.0 {
        let t = k * (l - l0) / l;
        d.map(|c| t * c)
    } else {
        [0.0; D]
    }
}

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

/// The `D` coordinates of slot `slot` in a flat array.
#[inline(always)]
fn point<const D: usize>(x: &[f64], slot: usize) -> SVector<f64, D> {
    let p: &[f64; D] = x[slot * D..slot * D + D].try_into().expect("D values");
    SVector::from(*p)
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
    /// Per spring, `(2D)^2` positions of the local matrix [[Ke, -Ke], [-Ke, Ke]]
    /// in row-major local order; `usize::MAX` where the entry is not stored
    /// (a fixed end or the lower triangle).
    local: Vec<usize>,
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
        let mut local = Vec::with_capacity(scene.springs.len() * 4 * d * d);
        for s in &scene.springs {
            let g = globals(s);
            for p in 0..2 * d {
                for q in 0..2 * d {
                    local.push(match (g[p], g[q]) {
                        (Some(r), Some(c)) if r <= c => find(r, c),
                        _ => SKIP,
                    });
                }
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
        let m = 2 * D;
        for (si, s) in scene.springs.iter().enumerate() {
            let ke = if tension_only {
                let d: [f64; D] = std::array::from_fn(|i| x[s.b * D + i] - x[s.a * D + i]);
                let l = d.iter().map(|c| c * c).sum::<f64>().sqrt();
                block(&d, s.k, s.rest.min(l))
            } else {
                spring_block::<D>(s, x, false)
            };
            let local = &self.local[si * m * m..(si + 1) * m * m];
            for p in 0..m {
                for q in 0..m {
                    let pos = local[p * m + q];
                    if pos != SKIP {
                        let sign = if (p < D) == (q < D) { scale } else { -scale };
                        vals[pos] += sign * ke[(p % D, q % D)];
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
