"""The mode gallery of `cargo xtask modes`: reads what examples/modes.rs
wrote into DIR (modes.csv, shapes.csv, springs.csv, scene.txt) and writes
DIR/modes.png, each mode's shape (the deformed grid, springs as lines; in 3D
a front view x-y and a side view z-y) titled with its number, frequency and
class, and DIR/modes.md, the table of the modes.

usage: python python/modes_gallery.py DIR"""
import csv
import math
import os
import sys
from collections import defaultdict

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402

from pictures import compact  # noqa: E402


def read(out):
    modes = list(csv.DictReader(open(os.path.join(out, "modes.csv"))))
    shapes = defaultdict(list)
    for row in csv.DictReader(open(os.path.join(out, "shapes.csv"))):
        shapes[int(row["mode"])].append([float(row[k]) for k in ("rest_x", "rest_y", "rest_z", "x", "y", "z")])
    springs = np.array([[int(r["a"]), int(r["b"])] for r in csv.DictReader(open(os.path.join(out, "springs.csv")))], dtype=int)
    name, dim, nx, ny = open(os.path.join(out, "scene.txt")).read().split()
    return modes, {m: np.array(s) for m, s in shapes.items()}, springs.reshape(-1, 2), name, int(dim)


def draw(ax, rest, moved, springs, axes):
    """The sheet at rest (grey) and displaced by the mode (blue), projected on `axes` (indices into x, y, z)."""
    h, v = axes
    for pos, colour, width in ((rest, "0.8", 0.6), (moved, "tab:blue", 0.9)):
        ends = pos[:, [h, v]]
        ax.add_collection(LineCollection(np.stack([ends[springs[:, 0]], ends[springs[:, 1]]], axis=1), colors=colour, linewidths=width))
    ax.plot(moved[:, h], moved[:, v], ".", color="tab:blue", ms=2)
    ax.autoscale()
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])


def gallery(out, modes, shapes, springs, name, dim):
    views = [((0, 1), "front x-y")] + ([((2, 1), "side z-y")] if dim == 3 else [])
    per_row = 4 if dim == 2 else 3
    rows = math.ceil(len(modes) / per_row)
    cols = per_row * len(views)
    width = [1.0, 0.45][: len(views)] * per_row
    fig, axs = plt.subplots(rows, cols, figsize=(sum(width) * 2.6, rows * 2.9), squeeze=False, gridspec_kw={"width_ratios": width})
    for ax in axs.flat:
        ax.axis("off")
    for i, m in enumerate(modes):
        s = shapes[int(m["mode"])]
        rest, moved = s[:, :3], s[:, 3:]
        for j, (axes, view) in enumerate(views):
            ax = axs[i // per_row, (i % per_row) * len(views) + j]
            ax.axis("on")
            draw(ax, rest, moved, springs, axes)
            if j == 0:
                ax.set_title(f"mode {m['mode']}: {float(m['frequency_hz']):.3f} Hz\n{m['class']}", fontsize=8, loc="left")
            else:
                ax.set_title(view.split()[1], fontsize=7)
    fig.suptitle(f"{name}: {len(modes)} modes" + (" (front x-y, side z-y)" if dim == 3 else ""))
    fig.tight_layout()
    fig.savefig(os.path.join(out, "modes.png"), dpi=90)
    plt.close(fig)
    compact(os.path.join(out, "modes.png"))


def table(out, modes, name):
    lines = [
        f"# Modes of {name}",
        "",
        "| mode | omega (rad/s) | f (Hz) | modeOutOfPlane | modeSymmetry | class |",
        "|---:|---:|---:|---:|---:|---|",
    ]
    for m in modes:
        lines.append(
            f"| {m['mode']} | {float(m['omega']):.10g} | {float(m['frequency_hz']):.4f} | "
            f"{float(m['out_of_plane']):.3f} | {float(m['symmetry']):+.3f} | {m['class']} |"
        )
    open(os.path.join(out, "modes.md"), "w").write("\n".join(lines) + "\n")


def main():
    if len(sys.argv) != 2 or sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        sys.exit(0 if len(sys.argv) == 2 else 2)
    out = sys.argv[1]
    modes, shapes, springs, name, dim = read(out)
    gallery(out, modes, shapes, springs, name, dim)
    table(out, modes, name)
    print(f"{os.path.join(out, 'modes.png')} and {os.path.join(out, 'modes.md')} written")


if __name__ == "__main__":
    main()
