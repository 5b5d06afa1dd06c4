//! The point load (loadX, loadY, loadZ on node (loadRow, loadColumn)) and
//! the anchor force (`docs/method.md`, section 8): force balance at rest in
//! full and modal space, the modal space with every mode against the full
//! space under a load switched on mid-run, and the FMI interface (refusals,
//! Step Mode).

use crate::common;

use common::*;
use modal_mass_spring::canonical_scenes;
use modal_mass_spring::fmi::variables::vr;
use modal_mass_spring::physics::*;

/// 2 N along -y and 1 N along x, as the tests apply it.
const LOAD: [f64; 3] = [1.0, -2.0, 0.0];

/// The paper's 2D scene (10 x 10, top row held) with `solver`, the point
/// load on its default load node (row 9, column 5) and mass-proportional
/// damping `alpha`.
fn loaded(solver: Settings, alpha: f64) -> (Simulator, f64) {
    let mut setup = canonical_scenes::canonical("paper-2d-top-row").unwrap().with_settings(solver);
    assert_eq!(setup.loads.load_node, Some(9 * 10 + 5), "the default load node is the middle of the bottom row");
    setup.loads.point_load = LOAD;
    setup.loads.damping_alpha = alpha;
    let sim = setup.simulator().unwrap();
    let weight = sim.scene().free_mass() * 9.81;
    (sim, weight)
}

/// |anchor force - (weight + load)| / |weight + load| after `seconds` of
/// damped motion, and the kinetic energy left.
fn balance(sim: &mut Simulator, weight: f64, seconds: f64) -> (f64, f64) {
    for _ in 0..(seconds / 0.01).round() as usize {
        sim.do_step(0.01).unwrap();
    }
    let want = [LOAD[0], LOAD[1] - weight, 0.0];
    let got = sim.anchor_force();
    let err = (0..3).map(|i| (got[i] - want[i]).powi(2)).sum::<f64>().sqrt();
    let norm = want.iter().map(|w| w * w).sum::<f64>().sqrt();
    (err / norm, sim.kinetic_energy())
}

/// Mass-proportional damping that takes the slowest mode of the scene near
/// critical damping (its frequency is about 3.5 rad/s), so every mode
/// settles within seconds.
const ALPHA: f64 = 8.0;

#[test]
fn at_rest_the_anchor_force_is_the_weight_plus_the_point_load() {
    let dofs = 180;
    for (label, solver) in [
        ("full space", Settings::new(Reduction::Full, Integrator::NewmarkExplicit, 0)),
        ("modal space, every mode", Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, dofs)),
        ("full space, implicit", Settings::new(Reduction::Full, Integrator::NewmarkImplicit, 0)),
    ] {
        let (mut sim, weight) = loaded(solver, ALPHA);
        let (rel, kinetic) = balance(&mut sim, weight, 20.0);
        println!("{label}: relative error {rel:.3e}, kinetic energy {kinetic:.3e} J");
        assert!(rel < 1e-6, "{label}: anchor force off by {rel:e} of weight + load");
    }
}

/// Every mode kept, the modal space is the full space in other coordinates:
/// with the same internal steps the two runs agree to round-off, also when
/// the point load is switched on at t = 0.3 s (a step input).
#[test]
fn every_mode_matches_the_full_space_with_a_load_switched_on() {
    let run = |reduction| {
        let mut solver = Settings::new(reduction, Integrator::NewmarkExplicit, if reduction == Reduction::Modal { 180 } else { 0 });
        solver.max_internal_step = 2e-4; // below both stable steps: the same internal steps in both spaces
        let setup = canonical_scenes::canonical("paper-2d-top-row").unwrap().with_settings(solver);
        let mut sim = setup.simulator().unwrap();
        assert!(sim.max_stable_step() == 2e-4, "{reduction:?}: stable step {} below the bound", sim.max_stable_step());
        let mut trace = Vec::new();
        for k in 0..100 {
            if k == 30 {
                let mut loads = sim.loads().clone();
                loads.point_load = LOAD;
                sim.set_loads(&loads).unwrap();
            }
            sim.do_step(0.01).unwrap();
            trace.push((sim.positions().to_vec(), sim.anchor_force(), sim.load_node_position().unwrap()[..2].to_vec()));
        }
        trace
    };
    let (full, modal) = (run(Reduction::Full), run(Reduction::Modal));
    let rest = canonical_scenes::canonical("paper-2d-top-row").unwrap().grid.build().unwrap();
    let scale = rest.length_scale();
    let mut worst: f64 = 0.0;
    for (k, ((xf, af, nf), (xm, am, nm))) in full.iter().zip(&modal).enumerate() {
        let dx = xf.iter().zip(xm).fold(0.0f64, |m, (a, b)| m.max((a - b).abs())) / scale;
        worst = worst.max(dx);
        assert!(dx < 1e-9, "step {k}: positions differ by {dx:e} of the sheet size");
        let da = (0..3).map(|i| (af[i] - am[i]).abs()).fold(0.0, f64::max);
        assert!(da < 1e-6, "step {k}: anchor forces differ by {da:e} N");
        assert_eq!(nf, &xf[95 * 2..95 * 2 + 2].to_vec());
        assert_eq!(nm, &xm[95 * 2..95 * 2 + 2].to_vec());
    }
    println!("largest position difference over 1 s: {worst:.3e} of the sheet size");
    // The load moved the node: it is a real step input, not a no-op.
    let before = &full[29].2;
    let after = &full[99].2;
    assert!((after[0] - before[0]).abs() > 1e-4, "the point load did not move its node along x");
}

#[test]
fn a_point_load_needs_a_free_node_and_finite_values() {
    let setup = canonical_scenes::canonical("paper-2d-top-row").unwrap().with_settings(Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, 4));
    let mut sim = setup.simulator().unwrap();
    sim.do_step(0.01).unwrap();
    let before = sim.snapshot();
    let mut loads = sim.loads().clone();
    loads.point_load = [f64::NAN, 0.0, 0.0];
    assert!(matches!(sim.set_loads(&loads), Err(PhysicsError::Invalid { quantity: Quantity::PointLoad, .. })));
    loads.point_load = [0.0, 1.0, 0.0];
    loads.load_node = Some(3); // top row: held
    assert_eq!(sim.set_loads(&loads), Err(PhysicsError::LoadNode { node: Some(3), held: true }));
    loads.load_node = None;
    assert_eq!(sim.set_loads(&loads), Err(PhysicsError::LoadNode { node: None, held: false }));
    assert_eq!(sim.snapshot(), before, "a refused load leaves the state and the loads as they were");
    // A zero point load may sit anywhere.
    loads.point_load = [0.0; 3];
    assert!(sim.set_loads(&loads).is_ok());
}

/// The point load as a load pattern: with gravity zero, modeSelection =
/// load and staticCorrection work from the point load alone.
#[test]
fn the_point_load_alone_is_a_load_pattern() {
    let mut solver = Settings::new(Reduction::Modal, Integrator::NewmarkExplicit, 6);
    solver.mode_selection = ModeSelection::Load;
    solver.static_correction = true;
    solver.linearization = Linearization::Equilibrium;
    let mut setup = canonical_scenes::canonical("paper-2d-top-row").unwrap().with_settings(solver);
    setup.loads.gravity = [0.0; 3];
    assert_eq!(setup.simulator().err(), Some(PhysicsError::NoLoad));
    setup.loads.point_load = LOAD;
    setup.loads.damping_alpha = ALPHA;
    let mut sim = setup.simulator().unwrap();
    for _ in 0..2000 {
        sim.do_step(0.01).unwrap();
    }
    // Linearized at the equilibrium under the point load, the run starts at rest away from it and settles
    // there, where the holder carries the load alone (gravity is zero).
    let f = sim.anchor_force();
    assert!((f[0] - LOAD[0]).abs() < 1e-9 && (f[1] - LOAD[1]).abs() < 1e-9, "anchor force {f:?}");
}

// ---- through the C ABI ----

/// `status` is fmi3Error with a logged message that contains `needle`.
#[test]
fn fmi_the_point_load_is_an_input_settable_in_step_mode() {
    let f = Fmu::new();
    assert_eq!(f.set_f64(vr::DAMPING_ALPHA, &[ALPHA]), OK);
    f.init();
    f.run(5, 0.01);
    let weight = 90.0 * 0.01 * 9.81;
    assert_eq!(f.set_f64(vr::LOAD_X, &[LOAD[0]]), OK, "{:?}", f.messages());
    assert_eq!(f.set_f64(vr::LOAD_Y, &[LOAD[1]]), OK);
    assert_eq!(f.f64s(vr::LOAD_X, 1), vec![LOAD[0]]);
    let node0 = f.f64s(vr::LOAD_NODE_X, 1)[0];
    f.run(300, 0.01);
    let node1 = f.f64s(vr::LOAD_NODE_X, 1)[0];
    assert!(node1 - node0 > 1e-4, "the load node moved along +x: {node0} -> {node1}");
    let positions = f.positions();
    assert_eq!(f.f64s(vr::LOAD_NODE_Y, 1)[0], positions[95 * 2 + 1]);
    assert_eq!(f.f64s(vr::LOAD_NODE_Z, 1)[0], 0.0, "z is 0 in 2D");
    let v = f.f64s(vr::LOAD_NODE_V_Y, 1)[0];
    assert!(v.is_finite());
    let fx = f.f64s(vr::ANCHOR_FORCE_X, 1)[0];
    let fy = f.f64s(vr::ANCHOR_FORCE_Y, 1)[0];
    println!("anchor force through the FMU after 3 s: ({fx}, {fy}), weight {weight}");
    assert!(fy < 0.0 && fy.is_finite() && fx.is_finite());
}

#[test]
fn fmi_non_finite_loads_are_refused_and_the_state_kept() {
    let f = Fmu::started();
    f.run(3, 0.01);
    let before = f.outputs();
    let state = f.snapshot();
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        f.refused(f.set_f64(vr::LOAD_X, &[bad]), "loadX = ");
        assert_eq!(f.f64s(vr::LOAD_X, 1), vec![0.0]);
    }
    assert_eq!(f.outputs(), before, "outputs unchanged");
    assert_eq!(f.snapshot(), state, "state unchanged");
    f.run(1, 0.01);
}

#[test]
fn fmi_the_load_node_must_be_a_free_node_of_the_grid() {
    let f = Fmu::new();
    f.refused(f.set_u64(vr::LOAD_ROW, 10), "loadRow = 10, loadColumn = 5 is outside the grid of ny = 10 rows");
    f.refused(f.set_u64(vr::LOAD_COLUMN, 10), "outside the grid");
    f.refused(f.set_u64(vr::LOAD_ROW, 9), "loadRow = 9, loadColumn = 5 is a held node (fixedNodes = top-row)");
    assert_eq!(f.get_u64(vr::LOAD_ROW), 0, "refused values are not stored");
    assert_eq!(f.get_u64(vr::LOAD_COLUMN), 5);
    // Growing the grid first lets a farther node be chosen; nx, ny and loadRow in one call too.
    let (vrs, values) = ([vr::NY, vr::LOAD_ROW], [20u64, 15u64]);
    assert_eq!(unsafe { modal_mass_spring::fmi::exports::fmi3SetUInt64(f.inst, vrs.as_ptr(), 2, values.as_ptr(), 2) }, OK, "{:?}", f.messages());
    assert_eq!(f.set_u64(vr::LOAD_ROW, 4), OK);
    f.init();
    f.expect_error(f.set_u64(vr::LOAD_ROW, 5), "fixed in Step Mode");
    // Top corners: the top edge (row ny - 1 from the bottom) between the corners is free.
    let g = Fmu::new();
    assert_eq!(g.set_i64(vr::FIXED_NODES, 2), OK);
    assert_eq!(g.set_u64(vr::LOAD_ROW, 9), OK, "{:?}", g.messages());
    g.refused(g.set_u64(vr::LOAD_COLUMN, 0), "is a held node");
}

/// The default load node is the middle of the bottom row of any grid:
/// loadRow counts from the bottom edge and loadColumn follows nx / 2 until
/// the host sets it. A column the host chose that a later nx leaves outside
/// the grid is refused at set-up.
#[test]
fn fmi_the_default_load_node_follows_the_grid() {
    let f = Fmu::new();
    let (vrs, values) = ([vr::NX, vr::NY], [5u64, 4u64]);
    assert_eq!(unsafe { modal_mass_spring::fmi::exports::fmi3SetUInt64(f.inst, vrs.as_ptr(), 2, values.as_ptr(), 2) }, OK);
    assert_eq!(f.get_u64(vr::LOAD_COLUMN), 2, "follows nx / 2");
    f.init();
    f.run(2, 0.01);
    let positions = f.positions();
    let node = 3 * 5 + 2; // row 3 from the top is the bottom row of 4
    assert_eq!(f.f64s(vr::LOAD_NODE_X, 1)[0], positions[node * 2]);
    assert_eq!(f.f64s(vr::LOAD_NODE_Y, 1)[0], positions[node * 2 + 1]);
    assert_eq!(f.set_f64(vr::LOAD_Y, &[-1.0]), OK, "{:?}", f.messages());
    f.run(1, 0.01);

    // Chosen by the host, the column stays; set-up refuses it outside a narrower grid.
    let g = Fmu::new();
    assert_eq!(g.set_u64(vr::LOAD_COLUMN, 7), OK);
    assert_eq!(g.set_u64(vr::NX, 20), OK);
    assert_eq!(g.get_u64(vr::LOAD_COLUMN), 7, "a chosen column does not follow nx");
    assert_eq!(g.set_u64(vr::NX, 6), OK);
    use modal_mass_spring::fmi::exports::{fmi3EnterInitializationMode, fmi3ExitInitializationMode};
    assert_eq!(unsafe { fmi3EnterInitializationMode(g.inst, false, 0.0, 0.0, false, 0.0) }, OK);
    let status = unsafe { fmi3ExitInitializationMode(g.inst) };
    let last = g.messages().last().cloned().unwrap_or_default();
    assert!(last.contains("must be a free node of the grid: loadRow = 0, loadColumn = 7 is outside the grid"), "{last}");
    assert_ne!(status, OK);
}
