//! Several holders (`nHolders`; `docs/method.md`, section 9): the split of
//! the held nodes, the refusals, each holder's force and torque adding up
//! to the momentum balance, every mode kept equal to full space with the
//! holders moving apart, the custom pattern naming the top corners equal
//! to them bit for bit, and the reduced model with and without the
//! holders' constraint modes against full space (a sheet held at its two
//! top corners, pulled taut and swung).

use modal_mass_spring::physics::setup::grid::paper;
use modal_mass_spring::physics::*;

/// The paper's 2D sheet of `n` x `n` nodes (0.1 m, 0.01 kg, 50 N/m, shear
/// springs) hung from its top corners, each by its own holder.
fn corners(n: usize, dim: usize) -> Grid {
    Grid { holders: 2, ..paper(n, n, dim, FixedNodes::TopCorners) }
}

fn loads(modes: usize, alpha: f64) -> Loads {
    Loads { damping_alpha: alpha, ..Loads::physical(modes) }
}

/// `n` load vectors with a static correction, prepared for the holders' motion.
fn reduced_with(n: usize, constraint_modes: bool) -> Settings {
    let mut s = Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, n);
    s.mode_selection = ModeSelection::Load;
    s.static_correction = true;
    s.anchor_motion = true;
    s.constraint_modes = constraint_modes;
    s
}

/// 8 load vectors with a static correction, prepared for the holders' motion.
fn reduced(constraint_modes: bool) -> Settings {
    reduced_with(8, constraint_modes)
}

fn full() -> Settings {
    Settings::new(Reduction::Full, Integrator::NewmarkExplicit, 0)
}

/// The second holder's target.
fn move_second(sim: &mut Simulator, to: [f64; 3]) {
    sim.edit_loads(&mut |l| l.holders[0].anchor = to).unwrap();
}

fn largest_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

fn norm(v: &[f64; 3]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

#[test]
fn held_nodes_split_by_column() {
    let mut g = corners(5, 2);
    let s = g.build().unwrap();
    assert_eq!(s.holders.len(), 2);
    assert_eq!((s.holders[0].slots.len(), s.holders[1].slots.len()), (1, 1));
    assert_eq!(s.holders[1].pivot, [0.4, 0.0, 0.0]);
    g.fixed_nodes = FixedNodes::TopRow;
    let s = g.build().unwrap();
    // 5 columns, 2 holders: columns 0-2 and 3-4.
    assert_eq!((s.holders[0].slots.len(), s.holders[1].slots.len()), (3, 2));
    assert_eq!(s.holders[1].pivot, [0.30000000000000004, 0.0, 0.0]);
    // The spring between the halves joins two holders: it stays in the scene.
    let between = s.springs.iter().filter(|sp| sp.a >= s.n_free && sp.b >= s.n_free).count();
    assert_eq!(between, 1);
    g.holders = 1;
    assert!(g.build().unwrap().springs.iter().all(|sp| sp.a < s.n_free || sp.b < s.n_free));
}

#[test]
fn bad_patterns_are_refused() {
    let mut g = corners(4, 2);
    g.holders = 3;
    assert!(matches!(g.build(), Err(PhysicsError::Holders(HolderProblem::TooFewColumns { holders: 3, columns: 2 }))));
    g.fixed_nodes = FixedNodes::Custom;
    g.holder_of_node = vec![0; 16];
    assert_eq!(g.build().unwrap_err(), PhysicsError::Holders(HolderProblem::NoHeldNode));
    g.holder_of_node[0] = 1;
    g.holder_of_node[3] = 2;
    assert_eq!(g.build().unwrap_err(), PhysicsError::Holders(HolderProblem::NoNode { holder: 3 }));
    g.holder_of_node[5] = 4;
    assert!(matches!(g.build(), Err(PhysicsError::Holders(HolderProblem::IdTooLarge { row: 1, col: 1, id: 4, holders: 3 }))));
    g.holder_of_node.pop();
    assert!(matches!(g.build(), Err(PhysicsError::Holders(HolderProblem::PatternLength { len: 15, expected: 16 }))));
    g.holders = 5;
    assert!(matches!(g.build(), Err(PhysicsError::Invalid { quantity: Quantity::Holders, .. })));
    // A holder the scene does not have may not move; the loads are kept.
    let mut sim = Simulator::new(corners(4, 2).build().unwrap(), &full(), &loads(0, 0.0)).unwrap();
    let e = sim.edit_loads(&mut |l| l.holders[1].anchor = [0.1, 0.0, 0.0]).unwrap_err();
    assert_eq!(e, PhysicsError::Holders(HolderProblem::Absent { holder: 3, holders: 2 }));
    assert_eq!(sim.loads().holders[1].anchor, [0.0; 3]);
}

#[test]
fn custom_corners_are_the_top_corners_bit_for_bit() {
    let mut custom = corners(6, 2);
    custom.fixed_nodes = FixedNodes::Custom;
    custom.holder_of_node = vec![0; 36];
    custom.holder_of_node[0] = 1;
    custom.holder_of_node[5] = 2;
    for settings in [full(), reduced(true)] {
        let n = settings.n_modes;
        let mut a = Simulator::new(corners(6, 2).build().unwrap(), &settings, &loads(n, 1.0)).unwrap();
        let mut b = Simulator::new(custom.build().unwrap(), &settings, &loads(n, 1.0)).unwrap();
        for k in 0..40 {
            let to = [0.002 * k as f64, 0.001 * k as f64, 0.0];
            move_second(&mut a, to);
            move_second(&mut b, to);
            a.do_step(0.01).unwrap();
            b.do_step(0.01).unwrap();
        }
        assert_eq!(a.positions(), b.positions());
        assert_eq!(a.holder_force(1), b.holder_force(1));
    }
}

/// The full space of `grid` and its modal space with every mode kept,
/// prepared for the holders' motion and turns, lightly damped.
fn full_and_every_mode(grid: &Grid) -> (Simulator, Simulator) {
    let dofs = grid.build().unwrap().n_dofs();
    let mut all = Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, dofs);
    all.anchor_motion = true;
    all.anchor_rotation = true;
    let f = Simulator::new(grid.build().unwrap(), &full(), &loads(0, 0.5)).unwrap();
    let m = Simulator::new(grid.build().unwrap(), &all, &loads(dofs, 0.5)).unwrap();
    (f, m)
}

/// The holders' forces add up to the momentum balance, and with every mode
/// kept the modal space is the full space's to round-off while the
/// holders move apart and turn.
#[test]
fn every_mode_kept_is_full_space_and_the_forces_add_up() {
    for dim in [2, 3] {
        let grid = corners(5, dim);
        let (mut f, mut m) = full_and_every_mode(&grid);
        let (mut worst, mut worst_force, mut sum_error) = (0.0f64, 0.0f64, 0.0f64);
        for k in 0..60 {
            let t = 0.01 * k as f64;
            for sim in [&mut f, &mut m] {
                sim.edit_loads(&mut |l| {
                    l.holders[0].anchor = [0.05 * t, -0.03 * t, 0.02 * t];
                    l.holders[0].rotation = [0.0, 0.0, 0.3 * t];
                    l.anchor = [0.0, 0.01 * t, 0.0];
                })
                .unwrap();
                sim.do_step(0.01).unwrap();
                let total = sim.anchor_force();
                let sum: [f64; 3] = std::array::from_fn(|i| sim.holder_force(0)[i] + sim.holder_force(1)[i]);
                sum_error = sum_error.max(norm(&std::array::from_fn(|i| sum[i] - total[i])) / norm(&total));
            }
            worst = worst.max(largest_difference(f.positions(), m.positions()));
            for k in 0..2 {
                let (a, b) = (f.holder_force(k), m.holder_force(k));
                worst_force = worst_force.max(norm(&std::array::from_fn(|i| a[i] - b[i])));
            }
        }
        println!("{dim}D, every mode: positions within {worst:.2e} m, holder forces within {worst_force:.2e} N, sums within {sum_error:.1e}");
        assert!(worst < 1e-9, "{dim}D: {worst}");
        assert!(worst_force < 1e-8, "{dim}D: {worst_force}");
        assert!(sum_error < 1e-12, "{dim}D: {sum_error}");
    }
}

/// A net held at its four corners by four holders that move and turn on
/// their own: every mode kept, the modal space is the full space's to
/// round-off, and the four forces add up to the momentum balance.
#[test]
fn four_holders_at_the_corners() {
    let mut grid = Grid { holders: 4, fixed_nodes: FixedNodes::Custom, ..paper(5, 5, 3, FixedNodes::TopRow) };
    grid.holder_of_node = vec![0; 25];
    (grid.holder_of_node[0], grid.holder_of_node[4], grid.holder_of_node[20], grid.holder_of_node[24]) = (1, 2, 3, 4);
    let (mut f, mut m) = full_and_every_mode(&grid);
    let (mut worst, mut sum_error) = (0.0f64, 0.0f64);
    for k in 0..50 {
        let t = 0.01 * k as f64;
        for sim in [&mut f, &mut m] {
            sim.edit_loads(&mut |l| {
                l.anchor = [-0.02 * t, 0.0, 0.01 * t];
                for (j, h) in l.holders.iter_mut().enumerate() {
                    let s = 1.0 + j as f64;
                    h.anchor = [0.02 * s * t, -0.01 * t, 0.03 * (s * t).sin()];
                    h.rotation = [0.0, 0.1 * s * t, 0.2 * t];
                }
            })
            .unwrap();
            sim.do_step(0.01).unwrap();
            let total = sim.anchor_force();
            let sum: [f64; 3] = std::array::from_fn(|i| (0..4).map(|k| sim.holder_force(k)[i]).sum());
            sum_error = sum_error.max(norm(&std::array::from_fn(|i| sum[i] - total[i])) / norm(&total));
        }
        worst = worst.max(largest_difference(f.positions(), m.positions()));
    }
    println!("four holders, every mode: positions within {worst:.2e} m, forces add up within {sum_error:.1e}");
    assert!(worst < 1e-9 && sum_error < 1e-12, "{worst} {sum_error}");
}

/// Holder 2 moved `to` over 1 s, then everything settles under damping:
/// positions and each holder's force of `settings` against full space,
/// relative to the weight per holder.
fn settled(grid: &Grid, settings: &Settings, to: [f64; 3]) -> (Vec<f64>, [[f64; 3]; 2]) {
    let n = settings.n_modes;
    let mut sim = Simulator::new(grid.build().unwrap(), settings, &loads(n, 6.0)).unwrap();
    for k in 1..=100 {
        move_second(&mut sim, to.map(|c| c * k as f64 / 100.0));
        sim.do_step(0.01).unwrap();
    }
    for _ in 0..800 {
        sim.do_step(0.01).unwrap();
    }
    (sim.positions().to_vec(), [sim.holder_force(0), sim.holder_force(1)])
}

#[test]
fn a_reduced_model_with_constraint_modes_holds_the_stretched_sheet() {
    let grid = corners(10, 2);
    let weight = 0.01 * 98.0 * 9.81 / 2.0;
    // (holder 2's move, basis size, tolerance on positions [m] and on each holder's force [share of the weight per holder]);
    // the 8 vectors with the move upwards are printed, not held to 2 %: at rest they are already 2.2 % off.
    let cases = [
        ([0.0, 0.0, 0.0], 8, None),
        ([0.03, 0.0, 0.0], 8, Some((0.01, 0.02))),
        ([0.18, 0.0, 0.0], 8, Some((0.03, 0.06))),
        ([0.0, 0.05, 0.0], 8, None),
        ([0.0, 0.05, 0.0], 12, Some((0.01, 0.02))),
    ];
    for (to, n, within) in cases {
        let (x_full, f_full) = settled(&grid, &full(), to);
        let sum: [f64; 3] = std::array::from_fn(|i| f_full[0][i] + f_full[1][i]);
        assert!((sum[1] + 2.0 * weight).abs() < 1e-6 * weight, "{sum:?}");
        for constraint_modes in [true, false] {
            let (x, f) = settled(&grid, &reduced_with(n, constraint_modes), to);
            let dx = largest_difference(&x, &x_full);
            let df = (0..2).map(|k| norm(&std::array::from_fn(|i| f[k][i] - f_full[k][i])) / weight).fold(0.0, f64::max);
            let total: [f64; 3] = std::array::from_fn(|i| f[0][i] + f[1][i]);
            println!(
                "holder 2 moved {to:?} m, {n} load vectors + static correction{}: positions within {dx:.2e} m, holder forces within {:.2} % of the weight per holder",
                if constraint_modes { " + constraint modes" } else { "" },
                100.0 * df
            );
            assert!((total[1] + 2.0 * weight).abs() < 1e-6 * weight && total[0].abs() < 1e-6 * weight, "{total:?}");
            if let (true, Some((m, share))) = (constraint_modes, within) {
                assert!(dx < m && df < share, "{to:?}: {dx} m, {df}");
            }
        }
    }
}

/// A snapshot taken while holder 2 moves and turns resumes the run bit for
/// bit, and a step the second holder cannot follow is discarded with the
/// state kept.
#[test]
fn snapshots_resume_and_a_jerk_is_discarded() {
    for settings in [full(), reduced(true)] {
        let n = settings.n_modes;
        let mut a = Simulator::new(corners(6, 3).build().unwrap(), &settings, &loads(n, 0.5)).unwrap();
        let drive = |sim: &mut Simulator, k: usize| {
            let t = 0.01 * k as f64;
            sim.edit_loads(&mut |l| {
                l.holders[0].anchor = [0.05 * t.sin(), 0.02 * t, -0.03 * t];
                l.holders[0].rotation = [0.1 * t, 0.0, 0.4 * t];
            })
            .unwrap();
            sim.do_step(0.01).unwrap();
        };
        for k in 0..20 {
            drive(&mut a, k);
        }
        let saved = a.snapshot();
        let mut b = Simulator::new(corners(6, 3).build().unwrap(), &settings, &loads(n, 0.5)).unwrap();
        b.restore(&saved).unwrap();
        for k in 20..40 {
            drive(&mut a, k);
            drive(&mut b, k);
        }
        assert_eq!(a.positions(), b.positions());
        assert_eq!(a.velocities(), b.velocities());
        assert_eq!(a.holder_force(1), b.holder_force(1));
        let before = a.snapshot();
        a.edit_loads(&mut |l| l.holders[0].anchor = [10.0, 0.0, 0.0]).unwrap();
        let e = a.do_step(0.01).unwrap_err();
        assert!(matches!(e, PhysicsError::StepFailed { cause: StepFailure::HolderTooFast { holder: 2, .. }, .. }), "{e}");
        assert_eq!(a.snapshot().state, before.state);
    }
}

/// A trained basis trains on the holders pulled apart too (a run per holder
/// and axis either way), and with 2 holders it follows the full space
/// through a pull and a swing.
#[test]
fn a_trained_basis_trains_on_the_holders_apart() {
    let grid = corners(8, 2);
    let mut trained = reduced(true);
    trained.mode_selection = ModeSelection::Trained;
    trained.n_modes = 10;
    let scene = grid.build().unwrap();
    let cases = modal_mass_spring::physics::setup::trained_basis::program(&scene, &loads(10, 0.0), &trained).unwrap();
    let apart: Vec<&str> = cases.iter().filter(|c| c.holder.is_some()).map(|c| c.label.as_str()).collect();
    assert_eq!(apart.len(), 4, "{apart:?}");
    let mut f = Simulator::new(grid.build().unwrap(), &full(), &loads(0, 1.0)).unwrap();
    let mut m = Simulator::new(grid.build().unwrap(), &trained, &loads(10, 1.0)).unwrap();
    let mut worst = 0.0f64;
    for k in 0..150 {
        let t = 0.01 * k as f64;
        for sim in [&mut f, &mut m] {
            sim.edit_loads(&mut |l| {
                l.holders[0].anchor = [0.05 * t.min(1.0), 0.03 * (3.0 * t).sin(), 0.0];
                l.anchor = [0.0, -0.03 * (3.0 * t).sin(), 0.0];
            })
            .unwrap();
            sim.do_step(0.01).unwrap();
        }
        worst = worst.max(largest_difference(f.positions(), m.positions()));
    }
    println!("trained basis of 10 vectors, holders pulled 5 cm apart and swung: positions within {worst:.2e} m of full space");
    assert!(worst < 0.03, "{worst}");
}

/// The sheet of the two-hands picture in 2D: pulled taut (each hand 5 % of
/// the width outward over 1 s), then the hands swing in opposite directions
/// (±3 cm vertically at 1 Hz) for 2 s, lightly damped: load vectors with a
/// static correction, with and without the constraint modes, against full
/// space; the largest distance of a node and of each hand's force over the run.
#[test]
fn pulled_taut_and_swung_by_two_hands() {
    let grid = corners(10, 2);
    let weight = 0.01 * 98.0 * 9.81 / 2.0;
    let drive = |sim: &mut Simulator, t: f64| {
        let pull = 0.045 * (t.min(1.0) * std::f64::consts::FRAC_PI_2).sin();
        let swing = if t > 1.0 { 0.03 * (2.0 * std::f64::consts::PI * (t - 1.0)).sin() } else { 0.0 };
        sim.edit_loads(&mut |l| {
            l.anchor = [-pull, swing, 0.0];
            l.holders[0].anchor = [pull, -swing, 0.0];
        })
        .unwrap();
        sim.do_step(0.01).unwrap();
    };
    let mut reference = Simulator::new(grid.build().unwrap(), &full(), &loads(0, 0.5)).unwrap();
    let mut full_run = Vec::new();
    for k in 0..300 {
        drive(&mut reference, 0.01 * (k + 1) as f64);
        full_run.push((reference.positions().to_vec(), [reference.holder_force(0), reference.holder_force(1)]));
    }
    let mut errors = std::collections::BTreeMap::new();
    for n in [8, 16, 32] {
        for constraint_modes in [true, false] {
            let mut m = Simulator::new(grid.build().unwrap(), &reduced_with(n, constraint_modes), &loads(n, 0.5)).unwrap();
            let (mut dx, mut df) = (0.0f64, 0.0f64);
            for (k, (x, f)) in full_run.iter().enumerate() {
                drive(&mut m, 0.01 * (k + 1) as f64);
                dx = dx.max(largest_difference(x, m.positions()));
                for h in 0..2 {
                    let b = m.holder_force(h);
                    df = df.max(norm(&std::array::from_fn(|i| f[h][i] - b[i])) / weight);
                }
            }
            println!(
                "pulled taut and swung, {n} load vectors + static correction{}: positions within {dx:.2e} m, each hand's force within {:.1} % of the weight per hand",
                if constraint_modes { " + constraint modes" } else { "" },
                100.0 * df
            );
            errors.insert((n, constraint_modes), (dx, df));
        }
    }
    // The constraint modes carry the hands' pull: with them each hand's force is closer at every size
    // (the swing itself needs more modes: the positions are off by centimetres below 32 vectors either way).
    for n in [8, 16, 32] {
        let (with, without) = (errors[&(n, true)], errors[&(n, false)]);
        assert!(with.1 < 0.8 * without.1, "{n}: {with:?} {without:?}");
    }
    assert!(errors[&(32, true)].0 < 0.04, "{errors:?}");
}

/// Every scheme steps a sheet whose second holder moves and turns (the
/// trigonometric one too: only holder 1's turning adds the Coriolis force
/// it cannot take), and they agree.
#[test]
fn every_scheme_moves_the_second_holder() {
    let grid = corners(6, 3);
    let mut runs = Vec::new();
    for (reduction, integrator) in [
        (Reduction::Full, Integrator::NewmarkExplicit),
        (Reduction::Full, Integrator::NewmarkImplicit),
        (Reduction::Modal, Integrator::NewmarkExplicit),
        (Reduction::Modal, Integrator::NewmarkImplicit),
        (Reduction::Modal, Integrator::Trigonometric),
    ] {
        let mut s = if reduction == Reduction::Full { full() } else { reduced_with(24, true) };
        s.integrator = integrator;
        s.max_internal_step = 1e-3;
        let n = s.n_modes;
        let mut sim = Simulator::new(grid.build().unwrap(), &s, &loads(n, 1.0)).unwrap();
        for k in 0..50 {
            let t = 0.01 * k as f64;
            sim.edit_loads(&mut |l| {
                l.holders[0].anchor = [0.03 * t, 0.02 * (2.0 * t).sin(), -0.02 * t];
                l.holders[0].rotation = [0.0, 0.2 * t, 0.3 * t];
            })
            .unwrap();
            sim.do_step(0.01).unwrap_or_else(|e| panic!("{reduction:?} {integrator:?}: {e}"));
        }
        runs.push((format!("{reduction:?} {integrator:?}"), sim.positions().to_vec()));
    }
    for (label, x) in &runs[1..] {
        let d = largest_difference(x, &runs[0].1);
        println!("{label}: {d:.2e} m from full explicit");
        assert!(d < 0.02, "{label}: {d}");
    }
}

/// Cubature forces with the holders moving apart: the springs at the
/// moving holders are added exactly, so the cubature stays within its
/// tolerance's reach of the exact reduced model; with every holder in
/// place it is the cubature of one holder.
#[test]
fn cubature_forces_follow_the_holders() {
    let grid = corners(10, 2);
    let exact = reduced_with(12, true);
    let mut cubature = exact.clone();
    cubature.force_evaluation = ForceEvaluation::Cubature;
    let mut a = Simulator::new(grid.build().unwrap(), &exact, &loads(12, 1.0)).unwrap();
    let mut b = Simulator::new(grid.build().unwrap(), &cubature, &loads(12, 1.0)).unwrap();
    let (mut dx, mut df, mut scale) = (0.0f64, 0.0f64, 0.0f64);
    for k in 0..200 {
        let t = 0.01 * k as f64;
        for sim in [&mut a, &mut b] {
            sim.edit_loads(&mut |l| {
                l.holders[0].anchor = [0.1 * t.min(1.0), 0.03 * (2.0 * t).sin(), 0.0];
                l.anchor = [-0.05 * t.min(1.0), 0.0, 0.0];
            })
            .unwrap();
            sim.do_step(0.01).unwrap();
        }
        dx = dx.max(largest_difference(a.positions(), b.positions()));
        let (fa, fb) = (a.holder_force(1), b.holder_force(1));
        df = df.max(norm(&std::array::from_fn(|i| fa[i] - fb[i])));
        scale = scale.max(norm(&fa));
    }
    println!("cubature ({} springs) against exact forces, 12 vectors, holders pulled 15 cm apart and swung: positions within {dx:.2e} m, holder 2's force within {:.2} % of its largest", b.cubature_springs(), 100.0 * df / scale);
    assert!(dx < 5e-3 && df < 0.03 * scale, "{dx} {df}");
}
