//! Speed of stepping, measured side by side in one run:
//!
//! - `internal_step/SCENE`: one internal step, modal (r = 2, 8, 32) against full space, every integrator (in the
//!   spaces its set-up accepts: the trigonometric one in modal space only; a call of 100 internal steps, divided by
//!   100);
//! - `cubature/cloth-3d-NxN`: one explicit internal step of 16 modes of the load with a static correction, every
//!   force evaluation (exact forces, cubature), on the 30 x 30 and the 100 x 100 cloth (a call of 1000 internal
//!   steps, divided by 1000: the outputs at the end of a call use every spring);
//! - `do_step/paper-2d-top-row`: a communication step of one internal step, through `Simulator::do_step` and
//!   through `fmi3DoStep` of the C ABI, beside the internal step alone: the differences are the overheads of a
//!   call; and the same with the holder's force, and torque, read after each step, and with the holder turning;
//! - `residual_check/cloth-3d-NxN`: `fmi3DoStep` of the cloth with 16 modes of the load, a static correction and
//!   cubature forces, as a host gets it (the default `forceResidualLimit`) and with the check off, 0.01 s steps;
//! - `residual_run/cloth-3d-300x300`: the same instance over a whole run of 30 s in 0.01 s calls from the state
//!   after set-up (restored before each run, untimed: the check's warm-up after a restore is that after set-up),
//!   the default forceResidualLimit against the check off, alternately in one run; prints the mean per call of each
//!   and their ratio.
//! - `trained/cloth-3d-NxN`: `fmi3DoStep` of the cloth with 16 trained vectors (`modeSelection = trained`), exact
//!   and cubature forces, default settings otherwise, without and with the node positions read after each step.
//! - `holders/paper-2d-top-row`: a communication step of 0.01 s with 1, 2 and 4 holders (the top row split among
//!   them), every holder moving on a circle of its own, modal (8 load vectors, a static correction, `anchorMotion`:
//!   the constraint modes in the basis) and full space, the force and torque of every holder read after each step.
//! - `adaptive/cloth-3d-NxN`: a whole run of 0.6 s in 0.01 s calls of `fmi3DoStep` from the state after set-up
//!   (restored before each run, untimed), default settings otherwise: full space, the best fixed reduced setting
//!   (16 trained vectors with cubature forces: E 0.0088 on 30 x 30 over its window, the fewest vectors there that
//!   meet 0.01), the same with exact forces, and `reduction = adaptive` (its set-up excluded); also full space and
//!   adaptive with gravity turned fully sideways (outside any training program) at 0.25 s, where adaptive falls
//!   back and carries its error on, and on 30 x 30 from the start.
//! - `full_space/cloth-3d-NxN` (N = 100, 300): the explicit full-space internal step through `fmi3DoStep` (ten
//!   internal steps of 1e-4 s per call, structural and shear springs, no auxiliary springs, the residual check off)
//!   beside the yardstick, a plain scalar loop over the same springs (one pass of spring forces into a force array,
//!   then a symplectic velocity and position update). Criterion reports each per internal step, with springs per
//!   second as the throughput; the group then times both alternately in one run and prints the ns per spring of
//!   each and their ratio; the FMU on 1 and on 2 threads (`threads`), whose trajectories it checks to be the same,
//!   bit for bit.
//!
//! cargo bench --bench step

use std::ffi::CString;
use std::ptr::{null, null_mut};
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use fmi_sys::fmi3::*;
use modal_mass_spring::canonical_scenes;
use modal_mass_spring::fmi::exports::*;
use modal_mass_spring::fmi::variables::{vr, INSTANTIATION_TOKEN};
use modal_mass_spring::physics::*;

const PER_CALL: usize = 100;

/// A simulator whose internal step is `dt` whatever the call length, or
/// the set-up's refusal.
fn try_simulator(p: &Grid, s: &Settings) -> Result<(Simulator, f64), PhysicsError> {
    let probe = Simulator::new(p.build()?, s, &Loads::physical(s.n_modes))?;
    let dt = probe.max_stable_step().min(1e-4);
    let fixed = Settings { max_internal_step: dt, ..s.clone() };
    Ok((Simulator::new(p.build()?, &fixed, &Loads::physical(s.n_modes))?, dt))
}

fn simulator(p: &Grid, s: &Settings) -> (Simulator, f64) {
    try_simulator(p, s).unwrap()
}

fn internal_step(c: &mut Criterion) {
    for name in canonical_scenes::names() {
        let p = canonical_scenes::canonical(name).unwrap().grid;
        let n = p.build().unwrap().n_dofs();
        let mut group = c.benchmark_group(format!("internal_step/{name}"));
        for &integrator in Integrator::ALL {
            let mut configs: Vec<(String, Settings)> =
                [2usize, 8, 32].into_iter().filter(|&r| r <= n).map(|r| (format!("modal-r{r}"), Settings::new(Reduction::Modal, integrator, r))).collect();
            configs.push(("full".into(), Settings::new(Reduction::Full, integrator, 0)));
            for (label, s) in configs {
                let (mut sim, dt) = match try_simulator(&p, &s) {
                    Ok(built) => built,
                    // A space the scheme cannot integrate (the trigonometric scheme in full space).
                    Err(e) if e.refuses_pairing() => continue,
                    Err(e) => panic!("{name} {integrator:?} {label}: {e}"),
                };
                let h = dt * PER_CALL as f64 * (1.0 - 1e-9);
                group.bench_function(BenchmarkId::new(format!("{integrator:?}"), label), |b| {
                    b.iter_custom(|iters| {
                        let t = Instant::now();
                        for _ in 0..iters {
                            sim.do_step(h).unwrap();
                        }
                        assert_eq!(sim.internal_steps_last(), PER_CALL);
                        t.elapsed() / PER_CALL as u32
                    })
                });
            }
        }
        group.finish();
    }
}

fn cubature(c: &mut Criterion) {
    const STEPS: usize = 1000;
    for n in [30, 100] {
        let setup = canonical_scenes::cloth(n, n);
        let mut group = c.benchmark_group(format!("cubature/cloth-3d-{n}x{n}"));
        group.sample_size(20);
        for &evaluation in ForceEvaluation::ALL {
            let mut s = Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, 16);
            s.mode_selection = ModeSelection::Load;
            s.static_correction = true;
            s.force_evaluation = evaluation;
            let probe = setup.with_settings(s.clone()).simulator().unwrap();
            let dt = probe.max_stable_step().min(1e-3);
            let mut sim = setup.with_settings(Settings { max_internal_step: dt, ..s }).simulator().unwrap();
            let springs = sim.cubature_springs();
            group.bench_function(BenchmarkId::new(format!("{evaluation:?}"), format!("{springs} springs")), |b| {
                b.iter_custom(|iters| {
                    let t = Instant::now();
                    for _ in 0..iters {
                        sim.do_step(dt * STEPS as f64 * (1.0 - 1e-9)).unwrap();
                    }
                    assert_eq!(sim.internal_steps_last(), STEPS);
                    t.elapsed() / STEPS as u32
                })
            });
        }
        group.finish();
    }
}

unsafe extern "C" fn silent(_: fmi3InstanceEnvironment, _: fmi3Status, _: fmi3String, _: fmi3String) {}

fn do_step(c: &mut Criterion) {
    let name = "paper-2d-top-row";
    let p = canonical_scenes::canonical(name).unwrap().grid;
    let s = Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, 2);
    let (mut many, dt) = simulator(&p, &s);
    let (mut one, _) = simulator(&p, &s);
    let mut group = c.benchmark_group(format!("do_step/{name}"));
    group.bench_function("internal step alone", |b| {
        b.iter_custom(|iters| {
            let t = Instant::now();
            for _ in 0..iters {
                many.do_step(dt * PER_CALL as f64 * (1.0 - 1e-9)).unwrap();
            }
            t.elapsed() / PER_CALL as u32
        })
    });
    group.bench_function("Simulator::do_step", |b| b.iter(|| one.do_step(dt).unwrap()));

    // The default FMU (this scene, explicit, r = 2) with the same internal step.
    let (name_c, token) = (CString::new("bench").unwrap(), CString::new(INSTANTIATION_TOKEN).unwrap());
    let inst =
        unsafe { fmi3InstantiateCoSimulation(name_c.as_ptr(), token.as_ptr(), null(), false, false, false, false, null(), 0, null_mut(), Some(silent), None) };
    assert!(!inst.is_null());
    unsafe {
        assert_eq!(fmi3SetFloat64(inst, &vr::MAX_INTERNAL_STEP, 1, &dt, 1), fmi3Status_fmi3OK);
        assert_eq!(fmi3EnterInitializationMode(inst, false, 0.0, 0.0, false, 0.0), fmi3Status_fmi3OK);
        assert_eq!(fmi3ExitInitializationMode(inst), fmi3Status_fmi3OK);
    }
    let mut time = 0.0;
    group.bench_function("fmi3DoStep", |b| {
        b.iter_custom(|iters| {
            let (mut event, mut terminate, mut early, mut last) = (false, false, false, 0.0);
            let t = Instant::now();
            for _ in 0..iters {
                let status = unsafe { fmi3DoStep(inst, time, dt, true, &mut event, &mut terminate, &mut early, &mut last) };
                // fmi3Warning once, when forceResidual passes its limit in the long undamped swing.
                assert!(status == fmi3Status_fmi3OK || status == fmi3Status_fmi3Warning);
                time += dt;
            }
            t.elapsed()
        })
    });
    // The same with the ports read after every step: the holder's force
    // (O(r)), its torque too (O(r^2)), and with the holder turning.
    let read = |names: &[u32]| {
        let mut sum = 0.0;
        for r in names {
            let mut v = 0.0;
            assert_eq!(unsafe { fmi3GetFloat64(inst, r, 1, &mut v, 1) }, fmi3Status_fmi3OK);
            sum += v;
        }
        sum
    };
    let force = [vr::ANCHOR_FORCE_X, vr::ANCHOR_FORCE_Y];
    let force_torque = [vr::ANCHOR_FORCE_X, vr::ANCHOR_FORCE_Y, vr::ANCHOR_TORQUE_Z];
    for (label, names, turning) in [
        ("fmi3DoStep + anchorForce", &force[..], false),
        ("fmi3DoStep + anchorForce + anchorTorque", &force_torque[..], false),
        ("fmi3DoStep turning + anchorForce + anchorTorque", &force_torque[..], true),
    ] {
        group.bench_function(label, |b| {
            b.iter_custom(|iters| {
                let (mut event, mut terminate, mut early, mut last) = (false, false, false, 0.0);
                let t = Instant::now();
                for _ in 0..iters {
                    if turning {
                        // A slow turn back and forth: 0.1 rad at 1 rad/s.
                        let angle = 0.1 * (time + dt).sin();
                        assert_eq!(unsafe { fmi3SetFloat64(inst, &vr::ANCHOR_R_Z, 1, &angle, 1) }, fmi3Status_fmi3OK);
                    }
                    let status = unsafe { fmi3DoStep(inst, time, dt, true, &mut event, &mut terminate, &mut early, &mut last) };
                    assert!(status == fmi3Status_fmi3OK || status == fmi3Status_fmi3Warning);
                    assert!(read(names).is_finite());
                    time += dt;
                }
                t.elapsed()
            })
        });
    }
    group.finish();
    unsafe { fmi3FreeInstance(inst) };
}

/// An instance of the cloth-3d scene on an n x n grid with 16 modes of the
/// load, a static correction and cubature forces, `limit` its
/// forceResidualLimit, initialized at t = 0.
fn cloth_instance(n: u64, limit: f64) -> fmi3Instance {
    cloth_with(n, &[(vr::MODE_SELECTION, 2), (vr::FORCE_EVALUATION, 2)], true, limit)
}

/// A new Co-Simulation instance of the FMU, silent.
fn instantiate() -> fmi3Instance {
    let (name, token) = (CString::new("bench").unwrap(), CString::new(INSTANTIATION_TOKEN).unwrap());
    let inst =
        unsafe { fmi3InstantiateCoSimulation(name.as_ptr(), token.as_ptr(), null(), false, false, false, false, null(), 0, null_mut(), Some(silent), None) };
    assert!(!inst.is_null());
    inst
}

/// An instance of the cloth-3d scene on an n x n grid with 16 modes, the
/// enumerations `choices`, a static correction if `correction`,
/// forceResidualLimit `limit`, every other value at its default, initialized at t = 0.
fn cloth_with(n: u64, choices: &[(u32, i64)], correction: bool, limit: f64) -> fmi3Instance {
    let inst = instantiate();
    let ok = fmi3Status_fmi3OK;
    unsafe {
        for (r, v) in [(vr::NX, n), (vr::NY, n), (vr::DIMENSION, 3), (vr::N_MODES, 16), (vr::LOAD_COLUMN, n / 2)] {
            assert_eq!(fmi3SetUInt64(inst, &r, 1, &v, 1), ok);
        }
        for &(r, v) in choices {
            assert_eq!(fmi3SetInt64(inst, &r, 1, &v, 1), ok);
        }
        assert_eq!(fmi3SetBoolean(inst, &vr::STATIC_CORRECTION, 1, &correction, 1), ok);
        for (r, v) in [(vr::AUX_STIFFNESS, 0.05), (vr::FORCE_RESIDUAL_LIMIT, limit)] {
            assert_eq!(fmi3SetFloat64(inst, &r, 1, &v, 1), ok);
        }
        assert_eq!(fmi3EnterInitializationMode(inst, false, 0.0, 0.0, false, 0.0), ok);
        assert_eq!(fmi3ExitInitializationMode(inst), ok);
    }
    inst
}

/// The time of `iters` calls of `fmi3DoStep` of `h` from `time` (advanced),
/// each followed by a read of the node positions into `positions` when given.
fn steps(inst: fmi3Instance, iters: u64, h: f64, time: &mut f64, mut positions: Option<&mut Vec<f64>>) -> Duration {
    let (mut event, mut terminate, mut early, mut last) = (false, false, false, 0.0);
    let t = Instant::now();
    for _ in 0..iters {
        let status = unsafe { fmi3DoStep(inst, *time, h, true, &mut event, &mut terminate, &mut early, &mut last) };
        assert!(status == fmi3Status_fmi3OK || status == fmi3Status_fmi3Warning);
        if let Some(x) = positions.as_deref_mut() {
            let r = vr::POSITIONS;
            assert_eq!(unsafe { fmi3GetFloat64(inst, &r, 1, x.as_mut_ptr(), x.len()) }, fmi3Status_fmi3OK);
        }
        *time += h;
    }
    t.elapsed()
}

fn holders(c: &mut Criterion) {
    let name = "paper-2d-top-row";
    let mut group = c.benchmark_group(format!("holders/{name}"));
    let mut modal = Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, 8);
    modal.mode_selection = ModeSelection::Load;
    modal.static_correction = true;
    modal.anchor_motion = true;
    for (space, s) in [("modal-r8", modal), ("full", Settings::new(Reduction::Full, Integrator::NewmarkExplicit, 0))] {
        for n in [1usize, 2, 4] {
            let mut p = canonical_scenes::canonical(name).unwrap().grid;
            p.holders = n;
            // The same internal step for every holder count (the bases differ, and so would their stable steps).
            let (mut sim, _) = simulator(&p, &Settings { max_internal_step: 5e-5, ..s.clone() });
            sim.do_step(0.01).unwrap();
            let steps = sim.internal_steps_last();
            let mut t = 0.0f64;
            group.bench_function(BenchmarkId::new(space, format!("{n} holders, {steps} internal steps")), |b| {
                b.iter(|| {
                    t += 0.01;
                    sim.edit_loads(&mut |l| {
                        l.anchor = [0.01 * (2.0 * t).cos(), 0.01 * (2.0 * t).sin(), 0.0];
                        for (k, h) in l.holders.iter_mut().enumerate().take(n - 1) {
                            let phase = t * (3.0 + k as f64);
                            h.anchor = [0.01 * phase.cos(), 0.01 * phase.sin(), 0.0];
                        }
                    })
                    .unwrap();
                    sim.do_step(0.01).unwrap();
                    (0..n).map(|k| sim.holder_force(k)[1] + sim.holder_torque(k)[2]).sum::<f64>()
                })
            });
        }
    }
}

fn residual_check(c: &mut Criterion) {
    for n in [30u64, 100] {
        let mut group = c.benchmark_group(format!("residual_check/cloth-3d-{n}x{n}"));
        group.sample_size(20);
        for (label, limit) in [("default forceResidualLimit", 0.9), ("check off", 0.0)] {
            let inst = cloth_instance(n, limit);
            let (h, mut time) = (0.01, 0.0);
            group.bench_function(label, |b| b.iter_custom(|iters| steps(inst, iters, h, &mut time, None)));
            unsafe { fmi3FreeInstance(inst) };
        }
        group.finish();
    }
}

fn residual_run(c: &mut Criterion) {
    let _ = c;
    let n = 300u64;
    if !wanted(&format!("residual_run/cloth-3d-{n}x{n}")) {
        return;
    }
    const CALLS: u64 = 3000;
    let mut runs = Vec::new();
    for limit in [0.9, 0.0] {
        let inst = cloth_instance(n, limit);
        let mut start: fmi3FMUState = null_mut();
        assert_eq!(unsafe { fmi3GetFMUState(inst, &mut start) }, fmi3Status_fmi3OK);
        runs.push((inst, start, Vec::new()));
    }
    for _ in 0..5 {
        for (inst, start, times) in runs.iter_mut() {
            assert_eq!(unsafe { fmi3SetFMUState(*inst, *start) }, fmi3Status_fmi3OK);
            let mut time = 0.0;
            times.push(steps(*inst, CALLS, 0.01, &mut time, None).as_secs_f64() * 1e6 / CALLS as f64);
        }
    }
    let (on, off) = (median(runs[0].2.clone()), median(runs[1].2.clone()));
    println!(
        "residual_run/cloth-3d-{n}x{n}: 30 s in 0.01 s calls, median of 5 runs: default forceResidualLimit {on:.2} us per call, check off {off:.2} us per call, ratio {:.2} (runs on: {:.2?}, off: {:.2?})",
        on / off,
        runs[0].2,
        runs[1].2
    );
    for (inst, mut start, _) in runs {
        unsafe {
            fmi3FreeFMUState(inst, &mut start);
            fmi3FreeInstance(inst);
        }
    }
}

/// `fmi3DoStep` of 0.01 s on the cloth with 16 trained vectors, exact
/// and cubature forces, every other value at its default (the residual
/// check and the trained range's check on), as a host gets it; and with the
/// node positions read after each step.
fn trained(c: &mut Criterion) {
    for n in [30u64, 100] {
        let mut group = c.benchmark_group(format!("trained/cloth-3d-{n}x{n}"));
        group.sample_size(10);
        for (label, force) in [("exact", 1i64), ("cubature", 2)] {
            let inst = cloth_with(n, &[(vr::MODE_SELECTION, 3), (vr::FORCE_EVALUATION, force)], false, 0.9);
            let mut positions = vec![0.0; 3 * (n * n) as usize];
            let (h, mut time) = (0.01, 0.0);
            for read in [false, true] {
                let id = if read { format!("{label}, positions read") } else { label.to_string() };
                group.bench_function(id, |b| b.iter_custom(|iters| steps(inst, iters, h, &mut time, read.then_some(&mut positions))));
            }
            unsafe { fmi3FreeInstance(inst) };
        }
        group.finish();
    }
}

/// A run of 0.6 s through `fmi3DoStep` from set-up: full space, a fixed
/// trained basis and the adaptive reduction (see the module documentation).
fn adaptive(c: &mut Criterion) {
    for n in [30u64, 100] {
        let mut group = c.benchmark_group(format!("adaptive/cloth-3d-{n}x{n}"));
        group.sample_size(10);
        // Gravity turned sideways (outside any training program) before the step given, if any.
        let cases = [
            ("full space", vec![(vr::REDUCTION, 2)], None),
            ("trained, 16 vectors, cubature", vec![(vr::MODE_SELECTION, 3), (vr::FORCE_EVALUATION, 2)], None),
            ("trained, 16 vectors, exact", vec![(vr::MODE_SELECTION, 3), (vr::FORCE_EVALUATION, 1)], None),
            ("adaptive", vec![(vr::REDUCTION, 3)], None),
            ("full space, gravity sideways", vec![(vr::REDUCTION, 2)], Some(0)),
            ("adaptive, gravity sideways", vec![(vr::REDUCTION, 3)], Some(0)),
            ("full space, gravity sideways at 0.25 s", vec![(vr::REDUCTION, 2)], Some(25)),
            ("adaptive, gravity sideways at 0.25 s", vec![(vr::REDUCTION, 3)], Some(25)),
        ];
        for (label, choices, turn) in cases.into_iter().filter(|c| c.2 != Some(0) || n == 30) {
            let inst = cloth_with(n, &choices, false, 0.9);
            let sideways = || assert_eq!(unsafe { fmi3SetFloat64(inst, &vr::GRAVITY, 1, [9.81, 0.0, 0.0].as_ptr(), 3) }, fmi3Status_fmi3OK);
            let mut start: fmi3FMUState = null_mut();
            assert_eq!(unsafe { fmi3GetFMUState(inst, &mut start) }, fmi3Status_fmi3OK);
            let turn = turn.unwrap_or(60);
            group.bench_function(label, |b| {
                b.iter_custom(|iters| {
                    let run = || {
                        assert_eq!(unsafe { fmi3SetFMUState(inst, start) }, fmi3Status_fmi3OK);
                        let mut t = 0.0;
                        let before = steps(inst, turn, 0.01, &mut t, None);
                        if turn < 60 {
                            sideways();
                        }
                        before + steps(inst, 60 - turn, 0.01, &mut t, None)
                    };
                    (0..iters).map(|_| run()).sum()
                })
            });
            unsafe {
                fmi3FreeFMUState(inst, &mut start);
                fmi3FreeInstance(inst);
            }
        }
        group.finish();
    }
}

/// An instance of the cloth-3d scene on an n x n grid in full space,
/// explicit, structural and shear springs, no auxiliary springs, the
/// residual check off, internal steps of `dt`, on `threads` threads, initialized at t = 0.
fn full_space_instance(n: u64, dt: f64, threads: u64) -> fmi3Instance {
    let inst = instantiate();
    let ok = fmi3Status_fmi3OK;
    unsafe {
        for (r, v) in [(vr::NX, n), (vr::NY, n), (vr::DIMENSION, 3), (vr::N_MODES, 1), (vr::THREADS, threads)] {
            assert_eq!(fmi3SetUInt64(inst, &r, 1, &v, 1), ok);
        }
        for (r, v) in [(vr::REDUCTION, 2i64), (vr::INTEGRATOR, 1)] {
            assert_eq!(fmi3SetInt64(inst, &r, 1, &v, 1), ok);
        }
        assert_eq!(fmi3SetBoolean(inst, &vr::SHEAR_SPRINGS, 1, &true, 1), ok);
        for (r, v) in [(vr::AUX_STIFFNESS, 0.0), (vr::FORCE_RESIDUAL_LIMIT, 0.0), (vr::MAX_INTERNAL_STEP, dt)] {
            assert_eq!(fmi3SetFloat64(inst, &r, 1, &v, 1), ok);
        }
        assert_eq!(fmi3EnterInitializationMode(inst, false, 0.0, 0.0, false, 0.0), ok);
        assert_eq!(fmi3ExitInitializationMode(inst), ok);
    }
    inst
}

/// The yardstick of the full space: the springs of the same scene in one
/// plain scalar pass (forces into a force array, gravity first), then a
/// symplectic Euler update of the free nodes, v += dt f / m, x += dt v.
struct PlainLoop {
    springs: Vec<(u32, u32, f64, f64)>,
    n_free: usize,
    x: Vec<f64>,
    v: Vec<f64>,
    f: Vec<f64>,
    mass: Vec<f64>,
    gravity: [f64; 3],
}

impl PlainLoop {
    fn new(scene: &Scene) -> Self {
        assert_eq!(scene.dim, 3);
        let n = scene.n_free * 3;
        PlainLoop {
            springs: scene.springs.iter().map(|s| (s.a as u32, s.b as u32, s.k, s.rest)).collect(),
            n_free: scene.n_free,
            x: scene.rest.clone(),
            v: vec![0.0; n],
            f: vec![0.0; scene.rest.len()],
            mass: scene.dof_mass[..n].to_vec(),
            gravity: [0.0, -9.81, 0.0],
        }
    }

    fn step(&mut self, dt: f64) {
        let n = self.n_free * 3;
        for (k, f) in self.f.iter_mut().enumerate() {
            *f = if k < n { self.mass[k] * self.gravity[k % 3] } else { 0.0 };
        }
        let (x, f) = (&self.x, &mut self.f);
        for &(a, b, k, l0) in &self.springs {
            let (a, b) = (3 * a as usize, 3 * b as usize);
            let d = [x[b] - x[a], x[b + 1] - x[a + 1], x[b + 2] - x[a + 2]];
            let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            let t = k * (l - l0) / l;
            for i in 0..3 {
                f[a + i] += t * d[i];
                f[b + i] -= t * d[i];
            }
        }
        for k in 0..n {
            self.v[k] += dt * self.f[k] / self.mass[k];
            self.x[k] += dt * self.v[k];
        }
    }
}

/// The filter on the command line (`cargo bench --bench step -- FILTER`)
/// selects `name`: the printed summaries follow criterion's filter.
fn wanted(name: &str) -> bool {
    std::env::args().skip(1).filter(|a| !a.starts_with('-')).all(|f| name.contains(&f))
}

/// Median of `samples`.
fn median(mut samples: Vec<f64>) -> f64 {
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

fn full_space(c: &mut Criterion) {
    const DT: f64 = 1e-4;
    const INTERNAL: u32 = 10;
    for n in [100u64, 300] {
        let grid = Grid {
            columns: n as usize,
            rows: n as usize,
            dim: 3,
            spacing: 0.1,
            node_mass: 0.01,
            spring_stiffness: 50.0,
            shear_springs: true,
            bending_springs: false,
            aux_stiffness: 0.0,
            fixed_nodes: FixedNodes::TopRow,
            holders: 1,
            holder_of_node: Vec::new(),
        };
        let scene = grid.build().unwrap();
        let springs = scene.springs.len();
        let mut plain = PlainLoop::new(&scene);
        let insts = [full_space_instance(n, DT, 1), full_space_instance(n, DT, 2)];
        let h = DT * INTERNAL as f64;
        let mut times = [0.0; 2];
        // The trajectory is the same on 1 and 2 threads, bit for bit.
        let mut positions = [vec![0.0; 3 * (n * n) as usize], vec![0.0; 3 * (n * n) as usize]];
        for ((&inst, x), time) in insts.iter().zip(positions.iter_mut()).zip(times.iter_mut()) {
            steps(inst, 5, h, time, None);
            assert_eq!(unsafe { fmi3GetFloat64(inst, &vr::POSITIONS, 1, x.as_mut_ptr(), x.len()) }, fmi3Status_fmi3OK);
        }
        assert!(positions[0] == positions[1], "1 and 2 threads differ");
        let mut group = c.benchmark_group(format!("full_space/cloth-3d-{n}x{n}"));
        group.sample_size(10);
        group.throughput(criterion::Throughput::Elements(springs as u64));
        let label = format!("{springs} springs");
        for (t, (&inst, time)) in insts.iter().zip(times.iter_mut()).enumerate() {
            group.bench_function(BenchmarkId::new(format!("fmi3DoStep, {} thread(s)", t + 1), &label), |b| {
                b.iter_custom(|iters| steps(inst, iters, h, time, None) / INTERNAL)
            });
        }
        group.bench_function(BenchmarkId::new("plain loop", &label), |b| {
            b.iter_custom(|iters| {
                let t = Instant::now();
                for _ in 0..iters {
                    plain.step(DT);
                }
                t.elapsed()
            })
        });
        group.finish();
        let per_spring = |t: Duration, calls: u64| t.as_secs_f64() * 1e9 / (calls as f64 * INTERNAL as f64 * springs as f64);
        if !wanted(&format!("full_space/cloth-3d-{n}x{n}")) {
            insts.iter().for_each(|&i| unsafe { fmi3FreeInstance(i) });
            continue;
        }
        // Alternately, in one run: ns per spring of each, and the ratios.
        let calls = if n == 100 { 40 } else { 4 };
        let (mut fmu, mut fmu2, mut yard) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..7 {
            fmu.push(per_spring(steps(insts[0], calls, h, &mut times[0], None), calls));
            fmu2.push(per_spring(steps(insts[1], calls, h, &mut times[1], None), calls));
            let t = Instant::now();
            for _ in 0..calls * INTERNAL as u64 {
                plain.step(DT);
            }
            yard.push(t.elapsed().as_secs_f64() * 1e9 / (calls as f64 * INTERNAL as f64 * springs as f64));
        }
        assert!(plain.x.iter().all(|x| x.is_finite()));
        let (f, f2, y) = (median(fmu), median(fmu2), median(yard));
        println!(
            "full_space/cloth-3d-{n}x{n}: {springs} springs, fmi3DoStep {f:.2} ns/spring on 1 thread ({:.2}x the plain loop), {f2:.2} on 2 threads ({:.2}x faster than 1), plain loop {y:.2} ns/spring",
            f / y,
            f / f2
        );
        insts.iter().for_each(|&i| unsafe { fmi3FreeInstance(i) });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(2));
    targets = full_space, residual_run, do_step, internal_step, cubature, residual_check, trained, holders, adaptive
}
criterion_main!(benches);
