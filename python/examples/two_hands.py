"""Two hands hold a cloth by its top corners, each corner its own holder:
nHolders = 2 with fixedNodes = top-corners gives the left corner to holder 1
(moved by anchorX, anchorY, anchorZ; its force is anchorForce) and the right
one to holder 2 (anchor2X ..., anchor2Force). The cloth, 12 x 10 nodes with
bending springs, starts flat at rest and settles under a strong damping;
then the hands pull apart along x until it is taut (each 6 % of the width
outward over 1 s) and swing in opposite directions for 3 s, hand 1 up and
hand 2 down first, under a light damping. dampingAlpha is tunable, so it is
a column of the input table like the hands.

fmpy.simulate_fmu runs the script twice with the same input table: in a
modal basis (modeSelection = load with a static correction and, with
anchorMotion, the constraint modes of holder 2, linearized at the hanging
equilibrium) and in full space (reduction = full), the reference.

    .venv/bin/python python/examples/two_hands.py [FMU] [--modes 24] [--seconds 3] [--swing 0.08]
        [--dimension 2|3] [--set NAME=VALUE]... [--out out/two_hands.gif] [--still out/two_hands.png]

It prints the largest sag, each hand's force (the range of each component
of anchorForce and anchor2Force), their sum against the weight once the
cloth has settled, the largest distance of a node between the reduced and
the full run, and the wall times. It draws the run as a GIF (--out, '' for
none) and the instant --still-time as a PNG (--still; docs/two_hands.png is
`--still docs/two_hands.png --out ''`): the springs coloured by their
stretch over the full-space run in grey, each hand with the force it pulls
the cloth with (minus anchorForce), the script and the forces over time.

--dimension 3 swings the hands across the plane of the cloth instead (hand 1
along +z, hand 2 along -z). The reduced run does not follow that swing: the
cloth turns out of its plane far beyond what a linear basis holds (and,
hung in its plane, it buckles out of it, so the equilibrium the basis is
built at is not flat; docs/method.md, sections 3 and 7): 24, 100 and 200 of
its 354 vectors stay 0.25, 0.23 and 0.18 m from the full run, where in the
plane 24 vectors keep within 1.5 cm of it."""

import argparse
import os
import shutil
import sys
import time

import numpy as np
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi3 import FMU3Slave

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.dirname(HERE))
from pictures import compact, compact_gif  # noqa: E402  (pictures small enough for the repository)
from sheet import springs  # noqa: E402  (springNeighbours as node pairs)

H = 0.01  # communication step [s]
SETTLE, PULL, RAMP = 1.5, 1.0, 0.5  # the script: settling, pulling apart, the swing growing [s]
DAMPING = (12.0, 0.5)  # dampingAlpha while the cloth settles, and after [1/s]
HANDS = ("tab:red", "tab:blue")
PREFIXES = ("anchor", "anchor2")  # holder 1's variables, holder 2's


def smooth(s):
    """0 to 1 with zero slope at both ends, for s from 0 to 1."""
    s = np.clip(s, 0.0, 1.0)
    return s * s * (3 - 2 * s)


def script(a):
    """hands(t): the hands' displacements from their places at time t, (2, 3): hand 1, hand 2."""
    apart = a.pull * a.spacing * (a.nx - 1)
    across = 2 if a.dimension == 3 else 1  # the swing: across the plane in 3D, up and down in 2D

    def hands(t):
        ts = max(t - SETTLE - PULL, 0.0)
        swing = a.swing * smooth(ts / RAMP) * np.sin(2 * np.pi * a.frequency * ts)
        d = np.zeros((2, 3))
        d[:, 0] = np.array([-1.0, 1.0]) * apart * smooth((t - SETTLE) / PULL)
        d[:, across] = np.array([1.0, -1.0]) * swing
        return d

    return hands


def input_table(md, hands, stop):
    """Every input of the FMU (those not driven at 0, so that fmpy misses none) and dampingAlpha, on
    the output grid. The FMU takes an anchor set at a communication point as where the holder is at
    the end of the step; simulate_fmu sets the table's value at the start of each step, so row t
    holds the hands' place at t + H."""
    names = [v.name for v in md.modelVariables if v.causality == "input"]
    t = np.arange(0.0, stop + H / 2, H)
    table = np.zeros(len(t), dtype=[("time", np.float64)] + [(n, np.float64) for n in names + ["dampingAlpha"]])
    table["time"] = t
    d = np.array([hands(ti + H) for ti in t])
    for hand, prefix in enumerate(PREFIXES):
        for axis, c in enumerate("XYZ"):
            table[prefix + c] = d[:, hand, axis]
    table["dampingAlpha"] = np.where(t < SETTLE, *DAMPING)
    return table


def run(unzipped, md, start_values, table, stop):
    """One simulate_fmu run on an instance of our own, whose positions are read after each step
    (fmpy's recorder sizes arrays from modelDescription.xml, not from this run's grid)."""
    variables = {v.name: v for v in md.modelVariables}
    vr = {name: v.valueReference for name, v in variables.items()}
    n, dim = start_values["nx"] * start_values["ny"], start_values["dimension"]
    values = {k: {i.name: int(i.value) for i in variables[k].declaredType.items}[v] if isinstance(v, str) else v for k, v in start_values.items()}
    messages, frames, setup = [], [], {}
    fmu = FMU3Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier, instanceName="cloth")
    fmu.instantiate(logMessage=lambda _env, status, _category, message: messages.append((status, message.decode(errors="replace"))))

    def step_finished(_t, _recorder):
        if not setup:  # calculated parameters, known once set-up has run
            setup["pairs"] = springs(fmu.getUInt64([vr["springNeighbours"]], nValues=n * 6), n)
            setup["omega"] = fmu.getFloat64([vr["modeFrequencies"]], nValues=int(fmu.getUInt64([vr["nModes"]])[0]))
            gravity = fmu.getFloat64([vr["gravity"]], nValues=3)[:dim]
            setup["mass"] = fmu.getFloat64([vr["nodeMass"]])[0] * n
            setup["weight"] = setup["mass"] * (n - 2) / n * np.array(gravity)  # of the free nodes
        frames.append(fmu.getFloat64([vr["positions"]], nValues=n * dim))
        return True

    outputs = [f"{prefix}Force{c}" for prefix in PREFIXES for c in "XYZ"]
    t0 = time.perf_counter()
    try:
        res = simulate_fmu(unzipped, start_values=values, input=table, output=outputs, stop_time=stop, output_interval=H,
                           fmu_instance=fmu, model_description=md, step_finished=step_finished, validate=False)
    except Exception:  # what the FMU refused, and why
        for status, message in messages:
            if status > 0:
                print(f"FMU ({'warning' if status == 1 else 'error'}): {message}", file=sys.stderr)
        raise
    finally:
        fmu.freeInstance()
    wall = time.perf_counter() - t0
    forces = np.stack([np.stack([res[f"{prefix}Force{c}"] for c in "XYZ"], axis=1) for prefix in PREFIXES], axis=1)
    return dict(frames=np.array(frames).reshape(len(frames), n, dim), forces=forces[1:, :, :dim], wall=wall,
                warnings=[m for s, m in messages if s > 0], **setup)


def summary(a, runs, rest):
    """Print what the runs show; returns the largest node distance between them."""
    modal, full = runs["modal"], runs["full"]
    dim = a.dimension
    times = H * np.arange(1, len(modal["frames"]) + 1)
    settled, pulled = int(round(SETTLE / H)) - 1, int(round((SETTLE + PULL) / H)) - 1
    sag = rest[None, :, 1] - modal["frames"][:, :, 1]
    k, node = np.unravel_index(np.argmax(sag), sag.shape)
    apart = np.linalg.norm(modal["frames"] - full["frames"], axis=2).max(axis=1)
    across = ("+z", "-z") if dim == 3 else ("up", "down")
    print(f"cloth: {a.nx} x {a.ny} nodes in {dim}D, {a.spacing:g} m apart, {modal['mass']:.2f} kg, held at its top corners by two hands (nHolders = 2)")
    print(f"script: settle {SETTLE:g} s (dampingAlpha {DAMPING[0]:g} 1/s); pull apart over {PULL:g} s, each hand "
          f"{a.pull * a.spacing * (a.nx - 1):.3f} m outward ({a.pull:.0%} of the width); swing {a.seconds:g} s, {a.swing:g} m at "
          f"{a.frequency:g} Hz, hand 1 {across[0]} and hand 2 {across[1]} first (dampingAlpha {DAMPING[1]:g} 1/s)")
    print(f"modal run: {a.modes} basis vectors (load, static correction, holder 2's constraint modes; linearized at {a.linearization}), "
          f"{modal['omega'][0]:.2f} to {modal['omega'][-1]:.1f} rad/s")
    print(f"largest sag: {sag.max():.3f} m (node row {node // a.nx}, column {node % a.nx}, t = {times[k]:.2f} s); settled {sag[settled].max():.3f} m")
    for i, prefix in enumerate(PREFIXES):
        f = modal["forces"][:, i]
        ranges = ", ".join(f"{c} {f[:, j].min():+.2f} to {f[:, j].max():+.2f}" for j, c in enumerate("xyz"[:dim]))
        print(f"hand {i + 1} force ({prefix}Force): {ranges} N")
    total = modal["forces"][settled].sum(axis=0)
    print(f"settled (t = {times[settled]:.2f} s): the two forces add up to ({', '.join(f'{v:+.4f}' for v in total)}) N, "
          f"the weight of the cloth's free nodes is ({', '.join(f'{v:+.4f}' for v in modal['weight'])}) N "
          f"(a difference of {np.linalg.norm(total - modal['weight']) / np.linalg.norm(modal['weight']):.1e} of it)")
    for name, r in runs.items():
        for message in r["warnings"][:3]:
            print(f"{name} run, FMU warning: {message}")
    print(f"reduced against full: largest node distance {apart.max():.4f} m (t = {times[apart.argmax()]:.2f} s; settling "
          f"{apart[: settled + 1].max():.4f} m, pulling {apart[settled : pulled + 1].max():.4f} m, swinging {apart[pulled:].max():.4f} m), "
          f"hand forces within {np.abs(modal['forces'] - full['forces']).max():.3f} N")
    print(f"wall time: modal run {modal['wall']:.2f} s, full run {full['wall']:.2f} s")
    return float(apart.max())


class Picture:
    """The figure of one instant: the cloth (springs coloured by stretch, the full-space run in grey
    behind, each hand with the force it pulls the cloth with), what the hands do, and their forces."""

    def __init__(self, plt, a, runs, rest, hands, stop):
        from matplotlib import colormaps, colors

        self.a, self.runs, self.rest, self.dim = a, runs, rest, a.dimension
        self.pairs = runs["modal"]["pairs"]
        self.held = [0, a.nx - 1]
        self.times = np.arange(0.0, stop + H / 2, H)
        self.hands = np.array([hands(t) for t in self.times])[:, :, : self.dim]
        self.view = [0, 2, 1] if self.dim == 3 else [0, 1]  # drawn axes: y (gravity's) up, z into the picture
        frames = [self.frame(name, k) for name in runs for k in range(len(self.times))]
        pulls = [x[self.held] - a.arrow * self.force(k) for k, x in enumerate(frames[: len(self.times)])]
        pts = np.concatenate(frames + pulls)
        self.lo, self.hi = pts.min(axis=0) - 0.05, pts.max(axis=0) + 0.05
        self.length0 = np.linalg.norm(rest[self.pairs[:, 0]] - rest[self.pairs[:, 1]], axis=1)
        self.smax = float(np.percentile([self.stretch(x).max() for x in frames], 95))
        self.norm = colors.PowerNorm(0.5, vmin=0.0, vmax=100 * self.smax)  # the body's few percent apart from the corners' tens
        self.cmap = colormaps["viridis"]
        self.fig = plt.figure(figsize=(9.6, 4.8))
        self.axes = None

    def frame(self, name, k):
        """Positions at output point k (0: the start, at rest)."""
        return self.rest if k == 0 else self.runs[name]["frames"][k - 1]

    def force(self, k):
        return self.runs["modal"]["forces"][k - 1] if k > 0 else np.zeros((2, self.dim))

    def stretch(self, x):
        return np.linalg.norm(x[self.pairs[:, 0]] - x[self.pairs[:, 1]], axis=1) / self.length0 - 1.0

    def layout(self):
        from matplotlib.cm import ScalarMappable
        from matplotlib.lines import Line2D

        fig, a = self.fig, self.a
        grid = fig.add_gridspec(2, 2, width_ratios=[1.25, 1.0], hspace=0.5, wspace=0.12, left=0.02, right=0.97, top=0.86, bottom=0.16)
        sheet = fig.add_subplot(grid[:, 0], **({"projection": "3d"} if self.dim == 3 else {}))
        moves, forces = fig.add_subplot(grid[0, 1]), fig.add_subplot(grid[1, 1])
        forces.sharex(moves)
        cax = fig.add_axes([0.1, 0.085, 0.3, 0.022])
        cb = fig.colorbar(ScalarMappable(norm=self.norm, cmap=self.cmap), cax=cax, orientation="horizontal")
        cb.set_label("stretch of a spring [%]", fontsize=7, labelpad=1)
        cb.ax.tick_params(labelsize=6)
        across = "xyz"[self.view[1]]
        for i, c in enumerate(HANDS):
            moves.plot(self.times, self.hands[:, i, 0], color=c, lw=1.3)
            moves.plot(self.times, self.hands[:, i, self.view[1]], color=c, lw=1.3, ls="--")
            for axis, ls in zip(range(self.dim), ("--", "-", ":"), strict=False):
                forces.plot(self.times[1:], self.runs["modal"]["forces"][:, i, axis], color=c, lw=1.0, ls=ls)
        total = self.runs["modal"]["forces"][:, :, 1].sum(axis=1)
        forces.plot(self.times[1:], total, color="k", lw=0.8)
        forces.axhline(self.runs["modal"]["weight"][1], color="0.5", lw=0.8, ls="-.")
        moves.set_title(f"what the hands do: {PREFIXES[0]}X/{across.upper()}, {PREFIXES[1]}X/{across.upper()} [m]", fontsize=8)
        forces.set_title("force of the cloth on each hand: anchorForce, anchor2Force [N]", fontsize=8)
        forces.set_xlabel("t [s]", fontsize=7, labelpad=1)
        proxy = lambda **kw: Line2D([], [], **kw)  # noqa: E731
        moves.legend([proxy(color=HANDS[0]), proxy(color=HANDS[1]), proxy(color="k"), proxy(color="k", ls="--")],
                     ["hand 1", "hand 2", "x", across], fontsize=6, ncol=2, loc="lower left")
        entries = [(proxy(color="k", ls=ls), c) for c, ls in zip("xyz"[: self.dim], ("--", "-", ":"), strict=False)]
        entries += [(proxy(color="k", lw=0.8), "sum of y"), (proxy(color="0.5", lw=0.8, ls="-."), "weight")]
        forces.legend(*zip(*entries, strict=True), fontsize=6, ncol=len(entries), loc="upper center", bbox_to_anchor=(0.5, -0.28), frameon=False)
        cursors = []
        for ax in (moves, forces):
            ax.tick_params(labelsize=6)
            ax.grid(alpha=0.3)
            cursors.append(ax.axvline(0.0, color="0.3", lw=0.8))
        lo, hi = self.lo, self.hi
        if self.dim == 3:
            sheet.set_xlim(lo[0], hi[0])
            sheet.set_ylim(lo[2], hi[2])
            sheet.set_zlim(lo[1], hi[1])
            sheet.set_box_aspect((hi[0] - lo[0], hi[2] - lo[2], hi[1] - lo[1]), zoom=1.2)
            sheet.view_init(elev=20, azim=-50)
            for axis in (sheet.xaxis, sheet.yaxis, sheet.zaxis):
                axis.set_ticklabels([])
            sheet.set_xlabel("x", fontsize=8, labelpad=-14)
            sheet.set_ylabel("z", fontsize=8, labelpad=-14)
            sheet.set_zlabel("y", fontsize=8, labelpad=-14)
        else:
            sheet.set_xlim(lo[0], hi[0])
            sheet.set_ylim(lo[1], hi[1])
            sheet.set_aspect("equal")
            sheet.set_xticks([])
            sheet.set_yticks([])
        mode = f"modal, {a.modes} vectors (load + static correction + constraint modes)"
        fig.suptitle(f"Two hands, one cloth: nHolders = 2, fixedNodes = top-corners, {mode}; full space in grey", fontsize=9)
        self.axes = (sheet, cursors, [])

    def draw(self, k):
        """The figure at output point k: the axes are laid out once, the cloth and the hands drawn anew."""
        from matplotlib.collections import LineCollection
        from mpl_toolkits.mplot3d.art3d import Line3DCollection

        if self.axes is None:
            self.layout()
        ax, cursors, drawn = self.axes
        while drawn:
            drawn.pop().remove()
        v = self.view
        x, xf, pull = self.frame("modal", k), self.frame("full", k), -self.a.arrow * self.force(k)
        lines = Line3DCollection if self.dim == 3 else LineCollection
        drawn.append(ax.add_collection(lines(xf[self.pairs][..., v], colors="0.75", linewidths=0.7)))
        drawn.append(ax.add_collection(lines(x[self.pairs][..., v], colors=self.cmap(self.norm(100 * self.stretch(x))), linewidths=1.2)))
        for i, c in enumerate(HANDS):
            p, f = x[self.held[i]][v], pull[i][v]
            if self.dim == 3:
                drawn.append(ax.quiver(*p, *f, color=c, linewidth=2.2, arrow_length_ratio=0.2))
            else:
                arrow = dict(arrowstyle="-|>", color=c, lw=2.2, mutation_scale=14)
                drawn.append(ax.annotate("", xy=p + f, xytext=p, arrowprops=arrow, annotation_clip=False))
            drawn.extend(ax.plot(*[[q] for q in p], "o", color=c, ms=9, mec="k", mew=0.7, zorder=5))
        ax.set_title(f"t = {k * H:.2f} s; arrows: each hand's pull on the cloth, {0.1 / self.a.arrow:g} N per 10 cm", fontsize=8)
        for cursor in cursors:
            cursor.set_xdata([k * H, k * H])


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("fmu", nargs="?", default=os.path.join(ROOT, "target", "fmu", "ModalMassSpring.fmu"))
    p.add_argument("--dimension", type=int, default=2, choices=[2, 3])
    p.add_argument("--nx", type=int, default=12)
    p.add_argument("--ny", type=int, default=10)
    p.add_argument("--modes", type=int, default=24, help="basis vectors of the modal run")
    p.add_argument("--linearization", default="equilibrium", choices=["rest", "equilibrium"], help="of the modal run")
    p.add_argument("--pull", type=float, default=0.06, help="how far each hand moves outward, as a share of the width")
    p.add_argument("--swing", type=float, default=0.08, help="amplitude of the swing [m]")
    p.add_argument("--frequency", type=float, default=0.5, help="of the swing [Hz]")
    p.add_argument("--seconds", type=float, default=3.0, help="length of the swing [s]")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="another start value for both runs: a number, true or false, or an enumeration's item (auxStiffness=0.5)")
    p.add_argument("--arrow", type=float, default=0.02, help="arrow length per newton [m/N]")
    p.add_argument("--out", default=os.path.join(ROOT, "out", "two_hands.gif"), help="the GIF ('' for none)")
    p.add_argument("--still", default=os.path.join(ROOT, "out", "two_hands.png"), help="one instant as a PNG ('' for none)")
    p.add_argument("--still-time", type=float, default=4.0, help="the still's instant [s]")
    a = p.parse_args(argv)

    stop = SETTLE + PULL + a.seconds
    scene = dict(nx=a.nx, ny=a.ny, dimension=a.dimension, nHolders=2, fixedNodes="top-corners", bendingSprings=True)
    for item in a.set:
        name, value = item.split("=", 1)
        scene[name] = {"true": True, "false": False}.get(value, value)
        for number in (int, float):
            try:
                scene[name] = number(value)
                break
            except ValueError:
                pass
    solvers = {
        "modal": dict(nModes=a.modes, modeSelection="load", staticCorrection=True, anchorMotion=True, linearization=a.linearization),
        "full": dict(reduction="full"),
    }
    md = read_model_description(a.fmu)
    a.spacing = float(scene.get("spacing", next(v.start for v in md.modelVariables if v.name == "spacing")))
    hands = script(a)
    table = input_table(md, hands, stop)
    unzipped = extract(a.fmu)  # a temporary directory, removed at the end
    try:
        runs = {name: run(unzipped, md, {**solver, **scene}, table, stop) for name, solver in solvers.items()}
    finally:
        shutil.rmtree(unzipped, ignore_errors=True)
    rest = np.zeros((a.nx * a.ny, a.dimension))  # node (row, col) at (col, -row) spacings
    rest[:, 0] = a.spacing * np.tile(np.arange(a.nx), a.ny)
    rest[:, 1] = -a.spacing * np.repeat(np.arange(a.ny), a.nx)
    apart = summary(a, runs, rest)
    if not (a.out or a.still):
        return apart

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.animation import PillowWriter

    t0 = time.perf_counter()
    picture = Picture(plt, a, runs, rest, hands, stop)
    if a.still:
        picture.draw(int(round(min(a.still_time, stop) / H)))
        os.makedirs(os.path.dirname(os.path.abspath(a.still)), exist_ok=True)
        picture.fig.savefig(a.still, dpi=90)
        compact(a.still, colours=128)
        print(f"{a.still} written")
    if a.out:
        fps = 12.5
        ks = list(range(0, len(picture.times), int(round(1 / (fps * H)))))
        os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
        writer = PillowWriter(fps=fps)
        with writer.saving(picture.fig, a.out, dpi=72):  # one drawing per frame (FuncAnimation makes two)
            for k in ks:
                picture.draw(k)
                writer.grab_frame()
        compact_gif(a.out, colours=64)
        print(f"{a.out} written ({len(ks)} frames)")
    plt.close(picture.fig)
    print(f"drawing: {time.perf_counter() - t0:.1f} s")
    return apart


if __name__ == "__main__":
    main()
