//! Timing: a simulator set up once and run from its start as often as asked.

use std::time::Instant;

use modal_mass_spring::physics::*;

use crate::fidelity::{read, Reading};
use crate::plan::{Change, FRAME};

pub struct Trajectory {
    pub frames: Vec<Vec<f64>>,
    /// The holder's force and the energies at the same times (not timed).
    pub readings: Vec<Reading>,
    pub setup_s: f64,
    /// Wall time of each timed run [s].
    pub run_s: Vec<f64>,
    /// The same without the reads of the node positions [s].
    pub step_s: Vec<f64>,
    pub internal_steps: usize,
    pub force_residual_max: f64,
    pub force_residual_mean: f64,
    pub springs_visited: Option<usize>,
    /// The run's `errorEstimate` at each output time (0 but for adaptive runs; not timed).
    pub estimates: Vec<f64>,
    /// At the end: the share of internal steps taken reduced and the basis size.
    pub reduced_fraction: f64,
    pub basis_size: usize,
    /// The basis size at set-up.
    pub setup_basis_size: usize,
}

/// Runs over budget stop here; the report lists them as such (not as unstable).
pub const OVER_BUDGET: &str = "over the time budget";

/// Runs longer than this are timed once.
pub const TIME_ONCE_S: f64 = 2.0;

/// Springs one force evaluation of `sim` visits: every spring, or the cubature set.
fn springs_visited(sim: &Simulator) -> Option<usize> {
    Some(sim.cubature_springs())
}

/// A simulator set up once, the state it starts from, and the set-up's wall time.
pub struct Prepared {
    pub sim: Simulator,
    pub start: Snapshot,
    pub setup_s: f64,
    /// The basis size at set-up (the free DOFs in full space).
    pub basis_size: usize,
}

pub fn set_up(p: &Grid, s: &Settings) -> Result<Prepared, PhysicsError> {
    let t0 = Instant::now();
    let sim = Simulator::new(p.build()?, s, &Loads::physical(s.n_modes))?;
    let setup_s = t0.elapsed().as_secs_f64();
    Ok(Prepared { start: sim.snapshot(), basis_size: sim.reduction_status().chosen_size, sim, setup_s })
}

/// Runs `repeats` times from the start of `prep`, co-simulation step `h`,
/// timing each run; a run longer than [`TIME_ONCE_S`] is not repeated.
/// Trajectories and `forceResidual` are those of the last run. `change`
/// sets the gravity before the first step that starts at its time.
pub fn run(prep: &mut Prepared, h: f64, seconds: f64, budget_s: f64, repeats: usize, change: Option<Change>) -> Result<Trajectory, String> {
    let sim = &mut prep.sim;
    let per_frame = (FRAME / h).round() as usize;
    let n_frames = (seconds / FRAME).round() as usize;
    let mut run_s = Vec::new();
    let mut step_s = Vec::new();
    let mut last = None;
    // The step before which the gravity changes (the study's times are multiples of its steps).
    let change_at = change.map(|c| ((c.at_s / h).round() as usize, c.gravity));
    for _ in 0..repeats.max(1) {
        sim.restore(&prep.start).map_err(|e| e.to_string())?;
        let mut frames = Vec::with_capacity(n_frames + 1);
        frames.push(sim.positions().to_vec());
        let mut readings = Vec::with_capacity(n_frames + 1);
        readings.push(read(sim));
        let mut estimates = Vec::with_capacity(n_frames + 1);
        estimates.push(sim.reduction_status().error_estimate);
        let (mut internal_steps, mut fr_max, mut fr_sum, mut untimed, mut reading) = (0, 0.0f64, 0.0, 0.0, 0.0);
        let t1 = Instant::now();
        for frame in 0..n_frames {
            for k in 0..per_frame {
                if let Some((at, gravity)) = change_at.filter(|&(at, _)| at == frame * per_frame + k) {
                    let loads = Loads { gravity, ..sim.loads().clone() };
                    sim.set_loads(&loads).map_err(|e| format!("at step {at}: {e}"))?;
                }
                sim.do_step(h).map_err(|e| e.to_string())?;
                internal_steps += sim.internal_steps_last();
                if t1.elapsed().as_secs_f64() > budget_s {
                    return Err(format!("{OVER_BUDGET}: stopped after {budget_s} s of wall time at t = {:.3} s", sim.time()));
                }
            }
            let t3 = Instant::now();
            frames.push(sim.positions().to_vec());
            reading += t3.elapsed().as_secs_f64();
            // forceResidual and the potential energy visit every spring:
            // read for the study, not timed.
            let t2 = Instant::now();
            let fr = sim.force_residual();
            readings.push(read(sim));
            estimates.push(sim.reduction_status().error_estimate);
            untimed += t2.elapsed().as_secs_f64();
            fr_max = fr_max.max(fr);
            fr_sum += fr;
        }
        let elapsed = t1.elapsed().as_secs_f64() - untimed;
        run_s.push(elapsed);
        step_s.push(elapsed - reading);
        last = Some((frames, readings, estimates, internal_steps / (per_frame * n_frames).max(1), fr_max, fr_sum / n_frames.max(1) as f64));
        if elapsed > TIME_ONCE_S {
            break;
        }
    }
    let (frames, readings, estimates, internal_steps, force_residual_max, force_residual_mean) = last.unwrap();
    let status = sim.reduction_status();
    Ok(Trajectory {
        frames,
        readings,
        setup_s: prep.setup_s,
        run_s,
        step_s,
        internal_steps,
        force_residual_max,
        force_residual_mean,
        springs_visited: springs_visited(sim),
        estimates,
        reduced_fraction: status.reduced_fraction,
        basis_size: status.basis_size,
        setup_basis_size: prep.basis_size,
    })
}

/// Sets up and runs.
pub fn simulate(p: &Grid, s: &Settings, h: f64, seconds: f64, budget_s: f64, repeats: usize, change: Option<Change>) -> Result<Trajectory, String> {
    run(&mut set_up(p, s).map_err(|e| e.to_string())?, h, seconds, budget_s, repeats, change)
}
