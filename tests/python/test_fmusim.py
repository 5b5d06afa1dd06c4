"""The FMU in fmusim, the reference FMI importer of the Modelica Association's
Reference-FMUs (v0.0.39, vendored in third_party/fmusim-0.0.39, built into
target/tools/fmusim by `cargo xtask fmusim`), against fmpy's simulate_fmu and
against itself across a saved and restored FMU state.

What the tests rely on, from fmusim's source (third_party/fmusim-0.0.39/fmusim):

- FMI3CSSimulation.c: communication point k is start + k * outputInterval (a
  point of an input event or the stop time in between is inserted; none here),
  each fmi3DoStep goes from the last point to the next, so its step size is
  the difference of the two, and the inputs are set before each step at the
  time the step starts.
- FMIRecorder.c: every output is a column (grouped by type, all Float64
  here); an array output is one column holding its values separated by
  spaces, in row-major order; numbers are written with "%.16g".
- FMIStaticInput.c: a continuous input is interpolated linearly between the
  rows of the input file around the step's start time,
  x0 + (t - t0) (x1 - x0) / (t1 - t0), so a value held between two rows is
  set exactly; where a time is repeated, a step starting at exactly that time
  (no tolerance) gets the later row.
- --final-fmu-state-file saves the state after the last step (fmi3GetFMUState,
  fmi3SerializeFMUState); --initial-fmu-state-file restores it right after
  instantiation (fmi3DeserializeFMUState, fmi3SetFMUState) and skips
  Initialization Mode; the steps then start at --start-time (else the default
  experiment's start), which must be the time of the state.

fmpy 0.3.32 sends the same step sizes (the same differences of the same
communication points) and sets the inputs at the same times, so the same FMU
computes the same numbers: fmusim's CSV must equal fmpy's results written the
way fmusim writes them, "%.16g", i.e. agree to the last digit fmusim keeps.
"""

import csv
import os
import re
import subprocess

import numpy as np
import pytest
from fmpy import simulate_fmu

from conftest import ROOT

H = 0.01  # output interval = communication step
STOP = 2.0
SPLIT_STEPS = 100  # (state) the run is saved after this many steps and continued
SPLIT = SPLIT_STEPS * H
# Two runs whose step sizes differ by a few ulps differ by round-off only:
# the bound tests/fmi_abi.rs sets for the same case, relative to the scale of
# the quantity.
ROUND_OFF = 1e-12
STEPS_FILE = ROOT / "tests" / "python" / "data" / "fmusim_steps.txt"
WRITE_STEPS = "MMS_WRITE_FMUSIM_STEPS"


class Run:
    """A finished fmusim run: the CSV's column names and rows (as written)
    and, when asked for, the FMI calls it logged."""

    def __init__(self, csv_path, log_path):
        with open(csv_path, newline="") as f:
            table = list(csv.reader(f))
        self.names, self.rows = table[0], table[1:]
        self.log = log_path.read_text().splitlines() if log_path else None

    def text(self, name):
        j = self.names.index(name)
        return [row[j] for row in self.rows]

    def values(self, name):
        """(rows, values per row) array of one column."""
        return np.array([[float(x) for x in cell.split(" ")] for cell in self.text(name)])


def fmusim_run(fmusim, fmu, directory, name, *options, log=False):
    """fmusim as Co-Simulation with a 0.01 s output interval, every output recorded."""
    out = directory / f"{name}.csv"
    log_path = directory / f"{name}.log" if log else None
    cmd = [fmusim, "--interface-type", "cs", "--output-interval", str(H), *options, "--output-file", str(out)]
    if log:
        cmd += ["--log-fmi-calls", "--fmi-log-file", str(log_path)]
    cmd.append(str(fmu))
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, f"{' '.join(cmd)} exited with {p.returncode}:\n{p.stdout}{p.stderr}"
    return Run(out, log_path)


def as_written(values):
    """Values the way fmusim's recorder writes them."""
    return " ".join("%.16g" % x for x in np.ravel(values))


def assert_same_as_fmpy(run, ref):
    """Every column of the fmusim run equals fmpy's result to the digits fmusim writes."""
    assert run.names[0] == "time"
    assert len(run.rows) == len(ref) == round(STOP / H) + 1
    for name in run.names:
        got = run.text(name)
        expected = [as_written(ref[name][i]) for i in range(len(ref))]
        wrong = [i for i in range(len(ref)) if got[i] != expected[i]]
        if wrong:
            diff = np.abs(run.values(name) - ref[name].reshape(len(ref), -1)).max()
            pytest.fail(f"{name}: fmusim and fmpy differ in {len(wrong)} of {len(ref)} rows, first at t = {ref['time'][wrong[0]]}, by up to {diff:.3g}")


def outputs(md):
    return [v.name for v in md.modelVariables if v.causality == "output"]


# -- fmusim's communication points (FMI3CSSimulation.c) ---------------------------


def is_close(a, b):
    """FMIIsClose of fmusim's FMIUtil.c."""
    return abs(a - b) <= 1e-5 or abs(a - b) <= 1e-5 * max(abs(a), abs(b))


def communication_steps(start, stop, h):
    """(currentCommunicationPoint, communicationStepSize) of every fmi3DoStep of
    a run without input events, computed the way fmusim does."""
    time, n, steps = start, 0, []
    while not (time > stop or is_close(time, stop)):
        regular = start + (n + 1) * h
        point = stop if regular > stop and not is_close(regular, stop) else regular
        steps.append((time, point - time))
        time = point
        if is_close(time, regular):
            n += 1
    return steps


DO_STEP = re.compile(r"fmi3DoStep\(currentCommunicationPoint=([^,]+), communicationStepSize=([^,]+),.*-> OK$")
SET_FLOAT64 = re.compile(r"fmi3SetFloat64\(valueReferences=\{(\d+)\}, nValueReferences=1, values=\{([^}]*)\}, nValues=1\) -> OK$")


def logged_steps(run):
    """(currentCommunicationPoint, communicationStepSize) of every fmi3DoStep, as logged ("%.16g")."""
    return [m.groups() for m in map(DO_STEP.match, run.log) if m]


# -- (a) the default run -------------------------------------------------------


def test_default_run_matches_fmpy(fmusim, default_fmu, default_md, tmp_path):
    """`fmusim --interface-type cs --output-interval 0.01 --stop-time 2` records
    every output, the arrays (positions, velocities, modalCoordinates) with all
    their values, and each equals fmpy's simulate_fmu to the digits it writes."""
    run = fmusim_run(fmusim, default_fmu, tmp_path, "default", "--stop-time", str(STOP))
    names = outputs(default_md)
    assert sorted(run.names[1:]) == sorted(names)
    ref = simulate_fmu(default_fmu, stop_time=STOP, output_interval=H, output=names)
    assert_same_as_fmpy(run, ref)
    assert run.values("positions").shape == (len(ref), ref["positions"][0].size) == (len(ref), 10 * 10 * 2)


# -- (b) FMU state saved to a file and restored --------------------------------


@pytest.fixture(scope="module")
def split_runs(fmusim, default_fmu, tmp_path_factory):
    """The run to 2 s in one go, and in two: to 1 s with the state saved, then
    from that state to 2 s. Every FMI call logged."""
    d = tmp_path_factory.mktemp("fmusim_state")
    state = d / "state.bin"
    full = fmusim_run(fmusim, default_fmu, d, "full", "--stop-time", str(STOP), log=True)
    first = fmusim_run(fmusim, default_fmu, d, "first", "--stop-time", str(SPLIT), "--final-fmu-state-file", str(state), log=True)
    assert state.stat().st_size > 0
    second = fmusim_run(
        fmusim, default_fmu, d, "second", "--start-time", str(SPLIT), "--stop-time", str(STOP), "--initial-fmu-state-file", str(state), log=True
    )
    return full, first, second, state


def scale_of(run, name):
    """Largest magnitude of a quantity over a run; the components X, Y, Z of a
    vector share the scale of the vector."""
    base = name[:-1] if name[-1:] in ("X", "Y", "Z") else name
    group = [base + c for c in "XYZ"] if all(base + c in run.names for c in "XYZ") else [name]
    return max(np.abs(run.values(n)).max() for n in group)


def test_state_file_continues_the_run(split_runs):
    """The run continued from the saved state is the uninterrupted run: bit for
    bit while fmusim sends both the same step sizes, to round-off after (from
    t = 1 s on its communication points are 1 + k h, not k h, so the step sizes
    differ by a few ulps)."""
    full, first, second, _ = split_runs
    assert first.log[-1] == "fmi3FreeInstance() -> OK" and any(line.startswith("fmi3SerializeFMUState(") for line in first.log)
    assert [line.split("(")[0] for line in second.log[1:3]] == ["fmi3DeserializeFMUState", "fmi3SetFMUState"]
    assert not any(line.startswith("fmi3EnterInitializationMode") for line in second.log)

    n = SPLIT_STEPS
    assert first.rows == full.rows[: n + 1]
    assert len(second.rows) == len(full.rows) - n
    # the state as restored, before any step
    assert second.rows[0] == full.rows[n]

    uninterrupted, continued = communication_steps(0.0, STOP, H)[n:], communication_steps(SPLIT, STOP, H)
    assert len(uninterrupted) == len(continued)
    same = next((k for k, (a, b) in enumerate(zip(uninterrupted, continued, strict=True)) if a != b), len(continued))
    assert second.rows[: same + 1] == full.rows[n : n + same + 1], f"the runs differ before the step sizes do (step {same} after t = {SPLIT})"

    for name in full.names:
        a, b = full.values(name)[n:], second.values(name)
        scale = STOP if name == "time" else scale_of(full, name)
        diff = np.abs(a - b).max()
        assert diff <= ROUND_OFF * scale, f"{name}: continued run differs by {diff:.3g} (scale {scale:.3g})"


def test_state_file_needs_the_start_time(fmusim, default_fmu, split_runs, tmp_path):
    """Without --start-time, fmusim steps from the default experiment's start
    (0 s) after restoring a state at 1 s; the FMU refuses the step."""
    state = split_runs[3]
    cmd = [fmusim, "--interface-type", "cs", "--output-interval", str(H), "--stop-time", str(STOP), "--initial-fmu-state-file", str(state)]
    p = subprocess.run(cmd + ["--output-file", str(tmp_path / "out.csv"), default_fmu], capture_output=True, text=True, timeout=600)
    assert p.returncode != 0
    assert "currentCommunicationPoint 0 does not match the FMU time 1" in p.stdout


def test_communication_steps(split_runs):
    """The step sizes fmusim sends, as it logs them, are the differences of
    its communication points, start + k h; recorded in
    tests/python/data/fmusim_steps.txt (rewritten with MMS_WRITE_FMUSIM_STEPS=1)."""
    full, _, second, _ = split_runs
    runs = {"uninterrupted": (full, 0.0), "continued": (second, SPLIT)}
    lines = [
        "# fmi3DoStep(currentCommunicationPoint, communicationStepSize) of fmusim 0.0.39 on the default FMU,",
        "# --interface-type cs --output-interval 0.01, as logged by --log-fmi-calls (%.16g);",
        "# uninterrupted: --stop-time 2; continued: --initial-fmu-state-file (state at 1 s) --start-time 1 --stop-time 2.",
        "# Written by tests/python/test_fmusim.py::test_communication_steps (MMS_WRITE_FMUSIM_STEPS=1).",
    ]
    for label, (run, start) in runs.items():
        steps = logged_steps(run)
        assert steps == [("%.16g" % t, "%.16g" % h) for t, h in communication_steps(start, STOP, H)], label
        lines += [f"{label} {t} {h}" for t, h in steps]
    text = "\n".join(lines) + "\n"
    if os.environ.get(WRITE_STEPS):
        STEPS_FILE.parent.mkdir(parents=True, exist_ok=True)
        STEPS_FILE.write_text(text)
    assert STEPS_FILE.exists(), f"{STEPS_FILE} is missing: run this test with {WRITE_STEPS}=1"
    assert STEPS_FILE.read_text() == text, f"fmusim's steps differ from {STEPS_FILE} (rewrite it with {WRITE_STEPS}=1)"


# -- (c) inputs from a CSV file ------------------------------------------------

# The point load as (step at which it changes, loadX, loadY) [N]: piecewise
# constant. Each change is two rows with the same time, the communication
# point k h itself (the double fmusim computes), so both masters switch at
# that step: fmusim only at exactly that time, fmpy within isclose. The values
# are 0 and powers of two: between rows fmpy interpolates as
# w0 v0 + (1 - w0) v1, which returns v0 = v1 exactly only for those.
# (step, loadX, loadY, anchorX): the point load and the anchor's target, both
# exact in binary so that fmpy's interpolation weights give them back exactly.
LOAD_SCHEDULE = [
    (0, 0.0, 0.0, 0.0),
    (30, 0.125, 0.0, 0.0),
    (40, 0.125, 0.0, 2.0**-7),
    (50, 0.125, -0.25, 2.0**-7),
    (70, 0.125, -0.25, -(2.0**-6)),
    (90, -0.25, -0.25, -(2.0**-6)),
    (120, -0.25, 0.125, 0.0),
    (140, 0.0, 0.125, 0.0),
    (160, 0.0, 0.0, 0.0),
]


def load_rows():
    rows = []
    for k, *values in LOAD_SCHEDULE:
        if rows:
            rows.append((k * H,) + rows[-1][1:])
        rows.append((k * H, *values))
    rows.append((STOP,) + rows[-1][1:])
    return rows


def load_at(step):
    """(loadX, loadY, anchorX) set for communication step `step`."""
    return next(tuple(values) for k, *values in reversed(LOAD_SCHEDULE) if k <= step)


def test_input_file_matches_fmpy(fmusim, default_fmu, default_md, tmp_path):
    """The point load and the anchor driven from a CSV file (--input-file) and
    from fmpy's input array: fmusim sets the scheduled inputs before every step, and the
    results equal fmpy's to the digits fmusim writes."""
    rows = load_rows()
    input_csv = tmp_path / "load.csv"
    input_csv.write_text("time,loadX,loadY,anchorX\n" + "".join(",".join(repr(float(v)) for v in r) + "\n" for r in rows))
    run = fmusim_run(fmusim, default_fmu, tmp_path, "load", "--stop-time", str(STOP), "--input-file", str(input_csv), log=True)

    # what fmusim set before each step
    vr = {v.name: v.valueReference for v in default_md.modelVariables}
    current, applied = {}, []
    for line in run.log:
        if m := SET_FLOAT64.match(line):
            current[int(m.group(1))] = float(m.group(2))
        elif DO_STEP.match(line):
            applied.append((current.get(vr["loadX"]), current.get(vr["loadY"]), current.get(vr["anchorX"])))
    assert applied == [load_at(k) for k in range(round(STOP / H))]

    names = outputs(default_md)
    signals = np.array(rows, dtype=[("time", np.float64), ("loadX", np.float64), ("loadY", np.float64), ("anchorX", np.float64)])
    ref = simulate_fmu(default_fmu, stop_time=STOP, output_interval=H, input=signals, output=names)
    assert_same_as_fmpy(run, ref)

    # the load moves its node (millimetres to centimetres against the run without it)
    unloaded = simulate_fmu(default_fmu, stop_time=STOP, output_interval=H, output=["loadNodeX", "loadNodeY"])
    for name in ("loadNodeX", "loadNodeY"):
        assert np.abs(ref[name] - unloaded[name]).max() > 1e-3, name
