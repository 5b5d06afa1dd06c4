"""Structural parameters through fmpy's low-level FMI 3 API (FMU3Slave):
Configuration Mode (as the standard says) and the Instantiated state (as
fmpy's simulate_fmu does); arrays follow the new sizes, with strict nValues."""

import numpy as np
import pytest
from fmpy.fmi1 import FMICallException


def configure(inst, **sizes):
    inst.slave.enterConfigurationMode()
    for name, value in sizes.items():
        inst.set_u64(name, value)
    inst.slave.exitConfigurationMode()


# In 3D the lowest modes of the flat sheet are out of its plane (auxiliary
# springs) and gravity in the plane does not excite them: the 3D case keeps all
# 5 * 5 * 3 modes of its free nodes so that it sags.
@pytest.mark.parametrize("nx,ny,dim,r", [(4, 3, 2, 5), (5, 6, 3, 75), (2, 2, 2, 4), (12, 10, 2, 3)])
def test_configuration_mode_resizes_arrays(new_instance, nx, ny, dim, r):
    inst = new_instance()
    configure(inst, nx=nx, ny=ny, dimension=dim, nModes=r)
    assert inst.sizes() == (nx, ny, dim, r)
    inst.initialize()
    n = nx * ny * dim
    x0 = inst.positions()
    assert x0.shape == (ny, nx, dim)
    assert inst.f64("velocities", n).shape == (n,)
    assert inst.f64("modalCoordinates", r).shape == (r,)
    f = inst.f64("modeFrequencies", r)
    assert np.all(f > 0) and np.all(np.diff(f) >= 0)
    np.testing.assert_array_equal(inst.f64("modeWeights", r), np.ones(r))
    # the grid of the new size, at rest
    h = inst.f64s("spacing")
    rows, cols = np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij")
    np.testing.assert_allclose(x0[..., 0], cols * h, atol=1e-12)
    np.testing.assert_allclose(x0[..., 1], -rows * h, atol=1e-12)
    # strict nValues: the default size (and any other) is refused
    for wrong in (200, n - 1, n + 1):
        with pytest.raises(FMICallException):
            inst.f64("positions", wrong)
    with pytest.raises(FMICallException):
        inst.f64("modeWeights", r + 1)
    # and it runs and sags: the bottom row goes down during the run
    lowest = x0[-1, :, 1].mean()
    for _ in range(50):
        inst.step(0.01)
        x = inst.positions()
        assert np.all(np.isfinite(x))
        lowest = min(lowest, x[-1, :, 1].mean())
    assert lowest < x0[-1, :, 1].mean() - 1e-3 * h


def test_structural_parameters_in_instantiated_state(new_instance):
    """fmpy's simulate_fmu sets start values in the Instantiated state."""
    inst = new_instance()
    inst.set_u64("nx", 6)
    inst.set_u64("nModes", 4)
    assert inst.sizes() == (6, 10, 2, 4)
    inst.initialize()
    assert inst.positions().shape == (10, 6, 2)
    assert inst.f64("modeFrequencies", 4).shape == (4,)


def test_several_structural_parameters_in_one_call(new_instance):
    inst = new_instance()
    vr = inst.vr
    inst.slave.enterConfigurationMode()
    inst.slave.setUInt64([vr["nx"], vr["ny"], vr["nModes"]], [7, 5, 3])
    inst.slave.exitConfigurationMode()
    assert [int(v) for v in inst.slave.getUInt64([vr["nx"], vr["ny"], vr["nModes"]])] == [7, 5, 3]
    inst.initialize()
    assert inst.positions().shape == (5, 7, 2)


def test_configuration_changes_the_modes(new_instance):
    """More modes: the first ones are the same (lowest r of the same problem)."""
    a, b = new_instance("a"), new_instance("b")
    configure(b, nModes=6)
    a.initialize()
    b.initialize()
    fa, fb = a.f64("modeFrequencies", 2), b.f64("modeFrequencies", 6)
    np.testing.assert_allclose(fb[:2], fa, rtol=1e-9)
    assert fb[5] > fa[1]


def test_mode_weights_set_after_resize(new_instance):
    inst = new_instance()
    configure(inst, nModes=4)
    inst.set_f64("modeWeights", [1, 0, 1, 0])
    with pytest.raises(FMICallException):
        inst.set_f64("modeWeights", [1, 1])  # still the old size: refused
    inst.initialize()
    np.testing.assert_array_equal(inst.f64("modeWeights", 4), [1, 0, 1, 0])
    inst.step(0.01, 20)
    q = inst.modal()
    assert q[1] == 0.0 and q[3] == 0.0 and q[0] != 0.0


def test_bad_structural_values_are_refused(new_instance):
    inst = new_instance()
    inst.slave.enterConfigurationMode()
    for name, bad in (("nx", 0), ("ny", 0), ("dimension", 1), ("dimension", 4)):
        with pytest.raises(FMICallException):
            inst.set_u64(name, bad)
    inst.slave.exitConfigurationMode()
    assert inst.sizes() == (10, 10, 2, 2)


def test_structural_parameters_fixed_after_initialization(new_instance):
    inst = new_instance()
    inst.initialize()
    with pytest.raises(FMICallException):
        inst.set_u64("nx", 5)
    with pytest.raises(FMICallException):
        inst.slave.enterConfigurationMode()
    assert inst.sizes() == (10, 10, 2, 2)
    assert any("nx" in m for _, _, m in inst.messages), inst.messages


def test_enumerations_select_the_model(new_instance):
    """reduction = full, integrator = newmark-implicit or trigonometric (Enumerations, Set/GetInt64)."""
    runs = {}
    for reduction, integrator in ((1, 1), (2, 1), (1, 2), (2, 2), (1, 3)):
        inst = new_instance(f"r{reduction}i{integrator}")
        inst.slave.setInt64([inst.vr["reduction"], inst.vr["integrator"]], [reduction, integrator])
        inst.initialize()
        assert list(inst.slave.getInt64([inst.vr["reduction"], inst.vr["integrator"]])) == [reduction, integrator]
        x0 = inst.positions()
        inst.step(0.01, 30)
        x = inst.positions()
        assert np.all(np.isfinite(x)) and x[-1, :, 1].mean() < x0[-1, :, 1].mean()
        runs[(reduction, integrator)] = x
    # the full-space run differs from the two-mode run
    assert not np.array_equal(runs[(1, 1)], runs[(2, 1)])
    assert not np.array_equal(runs[(1, 1)], runs[(1, 2)])
    assert not np.array_equal(runs[(1, 1)], runs[(1, 3)])
    with pytest.raises(FMICallException):
        new_instance().slave.setInt64([inst.vr["reduction"]], [4])
    # the trigonometric integrator needs the modal space: refused at set-up, naming both variables
    inst = new_instance("r2i3")
    inst.slave.setInt64([inst.vr["reduction"], inst.vr["integrator"]], [2, 3])
    with pytest.raises(FMICallException):
        inst.initialize()
    assert any("integrator" in m and "reduction" in m for _, _, m in inst.messages), inst.messages


def test_top_corners(new_instance):
    inst = new_instance()
    inst.slave.setInt64([inst.vr["fixedNodes"]], [2])
    inst.initialize()
    x0 = inst.positions()
    inst.step(0.01, 30)
    x = inst.positions()
    assert np.array_equal(x[0, 0], x0[0, 0]) and np.array_equal(x[0, -1], x0[0, -1])
    assert not np.array_equal(x[0, 1:-1], x0[0, 1:-1])  # the rest of the top row falls
