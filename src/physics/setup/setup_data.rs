//! What a modal set-up computes that costs time, as data: the basis and
//! its linearization point, the explicit-step bound, the cubature set, the
//! range of a trained basis, and for an adaptive run what its set-up chose
//! besides the basis ([`AdaptiveChoice`]). A simulator built from it
//! ([`crate::physics::Simulator::with_setup`]) skips the eigen
//! decomposition, the equilibrium, the training runs and the cubature
//! trainings and runs bit for bit as one that computed them, since every
//! later quantity is derived from these values by the same code.
//!
//! [`SetupData::to_bytes`] writes it little-endian, f64 as their bits;
//! [`SetupData::from_bytes`] refuses anything that does not parse to the
//! end, whose lengths do not fit the basis's n and r, or whose values are
//! not finite where they must be. Which parameters it belongs to is the
//! caller's business.

use crate::bytes::{put_f64s, put_u32, put_u64, put_u8, Reader};
use crate::physics::setup::modes::ModalBasis;

/// The cubature set: scene indices of the kept springs and their weights.
#[derive(Clone, Debug, PartialEq)]
pub struct SpringSet {
    pub springs: Vec<usize>,
    pub weights: Vec<f64>,
    /// Relative force errors reached on the training and the held-out poses.
    pub training_error: f64,
    pub held_out_error: f64,
}

/// The range a trained basis was trained for (`docs/method.md`, section 3):
/// per basis vector j the centre c_j and half-width h_j of the box its
/// coordinate spanned over the training snapshots.
#[derive(Clone, Debug, PartialEq)]
pub struct TrainedRange {
    pub center: Vec<f64>,
    pub half_width: Vec<f64>,
}

impl TrainedRange {
    /// The box of the coordinates `snapshots` (each one value per basis
    /// vector). A half-width is at least 1e-3 of the largest, so a vector
    /// the snapshots hardly move does not make round-off read as leaving.
    pub fn of(snapshots: &[Vec<f64>], r: usize) -> Self {
        let (mut lo, mut hi) = (vec![f64::INFINITY; r], vec![f64::NEG_INFINITY; r]);
        for q in snapshots {
            for j in 0..r {
                lo[j] = lo[j].min(q[j]);
                hi[j] = hi[j].max(q[j]);
            }
        }
        let center: Vec<f64> = (0..r).map(|j| 0.5 * (lo[j] + hi[j])).collect();
        let mut half_width: Vec<f64> = (0..r).map(|j| 0.5 * (hi[j] - lo[j])).collect();
        let floor = 1e-3 * half_width.iter().fold(0.0f64, |m, h| m.max(*h));
        half_width.iter_mut().for_each(|h| *h = h.max(floor).max(f64::MIN_POSITIVE));
        TrainedRange { center, half_width }
    }

    /// max_j |q_j - c_j| / h_j: at most 1 inside the box.
    pub fn distance(&self, q: &[f64]) -> f64 {
        q.iter().zip(&self.center).zip(&self.half_width).fold(0.0, |m, ((q, c), h)| m.max((q - c).abs() / h))
    }
}

/// What the set-up of an adaptive run chose besides its trained basis
/// (`crate::physics::setup::adaptive_basis`, `docs/method.md`, section 10).
/// The rest of what the run needs is cheap and derived again: the
/// stiffness at the linearization point, the trained vectors (the basis's
/// columns) and the settings of the trained basis.
#[derive(Clone, Debug, PartialEq)]
pub struct AdaptiveChoice {
    /// Principal components the basis keeps (1 ..= r; the rest of the basis
    /// is the vectors a trained basis always keeps), and the held-out
    /// projection error they reach.
    pub components: usize,
    pub held_out_error: f64,
    /// The components could not reach the tolerance's share: the basis holds every one.
    pub short: bool,
    /// sqrt of the mean of ‖d_k‖²_M over the training snapshots d_k [m sqrt(kg)].
    pub motion_scale: f64,
    /// Each training snapshot's coordinates in the basis (r values each):
    /// the poses the error model's cubature was trained on.
    pub poses: Vec<Vec<f64>>,
    /// Candidates for the error model's directions (n values each).
    pub error_directions: Vec<Vec<f64>>,
    /// With cubature forces, the error model's spring set (also the grown bases' cubature).
    pub error_set: Option<SpringSet>,
}

impl AdaptiveChoice {
    /// Its lengths fit a basis of `r` vectors over `n` degrees of freedom,
    /// and every value is finite (and non-negative where it is a size).
    pub fn fits(&self, n: usize, r: usize) -> bool {
        let finite = |v: &Vec<f64>| v.iter().all(|x| x.is_finite());
        (1..=r).contains(&self.components)
            && self.held_out_error.is_finite()
            && self.held_out_error >= 0.0
            && self.motion_scale.is_finite()
            && self.motion_scale >= 0.0
            && self.poses.iter().all(|q| q.len() == r && finite(q))
            && self.error_directions.iter().all(|d| d.len() == n && finite(d))
            && self.error_set.as_ref().is_none_or(SpringSet::is_sound)
    }
}

impl SpringSet {
    /// As many weights as springs, each finite and positive; finite errors.
    fn is_sound(&self) -> bool {
        self.springs.len() == self.weights.len()
            && self.weights.iter().all(|w| w.is_finite() && *w > 0.0)
            && self.training_error.is_finite()
            && self.held_out_error.is_finite()
    }
}

/// The products of a modal set-up.
#[derive(Clone, Debug)]
pub struct SetupData {
    pub basis: ModalBasis,
    /// Slot positions x* the modal coordinates are measured from.
    pub point: Vec<f64>,
    pub at_rest: bool,
    /// Squared-frequency bound of the reduced system with every spring [1/s^2].
    pub omega_sq_bound: f64,
    pub cubature: Option<SpringSet>,
    /// The range of a trained basis.
    pub range: Option<TrainedRange>,
    /// What the set-up of an adaptive run chose besides the basis.
    pub adaptive: Option<AdaptiveChoice>,
}

const MAGIC: &[u8; 8] = b"MMSSETUP";
/// 3: the adaptive section.
const FORMAT: u32 = 3;

/// A spring set: its springs (as f64), weights, and the two errors.
fn put_spring_set(b: &mut Vec<u8>, c: &SpringSet) {
    put_f64s(b, &c.springs.iter().map(|&s| s as f64).collect::<Vec<_>>());
    put_f64s(b, &c.weights);
    put_f64s(b, &[c.training_error, c.held_out_error]);
}

fn spring_set(r: &mut Reader) -> Option<SpringSet> {
    let springs = r.f64s().ok()?;
    if !springs.iter().all(|s| s.fract() == 0.0 && *s >= 0.0 && *s < 1e15) {
        return None;
    }
    let weights = r.f64s().ok()?;
    let errors = r.f64s().ok()?;
    if errors.len() != 2 {
        return None;
    }
    Some(SpringSet { springs: springs.iter().map(|&s| s as usize).collect(), weights, training_error: errors[0], held_out_error: errors[1] })
}

/// Vectors of one length: their count (u64), then all their values (as [`put_f64s`]).
fn put_vectors(b: &mut Vec<u8>, vectors: &[Vec<f64>]) {
    put_u64(b, vectors.len() as u64);
    put_f64s(b, &vectors.concat());
}

/// [`put_vectors`] read back as vectors of `len` values; `None` unless the values are exactly that many.
fn vectors(r: &mut Reader, len: usize) -> Option<Vec<Vec<f64>>> {
    let count = usize::try_from(r.u64().ok()?).ok()?;
    let values = r.f64s().ok()?;
    if len == 0 || values.len() != count.checked_mul(len)? {
        return None;
    }
    Some(values.chunks_exact(len).map(<[f64]>::to_vec).collect())
}

/// A flag byte: 0 or 1.
fn flag(r: &mut Reader) -> Option<bool> {
    match r.u8().ok()? {
        0 => Some(false),
        1 => Some(true),
        _ => None,
    }
}

impl SetupData {
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut b = Vec::new();
        b.extend_from_slice(MAGIC);
        put_u32(&mut b, FORMAT);
        put_u64(&mut b, self.basis.n as u64);
        put_u64(&mut b, self.basis.r as u64);
        put_f64s(&mut b, &self.basis.lambda);
        put_f64s(&mut b, &self.basis.phi);
        put_f64s(&mut b, &self.point);
        put_u8(&mut b, self.at_rest as u8);
        put_f64s(&mut b, &[self.omega_sq_bound]);
        match &self.cubature {
            None => put_u8(&mut b, 0),
            Some(c) => {
                put_u8(&mut b, 1);
                put_spring_set(&mut b, c);
            }
        }
        match &self.range {
            None => put_u8(&mut b, 0),
            Some(t) => {
                put_u8(&mut b, 1);
                put_f64s(&mut b, &t.center);
                put_f64s(&mut b, &t.half_width);
            }
        }
        match &self.adaptive {
            None => put_u8(&mut b, 0),
            Some(a) => {
                put_u8(&mut b, 1);
                put_u64(&mut b, a.components as u64);
                put_f64s(&mut b, &[a.held_out_error, a.motion_scale]);
                put_u8(&mut b, a.short as u8);
                put_vectors(&mut b, &a.poses);
                put_vectors(&mut b, &a.error_directions);
                match &a.error_set {
                    None => put_u8(&mut b, 0),
                    Some(c) => {
                        put_u8(&mut b, 1);
                        put_spring_set(&mut b, c);
                    }
                }
            }
        }
        b
    }

    /// Parses [`Self::to_bytes`]; `None` if the bytes are not exactly that
    /// (or the adaptive section does not fit the basis, see [`AdaptiveChoice::fits`]).
    pub fn from_bytes(bytes: &[u8]) -> Option<SetupData> {
        let mut r = Reader::new(bytes);
        if r.take(8).ok()? != MAGIC || r.u32().ok()? != FORMAT {
            return None;
        }
        let (n, rr) = (usize::try_from(r.u64().ok()?).ok()?, usize::try_from(r.u64().ok()?).ok()?);
        let lambda = r.f64s().ok()?;
        let phi = r.f64s().ok()?;
        let point = r.f64s().ok()?;
        let at_rest = flag(&mut r)?;
        let omega_sq_bound = *r.f64s().ok()?.first()?;
        let cubature = if flag(&mut r)? { Some(spring_set(&mut r)?) } else { None };
        let range = match flag(&mut r)? {
            false => None,
            true => {
                let (center, half_width) = (r.f64s().ok()?, r.f64s().ok()?);
                if center.len() != rr
                    || half_width.len() != rr
                    || !center.iter().all(|c| c.is_finite())
                    || !half_width.iter().all(|h| h.is_finite() && *h > 0.0)
                {
                    return None;
                }
                Some(TrainedRange { center, half_width })
            }
        };
        let adaptive = match flag(&mut r)? {
            false => None,
            true => {
                let components = usize::try_from(r.u64().ok()?).ok()?;
                let values = r.f64s().ok()?;
                let [held_out_error, motion_scale] = values[..] else { return None };
                let short = flag(&mut r)?;
                let poses = vectors(&mut r, rr)?;
                let error_directions = vectors(&mut r, n)?;
                let error_set = if flag(&mut r)? { Some(spring_set(&mut r)?) } else { None };
                let choice = AdaptiveChoice { components, held_out_error, short, motion_scale, poses, error_directions, error_set };
                if !choice.fits(n, rr) {
                    return None;
                }
                Some(choice)
            }
        };
        if !r.is_done() || lambda.len() != rr || phi.len() != n.checked_mul(rr)? {
            return None;
        }
        Some(SetupData { basis: ModalBasis { n, r: rr, lambda, phi }, point, at_rest, omega_sq_bound, cubature, range, adaptive })
    }
}
