//! Many instances on several threads at once: 8 threads, each stepping 3
//! instances in turn, changing tunables, and moving each instance's state
//! through serialization into a fresh instance halfway. Every history must
//! equal, bit for bit, the same run done alone on one thread.

use crate::common;

use std::sync::{Arc, Barrier};

use common::*;
use modal_mass_spring::fmi::exports::{fmi3EnterConfigurationMode, fmi3ExitConfigurationMode, fmi3SetFMUState};
use modal_mass_spring::fmi::variables::vr;

const THREADS: usize = 8;
const PER_THREAD: usize = 3;
const STEPS: usize = 60;

/// One run that differs per `id`: grid, modes, integrator, gravity, damping, weights.
struct Run {
    id: usize,
    f: Fmu,
    history: Vec<Vec<u64>>,
}

impl Run {
    fn configured(id: usize, name: &str) -> Fmu {
        let f = Fmu::named(name);
        assert_eq!(unsafe { fmi3EnterConfigurationMode(f.inst) }, OK);
        assert_eq!(f.set_u64(vr::NX, 6 + (id % 5) as u64), OK);
        assert_eq!(f.set_u64(vr::N_MODES, 2 + (id % 3) as u64), OK);
        assert_eq!(unsafe { fmi3ExitConfigurationMode(f.inst) }, OK);
        f
    }

    fn new(id: usize) -> Run {
        let f = Run::configured(id, &format!("run {id}"));
        assert_eq!(f.set_f64(vr::GRAVITY, &[0.1 * id as f64, -9.81, 0.0]), OK);
        assert_eq!(f.set_f64(vr::DAMPING_BETA, &[1e-4 * (id % 4) as f64]), OK);
        if id % 2 == 1 {
            assert_eq!(f.set_i64(vr::INTEGRATOR, 2), OK);
        }
        f.init(); // set-up: assembly and eigen decomposition
        Run { id, f, history: Vec::new() }
    }

    fn advance(&mut self) {
        let k = self.history.len();
        if k == STEPS / 3 {
            let r = self.f.sizes().3;
            let w: Vec<f64> = (0..r).map(|i| 1.0 + 0.25 * ((i + self.id) % 3) as f64).collect();
            assert_eq!(self.f.set_f64(vr::MODE_WEIGHTS, &w), OK);
        }
        if k == STEPS / 2 {
            let st = self.f.get_state();
            let blob = self.f.serialize(st);
            self.f.free_state(st);
            let g = Run::configured(self.id, &format!("run {}, second half", self.id));
            let (s, st) = g.deserialize(&blob);
            assert_eq!(s, OK, "{:?}", g.messages());
            assert_eq!(unsafe { fmi3SetFMUState(g.inst, st) }, OK, "{:?}", g.messages());
            g.free_state(st);
            self.f = g;
        }
        self.f.run(1, 0.01);
        self.history.push(self.f.outputs());
    }
}

#[test]
fn instances_on_many_threads_match_single_threaded_runs() {
    let n = THREADS * PER_THREAD;
    let alone: Vec<Vec<Vec<u64>>> = (0..n)
        .map(|id| {
            let mut r = Run::new(id);
            (0..STEPS).for_each(|_| r.advance());
            r.history
        })
        .collect();

    let barrier = Arc::new(Barrier::new(THREADS));
    let threads: Vec<_> = (0..THREADS)
        .map(|t| {
            let barrier = barrier.clone();
            std::thread::spawn(move || {
                let mut runs: Vec<Run> = (0..PER_THREAD).map(|k| Run::new(t * PER_THREAD + k)).collect();
                barrier.wait(); // all threads step at the same time
                for _ in 0..STEPS {
                    runs.iter_mut().for_each(Run::advance);
                }
                runs.into_iter().map(|r| (r.id, r.history)).collect::<Vec<_>>()
            })
        })
        .collect();
    let mut together: Vec<(usize, Vec<Vec<u64>>)> = threads.into_iter().flat_map(|h| h.join().unwrap()).collect();
    together.sort_by_key(|(id, _)| *id);

    assert_eq!(together.len(), n);
    for (id, h) in together {
        assert_eq!(h.len(), STEPS);
        assert!(h == alone[id], "run {id}: on a thread with others it differs from the run alone");
    }
}
