//! Cost of one internal step, modal (several r) against full space on the
//! same scene, measured side by side in one run.
//!
//! cargo bench --bench step

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use modal_mass_spring::physics::*;

fn internal_step(c: &mut Criterion) {
    for name in ["paper-2d-top-row", "paper-3d-sheet"] {
        let p = SceneParams::canonical(name).unwrap();
        let n = scene::Scene::build(&p).unwrap().n_dofs();
        let mut group = c.benchmark_group(format!("internal_step/{name}"));
        for integrator in [Integrator::NewmarkExplicit, Integrator::NewmarkImplicit] {
            let mut configs: Vec<(String, SolverParams)> = [2usize, 8, 32]
                .into_iter()
                .filter(|&r| r <= n)
                .map(|r| (format!("modal-r{r}"), SolverParams { n_modes: r, integrator, ..SolverParams::default() }))
                .collect();
            configs.push(("full".into(), SolverParams { reduction: Reduction::Full, n_modes: 0, integrator, ..SolverParams::default() }));
            for (label, s) in configs {
                let mut sim = Simulator::new(&p, &s, &Tunables::physical(s.n_modes)).unwrap();
                // One internal step per call: a step size inside every stability limit.
                let dt = sim.max_stable_step().min(1e-4);
                group.bench_function(BenchmarkId::new(format!("{integrator:?}"), label), |b| b.iter(|| sim.do_step(dt).unwrap()));
            }
        }
        group.finish();
    }
}

criterion_group!(benches, internal_step);
criterion_main!(benches);
