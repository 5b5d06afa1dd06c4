"""FMU state: get/set and serialize/deserialize reproduce a run bit for bit,
in the same instance and in a second one; two instances in one process do not
interfere."""

import numpy as np
import pytest
from fmpy.fmi1 import FMICallException

H = 0.01


def snapshot(inst):
    """Every output and tunable, exactly."""
    nx, ny, dim, r = inst.sizes()
    n = nx * ny * dim
    return {
        "positions": inst.f64("positions", n),
        "velocities": inst.f64("velocities", n),
        "modalCoordinates": inst.f64("modalCoordinates", r),
        "kineticEnergy": inst.f64s("kineticEnergy"),
        "potentialEnergy": inst.f64s("potentialEnergy"),
        "gravity": inst.f64("gravity", 3),
        "modeWeights": inst.f64("modeWeights", r),
    }


def history(inst, steps, h=H):
    out = []
    for _ in range(steps):
        inst.step(h)
        out.append(snapshot(inst))
    return out


def assert_same(a, b):
    assert len(a) == len(b)
    for sa, sb in zip(a, b, strict=True):
        for k in sa:
            assert np.array_equal(sa[k], sb[k]), k  # bit for bit


def assert_differs(a, b):
    assert any(not np.array_equal(sa["positions"], sb["positions"]) for sa, sb in zip(a, b, strict=True))


def test_get_set_state_same_instance(new_instance):
    inst = new_instance()
    inst.initialize()
    inst.step(H, 40)
    state = inst.slave.getFMUState()
    t = inst.time
    first = history(inst, 60)
    inst.slave.setFMUState(state)
    inst.time = t
    again = history(inst, 60)
    assert_same(first, again)
    inst.slave.freeFMUState(state)


def test_state_restores_tunables(new_instance):
    """A state holds the tunables in force when it was taken."""
    inst = new_instance()
    inst.initialize()
    inst.step(H, 20)
    state = inst.slave.getFMUState()
    t = inst.time
    first = history(inst, 30)
    inst.slave.setFMUState(state)
    inst.time = t
    inst.set_f64("gravity", [0.0, -20.0, 0.0])
    inst.set_f64("modeWeights", [1.0, 2.0])
    changed = history(inst, 30)
    assert_differs(first, changed)
    inst.slave.setFMUState(state)
    inst.time = t
    np.testing.assert_array_equal(inst.f64("gravity", 3), [0.0, -9.81, 0.0])
    np.testing.assert_array_equal(inst.f64("modeWeights", 2), [1.0, 1.0])
    assert_same(first, history(inst, 30))
    inst.slave.freeFMUState(state)


def test_state_overwritten_by_get_fmu_state(new_instance):
    """fmi3GetFMUState with an existing state overwrites it."""
    inst = new_instance()
    inst.initialize()
    state = inst.slave.getFMUState()
    inst.step(H, 25)
    import ctypes

    inst.slave.fmi3GetFMUState(inst.slave.component, ctypes.byref(state))
    t = inst.time
    first = history(inst, 10)
    inst.slave.setFMUState(state)
    inst.time = t
    assert_same(first, history(inst, 10))
    inst.slave.freeFMUState(state)


def test_serialize_deserialize_same_instance(new_instance):
    inst = new_instance()
    inst.initialize()
    inst.step(H, 30)
    state = inst.slave.getFMUState()
    data = inst.slave.serializeFMUState(state)
    inst.slave.freeFMUState(state)
    assert isinstance(data, bytes) and len(data) > 0
    t = inst.time
    first = history(inst, 50)
    restored = inst.slave.deserializeFMUState(data)
    inst.slave.setFMUState(restored)
    inst.slave.freeFMUState(restored)
    inst.time = t
    assert_same(first, history(inst, 50))


def test_serialized_state_in_a_second_instance(new_instance):
    a = new_instance("a")
    a.initialize()
    a.set_f64("gravity", [1.0, -9.81, 0.0])  # a state off the defaults
    a.step(H, 35)
    a.set_f64("modeWeights", [0.5, 1.5])
    a.step(H, 5)
    state = a.slave.getFMUState()
    data = a.slave.serializeFMUState(state)
    a.slave.freeFMUState(state)
    t = a.time
    first = history(a, 60)

    b = new_instance("b")
    b.initialize()
    b.step(H, 3)  # somewhere else entirely
    restored = b.slave.deserializeFMUState(data)
    b.slave.setFMUState(restored)
    b.slave.freeFMUState(restored)
    b.time = t
    np.testing.assert_array_equal(b.f64("modeWeights", 2), [0.5, 1.5])
    assert_same(first, history(b, 60))
    # serializing the same state twice gives the same bytes
    s1 = b.slave.getFMUState()
    s2 = b.slave.getFMUState()
    assert b.slave.serializeFMUState(s1) == b.slave.serializeFMUState(s2)
    b.slave.freeFMUState(s1)
    b.slave.freeFMUState(s2)


def test_serialized_state_of_a_resized_instance(new_instance):
    """A state of a 6 x 4 grid with 3 modes, restored in another instance
    configured the same way."""

    def make(name):
        inst = new_instance(name)
        inst.slave.enterConfigurationMode()
        inst.set_u64("nx", 6)
        inst.set_u64("ny", 4)
        inst.set_u64("nModes", 3)
        inst.slave.exitConfigurationMode()
        inst.initialize()
        return inst

    a = make("a")
    a.step(H, 20)
    state = a.slave.getFMUState()
    data = a.slave.serializeFMUState(state)
    a.slave.freeFMUState(state)
    t = a.time
    first = history(a, 30)
    b = make("b")
    restored = b.slave.deserializeFMUState(data)
    b.slave.setFMUState(restored)
    b.slave.freeFMUState(restored)
    b.time = t
    assert_same(first, history(b, 30))


def test_corrupt_serialized_state_is_refused(new_instance):
    inst = new_instance()
    inst.initialize()
    inst.step(H, 10)
    state = inst.slave.getFMUState()
    data = inst.slave.serializeFMUState(state)
    inst.slave.freeFMUState(state)
    before = snapshot(inst)
    for bad in (data[: len(data) // 2], b"\x00" * len(data), b"garbage"):
        with pytest.raises(FMICallException):
            inst.slave.deserializeFMUState(bad)
    # still usable, and unchanged
    assert_same([before], [snapshot(inst)])
    inst.step(H)


def test_state_of_a_different_grid_is_refused(new_instance):
    a = new_instance("a")
    a.slave.enterConfigurationMode()
    a.set_u64("nx", 5)
    a.slave.exitConfigurationMode()
    a.initialize()
    a.step(H, 5)
    s = a.slave.getFMUState()
    data = a.slave.serializeFMUState(s)
    a.slave.freeFMUState(s)
    b = new_instance("b")
    b.initialize()
    before = snapshot(b)
    try:
        restored = b.slave.deserializeFMUState(data)
    except FMICallException:
        restored = None
    if restored is not None:
        with pytest.raises(FMICallException):
            b.slave.setFMUState(restored)
        b.slave.freeFMUState(restored)
    assert_same([before], [snapshot(b)])


def test_two_instances_do_not_interfere(new_instance):
    """Interleaved stepping of two differently configured and driven instances
    gives exactly what each gives alone."""

    def setup(inst, nx, g, w):
        inst.slave.enterConfigurationMode()
        inst.set_u64("nx", nx)
        inst.slave.exitConfigurationMode()
        inst.set_f64("gravity", g)
        inst.set_f64("modeWeights", w)
        inst.initialize()

    cfg_a = (10, [0.0, -9.81, 0.0], [1.0, 1.0])
    cfg_b = (7, [2.0, -5.0, 0.0], [0.3, 2.0])

    a, b = new_instance("a"), new_instance("b")
    setup(a, *cfg_a)
    setup(b, *cfg_b)
    ha, hb = [], []
    for k in range(80):
        a.step(H)
        if k % 2 == 0:
            b.step(2 * H)  # different step sizes too
            hb.append(snapshot(b))
        ha.append(snapshot(a))

    solo_a = new_instance("solo_a")
    setup(solo_a, *cfg_a)
    assert_same(ha, history(solo_a, 80))
    solo_b = new_instance("solo_b")
    setup(solo_b, *cfg_b)
    assert_same(hb, history(solo_b, 40, 2 * H))


def test_freeing_one_instance_leaves_the_other(new_instance):
    a, b = new_instance("a"), new_instance("b")
    a.initialize()
    b.initialize()
    a.step(H, 10)
    b.step(H, 10)
    a.free()
    rest = history(b, 20)
    c = new_instance("c")
    c.initialize()
    c.step(H, 10)
    assert_same(rest, history(c, 20))


def test_reset_returns_to_instantiated(new_instance):
    inst = new_instance()
    inst.initialize()
    first = history(inst, 20)
    inst.slave.reset()
    inst.initialize()
    assert_same(first, history(inst, 20))


def test_adaptive_state_resumes_in_either_mode(new_instance):
    """reduction = adaptive: a state taken while reduced and one taken in full
    space (gravity turned beyond the training program) resume bit for bit in
    a second instance, with the estimate and the reduced share."""

    def adaptive(name):
        inst = new_instance(name)
        inst.slave.setInt64([inst.vr["reduction"]], [3])
        # 24 x 24 nodes: large enough for the chosen basis to pay (10 x 10 runs in full space throughout).
        inst.slave.setUInt64([inst.vr["nx"], inst.vr["ny"]], [24, 24])
        inst.initialize()
        return inst

    def outputs(inst):
        return {k: inst.f64s(k) for k in ("errorEstimate", "reducedFraction", "basisSize")}

    a = adaptive("a")
    a.step(H, 5)
    states = []
    for gravity in ([0.0, -9.81, 0.0], [9.81, 0.0, 0.0]):
        a.set_f64("gravity", gravity)
        a.step(H, 5)
        state = a.slave.getFMUState()
        states.append((a.slave.serializeFMUState(state), a.time, outputs(a)))
        a.slave.freeFMUState(state)
    a.set_f64("gravity", [0.0, -9.81, 0.0])
    first = [(history(a, 1), outputs(a)) for _ in range(20)]
    assert states[0][2]["basisSize"] < states[1][2]["basisSize"], "one state reduced, one in full space"
    b = adaptive("b")
    b.step(H, 3)
    for data, t, out in states:
        restored = b.slave.deserializeFMUState(data)
        b.slave.setFMUState(restored)
        b.slave.freeFMUState(restored)
        b.time = t
        assert outputs(b) == out
        if data is states[1][0]:
            b.set_f64("gravity", [0.0, -9.81, 0.0])
            again = [(history(b, 1), outputs(b)) for _ in range(20)]
            for (ha, oa), (hb, ob) in zip(first, again, strict=True):
                assert_same(ha, hb)
                assert oa == ob
