//! What a modal set-up computes that costs time, as data: the basis and
//! its linearization point, the explicit-step bound, the cubature set, the
//! range of a trained basis. A simulator built from it ([`crate::physics::Simulator::with_setup`]) skips the
//! eigen decomposition, the equilibrium, the training runs and the cubature training and runs
//! bit for bit as one that computed them, since every later quantity is
//! derived from these values by the same code.
//!
//! [`SetupData::to_bytes`] writes it little-endian, f64 as their bits;
//! [`SetupData::from_bytes`] refuses anything that does not parse to the
//! end. Which parameters it belongs to is the caller's business.

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
}

const MAGIC: &[u8; 8] = b"MMSSETUP";
const FORMAT: u32 = 2;

impl SetupData {
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut b = Vec::new();
        b.extend_from_slice(MAGIC);
        b.extend_from_slice(&FORMAT.to_le_bytes());
        let words = |b: &mut Vec<u8>, v: &[f64]| {
            b.extend_from_slice(&(v.len() as u64).to_le_bytes());
            v.iter().for_each(|x| b.extend_from_slice(&x.to_bits().to_le_bytes()));
        };
        b.extend_from_slice(&(self.basis.n as u64).to_le_bytes());
        b.extend_from_slice(&(self.basis.r as u64).to_le_bytes());
        words(&mut b, &self.basis.lambda);
        words(&mut b, &self.basis.phi);
        words(&mut b, &self.point);
        b.push(self.at_rest as u8);
        words(&mut b, &[self.omega_sq_bound]);
        match &self.cubature {
            None => b.push(0),
            Some(c) => {
                b.push(1);
                words(&mut b, &c.springs.iter().map(|&s| s as f64).collect::<Vec<_>>());
                words(&mut b, &c.weights);
                words(&mut b, &[c.training_error, c.held_out_error]);
            }
        }
        match &self.range {
            None => b.push(0),
            Some(t) => {
                b.push(1);
                words(&mut b, &t.center);
                words(&mut b, &t.half_width);
            }
        }
        b
    }

    /// Parses [`Self::to_bytes`]; `None` if the bytes are not exactly that.
    pub fn from_bytes(bytes: &[u8]) -> Option<SetupData> {
        let mut r = Reader { bytes, at: 0 };
        if r.take(8)? != MAGIC || u32::from_le_bytes(r.take(4)?.try_into().ok()?) != FORMAT {
            return None;
        }
        let (n, rr) = (r.u64()? as usize, r.u64()? as usize);
        let lambda = r.words()?;
        let phi = r.words()?;
        let point = r.words()?;
        let at_rest = match r.take(1)?[0] {
            0 => false,
            1 => true,
            _ => return None,
        };
        let omega_sq_bound = *r.words()?.first()?;
        let cubature = match r.take(1)?[0] {
            0 => None,
            1 => {
                let springs = r.words()?;
                if !springs.iter().all(|s| s.fract() == 0.0 && *s >= 0.0 && *s < 1e15) {
                    return None;
                }
                let weights = r.words()?;
                let errors = r.words()?;
                Some(SpringSet {
                    springs: springs.iter().map(|&s| s as usize).collect(),
                    weights,
                    training_error: *errors.first()?,
                    held_out_error: *errors.get(1)?,
                })
            }
            _ => return None,
        };
        let range = match r.take(1)?[0] {
            0 => None,
            1 => {
                let (center, half_width) = (r.words()?, r.words()?);
                if center.len() != rr
                    || half_width.len() != rr
                    || !center.iter().all(|c| c.is_finite())
                    || !half_width.iter().all(|h| h.is_finite() && *h > 0.0)
                {
                    return None;
                }
                Some(TrainedRange { center, half_width })
            }
            _ => return None,
        };
        if r.at != bytes.len() || lambda.len() != rr || phi.len() != n.checked_mul(rr)? {
            return None;
        }
        Some(SetupData { basis: ModalBasis { n, r: rr, lambda, phi }, point, at_rest, omega_sq_bound, cubature, range })
    }
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let end = self.at.checked_add(n)?;
        let s = self.bytes.get(self.at..end)?;
        self.at = end;
        Some(s)
    }
    fn u64(&mut self) -> Option<u64> {
        Some(u64::from_le_bytes(self.take(8)?.try_into().ok()?))
    }
    fn words(&mut self) -> Option<Vec<f64>> {
        let n = self.u64()? as usize;
        let raw = self.take(n.checked_mul(8)?)?;
        Some(raw.chunks_exact(8).map(|c| f64::from_bits(u64::from_le_bytes(c.try_into().unwrap()))).collect())
    }
}
