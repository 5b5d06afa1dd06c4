"""One run of a sweep, on whichever process it lands: the FMU extracted once
per machine, one fmpy.simulate_fmu run of one point of the grid, and its row
of summary numbers (with the node positions when a reference is compared).

The Dask workers get these functions by value (sweeping.cluster), so this
module imports nothing a worker lacks: fmpy and numpy only."""

import hashlib
import math
import os
import shutil
import tempfile
import time
import zipfile

import numpy as np

from .grid import METRICS, STATUS_NAMES, STEP


def time_average(times, values, start):
    """The average of `values` over [start, times[-1]], each value (at the
    end of its step) weighted by the step's length."""
    steps = np.diff(np.concatenate(([start], times)))
    return float((values * steps).sum() / steps.sum())


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
    point (`_positions`), those times (`_times`) and the positions before the
    first step (`_start`), for the error against a reference; they are not
    written out."""
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
                state.update(n=nx * ny * dim, nx=nx, dim=dim, rest=-(ny - 1) * fmu.getFloat64([vr["spacing"]])[0], sags=[], sag_times=[])
                state["omega0"] = fmu.getFloat64([vr["modeFrequencies"]], nValues=int(fmu.getUInt64([vr["nModes"]])[0]))[0]
            x = np.asarray(fmu.getFloat64([vr["positions"]], nValues=state["n"]))
            if keep_positions:
                state.setdefault("frames", []).append(x)
                state.setdefault("times", []).append(float(t))
            bottom_y = x[-state["nx"] * state["dim"] :][1 :: state["dim"]]
            state["sags"].append(state["rest"] - bottom_y.mean())
            state["sag_times"].append(float(t))
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
        sags, sag_times, start = np.array(state["sags"]), np.array(state["sag_times"]), float(res["time"][0])
        half = start + 0.5 * (sag_times[-1] - start)
        second_half = sag_times > half
        if keep_positions:
            row["_positions"] = np.array(state["frames"])
            row["_times"] = state["times"]
            row["_start"] = start_positions(unzipdir, md, start_values)
            row["_dim"] = state["dim"]
        row.update(
            finalTime=float(res["time"][-1]),
            meanSag=time_average(sag_times, sags, start),
            settledSag=time_average(sag_times[second_half], sags[second_half], half),
            maxSag=float(sags.max()),
            finalSag=float(sags[-1]),
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
