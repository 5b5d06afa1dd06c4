"""The measures of docs/method.md section 6 in python/measures.py: the
trajectory error E, E over growing windows and the largest node distance
error agree with the Rust example `trajectory_error` to 1e-12 relative on the
same data (seeded random trajectories, unequal masses, a run offset by a
constant vector whose E is known in closed form); the predictability horizon
and the twins' floor, and Spearman's rank correlation, on cases with known
answers.

The example is found as ``<target>/release/examples/trajectory_error``
(``$CARGO_TARGET_DIR`` or ``<repo>/target``), where ``cargo test --release``
builds it; when it is missing it is built with ``cargo build --release
--example trajectory_error``."""

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from conftest import ROOT, on_ci, target_dir

sys.path.insert(0, str(ROOT / "python"))
from measures import max_node_error, predictability, ranks, spearman, trajectory_error, trajectory_errors_by_window  # noqa: E402

RTOL = 1e-12


@pytest.fixture(scope="session")
def rust_error():
    """Path of the Rust example trajectory_error, built if missing."""
    path = target_dir() / "release" / "examples" / "trajectory_error"
    if not path.is_file():
        if not (ROOT / "examples" / "trajectory_error.rs").is_file():
            reason = "examples/trajectory_error.rs is not in this tree"
            if on_ci():
                pytest.fail(f"{reason} (CI=true: the cross-check must run)")
            pytest.skip(reason)
        subprocess.run(["cargo", "build", "--release", "--example", "trajectory_error"], cwd=ROOT, check=True)
    assert path.is_file(), f"{path} was not built"
    return path


def write_rows(path, rows):
    """One comma-separated row per line, every float exactly (17 digits)."""
    np.savetxt(path, np.atleast_2d(rows), delimiter=",", fmt="%.17g")
    return str(path)


def rust_measures(binary, tmp_path, run, reference, start, dim, masses=None, windows=False):
    """(E, max node error) of the Rust example on the same data, and E over
    growing windows with `windows`."""
    k = len(run)
    args = [
        str(binary),
        write_rows(tmp_path / "run.csv", np.reshape(run, (k, -1))),
        write_rows(tmp_path / "reference.csv", np.reshape(reference, (k, -1))),
        "--start",
        write_rows(tmp_path / "x0.csv", np.reshape(start, (1, -1))),
        "--dim",
        str(dim),
    ]
    if masses is not None:
        args += ["--masses", write_rows(tmp_path / "masses.csv", np.reshape(masses, (1, -1)))]
    out = subprocess.run(args, capture_output=True, text=True, check=True, timeout=60)
    result = json.loads(out.stdout)
    if windows:
        return result["E"], result["max_node_error"], np.array(result["E_by_window"])
    return result["E"], result["max_node_error"]


def random_case(seed, frames, nodes, dim):
    """A reference that drifts away from its start, a run near it, and the start."""
    rng = np.random.default_rng(seed)
    start = rng.uniform(-1.0, 1.0, nodes * dim)
    reference = start + np.cumsum(rng.normal(0.0, 0.05, (frames, nodes * dim)), axis=0)
    run = reference + rng.normal(0.0, 1e-3, reference.shape) * rng.uniform(0.1, 10.0, (1, nodes * dim))
    return run, reference, start


@pytest.mark.parametrize("seed,frames,nodes,dim", [(1, 30, 12, 2), (2, 201, 100, 2), (3, 50, 64, 3), (4, 1, 5, 3)])
def test_random_trajectories_agree_with_rust(rust_error, tmp_path, seed, frames, nodes, dim):
    run, reference, start = random_case(seed, frames, nodes, dim)
    e, worst = trajectory_error(run, reference, start, dim), max_node_error(run, reference, dim)
    e_rs, worst_rs = rust_measures(rust_error, tmp_path, run, reference, start, dim)
    print(f"seed {seed}: E = {e!r} (Rust {e_rs!r}), max node error {worst!r} (Rust {worst_rs!r})")
    assert 0.0 < e < 1.0 and worst > 0.0
    assert e == pytest.approx(e_rs, rel=RTOL, abs=0.0)
    assert worst == pytest.approx(worst_rs, rel=RTOL, abs=0.0)


def unequal_masses_case():
    nodes, dim = 40, 3
    run, reference, start = random_case(5, 60, nodes, dim)
    masses = np.random.default_rng(6).uniform(0.2, 5.0, nodes)
    return run, reference, start, dim, masses


def test_masses_weigh_the_nodes():
    """Masses weigh each node's squared distance: a heavy node's error counts
    more, so E moves away from the equal-mass E, which any common mass leaves
    as it is."""
    run, reference, start, dim, masses = unequal_masses_case()
    e, equal = trajectory_error(run, reference, start, dim, masses=masses), trajectory_error(run, reference, start, dim)
    assert abs(e - equal) > 1e-3 * equal, (e, equal)
    assert trajectory_error(run, reference, start, dim, masses=np.full(len(masses), 2.5)) == pytest.approx(equal, rel=1e-14)


def test_unequal_masses_agree_with_rust(rust_error, tmp_path):
    run, reference, start, dim, masses = unequal_masses_case()
    e_rs, worst_rs = rust_measures(rust_error, tmp_path, run, reference, start, dim, masses)
    assert trajectory_error(run, reference, start, dim, masses=masses) == pytest.approx(e_rs, rel=RTOL, abs=0.0)
    assert max_node_error(run, reference, dim) == pytest.approx(worst_rs, rel=RTOL, abs=0.0)


def offset_case(masses):
    """A reference whose every node moves from x_i(0) with the velocity v and
    a run offset from it by the constant vector c at every output time t_k:

        E = sqrt(Σ_k Σ_i m_i |c|²) / sqrt(Σ_k Σ_i m_i t_k² |v|²) = |c| sqrt(K) / (|v| sqrt(Σ_k t_k²)),

    whatever the masses, and every node is |c| from its reference position.
    Returns (run, reference, start, D, masses, E, largest node error)."""
    nodes, dim, t = 7, 3, np.linspace(0.0, 2.0, 21)
    v, c = np.array([0.3, -1.2, 0.4]), np.array([1e-3, 2e-3, -2e-3])
    start = np.random.default_rng(7).uniform(-1.0, 1.0, (nodes, dim))
    reference = start[None] + t[:, None, None] * v
    m = np.random.default_rng(8).uniform(0.5, 2.0, nodes) if masses else None
    e = np.linalg.norm(c) * math.sqrt(len(t)) / (np.linalg.norm(v) * math.sqrt((t**2).sum()))
    return reference + c, reference, start.ravel(), dim, m, e, np.linalg.norm(c)


@pytest.mark.parametrize("masses", [False, True], ids=["equal", "unequal"])
def test_known_error_of_an_offset_run(masses):
    run, reference, start, dim, m, e, worst = offset_case(masses)
    assert trajectory_error(run, reference, start, dim, masses=m) == pytest.approx(e, rel=RTOL, abs=0.0)
    assert max_node_error(run, reference, dim) == pytest.approx(worst, rel=RTOL, abs=0.0)


@pytest.mark.parametrize("masses", [False, True], ids=["equal", "unequal"])
def test_known_error_of_an_offset_run_in_rust(rust_error, tmp_path, masses):
    run, reference, start, dim, m, e, worst = offset_case(masses)
    e_rs, worst_rs = rust_measures(rust_error, tmp_path, run, reference, start, dim, m)
    assert e_rs == pytest.approx(e, rel=RTOL, abs=0.0)
    assert worst_rs == pytest.approx(worst, rel=RTOL, abs=0.0)


def test_error_shapes_and_zero():
    """Flattened rows and (time, ny, nx, D) arrays give the same numbers; the
    reference against itself has no error; mismatched shapes are refused."""
    run, reference, start = random_case(9, 20, 12, 3)

    def shaped(a):
        return a.reshape(len(a), 3, 4, 3)

    assert trajectory_error(shaped(run), shaped(reference), start.reshape(3, 4, 3), 3) == trajectory_error(run, reference, start, 3)
    assert max_node_error(shaped(run), shaped(reference), 3) == max_node_error(run, reference, 3)
    assert trajectory_error(reference, reference, start, 3) == 0.0 and max_node_error(reference, reference, 3) == 0.0
    with pytest.raises(ValueError):
        trajectory_error(run[:-1], reference, start, 3)
    with pytest.raises(ValueError):
        trajectory_error(run, reference, start[:-3], 3)
    with pytest.raises(ValueError):
        trajectory_error(run, reference, start, 3, masses=np.ones(11))


def test_spearman_known_answers():
    x = np.array([0.1, 0.5, 2.0, 3.0, 10.0, 11.0])
    assert spearman(x, np.exp(x)) == 1.0  # any increasing function
    assert spearman(x, -(x**3)) == -1.0
    # no ties: 1 - 6 Σ d² / (n (n² - 1)) with d = (1, -1, 1, -1, 0)
    assert spearman([1, 2, 3, 4, 5], [2, 1, 4, 3, 5]) == pytest.approx(1 - 6 * 4 / (5 * 24), rel=1e-15)
    # ties share their mean rank: ranks (1, 2.5, 2.5, 4) against (1, 2, 3, 4) give 3 / sqrt(10)
    assert spearman([1, 2, 2, 3], [1, 2, 3, 4]) == pytest.approx(3 / math.sqrt(10), rel=1e-15)
    assert spearman([1, 2, 2, 3], [4, 3, 2, 1]) == pytest.approx(-3 / math.sqrt(10), rel=1e-15)
    assert spearman([3, 3, 1, 1], [5, 5, 2, 2]) == 1.0
    # undefined: fewer than three pairs, or every value tied
    assert math.isnan(spearman([1, 2], [2, 1]))
    assert math.isnan(spearman([1, 1, 1, 1], [1, 2, 3, 4]))
    with pytest.raises(ValueError):
        spearman([1, 2, 3], [1, 2])


def test_ranks():
    assert ranks([10, 20, 20, 20, 5]).tolist() == [2.0, 4.0, 4.0, 4.0, 1.0]
    assert ranks([3.0, 1.0, 2.0]).tolist() == [3.0, 1.0, 2.0]
    assert ranks([]).tolist() == []


def two_nodes():
    """Two nodes in 2D (the case of src/measures.rs's tests): the reference moves
    node 0 by (3, 4) then (6, 8), node 1 by (0, 1) then (0, 2); the run is off
    by (1, 0) on node 0 and (0, 1) on node 1 at t_1, and exact at t_2."""
    start = np.array([0.0, 0.0, 1.0, 1.0])
    reference = np.array([start, [3.0, 4.0, 1.0, 2.0], [6.0, 8.0, 1.0, 3.0]])
    run = np.array([start, [4.0, 4.0, 1.0, 3.0], [6.0, 8.0, 1.0, 3.0]])
    return run, reference, start


def test_errors_by_window_have_their_known_values():
    """0 / 0 before the reference moves; Σ differences² = 2 over Σ motion² = 26
    after t_1, 130 after t_2; the last window is E; the run against itself is
    0 once the reference has moved; a run that moves alone is infinitely off."""
    run, reference, start = two_nodes()
    w = trajectory_errors_by_window(run, reference, start, 2)
    assert len(w) == 3 and math.isnan(w[0])
    assert w[1] == pytest.approx(math.sqrt(2 / 26), rel=1e-15) and w[2] == pytest.approx(math.sqrt(2 / 130), rel=1e-15)
    assert w[2] == trajectory_error(run, reference, start, 2)
    assert np.isnan(trajectory_errors_by_window(reference, reference, start, 2)[0])
    assert list(trajectory_errors_by_window(reference, reference, start, 2)[1:]) == [0.0, 0.0]
    assert trajectory_errors_by_window(run, np.array([start] * 3), start, 2)[1] == math.inf
    # masses weigh each node: 2 and 3 give (2·1 + 3·1) / (2·25 + 3·1) after t_1
    assert trajectory_errors_by_window(run, reference, start, 2, masses=[2.0, 3.0])[1] == pytest.approx(math.sqrt(5 / 53), rel=1e-15)


@pytest.mark.parametrize("seed,frames,nodes,dim", [(10, 40, 12, 2), (11, 25, 30, 3)])
def test_errors_by_window_agree_with_rust(rust_error, tmp_path, seed, frames, nodes, dim):
    run, reference, start = random_case(seed, frames, nodes, dim)
    w = trajectory_errors_by_window(run, reference, start, dim)
    _, _, w_rs = rust_measures(rust_error, tmp_path, run, reference, start, dim, windows=True)
    print(f"seed {seed}: E over the first 1, {frames // 2}, {frames} output times {w[0]!r}, {w[frames // 2 - 1]!r}, {w[-1]!r}")
    assert len(w_rs) == len(w) == frames
    # the windows differ: E is no constant that a wrong window would reproduce
    assert len(set(w.tolist())) == frames
    np.testing.assert_allclose(w, w_rs, rtol=RTOL, atol=0.0)


def test_predictability_known_answers():
    """The horizon is the earliest output time at which any twin's E reaches
    the threshold (reaching it exactly counts), the floor the largest last E."""
    times = [0.1, 0.2, 0.3, 0.4]
    slow, fast = [1e-5, 5e-4, 1e-3, 4e-3], [1e-4, 2e-3, 3e-3, 2e-3]
    assert predictability(times, [slow, fast]) == (0.2, 4e-3)
    assert predictability(times, [slow]) == (0.3, 4e-3)
    assert predictability(times, [slow, fast], threshold=1e-2) == (None, 4e-3)
    # NaN (the windows before the reference moves) reaches nothing
    assert predictability(times, [[math.nan, 1e-4, 1e-3, 1e-3]]) == (0.3, 1e-3)
    assert predictability(times, []) == (None, 0.0)
    assert predictability([], [[]]) == (None, 0.0)


def test_predictability_of_growing_twins():
    """Twins whose distance from the reference grows like e^(t / τ) from d0
    against a reference moving at speed v: E over [0, T] is known in closed
    form, so the horizon is the first output time at which it passes 1e-3."""
    t = np.arange(1, 201) * 0.01
    v, d0, tau = 1.0, 1e-7, 0.1
    start = np.zeros(2)
    reference = np.stack([v * t, np.zeros_like(t)], axis=1)
    twins, expected = [], []
    for direction in ([0.0, 1.0], [0.6, 0.8]):
        run = reference + np.outer(d0 * np.exp(t / tau), direction)
        twins.append(trajectory_errors_by_window(run, reference, start, 2))
        closed = np.sqrt(np.cumsum(d0**2 * np.exp(2 * t / tau)) / np.cumsum((v * t) ** 2))
        # x − x_ref of positions near 1 m keeps about 1e-16 / 1e-7 of a 1e-7 m distance
        np.testing.assert_allclose(twins[-1], closed, rtol=1e-8)
        expected.append(t[np.argmax(closed >= 1e-3)])
    horizon, floor = predictability(t, twins)
    assert horizon == min(expected) and 0.5 < horizon < 2.0, horizon
    assert floor == pytest.approx(max(w[-1] for w in twins), rel=0) and floor > 1e-3
