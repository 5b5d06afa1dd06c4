"""Main job: simulate an FMU of the modal mass-spring sheet with fmpy, print a
short summary and plot the sheet (nodes and springs) at a few times.

    .venv/bin/python python/main_job.py [FMU] [--stop-time 2] [--out out/default_scene.png]

`cargo xtask run` builds target/fmu/ModalMassSpring.fmu and runs this on it.
"""

import argparse
import os
import sys
import time

import numpy as np
from fmpy import read_model_description, simulate_fmu

from sheet import fixed_nodes, springs

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUTPUTS = ["positions", "modalCoordinates", "kineticEnergy", "potentialEnergy", "modeFrequencies", "springNeighbours"]


def start_values(md):
    """name -> start value (numbers; arrays as lists); Enumerations as item names too."""
    out, items = {}, {}
    for v in md.modelVariables:
        if v.start is None:
            continue
        if v.type == "Boolean":
            out[v.name] = str(v.start).lower() == "true"
        elif v.shape:
            out[v.name] = [float(x) for x in str(v.start).split()]
        elif v.type in ("UInt64", "Int64", "Enumeration"):
            out[v.name] = int(v.start)
        else:
            out[v.name] = float(v.start)
        if v.type == "Enumeration" and v.declaredType is not None:
            names = {int(i.value): i.name for i in v.declaredType.items}
            items[v.name] = names.get(int(v.start), str(v.start))
    return out, items


def plot(path, res, sv, items, title, n_frames=5):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection

    nx, ny = sv["nx"], sv["ny"]
    t = res["time"]
    x = res["positions"].reshape(len(t), nx * ny, -1)
    pairs = springs(res["springNeighbours"][0], nx * ny)
    fixed = fixed_nodes(nx, items["fixedNodes"])
    frames = [int(round(k)) for k in np.linspace(0, len(t) - 1, n_frames)]

    fig = plt.figure(figsize=(3.2 * n_frames, 7.2))
    grid = fig.add_gridspec(2, n_frames, height_ratios=[2.2, 1])
    lo, hi = x[..., :2].min(axis=(0, 1)), x[..., :2].max(axis=(0, 1))
    pad = 0.05 * (hi - lo).max()
    for k, f in enumerate(frames):
        ax = fig.add_subplot(grid[0, k])
        ax.add_collection(LineCollection(x[0][pairs][..., :2], colors="0.85", linewidths=0.6))
        ax.add_collection(LineCollection(x[f][pairs][..., :2], colors="tab:blue", linewidths=0.8))
        ax.plot(x[f][:, 0], x[f][:, 1], ".", color="tab:blue", ms=3)
        ax.plot(x[f][fixed, 0], x[f][fixed, 1], "s", color="tab:red", ms=4)
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
        ax.set_aspect("equal")
        ax.set_title(f"t = {t[f]:.2f} s")
        ax.set_xlabel("x [m]")
        if k == 0:
            ax.set_ylabel("y [m]")
    ax = fig.add_subplot(grid[1, : n_frames // 2 + 1])
    bottom = x[:, (ny - 1) * nx :, 1].mean(axis=1) - x[0, (ny - 1) * nx :, 1].mean()
    ax.plot(t, bottom, color="tab:blue")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("bottom row mean dy [m]")
    ax.grid(alpha=0.3)
    ax = fig.add_subplot(grid[1, n_frames // 2 + 1 :])
    ke, pe = res["kineticEnergy"], res["potentialEnergy"]
    ax.plot(t, ke, label="kinetic")
    ax.plot(t, pe, label="potential")
    ax.plot(t, ke + pe, "k--", lw=1, label="total")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("energy [J]")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.suptitle(title + "  (grey: rest, red: fixed nodes)")
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("fmu", nargs="?", default=os.path.join(ROOT, "target", "fmu", "ModalMassSpring.fmu"))
    p.add_argument("--stop-time", type=float, default=None, help="default: the FMU's default experiment (2 s)")
    p.add_argument("--interval", type=float, default=None, help="output interval (default: the FMU's step size)")
    p.add_argument("--out", default=os.path.join(ROOT, "out", "default_scene.png"))
    a = p.parse_args(argv)

    md = read_model_description(a.fmu)
    sv, items = start_values(md)
    de = md.defaultExperiment
    stop = a.stop_time if a.stop_time is not None else float(de.stopTime if de and de.stopTime else 2.0)
    interval = a.interval if a.interval is not None else float(de.stepSize if de and de.stepSize else 0.01)

    t0 = time.perf_counter()
    res = simulate_fmu(a.fmu, stop_time=stop, output_interval=interval, output=OUTPUTS)
    wall = time.perf_counter() - t0

    nx, ny, dim = sv["nx"], sv["ny"], sv["dimension"]
    x = res["positions"]
    if not np.all(np.isfinite(x)):
        print("error: non-finite positions", file=sys.stderr)
        return 1
    dy = x[:, -1, :, 1].mean(axis=1) - x[0, -1, :, 1].mean()
    omega = res["modeFrequencies"][0]
    ke, pe = res["kineticEnergy"], res["potentialEnergy"]
    scene = f"{nx} x {ny} grid, {dim}D, fixed {items['fixedNodes']}, spacing {sv['spacing']} m, " \
            f"node mass {sv['nodeMass']} kg, k {sv['springStiffness']} N/m"
    print(f"FMU          {os.path.relpath(a.fmu)}")
    print(f"scene        {scene}")
    print(f"solver       {items['reduction']}, {items['integrator']}, {sv['nModes']} modes, "
          f"weights {' '.join(f'{w:g}' for w in sv['modeWeights'][:8])}{' ...' if len(sv['modeWeights']) > 8 else ''}")
    shown = omega[:8]
    print(f"frequencies  {' '.join(f'{w:.4g}' for w in shown)}{' ...' if len(omega) > 8 else ''} rad/s"
          f"  ({' '.join(f'{w / (2 * np.pi):.4g}' for w in shown)}{' ...' if len(omega) > 8 else ''} Hz)")
    print(f"bottom row   sag time-averaged over the run: {-dy.mean() * 1000:.2f} mm, "
          f"at t = {res['time'][-1]:g} s: {-dy[-1] * 1000:.2f} mm, "
          f"largest: {-dy.min() * 1000:.2f} mm at t = {res['time'][int(np.argmin(dy))]:.2f} s")
    print(f"energy       at t = {res['time'][-1]:g} s: kinetic {ke[-1]:.5g} J, potential {pe[-1]:.5g} J, "
          f"total {ke[-1] + pe[-1]:.3g} J (largest kinetic {ke.max():.5g} J)")
    print(f"wall time    {wall:.3f} s for {stop:g} s simulated ({len(res)} output points, "
          f"{stop / wall:.0f}x real time), fmpy.simulate_fmu")
    plot(a.out, res, sv, items, f"{md.modelName}: {scene}\n{items['reduction']} ({sv['nModes']} modes), "
         f"{items['integrator']}")
    print(f"plot         {os.path.relpath(a.out)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
