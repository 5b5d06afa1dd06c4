"""reduction = adaptive through fmpy against a full-space reference of the same FMU.

Cloth 30 x 30 (the FMU of `cargo xtask fmu --scene cloth-3d`), undamped,
explicit, 60 steps of 0.01 s: the reference is full space at internal steps
of 0.0005 s. For each load (the canonical one; 0.85 g tilted 10 degrees,
inside the training program but never run; g sideways and 2 g tilted 70
degrees, far outside it, set after set-up) it prints E over [0, 0.6 s]
(docs/method.md, section 6), errorEstimate, reducedFraction and the time
of the doStep calls of adaptive and of full space at the same step.

    python python/examples/adaptive_check.py target/fmu/cloth-3d.fmu
"""

import argparse
import math
import time

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi3 import FMU3Slave

FULL, ADAPTIVE = 2, 3


def tilted(scale, about_x, about_z):
    """Gravity of `scale` g turned `about_z` degrees about z, then `about_x` about x."""
    a, b = math.radians(about_x), math.radians(about_z)
    g = [9.81 * math.sin(b), -9.81 * math.cos(b), 0.0]
    return [scale * g[0], scale * g[1] * math.cos(a), scale * g[1] * math.sin(a)]


LOADS = {
    "canonical": None,
    "0.85 g tilted 10 deg": tilted(0.85, 10, 10),
    "g sideways": [9.81, 0.0, 0.0],
    "2 g tilted 70 deg": tilted(2.0, 70, 0),
}


class Run:
    def __init__(self, path):
        self.md = read_model_description(path)
        self.dir = extract(path)
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}

    def __call__(self, reduction, gravity, internal_step=None, steps=60, h=0.01):
        """Positions at every communication point, the adaptive outputs, the time in doStep."""
        md, vr = self.md, self.vr
        fmu = FMU3Slave(guid=md.guid, unzipDirectory=self.dir, modelIdentifier=md.coSimulation.modelIdentifier, instanceName="check")
        fmu.instantiate()
        fmu.setUInt64([vr["nModes"]], [2])
        fmu.enterInitializationMode(startTime=0.0)
        fmu.setInt64([vr["reduction"]], [reduction])
        fmu.setFloat64([vr["dampingAlpha"], vr["dampingBeta"]], [0.0, 0.0])
        if internal_step:
            fmu.setFloat64([vr["maxInternalStep"]], [internal_step])
        fmu.exitInitializationMode()
        if gravity is not None:
            fmu.setFloat64([vr["gravity"]], gravity)
        n = 30 * 30 * 3
        xs = [np.array(fmu.getFloat64([vr["positions"]], nValues=n))]
        spent = 0.0
        for k in range(steps):
            t0 = time.perf_counter()
            fmu.doStep(currentCommunicationPoint=k * h, communicationStepSize=h)
            spent += time.perf_counter() - t0
            xs.append(np.array(fmu.getFloat64([vr["positions"]], nValues=n)))
        estimate, reduced = fmu.getFloat64([vr["errorEstimate"], vr["reducedFraction"]])
        fmu.terminate()
        fmu.freeInstance()
        return np.array(xs), estimate, reduced, spent


def error(x, ref):
    """E of docs/method.md section 6 (every node has the same mass)."""
    return math.sqrt(np.sum((x - ref) ** 2) / np.sum((ref - ref[0]) ** 2))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("fmu")
    run = Run(parser.parse_args().fmu)
    for name, gravity in LOADS.items():
        ref = run(FULL, gravity, internal_step=0.0005)[0]
        full = run(FULL, gravity)
        x, estimate, reduced, spent = run(ADAPTIVE, gravity)
        print(
            f"{name}: E {error(x, ref):.4f} errorEstimate {estimate:.4f} reducedFraction {reduced:.3f} "
            f"doStep {1e3 * spent:.1f} ms, full space {1e3 * full[3]:.1f} ms (E {error(full[0], ref):.4f})"
        )


if __name__ == "__main__":
    main()
