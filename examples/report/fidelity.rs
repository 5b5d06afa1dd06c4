//! How far each scene is predictable, and what a run is judged by beyond
//! that (docs/method.md, section 6). Twins of a full-space run, started a
//! hair away from it, measure the scene rather than any model: the time T_p
//! at which their E over [0, T_p] reaches [`PREDICTABLE_E`] bounds the
//! window over which E of a run says something about the run, and their E
//! over the whole run (the floor) is as close as any model can come there.
//! Past T_p a run is judged by coarse observables, averaged over windows of
//! [`AVERAGE_S`], against how far the twins' own observables spread.

use modal_mass_spring::measures::{predictability, trajectory_errors_by_window, twin_offset, Masses};
use modal_mass_spring::physics::*;

use crate::plan::{full_solver, Change, FRAME};
use crate::run::{run, set_up, simulate};

/// Seeds of the twins' start displacements (fixed: the report is reproducible).
pub const TWIN_SEEDS: [u64; 3] = [1, 2, 3];
/// Distance every free node of a twin starts from the base run's start [m].
pub const TWIN_KICK: f64 = 1e-7;
/// The twins and their base run: full space, explicit Newmark, at this
/// co-simulation step and internal step bound [s]. T_p is a property of the
/// dynamics; the cheapest scheme that resolves it will do.
pub const TWIN_STEP: f64 = 1e-3;
/// E over [0, T] of a twin at which the scene stops being predictable.
pub const PREDICTABLE_E: f64 = 1e-3;
/// Length of the windows the coarse observables are averaged over [s].
pub const AVERAGE_S: f64 = 0.25;
/// A run whose observables all stay within this multiple of the twins'
/// spread is counted as judged equal to the twins.
pub const SPREAD_MULTIPLE: f64 = 3.0;
/// The coarse observables, in the order of [`Coarse`]'s values, with their units.
pub const OBSERVABLES: [(&str, &str); 4] = [("holder's force", "N"), ("bottom row's mean position", "m"), ("kinetic energy", "J"), ("potential energy", "J")];

/// What a run reads at each output time beside the node positions, outside
/// the timing: the holder's force (3 components, z 0 in 2D), the kinetic
/// and the potential energy.
pub type Reading = [f64; 5];

/// Reads `sim`'s [`Reading`].
pub fn read(sim: &mut Simulator) -> Reading {
    let f = sim.anchor_force();
    [f[0], f[1], f[2], sim.kinetic_energy(), sim.potential_energy()]
}

/// Each observable of [`OBSERVABLES`] per window of [`AVERAGE_S`]: the mean
/// of its values at the output times after t = 0 in that window (a vector
/// for the force and the position, one value for the energies).
pub struct Coarse {
    windows: Vec<[Vec<f64>; 4]>,
}

/// The coarse observables of a trajectory of scene `p` (frames and readings
/// at the output times, t = 0 first).
pub fn coarse(p: &Grid, frames: &[Vec<f64>], readings: &[Reading]) -> Coarse {
    let (d, cols) = (p.dim, p.columns);
    let bottom = (p.rows - 1) * cols * d..p.rows * cols * d;
    let per_window = ((AVERAGE_S / FRAME).round() as usize).max(1);
    let values = |x: &[f64], r: &Reading| -> [Vec<f64>; 4] {
        let mut mean = vec![0.0; d];
        for node in x[bottom.clone()].chunks_exact(d) {
            for (m, c) in mean.iter_mut().zip(node) {
                *m += c / cols as f64;
            }
        }
        [r[..3].to_vec(), mean, vec![r[3]], vec![r[4]]]
    };
    let all: Vec<[Vec<f64>; 4]> = frames.iter().zip(readings).skip(1).map(|(x, r)| values(x, r)).collect();
    let windows = all
        .chunks(per_window)
        .map(|w| {
            std::array::from_fn(|o| {
                let mut m = vec![0.0; w[0][o].len()];
                for v in w {
                    for (a, b) in m.iter_mut().zip(&v[o]) {
                        *a += b / w.len() as f64;
                    }
                }
                m
            })
        })
        .collect();
    Coarse { windows }
}

/// Per observable, the largest distance between the window means of `a`
/// and `b` over the windows both have.
pub fn deviation(a: &Coarse, b: &Coarse) -> [f64; 4] {
    std::array::from_fn(|o| {
        a.windows.iter().zip(&b.windows).map(|(x, y)| x[o].iter().zip(&y[o]).map(|(p, q)| (p - q).powi(2)).sum::<f64>().sqrt()).fold(0.0, f64::max)
    })
}

/// A scene's twins against their base run.
pub struct Twins {
    /// The predictability horizon T_p: the first output time at which a
    /// twin's E over [0, T] reaches [`PREDICTABLE_E`]; `None` if none does
    /// within the run [s].
    pub until_s: Option<f64>,
    /// The twins' largest E over the whole run.
    pub floor: f64,
    /// Per observable, the twins' largest [`deviation`] from the base run.
    pub spread: [f64; 4],
    /// Wall time of the base run and the twins, set-up included [s].
    pub wall_s: f64,
}

/// The twins of scene `p` over `seconds` (full space, explicit Newmark at
/// [`TWIN_STEP`], each free node of twin s moved [`TWIN_KICK`] in the
/// direction [`TWIN_SEEDS`]\[s\] draws) against the same run undisturbed;
/// `tick` after each run.
pub fn twins(p: &Grid, seconds: f64, change: Option<Change>, tick: &dyn Fn()) -> Twins {
    let t0 = std::time::Instant::now();
    let solver = full_solver(Integrator::NewmarkExplicit, TWIN_STEP);
    let base = simulate(p, &solver, TWIN_STEP, seconds, f64::INFINITY, 1, change).expect("the twins' base run failed");
    tick();
    let base_coarse = coarse(p, &base.frames, &base.readings);
    let mut by_window = Vec::new();
    let mut spread = [0.0; 4];
    for seed in TWIN_SEEDS {
        let mut prep = set_up(p, &solver).expect("a twin's set-up failed");
        let dy = twin_offset(prep.sim.n_dofs(), p.dim, TWIN_KICK, seed);
        prep.sim.displace(&dy).expect("a twin's start");
        prep.start = prep.sim.snapshot();
        let twin = run(&mut prep, TWIN_STEP, seconds, f64::INFINITY, 1, change).expect("a twin's run failed");
        // From the first output time after t = 0 (the twins start apart: E over t = 0 alone is 1e-7 / 0).
        by_window.push(trajectory_errors_by_window(&twin.frames[1..], &base.frames[1..], &base.frames[0], Masses::Equal));
        for (s, d) in spread.iter_mut().zip(deviation(&coarse(p, &twin.frames, &twin.readings), &base_coarse)) {
            *s = f64::max(*s, d);
        }
        tick();
    }
    let times: Vec<f64> = (1..base.frames.len()).map(|k| k as f64 * FRAME).collect();
    let (until_s, floor) = predictability(&times, &by_window, PREDICTABLE_E);
    Twins { until_s, floor, spread, wall_s: t0.elapsed().as_secs_f64() }
}
