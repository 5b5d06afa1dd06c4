//! Soak: a million communication steps of the packed FMU (its release
//! binary, loaded by the `fmi` crate) on the default scene (10 x 10 in 2D,
//! top row fixed, 2 modes, explicit Newmark, no damping), checking every
//! thousandth step that the outputs are finite and that the total energy
//! stays where it started.

use crate::common;

use fmi::fmi3::{import::Fmi3Import, CoSimulation, Common, Fmi3Model, GetSet};
use fmi::traits::FmiImport;

const STEPS: usize = 1_000_000;
const H: f64 = 1e-4;

fn vr(import: &Fmi3Import, name: &str) -> u32 {
    import.model_description().model_variables.iter_abstract().find(|v| v.name() == name).unwrap().value_reference()
}

#[test]
fn a_million_steps_stay_finite_and_keep_their_energy() {
    let import: Fmi3Import = fmi::import::from_path(common::packed_fmu()).expect("fmi crate loads the FMU");
    let [positions, velocities, kinetic, potential, frequencies] =
        ["positions", "velocities", "kineticEnergy", "potentialEnergy", "modeFrequencies"].map(|n| vr(&import, n));
    let mut cs = import.instantiate_cs("soak", false, true, false, false, &[]).expect("instantiate");
    cs.enter_initialization_mode(None, 0.0, None).unwrap();
    cs.exit_initialization_mode().unwrap();
    let mut omega = [0.0; 2];
    cs.get_float64(&[frequencies], &mut omega).unwrap();

    let (mut x, mut v, mut e) = (vec![0.0; 200], vec![0.0; 200], [0.0; 2]);
    let mut t = 0.0;
    let (mut drift, mut swing) = (0.0f64, 0.0f64);
    let start = std::time::Instant::now();
    for k in 1..=STEPS {
        let (mut ev, mut term, mut early, mut last) = (false, false, false, f64::NAN);
        cs.do_step(t, H, true, &mut ev, &mut term, &mut early, &mut last).unwrap_or_else(|e| panic!("step {k} at t = {t}: {e}"));
        t = last;
        if k % 1000 == 0 {
            cs.get_float64(&[positions], &mut x).unwrap();
            cs.get_float64(&[velocities], &mut v).unwrap();
            cs.get_float64(&[kinetic, potential], &mut e).unwrap();
            assert!(x.iter().chain(&v).chain(&e).all(|z| z.is_finite()), "step {k}: non-finite output");
            // The sheet starts at rest with zero energy; without damping the
            // sum stays zero up to the integrator's error.
            drift = drift.max((e[0] + e[1]).abs());
            swing = swing.max(e[1].abs());
        }
    }
    let elapsed = start.elapsed().as_secs_f64();
    assert!((t - STEPS as f64 * H).abs() < 1e-6, "time {t}");
    assert!(swing > 1e-3, "the sheet moved: potential energy swing {swing} J");
    // Explicit Newmark (central differences) errs in energy by about
    // (omega dt)^2 of it, omega the highest kept frequency.
    let bound = (omega[1] * H).powi(2) * swing;
    assert!(drift <= bound, "energy drift {drift:e} J, above (omega dt)^2 x swing = {bound:e} J");
    eprintln!("{STEPS} steps of {H} s in {elapsed:.1} s; energy drift {drift:.3e} J, bound {bound:.3e} J, swing {swing:.3e} J");
}
