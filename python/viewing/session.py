"""One FMU instance driven live: set up from a scene's values, stepped in
real time, its tunable values and inputs changed as a page asks (each value
checked before the FMU sees it), its outputs read as frames.

A value the page sends is refused here, with the reason in the session's
messages, when it is not a finite number of the right count and range; a
value the FMU itself refuses (fmi3Error from a Set) leaves the instance as
it was (the FMU keeps its last good state) and its log line is shown. A
step the FMU discards (a diverging step, an anchor moved too fast) pauses
the run at the last good state."""

import ctypes
import math
import time
import numpy as np
from fmpy.fmi1 import FMICallException
from fmpy.fmi3 import FMU3Slave, fmi3Float64, fmi3ValueReference

from sheet import Fmu, springs

# The page may move a holder at most this far from rest [m], and pull the
# load node with at most this force per unit of its weight.
FARTHEST_ANCHOR = 5.0
STRONGEST_PULL = 50.0
# The most recent FMU log lines a session keeps for its page.
KEPT_MESSAGES = 50
READOUTS = ("kineticEnergy", "potentialEnergy", "forceResidual", "trainingRange", "errorEstimate", "reducedFraction")
STATUS = ["OK", "Warning", "Discard", "Error", "Fatal"]


class Refused(ValueError):
    """A value the page sent that the session did not pass on (the reason is the message)."""


def holders_of(values, nx, ny, n_holders, holder_of_node):
    """The nodes each holder holds, as the FMU assigns them (variables.toml, fixedNodes)."""
    kind = values.get("fixedNodes", 1)
    kind = {"top-row": 1, "top-corners": 2, "custom": 3}.get(kind, kind)
    if int(kind) == 3:
        ids = np.asarray(holder_of_node, dtype=np.int64).reshape(ny * nx)
        return [list(np.flatnonzero(ids == k + 1)) for k in range(n_holders)]
    columns = list(range(nx)) if int(kind) == 1 else [0, nx - 1]
    m = len(columns)
    return [[c for i, c in enumerate(columns) if (i * n_holders) // m == k] for k in range(n_holders)]


def prefix(k):
    """The name prefix of holder k's inputs and outputs (0-based: anchor, anchor2, ...)."""
    return "anchor" if k == 0 else f"anchor{k + 1}"


class Session:
    """One instance of the FMU for one page."""

    def __init__(self, fmu: Fmu, values: dict, label="view", h=0.01):
        self.fmu, self.values, self.h = fmu, dict(values), h
        self.messages = []
        self.inst = FMU3Slave(guid=fmu.md.guid, unzipDirectory=fmu.dir, modelIdentifier=fmu.md.coSimulation.modelIdentifier, instanceName=label)
        self.inst.instantiate(logMessage=self._log)
        self.closed = False
        try:
            self._set_up()
        except FMICallException as e:
            self.close()
            why = "; ".join(text for status, _, text in self.messages if status != "OK") or str(e)
            raise Refused(f"the FMU refused the scene's set-up: {why}") from None
        except Exception:
            self.close()
            raise

    def _log(self, _env, status, category, message):
        text = message.decode(errors="replace")
        self.messages.append((STATUS[status] if 0 <= status < len(STATUS) else str(status), category.decode(errors="replace"), text))
        del self.messages[:-KEPT_MESSAGES]

    def _set_up(self):
        fmu, inst = self.fmu, self.inst
        structural = {n: v for n, v in self.values.items() if fmu.vars[n].causality == "structuralParameter"}
        if structural:
            inst.enterConfigurationMode()
            for n, v in structural.items():
                fmu._set(inst, n, v)
            inst.exitConfigurationMode()
        for n, v in self.values.items():
            if n not in structural:
                fmu._set(inst, n, v)
        inst.enterInitializationMode(startTime=0.0)
        inst.exitInitializationMode()
        get = lambda n, k=1: fmu.get(inst, n, k)  # noqa: E731
        self.nx, self.ny, self.dim, self.r, self.n_holders = (get(n) for n in ("nx", "ny", "dimension", "nModes", "nHolders"))
        self.n = self.nx * self.ny
        self.frequencies = np.atleast_1d(get("modeFrequencies", self.r))
        self.out_of_plane = np.atleast_1d(get("modeOutOfPlane", self.r))
        self.symmetry = np.atleast_1d(get("modeSymmetry", self.r))
        self.weights = np.atleast_1d(get("modeWeights", self.r)).astype(float)
        self.reduction = int(inst.getInt64([fmu.vars["reduction"].valueReference])[0])
        self.springs = springs(inst.getUInt64([fmu.vars["springNeighbours"].valueReference], nValues=self.n * 6), self.n)
        holder_of_node = inst.getUInt64([fmu.vars["holderOfNode"].valueReference], nValues=self.n)
        self.holders = holders_of(self.values, self.nx, self.ny, self.n_holders, holder_of_node)
        # loadRow counts from the bottom edge; the output order starts at the top row.
        self.load_node = (self.ny - 1 - int(get("loadRow"))) * self.nx + int(get("loadColumn"))
        self.gravity = np.atleast_1d(get("gravity", 3)).astype(float)
        self.damping = [get("dampingAlpha"), get("dampingBeta")]
        self.weight = float(get("nodeMass")) * self.n * 9.81
        # Reads through fmpy's binding of fmi3GetFloat64 into arrays kept here (no Python lists).
        self._positions = np.empty(self.n * self.dim)
        self._positions_vr = (fmi3ValueReference * 1)(fmu.vars["positions"].valueReference)
        names = list(READOUTS) + [prefix(k) + f"Force{a}" for k in range(self.n_holders) for a in "XYZ"]
        self._readout_names = names
        self._readouts = np.empty(len(names))
        self._readouts_vr = (fmi3ValueReference * len(names))(*(fmu.vars[n].valueReference for n in names))
        self.start = self.positions()
        self.time = 0.0
        self.anchors = np.zeros((self.n_holders, 6))
        self.load = np.zeros(3)

    def _read(self, vrs, out):
        ptr = out.ctypes.data_as(ctypes.POINTER(fmi3Float64))
        self.inst.fmi3GetFloat64(self.inst.component, vrs, len(vrs), ptr, out.size)
        return out

    def positions(self):
        """Node positions, (nodes, dimension), in the order of the grid (row-major, row 0 on top)."""
        return self._read(self._positions_vr, self._positions).reshape(self.n, self.dim).copy()

    def mode_shapes(self):
        """modeShapes as (modes, nodes, dimension)."""
        v = self.fmu.vars["modeShapes"].valueReference
        return np.asarray(self.inst.getFloat64([v], nValues=self.r * self.n * self.dim)).reshape(self.r, self.n, self.dim)

    def _checked(self, name, values, lo=-math.inf, hi=math.inf, count=None):
        try:
            array = np.array(values, dtype=float).ravel()
        except (TypeError, ValueError) as e:
            raise Refused(f"{name}: not numbers ({e})") from None
        if count is not None and array.size != count:
            raise Refused(f"{name}: {array.size} values where {count} are expected")
        if not np.all(np.isfinite(array)):
            raise Refused(f"{name}: not finite ({array.tolist()})")
        if np.any(array < lo) or np.any(array > hi):
            raise Refused(f"{name}: outside [{lo}, {hi}] ({array.tolist()})")
        return array

    def _apply(self, name, array):
        """Sets a variable; an FMU refusal becomes Refused (the FMU keeps its last good state)."""
        try:
            self.fmu._set(self.inst, name, array if array.size > 1 else array[0])
        except FMICallException:
            last = self.messages[-1][2] if self.messages else "no message"
            raise Refused(f"{name}: the FMU refused it: {last}") from None

    def set_weights(self, weights):
        if self.reduction != 1:
            raise Refused("modeWeights: only a modal run (reduction = modal) takes mode weights")
        w = self._checked("modeWeights", weights, 0.0, 10.0, self.r)
        self._apply("modeWeights", w)
        self.weights = w

    def set_gravity(self, gravity):
        g = self._checked("gravity", gravity, -100.0, 100.0, 3)
        self._apply("gravity", g)
        self.gravity = g

    def set_damping(self, alpha, beta):
        a = self._checked("dampingAlpha", [alpha], 0.0, 100.0)
        b = self._checked("dampingBeta", [beta], 0.0, 1.0)
        self._apply("dampingAlpha", a)
        self._apply("dampingBeta", b)
        self.damping = [float(a[0]), float(b[0])]

    def checked_anchor(self, k, translation, rotation=(0.0, 0.0, 0.0)):
        """Holder k's (0-based) translation and rotation vector, checked: the six anchor inputs."""
        if not (isinstance(k, int) and 0 <= k < self.n_holders):
            raise Refused(f"holder {k!r}: the scene has {self.n_holders}")
        t = self._checked("holder translation", translation, -FARTHEST_ANCHOR, FARTHEST_ANCHOR, 3)
        r = self._checked("holder rotation", rotation, -4 * math.pi, 4 * math.pi, 3)
        return np.concatenate([t, r])

    def set_anchor(self, k, translation, rotation=(0.0, 0.0, 0.0)):
        """Holder k (0-based) displaced by `translation` and turned by the rotation vector `rotation`
        from rest; the FMU moves it there over the next step."""
        self.anchors[k] = self.checked_anchor(k, translation, rotation)

    def set_load(self, force):
        """The point load on the load node [N]."""
        limit = STRONGEST_PULL * self.weight
        self.load = self._checked("point load", force, -limit, limit, 3)

    def step(self):
        """One communication step of h with the holders and the load as set;
        a step the FMU refuses is undone (the inputs go back to their last values)."""
        p = self.fmu.vars
        names, values = [], []
        for k in range(self.n_holders):
            axes = ["X", "Y", "Z", "RX", "RY", "RZ"]
            names += [prefix(k) + a for a in axes]
            values += list(self.anchors[k])
        names += ["loadX", "loadY", "loadZ"]
        values += list(self.load)
        try:
            self.inst.setFloat64([p[n].valueReference for n in names], values)
            self.inst.doStep(currentCommunicationPoint=self.time, communicationStepSize=self.h)
        except FMICallException as e:
            last = self.messages[-1][2] if self.messages else str(e)
            raise Refused(f"step at t = {self.time:.3f} s refused: {last}") from None
        self.time += self.h

    def readouts(self):
        """The energies, the error indicators and each holder's force, in one Get."""
        v = dict(zip(self._readout_names, self._read(self._readouts_vr, self._readouts).tolist(), strict=True))
        out = {n: v[n] for n in READOUTS}
        for k in range(self.n_holders):
            out[f"holder {k + 1} force"] = [v[prefix(k) + f"Force{a}"] for a in "XYZ"]
        return out

    def close(self):
        if not self.closed:
            self.closed = True
            try:
                self.inst.terminate()
            except FMICallException:
                pass  # an instance in error (a refused set-up) is freed all the same
            finally:
                self.inst.freeInstance()


class Clock:
    """Real-time pacing: how many steps of h bring simulated time up to the
    wall clock since `resume` (at most `most` per call, so a slow machine
    runs slower than real time instead of falling ever further behind)."""

    def __init__(self, h, most=20):
        self.h, self.most = h, most
        self.resume(0.0)

    def resume(self, sim_time):
        self.wall0, self.sim0 = time.perf_counter(), sim_time

    def due(self, sim_time):
        ahead = (time.perf_counter() - self.wall0) - (sim_time - self.sim0)
        k = int(ahead / self.h)
        if k > self.most:
            # Behind: start counting again from now.
            self.resume(sim_time + self.most * self.h)
            return self.most
        return max(k, 0)
