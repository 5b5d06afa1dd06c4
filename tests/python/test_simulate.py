"""fmpy.simulate_fmu on the default FMU and on every scene-baked FMU.

fmpy 0.3.32 records array outputs in simulate_fmu: its Recorder reads each
array with nValues = the product of the variable's shape, and the shape comes
from the start values of the dimension variables in the model description.
So the positions are recorded as (time, ny, nx, dimension) arrays as long as
the structural parameters keep their start values (true for the default FMU
and for scene-baked FMUs)."""

import sys
from functools import lru_cache

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu

from conftest import ROOT, fmu_path

sys.path.insert(0, str(ROOT / "python"))
from measures import trajectory_error  # noqa: E402

OUTPUTS = ["positions", "velocities", "modalCoordinates", "kineticEnergy", "potentialEnergy", "modeFrequencies"]


@lru_cache(maxsize=None)
def simulate(path):
    return simulate_fmu(path, stop_time=2.0, output_interval=0.01, output=OUTPUTS)


def starts(path):
    return {v.name: v.start for v in read_model_description(path).modelVariables}


def fixed_mask(path):
    """Boolean (ny, nx) mask of the fixed nodes, from the start values."""
    s = starts(path)
    nx, ny = int(s["nx"]), int(s["ny"])
    mask = np.zeros((ny, nx), bool)
    if int(s["fixedNodes"]) == 1:  # top-row
        mask[0, :] = True
    else:  # top-corners
        mask[0, 0] = mask[0, -1] = True
    return mask


def test_result_shapes(any_fmu):
    s = starts(any_fmu)
    nx, ny, dim, r = (int(s[k]) for k in ("nx", "ny", "dimension", "nModes"))
    res = simulate(any_fmu)
    assert res["time"][0] == 0.0 and np.isclose(res["time"][-1], 2.0)
    assert len(res) == 201
    assert res["positions"].shape == (201, ny, nx, dim)
    assert res["velocities"].shape == (201, ny, nx, dim)
    assert res["modalCoordinates"].shape == (201, r)
    assert res["modeFrequencies"].shape == (201, r)


def test_finite(any_fmu):
    res = simulate(any_fmu)
    for name in OUTPUTS:
        assert np.all(np.isfinite(res[name])), name


def test_starts_at_rest_on_the_grid(any_fmu):
    """Row 0 on top, rest position (col h, -row h[, 0]), zero velocity."""
    s = starts(any_fmu)
    h = float(s["spacing"])
    res = simulate(any_fmu)
    x0 = res["positions"][0]
    ny, nx, dim = x0.shape
    rows, cols = np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij")
    np.testing.assert_allclose(x0[..., 0], cols * h, atol=1e-12)
    np.testing.assert_allclose(x0[..., 1], -rows * h, atol=1e-12)
    if dim == 3:
        np.testing.assert_allclose(x0[..., 2], 0.0, atol=1e-12)
    assert np.all(res["velocities"][0] == 0.0)
    assert res["kineticEnergy"][0] == 0.0


def test_sags_under_gravity(any_fmu):
    """The bottom row moves down: clearly below its rest height at its lowest
    and on average over the run. The centre of mass never rises above where it
    started (the sheet starts at rest, with no elastic energy)."""
    s = starts(any_fmu)
    h = float(s["spacing"])
    x = simulate(any_fmu)["positions"]
    y = x[:, -1, :, 1]  # (time, nx): y of the bottom row
    dy = y.mean(axis=1) - y[0].mean()
    assert dy.min() < -0.05 * h, f"bottom row hardly moves: lowest mean displacement {dy.min()}"
    assert dy[1:].mean() < -0.02 * h
    # the first output step already moves down (gravity acts from t = 0)
    assert dy[1] < 0
    com = x[..., 1].mean(axis=(1, 2))
    assert np.all(com[1:] < com[0])


def test_fixed_nodes_stay(any_fmu):
    res = simulate(any_fmu)
    mask = fixed_mask(any_fmu)
    x = res["positions"]
    assert np.all(x[:, mask] == x[0, mask][None])
    assert np.all(res["velocities"][:, mask] == 0.0)
    # and every free node moves at some time
    moved = np.abs(x - x[0][None]).max(axis=(0, 3))
    assert np.all(moved[~mask] > 0)


def test_energies(any_fmu):
    res = simulate(any_fmu)
    ke, pe = res["kineticEnergy"], res["potentialEnergy"]
    assert np.all(ke >= 0)
    assert pe[0] == pytest.approx(0.0, abs=1e-12)
    # falling converts potential energy into kinetic energy
    assert ke.max() > 0 and pe.min() < 0
    # kinetic energy is consistent with the recorded velocities and node mass
    m = float(starts(any_fmu)["nodeMass"])
    ke_v = 0.5 * m * (res["velocities"] ** 2).sum(axis=(1, 2, 3))
    np.testing.assert_allclose(ke, ke_v, rtol=1e-9, atol=1e-15)
    # no damping in any canonical scene: kinetic + potential energy is conserved
    # up to the integrator's error
    assert np.abs(ke + pe).max() < 0.02 * ke.max()


def test_mode_frequencies(any_fmu):
    f = simulate(any_fmu)["modeFrequencies"]
    assert np.all(f == f[0][None])  # a calculated parameter: fixed during the run
    assert np.all(f[0] > 0) and np.all(np.diff(f[0]) >= 0)


def test_default_is_paper_2d_top_row(default_fmu):
    """The default FMU runs the scene paper-2d-top-row: same result bit for bit."""
    a, b = simulate(default_fmu), simulate(str(fmu_path("paper-2d-top-row")))
    assert np.array_equal(a["positions"], b["positions"])


def test_stop_time_and_step_size_are_honoured(default_fmu):
    """Variable communication steps: a 2 s run with 0.05 s steps ends at the same
    physics time, and its positions stay close to the 0.01 s run (the internal
    steps differ, so not equal: within 2 % of the largest displacement)."""
    a = simulate(default_fmu)
    b = simulate_fmu(default_fmu, stop_time=2.0, output_interval=0.05, output=["positions"])
    assert len(b) == 41 and np.isclose(b["time"][-1], 2.0)
    x = a["positions"]
    scale = np.abs(x - x[0][None]).max()
    np.testing.assert_allclose(b["positions"], x[::5], atol=0.02 * scale)


def test_basis_options_through_fmpy(default_fmu):
    """modeSelection and linearization as start values of simulate_fmu (the
    default two modes, whose array sizes fmpy takes from the model
    description): the sideways sway that gravity does not drive is left out,
    and two modes chosen by the load at the equilibrium follow full space
    more closely than the paper's two lowest modes at rest."""
    outputs = ["positions", "modeFrequencies"]

    def run(**starts):
        return simulate_fmu(default_fmu, stop_time=2.0, output_interval=0.05, output=outputs, start_values=starts)

    full = run(reduction=2)
    sway = full["modeFrequencies"][0][0]
    lowest = run()
    chosen = run(modeSelection=2, linearization=2)
    assert np.isclose(lowest["modeFrequencies"][0][0], sway)
    assert not np.any(np.isclose(chosen["modeFrequencies"][0], sway, rtol=1e-6))

    def error(res):
        """E against full space; x(0) is the first recorded row, t = 0."""
        x, xr = res["positions"], full["positions"]
        return trajectory_error(x, xr, xr[0], dim=xr.shape[-1])

    assert error(chosen) < 0.5 * error(lowest), (error(chosen), error(lowest))


def test_cubature_through_fmpy(default_fmu):
    """forceEvaluation = cubature as a start value: the run follows the same
    basis with exact forces closely, and cubatureSprings says how few
    springs it visits (every spring with exact forces)."""
    outputs = ["positions", "cubatureSprings"]

    def run(**starts):
        return simulate_fmu(
            default_fmu, stop_time=2.0, output_interval=0.05, output=outputs, start_values=dict(modeSelection=2, staticCorrection=True, **starts)
        )

    exact = run()
    cubature = run(forceEvaluation=2, cubatureTolerance=0.002)
    springs_all, springs_kept = int(exact["cubatureSprings"][0]), int(cubature["cubatureSprings"][0])
    assert 0 < springs_kept < springs_all / 2, (springs_kept, springs_all)
    x, xr = cubature["positions"], exact["positions"]
    e = trajectory_error(x, xr, xr[0], dim=xr.shape[-1])
    assert e < 0.01, e
