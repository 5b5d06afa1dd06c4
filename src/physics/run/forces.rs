//! Spring forces (`docs/method.md`, section 2, paper eq. 1), elastic energy
//! and tangent stiffness.
//!
//! Every kernel walks the spring list once and is monomorphised on the
//! dimension `D`: the geometry of a spring (its vector, the sums at a node,
//! its D x D stiffness block) is nalgebra's fixed-size `SVector` and
//! `SMatrix`, so the inner loops have fixed length. What is fixed after
//! set-up (incidence lists, stiffnesses, sparsity) is apart from the scratch
//! a force evaluation writes ([`SpringScratch`]).

use nalgebra::SVector;

use crate::physics::setup::scene::Scene;

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
        let SpringSplit { blocks, chunks, late, energies } = split;
        let (n_free, d) = (scene.n_free, scene.dim);
        let all = 0..energies.len();
        let (gs, f_free) = (&mut scratch.g, &mut f[..n_free * d]);
        pool.install(|| match d {
            2 => self.pieces::<2>(n_free, x, all, blocks, chunks, gs, base, f_free, energies),
            _ => self.pieces::<3>(n_free, x, all, blocks, chunks, gs, base, f_free, energies),
        });
        for &block in late.iter() {
            let (lo, hi) = (block * NODE_BLOCK, ((block + 1) * NODE_BLOCK).min(n_free));
            let (base, f) = (Some(&base[lo * d..hi * d]), &mut f[lo * d..hi * d]);
            match d {
                2 => self.gather::<2>(gs, 0, lo, hi, base, f),
                _ => self.gather::<3>(gs, 0, lo, hi, base, f),
            }
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

/// The `D` coordinates of slot `slot` in a flat array.
#[inline(always)]
fn point<const D: usize>(x: &[f64], slot: usize) -> SVector<f64, D> {
    let p: &[f64; D] = x[slot * D..slot * D + D].try_into().expect("D values");
    SVector::from(*p)
}
