"""Parameter sweep: one fmpy.simulate_fmu run of the FMU per point of a grid of
start values, on a Dask cluster (dask.distributed) or serially, with one row of
summary numbers per run written to CSV (and Parquet where pyarrow is
installed) and a plot of the sweep next to it.

    .venv/bin/python python/sweep.py [FMU] --param springStiffness=50,100,200 --param nModes=2,4,8
    cargo xtask sweep -- --param dampingAlpha=0,0.5,2 --param step=0.01,0.005 --workers 2

Every --param NAME=V1,V2,... adds an axis; the runs are every combination
(a full factorial grid). NAME is any parameter or structural parameter of the
FMU (springStiffness, dampingAlpha, dampingBeta, nModes, nx, modeSelection,
staticCorrection, linearization, forceEvaluation, reduction, ...) or `step`,
the communication step (fmpy's simulate_fmu steps from output point to output
point, so it is also the output interval). Enumerations take item names or
numbers, Booleans true/false, arrays their elements separated by spaces
("gravity=0 -9.81 0,2 -9.81 0").

By default the runs go to a LocalCluster of --workers processes (one thread
each) on the loopback interface, without a dashboard; --scheduler ADDRESS uses
a running cluster instead (its workers need fmpy and numpy; the FMU is sent to
them); --serial runs them one after the other in this process, without Dask.
A run the FMU refuses (a parameter out of range, a configuration set-up
rejects, a diverging step) is a row with its status and the FMU's message.

With --reference NAME=VALUE ... a reference run is added and every run gets
its error E against it (docs/method.md section 6). --twins N (default 3) also
runs N twins of the reference, started 1e-7 m away (startOffset, startSeed =
1..N): the earliest time a twin's E over [0, T] reaches 1e-3 is the scene's
predictability horizon T_p (cloth parts within a second; the paper's 2D sheet
never), and every run gets E_window, its E over [0, T_p] (the whole run
without a horizon), beside E and the twins' own E (their floor): on a chaotic
scene E over the whole run measures the scene's sensitivity, not the model.

The numbers of a run depend on its start values only: the same sweep gives the
same CSV, bit for bit, serially or on any number of workers of this machine,
except the columns wallTime and worker (see NONDETERMINISTIC).
"""

import argparse
import math
import os
import sys
import time

# The sweep's parts, one module per job in python/sweeping/; the names the
# tests and other scripts use stay importable from here.
from sweeping.driver import HORIZON_THRESHOLD, TWIN_OFFSET, run_sweep
from sweeping.grid import METRICS, NONDETERMINISTIC, STEP, columns, experiment, grid_points, parse_grid  # noqa: F401 (METRICS, NONDETERMINISTIC)
from sweeping.output import cell, write_csv, write_parquet
from sweeping.plot import plot, plot_error

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_FMU = os.path.join(ROOT, "target", "fmu", "ModalMassSpring.fmu")
DEFAULT_OUT = os.path.join(ROOT, "out", "sweep", "sweep.csv")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("fmu", nargs="?", default=DEFAULT_FMU, help="default: target/fmu/ModalMassSpring.fmu")
    p.add_argument("--param", action="append", default=[], metavar="NAME=V1,V2,...", help="an axis of the grid (repeatable)")
    p.add_argument("--stop-time", type=float, default=None, help="default: the FMU's default experiment (2 s)")
    p.add_argument("--step", type=float, default=None, help="communication step and output interval where not swept (default: the FMU's, 0.01 s)")
    p.add_argument("--out", default=DEFAULT_OUT, help="the CSV; the plot (.png) and Parquet (.parquet) go next to it (default: out/sweep/sweep.csv)")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, default=None, help="processes of the LocalCluster (default: the number of cores)")
    where.add_argument("--scheduler", metavar="ADDRESS", help="the scheduler of a running cluster, e.g. tcp://10.0.0.5:8786")
    where.add_argument("--serial", action="store_true", help="run in this process, one run after the other, without Dask")
    p.add_argument(
        "--reference",
        action="append",
        default=None,
        metavar="NAME=VALUE",
        help="start value of a reference run (repeatable, e.g. --reference reduction=full --reference maxInternalStep=1e-4): "
        "every run gets E and maxNodeError against it (docs/method.md section 6), "
        "and the error plot shows E over the predictability window (--twins) against run time",
    )
    p.add_argument(
        "--twins",
        type=int,
        default=3,
        metavar="N",
        help=f"with --reference: N twins of the reference started {TWIN_OFFSET:g} m away (startOffset, startSeed = 1..N) give the "
        f"predictability horizon T_p (the earliest time a twin's E reaches {HORIZON_THRESHOLD:g}) and every run E over [0, T_p] "
        "(E_window); 0: none (default: 3)",
    )
    p.add_argument("--no-plot", action="store_true")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    a = p.parse_args(argv)
    if a.twins < 0:
        p.error(f"--twins must be 0 or more, not {a.twins}")

    from fmpy import read_model_description

    md = read_model_description(a.fmu)
    try:
        axes = parse_grid(md, a.param)
    except ValueError as e:
        p.error(str(e))
    reference = None
    if a.reference is not None:
        try:
            reference = {name: values[0] for name, values in parse_grid(md, a.reference)}
        except ValueError as e:
            p.error(str(e))
    twins = a.twins if reference is not None else 0
    if twins and not any(v.name == "startOffset" for v in md.modelVariables):
        p.error(f"{a.fmu} has no parameter startOffset to start twins with: rebuild it (cargo xtask fmu) or pass --twins 0")
    n = len(grid_points(axes))
    grid = " x ".join(f"{name} ({len(v)})" for name, v in axes) or "the FMU's start values"
    if reference is not None:
        grid += ", a reference run" + (f" and {twins} twins of it" if twins else "")
    t0 = time.perf_counter()
    if a.serial:
        print(f"sweep: {n} runs of {grid}, serially")
        rows = run_sweep(a.fmu, axes, a.stop_time, a.step, progress=not a.quiet, reference=reference, twins=twins)
    else:
        from distributed import Client, LocalCluster

        if a.scheduler:
            cluster = None
            client = Client(a.scheduler)
        else:
            workers = a.workers or os.cpu_count() or 1
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None)
            client = Client(cluster)
        where = a.scheduler or f"a local cluster of {len(client.scheduler_info()['workers'])} workers (started in {time.perf_counter() - t0:.1f} s)"
        print(f"sweep: {n} runs of {grid} on {where}")
        t0 = time.perf_counter()
        try:
            rows = run_sweep(a.fmu, axes, a.stop_time, a.step, client=client, progress=not a.quiet, reference=reference, twins=twins)
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    wall = time.perf_counter() - t0

    cols = columns(axes)
    write_csv(a.out, rows, cols)
    stem = os.path.splitext(a.out)[0]
    written = [a.out]
    if write_parquet(stem + ".parquet", rows, cols):
        written.append(stem + ".parquet")
    if not a.no_plot:
        stop, step = experiment(md, a.stop_time, a.step)
        fixed = [f"{name}={cell(v[0])}" for name, v in axes if len(v) == 1]
        setting = ", ".join(fixed + [f"stop time {stop:g} s"] + ([] if STEP in dict(axes) else [f"step {step:g} s"]))
        grid_rows = [r for r in rows if isinstance(r["run"], int)]
        plot(stem + ".png", grid_rows, axes, f"{md.modelName}: {os.path.basename(a.fmu)}, {n} runs; {setting}")
        written.append(stem + ".png")
        if reference is not None:
            ref = ", ".join(f"{k}={cell(v)}" for k, v in reference.items())
            plot_error(stem + "-error.png", rows, f"error against run time; reference {ref}; {setting}")
            written.append(stem + "-error.png")
    counts = {}
    for r in rows:
        counts[r["status"]] = counts.get(r["status"], 0) + 1
    statuses = ", ".join(f"{c} {s}" for s, c in sorted(counts.items()))
    print(f"sweep: {len(rows)} runs in {wall:.2f} s ({statuses}); wrote {', '.join(os.path.relpath(w) for w in written)}")
    for r in rows:
        if r["status"] != "ok":
            print(f"  run {r['run']} ({', '.join(f'{k}={cell(r[k])}' for k, _ in axes)}): {r['status']}: {r['message']}")
    if twins:
        print(predictability_summary(rows[-1], twins, sum(1 for r in rows if str(r["run"]).startswith("twin") and r["status"] in ("ok", "warning"))))
    return 0


def predictability_summary(ref, twins, completed):
    """The horizon T_p and the twins' floor, in a sentence."""
    start = f"predictability: {completed} of {twins} twins of the reference started {TWIN_OFFSET:g} m away completed"
    if completed == 0 or math.isnan(ref["twinsE"]):
        return f"{start}; no horizon known, E_window is E over the whole run"
    if math.isnan(ref["horizon"]):
        return (
            f"{start}; no horizon within the run: their E stays below {HORIZON_THRESHOLD:g} "
            f"(floor {ref['twinsE']:.3g} over the run), so E_window is E over the whole run"
        )
    return (
        f"{start}; horizon T_p = {ref['horizon']:g} s (a twin's E over [0, T_p] reaches {HORIZON_THRESHOLD:g}); "
        f"twins' floor {ref['twinsE_window']:.3g} over [0, T_p], {ref['twinsE']:.3g} over the run; E_window is E over [0, T_p]"
    )


if __name__ == "__main__":
    sys.exit(main())
