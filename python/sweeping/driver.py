"""The sweep: every point of the grid run serially or on a cluster, in grid
order, and with a reference run each run's error E against it."""

import math
import sys

import measures

from .cluster import run_on_cluster
from .grid import experiment, grid_points
from .runner import fmu_digest, run_one


def error_against(row, ref):
    """E of docs/method.md section 6 (every node has the same mass) and the
    largest node distance, of a run's positions against the reference's at
    the same output points, x(0) being the reference's start positions; NaN
    where the run did not complete or its output points differ."""
    x, r = row.get("_positions"), ref.get("_positions")
    if x is None or r is None or x.shape != r.shape:
        return math.nan, math.nan
    dim = ref["_dim"]
    return measures.trajectory_error(x, r, ref["_start"], dim), measures.max_node_error(x, r, dim)


def run_sweep(fmu, axes, stop_time=None, step=None, client=None, progress=True, reference=None):
    """The rows of every point of the grid, in grid order. `client`: a
    dask.distributed Client to run them on; None runs them here, serially.
    `reference`: start values of a reference run (e.g. full space at a short
    step), run beside the grid; every row then gets E and maxNodeError
    against it, and the reference's own row comes last, with `run` = "reference"."""
    from fmpy import read_model_description

    stop_time, step = experiment(read_model_description(fmu), stop_time, step)
    with open(fmu, "rb") as f:
        data = f.read()
    digest = fmu_digest(data)
    points = grid_points(axes)
    keep = reference is not None
    if keep:
        points = points + [dict(reference)]
    if client is None:
        rows = []
        for i, point in enumerate(points):
            rows.append(run_one(data, digest, point, stop_time, step, keep))
            if progress:
                serial_progress(i + 1, len(points))
    else:
        rows = run_on_cluster(client, data, digest, points, stop_time, step, progress, keep)
    if keep:
        ref = rows[-1]
        for row in rows:
            row["E"], row["maxNodeError"] = error_against(row, ref)
        for row in rows:
            for k in [k for k in row if k.startswith("_")]:
                del row[k]
    for i, row in enumerate(rows):
        row["run"] = i
    if keep:
        rows[-1]["run"] = "reference"
        for name, _ in axes:
            rows[-1].setdefault(name, "")
    return rows


def serial_progress(done, total, width=40):
    """A text bar on a terminal, a line per tenth of the runs elsewhere."""
    if sys.stdout.isatty():
        bar = "#" * (width * done // total)
        print(f"\r[{bar:<{width}}] | {done}/{total} runs", end="\n" if done == total else "", flush=True)
    elif done == total or done * 10 // total != (done - 1) * 10 // total:
        print(f"{done}/{total} runs", flush=True)
