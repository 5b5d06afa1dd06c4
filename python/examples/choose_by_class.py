"""Choose modes by class and run: the paper's 3D sheet (7 x 7 nodes, top row
held, weak auxiliary springs, all 126 modes) under a gravity with a part
across its plane, keeping only the modes of one class. The FMU says which
mode is which after set-up (modeOutOfPlane, modeSymmetry); the weights
delete the others (0) before the first step.

    .venv/bin/python python/examples/choose_by_class.py [FMU] [--keep in-plane] [--seconds 1]

--keep in-plane: the sheet stretches and sways in its plane and never leaves
it (z stays 0 to round-off); out-of-plane: it swings across its plane and
nothing moves in it; symmetric / antisymmetric: by the mirror image about
the vertical mid-line (the out-of-plane modes share one frequency, their
symmetry is any mix and both leave them out); all: every mode (the full
model)."""

import argparse
import os
import shutil

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi3 import FMU3Slave

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("fmu", nargs="?", default=os.path.join(ROOT, "target", "fmu", "ModalMassSpring.fmu"))
    p.add_argument("--keep", default="in-plane", choices=["in-plane", "out-of-plane", "symmetric", "antisymmetric", "all"])
    p.add_argument("--seconds", type=float, default=1.0)
    a = p.parse_args(argv)

    md = read_model_description(a.fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    unzipped = extract(a.fmu)  # a temporary directory, removed at the end
    fmu = FMU3Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier, instanceName="sheet")
    fmu.instantiate()

    # The 3D sheet: sizes in Configuration Mode, the rest before initialization.
    nx, ny, dim, n_modes = 7, 7, 3, 126
    fmu.enterConfigurationMode()
    fmu.setUInt64([vr["nx"], vr["ny"], vr["dimension"], vr["nModes"]], [nx, ny, dim, n_modes])
    fmu.exitConfigurationMode()
    fmu.setFloat64([vr["auxStiffness"]], [0.05])
    fmu.setFloat64([vr["gravity"]], [1.0, -9.81, 3.0])  # sideways and across the sheet
    fmu.enterInitializationMode(startTime=0.0)
    fmu.exitInitializationMode()

    # Which mode is which, computed at set-up.
    out_of_plane = np.array(fmu.getFloat64([vr["modeOutOfPlane"]], nValues=n_modes))
    symmetry = np.array(fmu.getFloat64([vr["modeSymmetry"]], nValues=n_modes))
    keep = {
        "in-plane": out_of_plane < 0.5,
        "out-of-plane": out_of_plane >= 0.5,
        "symmetric": symmetry > 0.9,
        "antisymmetric": symmetry < -0.9,
        "all": np.ones(n_modes, dtype=bool),
    }[a.keep]
    fmu.setFloat64([vr["modeWeights"]], list(keep.astype(float)))  # 1 keeps a mode, 0 deletes it

    rest = np.array(fmu.getFloat64([vr["positions"]], nValues=nx * ny * dim)).reshape(-1, dim)
    largest = np.zeros(dim)  # the largest |displacement| of a node along x, y, z
    t, h = 0.0, 0.01
    for _ in range(int(round(a.seconds / h))):
        fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        t += h
        x = np.array(fmu.getFloat64([vr["positions"]], nValues=nx * ny * dim)).reshape(-1, dim)
        largest = np.maximum(largest, np.abs(x - rest).max(axis=0))
    fmu.terminate()
    fmu.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)

    print(f"kept {keep.sum()} of {n_modes} modes ({a.keep})")
    print(f"largest displacement of a node over {t:.2f} s: x {largest[0]:.3e} m, y {largest[1]:.3e} m, z {largest[2]:.3e} m")
    return keep.sum(), largest


if __name__ == "__main__":
    main()
