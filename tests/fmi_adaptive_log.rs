//! reduction = adaptive through the C functions: each fall-back to full
//! space and each return to the reduced model is logged (category
//! logEvents) with its time and cause, and the step ends fmi3OK
//! (`docs/method.md`, section 10).

use crate::bake::{adaptive, resources};
use crate::common::*;
use modal_mass_spring::fmi::variables::vr;

/// The events an instance logged about its switches, cleared from its log.
fn switches(f: &Fmu) -> Vec<String> {
    let all = f.log.take();
    all.into_iter()
        .filter(|(s, c, m)| *s == OK && c == "logEvents" && (m.contains("adaptive: full space from") || m.contains("adaptive: back to")))
        .map(|(_, _, m)| m)
        .collect()
}

/// The time a switch message names ("... t = T ...").
fn time_in(message: &str) -> f64 {
    let at = message.find("t = ").expect("a time") + 4;
    message[at..].split([' ', ')', ';']).next().unwrap().parse().expect("a number")
}

#[test]
fn each_fall_back_and_return_is_logged_with_its_time_and_cause() {
    // Cloth 12 x 12 at a tolerance of 0.1 (11 vectors, exact forces), the
    // holder shaken 5 cm along x at 2 Hz for 20 steps (outside the
    // program): the estimate makes it fall back, and it returns on a grown basis.
    let p = adaptive(12, 0.1, 1);
    let f = Fmu::with_resources("logged", Some(&resources("switch-log", &p, None)));
    f.init();
    let full = f.f64s(vr::BASIS_SIZE, 1)[0];
    let mut in_full = false;
    let (mut falls, mut returns) = (0, 0);
    for k in 0..50 {
        let x = if k < 20 { 0.05 * (2.0 * std::f64::consts::PI * 2.0 * (k + 1) as f64 * 0.01).sin() } else { 0.0 };
        assert_eq!(f.set_f64(vr::ANCHOR_X, &[x]), OK);
        f.log.take();
        let t = f.time();
        assert_eq!(f.step(t, 0.01), OK, "{:?}", f.messages());
        let size = f.f64s(vr::BASIS_SIZE, 1)[0];
        let now_full = size > 100.0;
        let logged = switches(&f);
        if now_full == in_full {
            assert!(logged.is_empty(), "step {k}: no switch, yet {logged:?}");
            continue;
        }
        assert_eq!(logged.len(), 1, "step {k}: one switch, one event: {logged:?}");
        let m = &logged[0];
        if now_full {
            falls += 1;
            assert!(m.contains("full space from t = "), "{m}");
            assert!(m.contains("estimated error of the state"), "the holder's kicks drive the estimate: {m}");
            // The fall-back takes the whole step again in full space: from its start.
            assert!((time_in(m) - t).abs() < 1e-9, "{m} at a step from {t}");
        } else {
            returns += 1;
            // A return comes at the end of a step in full space.
            assert!(m.contains("back to the reduced model at t = ") && (time_in(m) - (t + 0.01)).abs() < 1e-9, "{m} after a step from {t}");
            assert!(m.contains(&format!("on {size} vectors")), "{m} with basisSize {size}");
        }
        in_full = now_full;
    }
    assert!(falls >= 1 && returns >= 1, "falls {falls}, returns {returns} (basisSize in full space {full})");
}

/// Cloth 12 x 12 at a tolerance of 0.1 after 3 steps inside its program, which made no switch.
fn three_steps_in(name: &str) -> Fmu {
    let p = adaptive(12, 0.1, 1);
    let f = Fmu::with_resources(name, Some(&resources(&format!("switch-{name}"), &p, None)));
    f.init();
    f.run(3, 0.01);
    let early = switches(&f);
    assert!(early.is_empty(), "inside the program: no switch: {early:?}");
    f
}

#[test]
fn gravity_outside_the_program_is_logged_as_the_cause() {
    let f = three_steps_in("outside");
    assert_eq!(f.set_f64(vr::GRAVITY, &[9.81, 0.0, 0.0]), OK);
    let t = f.time();
    assert_eq!(f.step(t, 0.01), OK);
    let logged = switches(&f);
    assert_eq!(logged.len(), 1, "{logged:?}");
    assert!(logged[0].contains("outside the training program") && (time_in(&logged[0]) - t).abs() < 1e-9, "{}", logged[0]);
    // Staying outside, it stays in full space: nothing more to say.
    f.run(5, 0.01);
    assert!(switches(&f).is_empty());
}

#[test]
fn a_tolerance_tightened_between_steps_makes_the_run_fall_back() {
    let f = three_steps_in("tightened");
    // Out of its range: refused, the value kept.
    assert_eq!(f.set_f64(vr::ERROR_TOLERANCE, &[0.0]), ERROR);
    assert_eq!(f.f64s(vr::ERROR_TOLERANCE, 1), [0.1]);
    assert_eq!(f.set_f64(vr::ERROR_TOLERANCE, &[1e-4]), OK);
    let mut logged = Vec::new();
    for _ in 0..10 {
        let t = f.time();
        assert_eq!(f.step(t, 0.01), OK);
        logged.extend(switches(&f));
        if !logged.is_empty() {
            break;
        }
    }
    assert!(logged.first().is_some_and(|m| m.contains("estimated error of the state")), "a fall-back on the estimate within 10 steps: {logged:?}");
}
