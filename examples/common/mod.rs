//! What the measuring examples share.

use modal_mass_spring::measures::{max_node_error, trajectory_error, Masses};

/// E of docs/method.md, section 6 (`modal_mass_spring::measures`), from the
/// reference's first frame, all nodes weighing the same; and the largest
/// node distance error (nodes of `d` coordinates).
pub fn error(run: &[Vec<f64>], reference: &[Vec<f64>], d: usize) -> (f64, f64) {
    (trajectory_error(run, reference, &reference[0], Masses::Equal), max_node_error(run, reference, d))
}
