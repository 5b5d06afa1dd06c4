//! Baked set-up: `resources/setup.bin`, written by `cargo xtask fmu --bake`,
//! holds the costly products of the modal set-up ([`SetupData`]: basis,
//! linearization point, cubature set; with reduction = adaptive also what
//! its set-up chose, with the error model's directions and spring set) with
//! the parameter values they were computed for. An instance whose values
//! match uses them and skips the eigen decomposition, the equilibrium, the
//! training runs and the cubature trainings, with a bit-identical run; one
//! whose values differ (or a file that is corrupt or from another build)
//! computes the set-up and logs why.
//!
//! The key is every structural and fixed parameter, the set-up gravity,
//! the set-up point load and errorTolerance at set-up (tunable, it sizes the basis),
//! except those set-up does not read ([`NOT_READ_BY_SETUP`]). File layout
//! (little-endian): magic `MMSBAKE1`, the crate version (u32 length +
//! bytes), the key (u32 count, then per variable u32 value reference, u32
//! count, f64 bits), the data (u64 length + [`SetupData::to_bytes`]), and a
//! CRC-32 of everything before it.

use crate::bytes::{put_f64, put_u32, put_u64, Reader, Truncated};
use crate::fmi::params::Params;
use crate::fmi::variables::{vr, Variability, VARIABLES};
use crate::physics::{SetupData, Simulator};

/// File name under `resources/`.
pub const FILE: &str = "setup.bin";
const MAGIC: &[u8; 8] = b"MMSBAKE1";
/// Fixed parameters the set-up of the basis and the cubature does not read
/// (a twin's start moves the state after it).
const NOT_READ_BY_SETUP: &[u32] = &[vr::INTEGRATOR, vr::MAX_INTERNAL_STEP, vr::START_OFFSET, vr::START_SEED];

/// Tunable parameters and inputs whose values at set-up the basis reads
/// (errorTolerance sizes the basis).
const SETUP_LOADS: &[u32] = &[vr::GRAVITY, vr::LOAD_X, vr::LOAD_Y, vr::LOAD_Z, vr::ERROR_TOLERANCE];

/// The values the set-up depends on, by value reference.
fn key(p: &Params) -> Vec<(u32, Vec<f64>)> {
    VARIABLES
        .iter()
        .enumerate()
        .filter(|(_, v)| v.holds_value() && (v.variability == Variability::Fixed || SETUP_LOADS.contains(&v.vr)) && !NOT_READ_BY_SETUP.contains(&v.vr))
        .map(|(i, v)| (v.vr, p.values[i].clone()))
        .collect()
}

/// The bake of `sim`, set up from `p` (an adaptive run's as set-up chose
/// it, whatever it grew to since); `None` in full space (nothing costly to keep).
pub fn write(p: &Params, sim: &Simulator) -> Option<Vec<u8>> {
    let data = sim.setup_data()?.to_bytes();
    let mut b = Vec::new();
    b.extend_from_slice(MAGIC);
    let version = env!("CARGO_PKG_VERSION").as_bytes();
    put_u32(&mut b, version.len() as u32);
    b.extend_from_slice(version);
    let key = key(p);
    put_u32(&mut b, key.len() as u32);
    for (vr, values) in &key {
        put_u32(&mut b, *vr);
        put_u32(&mut b, values.len() as u32);
        values.iter().for_each(|x| put_f64(&mut b, *x));
    }
    put_u64(&mut b, data.len() as u64);
    b.extend_from_slice(&data);
    let crc = crc32fast::hash(&b);
    b.extend_from_slice(&crc.to_le_bytes());
    Some(b)
}

/// The set-up data of a bake if it was made for the values of `p`, else why not.
pub fn read(bytes: &[u8], p: &Params) -> Result<SetupData, String> {
    let corrupt = || "the file is corrupt".to_string();
    if bytes.len() < MAGIC.len() + 4 || &bytes[..MAGIC.len()] != MAGIC {
        return Err("it is not a baked set-up".into());
    }
    let (body, crc) = bytes.split_at(bytes.len() - 4);
    if crc32fast::hash(body).to_le_bytes() != crc {
        return Err(corrupt());
    }
    let corrupted = |_: Truncated| corrupt();
    let mut r = Reader::new(&body[MAGIC.len()..]);
    let n = r.u32().map_err(corrupted)? as usize;
    let version = r.take(n).map_err(corrupted)?;
    if version != env!("CARGO_PKG_VERSION").as_bytes() {
        return Err(format!("it was baked by version {} of the FMU, this is {}", String::from_utf8_lossy(version), env!("CARGO_PKG_VERSION")));
    }
    let count = r.u32().map_err(corrupted)? as usize;
    let mut stored = Vec::with_capacity(count.min(VARIABLES.len()));
    for _ in 0..count {
        let vr = r.u32().map_err(corrupted)?;
        let n = r.u32().map_err(corrupted)? as usize;
        stored.push((vr, r.f64s_of(n).map_err(corrupted)?));
    }
    for (vr, values) in key(p) {
        let name = VARIABLES.iter().find(|v| v.vr == vr).map_or("?", |v| v.name);
        match stored.iter().find(|(s, _)| *s == vr) {
            Some((_, baked)) if *baked == values => {}
            Some((_, baked)) => return Err(format!("it was baked for {name} = {}, the instance has {}", show(baked), show(&values))),
            None => return Err(format!("it holds no value of {name}")),
        }
    }
    if stored.len() != key(p).len() {
        return Err("it was baked for other parameters".into());
    }
    let len = usize::try_from(r.u64().map_err(corrupted)?).map_err(|_| corrupt())?;
    let data = r.take(len).map_err(corrupted)?;
    if !r.is_done() {
        return Err(corrupt());
    }
    SetupData::from_bytes(data).ok_or_else(corrupt)
}

fn show(v: &[f64]) -> String {
    v.iter().map(|x| x.to_string()).collect::<Vec<_>>().join(" ")
}
