//! The implicit scheme's work beside the explicit step's, measured side by
//! side in one run, on cloth 3D (structural and shear springs) of N x N
//! nodes, N = 30 and 100, at rest:
//!
//! - `assembly/cloth-3d-NxN/tangent`: the tangent stiffness K(x) assembled
//!   on its sparsity (`StiffnessPattern::add_tangent`: each spring's D x D
//!   block scattered to the positions of its upper-triangle entries, held
//!   at set-up), what every Newton iteration of the implicit scheme and
//!   every estimate of an adaptive run's error model make;
//! - `.../spring forces`: one pass of the spring forces (the kernel of the
//!   explicit step), the yardstick of a pass over every spring;
//! - `.../implicit step`: one internal step of implicit Newmark in full
//!   space through `Simulator::do_step` (per Newton iteration the tangent,
//!   faer's numeric sparse Cholesky and a solve), from the state at rest
//!   under gravity (restored before each step, untimed).

use criterion::{criterion_group, criterion_main, Criterion};
use modal_mass_spring::canonical_scenes;
use modal_mass_spring::physics::run::forces::SpringForces;
use modal_mass_spring::physics::run::stiffness::StiffnessPattern;
use modal_mass_spring::physics::*;
use std::hint::black_box;

fn assembly(c: &mut Criterion) {
    for n in [30usize, 100] {
        let setup = canonical_scenes::cloth(n, n);
        let scene = setup.grid.build().expect("cloth builds");
        let mut group = c.benchmark_group(format!("assembly/cloth-3d-{n}x{n}"));
        let pattern = StiffnessPattern::new(&scene);
        let mut vals = vec![0.0; pattern.nnz()];
        group.bench_function("tangent", |b| {
            b.iter(|| {
                vals.fill(0.0);
                pattern.add_tangent(&scene, black_box(&scene.rest), 1.0, &mut vals);
            })
        });
        let springs = SpringForces::new(&scene);
        let mut scratch = springs.scratch(&scene);
        let mut f = vec![0.0; scene.n_dofs()];
        group.bench_function("spring forces", |b| {
            b.iter(|| {
                f.fill(0.0);
                black_box(springs.add_to(&scene, black_box(&scene.rest), &mut scratch, &mut f));
            })
        });
        let h = 1e-3;
        let mut settings = Settings::new(Reduction::Full, Integrator::NewmarkImplicit, 0);
        settings.max_internal_step = h;
        let mut sim = setup.with_settings(settings).simulator().expect("set-up");
        let start = sim.snapshot();
        group.bench_function("implicit step", |b| {
            b.iter_custom(|iters| {
                let mut total = std::time::Duration::ZERO;
                for _ in 0..iters {
                    sim.restore(&start).expect("restore");
                    let t = std::time::Instant::now();
                    sim.do_step(h).expect("step");
                    total += t.elapsed();
                }
                total
            })
        });
        group.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = assembly
}
criterion_main!(benches);
