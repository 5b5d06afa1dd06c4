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
                put_f64s(&mut b, &c.springs.iter().map(|&s| s as f64).collect::<Vec<_>>());
                put_f64s(&mut b, &c.weights);
                put_f64s(&mut b, &[c.training_error, c.held_out_error]);
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
        b
    }

    /// Parses [`Self::to_bytes`]; `None` if the bytes are not exactly that.
    pub fn from_bytes(bytes: &[u8]) -> Option<SetupData> {
        let mut r = Reader::new(bytes);
        if r.take(8).ok()? != MAGIC || r.u32().ok()? != FORMAT {
            return None;
        }
        let (n, rr) = (r.u64().ok()? as usize, r.u64().ok()? as usize);
        let lambda = r.f64s().ok()?;
        let phi = r.f64s().ok()?;
        let point = r.f64s().ok()?;
        let at_rest = match r.u8().ok()? {
            0 => false,
            1 => true,
            _ => return None,
        };
        let omega_sq_bound = *r.f64s().ok()?.first()?;
        let cubature = match r.u8().ok()? {
            0 => None,
            1 => {
                let springs = r.f64s().ok()?;
                if !springs.iter().all(|s| s.fract() == 0.0 && *s >= 0.0 && *s < 1e15) {
                    return None;
                }
                let weights = r.f64s().ok()?;
                let errors = r.f64s().ok()?;
                Some(SpringSet {
                    springs: springs.iter().map(|&s| s as usize).collect(),
                    weights,
                    training_error: *errors.first()?,
                    held_out_error: *errors.get(1)?,
                })
            }
            _ => return None,
        };
        let range = match r.u8().ok()? {
            0 => None,
            1 => {
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
            _ => return None,
        };
        if !r.is_done() || lambda.len() != rr || phi.len() != n.checked_mul(rr)? {
            return None;
        }
        Some(SetupData { basis: ModalBasis { n, r: rr, lambda, phi }, point, at_rest, omega_sq_bound, cubature, range })
    }
}
