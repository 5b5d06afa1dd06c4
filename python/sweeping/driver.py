"""The sweep: every point of the grid run serially or on a cluster, in grid
order, and with a reference run each run's error E against it, over the whole
run and over the window in which the scene is predictable (the reference's
twins, started a hair away, tell how long that is: docs/method.md section 6)."""

import math
import sys

import measures

from .cluster import run_on_cluster
from .grid import experiment, grid_points
from .runner import fmu_digest, run_one

# The twins of the reference: every free node moved by this [m] (startOffset),
# in directions seeded 1, 2, ... (startSeed).
TWIN_OFFSET = 1e-7
# The E a twin reaches at the predictability horizon T_p.
HORIZON_THRESHOLD = 1e-3


def errors_by_window(row, ref):
    """E over growing windows of the output points (docs/method.md section 6;
    every node has the same mass) of a run's positions against the
    reference's, x(0) being the reference's start positions; None where the
    run did not complete or its output points differ."""
    x, r = row.get("_positions"), ref.get("_positions")
    if x is None or r is None or x.shape != r.shape or len(r) == 0:
        return None
    return measures.trajectory_errors_by_window(x, r, ref["_start"], ref["_dim"])


def compare(rows, n_twins):
    """Gives every row E and maxNodeError against the reference (the last
    row), E_window (E over [0, T_p], the whole run when the twins, the
    `n_twins` rows before the reference's, find no horizon), the horizon T_p
    and the twins' largest E over the run and over the window (their floor)."""
    ref = rows[-1]
    windows = [errors_by_window(row, ref) for row in rows]
    twins = [w for w in windows[len(rows) - 1 - n_twins : -1] if w is not None]
    times = ref.get("_times", [])
    horizon, floor = measures.predictability(times, twins, HORIZON_THRESHOLD) if twins else (None, math.nan)
    last = times.index(horizon) if horizon is not None else len(times) - 1
    floor_window = max((float(w[last]) for w in twins), default=math.nan)
    for row, w in zip(rows, windows, strict=True):
        if w is None:
            row.update(E=math.nan, E_window=math.nan, maxNodeError=math.nan)
        else:
            row.update(E=float(w[-1]), E_window=float(w[last]), maxNodeError=measures.max_node_error(row["_positions"], ref["_positions"], ref["_dim"]))
        row.update(horizon=math.nan if horizon is None else horizon, twinsE=floor, twinsE_window=floor_window)


def run_sweep(fmu, axes, stop_time=None, step=None, client=None, progress=True, reference=None, twins=0):
    """The rows of every point of the grid, in grid order. `client`: a
    dask.distributed Client to run them on; None runs them here, serially.
    `reference`: start values of a reference run (e.g. full space at a short
    step), run beside the grid; every row then gets E and maxNodeError
    against it, and the reference's own row comes last, with `run` =
    "reference". `twins` (with a reference): that many twins of it, the same
    start values with startOffset = TWIN_OFFSET and startSeed = 1, 2, ...,
    run beside it (rows `twin1`, `twin2`, ... before the reference's), which
    give the predictability horizon T_p (column `horizon`, NaN when no twin's
    E reaches HORIZON_THRESHOLD within the run), the twins' largest E over the
    run and over [0, T_p] (`twinsE`, `twinsE_window`), and every run's E over
    [0, T_p] (`E_window`; the whole run without a horizon)."""
    from fmpy import read_model_description

    md = read_model_description(fmu)
    stop_time, step = experiment(md, stop_time, step)
    keep = reference is not None
    twins = twins if keep else 0
    if twins < 0:
        raise ValueError(f"twins must be 0 or more, not {twins}")
    if twins and not any(v.name == "startOffset" for v in md.modelVariables):
        raise ValueError(f"{fmu} has no parameter startOffset to start twins with (built before it?); rebuild it or run no twins")
    with open(fmu, "rb") as f:
        data = f.read()
    digest = fmu_digest(data)
    points = grid_points(axes)
    n_grid = len(points)
    if keep:
        points = points + [dict(reference, startOffset=TWIN_OFFSET, startSeed=s) for s in range(1, twins + 1)] + [dict(reference)]
    if client is None:
        rows = []
        for i, point in enumerate(points):
            rows.append(run_one(data, digest, point, stop_time, step, keep))
            if progress:
                serial_progress(i + 1, len(points))
    else:
        rows = run_on_cluster(client, data, digest, points, stop_time, step, progress, keep)
    if keep:
        compare(rows, twins)
        for row in rows:
            for k in [k for k in row if k.startswith("_")]:
                del row[k]
    for i, row in enumerate(rows):
        row["run"] = i
    if keep:
        for i, row in enumerate(rows[n_grid:-1]):
            row["run"] = f"twin{i + 1}"
        rows[-1]["run"] = "reference"
        for row in rows[n_grid:]:
            for name, _ in axes:
                row.setdefault(name, "")
    return rows


def serial_progress(done, total, width=40):
    """A text bar on a terminal, a line per tenth of the runs elsewhere."""
    if sys.stdout.isatty():
        bar = "#" * (width * done // total)
        print(f"\r[{bar:<{width}}] | {done}/{total} runs", end="\n" if done == total else "", flush=True)
    elif done == total or done * 10 // total != (done - 1) * 10 // total:
        print(f"{done}/{total} runs", flush=True)
