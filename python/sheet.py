"""One sheet run through the FMU with fmpy, by variable name: the canonical
scenes' values from modelDescription/variables.toml, any other variable on
top, mode weights fixed or chosen from what the FMU reports after set-up
(modeOutOfPlane, modeSymmetry, modeFrequencies), and weights or other tunable
values changed at given communication points. The node positions after
every communication step come back as an array.

Used by python/control.py (the paper's control experiments and control in
3D) and its tests; the examples in python/examples/ show the same calls
written out with fmpy alone."""

import os
import shutil
import tomllib
from dataclasses import dataclass, field

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi3 import FMU3Slave

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def scene(name):
    """The start values of a canonical scene (the fields of its [scenes.NAME] table)."""
    with open(os.path.join(ROOT, "modelDescription", "variables.toml"), "rb") as f:
        scenes = tomllib.load(f)["scenes"]
    if name not in scenes:
        raise ValueError(f"unknown scene {name!r} (scenes: {', '.join(sorted(scenes))})")
    return dict(scenes[name])


@dataclass
class Run:
    """What one run gives: the grid's width nx, the output times, the node positions (times, nodes,
    D) after each step, the positions before the first step, the springs as
    node pairs, the held nodes, the outputs read once after set-up and what
    the FMU logged (status, category, message)."""

    label: str
    nx: int
    times: np.ndarray
    frames: np.ndarray
    start: np.ndarray
    springs: np.ndarray
    fixed: list
    setup: dict = field(default_factory=dict)
    messages: list = field(default_factory=list)

    @property
    def dim(self):
        return self.frames.shape[2]


class Fmu:
    """The FMU extracted once into a temporary directory (`close` removes
    it; also a context manager); `run` makes one instance per run."""

    def __init__(self, path):
        self.path = str(path)
        self.md = read_model_description(self.path)
        self.dir = extract(self.path)
        self.vars = {v.name: v for v in self.md.modelVariables}

    def close(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *_):
        self.close()

    def _set(self, inst, name, value):
        v = self.vars[name]
        vr = [v.valueReference]
        if v.type == "Enumeration":
            items = {i.name: int(i.value) for i in v.declaredType.items}
            inst.setInt64(vr, [items[value] if isinstance(value, str) else int(value)])
        elif v.type == "Boolean":
            inst.setBoolean(vr, [bool(value)])
        elif v.type == "UInt64":
            inst.setUInt64(vr, [int(value)])
        elif v.type == "Float64":
            inst.setFloat64(vr, [float(x) for x in np.atleast_1d(value)])
        else:
            raise ValueError(f"{name}: type {v.type} not handled here")

    def get(self, inst, name, n=1):
        """A Float64 (array of n values) or UInt64 variable of a running instance."""
        v = self.vars[name]
        if v.type == "UInt64":
            return int(inst.getUInt64([v.valueReference])[0])
        values = np.array(inst.getFloat64([v.valueReference], nValues=n))
        return values if n > 1 or v.dimensions else float(values[0])

    def run(self, label, values, stop=2.0, h=0.01, weights=None, changes=()):
        """Simulate from rest to `stop` in communication steps h.

        values: variable name -> value (a scene's table and more); structural
        parameters go in in Configuration Mode, the rest before initialization.
        weights: a list of modeWeights, or a function of the set-up outputs
        (a dict with modeFrequencies, modeOutOfPlane, modeSymmetry) giving one;
        applied in Step Mode before the first step.
        changes: (t, {name: value or function of the set-up outputs}) pairs,
        applied at the communication point t, before the step that starts there.
        """
        inst = FMU3Slave(guid=self.md.guid, unzipDirectory=self.dir, modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=label)
        messages = []

        def logger(_env, status, category, message):
            messages.append((int(status), category.decode(), message.decode(errors="replace")))

        inst.instantiate(logMessage=logger)
        try:
            structural = {n: v for n, v in values.items() if self.vars[n].causality == "structuralParameter"}
            if structural:
                inst.enterConfigurationMode()
                for n, v in structural.items():
                    self._set(inst, n, v)
                inst.exitConfigurationMode()
            for n, v in values.items():
                if n not in structural:
                    self._set(inst, n, v)
            inst.enterInitializationMode(startTime=0.0)
            inst.exitInitializationMode()

            nx, ny, dim, r = (self.get(inst, n) for n in ("nx", "ny", "dimension", "nModes"))
            setup = {n: self.get(inst, n, r) for n in ("modeFrequencies", "modeOutOfPlane", "modeSymmetry")}
            setup["nModes"] = r
            resolve = lambda v: v(setup) if callable(v) else v  # noqa: E731
            if weights is not None:
                self._set(inst, "modeWeights", resolve(weights))
            n = nx * ny * dim
            start = self.get(inst, "positions", n).reshape(-1, dim)
            # springNeighbours: [ny][nx][6], the nodes each node's springs join it to
            pairs = springs(inst.getUInt64([self.vars["springNeighbours"].valueReference], nValues=nx * ny * 6), nx * ny)
            steps = int(round(stop / h))
            pending = sorted(((int(round(t / h)), c) for t, c in changes), key=lambda kc: kc[0])
            frames = np.empty((steps, nx * ny, dim))
            for k in range(steps):
                for when, change in pending:
                    if when == k:
                        for name, v in change.items():
                            self._set(inst, name, resolve(v))
                inst.doStep(currentCommunicationPoint=k * h, communicationStepSize=h)
                frames[k] = np.asarray(inst.getFloat64([self.vars["positions"].valueReference], nValues=n)).reshape(-1, dim)
            var = self.vars["fixedNodes"]
            items = {int(i.value): i.name for i in var.declaredType.items}
            held = values.get("fixedNodes", var.start)
            fixed = fixed_nodes(nx, held if isinstance(held, str) else items[int(held)])
            return Run(label, nx, h * np.arange(1, steps + 1), frames, start, pairs, fixed, setup, messages)
        finally:
            inst.terminate()
            inst.freeInstance()


def springs(neighbours, n):
    """Node pairs (i, j) of the springs of a sheet of n nodes from the FMU's
    springNeighbours: per node the nodes j > i it is joined to, then n (no
    node) in the places left."""
    j = np.asarray(neighbours, dtype=np.int64).reshape(n, -1)
    i = np.repeat(np.arange(n), j.shape[1])
    j = j.ravel()
    keep = j < n
    return np.stack([i[keep], j[keep]], axis=1)


def fixed_nodes(nx, kind):
    """The held nodes of a sheet nx nodes wide: the top row, or its two corners
    (fixedNodes = top-row or top-corners)."""
    return list(range(nx)) if kind == "top-row" else [0, nx - 1]
