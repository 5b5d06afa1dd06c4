"""The sheet's springs come from the FMU (springNeighbours), not from a
rebuild of the grid in Python: the pairs main_job.py draws are the springs
of the scene, and main_job runs on the FMU."""

import sys

import numpy as np
import pytest

from conftest import ROOT

sys.path.insert(0, str(ROOT / "python"))
import main_job  # noqa: E402


def neighbours(inst, nx, ny):
    return np.array(inst.slave.getUInt64([inst.vr["springNeighbours"]], nValues=nx * ny * 6))


@pytest.mark.parametrize("nx,ny,shear,bending", [(10, 10, True, False), (4, 3, False, False), (5, 6, True, True)])
def test_pairs_are_the_grid_springs(new_instance, nx, ny, shear, bending):
    inst = new_instance()
    inst.slave.enterConfigurationMode()
    inst.set_u64("nx", nx)
    inst.set_u64("ny", ny)
    inst.slave.exitConfigurationMode()
    inst.slave.setBoolean([inst.vr["shearSprings"], inst.vr["bendingSprings"]], [shear, bending])
    inst.initialize()
    pairs = main_job.springs(neighbours(inst, nx, ny), nx * ny)
    assert pairs.shape[1] == 2 and np.all(pairs[:, 0] < pairs[:, 1])
    assert len({tuple(p) for p in pairs}) == len(pairs), "a spring listed twice"
    # Every pair joins neighbours at rest: one spacing apart along a row or
    # column, a diagonal of a cell, or two spacings apart (bending).
    h = inst.f64s("spacing")
    x = inst.positions().reshape(nx * ny, -1)
    lengths = np.linalg.norm(x[pairs[:, 1]] - x[pairs[:, 0]], axis=1) / h
    allowed = [1.0] + ([np.sqrt(2.0)] if shear else []) + ([2.0] if bending else [])
    assert np.all(np.min(np.abs(lengths[:, None] - np.array(allowed)[None, :]), axis=1) < 1e-9)
    # Counted: rows, columns, two diagonals per cell, bending springs; none
    # along the held top row (both ends held, they never act).
    count = ny * (nx - 1) + nx * (ny - 1) - (nx - 1)
    count += 2 * (nx - 1) * (ny - 1) if shear else 0
    count += ny * (nx - 2) + nx * (ny - 2) - (nx - 2) if bending else 0
    assert len(pairs) == count


def test_main_job_draws_the_fmu_springs(default_fmu, tmp_path):
    out = tmp_path / "sheet.png"
    assert main_job.main([default_fmu, "--stop-time", "0.1", "--out", str(out)]) == 0
    assert out.stat().st_size > 10_000
