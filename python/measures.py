"""The measures of docs/method.md section 6 in numpy, the one Python copy
(src/measures.rs is the Rust one): the trajectory error E of a run against a
reference, over the whole run or over growing windows of it, the
predictability horizon of a scene from its twins, the largest node distance
error, and Spearman's rank correlation of two series.

Trajectories are arrays of node positions at the output times t_k: one row
per output time, each row the node positions flattened (D values per node,
node after node) or already shaped (..., D); `dim` is D. The start positions
x(0) are one such row.
"""

import math

import numpy as np


def _nodes(frames, dim):
    """(output times, nodes, D) view of a trajectory."""
    frames = np.asarray(frames, dtype=float)
    return frames.reshape(len(frames), -1, dim)


def _frame_sums(run, reference, start, dim, masses):
    """Per output time t_k: Σ_i m_i |x_i(t_k) − x_ref,i(t_k)|² and
    Σ_i m_i |x_ref,i(t_k) − x_i(0)|², the terms of E's two sums."""
    x, r = _nodes(run, dim), _nodes(reference, dim)
    if x.shape != r.shape:
        raise ValueError(f"run {x.shape} and reference {r.shape} differ in shape")
    x0 = np.asarray(start, dtype=float).reshape(-1, dim)
    if x0.shape != r.shape[1:]:
        raise ValueError(f"start positions {x0.shape} do not fit the trajectories {r.shape}")
    return _weighted_sums((x - r) ** 2, masses), _weighted_sums((r - x0) ** 2, masses)


def _weighted_sums(squares, masses):
    """Σ_i m_i s_k,i per output time k of the squared node distances s (times,
    nodes, D components); without masses every node weighs 1 (E is a ratio, so
    equal masses cancel)."""
    per_node = squares.sum(axis=2)
    if masses is None:
        return per_node.sum(axis=1)
    m = np.asarray(masses, dtype=float).reshape(-1)
    if m.shape[0] != squares.shape[1]:
        raise ValueError(f"{m.shape[0]} masses for {squares.shape[1]} nodes")
    return (per_node * m).sum(axis=1)


def trajectory_errors_by_window(run, reference, start, dim, masses=None):
    """E over growing windows of output times, as an array: element k − 1 is

        E_k = sqrt( Σ_{j<k} Σ_i m_i |x_i(t_j) − x_ref,i(t_j)|² ) / sqrt( Σ_{j<k} Σ_i m_i |x_ref,i(t_j) − x_i(0)|² )

    over the first k output times (the Python twin of
    measures::trajectory_errors_by_window). The arguments are those of
    `trajectory_error`; NaN while neither the run nor the reference has left
    x(0) (0 / 0), inf while only the run has. The last element is E over the
    whole run."""
    num, den = _frame_sums(run, reference, start, dim, masses)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.sqrt(np.cumsum(num) / np.cumsum(den))


def trajectory_error(run, reference, start, dim, masses=None):
    """E of docs/method.md section 6, over every output time t_k:

        E = sqrt( Σ_k Σ_i m_i |x_i(t_k) − x_ref,i(t_k)|² ) / sqrt( Σ_k Σ_i m_i |x_ref,i(t_k) − x_i(0)|² )

    `run` and `reference` hold the positions at the same output times, `start`
    the positions x(0) the run begins at (the sweep reads them from a fresh
    instance right after initialization; a trajectory recorded from t = 0 has
    them as its first row), `masses` one mass m_i per node (default: all equal,
    which cancel). A reference that never leaves x(0) gives inf (NaN if the
    run does not either), as IEEE division does; no output times give NaN.
    The last of `trajectory_errors_by_window`."""
    errors = trajectory_errors_by_window(run, reference, start, dim, masses)
    return float(errors[-1]) if len(errors) else math.nan


def predictability(times, twins, threshold=1e-3):
    """(horizon, floor) of a scene from its twins (docs/method.md section 6;
    the Python twin of measures::predictability): each element of `twins` is E
    over growing windows (`trajectory_errors_by_window`) of a run started a
    hair away from the reference, at the output `times`. The predictability
    horizon T_p is the earliest time at which any twin's E reaches `threshold`,
    None when none does within the run; the twins' floor is the largest last
    E (0 without twins)."""
    horizon = None
    floor = 0.0
    for e in twins:
        e = np.asarray(e, dtype=float)
        reached = np.flatnonzero(e >= threshold)  # NaN reaches nothing
        if len(reached):
            t = float(times[reached[0]])
            horizon = t if horizon is None else min(horizon, t)
        if len(e) and not math.isnan(e[-1]):
            floor = max(floor, float(e[-1]))
    return horizon, floor


def max_node_error(run, reference, dim):
    """The largest node distance error over every output time t_k and node i:

        max_k max_i |x_i(t_k) − x_ref,i(t_k)|

    (Euclidean distance of the D coordinates; 0 for no output times)."""
    x, r = _nodes(run, dim), _nodes(reference, dim)
    if x.shape != r.shape:
        raise ValueError(f"run {x.shape} and reference {r.shape} differ in shape")
    if x.size == 0:
        return 0.0
    return float(np.sqrt(((x - r) ** 2).sum(axis=2)).max())


def ranks(values):
    """Ranks from 1 in increasing order, tied values sharing the mean of
    their ranks: a value with j values below it and t values equal to it
    (itself included) has rank j + (t + 1) / 2. NaN equals nothing, so NaNs
    take the last ranks, one each, in their order."""
    v = np.asarray(values, dtype=float).reshape(-1)
    if len(v) == 0:
        return v
    order = np.argsort(v, kind="mergesort")
    s = v[order]
    group = np.concatenate([[0], np.cumsum(s[1:] != s[:-1])])  # runs of equal values
    positions = np.arange(1, len(v) + 1, dtype=float)
    mean_rank = np.bincount(group, weights=positions) / np.bincount(group)
    r = np.empty(len(v))
    r[order] = mean_rank[group]
    return r


def spearman(x, y):
    """Spearman's rank correlation: the Pearson correlation of the ranks
    (ties share their mean rank, see `ranks`),

        ρ = Σ_j (R_j − R̄)(S_j − S̄) / sqrt( Σ_j (R_j − R̄)² Σ_j (S_j − S̄)² )

    with R = ranks(x), S = ranks(y). NaN for fewer than 3 pairs or a series
    whose values all tie."""
    x, y = np.asarray(x, dtype=float).reshape(-1), np.asarray(y, dtype=float).reshape(-1)
    if len(x) != len(y):
        raise ValueError(f"{len(x)} and {len(y)} values")
    if len(x) < 3:
        return math.nan
    rx, ry = ranks(x), ranks(y)
    rx, ry = rx - rx.mean(), ry - ry.mean()
    den = (rx * rx).sum() * (ry * ry).sum()
    if den == 0.0:
        return math.nan
    return float((rx * ry).sum() / np.sqrt(den))
