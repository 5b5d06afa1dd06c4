//! Physics core checks: modes, frequencies, modal vs full space, weights,
//! sub-stepping, snapshots.

use modal_mass_spring::canonical_scenes;
use modal_mass_spring::physics::run::stiffness::StiffnessPattern;
use modal_mass_spring::physics::setup::modes::ModalBasis;
use modal_mass_spring::physics::setup::scene::Scene;
use modal_mass_spring::physics::*;

fn scene(name: &str) -> Grid {
    canonical_scenes::canonical(name).unwrap().grid
}

fn solver(reduction: Reduction, integrator: Integrator, n_modes: usize) -> Settings {
    Settings::new(reduction, integrator, n_modes)
}

fn simulator(p: &Grid, s: &Settings, loads: &Loads) -> Simulator {
    Simulator::new(p.build().unwrap(), s, loads).unwrap()
}

/// A state from the concatenation [y, y', y''].
fn state(flat: Vec<f64>) -> State {
    let n = flat.len() / 3;
    State {
        time: 0.0,
        y: flat[..n].to_vec(),
        v: flat[n..2 * n].to_vec(),
        a: flat[2 * n..].to_vec(),
        anchor: [0.0; 3],
        anchor_rate: [0.0; 3],
        rotation: [0.0; 3],
        spin: [0.0; 3],
        holders: Default::default(),
    }
}

fn basis(p: &Grid, r: usize) -> (Scene, StiffnessPattern, Vec<f64>, ModalBasis) {
    let s = p.build().unwrap();
    let pat = StiffnessPattern::new(&s);
    let mut k0 = vec![0.0; pat.nnz()];
    pat.add_tangent(&s, &s.rest, 1.0, &mut k0);
    let b = ModalBasis::lowest(&s, &pat, &k0, r).unwrap();
    (s, pat, k0, b)
}

#[test]
fn modes_are_mass_orthonormal_and_diagonalise_k() {
    for name in ["paper-2d-top-row", "paper-3d-sheet"] {
        let (s, pat, k0, b) = basis(&scene(name), 12);
        let (n, r) = (b.n, b.r);
        let mut kphi = vec![0.0; n];
        for i in 0..r {
            let col_i: Vec<f64> = (0..n).map(|k| b.phi[k * r + i]).collect();
            pat.sym_matvec(&k0, &col_i, &mut kphi);
            for j in 0..r {
                let mij: f64 = (0..n).map(|k| b.phi[k * r + j] * s.dof_mass[k] * col_i[k]).sum();
                let kij: f64 = (0..n).map(|k| b.phi[k * r + j] * kphi[k]).sum();
                let delta = if i == j { 1.0 } else { 0.0 };
                assert!((mij - delta).abs() < 1e-10, "{name}: Phi^T M Phi [{i},{j}] = {mij}");
                let want = delta * b.lambda[i];
                assert!((kij - want).abs() < 1e-9 * b.lambda[r - 1], "{name}: Phi^T K Phi [{i},{j}] = {kij}, want {want}");
            }
        }
        assert!(b.lambda.windows(2).all(|w| w[0] <= w[1]));
        assert!(b.lambda[0] > 0.0, "{name}: lowest eigenvalue {}", b.lambda[0]);
    }
}

/// Period from upward zero crossings of a sampled signal (linear interpolation).
fn measured_omega(samples: &[f64], dt: f64) -> f64 {
    let mut crossings = Vec::new();
    for k in 1..samples.len() {
        if samples[k - 1] < 0.0 && samples[k] >= 0.0 {
            let frac = samples[k - 1] / (samples[k - 1] - samples[k]);
            crossings.push((k as f64 - 1.0 + frac) * dt);
        }
    }
    assert!(crossings.len() >= 4, "too few oscillations: {}", crossings.len());
    let periods = (crossings.len() - 1) as f64;
    2.0 * std::f64::consts::PI * periods / (crossings[crossings.len() - 1] - crossings[0])
}

/// Starts `sim` at amplitude `eps` of mode j (zero gravity), records its coordinate.
fn oscillate(sim: &mut Simulator, flat: Vec<f64>, j: usize, dt: f64, steps: usize) -> Vec<f64> {
    let mut t = sim.loads().clone();
    t.gravity = [0.0; 3];
    sim.restore(&Snapshot { state: state(flat), loads: t, adaptive: None }).unwrap();
    (0..steps)
        .map(|_| {
            sim.do_step(dt).unwrap();
            sim.modal_coordinates()[j]
        })
        .collect()
}

#[test]
fn small_amplitude_full_space_frequencies_equal_mode_frequencies() {
    let p = scene("paper-2d-top-row");
    let r = 6;
    let (_, _, _, b) = basis(&p, r);
    let n = b.n;
    for j in [0, 5] {
        let eps = 1e-6;
        let omega = b.lambda[j].sqrt();
        let mut sim = simulator(&p, &solver(Reduction::Full, Integrator::NewmarkImplicit, r), &Loads::physical(r));
        assert!((sim.mode_frequencies()[j] - omega).abs() < 1e-12 * omega);
        let mut state = vec![0.0; 3 * n];
        for k in 0..n {
            state[k] = eps * b.phi[k * r + j];
            state[2 * n + k] = -b.lambda[j] * eps * b.phi[k * r + j];
        }
        // Shift so the signal oscillates about zero: start at a velocity peak.
        let period = 2.0 * std::f64::consts::PI / omega;
        let dt = period / 400.0;
        let samples = oscillate(&mut sim, state, j, dt, 400 * 8);
        let measured = measured_omega(&samples, dt);
        // Average-acceleration Newmark lengthens the period by (omega dt)^2 / 12.
        let expected = omega / (1.0 + (omega * dt).powi(2) / 12.0);
        assert!((measured - expected).abs() < 2e-4 * omega, "mode {j}: measured {measured}, modeFrequencies {omega}");
    }
}

fn run(p: &Grid, s: &Settings, t: &Loads, h: f64, steps: usize) -> Vec<Vec<f64>> {
    let mut sim = simulator(p, s, t);
    (0..steps)
        .map(|_| {
            sim.do_step(h).unwrap();
            sim.positions().to_vec()
        })
        .collect()
}

#[test]
fn all_modes_reproduce_full_space_to_round_off() {
    for (name, steps) in [("paper-2d-top-row", 50), ("paper-2d-top-corners", 50), ("paper-3d-sheet", 50)] {
        let p = scene(name);
        let n = p.build().unwrap().n_dofs();
        for integrator in [Integrator::NewmarkExplicit, Integrator::NewmarkImplicit] {
            let mut t = Loads::physical(n);
            t.damping_alpha = 0.3;
            t.damping_beta = 1e-3;
            let modal = run(&p, &solver(Reduction::Modal, integrator, n), &t, 0.01, steps);
            let full = run(&p, &solver(Reduction::Full, integrator, n), &t, 0.01, steps);
            let rest = simulator(&p, &solver(Reduction::Full, integrator, 0), &Loads::physical(0)).positions().to_vec();
            let disp = full.last().unwrap().iter().zip(&rest).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            let diff = modal.iter().flatten().zip(full.iter().flatten()).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(disp > 1e-3, "{name}: the sheet must move, max displacement {disp}");
            assert!(diff < 1e-9 * disp.max(1.0), "{name} {integrator:?}: modal vs full differ by {diff} (displacement {disp})");
        }
    }
}

#[test]
fn zero_weight_keeps_its_mode_at_rest() {
    let p = scene("paper-2d-top-row");
    for integrator in [Integrator::NewmarkExplicit, Integrator::NewmarkImplicit] {
        // Mode 1 is the vertical stretch that gravity drives hardest.
        let mut free = simulator(&p, &solver(Reduction::Modal, integrator, 4), &Loads::physical(4));
        let mut t = Loads::physical(4);
        t.mode_weights = vec![1.0, 0.0, 1.0, 1.0];
        let mut sim = simulator(&p, &solver(Reduction::Modal, integrator, 4), &t);
        for _ in 0..100 {
            free.do_step(0.01).unwrap();
            sim.do_step(0.01).unwrap();
            assert_eq!(sim.modal_coordinates()[1], 0.0);
        }
        assert!(free.modal_coordinates()[1].abs() > 1e-2);
        assert!(sim.modal_coordinates()[3].abs() > 1e-5);
    }
}

#[test]
fn weights_scale_the_response_but_not_the_frequency() {
    let p = scene("paper-2d-top-corners");
    let r = 4;
    let j = 2;
    let mut omegas = Vec::new();
    for w in [0.5, 1.0, 2.0] {
        let mut t = Loads::physical(r);
        t.mode_weights[j] = w;
        let mut sim = simulator(&p, &solver(Reduction::Modal, Integrator::NewmarkImplicit, r), &t);
        let omega = sim.mode_frequencies()[j];
        let mut state = vec![0.0; 3 * r];
        state[j] = 1e-6;
        state[2 * r + j] = -omega * omega * 1e-6;
        let dt = 2.0 * std::f64::consts::PI / omega / 400.0;
        let samples = oscillate(&mut sim, state, j, dt, 400 * 6);
        omegas.push((measured_omega(&samples, dt), omega));
    }
    for (measured, omega) in &omegas {
        assert!((measured - omegas[1].0).abs() < 1e-6 * omega, "{omegas:?}");
    }
    // Under gravity the static response of a mode scales with its weight.
    let mut sag = Vec::new();
    for w in [1.0, 2.0] {
        let mut t = Loads::physical(r);
        t.mode_weights = vec![w; r];
        t.damping_alpha = 5.0;
        let mut sim = simulator(&scene("paper-2d-top-row"), &solver(Reduction::Modal, Integrator::NewmarkImplicit, r), &t);
        for _ in 0..400 {
            sim.do_step(0.01).unwrap();
        }
        sag.push(sim.modal_coordinates()[1]);
    }
    let ratio = sag[1] / sag[0];
    assert!(ratio > 1.5 && ratio < 2.5, "doubling the weights scales the sag by {ratio}");
}

#[test]
fn explicit_diverges_without_substepping_and_is_stable_with_it() {
    let p = scene("paper-2d-top-row");
    let h = 1.0 / 60.0;
    let mut s = solver(Reduction::Full, Integrator::NewmarkExplicit, 0);
    s.substepping = false;
    let mut sim = simulator(&p, &s, &Loads::physical(0));
    let before = sim.positions().to_vec();
    let failed = (0..200).find_map(|_| sim.do_step(h).err());
    let e = failed.expect("explicit full-space run at dt = 1/60 s must diverge");
    assert!(e.to_string().contains("diverged"), "{e}");
    assert!(sim.positions().iter().all(|v| v.is_finite()));
    let _ = before;

    s.substepping = true;
    let mut sim = simulator(&p, &s, &Loads::physical(0));
    let mut max_energy = 0.0f64;
    for _ in 0..120 {
        sim.do_step(h).unwrap();
        max_energy = max_energy.max(sim.kinetic_energy());
    }
    assert!(sim.internal_steps_last() > 1);
    assert!(sim.positions().iter().all(|v| v.is_finite()));
    // kinetic energy stays below what gravity could give the sheet falling its own height
    assert!(max_energy < 0.9 * 9.81 * 1.0, "kinetic energy {max_energy}");
}

#[test]
fn failed_step_keeps_the_last_good_state() {
    let p = scene("paper-2d-top-row");
    let mut s = solver(Reduction::Full, Integrator::NewmarkExplicit, 0);
    s.substepping = false;
    let mut sim = simulator(&p, &s, &Loads::physical(0));
    loop {
        let snap = sim.snapshot();
        let pos = sim.positions().to_vec();
        if sim.do_step(0.05).is_err() {
            assert_eq!(sim.snapshot(), snap);
            assert_eq!(sim.positions(), &pos[..]);
            break;
        }
    }
}

#[test]
fn snapshot_restore_reproduces_bit_for_bit() {
    for red in [Reduction::Modal, Reduction::Full] {
        for integ in [Integrator::NewmarkExplicit, Integrator::NewmarkImplicit] {
            let p = scene("paper-3d-sheet");
            let s = solver(red, integ, 3);
            let mut a = simulator(&p, &s, &Loads::physical(3));
            for _ in 0..10 {
                a.do_step(0.01).unwrap();
            }
            let snap = a.snapshot();
            let mut b = simulator(&p, &s, &Loads::physical(3));
            b.restore(&snap).unwrap();
            for _ in 0..10 {
                a.do_step(0.01).unwrap();
                b.do_step(0.01).unwrap();
            }
            assert_eq!(a.positions(), b.positions());
            assert_eq!(a.velocities(), b.velocities());
            assert_eq!(a.time(), b.time());
        }
    }
}

/// The full space on 1, 2 and 3 threads: the same positions and
/// velocities, bit for bit (cloth 40 x 40 with its auxiliary springs: pieces
/// of node blocks, blocks gathered after the pieces, the springs past the grid's).
#[test]
fn full_space_threads_reproduce_one_thread_bit_for_bit() {
    for integ in [Integrator::NewmarkExplicit, Integrator::NewmarkImplicit] {
        let mut p = scene("cloth-3d");
        (p.columns, p.rows) = (40, 40);
        let runs: Vec<(Vec<f64>, Vec<f64>, f64)> = [1, 2, 3]
            .into_iter()
            .map(|threads| {
                let s = Settings { threads, ..solver(Reduction::Full, integ, 1) };
                let mut sim = simulator(&p, &s, &Loads::physical(1));
                for _ in 0..5 {
                    sim.do_step(0.01).unwrap();
                }
                (sim.positions().to_vec(), sim.velocities().to_vec(), sim.potential_energy())
            })
            .collect();
        for (threads, run) in [2, 3].into_iter().zip(&runs[1..]) {
            assert!(run.0 == runs[0].0 && run.1 == runs[0].1, "{integ:?}: {threads} threads leave the trajectory of 1");
            // The energy is summed per piece: round-off.
            assert!((run.2 - runs[0].2).abs() <= 1e-12 * runs[0].2.abs(), "{integ:?}: energy {} against {}", run.2, runs[0].2);
        }
    }
}

#[test]
fn gravity_change_changes_motion_and_modal_sags() {
    let p = scene("paper-2d-top-row");
    let mut sim = simulator(&p, &solver(Reduction::Modal, Integrator::NewmarkExplicit, 2), &Loads::physical(2));
    let y0 = sim.positions()[2 * 95 + 1];
    for _ in 0..50 {
        sim.do_step(0.01).unwrap();
    }
    assert!(sim.positions()[2 * 95 + 1] < y0 - 1e-3, "bottom row must sag");
}

#[test]
fn partial_eigensolver_matches_the_dense_one() {
    // Above the size where `lowest` switches to the shift-invert Krylov-Schur solver.
    let corners = Grid { columns: 24, rows: 18, ..scene("paper-2d-top-corners") };
    for p in [canonical_scenes::cloth(20, 20).grid, corners] {
        let s = p.build().unwrap();
        let pat = StiffnessPattern::new(&s);
        let mut k0 = vec![0.0; pat.nnz()];
        pat.add_tangent(&s, &s.rest, 1.0, &mut k0);
        let r = 10;
        let dense = ModalBasis::dense(&s, &pat, &k0, r).unwrap();
        let partial = ModalBasis::partial(&s, &pat, &k0, r).unwrap();
        let n = s.n_dofs();
        for j in 0..r {
            let (ld, lp) = (dense.lambda[j], partial.lambda[j]);
            assert!((ld - lp).abs() <= 1e-9 * ld.max(dense.lambda[r - 1] * 1e-6), "mode {j}: dense {ld}, partial {lp}");
            // An eigenpair, mass-normalised (shapes are compared through the
            // residual: the 3D sheet's lowest modes form a degenerate cluster).
            let phi: Vec<f64> = (0..n).map(|i| partial.phi[i * r + j]).collect();
            let mut kphi = vec![0.0; n];
            pat.sym_matvec(&k0, &phi, &mut kphi);
            let residual = (0..n).map(|i| (kphi[i] - lp * s.dof_mass[i] * phi[i]).powi(2)).sum::<f64>().sqrt();
            let scale = (0..n).map(|i| (kphi[i]).powi(2)).sum::<f64>().sqrt();
            assert!(residual <= 1e-8 * scale, "mode {j}: residual {residual:e} of {scale:e}");
            for m in 0..r {
                let dot: f64 = (0..n).map(|i| s.dof_mass[i] * phi[i] * partial.phi[i * r + m]).sum();
                let expected = if m == j { 1.0 } else { 0.0 };
                assert!((dot - expected).abs() < 1e-9, "phi_{j}^T M phi_{m} = {dot}");
            }
        }
    }
}

/// Communication steps as masters compute them: the difference of two
/// communication points `start + n h`, a few ulps off h (fmusim and fmpy's
/// `simulate_fmu` both do this; fmpy's container sends h itself).
fn master_steps(start: f64, h: f64, n: usize) -> Vec<f64> {
    (0..n).map(|k| (start + (k + 1) as f64 * h) - (start + k as f64 * h)).collect()
}

#[test]
fn internal_steps_do_not_depend_on_round_off_in_the_step_size() {
    let h = 0.01;
    // After t = 1 s, fmusim's 0.01 s steps are 0.01000000000000001 s: one ulp
    // above maxInternalStep = 0.01 s, which split each into two steps of half the size.
    let above = master_steps(1.0, h, 100);
    assert!(above.iter().any(|&s| s > h && (s / h).ceil() == 2.0), "the sequence must hold steps just above maxInternalStep");
    let below = master_steps(0.0, h, 100);
    assert!(below.iter().any(|&s| s < h));
    let p = scene("paper-2d-top-row");
    for (reduction, integrator, modes) in [
        (Reduction::Modal, Integrator::NewmarkExplicit, 2),
        (Reduction::Modal, Integrator::NewmarkImplicit, 8),
        (Reduction::Full, Integrator::NewmarkExplicit, 0),
    ] {
        let s = solver(reduction, integrator, modes);
        let mut exact = simulator(&p, &s, &Loads::physical(modes));
        let mut runs: Vec<Simulator> = (0..3).map(|_| simulator(&p, &s, &Loads::physical(modes))).collect();
        let sequences = [vec![h; 100], above.clone(), master_steps(1000.0, h, 100)];
        for k in 0..100 {
            exact.do_step(h).unwrap();
            for (sim, steps) in runs.iter_mut().zip(&sequences) {
                sim.do_step(steps[k]).unwrap();
                assert_eq!(sim.internal_steps_last(), exact.internal_steps_last(), "{reduction:?} {integrator:?}: step {k} of {}", steps[k]);
            }
        }
        let scale = exact.positions().iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let (x_exact, v_exact) = (exact.positions().to_vec(), exact.velocities().to_vec());
        for (sim, steps) in runs.iter_mut().zip(&sequences) {
            let diff = sim.positions().iter().zip(&x_exact).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            let dv = sim.velocities().iter().zip(&v_exact).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(
                diff <= 1e-12 * scale && dv <= 1e-10,
                "{reduction:?} {integrator:?}, steps from {}: positions {diff:e} m, velocities {dv:e} m/s apart",
                steps[1]
            );
        }
    }
}

/// The modal coordinates are computed when read, not after every step:
/// read once after several steps (or after a restore) they are the values
/// a run reading them after every step sees, bit for bit, in full space
/// (Φᵀ M (x − x*) of the reported modes), in the modal space and in an
/// adaptive run on both sides of its fall-back.
#[test]
fn modal_coordinates_read_late_are_those_of_the_state() {
    let cloth = canonical_scenes::cloth(30, 30);
    let settings = [
        Settings::new(Reduction::Full, Integrator::NewmarkExplicit, 4),
        Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, 4),
        Settings::new(Reduction::Adaptive, Integrator::NewmarkExplicit, 4),
    ];
    for s in settings {
        let mut every = cloth.with_settings(s.clone()).simulator().unwrap();
        let mut late = cloth.with_settings(s.clone()).simulator().unwrap();
        let start = late.snapshot();
        let mut seen = Vec::new();
        for k in 1..=24 {
            if k == 13 {
                // Gravity turned sideways: the adaptive run falls back to full space.
                for sim in [&mut every, &mut late] {
                    let loads = Loads { gravity: [9.81, 0.0, 0.0], ..sim.loads().clone() };
                    sim.set_loads(&loads).unwrap();
                }
            }
            every.do_step(0.01).unwrap();
            late.do_step(0.01).unwrap();
            seen.push(every.modal_coordinates().to_vec());
            if k % 6 == 0 {
                assert_eq!(late.modal_coordinates(), &seen[k - 1][..], "{:?} at step {k}", s.reduction);
            }
        }
        assert!(seen[23].iter().any(|q| *q != 0.0), "{:?}: the coordinates move", s.reduction);
        late.restore(&start).unwrap();
        late.do_step(0.01).unwrap();
        assert_eq!(late.modal_coordinates(), &seen[0][..], "{:?} after a restore", s.reduction);
    }
}
