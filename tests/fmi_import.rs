//! The packed FMU loaded by an independent importer (the `fmi` crate) and
//! stepped. Builds target/fmu/ModalMassSpring.fmu with `cargo xtask fmu`
//! when it is missing or older than the sources.

use crate::common;

use fmi::fmi3::{import::Fmi3Import, CoSimulation, Common, Fmi3Model, GetSet};
use fmi::traits::FmiImport;

fn vr(import: &Fmi3Import, name: &str) -> u32 {
    import
        .model_description()
        .model_variables
        .iter_abstract()
        .find(|v| v.name() == name)
        .unwrap_or_else(|| panic!("{name} not in the model description"))
        .value_reference()
}

#[test]
fn fmi_crate_imports_and_steps_the_fmu() {
    let import: Fmi3Import = fmi::import::from_path(common::packed_fmu()).expect("fmi crate loads the FMU");
    let md = import.model_description();
    assert_eq!(md.fmi_version, "3.0");
    assert_eq!(md.model_name, "ModalMassSpring");
    let (positions, damping, time) = (vr(&import, "positions"), vr(&import, "dampingAlpha"), vr(&import, "time"));

    let mut cs = import.instantiate_cs("cs", false, true, false, false, &[]).expect("instantiate");
    assert_eq!(cs.get_version(), "3.0");
    cs.set_float64(&[damping], &[0.1]).expect("set a parameter before initialization");
    cs.enter_initialization_mode(None, 0.0, Some(2.0)).unwrap();
    cs.exit_initialization_mode().unwrap();

    let mut p0 = vec![0.0; 200];
    cs.get_float64(&[positions], &mut p0).unwrap();
    let h = 0.01;
    let mut t = 0.0;
    for _ in 0..30 {
        let (mut ev, mut term, mut early, mut last) = (false, false, false, 0.0);
        cs.do_step(t, h, true, &mut ev, &mut term, &mut early, &mut last).expect("DoStep");
        assert!(!ev && !term && !early);
        t += h;
        assert!((last - t).abs() < 1e-9);
    }
    let mut now = [0.0];
    cs.get_float64(&[time], &mut now).unwrap();
    assert!((now[0] - 0.3).abs() < 1e-9);

    let mut p = vec![0.0; 200];
    cs.get_float64(&[positions], &mut p).unwrap();
    assert!(p.iter().all(|x| x.is_finite()));
    // Top row (row 0) fixed, every node of the bottom row (row 9) lower than at rest.
    assert_eq!(&p[..20], &p0[..20]);
    for col in 0..10 {
        let y = 9 * 20 + col * 2 + 1;
        assert!(p[y] < p0[y] - 1e-3, "node (9, {col}) does not sag: {} vs {}", p[y], p0[y]);
    }
    // A wrong nValues is an error, not a crash.
    let mut short = vec![0.0; 199];
    assert!(cs.get_float64(&[positions], &mut short).is_err());
}
