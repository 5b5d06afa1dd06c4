//! Byte format of a serialized FMU state (little-endian):
//!
//! | bytes | content |
//! |---|---|
//! | 8 | magic `MMSFMU3S` |
//! | 4 | format version |
//! | 8 | fingerprint of the variable layout |
//! | 8 | payload length |
//! | n | payload: mode, start time, stop time, every parameter and input (vr, length, values), the model's snapshot ([`Model::write_snapshot`], documented with the model) |
//! | 4 | CRC-32 (IEEE) of everything before |
//!
//! Decoding checks all of it and every value against the model description,
//! so a corrupted or foreign blob is refused instead of loaded.

use crate::bytes::{put_f64, put_f64s, put_u32, put_u64, Reader};

use super::fmu_state::FmuState;
use super::model::Model;
use super::params::Params;
use super::state_machine::Mode;
use super::values::check_value;
use super::variables::{index_of, LAYOUT_FINGERPRINT, OLDER_LAYOUT_FINGERPRINTS, SINCE_FORMAT, VARIABLES};
use crate::TheModel;

pub const MAGIC: &[u8; 8] = b"MMSFMU3S";
/// 1: FNV-1a checksum, no stop time; 2: CRC-32, stop time; 3: the
/// simulator state as time and three arrays (y, y', y'') instead of one
/// concatenated array; 4: the point load and its node among the loads,
/// the anchor's position and rate in the state and its target among the loads;
/// 5: the holder's orientation and spin, and its target; 6: holders 2 to 4
/// (their motions in the state, their targets among the loads) and the
/// variables that set them; 7: the variables of a later table (those with
/// `since_format` 7); 8: an adaptive run's part after the loads; 9: the
/// variables of a later table again (`since_format` 9); 10: the unseen
/// residual's share at the last check in the adaptive part; 11: in the
/// adaptive part, the state of the twin that carries the error in full
/// space instead of the error (a flag after the mode), and the error
/// tolerance in effect among the loads (the model's tolerance became tunable). Formats 5 to 10 are still read: the holders 2 to 4 of
/// format 5 are at rest, the variables a format lacks take their start
/// values, and an adaptive part before format 10 has measured no share.
pub const VERSION: u32 = 11;
/// The oldest format read.
pub const OLDEST: u32 = 5;
/// Bytes before the payload.
pub const HEADER: usize = 8 + 4 + 8 + 8;
/// Bytes after the payload.
pub const TRAILER: usize = 4;

pub fn checksum(bytes: &[u8]) -> u32 {
    crc32fast::hash(bytes)
}

/// Header, `payload` and checksum: a blob [`decode`] reads if the payload is valid.
pub fn seal(payload: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER + payload.len() + TRAILER);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&LAYOUT_FINGERPRINT.to_le_bytes());
    put_u64(&mut out, payload.len() as u64);
    out.extend_from_slice(payload);
    let sum = checksum(&out);
    out.extend_from_slice(&sum.to_le_bytes());
    out
}

pub fn encode(s: &FmuState) -> Vec<u8> {
    seal(&payload(s))
}

/// The payload of [`encode`], without header and checksum.
pub fn payload(s: &FmuState) -> Vec<u8> {
    let mut p = Vec::new();
    p.push(s.mode as u8);
    put_f64(&mut p, s.start_time);
    match s.stop_time {
        None => p.push(0),
        Some(t) => {
            p.push(1);
            put_f64(&mut p, t);
        }
    }
    let params: Vec<usize> = (0..VARIABLES.len()).filter(|&i| VARIABLES[i].holds_value()).collect();
    put_u64(&mut p, params.len() as u64);
    for i in params {
        put_u32(&mut p, VARIABLES[i].vr);
        put_f64s(&mut p, &s.params.values[i]);
    }
    match &s.snapshot {
        None => p.push(0),
        Some(snap) => {
            p.push(1);
            TheModel::write_snapshot(snap, &mut p);
        }
    }
    p
}

pub fn decode(bytes: &[u8]) -> Result<FmuState, String> {
    if bytes.is_empty() {
        return Err("the serialized state is empty".into());
    }
    if bytes.len() < HEADER + TRAILER {
        return Err(format!("{} bytes is too short for a serialized state", bytes.len()));
    }
    if &bytes[..8] != MAGIC {
        return Err("not a serialized state of this FMU (bad magic)".into());
    }
    let version = u32::from_le_bytes(bytes[8..12].try_into().unwrap());
    if version < OLDEST {
        return Err(format!("serialized state format {version} was written by an older version of this FMU; this version reads formats {OLDEST} to {VERSION}"));
    }
    if version > VERSION {
        return Err(format!("serialized state format {version}, this FMU reads formats {OLDEST} to {VERSION}"));
    }
    let fp = u64::from_le_bytes(bytes[12..20].try_into().unwrap());
    // Formats after the newest variable's share the current layout.
    let layout = OLDER_LAYOUT_FINGERPRINTS.iter().find(|(f, _)| *f == version).map_or(LAYOUT_FINGERPRINT, |(_, l)| *l);
    if layout != fp {
        return Err("serialized state of a different model description".into());
    }
    let len = u64::from_le_bytes(bytes[20..28].try_into().unwrap());
    if len != (bytes.len() - HEADER - TRAILER) as u64 {
        return Err(format!("payload length {len} does not match the {} bytes given (truncated or extended)", bytes.len()));
    }
    let (body, tail) = bytes.split_at(bytes.len() - TRAILER);
    if checksum(body) != u32::from_le_bytes(tail.try_into().unwrap()) {
        return Err("CRC-32 mismatch: the serialized state is corrupted".into());
    }
    let mut r = Reader::new(&body[HEADER..]);
    let mode = Mode::from_u8(r.u8()?).ok_or("bad mode")?;
    let start_time = r.f64()?;
    if !start_time.is_finite() {
        return Err("start time is not finite".into());
    }
    let stop_time = match r.u8()? {
        0 => None,
        1 => {
            let t = r.f64()?;
            if t.is_nan() || t < start_time {
                return Err(format!("stop time {t} is before the start time {start_time}"));
            }
            Some(t)
        }
        _ => return Err("bad stop time flag".into()),
    };
    let mut params = Params { values: vec![Vec::new(); VARIABLES.len()] };
    let n = r.u64()?;
    let mut seen = vec![false; VARIABLES.len()];
    for _ in 0..n {
        let vr = r.u32()?;
        let i = index_of(vr).filter(|&i| VARIABLES[i].holds_value()).ok_or(format!("value reference {vr} is not a parameter or input"))?;
        if std::mem::replace(&mut seen[i], true) {
            return Err(format!("{} appears twice", VARIABLES[i].name));
        }
        params.values[i] = r.f64s()?;
    }
    for (i, v) in VARIABLES.iter().enumerate() {
        if v.holds_value() {
            if !seen[i] {
                if SINCE_FORMAT.iter().any(|&(vr, f)| vr == v.vr && f > version) {
                    // Sized below, once the structural parameters are known.
                    params.values[i] = v.start.get(..1).unwrap_or(&[0.0]).to_vec();
                    continue;
                }
                return Err(format!("{} is missing", v.name));
            }
            // Array sizes are checked below, once the structural parameters are known.
            if v.dims.is_empty() && params.values[i].len() != 1 {
                return Err(format!("{} holds {} values, expected 1", v.name, params.values[i].len()));
            }
            for x in &params.values[i] {
                check_value(v, Some(*x)).map_err(|m| format!("{} = {x}: {m}", v.name))?;
            }
        }
    }
    for (i, v) in VARIABLES.iter().enumerate() {
        let want = if v.holds_value() { params.size_of(v) } else { 0 };
        if !seen[i] && v.holds_value() && !v.dims.is_empty() {
            let fill = params.values[i][0];
            params.values[i] = vec![fill; want];
        }
        if params.values[i].len() != want {
            return Err(format!("{} holds {} values, expected {want}", v.name, params.values[i].len()));
        }
    }
    let snapshot = match r.u8()? {
        0 => None,
        1 => Some(TheModel::read_snapshot(&mut r, version)?),
        _ => return Err("bad snapshot flag".into()),
    };
    if !r.is_done() {
        return Err(format!("{} unexpected bytes at the end", r.remaining()));
    }
    if matches!(mode, Mode::StepMode | Mode::Terminated) && snapshot.is_none() {
        return Err("a state after initialization must hold the simulator state".into());
    }
    if let Some(s) = &snapshot {
        TheModel::check_snapshot(s, &params)?;
    }
    if matches!(mode, Mode::Instantiated | Mode::ConfigurationMode) && stop_time.is_some() {
        return Err("a state before initialization has no stop time".into());
    }
    Ok(FmuState::new(mode, start_time, stop_time, params, snapshot))
}
