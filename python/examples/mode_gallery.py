"""Draw the mode gallery from the FMU alone: the modes it keeps (modeShapes),
their frequencies (modeFrequencies) and classes (modeOutOfPlane,
modeSymmetry), read through fmpy after set-up, drawn as the deformed sheet
(3D: a front view x-y and a side view z-y) into a PNG. `cargo xtask modes`
draws the same from the repository's sources, with a table.

    .venv/bin/python python/examples/mode_gallery.py [FMU] [--dimension 3] [--modes 12]
        [--mode-selection lowest|load] [--gravity 3,-9.81,0] [--out out/mode_gallery.png]

The default: the paper's 3D sheet, the 6 modes a gravity pulling down and
sideways loads most (modeSelection = load: symmetric and antisymmetric
modes in the plane). The 42 lowest modes are the auxiliary springs'
out-of-plane cluster (`--mode-selection lowest`), and a gravity with any
part across the sheet loads those most (`--gravity 0,-9.81,1`).
--dimension 2 draws the paper's 2D sheet."""

import argparse
import math
import os
import shutil
import sys

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi3 import FMU3Slave

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.dirname(HERE))
from modes_gallery import draw  # noqa: E402  (the gallery's drawing of one shape)
from sheet import springs  # noqa: E402  (springNeighbours as node pairs)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("fmu", nargs="?", default=os.path.join(ROOT, "target", "fmu", "ModalMassSpring.fmu"))
    p.add_argument("--dimension", type=int, default=3, choices=[2, 3])
    p.add_argument("--modes", type=int, default=6)
    p.add_argument("--mode-selection", default="load", choices=["lowest", "load"])
    p.add_argument("--gravity", default="3,-9.81,0", help="gravity at set-up, x,y,z [m/s2] (the load modes follow it)")
    p.add_argument("--out", default=os.path.join(ROOT, "out", "mode_gallery.png"))
    a = p.parse_args(argv)

    md = read_model_description(a.fmu)
    variables = {v.name: v for v in md.modelVariables}
    vr = {name: v.valueReference for name, v in variables.items()}
    unzipped = extract(a.fmu)  # a temporary directory, removed at the end
    fmu = FMU3Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier, instanceName="gallery")
    fmu.instantiate()
    nx = ny = 7 if a.dimension == 3 else 10
    dim, r = a.dimension, a.modes
    fmu.enterConfigurationMode()
    fmu.setUInt64([vr["nx"], vr["ny"], vr["dimension"], vr["nModes"]], [nx, ny, dim, r])
    fmu.exitConfigurationMode()
    if dim == 3:
        fmu.setFloat64([vr["auxStiffness"]], [0.05])
    selection = {i.name: int(i.value) for i in variables["modeSelection"].declaredType.items}[a.mode_selection]
    fmu.setInt64([vr["modeSelection"]], [selection])
    fmu.setFloat64([vr["gravity"]], [float(g) for g in a.gravity.split(",")])
    fmu.enterInitializationMode(startTime=0.0)
    fmu.exitInitializationMode()

    n = nx * ny
    rest = np.array(fmu.getFloat64([vr["positions"]], nValues=n * dim)).reshape(n, dim)
    shapes = np.array(fmu.getFloat64([vr["modeShapes"]], nValues=r * n * dim)).reshape(r, n, dim)
    omega = fmu.getFloat64([vr["modeFrequencies"]], nValues=r)
    out_of_plane = fmu.getFloat64([vr["modeOutOfPlane"]], nValues=r)
    symmetry = fmu.getFloat64([vr["modeSymmetry"]], nValues=r)
    pairs = springs(fmu.getUInt64([vr["springNeighbours"]], nValues=n * 6), n)
    spacing = fmu.getFloat64([vr["spacing"]])[0]
    fmu.terminate()
    fmu.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    views = [(0, 1)] + ([(2, 1)] if dim == 3 else [])
    per_row = 3
    rows = math.ceil(r / per_row)
    widths = [1.0, 0.45][: len(views)] * per_row  # a side view is narrow
    fig, axs = plt.subplots(rows, len(widths), figsize=(sum(widths) * 2.6, rows * 2.9), squeeze=False, gridspec_kw={"width_ratios": widths})
    for ax in axs.flat:
        ax.axis("off")
    to3 = lambda x: np.pad(x, ((0, 0), (0, 3 - dim)))  # noqa: E731  (z = 0 in 2D)
    for i in range(r):
        # each shape scaled so the node that moves most moves half a spacing
        moved = rest + 0.5 * spacing * shapes[i] / np.abs(shapes[i]).max()
        parity = " symmetric" if symmetry[i] > 0.9 else " antisymmetric" if symmetry[i] < -0.9 else ""
        kind = ("out-of-plane" if out_of_plane[i] > 0.5 else "in-plane") + parity
        for j, axes in enumerate(views):
            ax = axs[i // per_row, (i % per_row) * len(views) + j]
            ax.axis("on")
            draw(ax, to3(rest), to3(moved), pairs, axes)
            if j == 0:
                ax.set_title(f"mode {i + 1}: {omega[i] / (2 * math.pi):.2f} Hz\n{kind}", fontsize=8, loc="left")
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    fig.savefig(a.out, dpi=80)
    plt.close(fig)
    for i in range(r):
        print(f"mode {i + 1}: omega {omega[i]:.4f} rad/s, out of plane {out_of_plane[i]:.3f}, symmetry {symmetry[i]:+.3f}")
    print(f"{a.out} written")
    return a.out


if __name__ == "__main__":
    main()
