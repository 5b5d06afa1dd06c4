use modal_mass_spring::canonical_scenes;
use modal_mass_spring::physics::*;
fn main() {
    let base = canonical_scenes::cloth(30, 30);
    let mut sim = base.with_settings(Settings::new(Reduction::Adaptive, Integrator::NewmarkExplicit, 16)).simulator().unwrap();
    let start = sim.snapshot();
    for _ in 0..300 {
        sim.restore(&start).unwrap();
        for _ in 0..60 {
            sim.do_step(0.01).unwrap();
        }
    }
}
