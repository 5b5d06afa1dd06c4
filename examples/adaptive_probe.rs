//! The adaptive reduction against full space on cloth N x N (undamped,
//! explicit, 0.01 s steps, 0.6 s), with gravity set after set-up to the
//! canonical load, a load inside the training program it never ran, and
//! two far outside it (and `turned`: the canonical load, gravity turned sideways in
//! the sheet's plane at 0.25 s, as the study's `-turned` scenes): E, errorEstimate, the share of steps reduced, the
//! basis size every 0.1 s, and the run time against full space
//! (`docs/method.md`, section 10).
//!
//! `cargo run --release --example adaptive_probe -- [N] [TOLERANCE]` (`ONLY=case` runs one case,
//! `STEPS=k` k steps instead of 60, `STEP=h` steps of h s instead of 0.01, `CUBATURE=1` cubature
//! forces, `TRACE=case` every step with its forceResidual, `FINE=h` full space at internal steps of h, `DAMPED=1` the scene's damping)

use modal_mass_spring::canonical_scenes;
use modal_mass_spring::physics::*;
use std::time::Instant;
fn gravity(scale: f64, x_deg: f64, z_deg: f64) -> [f64; 3] {
    let (a, b) = (x_deg.to_radians(), z_deg.to_radians());
    let g = [9.81 * b.sin(), -9.81 * b.cos(), 0.0];
    let g = [g[0], g[1] * a.cos(), g[1] * a.sin()];
    [scale * g[0], scale * g[1], scale * g[2]]
}
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    #[allow(non_snake_case)]
    let H: f64 = std::env::var("STEP").ok().map_or(0.01, |v| v.parse().unwrap());
    let nx: usize = args.get(0).map_or(30, |v| v.parse().unwrap());
    let tol: f64 = args.get(1).map_or(0.01, |v| v.parse().unwrap());
    let mut base = canonical_scenes::cloth(nx, nx);
    if std::env::var("DAMPED").is_err() {
        base.loads.damping_alpha = 0.0;
        base.loads.damping_beta = 0.0;
    }
    let cases = [
        ("canonical", gravity(1.0, 0.0, 0.0)),
        ("inside", gravity(0.85, 10.0, 10.0)),
        ("sideways", [9.81, 0.0, 0.0]),
        ("2g70", gravity(2.0, 70.0, 0.0)),
        ("point", gravity(1.0, 0.0, 0.0)),
        ("turned", gravity(1.0, 0.0, 0.0)),
    ];
    let weight = base.grid.node_mass * (nx * nx) as f64 * 9.81;
    let fine: f64 = std::env::var("FINE").ok().map_or(0.0, |v| v.parse().unwrap());
    let mut full_settings = Settings::new(Reduction::Full, Integrator::NewmarkExplicit, 0);
    if fine > 0.0 {
        full_settings.max_internal_step = fine;
    }
    let full = base.with_settings(full_settings);
    let mut ad_settings = Settings { error_tolerance: tol, ..Settings::new(Reduction::Adaptive, Integrator::NewmarkExplicit, 2) };
    if std::env::var("CUBATURE").is_ok() {
        ad_settings.force_evaluation = ForceEvaluation::Cubature;
    }
    let ad = base.with_settings(ad_settings);
    let only = std::env::var("ONLY").ok();
    for (name, g) in cases {
        if only.as_deref().is_some_and(|o| o != name) {
            continue;
        }
        let mut f = full.simulator().unwrap();
        let t0 = Instant::now();
        let mut m = ad.simulator().unwrap();
        let setup = t0.elapsed().as_secs_f64();
        let st = m.reduction_status();
        println!("{name:10} basis {} error directions {} cubature springs {}", st.basis_size, st.error_directions, m.cubature_springs());
        let x0 = f.positions().to_vec();
        // A tenth of the sheet's weight on the load node, sideways and out of the plane: no program has it.
        let p = if name == "point" { [0.1 * weight, 0.0, 0.1 * weight] } else { [0.0; 3] };
        for s in [&mut f, &mut m] {
            let l = Loads { gravity: g, point_load: p, ..s.loads().clone() };
            s.set_loads(&l).unwrap();
        }
        let (mut num, mut den) = (0.0, 0.0);
        let (mut tf, mut tm) = (0.0, 0.0);
        let steps: usize = std::env::var("STEPS").ok().map_or(60, |v| v.parse().unwrap());
        let starts = [f.snapshot(), m.snapshot()];
        // Step k of the `turned` case turns gravity sideways in the sheet's plane at 0.25 s.
        let turns_at = |k: usize| name == "turned" && ((k - 1) as f64 * H - 0.25).abs() < 0.5 * H;
        for k in 1..=steps {
            if turns_at(k) {
                // Gravity turned sideways in the sheet's plane, as the study's `-turned` scenes do.
                for s in [&mut f, &mut m] {
                    let l = Loads { gravity: [9.81, 0.0, 0.0], ..s.loads().clone() };
                    s.set_loads(&l).unwrap();
                }
            }
            let t = Instant::now();
            f.do_step(H).unwrap();
            tf += t.elapsed().as_secs_f64();
            let t = Instant::now();
            m.do_step(H).unwrap();
            let dt = t.elapsed().as_secs_f64();
            tm += dt;
            let (xf, xm) = (f.positions().to_vec(), m.positions().to_vec());
            num += xf.iter().zip(&xm).map(|(a, b)| (a - b) * (a - b)).sum::<f64>();
            den += xf.iter().zip(&x0).map(|(a, b)| (a - b) * (a - b)).sum::<f64>();
            let st = m.reduction_status();
            let trace = std::env::var("TRACE").is_ok_and(|v| v == name);
            if trace {
                let e = xf.iter().zip(&xm).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
                let d = xf.iter().zip(&x0).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
                println!(
                    "  t {:.2} e {e:.4} d {d:.3} e/d {:.4} E {:.4} est {:.4} basis {} step {:.3} ms fr {:.3}",
                    k as f64 * H,
                    e / d,
                    (num / den).sqrt(),
                    st.error_estimate,
                    st.basis_size,
                    dt * 1e3,
                    m.force_residual()
                );
            }
            if k % 10 == 0 {
                println!(
                    "{name:10} t {:.2} E {:.4} est {:.4} ratio {:.2} reduced {:.3} basis {}",
                    k as f64 * H,
                    (num / den).sqrt(),
                    st.error_estimate,
                    st.error_estimate / (num / den).sqrt(),
                    st.reduced_fraction,
                    st.basis_size
                );
            }
        }
        println!("internal steps full {} adaptive {}", f.internal_steps_last(), m.internal_steps_last());
        println!("{name:10} set-up {setup:.2} s, full {tf:.3} s, adaptive {tm:.3} s ({:.1}x)", tf / tm);
        // The same runs again from the start, each alone (as a user runs one; the two interleaved share the caches).
        let mut alone = [0.0; 2];
        for ((s, start), t) in [&mut f, &mut m].into_iter().zip(&starts).zip(&mut alone) {
            s.restore(start).unwrap();
            let t0 = Instant::now();
            for k in 1..=steps {
                if turns_at(k) {
                    let l = Loads { gravity: [9.81, 0.0, 0.0], ..s.loads().clone() };
                    s.set_loads(&l).unwrap();
                }
                s.do_step(H).unwrap();
            }
            *t = t0.elapsed().as_secs_f64();
        }
        println!("{name:10} each alone: full {:.4} s, adaptive {:.4} s ({:.1}x)", alone[0], alone[1], alone[0] / alone[1]);
    }
}
