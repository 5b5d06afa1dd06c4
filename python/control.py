"""Control by choosing modes, through the FMU: the paper's experiments (its
Figs. 7, 8 and 9) and control of the 3D sheet, as pictures, two animations and
the numbers that check them.

    .venv/bin/python python/control.py [FMU] [--figure fig7,fig8,fig9,3d | all] [--out DIR]

`cargo xtask control` builds the default FMU and runs this on it (default
DIR target/control; docs/control/ holds the committed pictures, made with
`cargo xtask control --out docs/control`). Every run is the default FMU with
a canonical scene's values and the changes named below, simulated from rest
for 2 s in communication steps of 0.01 s (explicit Newmark, undamped, the
FMU's defaults). docs/control.md describes what each figure shows.

- fig7: paper-2d-top-row, full space against the 2 lowest modes.
- fig8: paper-2d-top-corners with nodes 5 times as heavy (HEAVIER), three mode
  sets: (a) the 2 lowest, (b) of the 13 lowest the 10 highest (modes 4-13),
  (c) higher still (modes 14-23); a still and a GIF of the three side by side.
- fig9: paper-3d-sheet (auxiliary springs), full space against all 126 modes.
- 3d: paper-3d-sheet under a gravity with an out-of-plane part, the modes
  chosen by the FMU's modeOutOfPlane: in-plane modes only, out-of-plane
  modes only, out-of-plane modes amplified (weight 2), and the out-of-plane
  modes switched on at t = 1 s (modeWeights changed between two steps); a
  still and a GIF."""

import argparse
import os
import sys

import numpy as np

from measures import max_node_error, trajectory_error
from pictures import compact, compact_gif
from sheet import ROOT, Fmu, scene

STOP, STEP = 2.0, 0.01
# Fig. 8: "the masses are made larger" (the paper gives no number).
HEAVIER = 5.0
FIG8_SETS = {
    "a": ("(a) modes 1-2", 2, [1.0] * 2),
    "b": ("(b) modes 4-13 (the 10 highest of the 13 lowest)", 13, [0.0] * 3 + [1.0] * 10),
    "c": ("(c) modes 14-23", 23, [0.0] * 13 + [1.0] * 10),
}
# 3D: gravity with a part across the sheet (along z), as a steady side wind.
SIDE_GRAVITY = [0.0, -9.81, 3.0]
SWITCH_AT = 1.0
FIGURES = ("fig7", "fig8", "fig9", "3d")


def out_of_plane(setup):
    """Which modes are out of the sheet's plane, from the FMU's modeOutOfPlane."""
    return np.asarray(setup["modeOutOfPlane"]) > 0.5


def in_plane_only(setup):
    return (~out_of_plane(setup)).astype(float)


def out_of_plane_only(setup):
    return out_of_plane(setup).astype(float)


def out_of_plane_doubled(setup):
    return np.where(out_of_plane(setup), 2.0, 1.0)


def every_mode(setup):
    return np.ones(setup["nModes"])


# ---- the runs ---------------------------------------------------------------


def fig7_runs(fmu):
    s = scene("paper-2d-top-row")
    return {"full": fmu.run("full space", {**s, "reduction": "full"}, STOP, STEP), "modal": fmu.run("2 lowest modes", s, STOP, STEP)}


def fig8_runs(fmu):
    s = scene("paper-2d-top-corners")
    s["nodeMass"] = HEAVIER * float(s.get("nodeMass", fmu.vars["nodeMass"].start))
    runs = {k: fmu.run(label, {**s, "nModes": r}, STOP, STEP, weights=w) for k, (label, r, w) in FIG8_SETS.items()}
    runs["full"] = fmu.run("full space", {**s, "reduction": "full"}, STOP, STEP)
    return runs


def fig9_runs(fmu):
    s = scene("paper-3d-sheet")
    return {"full": fmu.run("full space", {**s, "reduction": "full"}, STOP, STEP), "modal": fmu.run(f"all {s['nModes']} modes", s, STOP, STEP)}


def control3d_runs(fmu):
    s = {**scene("paper-3d-sheet"), "gravity": SIDE_GRAVITY}
    return {
        "full": fmu.run("full space", {**s, "reduction": "full"}, STOP, STEP),
        "every": fmu.run("every mode", s, STOP, STEP),
        "in": fmu.run("in-plane modes only", s, STOP, STEP, weights=in_plane_only),
        "out": fmu.run("out-of-plane modes only", s, STOP, STEP, weights=out_of_plane_only),
        "double": fmu.run("out-of-plane modes x 2", s, STOP, STEP, weights=out_of_plane_doubled),
        "switch": fmu.run(
            f"out-of-plane modes on at t = {SWITCH_AT:g} s", s, STOP, STEP, weights=in_plane_only, changes=[(SWITCH_AT, {"modeWeights": every_mode})]
        ),
    }


# ---- measures of the pictures -------------------------------------------------


def error(run, reference):
    """E of run against reference (docs/method.md section 6; equal masses cancel)."""
    n = len(run.times)
    return trajectory_error(run.frames.reshape(n, -1), reference.frames.reshape(n, -1), reference.start.ravel(), run.dim)


def largest_node_error(run, reference):
    n = len(run.times)
    return max_node_error(run.frames.reshape(n, -1), reference.frames.reshape(n, -1), run.dim)


def shape_distance(a, b):
    """How different two motions are whatever their sizes: the distance
    between their displacement histories x(t_k) - x(0), each scaled to unit
    norm over the run. 0: the same motion up to a factor; sqrt(2): orthogonal
    (nothing in common); 2: opposite."""
    da = (a.frames - a.start).ravel()
    db = (b.frames - b.start).ravel()
    return float(np.linalg.norm(da / np.linalg.norm(da) - db / np.linalg.norm(db)))


def largest_displacement(run, axes=slice(None)):
    """The largest distance any node moves from its start, over the given coordinates."""
    d = run.frames[..., axes] - run.start[..., axes]
    return float(np.sqrt((d**2).sum(axis=-1)).max())


def magnification(run, size=0.35):
    """A round display factor (1, 2, 5, 10, 20, ...) that shows the run's
    largest displacement at no more than `size` metres; 1 when it is already
    that large."""
    d = largest_displacement(run)
    factors = [m * 10.0**k for k in range(6) for m in (1.0, 2.0, 5.0)]
    return max([f for f in factors if d * f <= size], default=1.0)


# ---- pictures -------------------------------------------------------------------


def pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def frame(run, t, magnify=1.0):
    """The node positions at time t (a multiple of the step; 0: the start),
    the displacement from the start magnified for display."""
    x = run.start if t == 0 else run.frames[int(round(t / STEP)) - 1]
    return run.start + magnify * (x - run.start)


def draw2d(ax, run, x, colour):
    """The sheet at x over its start (grey), held nodes red."""
    from matplotlib.collections import LineCollection

    ax.add_collection(LineCollection(run.start[run.springs][..., :2], colors="0.85", linewidths=0.5))
    ax.add_collection(LineCollection(x[run.springs][..., :2], colors=colour, linewidths=0.8))
    ax.plot(x[:, 0], x[:, 1], ".", color=colour, ms=2.5)
    ax.plot(x[run.fixed, 0], x[run.fixed, 1], "s", color="tab:red", ms=3.5)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])


def draw3d(ax, run, x, colour, limits):
    """The sheet at x in perspective, y (gravity's own axis) drawn upwards and z across."""
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    view = lambda p: p[..., [0, 2, 1]]  # noqa: E731  (x, z, y): y up
    ax.add_collection3d(Line3DCollection(view(run.start[run.springs]), colors="0.85", linewidths=0.5))
    ax.add_collection3d(Line3DCollection(view(x[run.springs]), colors=colour, linewidths=0.8))
    held = view(x[run.fixed])
    ax.plot(held[:, 0], held[:, 1], held[:, 2], "s", color="tab:red", ms=2.5)
    lo, hi = limits
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[2], hi[2])
    ax.set_zlim(lo[1], hi[1])
    ax.set_box_aspect((hi[0] - lo[0], hi[2] - lo[2], hi[1] - lo[1]))
    ax.view_init(elev=18, azim=-58)
    ax.set_xticklabels([])
    ax.set_yticklabels([])
    ax.set_zticklabels([])
    ax.set_xlabel("x", labelpad=-12, fontsize=7)
    ax.set_ylabel("z", labelpad=-12, fontsize=7)
    ax.set_zlabel("y", labelpad=-12, fontsize=7)


def bounds(frames, pad=0.04):
    """Common limits (lo, hi) of every node of these position arrays."""
    pts = np.concatenate([f.reshape(-1, f.shape[-1]) for f in frames])
    lo, hi = pts.min(axis=0) - pad, pts.max(axis=0) + pad
    return lo, hi


COLOURS = ["tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown", "tab:olive"]


def sheets(path, rows, instants, title, trace=None, three_d=False):
    """A grid of pictures: one row per run (label, run, display magnification),
    one column per instant; below them, optionally, `trace(ax)` draws a
    quantity over time across the figure's width."""
    plt = pyplot()
    ncol = len(instants)
    shown = [[frame(run, t, mag) for t in instants] for _, run, mag in rows]
    lo, hi = bounds([x for row in shown for x in row])
    size = 2.3 if three_d else 1.9
    fig = plt.figure(figsize=(size * ncol + 0.6, size * len(rows) + (2.4 if trace else 0.0) + 0.5))
    grid = fig.add_gridspec(len(rows) + (1 if trace else 0), ncol, height_ratios=[1.0] * len(rows) + ([0.9] if trace else []))
    for i, ((label, run, mag), xs) in enumerate(zip(rows, shown, strict=True)):
        colour = COLOURS[i % len(COLOURS)]
        for j, (t, x) in enumerate(zip(instants, xs, strict=True)):
            if three_d:
                ax = fig.add_subplot(grid[i, j], projection="3d")
                draw3d(ax, run, x, colour, (lo, hi))
            else:
                ax = fig.add_subplot(grid[i, j])
                draw2d(ax, run, x, colour)
                ax.set_xlim(lo[0], hi[0])
                ax.set_ylim(lo[1], hi[1])
            if i == 0:
                ax.set_title(f"t = {t:g} s", fontsize=9)
            if j == 0:
                text = label + (f"\n(displacement x {mag:g})" if mag != 1 else "")
                if three_d:
                    ax.text2D(-0.12, 0.5, text, transform=ax.transAxes, rotation=90, va="center", ha="center", fontsize=8, color=colour)
                else:
                    ax.set_ylabel(text, fontsize=8, color=colour)
    if trace:
        trace(fig.add_subplot(grid[len(rows), :]))
    fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.97))
    fig.savefig(path, dpi=80)
    plt.close(fig)
    compact(path)


def bottom_row_trace(runs):
    """A drawing of the bottom row's mean y over time for each run."""

    def draw(ax):
        for i, run in enumerate(runs):
            nx = run.nx
            y = np.concatenate([[run.start[-nx:, 1].mean()], run.frames[:, -nx:, 1].mean(axis=1)])
            ax.plot(np.concatenate([[0.0], run.times]), y, color=COLOURS[i % len(COLOURS)], lw=1.2 if i else 2.2, label=run.label)
        ax.set_xlabel("t [s]")
        ax.set_ylabel("bottom row mean y [m]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)

    return draw


def animation(path, panels, title, fps=12.5, three_d=False, colours=COLOURS):
    """A GIF of the runs side by side: panels are (label, run, magnification)."""
    plt = pyplot()
    from matplotlib.animation import FuncAnimation, PillowWriter

    every = int(round(1.0 / (fps * STEP)))
    ks = list(range(0, len(panels[0][1].times) + 1, every))
    times = [k * STEP for k in ks]
    lo, hi = bounds([frame(run, t, mag) for _, run, mag in panels for t in times])
    fig = plt.figure(figsize=((3.0 if three_d else 2.8) * len(panels), 3.9))
    axs = [fig.add_subplot(1, len(panels), i + 1, **({"projection": "3d"} if three_d else {})) for i in range(len(panels))]

    def show(k):
        for i, (ax, (label, run, mag)) in enumerate(zip(axs, panels, strict=True)):
            ax.clear()
            x = frame(run, k * STEP, mag)
            if three_d:
                draw3d(ax, run, x, colours[i], (lo, hi))
            else:
                draw2d(ax, run, x, colours[i])
                ax.set_xlim(lo[0], hi[0])
                ax.set_ylim(lo[1], hi[1])
            ax.set_title(label.replace(" (", "\n(") + (f"\n(displacement x {mag:g})" if mag != 1 else ""), fontsize=8)
        fig.suptitle(f"{title}   t = {k * STEP:.2f} s", fontsize=9)
        return []

    show(ks[0])
    fig.tight_layout(rect=(0, 0, 1, 0.93))
    FuncAnimation(fig, show, frames=ks, blit=False).save(path, writer=PillowWriter(fps=fps), dpi=64)
    plt.close(fig)
    compact_gif(path)


# ---- the figures: runs, pictures, numbers -----------------------------------------


INSTANTS = [0.1, 0.2, 0.3, 0.5, 1.0, 2.0]


def against_full(runs, out, name, scene_name, three_d=False):
    """Full space against the modal run of `runs`: the picture NAME.png and
    the line of numbers (E over the run, the largest node distance)."""
    full, modal = runs["full"], runs["modal"]
    e, d = error(modal, full), largest_node_error(modal, full)
    sheets(
        os.path.join(out, f"{name}.png"),
        [("full space", full, 1.0), (modal.label, modal, 1.0)],
        INSTANTS,
        f"Fig. {name[3:]}: {scene_name}, full space against {modal.label} (E = {e:.2g} over {STOP:g} s, largest node distance {d:.2g} m)",
        trace=None if three_d else bottom_row_trace([full, modal]),
        three_d=three_d,
    )
    return [
        f"{name}: {modal.label} against full space over {STOP:g} s: E = {e:.3g}, largest node distance {d:.3g} m, "
        f"largest displacement {largest_displacement(full):.3g} m (full) / {largest_displacement(modal):.3g} m (modal)"
    ]


def fig7(fmu, out):
    return against_full(fig7_runs(fmu), out, "fig7", "paper-2d-top-row")


def fig8(fmu, out):
    runs = fig8_runs(fmu)
    sets = [(FIG8_SETS[k][0], runs[k], magnification(runs[k])) for k in "abc"]
    sheets(
        os.path.join(out, "fig8.png"),
        sets + [("full space (for comparison)", runs["full"], 1.0)],
        INSTANTS,
        f"Fig. 8: paper-2d-top-corners, nodes {HEAVIER:g}x as heavy, three sets of modes",
    )
    animation(os.path.join(out, "fig8.gif"), sets, "paper-2d-top-corners, three sets of modes")
    lines = [f"fig8: largest displacement {runs[k].label}: {largest_displacement(runs[k]):.4f} m (drawn x {sets[i][2]:g})" for i, k in enumerate("abc")]
    size = {k: largest_displacement(runs[k]) for k in "abc"}
    lines.append(f"fig8: largest displacements (a) / (b) {size['a'] / size['b']:.1f}, (b) / (c) {size['b'] / size['c']:.1f}")
    lines.append(f"fig8: largest displacement full space: {largest_displacement(runs['full']):.4f} m; E of (a) against it {error(runs['a'], runs['full']):.3f}")
    for k in "abc":
        warned = [m for status, _, m in runs[k].messages if status >= 1]
        lines.append(f"fig8: {runs[k].label}: " + (f"the FMU warned: {warned[0]}" if warned else "no warning"))
    for p, q in (("a", "b"), ("a", "c"), ("b", "c")):
        lines.append(f"fig8: shape distance ({p}) - ({q}) = {shape_distance(runs[p], runs[q]):.3f} (0: one motion up to a factor, 1.414: nothing in common)")
    return lines


def fig9(fmu, out):
    return against_full(fig9_runs(fmu), out, "fig9", "paper-3d-sheet", three_d=True)


def largest_out_of_plane(run):
    """max over time and nodes of |z - z(0)|."""
    return float(np.abs(run.frames[..., 2] - run.start[:, 2]).max())


def control3d(fmu, out):
    runs = control3d_runs(fmu)
    order = ["full", "in", "out", "double", "switch"]

    def trace(ax):
        for i, k in enumerate(order):
            r = runs[k]
            z = np.abs(r.frames[..., 2] - r.start[:, 2]).max(axis=1)
            ax.semilogy(r.times, np.maximum(z, 1e-18), color=COLOURS[i], label=r.label)
        ax.axvline(SWITCH_AT, color="0.6", ls=":", lw=1)
        ax.set_xlabel("t [s]")
        ax.set_ylabel("largest |z| of a node [m]")
        ax.set_ylim(1e-18, 1.0)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, ncol=3)

    sheets(
        os.path.join(out, "control-3d.png"),
        [(runs[k].label, runs[k], 1.0) for k in order],
        [0.25, 0.5, 1.0, 1.25, 1.5, 2.0],
        f"paper-3d-sheet under gravity {tuple(SIDE_GRAVITY)} m/s2: modes chosen by modeOutOfPlane",
        trace=trace,
        three_d=True,
    )
    animation(
        os.path.join(out, "control-3d.gif"),
        [(runs[k].label, runs[k], 1.0) for k in ("full", "in", "out", "switch")],
        f"paper-3d-sheet, gravity {tuple(SIDE_GRAVITY)}",
        three_d=True,
        colours=[COLOURS[order.index(k)] for k in ("full", "in", "out", "switch")],
    )
    k = int(round(SWITCH_AT / STEP))
    switch, inp = runs["switch"], runs["in"]
    same = bool(np.array_equal(switch.frames[:k], inp.frames[:k]))
    lines = [f"3d: every mode against full space: E = {error(runs['every'], runs['full']):.2e}"]
    lines.append(f"3d: in-plane modes: {int(in_plane_only(inp.setup).sum())} of {inp.setup['nModes']} (modeOutOfPlane < 0.5)")
    for key in order:
        r = runs[key]
        lines.append(f"3d: {r.label}: largest |z| {largest_out_of_plane(r):.2e} m, largest in-plane displacement {largest_displacement(r, slice(0, 2)):.2e} m")
    lines += [
        f"3d: out-of-plane modes x 2: E against every mode {error(runs['double'], runs['every']):.3f}",
        f"3d: out-of-plane modes switched on at t = {SWITCH_AT:g} s: the in-plane-only run bit for bit before: {same}; "
        f"largest |z| 0.1 s after: {np.abs(switch.frames[k:k + 10, :, 2]).max():.4f} m",
    ]
    return lines


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("fmu", nargs="?", default=os.path.join(ROOT, "target", "fmu", "ModalMassSpring.fmu"))
    p.add_argument("--figure", default="all", help=f"comma-separated, of {', '.join(FIGURES)}; or all (default)")
    p.add_argument("--out", default=os.path.join(ROOT, "target", "control"))
    a = p.parse_args(argv)
    names = FIGURES if a.figure == "all" else [n.strip() for n in a.figure.split(",")]
    unknown = [n for n in names if n not in FIGURES]
    if unknown:
        p.error(f"unknown figure {', '.join(unknown)} (figures: {', '.join(FIGURES)})")
    os.makedirs(a.out, exist_ok=True)
    makers = {"fig7": fig7, "fig8": fig8, "fig9": fig9, "3d": control3d}
    lines = []
    with Fmu(a.fmu) as fmu:
        for name in names:
            for line in makers[name](fmu, a.out):
                print(line, flush=True)
                lines.append(line)
    with open(os.path.join(a.out, "numbers.txt"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"pictures and numbers.txt in {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
