//! The simulator's part of a serialized FMU state (the payload's tail in
//! [`crate::fmi::serialize`]): time, y, y', y'', the anchor and its rate,
//! the holder's orientation and spin, then (format 6) per holder 2 to 4
//! its displacement, velocity, rotation vector and spin; then the loads:
//! gravity, point load, load node, anchor and holder targets, (format 6)
//! per holder 2 to 4 its displacement and rotation targets, damping,
//! weights, (format 11) the error tolerance in effect (NaN: the one set
//! up); then (format 8) whether an adaptive part follows and the part:
//! the mode, e, e', e'' of the error model, the estimate's sums, counts and
//! schedule, the stretch's counters, its poses, the grown vectors and where
//! the error model was last linearized; (format 10) the unseen residual's
//! share at the last check, among the estimate's sums; (format 11) after
//! the mode, whether the error's place holds the state of the twin that
//! goes on beside the run in full space (its y, y', y'') instead of e.
//! Format 5 has no holders 2 to 4: they are at rest.

use crate::bytes::{put_f64, put_f64s, put_u64, put_u8, Reader};
use crate::physics::{AdaptivePart, Loads, Motion, Pose, Snapshot, State, OTHER_HOLDERS};

pub fn write(snap: &Snapshot, p: &mut Vec<u8>) {
    let s = &snap.state;
    put_f64(p, s.time);
    put_f64s(p, &s.y);
    put_f64s(p, &s.v);
    put_f64s(p, &s.a);
    s.anchor.iter().chain(&s.anchor_rate).chain(&s.rotation).chain(&s.spin).for_each(|x| put_f64(p, *x));
    for m in &s.holders {
        m.anchor.iter().chain(&m.anchor_rate).chain(&m.rotation).chain(&m.spin).for_each(|x| put_f64(p, *x));
    }
    let l = &snap.loads;
    l.gravity.iter().for_each(|g| put_f64(p, *g));
    l.point_load.iter().for_each(|f| put_f64(p, *f));
    put_u64(p, l.load_node.map_or(u64::MAX, |n| n as u64));
    l.anchor.iter().chain(&l.rotation).for_each(|a| put_f64(p, *a));
    for h in &l.holders {
        h.anchor.iter().chain(&h.rotation).for_each(|a| put_f64(p, *a));
    }
    put_f64(p, l.damping_alpha);
    put_f64(p, l.damping_beta);
    put_f64s(p, &l.mode_weights);
    // Format 11: the error tolerance in effect (NaN: the one set up).
    put_f64(p, l.error_tolerance.unwrap_or(f64::NAN));
    let Some(a) = &snap.adaptive else {
        put_u8(p, 0);
        return;
    };
    put_u8(p, 1);
    put_u8(p, u8::from(a.in_full));
    put_u8(p, u8::from(a.twin));
    a.error.iter().for_each(|e| put_f64s(p, e));
    a.sums.iter().for_each(|x| put_f64(p, *x));
    a.counts.iter().chain(&a.stretch).for_each(|c| put_u64(p, *c));
    for list in [&a.seen, &a.grown] {
        put_u64(p, list.len() as u64);
        list.iter().for_each(|v| put_f64s(p, v));
    }
    put_f64s(p, &a.linearized);
}

/// A count of vectors, each at least 8 bytes long in what is left.
fn vectors(r: &mut Reader) -> Result<Vec<Vec<f64>>, String> {
    let count = r.u64()?;
    if count > (r.remaining() / 8) as u64 {
        return Err(format!("the adaptive part claims {count} vectors, more than the state holds"));
    }
    (0..count).map(|_| r.f64s().map_err(String::from)).collect()
}

fn adaptive_part(r: &mut Reader, format: u32) -> Result<Option<Box<AdaptivePart>>, String> {
    match r.u8()? {
        0 => return Ok(None),
        1 => {}
        f => return Err(format!("the adaptive part's flag is {f}, not 0 or 1")),
    }
    let in_full = match r.u8()? {
        0 => false,
        1 => true,
        m => return Err(format!("the adaptive run's mode is {m}, not 0 or 1")),
    };
    // Format 11 says whether the error's place holds the twin's state.
    let twin = match if format >= 11 { r.u8()? } else { 0 } {
        0 => false,
        1 => true,
        t => return Err(format!("the adaptive part's twin flag is {t}, not 0 or 1")),
    };
    let error = [r.f64s()?, r.f64s()?, r.f64s()?];
    // Format 10 adds the unseen share of the last check (0 before: none measured).
    let mut sums = [0.0; 6];
    for x in sums.iter_mut().take(if format >= 10 { 6 } else { 5 }) {
        *x = r.f64()?;
    }
    let (mut counts, mut stretch) = ([0; 5], [0; 3]);
    for c in counts.iter_mut().chain(&mut stretch) {
        *c = r.u64()?;
    }
    let (seen, grown, linearized) = (vectors(r)?, vectors(r)?, r.f64s()?);
    Ok(Some(Box::new(AdaptivePart { in_full, twin, error, sums, counts, stretch, seen, grown, linearized })))
}

fn vector(r: &mut Reader) -> Result<[f64; 3], String> {
    Ok([r.f64()?, r.f64()?, r.f64()?])
}

pub fn read(r: &mut Reader, format: u32) -> Result<Snapshot, String> {
    let holders = format >= 6;
    let (time, y, v, a) = (r.f64()?, r.f64s()?, r.f64s()?, r.f64s()?);
    let (anchor, anchor_rate, rotation, spin) = (vector(r)?, vector(r)?, vector(r)?, vector(r)?);
    let mut motions = [Motion::default(); OTHER_HOLDERS];
    if holders {
        for m in &mut motions {
            *m = Motion { anchor: vector(r)?, anchor_rate: vector(r)?, rotation: vector(r)?, spin: vector(r)? };
        }
    }
    let state = State { time, y, v, a, anchor, anchor_rate, rotation, spin, holders: motions };
    let gravity = vector(r)?;
    let point_load = vector(r)?;
    let load_node = match r.u64()? {
        u64::MAX => None,
        n => Some(usize::try_from(n).map_err(|_| "load node out of range".to_string())?),
    };
    let (anchor, rotation) = (vector(r)?, vector(r)?);
    let mut poses = [Pose::default(); OTHER_HOLDERS];
    if holders {
        for p in &mut poses {
            *p = Pose { anchor: vector(r)?, rotation: vector(r)? };
        }
    }
    if !anchor.iter().chain(&rotation).chain(poses.iter().flat_map(|p| p.anchor.iter().chain(&p.rotation))).all(|a| a.is_finite()) {
        return Err("a holder's target holds non-finite values".into());
    }
    let damping_alpha = r.f64()?;
    let damping_beta = r.f64()?;
    let mode_weights = r.f64s()?;
    let error_tolerance = if format >= 11 { Some(r.f64()?).filter(|t| !t.is_nan()) } else { None };
    if !(state.is_finite() && state.time >= 0.0) {
        return Err("the simulator state holds a negative or non-finite time or non-finite values".into());
    }
    if state.v.len() != state.y.len() || state.a.len() != state.y.len() {
        return Err(format!("the simulator state holds arrays of {}, {} and {} values", state.y.len(), state.v.len(), state.a.len()));
    }
    let loads = Loads { gravity, point_load, load_node, anchor, rotation, holders: poses, damping_alpha, damping_beta, mode_weights, error_tolerance };
    let adaptive = if format >= 8 { adaptive_part(r, format)? } else { None };
    Ok(Snapshot { state, loads, adaptive })
}
