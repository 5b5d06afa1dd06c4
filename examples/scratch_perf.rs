use modal_mass_spring::canonical_scenes;
use modal_mass_spring::physics::*;
fn main() {
    for (n, tol) in [(12usize, 0.1), (12, 0.15), (12, 0.2), (14, 0.08), (16, 0.05), (16, 0.08)] {
        let sim = canonical_scenes::cloth(n, n)
            .with_settings(Settings { error_tolerance: tol, ..Settings::new(Reduction::Adaptive, Integrator::NewmarkExplicit, 2) })
            .simulator()
            .unwrap();
        let s = sim.reduction_status();
        println!("{n} tol {tol}: dofs {} r {} reduces {}", sim.n_dofs(), s.chosen_size, s.reduces);
    }
}
