//! Instantiate / configure / step / get, serialize, deserialize and set the
//! state / free, many times over, through the C functions, including the
//! refused calls and the states left for fmi3FreeInstance to free. Run under
//! valgrind by `cargo xtask valgrind` (part of `cargo xtask test`), where
//! any leak or invalid access fails the run.
//!
//! `cargo run --example fmi_cycles [CYCLES]`

use std::ffi::{c_void, CString};
use std::ptr::{null, null_mut};

use fmi_sys::fmi3::*;
use modal_mass_spring::fmi::exports::*;
use modal_mass_spring::fmi::variables::{vr, INSTANTIATION_TOKEN};

const OK: fmi3Status = fmi3Status_fmi3OK;
const WARNING: fmi3Status = fmi3Status_fmi3Warning;
const DISCARD: fmi3Status = fmi3Status_fmi3Discard;
const ERROR: fmi3Status = fmi3Status_fmi3Error;

unsafe extern "C" fn logger(env: fmi3InstanceEnvironment, status: fmi3Status, _: fmi3String, _: fmi3String) {
    let counts = &mut *(env as *mut [usize; 5]);
    counts[status as usize] += 1;
}

fn check(what: &str, got: fmi3Status, want: fmi3Status) {
    if got != want {
        eprintln!("fmi_cycles: {what}: status {got}, expected {want}");
        std::process::exit(2);
    }
}

/// A communication step; fmi3Warning (the first step past forceResidualLimit,
/// as when one mode holds none of the load) counts as done, like fmi3OK.
unsafe fn step(inst: fmi3Instance, t: f64, h: f64) -> fmi3Status {
    let (mut a, mut b, mut c, mut last) = (false, false, false, 0.0);
    match fmi3DoStep(inst, t, h, false, &mut a, &mut b, &mut c, &mut last) {
        WARNING => OK,
        s => s,
    }
}

unsafe fn cycle(i: usize, counts: &mut [usize; 5]) {
    let env = counts as *mut [usize; 5] as *mut c_void;
    let name = CString::new(format!("cycle {i}")).unwrap();
    let token = CString::new(INSTANTIATION_TOKEN).unwrap();
    let wrong = CString::new("{wrong}").unwrap();
    let refused = fmi3InstantiateCoSimulation(name.as_ptr(), wrong.as_ptr(), null(), false, false, false, false, null(), 0, env, Some(logger), None);
    assert!(refused.is_null());
    let inst = fmi3InstantiateCoSimulation(name.as_ptr(), token.as_ptr(), null(), false, true, false, false, null(), 0, env, Some(logger), None);
    assert!(!inst.is_null());

    // A different set-up each cycle: grid, modes, reduction, integrator.
    check("enter configuration", fmi3EnterConfigurationMode(inst), OK);
    let (nx, modes) = (4 + (i % 4) as u64, 1 + (i % 3) as u64);
    check("nx", fmi3SetUInt64(inst, &vr::NX, 1, &nx, 1), OK);
    check("ny", fmi3SetUInt64(inst, &vr::NY, 1, &5, 1), OK);
    check("nModes", fmi3SetUInt64(inst, &vr::N_MODES, 1, &modes, 1), OK);
    check("exit configuration", fmi3ExitConfigurationMode(inst), OK);
    check("reduction", fmi3SetInt64(inst, &vr::REDUCTION, 1, &(1 + (i % 2) as i64), 1), OK);
    check("integrator", fmi3SetInt64(inst, &vr::INTEGRATOR, 1, &(1 + (i / 2 % 2) as i64), 1), OK);
    check("NaN refused", fmi3SetFloat64(inst, &vr::DAMPING_ALPHA, 1, &f64::NAN, 1), ERROR);
    check("enter initialization", fmi3EnterInitializationMode(inst, false, 0.0, 0.0, true, 10.0), OK);
    check("exit initialization", fmi3ExitInitializationMode(inst), OK);

    let mut t = 0.0;
    for _ in 0..10 {
        check("step", step(inst, t, 0.01), OK);
        t += 0.01;
    }
    check("wrong communication point", step(inst, t + 1.0, 0.01), ERROR);
    let mut x = vec![0.0; (nx * 5 * 2) as usize];
    check("positions", fmi3GetFloat64(inst, &vr::POSITIONS, 1, x.as_mut_ptr(), x.len()), OK);
    check("wrong nValues", fmi3GetFloat64(inst, &vr::POSITIONS, 1, x.as_mut_ptr(), x.len() - 1), ERROR);

    // FMU state: get, serialize, deserialize (good and corrupted), set, free.
    let mut st = null_mut();
    check("get state", fmi3GetFMUState(inst, &mut st), OK);
    check("overwrite state", fmi3GetFMUState(inst, &mut st), OK);
    let mut n = 0;
    check("state size", fmi3SerializedFMUStateSize(inst, st, &mut n), OK);
    let mut blob = vec![0u8; n];
    check("serialize", fmi3SerializeFMUState(inst, st, blob.as_mut_ptr(), n), OK);
    let mut back = null_mut();
    check("deserialize", fmi3DeserializeFMUState(inst, blob.as_ptr(), n, &mut back), OK);
    blob[n / 2] ^= 0x55;
    let mut bad = null_mut();
    check("corrupted blob", fmi3DeserializeFMUState(inst, blob.as_ptr(), n, &mut bad), ERROR);
    check("empty blob", fmi3DeserializeFMUState(inst, blob.as_ptr(), 0, &mut bad), ERROR);
    for _ in 0..5 {
        check("step", step(inst, t, 0.01), OK);
        t += 0.01;
    }
    check("set state", fmi3SetFMUState(inst, back), OK);
    t = 0.1;
    check("step after set state", step(inst, t, 0.01), OK);
    t += 0.01;
    check("free state", fmi3FreeFMUState(inst, &mut back), OK);
    // `st` is left to fmi3FreeInstance on odd cycles.
    if i % 2 == 0 {
        check("free state", fmi3FreeFMUState(inst, &mut st), OK);
    }

    // A step that is refused, then terminate, reset and run again.
    check("max internal step", fmi3SetFloat64(inst, &vr::MAX_INTERNAL_STEP, 1, &1e-9, 1), ERROR);
    check("past stop time", step(inst, t, 100.0), ERROR);
    check("terminate", fmi3Terminate(inst), OK);
    check("step after terminate", step(inst, t, 0.01), ERROR);
    check("reset", fmi3Reset(inst), OK);
    check("max internal step", fmi3SetFloat64(inst, &vr::MAX_INTERNAL_STEP, 1, &1e-9, 1), OK);
    check("enter initialization", fmi3EnterInitializationMode(inst, false, 0.0, 0.0, false, 0.0), OK);
    check("exit initialization", fmi3ExitInitializationMode(inst), OK);
    check("too many internal steps", step(inst, 0.0, 1.0), DISCARD);
    fmi3FreeInstance(inst);
    check("call after free", fmi3Reset(inst), ERROR);
}

fn parse_args() -> Result<usize, lexopt::Error> {
    use lexopt::prelude::*;
    let mut cycles = None;
    let mut parser = lexopt::Parser::from_env();
    while let Some(arg) = parser.next()? {
        match arg {
            Value(v) if cycles.is_none() => cycles = Some(v.parse()?),
            _ => return Err(arg.unexpected()),
        }
    }
    Ok(cycles.unwrap_or(16))
}

fn main() {
    let cycles = parse_args().unwrap_or_else(|e| {
        eprintln!("fmi_cycles: {e}\nusage: fmi_cycles [CYCLES]");
        std::process::exit(2)
    });
    let mut counts = [0usize; 5];
    for i in 0..cycles {
        unsafe { cycle(i, &mut counts) };
    }
    println!("fmi_cycles: {cycles} cycles; messages logged: {} ok, {} discard, {} error", counts[0], counts[2], counts[3]);
}
