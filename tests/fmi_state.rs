//! The FMU state through the fmi3 C functions: get, set, free, serialize
//! and deserialize, a state resumed in a second instance, states kept to
//! their instance, and every corrupted or foreign blob refused with the
//! instance unchanged.

use std::ptr::null_mut;

use fmi_sys::fmi3::*;
use modal_mass_spring::fmi::exports::*;
use modal_mass_spring::fmi::variables::vr;

use crate::common;
use common::*;

#[test]
fn fmu_state_round_trip() {
    let f = Fmu::started();
    f.run(10, 0.01);
    let st = f.get_state();
    f.run(10, 0.01);
    let a = f.positions();
    assert_eq!(unsafe { fmi3SetFMUState(f.inst, st) }, OK);
    assert!((f.time() - 0.1).abs() < 1e-12);
    f.run(10, 0.01);
    assert_eq!(bits(&f.positions()), bits(&a));

    // The state holds tunables too.
    assert_eq!(f.set_f64(vr::GRAVITY, &[1.0, 0.0, 0.0]), OK);
    assert_eq!(unsafe { fmi3SetFMUState(f.inst, st) }, OK);
    assert_eq!(f.get_f64(vr::GRAVITY, 3).1, vec![0.0, -9.81, 0.0]);

    // Overwriting an existing state in place, then freeing.
    let mut st2 = st;
    assert_eq!(unsafe { fmi3GetFMUState(f.inst, &mut st2) }, OK);
    assert_eq!(st2, st);
    assert_eq!(unsafe { fmi3FreeFMUState(f.inst, &mut st2) }, OK);
    assert!(st2.is_null());
    assert_eq!(unsafe { fmi3FreeFMUState(f.inst, &mut st2) }, OK, "freeing NULL is fine");
    f.expect_error(unsafe { fmi3SetFMUState(f.inst, null_mut()) }, "null state");
}

#[test]
fn serialized_state_resumes_in_a_second_instance() {
    let f = Fmu::started();
    assert_eq!(f.set_f64(vr::DAMPING_BETA, &[0.001]), OK);
    f.run(7, 0.01);
    let st = f.get_state();
    let blob = f.serialize(st);
    f.run(13, 0.01);
    let a = f.positions();

    let g = Fmu::new(); // Instantiated: the state carries its mode.
    let (s, st2) = g.deserialize(&blob);
    assert_eq!(s, OK, "{:?}", g.messages());
    assert_eq!(unsafe { fmi3SetFMUState(g.inst, st2) }, OK, "{:?}", g.messages());
    assert_eq!(g.get_f64(vr::DAMPING_BETA, 1).1, vec![0.001]);
    g.run(13, 0.01);
    assert_eq!(bits(&g.positions()), bits(&a));
    // Serializing the deserialized state gives the same bytes.
    assert_eq!(g.serialize(st2), blob);
}

#[test]
fn corrupted_or_foreign_blobs_are_refused() {
    let f = Fmu::started();
    f.run(3, 0.01);
    let st = f.get_state();
    let blob = f.serialize(st);
    let mut n = 0usize;
    assert_eq!(unsafe { fmi3SerializedFMUStateSize(f.inst, st, &mut n) }, OK);
    let mut short = vec![0u8; n - 1];
    f.expect_error(unsafe { fmi3SerializeFMUState(f.inst, st, short.as_mut_ptr(), n - 1) }, "buffer size");

    for i in [0, 9, 15, 25, 40, blob.len() / 2, blob.len() - 1] {
        let mut bad = blob.clone();
        bad[i] ^= 0x10;
        let (s, p) = f.deserialize(&bad);
        f.expect_error(s, &format!("flipped byte {i}"));
        assert!(p.is_null());
    }
    f.expect_error(f.deserialize(&blob[..blob.len() - 8]).0, "truncated");
    f.expect_error(f.deserialize(&[]).0, "empty");
    let mut longer = blob.clone();
    longer.push(0);
    f.expect_error(f.deserialize(&longer).0, "trailing byte");

    // A blob from an instance with another structure.
    let g = Fmu::new();
    assert_eq!(g.set_u64(vr::NX, 4), OK);
    let gst = g.get_state();
    let other = g.serialize(gst);
    f.expect_error(f.deserialize(&other).0, "different nx");

    // The instance is unchanged by all this.
    let t = f.time();
    f.run(1, 0.01);
    assert!(f.time() > t);
}

#[test]
fn fmu_states_belong_to_their_instance() {
    let a = Fmu::started();
    let b = Fmu::started();
    a.run(2, 0.01);
    let sa = a.get_state();
    let before = b.snapshot();
    unsafe {
        b.expect_error(fmi3SetFMUState(b.inst, sa), "a state of another instance");
        let mut n = 0;
        b.expect_error(fmi3SerializedFMUStateSize(b.inst, sa, &mut n), "size of another instance's state");
        let mut foreign = sa;
        b.expect_error(fmi3FreeFMUState(b.inst, &mut foreign), "freeing another instance's state");
        b.expect_error(fmi3GetFMUState(b.inst, &mut foreign), "overwriting another instance's state");
        assert_eq!(foreign, sa);
        // A copy of a freed state pointer is refused, not dereferenced.
        let mut copy = sa;
        a.free_state(sa);
        a.expect_error(fmi3SetFMUState(a.inst, copy), "a freed state");
        a.expect_error(fmi3FreeFMUState(a.inst, &mut copy), "freeing twice");
        let mut junk = [0u64; 16];
        a.expect_error(fmi3SetFMUState(a.inst, junk.as_mut_ptr() as fmi3FMUState), "a pointer that is no state");
    }
    assert_eq!(b.snapshot(), before);
    // States left at fmi3FreeInstance are freed with it (checked for leaks under valgrind).
    let _left = a.get_state();
}

/// The instance state and outputs before and after a refused deserialization.
fn refused_unchanged(f: &Fmu, blob: &[u8], what: &str) {
    let (state, outputs) = (f.snapshot(), f.outputs());
    let (s, p) = f.deserialize(blob);
    f.expect_error(s, what);
    assert!(p.is_null(), "{what}");
    assert_eq!(f.snapshot(), state, "{what}");
    assert_eq!(f.outputs(), outputs, "{what}");
}

#[test]
fn every_corruption_of_a_serialized_state_is_refused() {
    use modal_mass_spring::fmi::serialize::{checksum, decode, payload, seal, HEADER, TRAILER};
    let f = Fmu::started();
    f.run(3, 0.01);
    let blob = f.snapshot();
    f.run(2, 0.01); // the instance is elsewhere than the blob
    assert!(decode(&blob).is_ok());

    // Every bit flipped, every truncation, an extension, nothing at all.
    for i in 0..blob.len() {
        for bit in 0..8 {
            let mut bad = blob.clone();
            bad[i] ^= 1 << bit;
            assert!(decode(&bad).is_err(), "bit {bit} of byte {i}");
        }
    }
    for len in 0..blob.len() {
        assert!(decode(&blob[..len]).is_err(), "truncated to {len}");
    }
    // The same through the C function, with the instance compared after each.
    for (what, bad) in [
        ("empty", vec![]),
        ("truncated", blob[..blob.len() - 1].to_vec()),
        ("header only", blob[..HEADER].to_vec()),
        ("one byte more", [blob.clone(), vec![0]].concat()),
        ("flipped byte in the payload", {
            let mut b = blob.clone();
            b[HEADER + 3] ^= 0x40;
            b
        }),
        ("flipped checksum", {
            let mut b = blob.clone();
            let n = b.len();
            b[n - 1] ^= 1;
            b
        }),
        ("zeros", vec![0; blob.len()]),
    ] {
        refused_unchanged(&f, &bad, what);
    }

    // Valid checksums over a wrong header: version, layout fingerprint, magic.
    let resealed = |edit: &dyn Fn(&mut Vec<u8>)| {
        let mut b = blob[..blob.len() - TRAILER].to_vec();
        edit(&mut b);
        let sum = checksum(&b);
        b.extend_from_slice(&sum.to_le_bytes());
        b
    };
    refused_unchanged(&f, &resealed(&|b| b[8] = 1), "format version 1");
    // Format 2 held the simulator state as one concatenated array: a state
    // of the FMU's previous version is refused, saying so.
    let older = resealed(&|b| b[8..12].copy_from_slice(&2u32.to_le_bytes()));
    let (s, _) = f.deserialize(&older);
    assert_eq!(s, ERROR);
    let logged = f.log.take();
    assert!(logged.last().is_some_and(|(_, _, m)| m.contains("format 2 was written by an older version")), "{logged:?}");
    refused_unchanged(&f, &older, "format version 2");
    refused_unchanged(&f, &resealed(&|b| b[8..12].copy_from_slice(&99u32.to_le_bytes())), "format version 99");
    refused_unchanged(&f, &resealed(&|b| b[12] ^= 1), "another variable layout");
    refused_unchanged(&f, &resealed(&|b| b[0] = b'X'), "another magic");

    // Valid checksums over payloads a corrupted or hostile writer could make.
    let good = decode(&blob).unwrap();
    let mut p = payload(&good);
    assert_eq!(seal(&p), blob);
    p[0] = 9;
    refused_unchanged(&f, &seal(&p), "mode 9");
    let edit = |change: &dyn Fn(&mut modal_mass_spring::fmi::fmu_state::FmuState)| {
        let mut s = good.clone();
        change(&mut s);
        seal(&payload(&s))
    };
    let idx = |r: u32| modal_mass_spring::fmi::variables::index_of(r).unwrap();
    refused_unchanged(&f, &edit(&|s| s.start_time = f64::NAN), "NaN start time");
    refused_unchanged(&f, &edit(&|s| s.stop_time = Some(-1.0)), "stop time before start");
    refused_unchanged(&f, &edit(&|s| s.params.values[idx(vr::SPACING)][0] = -0.1), "negative spacing");
    refused_unchanged(&f, &edit(&|s| s.params.values[idx(vr::NODE_MASS)][0] = f64::INFINITY), "infinite mass");
    refused_unchanged(&f, &edit(&|s| s.params.values[idx(vr::FIXED_NODES)][0] = 7.0), "enumeration value 7");
    refused_unchanged(&f, &edit(&|s| s.params.values[idx(vr::GRAVITY)].push(0.0)), "four gravity values");
    refused_unchanged(&f, &edit(&|s| s.params.values[idx(vr::MODE_WEIGHTS)].pop().map(|_| ()).unwrap()), "one weight for two modes");
    refused_unchanged(&f, &edit(&|s| s.params.values[idx(vr::NX)][0] = 11.0), "another grid");
    refused_unchanged(&f, &edit(&|s| s.snapshot = None), "Step Mode without simulator state");
    refused_unchanged(&f, &edit(&|s| s.snapshot.as_mut().unwrap().state.y[0] = f64::NAN), "NaN in the simulator state");
    refused_unchanged(&f, &edit(&|s| s.snapshot.as_mut().unwrap().state.time = -1.0), "negative simulator time");
    refused_unchanged(&f, &edit(&|s| s.snapshot.as_mut().unwrap().loads.damping_alpha = 3.0), "loads that differ from the parameters");
    refused_unchanged(&f, &edit(&|s| s.snapshot.as_mut().unwrap().state.v.push(0.0)), "velocities longer than the coordinates");
    let mut extra = payload(&good);
    extra.push(0);
    refused_unchanged(&f, &seal(&extra), "a byte after the payload");

    // Decodable, but refused when made current: the instance stays as it was.
    for (what, bad) in [
        (
            "a simulator state of the wrong length",
            edit(&|s| {
                let st = &mut s.snapshot.as_mut().unwrap().state;
                [&mut st.y, &mut st.v, &mut st.a].into_iter().for_each(|x| x.push(0.0));
            }),
        ),
        ("positions that overflow the energies", edit(&|s| s.snapshot.as_mut().unwrap().state.y[0] = 1e300)),
    ] {
        let (state, outputs) = (f.snapshot(), f.outputs());
        let (s, p) = f.deserialize(&bad);
        assert_eq!(s, OK, "{what}: {:?}", f.messages());
        f.expect_error(unsafe { fmi3SetFMUState(f.inst, p) }, what);
        assert_eq!(f.snapshot(), state, "{what}");
        assert_eq!(f.outputs(), outputs, "{what}");
        f.free_state(p);
    }

    // After all of it the instance steps on exactly like an untouched twin.
    let twin = Fmu::started();
    twin.run(5, 0.01);
    f.run(5, 0.01);
    twin.run(5, 0.01);
    assert_eq!(f.outputs(), twin.outputs());
}
