//! The stepping cost of the adaptive reduction beside full space and 16
//! fixed trained vectors (exact forces, and cubature forces) on the
//! canonical cloth N x N: 60 steps of 0.01 s from the state after set-up,
//! the four runs alternated R times, the fastest and the median of each
//! (`docs/method.md`, section 10).
//!
//! `cargo run --release --example adaptive_cost -- [N] [R] [sideways|turned]`
//! (30 and 15 by default; `sideways`: gravity turned fully sideways after
//! set-up, outside the training program, where adaptive runs in full space;
//! `turned`: 168 steps of 1/240 s with gravity turned sideways in the
//! sheet's plane at 0.25 s, as the study's `-turned` scenes, where adaptive
//! falls back mid-run and carries its error on in full space).
use modal_mass_spring::canonical_scenes;
use modal_mass_spring::physics::*;
use std::time::Instant;
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let nx: usize = args.first().map_or(30, |v| v.parse().unwrap());
    let reps: usize = args.get(1).map_or(15, |v| v.parse().unwrap());
    let base = canonical_scenes::cloth(nx, nx);
    let full = Settings::new(Reduction::Full, Integrator::NewmarkExplicit, 0);
    let mut trained = Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, 16);
    trained.mode_selection = ModeSelection::Trained;
    let cubature = Settings { force_evaluation: ForceEvaluation::Cubature, ..trained.clone() };
    let adaptive = Settings::new(Reduction::Adaptive, Integrator::NewmarkExplicit, 2);
    let mut sims: Vec<_> = [full, trained, cubature, adaptive].into_iter().map(|s| base.with_settings(s).simulator().unwrap()).collect();
    let turned = args.get(2).is_some_and(|a| a == "turned");
    let (steps, h, turn_at) = if turned { (168, 1.0 / 240.0, 61) } else { (60, 0.01, usize::MAX) };
    if args.get(2).is_some_and(|a| a == "sideways") {
        for s in &mut sims {
            let loads = Loads { gravity: [9.81, 0.0, 0.0], ..s.loads().clone() };
            s.set_loads(&loads).unwrap();
        }
    }
    let starts: Vec<_> = sims.iter().map(|s| s.snapshot()).collect();
    let mut times = vec![Vec::new(); 4];
    for _ in 0..reps {
        for (i, s) in sims.iter_mut().enumerate() {
            s.restore(&starts[i]).unwrap();
            let t = Instant::now();
            for k in 1..=steps {
                if k == turn_at {
                    let loads = Loads { gravity: [9.81, 0.0, 0.0], ..s.loads().clone() };
                    s.set_loads(&loads).unwrap();
                }
                s.do_step(h).unwrap();
            }
            times[i].push(t.elapsed().as_secs_f64() * 1e3);
        }
    }
    for (name, t) in ["full", "trained 16", "cubature 16", "adaptive"].iter().zip(&mut times) {
        t.sort_by(|a, b| a.partial_cmp(b).unwrap());
        println!("{name:12} min {:.3} ms median {:.3} ms", t[0], t[t.len() / 2]);
    }
    let st = sims[3].reduction_status();
    println!("adaptive basis {} directions {} reduced {:.3} estimate {:.4}", st.basis_size, st.error_directions, st.reduced_fraction, st.error_estimate);
    println!(
        "adaptive / trained 16 {:.2}, / cubature 16 {:.2}, / full {:.2} (fastest)",
        times[3][0] / times[1][0],
        times[3][0] / times[2][0],
        times[3][0] / times[0][0]
    );
    println!("cubature springs {}", sims[2].cubature_springs());
    println!("internal steps in the last step: full {}, adaptive {}", sims[0].internal_steps_last(), sims[3].internal_steps_last());
}
