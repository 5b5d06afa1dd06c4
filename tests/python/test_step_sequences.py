"""Communication steps as real masters compute them.

- fmpy's simulate_fmu (fmpy/simulation.py, simulateCS): the next
  communication point is start + (n + 1) * interval and the step the
  difference to the current one, so the steps are a few ulps off the
  interval; the last step is cut at the stop time when the FMU can handle
  variable steps.
- fmusim 0.0.39 (fmusim/FMI3CSSimulation.c): the same arithmetic in C
  doubles (nextRegularPoint = startTime + (nSteps + 1) * outputInterval;
  stepSize = nextCommunicationPoint - time), FMIIsClose (FMIUtil.c: within
  1e-5 absolute or 1e-5 relative) in place of math.isclose's 1e-9 for the
  stop time.
- fmpy's container_fmu 0.3.32 (native/container-fmu, lib.rs): each component
  gets the fixed step itself, from currentCommunicationPoint = startTime +
  nSteps * fixedStepSize.

The FMU splits a step into internal steps counted with a relative tolerance
of 1e-8 (docs/method.md, section 4), so every sequence gives the same
trajectory to round-off, with the same input signals; a step whose count
does change shows how far that would move it.
"""

import itertools
from math import isclose

import numpy as np
import pytest
from fmpy import simulate_fmu

from conftest import Instance

STOP = 2.0


def fmpy_sequence(start, stop, interval, variable_steps=True):
    """(currentCommunicationPoint, communicationStepSize) of simulate_fmu
    for an FMI 3.0 Co-Simulation FMU without input events."""
    time, n, out = start, 0, []
    while not (time > stop or isclose(time, stop)):
        nxt = start + (n + 1) * interval
        if nxt > stop and not isclose(nxt, stop):
            if not variable_steps:
                break
            nxt = stop
        out.append((time, nxt - time))
        time = nxt
        if isclose(time, start + (n + 1) * interval):
            n += 1
    return out


def fmusim_is_close(a, b, eps=1e-5):
    return abs(a - b) <= eps or abs(a - b) <= eps * max(abs(a), abs(b))


def fmusim_sequence(start, stop, interval):
    """The same loop as FMI3CSSimulation.c (no input file, no early return)."""
    time, n, out = start, 0, []
    while not (time > stop or fmusim_is_close(time, stop)):
        nxt = start + (n + 1) * interval
        if nxt > stop and not fmusim_is_close(nxt, stop):
            nxt = stop
        out.append((time, nxt - time))
        time = nxt
        if fmusim_is_close(time, start + (n + 1) * interval):
            n += 1
    return out


def container_sequence(start, stop, interval):
    """What fmpy's container sends a component, its fixed step being the interval."""
    n = int(round((stop - start) / interval))
    return [(start + k * interval, interval) for k in range(n)]


def accumulating_sequence(start, stop, interval):
    """A plain loop: t += h, the step h itself."""
    t, out = start, []
    for _ in range(int(round((stop - start) / interval))):
        out.append((t, interval))
        t += interval
    return out


def anchor_x(t):
    return 0.03 * np.sin(2 * np.pi * 0.8 * t)


def load_y(t):
    return -0.2 - 0.1 * np.cos(2 * np.pi * 1.3 * t)


def run(default_md, unzipped, sequence, start, interval):
    """The FMU driven through `sequence` with the inputs on their signals:
    at step k the anchor's target is the signal at (k + 1) * interval, the
    end of the step, and the load the signal at k * interval, its start
    (in time since the start). The same input values for every master,
    whatever round-off its clock has: the runs differ in the steps only.
    Every output at every communication point."""
    inst = Instance(default_md, unzipped, name="seq")
    inst.set_f64("dampingAlpha", 0.3)
    inst.initialize(start)
    rows = []
    try:
        for k, (t, h) in enumerate(sequence):
            inst.set_f64("anchorX", anchor_x((k + 1) * interval))
            inst.set_f64("loadY", load_y(k * interval))
            inst.slave.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            rows.append(np.concatenate([inst.positions().ravel(), inst.f64("velocities", 200),
                                        [inst.f64s(n) for n in ("kineticEnergy", "potentialEnergy", "anchorForceX", "anchorForceY")]]))
    finally:
        inst.free()
    return np.array(rows)


def relative_gap(a, b):
    """Largest difference per kind of output, relative to that output's size."""
    parts = [slice(0, 200), slice(200, 400), slice(400, 402), slice(402, 404)]
    return max(np.abs(a[:, p] - b[:, p]).max() / np.abs(b[:, p]).max() for p in parts)


CASES = [(0.0, 0.01), (0.0, 0.02), (0.0, 0.001), (1000.0, 0.01)]


@pytest.mark.parametrize("start, interval", CASES, ids=[f"start={s:g},interval={i:g}" for s, i in CASES])
def test_masters_step_sequences_give_one_trajectory(default_md, unzipped, start, interval):
    """With maxInternalStep = 0.01 s (the default) an interval of 0.01 s is
    one internal step; fmpy's and fmusim's steps reach a few ulps above it,
    where a plain ceil(h / maxInternalStep) would take two."""
    stop = start + STOP
    seqs = {
        "fmpy": fmpy_sequence(start, stop, interval),
        "fmusim": fmusim_sequence(start, stop, interval),
        "container": container_sequence(start, stop, interval),
        "accumulating": accumulating_sequence(start, stop, interval),
    }
    steps = np.array([h for _, h in seqs["fmpy"]])
    assert len(steps) == int(round(STOP / interval))
    above = int(np.sum(steps > interval))
    print(f"\nstart {start:g} s, interval {interval:g} s: fmpy/fmusim steps from {interval - steps.min():.1e} s below "
          f"to {steps.max() - interval:.1e} s above the interval, {above} of {len(steps)} above")
    assert above > 0 and np.any(steps < interval)
    # fmusim computes the same doubles, but takes a time within 1e-5 * |t| of
    # the stop time for the stop time: from t = 1000 s on, within 0.01 s, so
    # it ends a step of 0.01 s early (at 1001.99 s of 1002 s)
    short = len(seqs["fmpy"]) - len(seqs["fmusim"])
    assert short == (1 if stop * 1e-5 >= interval else 0)
    assert seqs["fmusim"] == seqs["fmpy"][: len(seqs["fmusim"])]
    if short:
        print(f"  fmusim stops at {sum(seqs['fmusim'][-1]):.10g} s, {short} step before {stop:g} s")
    reference = run(default_md, unzipped, seqs["container"], start, interval)
    for name in ("fmpy", "accumulating"):
        off = max(abs(h - interval) for _, h in seqs[name]) / interval
        gap = relative_gap(run(default_md, unzipped, seqs[name], start, interval), reference)
        print(f"  {name}: steps up to {off:.1e} (relative) off the interval; trajectory {gap:.1e} (relative) from constant steps")
        # Near t = 0 the steps are round-off of the interval and so is the
        # gap. At t = 1000 s one ulp of t is 1.1e-13 s: fmpy's steps are
        # then 1e-11 longer or shorter, other steps, and the trajectory moves
        # by less than that. (The accumulating master sends the interval
        # itself: bit for bit.)
        assert gap < max(1e-12, off)


def test_one_internal_step_more_is_seen(default_md, unzipped):
    """The comparison above sees a changed internal step count: one step of
    0.01 s made 2e-8 longer (past the tolerance: two internal steps) and the
    next as much shorter moves the trajectory by far more than 1e-12."""
    seq = container_sequence(0.0, STOP, 0.01)
    changed = list(seq)
    changed[50] = (seq[50][0], 0.01 * (1 + 2e-8))
    changed[51] = (seq[51][0] + 0.01 * 2e-8, 0.01 * (1 - 2e-8))
    gap = relative_gap(run(default_md, unzipped, changed, 0.0, 0.01), run(default_md, unzipped, seq, 0.0, 0.01))
    print(f"\none step split in two: {gap:.1e} (relative)")
    assert gap > 1e-9


def test_fmpy_sequence_is_what_simulate_fmu_sends(default_fmu):
    """The replica of simulate_fmu's loop against simulate_fmu itself: the
    communication points it reaches (the steps are their differences)."""
    for start in (0.0, 1000.0):
        times = []
        simulate_fmu(default_fmu, start_time=start, stop_time=start + STOP, output_interval=0.01, output=["kineticEnergy"],
                     step_finished=lambda t, recorder, times=times: times.append(t) or True)
        replica = fmpy_sequence(start, start + STOP, 0.01)
        assert times == [t + h for t, h in replica]
        assert [b - a for a, b in itertools.pairwise([start] + times)] == [h for _, h in replica]


def test_container_sends_multiples_of_its_fixed_step(tmp_path):
    """fmpy's container FMU, run by simulate_fmu with steps a few ulps off
    0.01 s, sends its components the fixed step 0.01 s itself from
    startTime + nSteps * 0.01: the calls it logs (logFMICalls, floats in
    Rust's shortest round-trip form) are the container sequence above."""
    import re
    import sys

    from conftest import ROOT

    sys.path.insert(0, str(ROOT / "python"))
    import chain

    path = chain.fmpy_container(chain.default_fmu(), 0.01, tmp_path / "c.fmu")
    calls = []

    def logger(env, status, category, message):
        m = re.match(r"\[A\] fmi3DoStep\(currentCommunicationPoint=([^,]+), communicationStepSize=([^,]+),", message.decode())
        if m:
            calls.append((float(m.group(1)), float(m.group(2))))

    times = []
    simulate_fmu(str(path), stop_time=STOP, output_interval=0.01, debug_logging=True, logger=logger, output=["A.loadNodeY"],
                 step_finished=lambda t, recorder: times.append(t) or True)
    sent = [b - a for a, b in itertools.pairwise([0.0] + times)]
    assert any(h != 0.01 for h in sent)  # simulate_fmu's steps to the container
    assert calls == container_sequence(0.0, STOP, 0.01)
