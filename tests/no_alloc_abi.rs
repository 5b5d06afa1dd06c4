//! Step Mode through the C ABI allocates nothing: after a warm-up step, a
//! counting global allocator watches fmi3Set of every tunable parameter and
//! input (to its own value and to another one), fmi3DoStep and fmi3Get of
//! every scalar output and calculated parameter, for the FMU's default
//! settings, for cubature forces, for a trained basis with cubature forces
//! (trainingRange read with the outputs) and for the trigonometric integrator. Only
//! allocations of the thread that calls count (the test harness's own
//! threads allocate when they please).

use crate::common;
use crate::counting;

use common::*;
use counting::allocations;
use fmi_sys::fmi3::*;
use modal_mass_spring::fmi::exports::*;
use modal_mass_spring::fmi::variables::{vr, Causality, Dim, Type, Variability, Variable, VARIABLES};

/// What Step Mode may set: tunable parameters and inputs.
fn settable_in_step_mode(v: &Variable) -> bool {
    (v.causality == Causality::Parameter && v.variability == Variability::Tunable) || v.causality == Causality::Input
}

/// Scalar values computed by the simulator.
fn scalar_output(v: &Variable) -> bool {
    matches!(v.causality, Causality::Output | Causality::CalculatedParameter | Causality::Independent) && v.dims.is_empty()
}

/// `x` moved a little, inside the variable's range.
fn nudged(v: &Variable, x: f64) -> f64 {
    let y = x + 1e-4 * (1.0 + x.abs());
    if v.max.is_some_and(|m| y > m) {
        x - 1e-4 * (1.0 + x.abs())
    } else {
        y
    }
}

/// One value array per variable, prepared before anything is counted.
struct Values {
    r: u32,
    ty: Type,
    f64s: Vec<f64>,
    i64s: Vec<i64>,
    u64s: Vec<u64>,
    bools: Vec<bool>,
}

impl Values {
    fn of(v: &Variable, x: &[f64]) -> Values {
        Values {
            r: v.vr,
            ty: v.ty,
            f64s: x.to_vec(),
            i64s: x.iter().map(|&x| x as i64).collect(),
            u64s: x.iter().map(|&x| x as u64).collect(),
            bools: x.iter().map(|&x| x != 0.0).collect(),
        }
    }

    /// fmi3Set of these values.
    fn set(&self, inst: fmi3Instance) -> fmi3Status {
        let r = &self.r;
        unsafe {
            match self.ty {
                Type::Float64 => fmi3SetFloat64(inst, r, 1, self.f64s.as_ptr(), self.f64s.len()),
                Type::Int64 => fmi3SetInt64(inst, r, 1, self.i64s.as_ptr(), self.i64s.len()),
                Type::UInt64 => fmi3SetUInt64(inst, r, 1, self.u64s.as_ptr(), self.u64s.len()),
                Type::Boolean => fmi3SetBoolean(inst, r, 1, self.bools.as_ptr(), self.bools.len()),
            }
        }
    }

    /// fmi3Get into these values.
    fn get(&mut self, inst: fmi3Instance) -> fmi3Status {
        let r = &self.r;
        unsafe {
            match self.ty {
                Type::Float64 => fmi3GetFloat64(inst, r, 1, self.f64s.as_mut_ptr(), self.f64s.len()),
                Type::Int64 => fmi3GetInt64(inst, r, 1, self.i64s.as_mut_ptr(), self.i64s.len()),
                Type::UInt64 => fmi3GetUInt64(inst, r, 1, self.u64s.as_mut_ptr(), self.u64s.len()),
                Type::Boolean => fmi3GetBoolean(inst, r, 1, self.bools.as_mut_ptr(), self.bools.len()),
            }
        }
    }
}

/// Sets every tunable parameter and input to its own value and to a
/// nudged one, steps, and reads every scalar output, four times over, after
/// one warm-up step; `settings` are set before initialization; the
/// variables named in `refused` are left alone (the set-up refuses them
/// in Step Mode, and another test shows it). The sheet has 4 holders, all
/// moved by their inputs.
fn step_mode_allocates_nothing(what: &str, settings: &[(u32, i64)], refused: &[&str]) {
    let fmu = Fmu::new();
    assert_eq!(fmu.set_u64(vr::N_HOLDERS, 4), OK, "{what}: {:?}", fmu.messages());
    for &(r, x) in settings {
        assert_eq!(fmu.set_i64(r, x), OK, "{what}: {:?}", fmu.messages());
    }
    fmu.init();
    let h = 0.01;
    assert_eq!(fmu.step(0.0, h), OK, "{what}: {:?}", fmu.messages());
    let mut sets = Vec::new();
    for v in VARIABLES.iter().filter(|v| settable_in_step_mode(v) && !refused.contains(&v.name)) {
        let mut now = Values::of(v, &vec![0.0; size(&fmu, v)]);
        assert_eq!(now.get(fmu.inst), OK, "{what}: {}", v.name);
        let own: Vec<f64> = match v.ty {
            Type::Float64 => now.f64s.clone(),
            Type::Int64 => now.i64s.iter().map(|&x| x as f64).collect(),
            Type::UInt64 => now.u64s.iter().map(|&x| x as f64).collect(),
            Type::Boolean => now.bools.iter().map(|&x| x as u8 as f64).collect(),
        };
        let other: Vec<f64> = own.iter().map(|&x| if v.ty == Type::Float64 { nudged(v, x) } else { x }).collect();
        sets.push((v.name, Values::of(v, &own), Values::of(v, &other)));
    }
    assert!(sets.iter().any(|(n, _, _)| *n == "loadX") && sets.len() >= 8, "{what}: tunables and inputs found: {}", sets.len());
    let mut gets: Vec<(&str, Values)> = VARIABLES.iter().filter(|v| scalar_output(v)).map(|v| (v.name, Values::of(v, &[0.0]))).collect();
    assert!(gets.len() >= 10, "{what}: scalar outputs found: {}", gets.len());
    let (mut event, mut terminate, mut early, mut last) = (false, false, false, 0.0);
    let mut t = h;
    let mut failures = Vec::with_capacity(64);
    let n = allocations(|| {
        for round in 0..4 {
            for (name, own, other) in &sets {
                let s = if round % 2 == 0 { other.set(fmu.inst) } else { own.set(fmu.inst) };
                if s != OK {
                    failures.push((*name, s));
                }
            }
            let s = unsafe { fmi3DoStep(fmu.inst, t, h, true, &mut event, &mut terminate, &mut early, &mut last) };
            if s != OK {
                failures.push(("fmi3DoStep", s));
            }
            t += h;
            for (name, values) in &mut gets {
                let s = values.get(fmu.inst);
                if s != OK {
                    failures.push((*name, s));
                }
            }
        }
    });
    assert!(failures.is_empty(), "{what}: calls not OK: {failures:?}; {:?}", fmu.messages());
    assert_eq!(n, 0, "{what}: {n} allocations in 4 rounds of Set of every tunable and input, fmi3DoStep and Get of every scalar output");
}

/// Elements of `v` in the instance's current sizes.
fn size(fmu: &Fmu, v: &Variable) -> usize {
    v.dims
        .iter()
        .map(|d| match *d {
            Dim::Fixed(n) => n,
            Dim::Param(p) => fmu.get_u64(p) as usize,
        })
        .product()
}

#[test]
fn default_settings() {
    step_mode_allocates_nothing("default", &[], &[]);
}

#[test]
fn cubature_forces() {
    step_mode_allocates_nothing("cubature", &[(vr::FORCE_EVALUATION, 2)], &[]);
}

#[test]
fn trained_basis_with_cubature() {
    // trainingRange is among the scalar outputs read, trainingRangeLimit among the tunables set.
    assert!(VARIABLES.iter().any(|v| v.vr == vr::TRAINING_RANGE && scalar_output(v)));
    assert!(VARIABLES.iter().any(|v| v.vr == vr::TRAINING_RANGE_LIMIT && settable_in_step_mode(v)));
    step_mode_allocates_nothing("trained, cubature", &[(vr::MODE_SELECTION, 3), (vr::FORCE_EVALUATION, 2)], &[]);
}

#[test]
fn trigonometric_integrator() {
    // A turning holder is refused by the trigonometric scheme (tests/turning.rs).
    step_mode_allocates_nothing("trigonometric", &[(vr::INTEGRATOR, 3)], &["anchorRX", "anchorRY", "anchorRZ"]);
}
