"""The measures of docs/method.md section 6 in numpy, the one Python copy:
the trajectory error E of a run against a reference, the largest node
distance error, and Spearman's rank correlation of two series.

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


def _weighted_sum(squares, masses):
    """Σ_k Σ_i m_i s_k,i of the squared node distances s (times, nodes, D
    components); without masses every node weighs 1 (E is a ratio, so equal
    masses cancel)."""
    if masses is None:
        return float(squares.sum())
    m = np.asarray(masses, dtype=float).reshape(-1)
    if m.shape[0] != squares.shape[1]:
        raise ValueError(f"{m.shape[0]} masses for {squares.shape[1]} nodes")
    return float((squares.sum(axis=2) * m).sum())


def trajectory_error(run, reference, start, dim, masses=None):
    """E of docs/method.md section 6, over every output time t_k:

        E = sqrt( Σ_k Σ_i m_i |x_i(t_k) − x_ref,i(t_k)|² ) / sqrt( Σ_k Σ_i m_i |x_ref,i(t_k) − x_i(0)|² )

    `run` and `reference` hold the positions at the same output times, `start`
    the positions x(0) the run begins at (the sweep reads them from a fresh
    instance right after initialization; a trajectory recorded from t = 0 has
    them as its first row), `masses` one mass m_i per node (default: all equal,
    which cancel). A reference that never leaves x(0) gives inf (NaN if the
    run does not either), as IEEE division does."""
    x, r = _nodes(run, dim), _nodes(reference, dim)
    if x.shape != r.shape:
        raise ValueError(f"run {x.shape} and reference {r.shape} differ in shape")
    x0 = np.asarray(start, dtype=float).reshape(-1, dim)
    if x0.shape != r.shape[1:]:
        raise ValueError(f"start positions {x0.shape} do not fit the trajectories {r.shape}")
    num = _weighted_sum((x - r) ** 2, masses)
    den = _weighted_sum((r - x0) ** 2, masses)
    if den == 0.0:
        return math.nan if num == 0.0 else math.inf
    return math.sqrt(num) / math.sqrt(den)


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
