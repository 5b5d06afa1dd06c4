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

The numbers of a run depend on its start values only: the same sweep gives the
same CSV, bit for bit, serially or on any number of workers of this machine,
except the columns wallTime and worker (see NONDETERMINISTIC).
"""

import argparse
import hashlib
import itertools
import math
import os
import shutil
import sys
import tempfile
import time
import zipfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_FMU = os.path.join(ROOT, "target", "fmu", "ModalMassSpring.fmu")
DEFAULT_OUT = os.path.join(ROOT, "out", "sweep", "sweep.csv")

# A sweep axis that is not a variable of the FMU: the communication step.
STEP = "step"

# Result columns after the swept parameters, in this order.
METRICS = [
    "status",  # ok, warning (completed, the FMU warned), discard (a step was refused), error (refused)
    "finalTime",  # s, the time the run reached
    "finalSag",  # m, how far the bottom row's mean y is below its rest position at finalTime
    "maxSag",  # m, the largest of it over the output points
    "maxKineticEnergy",  # J, over the output points
    "finalKineticEnergy",  # J
    "finalPotentialEnergy",  # J
    "maxForceResidual",  # over the output points
    "lowestFrequency",  # rad/s, modeFrequencies[0]
    "outputPoints",  # communication points after the start
    "E",  # error against the reference run (--reference), docs/method.md section 6; NaN without one
    "maxNodeError",  # m, the largest node distance from the reference over the output points
    "message",  # the FMU's warnings and errors, or the exception of a refused run
]
# Columns that differ from one execution of the same run to the next: left
# out when two sweeps are compared.
NONDETERMINISTIC = ["wallTime", "worker"]

STATUS_NAMES = {1: "warning", 2: "discard", 3: "error", 4: "fatal"}


# -- the grid ------------------------------------------------------------------


def sweepable(md):
    """name -> model variable of everything a start value can be given to."""
    return {
        v.name: v
        for v in md.modelVariables
        if v.causality in ("parameter", "structuralParameter", "input") and v.variability != "constant" and v.initial in ("exact", "approx", None)
    }


def parse_value(var, text):
    """One start value of `var` from its text on the command line."""
    text = text.strip()
    if var is None:  # the step
        value = float(text)
        if not value > 0:
            raise ValueError(f"{STEP} must be positive, not {text}")
        return value
    if var.shape:
        return [parse_value(_Scalar(var), t) for t in text.split()]
    if var.type == "Boolean":
        if text.lower() in ("true", "1"):
            return True
        if text.lower() in ("false", "0"):
            return False
        raise ValueError(f"{var.name} is a Boolean: true or false, not {text!r}")
    if var.type == "Enumeration":
        items = {i.name: int(i.value) for i in var.declaredType.items} if var.declaredType is not None else {}
        if text in items:
            return text
        by_value = {v: k for k, v in items.items()}
        try:
            return by_value[int(text)]
        except (ValueError, KeyError):
            raise ValueError(f"{var.name}: {text!r} is none of {', '.join(items)}") from None
    if var.type.startswith(("Int", "UInt")):
        return int(text)
    return float(text)


class _Scalar:
    """An array variable's element type, for parse_value."""

    def __init__(self, var):
        self.name, self.type, self.shape, self.declaredType = var.name, var.type, (), var.declaredType


def parse_grid(md, params):
    """[(name, [values])] from the --param texts NAME=V1,V2,..."""
    names = sweepable(md)
    axes = []
    for p in params:
        name, sep, values = p.partition("=")
        name = name.strip()
        if not sep or not values.strip():
            raise ValueError(f"--param {p!r}: expected NAME=V1,V2,...")
        if name != STEP and name not in names:
            raise ValueError(f"--param {name}: not a parameter of {md.modelName}; one of {STEP}, {', '.join(names)}")
        if name in (a for a, _ in axes):
            raise ValueError(f"--param {name} given twice")
        var = None if name == STEP else names[name]
        axes.append((name, [parse_value(var, v) for v in values.split(",")]))
    return axes


def grid_points(axes):
    """Every combination of the axes' values, the last axis varying fastest."""
    names = [n for n, _ in axes]
    return [dict(zip(names, combo)) for combo in itertools.product(*(v for _, v in axes))]


# -- one run -------------------------------------------------------------------


def fmu_digest(data):
    return hashlib.sha256(data).hexdigest()[:16]


def unpacked_fmu(data, digest):
    """The FMU `data` extracted once per machine and user into the temporary
    directory (a directory named by its digest; several worker processes may
    race for it, the first complete one wins)."""
    target = os.path.join(tempfile.gettempdir(), f"mms-sweep-{os.getuid()}-{digest}")
    if os.path.isfile(os.path.join(target, "modelDescription.xml")):
        return target
    staging = tempfile.mkdtemp(prefix=os.path.basename(target) + ".", dir=os.path.dirname(target))
    path = os.path.join(staging, "fmu.zip")
    with open(path, "wb") as f:
        f.write(data)
    with zipfile.ZipFile(path) as z:
        z.extractall(os.path.join(staging, "fmu"))
    try:
        os.rename(os.path.join(staging, "fmu"), target)
    except OSError:
        if not os.path.isfile(os.path.join(target, "modelDescription.xml")):
            raise
    shutil.rmtree(staging, ignore_errors=True)
    return target


def fmpy_start_value(var, value):
    """The start value as fmpy's apply_start_values takes it."""
    if var.type == "Enumeration":
        return {i.name: int(i.value) for i in var.declaredType.items}[value]
    return value


def run_one(fmu_data, digest, point, stop_time, step, keep_positions=False):
    """Simulate one point of the grid with fmpy.simulate_fmu; returns its row
    (the point's values, then METRICS and NONDETERMINISTIC). With
    `keep_positions` the row also holds the node positions at every output
    point (`_positions`) and before the first step (`_start`), for the error
    against a reference; they are not written out."""
    from fmpy import read_model_description, simulate_fmu
    from fmpy.fmi1 import FMICallException
    from fmpy.fmi3 import FMU3Slave

    t0 = time.perf_counter()
    row = dict(point)
    row.update({m: math.nan for m in METRICS})
    row.update(status="ok", message="", outputPoints=0)
    messages = []
    fmu = None
    try:
        unzipdir = unpacked_fmu(fmu_data, digest)
        md = read_model_description(unzipdir, validate=False)
        variables = {v.name: v for v in md.modelVariables}
        vr = {n: v.valueReference for n, v in variables.items()}
        start_values = {n: fmpy_start_value(variables[n], v) for n, v in point.items() if n != STEP}
        interval = point.get(STEP, step)

        def logger(_env, status, category, message):
            if status >= 1:  # fmi3Warning and worse: what the row reports
                messages.append(message.decode(errors="replace"))

        fmu = FMU3Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier, instanceName="sweep")
        fmu.instantiate(logMessage=logger)
        state = {}

        def step_finished(t, recorder):
            if not state:  # first communication point: the sizes and the rest position
                nx, ny, dim = (int(x) for x in fmu.getUInt64([vr["nx"], vr["ny"], vr["dimension"]]))
                state.update(n=nx * ny * dim, nx=nx, dim=dim, rest=-(ny - 1) * fmu.getFloat64([vr["spacing"]])[0], sags=[])
                state["omega0"] = fmu.getFloat64([vr["modeFrequencies"]], nValues=int(fmu.getUInt64([vr["nModes"]])[0]))[0]
            x = np.asarray(fmu.getFloat64([vr["positions"]], nValues=state["n"]))
            if keep_positions:
                state.setdefault("frames", []).append(x)
            bottom_y = x[-state["nx"] * state["dim"] :][1 :: state["dim"]]
            state["sags"].append(state["rest"] - bottom_y.mean())
            return True

        res = simulate_fmu(
            unzipdir,
            validate=False,
            stop_time=stop_time,
            output_interval=interval,
            start_values=start_values,
            output=["kineticEnergy", "potentialEnergy", "forceResidual"],
            step_finished=step_finished,
            model_description=md,
            fmu_instance=fmu,
        )
        sags = np.array(state["sags"])
        if keep_positions:
            row["_positions"] = np.array(state["frames"])
            row["_start"] = start_positions(unzipdir, md, start_values)
            row["_dim"] = state["dim"]
        row.update(
            finalTime=float(res["time"][-1]),
            finalSag=float(sags[-1]),
            maxSag=float(sags.max()),
            maxKineticEnergy=float(res["kineticEnergy"].max()),
            finalKineticEnergy=float(res["kineticEnergy"][-1]),
            finalPotentialEnergy=float(res["potentialEnergy"][-1]),
            maxForceResidual=float(res["forceResidual"].max()),
            lowestFrequency=float(state["omega0"]),
            outputPoints=len(sags),
        )
        if messages:
            row["status"] = "warning"
    except FMICallException as e:
        row["status"] = STATUS_NAMES.get(e.status, "error")
        messages = messages or [str(e)]
    except Exception as e:  # fmpy's own checks of the start values, an FMU that does not load, ...
        row["status"] = "error"
        messages.append(f"{type(e).__name__}: {e}")
    finally:
        if fmu is not None:
            fmu.freeInstance()
    row["message"] = " | ".join(messages)
    row["wallTime"] = time.perf_counter() - t0
    row["worker"] = f"{os.uname().nodename}:{os.getpid()}"
    return row


def start_positions(unzipdir, md, start_values):
    """The node positions a run with these start values begins at: read from
    a fresh instance right after initialization."""
    from fmpy.fmi3 import FMU3Slave
    from fmpy.simulation import apply_start_values

    fmu = FMU3Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier, instanceName="start")
    fmu.instantiate()
    try:
        apply_start_values(fmu, md, dict(start_values))
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        vr = {v.name: v.valueReference for v in md.modelVariables}
        nx, ny, dim = (int(x) for x in fmu.getUInt64([vr["nx"], vr["ny"], vr["dimension"]]))
        return np.asarray(fmu.getFloat64([vr["positions"]], nValues=nx * ny * dim))
    finally:
        fmu.freeInstance()


def error_against(row, ref):
    """E of docs/method.md section 6 (every node has the same mass) and the
    largest node distance, of a run's positions against the reference's at
    the same output points; NaN where the run did not complete or its output
    points differ."""
    x, r = row.get("_positions"), ref.get("_positions")
    if x is None or r is None or x.shape != r.shape:
        return math.nan, math.nan
    dim = ref["_dim"]
    diff = (x - r).reshape(len(x), -1, dim)
    motion = (r - ref["_start"]).reshape(len(r), -1, dim)
    e = math.sqrt(float((diff**2).sum())) / math.sqrt(float((motion**2).sum()))
    return e, float(np.sqrt((diff**2).sum(axis=2)).max())


# -- the sweep -----------------------------------------------------------------


def experiment(md, stop_time=None, step=None):
    """(stop time, step): the ones given, else the FMU's default experiment's."""
    de = md.defaultExperiment
    if stop_time is None:
        stop_time = float(de.stopTime) if de and de.stopTime else 2.0
    if step is None:
        step = float(de.stepSize) if de and de.stepSize else 0.01
    return stop_time, step


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


def run_on_cluster(client, data, digest, points, stop_time, step, progress, keep_positions=False):
    import cloudpickle
    from distributed import progress as progress_bar
    from distributed import wait

    # The workers get run_one by value, so a cluster's workers need fmpy and
    # numpy but not this file.
    module = sys.modules[__name__]
    if module.__name__ != "__main__":
        cloudpickle.register_pickle_by_value(module)
    # A key of its own (hash=False): a content-hashed key would be shared by
    # every sweep of the same FMU on this client, and this sweep's cancel at
    # the end could then drop the data a following sweep has just scattered.
    fmu_data = client.scatter(data, broadcast=True, hash=False)
    futures = [client.submit(run_one, fmu_data, digest, p, stop_time, step, keep_positions, pure=False) for p in points]
    if progress:
        progress_bar(futures)
        print()
    wait(futures)
    rows = []
    for point, future in zip(points, futures):
        try:
            rows.append(future.result())
        except Exception as e:  # a worker that died on this run, ...
            row = dict(point)
            row.update({m: math.nan for m in METRICS})
            row.update(status="error", message=f"{type(e).__name__}: {e}", outputPoints=0, wallTime=math.nan, worker="")
            rows.append(row)
    client.cancel([fmu_data])
    return rows


def columns(axes):
    return ["run"] + [n for n, _ in axes] + METRICS + NONDETERMINISTIC


# -- output --------------------------------------------------------------------


def cell(value):
    """Text of one CSV cell: floats exactly (repr), arrays space-separated."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, (list, tuple)):
        return " ".join(cell(v) for v in value)
    return str(value)


def write_csv(path, rows, cols):
    import csv

    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(cols)
        for r in rows:
            w.writerow([cell(r[c]) for c in cols])


def write_parquet(path, rows, cols):
    """Parquet next to the CSV when pyarrow is installed; returns whether it was written."""
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        return False
    table = pa.table({c: [r[c] for r in rows] for c in cols})
    pq.write_table(table, path)
    return True


PLOTTED = [
    ("finalSag", "final sag of the bottom row [m]"),
    ("maxKineticEnergy", "largest kinetic energy [J]"),
    ("finalPotentialEnergy", "final potential energy [J]"),
    ("wallTime", "wall time of the run [s]"),
]


def plot(path, rows, axes, title):
    """One panel per summary number against the first swept parameter that
    takes more than one number (else the first that takes more than one
    value), one line per combination of the others."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    varying = [(n, v) for n, v in axes if len(v) > 1]
    is_number = lambda v: isinstance(v, (int, float)) and not isinstance(v, bool)
    varying.sort(key=lambda axis: not all(is_number(v) for v in axis[1]))  # stable: numbers first
    if varying:
        xname, xvalues = varying[0]
    else:
        xname, xvalues = "run", list(range(len(rows)))
    others = [n for n, _ in varying[1:]]
    numeric = all(is_number(v) for v in xvalues)
    labels = [cell(v) for v in xvalues]

    def xpos(row):
        value = row[xname]
        return value if numeric else labels.index(cell(value))

    series = {}
    for r in rows:
        series.setdefault(tuple(cell(r[n]) for n in others), []).append(r)
    fig, panels = plt.subplots(2, 2, figsize=(11, 7.5), sharex=True)
    for ax, (metric, ylabel) in zip(panels.flat, PLOTTED):
        for key, rs in series.items():
            ok = sorted((r for r in rs if r["status"] in ("ok", "warning") and not math.isnan(r[metric])), key=xpos)
            label = ", ".join(f"{n}={k}" for n, k in zip(others, key)) or None
            ax.plot([xpos(r) for r in ok], [r[metric] for r in ok], "o-", ms=4, label=label)
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3)
        if numeric and min(xvalues) > 0 and max(xvalues) >= 10 * min(xvalues):
            ax.set_xscale("log")
    for ax in panels[1]:
        ax.set_xlabel(xname)
        if not numeric:
            ax.set_xticks(range(len(labels)), labels)
    if others and len(series) <= 12:
        panels[0, 0].legend(fontsize=8)
    refused = [r for r in rows if r["status"] not in ("ok", "warning")]
    fig.suptitle(title + (f"\n{len(refused)} of {len(rows)} runs refused (their messages are in the CSV)" if refused else ""))
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)


def plot_error(path, rows, title):
    """Error against run time: E of every completed run against its wall time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    done = [r for r in rows if r["run"] != "reference" and not math.isnan(r["E"]) and r["E"] > 0]
    fig, ax = plt.subplots(figsize=(7, 5))
    ax.loglog([r["wallTime"] for r in done], [r["E"] for r in done], "o")
    for r in done:
        ax.annotate(str(r["run"]), (r["wallTime"], r["E"]), fontsize=7, xytext=(3, 3), textcoords="offset points")
    ax.set_xlabel("wall time of the run [s]")
    ax.set_ylabel("E against the reference")
    ax.grid(alpha=0.3, which="both")
    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


# -- command line ---------------------------------------------------------------


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
        "every run gets E and maxNodeError against it (docs/method.md section 6), and the plot shows E against run time",
    )
    p.add_argument("--no-plot", action="store_true")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    a = p.parse_args(argv)

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
    n = len(grid_points(axes))
    grid = " x ".join(f"{name} ({len(v)})" for name, v in axes) or "the FMU's start values"
    t0 = time.perf_counter()
    if a.serial:
        print(f"sweep: {n} runs of {grid}, serially")
        rows = run_sweep(a.fmu, axes, a.stop_time, a.step, progress=not a.quiet, reference=reference)
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
            rows = run_sweep(a.fmu, axes, a.stop_time, a.step, client=client, progress=not a.quiet, reference=reference)
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
        grid_rows = rows[:-1] if reference is not None else rows
        plot(stem + ".png", grid_rows, axes, f"{md.modelName}: {os.path.basename(a.fmu)}, {n} runs; {setting}")
        written.append(stem + ".png")
        if reference is not None:
            ref = ", ".join(f"{k}={cell(v)}" for k, v in reference.items())
            plot_error(stem + "-error.png", rows, f"error against run time; reference {ref}; {setting}")
            written.append(stem + "-error.png")
    counts = {}
    for r in rows:
        counts[r["status"]] = counts.get(r["status"], 0) + 1
    print(f"sweep: {n} runs in {wall:.2f} s ({', '.join(f'{c} {s}' for s, c in sorted(counts.items()))}); wrote {', '.join(os.path.relpath(w) for w in written)}")
    for r in rows:
        if r["status"] != "ok":
            print(f"  run {r['run']} ({', '.join(f'{k}={cell(r[k])}' for k, _ in axes)}): {r['status']}: {r['message']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
