//! Measures of a run against a reference (`docs/method.md`, section 6),
//! written once for the study, the examples and the tests: the trajectory
//! error E, over the whole run or over growing windows of it, the largest
//! node distance error, the median and Spearman's rank correlation, and
//! the seeded start of a twin run and the predictability horizon it gives.
//!
//! A trajectory is a slice of frames, one per output time t_k, each the
//! flattened node positions (`dim` coordinates per node).

use rand_chacha::rand_core::{RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The node masses m_i of E.
#[derive(Clone, Copy, Debug, Default)]
pub enum Masses<'a> {
    /// Every node weighs the same, so m_i cancels: the squared differences
    /// of a frame are summed coordinate by coordinate in their flat order.
    #[default]
    Equal,
    /// One mass per node of `dim` coordinates: the squared distances of a
    /// frame's nodes are summed, each times its node's mass.
    PerNode { masses: &'a [f64], dim: usize },
}

impl Masses<'_> {
    /// Σ_i m_i |a_i − b_i|² over the nodes of one frame.
    fn weighted_sq(&self, a: &[f64], b: &[f64]) -> f64 {
        match *self {
            Masses::Equal => a.iter().zip(b).map(|(p, q)| (p - q).powi(2)).sum(),
            Masses::PerNode { masses, dim } => a.chunks_exact(dim).zip(b.chunks_exact(dim)).zip(masses).map(|((p, q), m)| m * squared_distance(p, q)).sum(),
        }
    }
}

fn squared_distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(p, q)| (p - q).powi(2)).sum()
}

/// E over growing windows of output times: element k − 1 is
///
/// ```text
/// E_k = sqrt( Σ_{j<k} Σ_i m_i |x_i(t_j) − x_ref,i(t_j)|² ) / sqrt( Σ_{j<k} Σ_i m_i |x_ref,i(t_j) − x_i(0)|² )
/// ```
///
/// over the first k output times, with `start` = x(0); NaN while the
/// reference has not moved from x(0) (0 / 0). The last element is E over
/// the whole run. Frames past the shorter trajectory are left out.
pub fn trajectory_errors_by_window<R: AsRef<[f64]>, Q: AsRef<[f64]>>(run: &[R], reference: &[Q], start: &[f64], masses: Masses) -> Vec<f64> {
    let (mut num, mut den) = (0.0, 0.0);
    run.iter()
        .zip(reference)
        .map(|(x, xr)| {
            num += masses.weighted_sq(x.as_ref(), xr.as_ref());
            den += masses.weighted_sq(xr.as_ref(), start);
            (num / den).sqrt()
        })
        .collect()
}

/// E of `docs/method.md`, section 6, over all output times t_k:
///
/// ```text
/// E = sqrt( Σ_k Σ_i m_i |x_i(t_k) − x_ref,i(t_k)|² ) / sqrt( Σ_k Σ_i m_i |x_ref,i(t_k) − x_i(0)|² )
/// ```
///
/// with `start` = x(0). NaN for empty trajectories or a reference that
/// never leaves x(0).
pub fn trajectory_error<R: AsRef<[f64]>, Q: AsRef<[f64]>>(run: &[R], reference: &[Q], start: &[f64], masses: Masses) -> f64 {
    trajectory_errors_by_window(run, reference, start, masses).last().copied().unwrap_or(f64::NAN)
}

/// The predictability horizon of a scene from its twins (`docs/method.md`,
/// section 6): each element of `twins` is E over growing windows
/// ([`trajectory_errors_by_window`]) of a run started a hair away from the
/// reference, at the output `times`; the horizon is the earliest time at
/// which any twin's E reaches `threshold`, `None` when none does within the
/// run. The twins' floor at the end is the largest last E.
pub fn predictability(times: &[f64], twins: &[Vec<f64>], threshold: f64) -> (Option<f64>, f64) {
    let horizon =
        twins.iter().filter_map(|e| e.iter().position(|&x| x >= threshold).map(|k| times[k])).fold(None, |m: Option<f64>, t| Some(m.map_or(t, |m| m.min(t))));
    let floor = twins.iter().filter_map(|e| e.last().copied()).fold(0.0, f64::max);
    (horizon, floor)
}

/// The start of a twin in the free DOFs (`dim` per free node, in their
/// order): every free node moved by `size` [m] in its own direction, a point
/// of the cube [-1, 1]^dim drawn from ChaCha8 seeded with `seed` (each
/// coordinate 53 random bits) and scaled to length `size`: the twins of
/// the study, the tests and the FMU's `startOffset`.
pub fn twin_offset(dofs: usize, dim: usize, size: f64, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut dy = vec![0.0; dofs];
    for node in dy.chunks_exact_mut(dim) {
        for d in node.iter_mut() {
            *d = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0;
        }
        // A draw of 0 in every coordinate leaves its node where it is.
        let norm = node.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-300);
        node.iter_mut().for_each(|d| *d = size * *d / norm);
    }
    dy
}

/// The largest distance between a node and its reference position over all
/// output times, max_k max_i |x_i(t_k) − x_ref,i(t_k)| (nodes of `dim`
/// coordinates); 0 for empty trajectories.
pub fn max_node_error<R: AsRef<[f64]>, Q: AsRef<[f64]>>(run: &[R], reference: &[Q], dim: usize) -> f64 {
    run.iter()
        .zip(reference)
        .flat_map(|(x, xr)| x.as_ref().chunks_exact(dim).zip(xr.as_ref().chunks_exact(dim)))
        .map(|(a, b)| squared_distance(a, b).sqrt())
        .fold(0.0, f64::max)
}

/// The median as the element at index n / 2 of the sorted values (of an
/// even count, the upper of the two middle ones); NaN for no values.
/// Sorts `values` in place, NaN last.
pub fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    values.get(values.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Ranks from 1 in increasing order, ties sharing their mean rank: a value
/// preceded by i others and tied with the values up to position j (from 0)
/// gets (i + j) / 2 + 1.
pub fn ranks(values: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    let mut r = vec![0.0; values.len()];
    let mut i = 0;
    while i < order.len() {
        let mut j = i;
        while j + 1 < order.len() && values[order[j + 1]] == values[order[i]] {
            j += 1;
        }
        for &k in &order[i..=j] {
            r[k] = (i + j) as f64 / 2.0 + 1.0;
        }
        i = j + 1;
    }
    r
}

/// Spearman's rank correlation: the Pearson correlation of the ranks
/// ([`ranks`], ties at their mean rank) of the paired values,
///
/// ```text
/// ρ = Σ (r_x − r̄_x)(r_y − r̄_y) / sqrt( Σ (r_x − r̄_x)² Σ (r_y − r̄_y)² )
/// ```
///
/// 1 for the same order, −1 for the reverse; NaN when either side is all
/// ties (or there are fewer than two pairs).
pub fn spearman(x: &[f64], y: &[f64]) -> f64 {
    assert_eq!(x.len(), y.len(), "Spearman's rank correlation pairs the values");
    let (rx, ry) = (ranks(x), ranks(y));
    let n = rx.len() as f64;
    let (mx, my) = (rx.iter().sum::<f64>() / n, ry.iter().sum::<f64>() / n);
    let cov: f64 = rx.iter().zip(&ry).map(|(a, b)| (a - mx) * (b - my)).sum();
    let vx: f64 = rx.iter().map(|a| (a - mx).powi(2)).sum();
    let vy: f64 = ry.iter().map(|b| (b - my).powi(2)).sum();
    cov / (vx * vy).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two nodes in 2D; the reference moves node 0 by (3, 4) then (6, 8),
    /// node 1 by (0, 1) then (0, 2); the run is off by (1, 0) on node 0 and
    /// (0, 1) on node 1 at t_1, and exact at t_2.
    fn two_nodes() -> (Vec<Vec<f64>>, Vec<Vec<f64>>, Vec<f64>) {
        let start = vec![0.0, 0.0, 1.0, 1.0];
        let reference = vec![start.clone(), vec![3.0, 4.0, 1.0, 2.0], vec![6.0, 8.0, 1.0, 3.0]];
        let run = vec![start.clone(), vec![4.0, 4.0, 1.0, 3.0], vec![6.0, 8.0, 1.0, 3.0]];
        (run, reference, start)
    }

    #[test]
    fn trajectory_error_has_its_known_values() {
        let (run, reference, start) = two_nodes();
        // Σ differences² = 1 + 1 = 2; Σ motion² = (25 + 1) + (100 + 4) = 130.
        let e = trajectory_error(&run, &reference, &start, Masses::Equal);
        assert_eq!(e, (2.0f64 / 130.0).sqrt());
        // Masses 2 and 3: (2·1 + 3·1) / (2·25 + 3·1 + 2·100 + 3·4) = 5 / 265.
        let masses = [2.0, 3.0];
        let weighted = trajectory_error(&run, &reference, &start, Masses::PerNode { masses: &masses, dim: 2 });
        assert!((weighted - (5.0f64 / 265.0).sqrt()).abs() < 1e-15, "{weighted}");
        // Equal masses per node give the unweighted E.
        let ones = [1.0, 1.0];
        let same = trajectory_error(&run, &reference, &start, Masses::PerNode { masses: &ones, dim: 2 });
        assert!((same - e).abs() < 1e-15);
        // The run against itself, and x(0) taken as given, not as reference[0].
        assert_eq!(trajectory_error(&reference, &reference, &start, Masses::Equal), 0.0);
        let shifted = [1.0, 0.0, 1.0, 1.0];
        // Σ motion² from (1, 0): (4 + 16 + 1) + (25 + 64 + 4) + 1 (t = 0, node 0 off by 1) = 115.
        assert_eq!(trajectory_error(&run, &reference, &shifted, Masses::Equal), (2.0f64 / 115.0).sqrt());
    }

    #[test]
    fn errors_by_window_grow_with_the_window() {
        let (run, reference, start) = two_nodes();
        let w = trajectory_errors_by_window(&run, &reference, &start, Masses::Equal);
        assert_eq!(w.len(), 3);
        assert!(w[0].is_nan(), "0 / 0 before the reference moves");
        assert_eq!(w[1], (2.0f64 / 26.0).sqrt());
        assert_eq!(w[2], trajectory_error(&run, &reference, &start, Masses::Equal));
        assert!(trajectory_error::<Vec<f64>, Vec<f64>>(&[], &[], &start, Masses::Equal).is_nan());
    }

    #[test]
    fn max_node_error_is_the_largest_distance() {
        let (run, reference, _) = two_nodes();
        assert_eq!(max_node_error(&run, &reference, 2), 1.0);
        let far = vec![vec![0.0, 0.0, 1.0, 1.0], vec![3.0, 4.0, 1.0, 2.0], vec![6.0, 8.0, 4.0, 7.0]];
        assert_eq!(max_node_error(&far, &reference, 2), 5.0);
        // As four 1D nodes: the largest coordinate difference.
        assert_eq!(max_node_error(&far, &reference, 1), 4.0);
    }

    #[test]
    fn median_takes_the_middle_or_upper_middle() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 3.0);
        assert_eq!(median(&mut [5.0]), 5.0);
        assert!(median(&mut []).is_nan());
    }

    #[test]
    fn ranks_share_ties() {
        assert_eq!(ranks(&[10.0, 30.0, 20.0]), vec![1.0, 3.0, 2.0]);
        assert_eq!(ranks(&[1.0, 2.0, 2.0, 3.0]), vec![1.0, 2.5, 2.5, 4.0]);
        assert_eq!(ranks(&[7.0, 7.0, 7.0]), vec![2.0, 2.0, 2.0]);
    }

    #[test]
    fn spearman_has_its_known_values() {
        let x = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(spearman(&x, &[2.0, 4.0, 8.0, 16.0, 32.0]), 1.0);
        assert_eq!(spearman(&x, &[5.0, 4.0, 3.0, 2.0, 1.0]), -1.0);
        // Ranks of y: 2, 1, 4, 3, 5; Σ d² = 4, ρ = 1 − 6·4 / (5·24) = 0.8.
        assert!((spearman(&x, &[20.0, 10.0, 40.0, 30.0, 50.0]) - 0.8).abs() < 1e-15);
        // With ties: x ranks 1, 2.5, 2.5, 4; y ranks 1, 2, 3, 4: ρ = 4.5 / sqrt(4.5 · 5).
        let rho = spearman(&[1.0, 2.0, 2.0, 3.0], &[1.0, 2.0, 3.0, 4.0]);
        assert!((rho - 4.5 / (4.5f64 * 5.0).sqrt()).abs() < 1e-15, "{rho}");
        assert!(spearman(&[1.0, 1.0, 1.0], &[1.0, 2.0, 3.0]).is_nan());
    }
}
