//! Random call sequences through the C functions: the input bytes are read
//! as operations on two instance slots (instantiate with good and bad
//! arguments, modes, steps with random times, Get/Set with random value
//! references, nValues and values including NaN and infinities, FMU states,
//! serialization, reset, terminate, free, and calls on freed pointers).
//!
//! Every call on a live instance goes through `checked` (no fmi3Fatal, a
//! refusal is logged and changes nothing); a successful step and every
//! successful read give finite values. Values come from tables that include
//! the extremes but no combination that makes one legitimate call run for
//! long (a step is at most 0.1 s, stiffness / mass at most 1e6 unless it is
//! so extreme that the step is refused outright).

#![no_main]

use std::ffi::CString;
use std::ptr::{null, null_mut};

use libfuzzer_sys::fuzz_target;
use modal_mass_spring_fuzz::*;

struct Input<'a>(&'a [u8]);

impl Input<'_> {
    fn byte(&mut self) -> Option<u8> {
        let (&b, rest) = self.0.split_first()?;
        self.0 = rest;
        Some(b)
    }
    fn pick<T: Copy>(&mut self, table: &[T]) -> Option<T> {
        Some(table[self.byte()? as usize % table.len()])
    }
    fn flag(&mut self) -> Option<bool> {
        Some(self.byte()? & 1 == 1)
    }
}

const F64: &[f64] = &[
    0.0,
    -0.0,
    1.0,
    -1.0,
    0.5,
    2.0,
    0.01,
    0.05,
    0.1,
    50.0,
    1e3,
    1e-3,
    -9.81,
    1e-300,
    1e300,
    f64::MIN_POSITIVE,
    5e-324,
    f64::MAX,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
];
const GRID: &[u64] = &[0, 1, 2, 3, 4, 6, 10, 1001, 1 << 53, u64::MAX];
const DIMENSION: &[u64] = &[0, 1, 2, 3, 4];
const MODES: &[u64] = &[0, 1, 2, 3, 5, 12, 40, 200, 3_000_001];
const ENUM: &[i64] = &[0, 1, 2, 3, -1, i64::MAX, i64::MIN];
const BOOL: &[u8] = &[0, 1, 2, 255];
const STEP: &[f64] = &[0.001, 0.01, 0.0173, 0.05, 0.1, 0.0, -0.01, f64::NAN, f64::INFINITY, 5e-324, 1e300];
const START: &[f64] = &[0.0, 1.5, -2.0, f64::NAN, f64::INFINITY];

struct Slot {
    env: Box<Env>,
    inst: fmi3Instance,
    states: Vec<fmi3FMUState>,
}

#[derive(Default)]
struct World {
    slots: [Option<Slot>; 2],
    /// Pointers of freed instances and of states freed with them.
    stale: Vec<fmi3Instance>,
    stale_states: Vec<fmi3FMUState>,
    blobs: Vec<Vec<u8>>,
}

impl World {
    fn live(&self, p: usize) -> bool {
        self.slots.iter().flatten().any(|s| s.inst as usize == p || s.states.iter().any(|&t| t as usize == p))
    }
}

fn value_reference(input: &mut Input) -> Option<u32> {
    let vars = &model().variables;
    let i = input.byte()? as usize;
    Some(match vars.get(i % (vars.len() + 3)) {
        Some(v) => v.vr,
        None => [5, 999, u32::MAX][i % 3],
    })
}

/// nValues for a call: mostly right, sometimes off.
fn count(input: &mut Input, right: usize) -> Option<usize> {
    Some(match input.byte()? % 8 {
        0 => right + 1,
        1 => right.saturating_sub(1),
        2 => 0,
        _ => right,
    })
}

fn op(w: &mut World, input: &mut Input) -> Option<()> {
    let f = fmi();
    let which = input.byte()? as usize % 2;
    let code = input.byte()? % 23;
    LAST.with(|l| l.set((which, code, OK)));
    if code == 0 {
        // Instantiate: good or bad name and token.
        if w.slots[which].is_some() {
            return Some(());
        }
        let name_ok = input.byte()? % 4;
        let token_ok = input.byte()? % 3;
        let env = Box::<Env>::default();
        let good = CString::new(model().instantiation_token.as_str()).unwrap();
        let wrong = CString::new("{00000000-0000-0000-0000-000000000000}").unwrap();
        let names = [CString::new("fuzz").unwrap(), CString::new("").unwrap(), CString::new(" ").unwrap()];
        let name = if name_ok == 3 { null() } else { names[name_ok as usize].as_ptr() };
        let token = [good.as_ptr(), wrong.as_ptr(), null()][token_ok as usize];
        let inst = unsafe { f.fmi3InstantiateCoSimulation(name, token, null(), false, input.flag()?, false, false, null(), 0, env.ptr(), Some(logger), None) };
        if name_ok == 0 && token_ok == 0 {
            assert!(!inst.is_null(), "valid instantiation refused");
            w.slots[which] = Some(Slot { env, inst, states: Vec::new() });
        } else {
            assert!(inst.is_null(), "invalid instantiation accepted");
            assert!(env.count(ERROR) == 1, "refused instantiation not logged");
        }
        return Some(());
    }
    if code == 1 {
        // A call on a freed pointer: refused (unless the address came back as a live one).
        if let Some(&p) = w.stale.get(input.byte()? as usize % w.stale.len().max(1)) {
            if !w.live(p as usize) {
                let s = unsafe {
                    match input.byte()? % 4 {
                        0 => f.fmi3Reset(p),
                        1 => f.fmi3DoStep(p, 0.0, 0.01, false, &mut false, &mut false, &mut false, &mut 0.0),
                        2 => f.fmi3GetFloat64(p, &vr("time"), 1, &mut 0.0, 1),
                        _ => {
                            f.fmi3FreeInstance(p);
                            ERROR
                        }
                    }
                };
                assert_eq!(s, ERROR, "a call on a freed instance was not refused");
            }
        }
        return Some(());
    }
    let Some(slot) = w.slots[which].as_mut() else { return Some(()) };
    let inst = slot.inst;
    // SAFETY: the Env is boxed and lives as long as the slot, which is only
    // dropped (operation 2) after its last use here.
    let env: &Env = unsafe { &*(&*slot.env as *const Env) };
    let check = |what: &str, call: &mut dyn FnMut() -> fmi3Status| {
        let s = checked(inst, env, what, false, call);
        LAST.with(|l| l.set((which, code, s)));
        s
    };
    match code {
        2 => {
            // Free: the instance takes its remaining states with it.
            unsafe { f.fmi3FreeInstance(inst) };
            let slot = w.slots[which].take().unwrap();
            w.stale.push(slot.inst);
            w.stale_states.extend(slot.states);
        }
        3 => {
            check("fmi3EnterConfigurationMode", &mut || unsafe { f.fmi3EnterConfigurationMode(inst) });
        }
        4 => {
            check("fmi3ExitConfigurationMode", &mut || unsafe { f.fmi3ExitConfigurationMode(inst) });
        }
        5 => {
            let start = input.pick(START)?;
            let stop_defined = input.flag()?;
            let stop = start + input.pick(&[0.05, 1.0, -1.0, f64::NAN, f64::INFINITY])?;
            check("fmi3EnterInitializationMode", &mut || unsafe { f.fmi3EnterInitializationMode(inst, false, 0.0, start, stop_defined, stop) });
        }
        6 => {
            check("fmi3ExitInitializationMode", &mut || unsafe { f.fmi3ExitInitializationMode(inst) });
        }
        7 => {
            let now = time(inst);
            let t = now + input.pick(&[0.0, 0.0, 0.0, 0.5, -0.01, 1e-12, f64::NAN])?;
            let h = input.pick(STEP)?;
            let (mut a, mut b, mut c, mut last) = (true, true, true, f64::NAN);
            let s = checked(inst, env, "fmi3DoStep", true, &mut || unsafe { f.fmi3DoStep(inst, t, h, false, &mut a, &mut b, &mut c, &mut last) });
            LAST.with(|l| l.set((which, code, s)));
            if s == OK || s == WARNING {
                assert!(!a && !b && !c);
                assert!((time(inst) - (now + h)).abs() <= 1e-9 * (now + h).abs().max(1.0), "time after the step");
                assert!(last == time(inst), "lastSuccessfulTime");
                assert!(outputs(inst).is_some(), "outputs refused after a successful step");
            }
        }
        8 => {
            check("fmi3Terminate", &mut || unsafe { f.fmi3Terminate(inst) });
        }
        9 => {
            check("fmi3Reset", &mut || unsafe { f.fmi3Reset(inst) });
        }
        10..=13 => {
            // Set one or two variables of one type.
            let n_vrs = 1 + input.byte()? as usize % 2;
            let vrs: Vec<u32> = (0..n_vrs).map(|_| value_reference(input)).collect::<Option<_>>()?;
            let right: usize = vrs.iter().map(|&r| size_of(inst, r)).sum();
            let n = count(input, right)?.min(4096);
            match code {
                10 => {
                    let x: Vec<f64> = (0..n).map(|_| input.pick(F64)).collect::<Option<_>>()?;
                    check("fmi3SetFloat64", &mut || unsafe { f.fmi3SetFloat64(inst, vrs.as_ptr(), n_vrs, x.as_ptr(), n) });
                }
                11 => {
                    let x: Vec<u64> = vrs
                        .iter()
                        .cycle()
                        .take(n)
                        .map(|&r| {
                            input.pick(if r == vr("dimension") {
                                DIMENSION
                            } else if r == vr("nModes") {
                                MODES
                            } else {
                                GRID
                            })
                        })
                        .collect::<Option<_>>()?;
                    check("fmi3SetUInt64", &mut || unsafe { f.fmi3SetUInt64(inst, vrs.as_ptr(), n_vrs, x.as_ptr(), n) });
                }
                12 => {
                    let x: Vec<i64> = (0..n).map(|_| input.pick(ENUM)).collect::<Option<_>>()?;
                    check("fmi3SetInt64", &mut || unsafe { f.fmi3SetInt64(inst, vrs.as_ptr(), n_vrs, x.as_ptr(), n) });
                }
                _ => {
                    // Any byte, as a host might pass for fmi3Boolean.
                    let x: Vec<u8> = (0..n).map(|_| input.pick(BOOL)).collect::<Option<_>>()?;
                    check("fmi3SetBoolean", &mut || unsafe { f.fmi3SetBoolean(inst, vrs.as_ptr(), n_vrs, x.as_ptr(), n) });
                }
            }
        }
        14 | 15 => {
            let r = value_reference(input)?;
            let n = count(input, size_of(inst, r))?.min(1 << 20);
            if code == 14 {
                let mut x = vec![f64::NAN; n];
                if check("fmi3GetFloat64", &mut || unsafe { f.fmi3GetFloat64(inst, &r, 1, x.as_mut_ptr(), n) }) == OK {
                    assert!(x.iter().all(|y| y.is_finite()), "non-finite value of vr {r}");
                }
            } else {
                let mut x = vec![0u64; n];
                match input.byte()? % 3 {
                    0 => check("fmi3GetUInt64", &mut || unsafe { f.fmi3GetUInt64(inst, &r, 1, x.as_mut_ptr(), n) }),
                    1 => check("fmi3GetInt64", &mut || unsafe { f.fmi3GetInt64(inst, &r, 1, x.as_mut_ptr() as *mut i64, n) }),
                    _ => check("fmi3GetBoolean", &mut || unsafe { f.fmi3GetBoolean(inst, &r, 1, x.as_mut_ptr() as *mut bool, n) }),
                };
            }
        }
        16 => {
            // Into a new state, or over one of this instance's.
            let mut st = if input.flag()? { slot.states.last().copied().unwrap_or(null_mut()) } else { null_mut() };
            let new = st.is_null();
            if check("fmi3GetFMUState", &mut || unsafe { f.fmi3GetFMUState(inst, &mut st) }) == OK && new {
                slot.states.push(st);
            }
        }
        17 | 18 | 19 => {
            // A state of this instance, of the other slot, a freed one, or NULL.
            let other = w.slots[1 - which].as_ref().map(|s| s.states.clone()).unwrap_or_default();
            let slot = w.slots[which].as_mut().unwrap();
            let k = input.byte()? as usize;
            let st = match input.byte()? % 4 {
                0 => slot.states.get(k % slot.states.len().max(1)).copied(),
                1 => other.get(k % other.len().max(1)).copied(),
                2 => w.stale_states.get(k % w.stale_states.len().max(1)).copied(),
                _ => Some(null_mut()),
            };
            let Some(mut st) = st else { return Some(()) };
            // Only a live state of this very instance is usable (a freed address may come back as one).
            let at = slot.states.iter().position(|&x| x == st);
            let was_null = st.is_null();
            let s = match code {
                17 => check("fmi3SetFMUState", &mut || unsafe { f.fmi3SetFMUState(inst, st) }),
                18 => {
                    let s = check("fmi3FreeFMUState", &mut || unsafe { f.fmi3FreeFMUState(inst, &mut st) });
                    if s == OK {
                        assert!(st.is_null());
                        if let Some(i) = at {
                            slot.states.remove(i);
                        }
                    }
                    s
                }
                _ => {
                    let mut n = 0;
                    let s = check("fmi3SerializedFMUStateSize", &mut || unsafe { f.fmi3SerializedFMUStateSize(inst, st, &mut n) });
                    if s == OK {
                        let mut b = vec![0u8; n];
                        assert_eq!(check("fmi3SerializeFMUState", &mut || unsafe { f.fmi3SerializeFMUState(inst, st, b.as_mut_ptr(), n) }), OK);
                        w.blobs.push(b);
                    }
                    s
                }
            };
            // Freeing NULL is a no-op; anything else not of this instance is refused.
            if at.is_none() {
                let expected = if code == 18 && was_null { OK } else { ERROR };
                assert_eq!(s, expected, "FMU state {st:?} that is not one of this instance");
            }
        }
        20 => {
            // Deserialize a blob seen before, possibly with one byte changed.
            let Some(mut b) = w.blobs.get(input.byte()? as usize % w.blobs.len().max(1)).cloned() else { return Some(()) };
            if input.flag()? && !b.is_empty() {
                let at = input.byte()? as usize % b.len();
                b[at] ^= input.byte()?.max(1);
            }
            let mut st = null_mut();
            if check("fmi3DeserializeFMUState", &mut || unsafe { f.fmi3DeserializeFMUState(inst, b.as_ptr(), b.len(), &mut st) }) == OK {
                slot.states.push(st);
            }
        }
        21 => {
            let known = CString::new("logAll").unwrap();
            let unknown = CString::new("logEverything").unwrap();
            let cats = [known.as_ptr(), unknown.as_ptr(), null()];
            let on = input.flag()?;
            let k = input.byte()? as usize % 4;
            let n = if k == 3 { 0 } else { 1 };
            check("fmi3SetDebugLogging", &mut || unsafe { f.fmi3SetDebugLogging(inst, on, n, cats[k % 3..].as_ptr()) });
        }
        _ => {
            // Functions of interfaces and features this FMU does not have: always refused.
            let which = input.byte()? % 4;
            let s = check("an unsupported function", &mut || unsafe {
                match which {
                    0 => f.fmi3EnterEventMode(inst),
                    1 => f.fmi3EnterStepMode(inst),
                    2 => f.fmi3GetDirectionalDerivative(inst, &vr("kineticEnergy"), 1, &vr("gravity"), 1, &1.0, 1, &mut 0.0, 1),
                    _ => f.fmi3SetTime(inst, 0.0),
                }
            });
            assert_eq!(s, ERROR);
        }
    }
    Some(())
}

thread_local! {
    /// Slot, operation and status of the last call, for the coverage feedback.
    static LAST: std::cell::Cell<(usize, u8, fmi3Status)> = const { std::cell::Cell::new((0, 0, 0)) };
}

fuzz_target!(|data: &[u8]| {
    let mut w = World::default();
    let mut input = Input(data);
    // A bounded number of operations keeps one input short.
    for _ in 0..64 {
        if op(&mut w, &mut input).is_none() {
            break;
        }
        // Feedback: (operation, status, state afterwards).
        let (which, code, status) = LAST.with(|l| l.get());
        let state = w.slots[which].as_ref().map_or(7, |s| mode(s.inst) as usize);
        feature(code as usize * 64 + (status as usize % 8) * 8 + state.min(7));
    }
    for slot in w.slots.iter_mut().filter_map(Option::take) {
        unsafe { fmi().fmi3FreeInstance(slot.inst) };
    }
});
