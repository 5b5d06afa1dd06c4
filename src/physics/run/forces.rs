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

/// Exact spring forces on the free DOFs (paper eq. 1), in two kinds of
/// passes over flat arrays, each independent per spring or per node:
///
/// 1. springs, [`LANES`] at a time: d = x_b - x_a and l^2 = |d|^2
///    (gathers), t = k (l - l0) / l and the energy 1/2 k (l - l0)^2 lane by
///    lane, so the compiler issues packed square roots and divisions (the
///    divider bounds the kernel; on x86-64 CPUs with AVX a copy compiled for
///    AVX runs them four wide, the same IEEE operations and so the same
///    bits), and g = t d into the scratch;
/// 2. gather: per free slot, f += sum of g over the springs starting there
///    - sum of g over the springs ending there.
///
/// The two alternate over blocks of [`NODE_BLOCK`] slots: before a block is
/// gathered, the springs up to the last one it needs are evaluated (in
/// spring order), so on a grid, whose springs run row by row, the g a block
/// reads were written moments before and are read from cache, not memory.
/// Every value and every sum is that of one spring pass followed by one
/// gather pass, in the same order: only the traffic changes.
///
/// Scattering each spring straight into f instead chains every update of a
/// node through memory and keeps the divider scalar; it measured about twice
/// as slow on the 2D paper scene. The incidence lists and the block
/// schedule are made once per scene, the per-spring buffer once per
/// simulator ([`SpringScratch`]).
pub struct SpringForces {
    /// For free slot `s`: `springs[offsets[2s]..offsets[2s + 1]]` start there,
    /// `springs[offsets[2s + 1]..offsets[2s + 2]]` end there.
    offsets: Vec<u32>,
    springs: Vec<u32>,
    /// Per spring: its end slots (a, b), stiffness and rest length, copied
    /// from the scene into flat arrays; `stiffness` and `rest` padded to
    /// whole lanes with k = 0, l0 = 0.
    ends: Vec<[u32; 2]>,
    stiffness: Vec<f64>,
    rest: Vec<f64>,
    /// Per block of [`NODE_BLOCK`] free slots: the spring chunks (of
    /// [`LANES`]) that must be evaluated before it is gathered, from the
    /// first chunk on (non-decreasing), and the first chunk it reads.
    needs: Vec<u32>,
    firsts: Vec<u32>,
}

/// The split of one force evaluation over threads ([`SpringForces::add_to_parallel`]):
/// piece t gathers the node blocks `blocks[t]..blocks[t + 1]` and evaluates
/// the spring chunks `chunks[t]..chunks[t + 1]`, those its blocks need
/// beyond what the blocks before needed. A block that reads a chunk of an
/// earlier piece (on a grid, the first rows of a piece) is gathered after
/// every piece is done (`late`). Each g is computed once, by one piece, and
/// each node sums its springs in the same order: the forces are bit for bit
/// those of one thread; the energy is summed per piece, then over the pieces.
pub struct SpringSplit {
    blocks: Vec<usize>,
    chunks: Vec<usize>,
    late: Vec<usize>,
    energies: Vec<[f64; LANES]>,
}

/// What one force evaluation writes per spring: g = t d (`D` values).
pub struct SpringScratch {
    g: Vec<f64>,
}

/// Lanes of the spring loop; four partial energy sums keep it vectorizable.
const LANES: usize = 4;

/// Free slots gathered per block (see [`SpringForces`]).
const NODE_BLOCK: usize = 256;

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
        let ends = scene.springs.iter().map(|s| [s.a as u32, s.b as u32]).collect();
        // The chunks each block needs: up to its last incident spring, and at least what the block before needed.
        let mut needs = Vec::with_capacity(nf.div_ceil(NODE_BLOCK));
        let mut firsts = Vec::with_capacity(nf.div_ceil(NODE_BLOCK));
        let mut need = 0u32;
        for block in 0..nf.div_ceil(NODE_BLOCK) {
            let (lo, hi) = (block * NODE_BLOCK, ((block + 1) * NODE_BLOCK).min(nf));
            let incident = &springs[offsets[2 * lo] as usize..offsets[2 * hi] as usize];
            let last = incident.iter().map(|&s| s + 1).max().unwrap_or(0);
            need = need.max((last as usize).div_ceil(LANES) as u32);
            needs.push(need);
            firsts.push(incident.iter().min().map_or(u32::MAX, |&s| s / LANES as u32));
        }
        SpringForces { offsets, springs, ends, stiffness, rest, needs, firsts }
    }

    /// The split of an evaluation over `threads` pieces of about as many
    /// node blocks each (see [`SpringSplit`]).
    pub fn split(&self, threads: usize) -> SpringSplit {
        let blocks_n = self.needs.len();
        let pieces = threads.clamp(1, blocks_n.max(1));
        let blocks: Vec<usize> = (0..=pieces).map(|t| t * blocks_n / pieces).collect();
        let total = self.stiffness.len() / LANES;
        let chunks: Vec<usize> = (0..=pieces)
            .map(|t| {
                if t == 0 {
                    0
                } else if t == pieces {
                    total
                } else {
                    self.needs[blocks[t] - 1] as usize
                }
            })
            .collect();
        let late = (0..pieces)
            .flat_map(|t| {
                let start = chunks[t];
                (blocks[t]..blocks[t + 1]).filter(move |&b| (self.firsts[b] as usize) < start)
            })
            .collect();
        SpringSplit { blocks, chunks, late, energies: vec![[0.0; LANES]; pieces] }
    }

    /// Buffers for [`Self::add_to`] on `scene`.
    pub fn scratch(&self, scene: &Scene) -> SpringScratch {
        SpringScratch { g: vec![0.0; scene.springs.len() * scene.dim] }
    }

    /// Adds the spring forces at slot positions `x` to `f` (the free DOFs)
    /// and returns the elastic energy sum 1/2 k (l - l0)^2.
    pub fn add_to(&self, scene: &Scene, x: &[f64], scratch: &mut SpringScratch, f: &mut [f64]) -> f64 {
        match scene.dim {
            2 => self.add_to_d::<2>(scene, x, scratch, None, f),
            _ => self.add_to_d::<3>(scene, x, scratch, None, f),
        }
    }

    /// f = `base` + the spring forces (the same bits as copying `base`
    /// into f and [`Self::add_to`], in one pass less); returns the energy.
    pub fn set_to(&self, scene: &Scene, x: &[f64], scratch: &mut SpringScratch, base: &[f64], f: &mut [f64]) -> f64 {
        match scene.dim {
            2 => self.add_to_d::<2>(scene, x, scratch, Some(base), f),
            _ => self.add_to_d::<3>(scene, x, scratch, Some(base), f),
        }
    }

    fn add_to_d<const D: usize>(&self, scene: &Scene, x: &[f64], scratch: &mut SpringScratch, base: Option<&[f64]>, f: &mut [f64]) -> f64 {
        let gs = &mut scratch.g;
        let chunks = self.stiffness.len() / LANES;
        let mut energy = [0.0; LANES];
        let mut done = 0;
        for (block, &need) in self.needs.iter().enumerate() {
            let need = need as usize;
            if need > done {
                self.springs_between::<D>(x, done, need, gs, 0, &mut energy);
                done = need;
            }
            let lo = block * NODE_BLOCK;
            let hi = (lo + NODE_BLOCK).min(scene.n_free);
            let base = base.map(|b| &b[lo * D..hi * D]);
            self.gather::<D>(gs, 0, lo, hi, base, &mut f[lo * D..hi * D]);
        }
        if chunks > done {
            self.springs_between::<D>(x, done, chunks, gs, 0, &mut energy);
        }
        energy.iter().sum()
    }

    /// [`Self::set_to`] over the pieces of `split` on the threads of `pool`:
    /// the same forces, bit for bit; the energy summed per piece.
    #[allow(clippy::too_many_arguments)]
    pub fn set_to_parallel(
        &self,
        scene: &Scene,
        x: &[f64],
        scratch: &mut SpringScratch,
        split: &mut SpringSplit,
        pool: &rayon::ThreadPool,
        base: &[f64],
        f: &mut [f64],
    ) -> f64 {
        match scene.dim {
            2 => self.parallel_d::<2>(scene.n_free, x, scratch, split, pool, base, f),
            _ => self.parallel_d::<3>(scene.n_free, x, scratch, split, pool, base, f),
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn parallel_d<const D: usize>(
        &self,
        n_free: usize,
        x: &[f64],
        scratch: &mut SpringScratch,
        split: &mut SpringSplit,
        pool: &rayon::ThreadPool,
        base: &[f64],
        f: &mut [f64],
    ) -> f64 {
        let SpringSplit { blocks, chunks, late, energies } = split;
        let pieces = energies.len();
        pool.install(|| self.pieces::<D>(n_free, x, 0..pieces, blocks, chunks, &mut scratch.g, base, &mut f[..n_free * D], energies));
        let gs = &scratch.g;
        for &block in late.iter() {
            let lo = block * NODE_BLOCK;
            let hi = (lo + NODE_BLOCK).min(n_free);
            self.gather::<D>(gs, 0, lo, hi, Some(&base[lo * D..hi * D]), &mut f[lo * D..hi * D]);
        }
        energies.iter().map(|e| e.iter().sum::<f64>()).sum()
    }

    /// Pieces `range` of the split: `gs` holds the g of their chunks, `f`
    /// the DOFs of their blocks, `energies` their sums; halved recursively
    /// onto the pool's threads.
    #[allow(clippy::too_many_arguments)]
    fn pieces<const D: usize>(
        &self,
        n_free: usize,
        x: &[f64],
        range: std::ops::Range<usize>,
        blocks: &[usize],
        chunks: &[usize],
        gs: &mut [f64],
        base: &[f64],
        f: &mut [f64],
        energies: &mut [[f64; LANES]],
    ) {
        let (t0, t1) = (range.start, range.end);
        if t1 - t0 > 1 {
            let mid = (t0 + t1) / 2;
            let g_at = ((chunks[mid] - chunks[t0]) * LANES * D).min(gs.len());
            let f_at = ((blocks[mid] - blocks[t0]) * NODE_BLOCK * D).min(f.len());
            let (g0, g1) = gs.split_at_mut(g_at);
            let (f0, f1) = f.split_at_mut(f_at);
            let (e0, e1) = energies.split_at_mut(mid - t0);
            rayon::join(
                || self.pieces::<D>(n_free, x, t0..mid, blocks, chunks, g0, base, f0, e0),
                || self.pieces::<D>(n_free, x, mid..t1, blocks, chunks, g1, base, f1, e1),
            );
            return;
        }
        // One piece: its chunks interleaved with its blocks, as add_to does.
        let (first_chunk, last_chunk) = (chunks[t0], chunks[t0 + 1]);
        let first = first_chunk * LANES;
        let mut energy = [0.0; LANES];
        let mut done = first_chunk;
        for block in blocks[t0]..blocks[t0 + 1] {
            let need = (self.needs[block] as usize).min(last_chunk);
            if need > done {
                self.springs_between::<D>(x, done, need, gs, first, &mut energy);
                done = need;
            }
            if (self.firsts[block] as usize) < first_chunk {
                continue; // gathered after every piece
            }
            let lo = block * NODE_BLOCK;
            let hi = (lo + NODE_BLOCK).min(n_free);
            let at = (blocks[t0] * NODE_BLOCK) * D;
            self.gather::<D>(gs, first, lo, hi, Some(&base[lo * D..hi * D]), &mut f[lo * D - at..hi * D - at]);
        }
        if last_chunk > done {
            self.springs_between::<D>(x, done, last_chunk, gs, first, &mut energy);
        }
        energies[0] = energy;
    }

    /// The spring loop over chunks `from..to` (of [`LANES`] springs): g of
    /// each into `gs`, its energy into the lane sums `energy`; four wide on
    /// CPUs with AVX (see [`SpringForces`]).
    /// `gs` holds the g of the springs from `first` on.
    fn springs_between<const D: usize>(&self, x: &[f64], from: usize, to: usize, gs: &mut [f64], first: usize, energy: &mut [f64; LANES]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU has AVX (checked above), all the copy needs.
            return unsafe { self.springs_between_avx::<D>(x, from, to, gs, first, energy) };
        }
        self.springs_between_any::<D>(x, from, to, gs, first, energy)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn springs_between_avx<const D: usize>(&self, x: &[f64], from: usize, to: usize, gs: &mut [f64], first: usize, energy: &mut [f64; LANES]) {
        self.springs_between_any::<D>(x, from, to, gs, first, energy)
    }

    #[inline(always)]
    fn springs_between_any<const D: usize>(&self, x: &[f64], from: usize, to: usize, gs: &mut [f64], first: usize, energy: &mut [f64; LANES]) {
        let whole = self.ends.len() / LANES;
        for c in from..to.min(whole) {
            self.chunk::<D, false>(x, c, gs, first, energy);
        }
        for c in from.max(whole)..to {
            self.chunk::<D, true>(x, c, gs, first, energy);
        }
    }

    /// Springs `LANES c .. LANES (c + 1)`; `TAIL`: the last chunk, whose
    /// lanes past the last spring are padding (|d|^2 = 1, k = l0 = 0:
    /// no energy, no g written).
    #[inline(always)]
    fn chunk<const D: usize, const TAIL: bool>(&self, x: &[f64], c: usize, gs: &mut [f64], first: usize, energy: &mut [f64; LANES]) {
        let base = c * LANES;
        let mut d = [[0.0; D]; LANES];
        let mut l2 = [1.0; LANES];
        for i in 0..LANES {
            if !TAIL || base + i < self.ends.len() {
                let [a, b] = self.ends[base + i];
                let diff = point::<D>(x, b as usize) - point::<D>(x, a as usize);
                d[i] = diff.into();
                l2[i] = diff.norm_squared();
            }
        }
        let k: &[f64; LANES] = self.stiffness[base..base + LANES].try_into().expect("LANES values");
        let l0: &[f64; LANES] = self.rest[base..base + LANES].try_into().expect("LANES values");
        let l: [f64; LANES] = std::array::from_fn(|i| l2[i].sqrt());
        let stretch: [f64; LANES] = std::array::from_fn(|i| l[i] - l0[i]);
        let force: [f64; LANES] = std::array::from_fn(|i| k[i] * stretch[i]);
        let t: [f64; LANES] = std::array::from_fn(|i| force[i] / l[i]);
        for i in 0..LANES {
            energy[i] += 0.5 * force[i] * stretch[i];
        }
        for i in 0..LANES {
            if !TAIL || base + i < self.ends.len() {
                let s = base + i - first;
                let g: &mut [f64; D] = (&mut gs[s * D..s * D + D]).try_into().expect("D values");
                *g = (SVector::from(d[i]) * t[i]).into();
            }
        }
    }

    /// f += sum of g over the springs starting at each free slot of
    /// `lo..hi` - sum over those ending there (f = `base` + the same, given
    /// `base`); `f` and `base` hold those slots' DOFs.
    #[inline]
    fn gather<const D: usize>(&self, gs: &[f64], first: usize, lo: usize, hi: usize, base: Option<&[f64]>, f: &mut [f64]) {
        let sum = |springs: &[u32]| -> SVector<f64, D> {
            let mut acc = SVector::<f64, D>::zeros();
            for &s in springs {
                acc += point::<D>(gs, s as usize - first);
            }
            acc
        };
        for (slot, fs) in (lo..hi).zip(f.chunks_exact_mut(D)) {
            let o = &self.offsets[2 * slot..2 * slot + 3];
            let starts = sum(&self.springs[o[0] as usize..o[1] as usize]);
            let stops = sum(&self.springs[o[1] as usize..o[2] as usize]);
            let fs: &mut [f64; D] = fs.try_into().expect("D values");
            let from = match base {
                Some(b) => b[(slot - lo) * D..(slot - lo + 1) * D].try_into().expect("D values"),
                None => *fs,
            };
            *fs = (SVector::from(from) + (starts - stops)).into();
        }
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
