//! The one reader and writer of the FMU's byte formats: serialized FMU
//! states (`fmi::serialize`), the baked set-up file (`model::bake`) and the
//! set-up data inside it (`physics::setup::setup_data`). Little-endian
//! throughout; a float is its IEEE 754 bits, so every value reads back
//! bit for bit. Every read checks the bytes left first, so truncated or
//! hostile input is refused without reading past the end or allocating
//! more than the input could hold.

/// A read ran past the end of the bytes (or a length could not be represented).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Truncated;

impl From<Truncated> for String {
    fn from(_: Truncated) -> String {
        "truncated: the bytes end before the data they announce".into()
    }
}

/// Reads bytes front to back.
pub struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    pub fn new(bytes: &'a [u8]) -> Self {
        Reader { bytes, at: 0 }
    }

    /// The next `n` bytes.
    pub fn take(&mut self, n: usize) -> Result<&'a [u8], Truncated> {
        let end = self.at.checked_add(n).ok_or(Truncated)?;
        let s = self.bytes.get(self.at..end).ok_or(Truncated)?;
        self.at = end;
        Ok(s)
    }

    /// Bytes not read yet.
    pub fn remaining(&self) -> usize {
        self.bytes.len() - self.at
    }

    /// Every byte was read.
    pub fn is_done(&self) -> bool {
        self.at == self.bytes.len()
    }

    pub fn u8(&mut self) -> Result<u8, Truncated> {
        Ok(self.take(1)?[0])
    }

    pub fn u32(&mut self) -> Result<u32, Truncated> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into().expect("4 bytes")))
    }

    pub fn u64(&mut self) -> Result<u64, Truncated> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into().expect("8 bytes")))
    }

    pub fn f64(&mut self) -> Result<f64, Truncated> {
        Ok(f64::from_bits(self.u64()?))
    }

    /// `n` floats; `n` is checked against the bytes left before allocating.
    pub fn f64s_of(&mut self, n: usize) -> Result<Vec<f64>, Truncated> {
        let raw = self.take(n.checked_mul(8).ok_or(Truncated)?)?;
        Ok(raw.chunks_exact(8).map(|c| f64::from_bits(u64::from_le_bytes(c.try_into().expect("8 bytes")))).collect())
    }

    /// Floats after their count as a u64 (what [`put_f64s`] writes).
    pub fn f64s(&mut self) -> Result<Vec<f64>, Truncated> {
        let n = self.u64()?;
        self.f64s_of(usize::try_from(n).map_err(|_| Truncated)?)
    }
}

pub fn put_u8(v: &mut Vec<u8>, x: u8) {
    v.push(x);
}

pub fn put_u32(v: &mut Vec<u8>, x: u32) {
    v.extend_from_slice(&x.to_le_bytes());
}

pub fn put_u64(v: &mut Vec<u8>, x: u64) {
    v.extend_from_slice(&x.to_le_bytes());
}

pub fn put_f64(v: &mut Vec<u8>, x: f64) {
    v.extend_from_slice(&x.to_bits().to_le_bytes());
}

/// Floats after their count as a u64.
pub fn put_f64s(v: &mut Vec<u8>, x: &[f64]) {
    put_u64(v, x.len() as u64);
    x.iter().for_each(|x| put_f64(v, *x));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn what_is_written_reads_back_bit_for_bit_and_a_short_read_is_refused() {
        let mut b = Vec::new();
        put_u8(&mut b, 7);
        put_u32(&mut b, 0xdead_beef);
        put_f64s(&mut b, &[1.5, -0.0, f64::MIN_POSITIVE]);
        let mut r = Reader::new(&b);
        assert_eq!(r.u8(), Ok(7));
        assert_eq!(r.u32(), Ok(0xdead_beef));
        let xs = r.f64s().unwrap();
        assert_eq!(xs.iter().map(|x| x.to_bits()).collect::<Vec<_>>(), [1.5f64, -0.0, f64::MIN_POSITIVE].map(f64::to_bits));
        assert!(r.is_done());
        assert_eq!(r.u8(), Err(Truncated));
        // A count larger than the bytes left is refused before allocating.
        let mut b = Vec::new();
        put_u64(&mut b, u64::MAX / 4);
        assert_eq!(Reader::new(&b).f64s(), Err(Truncated));
    }
}
