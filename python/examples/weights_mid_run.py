"""Change mode weights in the middle of a run from fmpy: two instances of the
sheet held at its two top corners (12 lowest modes) run side by side; at
t = --at one of them deletes its lowest mode and doubles the next one
(modeWeights is tunable: set between two steps, it acts from the next step
on). Until then the two runs are the same to the last bit; after it they part.

    .venv/bin/python python/examples/weights_mid_run.py [FMU] [--at 1.0] [--seconds 2]"""

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
    p.add_argument("--at", type=float, default=1.0, help="when the weights change [s]")
    p.add_argument("--seconds", type=float, default=2.0)
    a = p.parse_args(argv)

    md = read_model_description(a.fmu)
    variables = {v.name: v for v in md.modelVariables}
    vr = {name: v.valueReference for name, v in variables.items()}
    unzipped = extract(a.fmu)  # a temporary directory, removed at the end
    nx, ny, dim, n_modes = 10, 10, 2, 12
    # fixedNodes is an enumeration: set through its item's value
    corners = {i.name: int(i.value) for i in variables["fixedNodes"].declaredType.items}["top-corners"]

    sheets = []
    for name in ("kept", "changed"):
        fmu = FMU3Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        fmu.instantiate()
        fmu.enterConfigurationMode()
        fmu.setUInt64([vr["nx"], vr["ny"], vr["nModes"]], [nx, ny, n_modes])
        fmu.exitConfigurationMode()
        fmu.setInt64([vr["fixedNodes"]], [corners])
        fmu.enterInitializationMode(startTime=0.0)
        fmu.exitInitializationMode()
        sheets.append(fmu)
    kept, changed = sheets

    def bottom_row(fmu):
        x = np.array(fmu.getFloat64([vr["positions"]], nValues=nx * ny * dim)).reshape(ny, nx, dim)
        return x[-1]

    t, h = 0.0, 0.01
    apart_before, apart_after = 0.0, 0.0
    for _ in range(int(round(a.seconds / h))):
        if abs(t - a.at) < h / 2:
            weights = [1.0] * n_modes
            weights[0], weights[1] = 0.0, 2.0  # delete mode 1, double mode 2
            changed.setFloat64([vr["modeWeights"]], weights)
            print(f"t = {t:.2f} s: modeWeights of 'changed' set to {weights}")
        for fmu in sheets:
            fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        t += h
        apart = float(np.abs(bottom_row(kept) - bottom_row(changed)).max())
        if t <= a.at + h / 2:
            apart_before = max(apart_before, apart)
        else:
            apart_after = max(apart_after, apart)
    for fmu in sheets:
        fmu.terminate()
        fmu.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)

    print(f"largest distance between the two bottom rows: {apart_before:.3e} m up to t = {a.at:.2f} s, {apart_after:.3e} m after")
    return apart_before, apart_after


if __name__ == "__main__":
    main()
