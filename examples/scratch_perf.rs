use modal_mass_spring::canonical_scenes;
use modal_mass_spring::physics::*;
use std::time::Instant;
fn main() {
    let base = canonical_scenes::cloth(30, 30);
    for red in [Reduction::Full, Reduction::Adaptive, Reduction::Full, Reduction::Adaptive] {
        let mut sim = base.with_settings(Settings::new(red, Integrator::NewmarkExplicit, 2)).simulator().unwrap();
        let l = Loads { gravity: [9.81, 0.0, 0.0], ..sim.loads().clone() };
        sim.set_loads(&l).unwrap();
        let start = sim.snapshot();
        let t = Instant::now();
        for _ in 0..100 {
            sim.restore(&start).unwrap();
            for _ in 0..60 { sim.do_step(0.01).unwrap(); }
        }
        println!("{red:?}: {:.3} ms per run", t.elapsed().as_secs_f64() * 10.0);
    }
}
