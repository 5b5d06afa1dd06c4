"""Tunable parameters: modeWeights as array start values through
simulate_fmu, and gravity / weights / damping changed between steps through
fmpy's low-level API."""

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.fmi1 import FMICallException

OUT = ["positions", "modalCoordinates", "modeFrequencies", "kineticEnergy", "potentialEnergy"]


def run(path, **start_values):
    return simulate_fmu(path, stop_time=2.0, output_interval=0.01, output=OUT, start_values=start_values)


@pytest.fixture(scope="module")
def reference(default_fmu):
    return run(default_fmu)


def test_explicit_default_weights_equal_the_default(default_fmu, reference):
    r = run(default_fmu, modeWeights=[1.0, 1.0])
    assert np.array_equal(r["positions"], reference["positions"])


def test_gravity_excites_only_the_symmetric_mode(reference):
    """Mode 0 of the default scene is the sideways sway (antisymmetric), mode 1
    the vertical stretch: straight-down gravity excites mode 1 only, so mode 0
    stays at round-off level."""
    q = np.abs(reference["modalCoordinates"]).max(axis=0)
    assert q[1] > 1e-3 and q[0] < 1e-9 * q[1]


# Sideways gravity excites both modes of the default scene.
SIDEWAYS = [3.0, -9.81, 0.0]


@pytest.mark.parametrize("weights,deleted", [([0.0, 1.0], 0), ([1.0, 0.0], 1)])
def test_zero_weight_deletes_the_mode(default_fmu, weights, deleted):
    ref = run(default_fmu, gravity=SIDEWAYS)
    r = run(default_fmu, gravity=SIDEWAYS, modeWeights=weights)
    q_ref, q = ref["modalCoordinates"], r["modalCoordinates"]
    assert np.abs(q_ref).max(axis=0).min() > 1e-3, "both modes excited in the reference"
    assert np.all(q[:, deleted] == 0.0), "a mode of weight 0 is never excited"
    kept = 1 - deleted
    assert np.abs(q[:, kept]).max() > 1e-3
    x, x_ref = r["positions"], ref["positions"]
    scale = np.abs(x_ref - x_ref[0][None]).max()
    assert np.abs(x - x_ref).max() > 0.05 * scale, "deleting a mode visibly changes the motion"
    # a weight never changes a frequency
    assert np.array_equal(r["modeFrequencies"], ref["modeFrequencies"])


def test_weights_zero_one_against_one_one_default_gravity(default_fmu, reference):
    """With straight-down gravity, deleting the sway mode keeps it at exactly 0
    (in the reference it is round-off, not 0) and deleting the stretch mode
    leaves the sheet nearly at rest."""
    r01 = run(default_fmu, modeWeights=[0.0, 1.0])
    assert np.all(r01["modalCoordinates"][:, 0] == 0.0)
    assert np.any(reference["modalCoordinates"][:, 0] != 0.0)
    r10 = run(default_fmu, modeWeights=[1.0, 0.0])
    x, x_ref = r10["positions"], reference["positions"]
    assert np.abs(x - x[0][None]).max() < 1e-6 * np.abs(x_ref - x_ref[0][None]).max()


def test_both_weights_zero_keeps_the_sheet_at_rest(default_fmu):
    r = run(default_fmu, modeWeights=[0.0, 0.0])
    x = r["positions"]
    assert np.all(x == x[0][None])
    assert np.all(r["kineticEnergy"] == 0.0)


def test_weight_two_doubles_the_response(default_fmu, reference):
    """From rest, early on (small displacement, nonlinear remainder negligible)
    a weight of 2 doubles the modal response."""
    r = run(default_fmu, modeWeights=[2.0, 2.0])
    q1, q2 = reference["modalCoordinates"][1:4], r["modalCoordinates"][1:4]
    np.testing.assert_allclose(q2, 2.0 * q1, rtol=0.02)
    assert np.array_equal(r["modeFrequencies"], reference["modeFrequencies"])


def test_weights_as_string_start_value(default_fmu):
    """fmpy also takes array start values as whitespace-separated strings."""
    r = run(default_fmu, modeWeights="0 1")
    assert np.all(r["modalCoordinates"][:, 0] == 0.0)


def test_wrong_number_of_weights_is_refused(default_fmu):
    # fmpy checks the length against the array's dimension (nModes = 2)
    with pytest.raises(Exception, match='"modeWeights" must have 2 elements but has 3'):
        run(default_fmu, modeWeights=[1.0, 1.0, 1.0])


def test_gravity_start_value(default_fmu, reference):
    r = run(default_fmu, gravity=[0.0, -2 * 9.81, 0.0])
    y, y_ref = r["positions"][:, -1, :, 1], reference["positions"][:, -1, :, 1]
    assert (y - y[0]).mean(axis=1).min() < (y_ref - y_ref[0]).mean(axis=1).min()


# -- changes between steps through the low-level API ---------------------------


def run_pair(new_instance, change, steps_before=50, steps_after=50, h=0.01):
    """Two instances in lock step; `change(b)` is applied to the second after
    `steps_before` steps. Returns the position histories (time, ny, nx, d)."""
    a, b = new_instance("a"), new_instance("b")
    a.initialize()
    b.initialize()
    xa, xb = [a.positions()], [b.positions()]
    for k in range(steps_before + steps_after):
        if k == steps_before:
            change(b)
        a.step(h)
        b.step(h)
        xa.append(a.positions())
        xb.append(b.positions())
    return np.array(xa), np.array(xb), a, b


def test_gravity_changed_between_steps(new_instance):
    g = [0.0, -3 * 9.81, 0.0]
    xa, xb, _, b = run_pair(new_instance, lambda b: b.set_f64("gravity", g))
    np.testing.assert_array_equal(b.f64("gravity", 3), g)
    assert np.array_equal(xa[:51], xb[:51]), "identical up to the change"
    assert not np.array_equal(xa[51:], xb[51:])
    # stronger gravity pulls the bottom row further down
    assert xb[-1, -1, :, 1].mean() < xa[-1, -1, :, 1].mean()


def test_sideways_gravity(new_instance):
    xa, xb, _, _ = run_pair(new_instance, lambda b: b.set_f64("gravity", [5.0, -9.81, 0.0]))
    dx = xb[51:, -1, :, 0].mean(axis=1) - xa[51:, -1, :, 0].mean(axis=1)
    assert dx[-1] > 0, "gravity along +x pushes the sheet to +x"


def test_zero_gravity_from_rest_stays_at_rest(new_instance):
    inst = new_instance()
    inst.set_f64("gravity", [0.0, 0.0, 0.0])
    inst.initialize()
    x0 = inst.positions()
    inst.step(0.01, 50)
    assert np.array_equal(inst.positions(), x0)
    assert inst.f64s("kineticEnergy") == 0.0


def test_weights_changed_between_steps(new_instance):
    xa, xb, a, b = run_pair(new_instance, lambda b: b.set_f64("modeWeights", [3.0, 0.5]))
    np.testing.assert_array_equal(b.f64("modeWeights", 2), [3.0, 0.5])
    assert np.array_equal(xa[:51], xb[:51])
    assert not np.array_equal(xa[51:], xb[51:])
    np.testing.assert_array_equal(a.f64("modeFrequencies", 2), b.f64("modeFrequencies", 2))


def test_weight_set_to_zero_mid_run_freezes_its_drive(new_instance):
    """Setting w_0 = 0 mid-run removes the drive of mode 0: from then on it
    oscillates freely (q'' = -lambda q), so it keeps its frequency and amplitude
    and no longer follows the gravity-loaded reference."""
    xa, xb, a, b = run_pair(new_instance, lambda b: b.set_f64("modeWeights", [0.0, 1.0]), 50, 100)
    assert not np.array_equal(xa[51:], xb[51:])


def test_damping_changed_between_steps(new_instance):
    a, b = new_instance("a"), new_instance("b")
    a.initialize()
    b.initialize()
    a.step(0.01, 30)
    b.step(0.01, 30)
    b.set_f64("dampingAlpha", 5.0)
    ea, eb = [], []
    for _ in range(150):
        a.step(0.01)
        b.step(0.01)
        ea.append(a.f64s("kineticEnergy") + a.f64s("potentialEnergy"))
        eb.append(b.f64s("kineticEnergy") + b.f64s("potentialEnergy"))
    assert b.f64s("dampingAlpha") == 5.0
    # damping dissipates energy: the damped run ends with clearly less
    assert eb[-1] < ea[-1] - 0.1 * abs(ea[-1] - ea[0]) - 1e-6
    assert abs(b.f64s("kineticEnergy")) < abs(a.f64s("kineticEnergy")) or eb[-1] < ea[-1]


def test_bad_tunable_values_are_refused(new_instance):
    inst = new_instance()
    inst.initialize()
    inst.step(0.01, 5)
    x = inst.positions()
    bad_values = (("modeWeights", [-1.0, 1.0]), ("dampingAlpha", [-1.0]), ("dampingBeta", [-0.5]), ("errorTolerance", [0.0]))
    for name, bad in bad_values:
        with pytest.raises(FMICallException):
            inst.set_f64(name, bad)
    np.testing.assert_array_equal(inst.f64("modeWeights", 2), [1.0, 1.0])
    assert inst.f64s("dampingAlpha") == 0.0
    assert inst.f64s("errorTolerance") == 0.01
    inst.set_f64("errorTolerance", [0.03])  # tunable: accepted between steps
    assert inst.f64s("errorTolerance") == 0.03
    with pytest.raises(FMICallException):
        inst.set_f64("gravity", [0.0, -9.81])  # 3 components
    inst.step(0.01)
    assert np.all(np.isfinite(inst.positions())) and not np.array_equal(inst.positions(), x)


def test_fixed_parameters_refused_in_step_mode(new_instance):
    inst = new_instance()
    inst.initialize()
    for name in ("spacing", "nodeMass", "springStiffness"):
        with pytest.raises(FMICallException):
            inst.set_f64(name, [1.0])


def test_adaptive_refuses_mode_weights(new_instance):
    """Mode weights act on a fixed basis: an adaptive run (which approximates
    the unweighted physics on a basis of its own) refuses any weight but 1,
    says why, and steps on as before; weights of 1 are accepted."""
    inst = new_instance()
    inst.slave.setInt64([inst.vr["reduction"]], [3])
    inst.initialize()
    inst.step(0.01, 3)
    n = int(inst.u64("nModes"))
    with pytest.raises(FMICallException):
        inst.set_f64("modeWeights", [0.5] + [1.0] * (n - 1))
    assert any("modeWeights must be 1 in an adaptive run" in m for _, _, m in inst.messages), inst.messages
    np.testing.assert_array_equal(inst.f64("modeWeights", n), np.ones(n))
    inst.set_f64("modeWeights", np.ones(n))
    inst.step(0.01)
    assert np.all(np.isfinite(inst.positions()))
