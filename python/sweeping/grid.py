"""The grid of a sweep and the columns of its rows: which variables take a
start value, their values parsed from the command line's NAME=V1,V2,...
texts, every combination of them, the experiment's stop time and step."""

import itertools

# A sweep axis that is not a variable of the FMU: the communication step.
STEP = "step"

# Result columns after the swept parameters, in this order.
METRICS = [
    "status",  # ok, warning (completed, the FMU warned), discard (a step was refused), error (refused)
    "finalTime",  # s, the time the run reached
    # The sag: how far the bottom row's mean y is below its rest position.
    # Without damping the sheet swings about its equilibrium for the whole
    # run, so the sag at one instant (finalSag) may be anywhere in a swing;
    # its time averages sit near the static sag.
    "meanSag",  # m, the sag averaged over time over the whole run (each output point weighted by its step)
    "settledSag",  # m, the same average over the second half of the run
    "maxSag",  # m, the largest sag at the output points
    "finalSag",  # m, the sag at finalTime, one instant of the swing
    "maxKineticEnergy",  # J, over the output points
    "finalKineticEnergy",  # J
    "finalPotentialEnergy",  # J
    "maxForceResidual",  # over the output points
    "lowestFrequency",  # rad/s, modeFrequencies[0]
    "outputPoints",  # communication points after the start
    "E",  # error against the reference run (--reference), docs/method.md section 6; NaN without one
    "maxNodeError",  # m, the largest node distance from the reference over the output points
    "E_window",  # E over [0, horizon]: the window in which the scene is predictable (the whole run without a horizon)
    "horizon",  # s, the predictability horizon T_p: the earliest time a twin's E over [0, T_p] reaches 1e-3; NaN: none within the run (or no twins)
    "twinsE",  # the twins' largest E over the whole run: the floor no model of the scene can be judged below; NaN without twins (--twins 0)
    "twinsE_window",  # the twins' largest E over [0, horizon], the floor of E_window
    "message",  # the FMU's warnings and errors, or the exception of a refused run
]
# Columns that differ from one execution of the same run to the next: left
# out when two sweeps are compared.
NONDETERMINISTIC = ["wallTime", "worker"]

STATUS_NAMES = {1: "warning", 2: "discard", 3: "error", 4: "fatal"}


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
    return [dict(zip(names, combo, strict=True)) for combo in itertools.product(*(v for _, v in axes))]


def experiment(md, stop_time=None, step=None):
    """(stop time, step): the ones given, else the FMU's default experiment's."""
    de = md.defaultExperiment
    if stop_time is None:
        stop_time = float(de.stopTime) if de and de.stopTime else 2.0
    if step is None:
        step = float(de.stepSize) if de and de.stepSize else 0.01
    return stop_time, step


def columns(axes):
    return ["run"] + [n for n, _ in axes] + METRICS + NONDETERMINISTIC
