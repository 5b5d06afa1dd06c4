"""Several holders through fmpy (nHolders, fixedNodes = custom with
holderOfNode, anchor{k}X ... anchor{k}RZ, anchor{k}Force, anchor{k}Torque)
against the NumPy reference of the static equilibrium (reference_statics.py,
no code shared with the FMU).

A sheet hangs from its two top corners, each held by its own holder; holder 2
is set away from its place before initialization (the FMU then starts at the
linear static response to it) and the run settles under dampingAlpha = 8 1/s
for 20 s. Full space must match the reference to 1e-6 m and 1e-6 of the weight
per holder; 8 load vectors with a static correction and the holders'
constraint modes (anchorMotion) within 1 cm and 2 % of the weight per holder
where holder 2 moved a few centimetres, 3 cm and 6 % where it moved a fifth of
the sheet's width. In every case the holders' forces add up to the weight plus
the point load to 1e-6.
"""

import numpy as np
import pytest
from fmpy.fmi1 import FMICallException

from reference_statics import solve_statics

NX, NY, STEP, SETTLE = 6, 5, 0.5, 20.0
WIDTH = 0.1 * (NX - 1)
WEIGHT = 0.01 * 9.81 * (NX * NY - 2)  # the free nodes'
PER_HOLDER = WEIGHT / 2
LOAD = (0.2, -0.3, 0.0)
FULL = {"reduction": 2}
REDUCED = {"nModes": 8, "modeSelection": 2, "staticCorrection": True, "anchorMotion": True}


def corners(nx, ny):
    pattern = np.zeros((ny, nx), dtype=int)
    pattern[0, 0], pattern[0, -1] = 1, 2
    return pattern


def run(new_instance, solver, moved, *, custom=False, steps=None, load=LOAD):
    inst = new_instance()
    s = inst.slave
    s.enterConfigurationMode()
    s.setUInt64([inst.vr["nx"], inst.vr["ny"], inst.vr["nHolders"]], [NX, NY, 2])
    if "nModes" in solver:
        s.setUInt64([inst.vr["nModes"]], [solver["nModes"]])
    s.exitConfigurationMode()
    s.setInt64([inst.vr["fixedNodes"]], [3 if custom else 2])
    if custom:
        s.setUInt64([inst.vr["holderOfNode"]], [int(k) for k in corners(NX, NY).ravel()])
    for name in ("reduction", "modeSelection"):
        if name in solver:
            s.setInt64([inst.vr[name]], [solver[name]])
    for name in ("staticCorrection", "anchorMotion"):
        if name in solver:
            s.setBoolean([inst.vr[name]], [solver[name]])
    s.setUInt64([inst.vr["loadRow"], inst.vr["loadColumn"]], [0, 2])
    inst.set_f64("dampingAlpha", 8.0)
    names = ["loadX", "loadY", "loadZ", "anchor2X", "anchor2Y", "anchor2Z"]
    s.setFloat64([inst.vr[n] for n in names], [*load, *moved])
    inst.initialize()
    inst.step(STEP, steps if steps is not None else round(SETTLE / STEP))
    out = {
        "positions": inst.positions().reshape(NY, NX, 2),
        "forces": [np.array([inst.f64s(f"{p}Force{c}") for c in "XY"]) for p in ("anchor", "anchor2")],
        "torques": [inst.f64s(f"{p}TorqueZ") for p in ("anchor", "anchor2")],
    }
    assert not [m for m in inst.messages if m[0] > 0], inst.messages
    return out


def reference(moved, load=LOAD):
    return solve_statics(corners(NX, NY), 2, placements={2: (moved, (0.0, 0.0, 0.0))}, load=load, load_row=0, load_column=2)


MOVES = {"at rest": ((0.0, 0.0, 0.0), 0.01, 0.02), "a few cm": ((0.03, -0.02, 0.0), 0.01, 0.02),
         "a fifth of the width": ((WIDTH / 5, 0.0, 0.0), 0.03, 0.06)}


@pytest.mark.parametrize("label", MOVES)
def test_each_holder_against_the_reference(new_instance, label):
    moved, within_m, within_share = MOVES[label]
    ref = reference(moved)
    expected_sum = np.array([LOAD[0], -WEIGHT + LOAD[1]])
    for solver, tol_m, tol_share in ((FULL, 1e-6, 1e-6), (REDUCED, within_m, within_share)):
        got = run(new_instance, solver, moved)
        dx = np.abs(got["positions"] - ref.positions).max()
        df = max(np.abs(got["forces"][k] - np.asarray(ref.forces[k + 1])[:2]).max() for k in range(2)) / PER_HOLDER
        dt = max(abs(got["torques"][k] - float(np.atleast_1d(ref.torques[k + 1])[-1])) for k in range(2))
        total = got["forces"][0] + got["forces"][1]
        print(f"\n{label}, {'full' if solver is FULL else '8 load vectors + static correction + constraint modes'}: "
              f"positions within {dx:.2e} m, forces within {100 * df:.3f} % of the weight per holder, torques within {dt:.2e} N m, "
              f"sum off by {np.abs(total - expected_sum).max():.1e} N")
        assert dx < tol_m and df < tol_share
        assert np.abs(total - expected_sum).max() < 1e-6 * WEIGHT
        if solver is FULL:
            assert dt < 1e-6 * PER_HOLDER * WIDTH


def test_custom_pattern_naming_the_corners_is_the_same_run(new_instance):
    a = run(new_instance, REDUCED, (0.05, 0.0, 0.0), steps=20)
    b = run(new_instance, REDUCED, (0.05, 0.0, 0.0), steps=20, custom=True)
    assert np.array_equal(a["positions"], b["positions"])
    assert all(np.array_equal(x, y) for x, y in zip(a["forces"], b["forces"], strict=True))


def test_a_holder_that_does_not_exist_is_refused_and_the_state_kept(new_instance):
    inst = new_instance()
    inst.initialize()
    before = inst.positions().copy()
    with pytest.raises(FMICallException):
        inst.set_f64("anchor3X", 0.1)
    assert any("holder 3" in m[2] and "nHolders" in m[2] for m in inst.messages), inst.messages
    assert inst.f64s("anchor3X") == 0.0
    inst.step(0.01, 1)
    assert np.isfinite(inst.positions()).all() and inst.positions().shape == before.shape


def test_a_serialized_state_with_moving_holders_resumes_bit_for_bit(new_instance):
    """Holder 2 moving and turning, holder 1 moving: a state serialized
    mid-run and loaded into a fresh instance takes the same steps to the bit."""
    def drive(inst, k):
        t = 0.01 * k
        inst.slave.setFloat64([inst.vr[n] for n in ("anchorX", "anchor2X", "anchor2Y", "anchor2RZ")],
                              [0.01 * t, 0.05 * np.sin(3 * t), 0.02 * t, 0.3 * t])
        inst.step(0.01)

    def make():
        inst = new_instance()
        inst.slave.setUInt64([inst.vr["nHolders"]], [2])
        inst.slave.setInt64([inst.vr["fixedNodes"]], [2])
        inst.slave.setBoolean([inst.vr["anchorMotion"]], [True])
        inst.initialize()
        return inst

    a = make()
    for k in range(30):
        drive(a, k)
    blob = a.slave.serializeFMUState(a.slave.getFMUState())
    b = make()
    state = b.slave.deserializeFMUState(blob)
    b.slave.setFMUState(state)
    b.slave.freeFMUState(state)
    b.time = a.time
    for k in range(30, 60):
        drive(a, k)
        drive(b, k)
    assert np.array_equal(a.positions(), b.positions())
    assert a.f64s("anchor2ForceX") == b.f64s("anchor2ForceX") and a.f64s("anchorTorqueZ") == b.f64s("anchorTorqueZ")
