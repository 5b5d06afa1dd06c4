"""The coupling ports through fmpy (docs/method.md, section 8): force balance
at rest in modal and full space, the equivalence principle for a moving
anchor, a turning holder, and a wild anchor refused with the state kept."""

import numpy as np
import pytest

REDUCTION = {"modal": 1, "full": 2}


def configured(new_instance, reduction, modes=None, **f64):
    inst = new_instance(reduction)
    if modes is not None:
        inst.slave.enterConfigurationMode()
        inst.set_u64("nModes", modes)
        inst.slave.exitConfigurationMode()
    inst.slave.setInt64([inst.vr["reduction"]], [REDUCTION[reduction]])
    for name, value in f64.items():
        inst.slave.setFloat64([inst.vr[name]], list(np.atleast_1d(value).astype(float)))
    return inst


@pytest.mark.parametrize("reduction,modes", [("modal", None), ("modal", 180), ("full", None)], ids=["default", "every-mode", "full"])
def test_at_rest_the_anchor_force_is_the_weight_plus_the_load(new_instance, reduction, modes):
    """A static point load on the load node, damped motion, 20 s: the anchor
    force is the weight of the free nodes plus the load to 1e-6 relative,
    from the momentum balance with any basis: the default FMU's 2 lowest
    modes (whose springs' pull on the held nodes was 22 % light), every
    mode (180 on the default 10 x 10 grid), full space."""
    load = (1.0, -2.0)
    inst = configured(new_instance, reduction, modes=modes, dampingAlpha=8.0, loadX=load[0], loadY=load[1])
    inst.initialize()
    inst.step(0.01, 2000)
    nx, ny, _, _ = inst.sizes()
    weight = inst.f64s("nodeMass") * nx * (ny - 1) * 9.81  # the top row is held
    want = np.array([load[0], load[1] - weight, 0.0])
    got = np.array([inst.f64s(f"anchorForce{c}") for c in "XYZ"])
    rel = np.linalg.norm(got - want) / np.linalg.norm(want)
    print(f"{reduction}: anchor force {got}, weight + load {want}, relative error {rel:.2e}")
    assert rel < 1e-6


@pytest.mark.parametrize("reduction", ["modal", "full"])
def test_equivalence_principle(new_instance, reduction):
    """An anchor accelerating at a, its targets on the parabola, gives
    relative to the anchor the motion of a still anchor under g - a; the
    difference falls as the communication step shrinks."""
    accel = np.array([3.0, 2.0])
    errors = []
    for h in (0.02, 0.01, 0.005):
        moving = configured(new_instance, reduction, modes=12 if reduction == "modal" else None, maxInternalStep=1e-3)
        still = configured(new_instance, reduction, modes=12 if reduction == "modal" else None, maxInternalStep=1e-3)
        still.slave.setFloat64([still.vr["gravity"]], [-accel[0], -9.81 - accel[1], 0.0])
        moving.initialize()
        still.initialize()
        err = 0.0
        for k in range(round(1.0 / h)):
            a = 0.5 * accel * ((k + 1) * h) ** 2
            moving.slave.setFloat64([moving.vr["anchorX"], moving.vr["anchorY"]], list(a))
            moving.step(h)
            still.step(h)
            err = max(err, float(np.abs(moving.positions() - a - still.positions()).max()))
        print(f"{reduction}, h = {h}: largest difference relative to the anchor {err:.3e} m")
        errors.append(err)
        moving.free()
        still.free()
    assert errors[2] < 0.6 * errors[1] < 0.36 * errors[0]
    assert errors[2] < 2e-3


def test_a_wild_anchor_is_discarded_and_the_state_kept(new_instance):
    """An anchor jump of 5 m within one 0.01 s step cannot be integrated:
    fmi3Discard, the outputs and the state as before; the run goes on once
    the anchor's target is back within reach."""
    inst = new_instance()
    inst.initialize()
    inst.step(0.01, 5)
    before = inst.positions().copy()
    inst.set_f64("anchorX", 5.0)
    with pytest.raises(Exception, match="fmi3Discard|status 2|Discard"):
        inst.slave.doStep(currentCommunicationPoint=inst.time, communicationStepSize=0.01)
    assert np.array_equal(inst.positions(), before)
    assert any("anchor's velocity changes by" in m for _, _, m in inst.messages), inst.messages
    inst.set_f64("anchorX", 0.01)
    inst.step(0.01, 3)
    assert np.isfinite(inst.positions()).all()


def test_a_turning_holder_through_fmpy(new_instance):
    """anchorRZ through fmpy: the holder turns the sheet by 0.5 rad at a
    constant rate and holds it there; damped, it settles hanging from the
    turned holder: the positions are the turned rest shape's frame plus the
    sag, the holder force is the weight, and the torque the weight's
    moment about the pivot (node (0, 0))."""
    inst = configured(new_instance, "full", dampingAlpha=8.0)
    inst.initialize()
    nx, ny, d, _ = inst.sizes()
    steps = 50
    for k in range(steps):
        inst.slave.setFloat64([inst.vr["anchorRZ"]], [0.5 * (k + 1) / steps])
        inst.step(0.01, 1)
    inst.step(0.01, 1500)
    weight = inst.f64s("nodeMass") * nx * (ny - 1) * 9.81
    force = np.array([inst.f64s(f"anchorForce{c}") for c in "XYZ"])
    torque = np.array([inst.f64s(f"anchorTorque{c}") for c in "XYZ"])
    x = inst.positions()
    held = x[0]
    spacing = inst.f64s("spacing")
    angle = np.arctan2(held[-1, 1] - held[0, 1], held[-1, 0] - held[0, 0])
    free = x[1:].reshape(-1, d)
    moment = np.sum((free[:, 0] - held[0, 0]) * (-weight / len(free)))
    print(f"held row turned by {angle:.6f} rad; force {force} N (weight {weight:.4f} N); torque {torque} N m, "
          f"the weight's moment {moment:.6f} N m")
    assert abs(angle - 0.5) < 1e-12
    assert np.allclose(held[:, 0] - held[0, 0], np.cos(0.5) * spacing * np.arange(nx), atol=1e-12)
    assert np.linalg.norm(force - [0.0, -weight, 0.0]) < 1e-9 * weight
    assert abs(torque[2] - moment) < 1e-9 * abs(moment) and torque[0] == torque[1] == 0.0
