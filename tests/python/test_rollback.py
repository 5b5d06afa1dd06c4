"""A master that rejects steps and retries them from a saved FMU state, and
variable communication steps with the inputs moving (anchorX, loadY).

The inputs follow smooth signals: the anchor target set at t is the
signal's value at the end of the step, t + h (the anchor is where the value
says at the end of the step); the point load is the signal at t, held over
the step.
"""

import itertools

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.fmi1 import FMICallException

H = 0.01


def anchor_x(t):
    return 0.05 * np.sin(2 * np.pi * 1.5 * t)


def load_y(t):
    return -0.3 - 0.2 * np.cos(2 * np.pi * t)


def make(new_instance, max_internal_step=None, name="instance"):
    inst = new_instance(name)
    inst.set_f64("dampingAlpha", 0.5)
    if max_internal_step is not None:
        inst.set_f64("maxInternalStep", max_internal_step)
    inst.initialize()
    return inst


def snapshot(inst):
    """Every output, and the inputs as the FMU holds them, exactly."""
    nx, ny, dim, r = inst.sizes()
    scalars = ["kineticEnergy", "potentialEnergy", "forceResidual", "anchorX", "loadY"]
    scalars += [f"{p}{a}" for p in ("loadNode", "loadNodeV", "anchorForce") for a in "XY"]
    return {
        "positions": inst.f64("positions", nx * ny * dim),
        "velocities": inst.f64("velocities", nx * ny * dim),
        "modalCoordinates": inst.f64("modalCoordinates", r),
        **{n: inst.f64s(n) for n in scalars},
    }


def assert_same(a, b):
    assert len(a) == len(b)
    for k, (sa, sb) in enumerate(zip(a, b, strict=True)):
        for name in sa:
            assert np.array_equal(sa[name], sb[name]), f"communication point {k + 1}: {name}"


def do_step(inst, t, h):
    """fmi3DoStep telling the FMU that the master may go back."""
    inst.slave.doStep(currentCommunicationPoint=t, communicationStepSize=h, noSetFMUStatePriorToCurrentPoint=False)


class Saved:
    """An FMU state kept as fmi3FMUState or as its serialized bytes."""

    def __init__(self, inst, how):
        self.inst, self.how = inst, how
        state = inst.slave.getFMUState()
        if how == "serialized":
            self.data = inst.slave.serializeFMUState(state)
            inst.slave.freeFMUState(state)
        else:
            self.state = state

    def restore(self):
        if self.how == "serialized":
            state = self.inst.slave.deserializeFMUState(self.data)
            self.inst.slave.setFMUState(state)
            self.inst.slave.freeFMUState(state)
        else:
            self.inst.slave.setFMUState(self.state)
            self.inst.slave.freeFMUState(self.state)


# The rejected attempts: (step, step size of the attempt as a multiple of H,
# anchor offset, load factor). The last one moves the anchor by 30 m in one
# step, which the FMU refuses itself (fmi3Discard, state kept) before the
# master rejects it too.
REJECTED = {0: (1.7, 0.02, 3.0), 7: (0.5, -0.03, -1.0), 8: (2.0, 0.01, 0.0), 23: (1.0, 0.0, 2.0), 40: (1.0, 30.0, 1.0)}
N = 60


def run(inst, rejected=(), how="state", inputs="after"):
    """N steps of H with the inputs on their signals; at the steps in
    rejected, first an attempt with other inputs and another step size that
    the master rejects and rolls back. inputs = "after": the master sets the
    inputs again after restoring; "before": it set them before saving the
    state and relies on the state to hold them."""
    history, discarded = [], 0
    t = 0.0
    for k in range(N):
        target, load = anchor_x(t + H), load_y(t)
        if inputs == "before":
            inst.set_f64("anchorX", target)
            inst.set_f64("loadY", load)
        if k in rejected:
            factor, offset, scale = REJECTED[k]
            saved = Saved(inst, how)
            inst.set_f64("anchorX", anchor_x(t + factor * H) + offset)
            inst.set_f64("loadY", scale * load)
            try:
                do_step(inst, t, factor * H)
                snapshot(inst)  # the master looks at the attempt (every output computed)
            except FMICallException:
                discarded += 1
            saved.restore()
        if inputs == "after":
            inst.set_f64("anchorX", target)
            inst.set_f64("loadY", load)
        do_step(inst, t, H)
        t = (k + 1) * H
        history.append(snapshot(inst))
    return history, discarded


@pytest.mark.parametrize("inputs", ["after", "before"])
@pytest.mark.parametrize("how", ["state", "serialized"])
def test_rejected_steps_leave_no_trace(new_instance, how, inputs):
    """Rolled back attempts with other inputs and other step sizes, from
    fmi3GetFMUState/SetFMUState or Serialize/Deserialize: bit for bit the
    run that never rejected, whether the master sets the inputs again after
    the rollback or leaves them to the restored state."""
    plain, _ = run(make(new_instance, name="plain"))
    retried, discarded = run(make(new_instance, name="retried"), REJECTED, how, inputs)
    when = "again after each rollback" if inputs == "after" else "before saving the state only"
    print(f"\n{how}, inputs set {when}: {len(REJECTED)} attempts rolled back ({discarded} discarded by the FMU)")
    assert discarded == 1
    assert_same(plain, retried)
    # the attempts did move the sheet: a run that keeps the first attempt differs
    kept = make(new_instance, name="kept")
    kept.set_f64("anchorX", anchor_x(1.7 * H) + 0.02)
    kept.set_f64("loadY", 3.0 * load_y(0.0))
    do_step(kept, 0.0, 1.7 * H)
    assert not np.array_equal(snapshot(kept)["positions"], plain[0]["positions"])


def test_restored_state_holds_the_inputs(new_instance):
    """The inputs in force when the state was taken come back with it."""
    inst = make(new_instance)
    inst.set_f64("anchorX", 0.01)
    inst.set_f64("loadY", -0.4)
    inst.step(H, 3)
    saved = Saved(inst, "serialized")
    inst.set_f64("anchorX", 0.5)
    inst.set_f64("loadY", 2.0)
    saved.restore()
    assert (inst.f64s("anchorX"), inst.f64s("loadY")) == (0.01, -0.4)


def continue_run(inst, a1, h, n=20):
    for k in range(n):
        inst.set_f64("anchorX", a1 + 0.001 * k)
        inst.step(h)
    return snapshot(inst)


@pytest.mark.parametrize(
    "h, max_internal_step, a0, a1, load",
    [(2.0**-6, None, 0.0, 0.03125, -0.5), (0.01, 0.005, 0.0123, 0.0371, -0.37)],
    ids=["dyadic", "general"],
)
def test_two_half_steps_on_the_linear_path_are_one_step(new_instance, h, max_internal_step, a0, a1, load):
    """One step of h towards a1, or two of h/2, the first towards the middle
    of the same linear path, with the load held: the same anchor motion and
    the same load by definition, and with maxInternalStep dividing h/2 the
    same internal steps (h = 1/64 s with the default 0.01 s: two internal
    steps of 1/128 s; h = 0.01 s with 0.005 s). Bit for bit, also with
    values that are not dyadic (measured)."""
    def whole_and_halves(internal_step, tag):
        """The runs after one step of h and after two of h/2, continued alike."""
        whole, halves = make(new_instance, internal_step, "whole" + tag), make(new_instance, internal_step, "halves" + tag)
        for inst in (whole, halves):  # the anchor already moving when the step starts
            inst.set_f64("anchorX", a0)
            inst.set_f64("loadY", load)
            inst.step(h)
        whole.set_f64("anchorX", a1)
        whole.step(h)
        halves.set_f64("anchorX", a0 + (a1 - a0) / 2)
        halves.step(h / 2)
        halves.set_f64("anchorX", a1)
        halves.step(h / 2)
        return continue_run(whole, a1, h), continue_run(halves, a1, h)

    a, b = whole_and_halves(max_internal_step, "")
    for name in a:
        assert np.array_equal(a[name], b[name]), name
    # with internal steps that differ the two are not the same: h = 0.01 s
    # is one internal step of the default 0.01 s, h/2 one of 0.005 s
    if max_internal_step is not None:
        a, b = whole_and_halves(None, "2")
        rel = np.abs(a["positions"] - b["positions"]).max() / np.abs(a["positions"]).max()
        print(f"\nother internal steps: {rel:.1e} apart (relative)")
        assert rel > 1e-9  # measured 8e-6


def run_steps(new_instance, steps, max_internal_step, name):
    """Positions after each of `steps` with the inputs on their signals."""
    inst = make(new_instance, max_internal_step, name)
    t, times, xs = 0.0, [], []
    for h in steps:
        inst.set_f64("anchorX", anchor_x(t + h))
        inst.set_f64("loadY", load_y(t))
        inst.slave.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        t += h
        times.append(t)
        xs.append(inst.positions().ravel())
    inst.free()
    return np.array(times), np.array(xs)


def grid_error(run, ref):
    """Largest position error at the communication points that lie on the reference grid [m]."""
    times, xs = run
    rt, rx = ref
    k = np.searchsorted(rt, times - 1e-12)
    on = np.abs(rt[np.minimum(k, len(rt) - 1)] - times) < 1e-12
    assert on.sum() >= len(times) // 2
    return np.abs(xs[on] - rx[k[on]]).max()


def test_variable_steps_with_moving_inputs_converge(new_instance):
    """Random steps between h/2 and 3h/2 (multiples of 2^-12 s, so they meet
    the reference grid) with the inputs on their signals: as accurate as
    constant steps of h against a run at 2^-12 s, and the error shrinks as h
    halves. Not equal to constant steps: the inputs are sampled elsewhere."""
    fine = 2.0**-12
    ref = run_steps(new_instance, [fine] * 4096, fine, "reference")
    rng = np.random.default_rng(7)
    lines, var_errors = [], []
    for h in (2.0**-6, 2.0**-7, 2.0**-8):
        n, seq = int(round(h / fine)), []
        while sum(seq) < 4096:
            seq.append(min(int(rng.integers(n // 2, 3 * n // 2 + 1)), 4096 - sum(seq)))
        steps = [m * fine for m in seq]
        e_var = grid_error(run_steps(new_instance, steps, 2.0**-10, "variable"), ref)
        e_const = grid_error(run_steps(new_instance, [h] * int(round(1 / h)), 2.0**-10, "constant"), ref)
        var_errors.append(e_var)
        lines.append(f"h = {h:g} s: {len(steps)} steps from {min(steps):g} to {max(steps):g} s: {e_var:.2e} m; constant h: {e_const:.2e} m")
        assert e_var < 2.0 * e_const  # measured 1.1x to 1.35x
    print("\n" + "\n".join(lines))
    assert all(b < 0.6 * a for a, b in itertools.pairwise(var_errors))  # measured /4.1, /2.8


def test_simulate_fmu_cuts_steps_at_an_input_event(default_fmu, new_instance):
    """fmpy's simulate_fmu, seeing canHandleVariableCommunicationStepSize,
    ends a step at the time of a jump in the input (loadY from -0.2 to
    -0.7 N at 0.123 s): steps of 0.003 and 0.007 s there. With internal
    steps of 1 ms that is the same run as constant steps of 1 ms with the
    load switching at 0.123 s, to round-off."""
    te = 0.123
    signal = np.array([(0.0, -0.2), (te, -0.2), (te, -0.7), (1.0, -0.7)], dtype=[("time", "f8"), ("loadY", "f8")])
    times = []
    res = simulate_fmu(default_fmu, stop_time=1.0, output_interval=0.01, input=signal, output=["positions"],
                       start_values={"maxInternalStep": 0.001, "dampingAlpha": 0.5},
                       step_finished=lambda t, recorder: times.append(t) or True)
    steps = np.diff([0.0] + times)
    k = times.index(te)
    assert steps[k] == pytest.approx(0.003) and steps[k + 1] == pytest.approx(0.007)

    inst = make(new_instance, 0.001)
    x = {}
    for j in range(1000):
        inst.set_f64("loadY", -0.2 if j < 123 else -0.7)
        inst.slave.doStep(currentCommunicationPoint=j * 0.001, communicationStepSize=0.001)
        x[j + 1] = inst.positions()
    worst = 0.0
    for t, p in zip(res["time"][1:], res["positions"][1:], strict=True):
        ref = x[int(round(t / 0.001))]
        worst = max(worst, np.abs(p - ref).max() / np.abs(ref).max())
    print(f"\nsimulate_fmu's steps around the event: {steps[k - 1]:.4g} {steps[k]:.4g} {steps[k + 1]:.4g} s; "
          f"{worst:.1e} (relative) from constant 1 ms steps")
    assert worst < 1e-12  # measured 2.4e-16
