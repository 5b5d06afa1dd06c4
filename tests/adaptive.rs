//! reduction = adaptive (`docs/method.md`, section 10) on cloth 30 x 30,
//! undamped, explicit, 0.01 s steps, over [0, 0.6 s] (inside the cloth's
//! predictable window), against the full-space run under the same loads:
//! the error it reaches, its estimate of it, the share of steps it takes
//! reduced. `cargo test --release --test suite adaptive:: -- --nocapture` prints the table.

use modal_mass_spring::canonical_scenes;
use modal_mass_spring::physics::*;

const H: f64 = 0.01;
const STEPS: usize = 60;

/// Gravity 9.81 m/s^2 scaled by `scale`, tilted by `x_deg` about x and `z_deg` about z.
fn gravity(scale: f64, x_deg: f64, z_deg: f64) -> [f64; 3] {
    let (a, b) = (x_deg.to_radians(), z_deg.to_radians());
    let g = [9.81 * b.sin(), -9.81 * b.cos(), 0.0];
    [scale * g[0], scale * g[1] * a.cos(), scale * g[1] * a.sin()]
}

struct Outcome {
    e: f64,
    estimate: f64,
    reduced: f64,
}

/// E of the adaptive run against full space with gravity `g` set after set-up, and what the run reports.
fn run(g: [f64; 3], tolerance: f64) -> Outcome {
    let mut base = canonical_scenes::cloth(30, 30);
    base.loads.damping_alpha = 0.0;
    base.loads.damping_beta = 0.0;
    let mut full = base.with_settings(Settings::new(Reduction::Full, Integrator::NewmarkExplicit, 0)).simulator().unwrap();
    let adaptive = Settings { error_tolerance: tolerance, ..Settings::new(Reduction::Adaptive, Integrator::NewmarkExplicit, 2) };
    let mut sim = base.with_settings(adaptive).simulator().unwrap();
    let start = full.positions().to_vec();
    for s in [&mut full, &mut sim] {
        let loads = Loads { gravity: g, ..s.loads().clone() };
        s.set_loads(&loads).unwrap();
    }
    let (mut error, mut motion) = (0.0, 0.0);
    for _ in 0..STEPS {
        full.do_step(H).unwrap();
        sim.do_step(H).unwrap();
        let (x, y) = (full.positions(), sim.positions().to_vec());
        error += x.iter().zip(&y).map(|(a, b)| (a - b).powi(2)).sum::<f64>();
        motion += x.iter().zip(&start).map(|(a, b)| (a - b).powi(2)).sum::<f64>();
    }
    let status = sim.reduction_status();
    Outcome { e: (error / motion).sqrt(), estimate: status.error_estimate, reduced: status.reduced_fraction }
}

/// The estimate is within a factor of 3 of E, or below a tenth of the tolerance where E is.
fn within_bounds(o: &Outcome, tolerance: f64) -> bool {
    o.estimate >= o.e / 3.0 && (o.estimate <= 3.0 * o.e || (o.e < 0.1 * tolerance && o.estimate <= 0.1 * tolerance))
}

#[test]
fn inside_the_program_the_run_stays_reduced_within_the_tolerance() {
    let tolerance = 0.01;
    for (name, g) in [("the canonical load", gravity(1.0, 0.0, 0.0)), ("0.85 g tilted 10 degrees about x and z", gravity(0.85, 10.0, 10.0))] {
        let o = run(g, tolerance);
        println!("{name}: E {:.4}, estimate {:.4}, reduced {:.3}", o.e, o.estimate, o.reduced);
        assert!(o.e <= tolerance, "{name}: E = {}", o.e);
        assert!(within_bounds(&o, tolerance), "{name}: estimate {} against E {}", o.estimate, o.e);
        assert!(o.reduced >= 0.9, "{name}: {} of the steps reduced", o.reduced);
    }
}

#[test]
fn far_outside_the_program_the_run_falls_back() {
    let tolerance = 0.01;
    // Twice gravity, 70 degrees out of the sheet's plane.
    let o = run(gravity(2.0, 70.0, 0.0), tolerance);
    println!("2 g tilted 70 degrees: E {:.4}, estimate {:.4}, reduced {:.3}", o.e, o.estimate, o.reduced);
    assert!(o.reduced < 0.9, "the run fell back: {} reduced", o.reduced);
    assert!(o.e <= 2.0 * tolerance, "E = {}", o.e);
    assert!(within_bounds(&o, tolerance), "estimate {} against E {}", o.estimate, o.e);
}
