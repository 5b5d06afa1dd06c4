"""Two sheets in a chain: sheet B hangs from the load node of sheet A.

    .venv/bin/python python/chain.py [FMU] [--step 0.015625] [--stop-time 3] [--out out/chain.png]
        [--coupling explicit|jacobi|aitken|iqn-ils] [--sheets default|full|modes20|modes8]
        [--tol 1e-10] [--max-iter 50] [--hold mean|end] [--reuse 8]

Both sheets are instances of the same FMU. The coupling is

    B.anchor = A.loadNode - A.loadNode(t = 0)    (B's held row follows A's load node)
    A.load   = B.anchorForce                      (B pulls on A's load node)

The masters here:

- `run_master`: a plain loop over fmpy's FMU3Slave, Jacobi (both sheets step
  from the outputs at the start of the step) or Gauss-Seidel (A steps first,
  then B's anchor is set to where A's load node ended the step, then B steps),
  or implicit (python/coupling.py: each step repeated from saved FMU states
  until B's pull and A's load node agree, accelerated by Aitken's relaxation
  or IQN-ILS);
- `fmpy_container`: the same pair packed by fmpy's `container_fmu` (Jacobi)
  and run as one FMU with `simulate_fmu`;
- `fmt_container`: the same pair packed by fmu-manipulation-toolbox's
  `fmucontainer` (Jacobi, or Gauss-Seidel A then B with `sequential`).

A container connects outputs to inputs as they are, so there B's anchor is
A's load node itself: set in Initialization Mode it places B at rest there,
and from then on B's anchor moves exactly as A.loadNode - A.loadNode(0) does
(`anchor="absolute"` makes the plain master do the same).
"""

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

import coupling

ROOT = Path(__file__).resolve().parents[1]

# The two sheets (structural and fixed parameters of each instance). B hangs
# from column 1 of A's bottom row, off A's middle, so that the pair swings
# sideways as well. Every mode is kept, so the modal basis holds the point
# load exactly.
SHEETS = {
    "A": {"nx": 5, "ny": 4, "nModes": 30, "loadColumn": 1, "springStiffness": 50.0, "nodeMass": 0.05},
    "B": {"nx": 3, "ny": 3, "nModes": 12, "springStiffness": 10.0, "nodeMass": 0.01},
}
# Both sheets: mass-proportional damping [1/s] and one internal step [s] for
# every communication step size, so runs at different steps differ only in
# the coupling.
COMMON = {"dampingAlpha": 5.0, "maxInternalStep": 2.0**-12}
# A stiff pair: 6 x 6 sheets of equal mass and stiffness, B's 1.5 kg on one
# node of A, where passing the force one step late feeds in energy at
# h = 0.01 s until the FMU discards the step (Jacobi and Gauss-Seidel).
STIFF_A = {"nx": 6, "ny": 6, "loadColumn": 2, "springStiffness": 50.0, "nodeMass": 0.05}
STIFF_B = {"nx": 6, "ny": 6, "springStiffness": 50.0, "nodeMass": 0.05}
# The pairs --sheets chooses: "default" is SHEETS; the stiff pair in full
# space (reduction = full, 2) and with 20 and 8 modes.
SHEET_SETS = {
    "default": SHEETS,
    "full": {"A": {**STIFF_A, "reduction": 2}, "B": {**STIFF_B, "reduction": 2}},
    "modes20": {"A": {**STIFF_A, "nModes": 20}, "B": {**STIFF_B, "nModes": 20}},
    "modes8": {"A": {**STIFF_A, "nModes": 8}, "B": {**STIFF_B, "nModes": 8}},
}
# Parameters of enumeration type (set with fmi3SetInt64).
ENUMERATIONS = {"reduction"}
# Couplings: explicit orders, and implicit with an acceleration (python/coupling.py).
EXPLICIT = ("jacobi", "gauss-seidel")
IMPLICIT = ("aitken", "iqn-ils")
# The coupling: (output of one sheet, input of the other).
LINKS = [("A", "loadNodeX", "B", "anchorX"), ("A", "loadNodeY", "B", "anchorY"),
         ("B", "anchorForceX", "A", "loadX"), ("B", "anchorForceY", "A", "loadY")]
# Recorded at every communication point, named "sheet.variable".
RECORDED = [f"{s}.{n}" for s in "AB" for n in
            ("loadNodeX", "loadNodeY", "anchorForceX", "anchorForceY", "kineticEnergy", "potentialEnergy",
             "loadX", "loadY", "anchorX", "anchorY")]


# Inputs the links set, and the outputs they come from.
LINKED_INPUTS = {f"{d}.{i}": f"{s}.{o}" for s, o, d, i in LINKS}


def default_fmu():
    return ROOT / "target" / "fmu" / "ModalMassSpring.fmu"


def free_mass(sheet, sheets="default"):
    """Mass of the free nodes (every row but the held top row) [kg]."""
    p = SHEET_SETS[sheets][sheet]
    return (p["ny"] - 1) * p["nx"] * p["nodeMass"]


class Sheet:
    """One instance of the FMU, its variables by name; p its parameters
    (default SHEETS[name])."""

    def __init__(self, fmu, unzipdir, md, name, p=None):
        from fmpy.fmi3 import FMU3Slave

        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.messages = []
        self.slave = FMU3Slave(guid=md.guid, unzipDirectory=unzipdir,
                               modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        self.slave.instantiate(logMessage=lambda env, status, cat, msg: self.messages.append(msg.decode()))
        self.p = p = SHEETS[name] if p is None else p
        enums = [k for k in p if k in ENUMERATIONS]
        if enums:
            self.slave.setInt64([self.vr[k] for k in enums], [p[k] for k in enums])
        ints = [k for k, v in p.items() if isinstance(v, int) and k not in ENUMERATIONS]
        floats = [k for k, v in p.items() if isinstance(v, float)] + list(COMMON)
        self.slave.setUInt64([self.vr[k] for k in ints], [p[k] for k in ints])
        self.slave.setFloat64([self.vr[k] for k in floats], [{**p, **COMMON}[k] for k in floats])

    def get(self, *names):
        return self.slave.getFloat64([self.vr[n] for n in names])

    def set(self, names, values):
        self.slave.setFloat64([self.vr[n] for n in names], list(values))

    def free(self):
        self.slave.terminate()
        self.slave.freeInstance()


class StepRefused(RuntimeError):
    """A sheet refused a communication step (fmi3Discard or fmi3Error);
    the message holds what the FMU logged last."""


def run_master(fmu, h, stop, scheme="jacobi", anchor="relative", positions=False, sheets="default", **implicit):
    """The pair with a plain master at constant communication step h.

    scheme: "jacobi" or "gauss-seidel" (A first), or implicit coupling,
    "aitken" or "iqn-ils" (python/coupling.py, options in implicit: tol,
    max_iter and those of the acceleration). sheets: a key of SHEET_SETS.
    anchor: "relative"
    (B.anchor = A.loadNode - A.loadNode(0), B starts at its own rest
    position) or "absolute" (B.anchor = A.loadNode, B starts at rest hanging
    from A's load node: what a container does). Returns {"time": ...,
    "A.loadNodeY": ..., ...} at every communication point, t = 0 included;
    with positions also "A.positions" and "B.positions" (time, ny, nx, 2);
    "A.restNode", A's load node at rest, and "messages", what the FMUs
    logged; implicit coupling adds "iterations" (evaluations per step) and
    "stats" (coupling.Stats.summary()). A refused step raises StepRefused,
    an implicit step that does not converge coupling.NotConverged.
    """
    from fmpy import extract, read_model_description
    from fmpy.fmi1 import FMICallException

    md = read_model_description(str(fmu))
    unzipdir = extract(str(fmu))
    pair = SHEET_SETS[sheets]
    a, b = Sheet(fmu, unzipdir, md, "A", pair["A"]), Sheet(fmu, unzipdir, md, "B", pair["B"])
    by_name = {"A": a, "B": b}
    try:
        p0 = np.array(a.get("loadNodeX", "loadNodeY"))
        offset = np.zeros(2) if anchor == "absolute" else p0
        if anchor == "absolute":
            b.set(["anchorX", "anchorY"], p0)
        for s in (a, b):
            s.slave.enterInitializationMode(startTime=0.0)
            s.slave.exitInitializationMode()
        rows, frames = [], []

        per_sheet = {s: [name[2:] for name in RECORDED if name[0] == s] for s in "AB"}

        def record(t):
            values = {s: dict(zip(per_sheet[s], by_name[s].get(*per_sheet[s]), strict=True)) for s in "AB"}
            rows.append([t] + [values[name[0]][name[2:]] for name in RECORDED])
            if positions:
                frames.append([positions_of(by_name[s], s) for s in "AB"])

        def exchange_load():
            a.set(["loadX", "loadY"], b.get("anchorForceX", "anchorForceY"))

        def exchange_anchor():
            b.set(["anchorX", "anchorY"], np.array(a.get("loadNodeX", "loadNodeY")) - offset)

        # Inputs are recorded as the master has set them for the next step,
        # as a container shows them.
        exchange_load()
        exchange_anchor()
        record(0.0)
        if scheme in IMPLICIT:
            acc, settings, stats = implicit_setup(scheme, implicit)
        elif scheme not in EXPLICIT:
            raise ValueError(f"unknown scheme {scheme}")
        for k in range(int(round(stop / h))):
            t = k * h
            try:
                if scheme in IMPLICIT:
                    coupling.implicit_step(a, b, t, h, offset, acc, stats, **settings)
                    # B's force at the end of the step predicts A's load over the next
                    exchange_load()
                else:
                    explicit_step(a, b, t, h, scheme, exchange_load, exchange_anchor)
            except FMICallException as e:
                said = (a.messages + b.messages)[-1:] or [str(e)]
                raise StepRefused(f"{scheme} chain, step from t = {t:g} s by {h:g} s: {said[0]}") from e
            record((k + 1) * h)
    finally:
        a.free()
        b.free()
        shutil.rmtree(unzipdir, ignore_errors=True)
    out = {"time": np.array([r[0] for r in rows])}
    for j, name in enumerate(RECORDED):
        out[name] = np.array([r[j + 1] for r in rows])
    if positions:
        for i, s in enumerate("AB"):
            out[f"{s}.positions"] = np.array([f[i] for f in frames])
    out["A.restNode"] = p0
    out["messages"] = a.messages + b.messages
    if scheme in IMPLICIT:
        out["iterations"] = np.array(stats.iterations)
        out["stats"] = stats.summary()
    return out


def implicit_setup(scheme, options):
    """(acceleration, settings of coupling.implicit_step, stats) of an
    implicit coupling: tol, max_iter and hold from options, the rest of them
    for the acceleration (initial, reuse, drop)."""
    settings = {k: options[k] for k in ("tol", "max_iter", "hold") if k in options}
    rest = {k: v for k, v in options.items() if k not in settings}
    return coupling.accelerator(scheme, **rest), settings, coupling.Stats()


def explicit_step(a, b, t, h, scheme, exchange_load, exchange_anchor):
    """One step of an explicit master: Jacobi or Gauss-Seidel (A first)."""
    if scheme == "jacobi":
        a.slave.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        b.slave.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        exchange_load()
        exchange_anchor()
    else:
        a.slave.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        exchange_anchor()
        b.slave.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        exchange_load()


def positions_of(sheet, name):
    nx, ny = sheet.p["nx"], sheet.p["ny"]
    return np.array(sheet.slave.getFloat64([sheet.vr["positions"]], nValues=nx * ny * 2)).reshape(ny, nx, 2)


def total_energy(r):
    """Mechanical energy of the pair at every communication point [J].

    Each sheet reports kinetic energy and potential energy (springs, gravity
    and its point load, relative to its rest state). A's point load is B's
    pull, an internal force of the pair, whose energy B's outputs already
    hold: its potential -f . (x - x(0)) is taken out of A's again. What is
    left is kinetic + elastic + gravitational energy of both sheets.
    """
    e = sum(r[f"{s}.kineticEnergy"] + r[f"{s}.potentialEnergy"] for s in "AB")
    for axis in "XY":
        e = e + r[f"A.load{axis}"] * (r[f"A.loadNode{axis}"] - r[f"A.loadNode{axis}"][0])
    return e


def _container_variables(md):
    """(name, type, causality, variability, start, targets) of the container's variables."""
    rows = []
    for s, p in SHEETS.items():
        for k, v in p.items():
            rows.append((f"{s}.{k}", "UInt64" if isinstance(v, int) else "Float64", "parameter", "fixed", v, [(s, k)]))
    for k, v in COMMON.items():
        variability = {v.name: v.variability for v in md.modelVariables}[k]
        rows.append((k, "Float64", "parameter", variability, v, [("A", k), ("B", k)]))
    for name in RECORDED:
        rows.append((name, "Float64", "output", "continuous", None, [(name[0], name[2:])]))
    return rows


def fmpy_container(fmu, h, path):
    """The pair as one FMU made by fmpy's container_fmu (fmpy 0.3.32):
    fixedInternalStepSize h, Jacobi. Returns path."""
    from fmpy import read_model_description
    from fmpy.container_fmu.cli import create_container_fmu
    from fmpy.container_fmu.config import Component, Configuration, Connection
    from fmpy.model_description import CoSimulation, DefaultExperiment, ModelDescription, ModelVariable

    fmu = Path(fmu).resolve()
    md = read_model_description(str(fmu))
    var = {v.name: v for v in md.modelVariables}
    comps = {s: Component(name=s, filename=fmu, modelDescription=md) for s in "AB"}
    variables = [ModelVariable(type="Float64", variability="continuous", causality="independent", name="time")]
    mappings = {}
    for name, typ, causality, variability, start, targets in _container_variables(md):
        v = ModelVariable(name=name, type=typ, causality=causality, variability=variability,
                          start=None if start is None else repr(start),
                          initial="calculated" if causality == "output" else None)
        variables.append(v)
        mappings[v] = [(comps[s], var[n]) for s, n in targets]
    container_md = ModelDescription(fmiVersion="3.0", modelName="Chain", instantiationToken="chain",
                                    defaultExperiment=DefaultExperiment(stopTime="3", stepSize=repr(h)),
                                    coSimulation=CoSimulation(fixedInternalStepSize=h), modelVariables=variables)
    connections = [Connection(comps[s], [var[o]], comps[d], [var[i]]) for s, o, d, i in LINKS]
    config = Configuration(parallelDoStep=False, modelDescription=container_md, components=list(comps.values()),
                           connections=connections, variableMappings=mappings)
    # create_container_fmu empties the directory it is given
    with tempfile.TemporaryDirectory() as work:
        create_container_fmu(config, Path(work), Path(path))
    return path


def fmt_container(fmu, h, directory, sequential=False):
    """The pair as one FMU made by fmu-manipulation-toolbox's fmucontainer
    (FMI 3.0 interface, internal step h): Jacobi, or Gauss-Seidel A then B
    with sequential. Returns the path of the container."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    # it names embedded FMUs by file name: one file per instance
    for s in "AB":
        (directory / f"{s}.fmu").write_bytes(Path(fmu).read_bytes())
    lines = ["rule;from_fmu;from_port;to_fmu;to_port", "FMU;A.fmu;;;", "FMU;B.fmu;;;"]
    lines += [f"LINK;{s}.fmu;{o};{d}.fmu;{i}" for s, o, d, i in LINKS]
    for s, p in SHEETS.items():
        lines += [f"START;{s}.fmu;{k};{v!r};" for k, v in {**p, **COMMON}.items()]
    # it exposes outputs of the embedded FMUs only (an input as output is refused)
    from fmpy import read_model_description

    causality = {v.name: v.causality for v in read_model_description(str(fmu)).modelVariables}
    lines += [f"OUTPUT;{name[0]}.fmu;{name[2:]};;{name}" for name in RECORDED if causality[name[2:]] == "output"]
    name = "chain_sequential" if sequential else "chain"
    (directory / f"{name}.csv").write_text("\n".join(lines) + "\n")
    cmd = [sys.executable, "-m", "fmu_manipulation_toolbox.cli.fmucontainer", "-container", f"{name}.csv:{h!r}",
           "-fmi", "3", "-fmu-directory", str(directory), "-no-auto-input", "-no-auto-output", "-no-auto-link"]
    if sequential:
        cmd.append("-sequential")
    done = subprocess.run(cmd, cwd=directory, capture_output=True, text=True)
    path = directory / f"{name}.fmu"
    if done.returncode != 0 or not path.exists():
        raise RuntimeError(f"{' '.join(cmd)} failed ({done.returncode}):\n{done.stdout}\n{done.stderr}")
    return path


def run_container(path, h, stop):
    """simulate_fmu on a container, output every communication step; the
    same names as run_master. Log messages in "messages"."""
    from fmpy import simulate_fmu

    messages = []
    from fmpy import read_model_description

    names = {v.name for v in read_model_description(str(path)).modelVariables}
    res = simulate_fmu(str(path), stop_time=stop, output_interval=h, output=[n for n in RECORDED if n in names],
                       logger=lambda env, status, cat, msg: messages.append((status, cat.decode(), msg.decode())))
    out = {name: np.asarray(res[name]) for name in res.dtype.names}
    for name, source in LINKED_INPUTS.items():
        # the container sets each linked input to its source at every communication point
        if source in out:
            out.setdefault(name, out[source])
    out["messages"] = messages
    return out


def plot(r, path, sheets="default"):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    t = r["time"]
    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    # the sheets at rest, at B's lowest point and at the end; B drawn hanging
    # from A's load node, centred under it
    ax = axes[0]
    dx = -(SHEET_SETS[sheets]["B"]["nx"] - 1) / 2 * 0.1
    lowest = int(np.argmin(r["B.loadNodeY"]))
    frames = [(0, ":", 0.5), (lowest, "--", 0.7), (len(t) - 1, "-", 1.0)]
    for k, style, alpha in frames:
        for s, colour in (("A", "C0"), ("B", "C1")):
            x = r[f"{s}.positions"][k].copy()
            if s == "B":
                x[..., 0] += r["A.restNode"][0] + dx
                x[..., 1] += r["A.restNode"][1]
            ax.plot(x[..., 0], x[..., 1], style, color=colour, alpha=alpha, lw=0.9)
            ax.plot(x[..., 0].T, x[..., 1].T, style, color=colour, alpha=alpha, lw=0.9)
    ax.legend([Line2D([], [], ls=style, color="k") for _, style, _ in frames],
              [f"t = {t[k]:.2f} s" for k, _, _ in frames], fontsize=8, loc="lower right")
    ax.set_aspect("equal")
    ax.set_title("A (blue) holding B (orange)")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax = axes[1]
    ax.plot(t, r["A.loadNodeY"] - r["A.loadNodeY"][0], label="A's load node")
    ax.plot(t, r["B.loadNodeY"] - r["B.loadNodeY"][0], label="B's load node")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("y displacement [m]")
    twin = ax.twinx()
    twin.plot(t, -r["A.loadY"], color="C2", lw=0.8, label="B's pull on A [N]")
    twin.set_ylabel("B's pull on A [N]")
    lines = ax.get_lines() + twin.get_lines()
    ax.legend(lines, [line.get_label() for line in lines], fontsize=8, loc="lower right")
    ax = axes[2]
    ax.semilogy(t[1:], (r["A.kineticEnergy"] + r["B.kineticEnergy"])[1:], label="kinetic")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("kinetic energy [J]")
    twin = ax.twinx()
    twin.plot(t, total_energy(r), color="C3", label="kinetic + potential")
    twin.set_ylabel("energy of the pair [J]")
    lines = ax.get_lines() + twin.get_lines()
    ax.legend(lines, [line.get_label() for line in lines], fontsize=8, loc="upper right")
    ax.set_title(f"damping {COMMON['dampingAlpha']:g} 1/s")
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("fmu", nargs="?", default=str(default_fmu()))
    ap.add_argument("--step", type=float, default=2.0**-6, help="communication step [s]")
    ap.add_argument("--stop-time", type=float, default=3.0)
    ap.add_argument("--out", default=str(ROOT / "out" / "chain.png"))
    ap.add_argument("--coupling", choices=["explicit", "jacobi", *IMPLICIT], default="explicit",
                    help="explicit (Gauss-Seidel, A first), jacobi, or implicit with Aitken's relaxation or IQN-ILS")
    ap.add_argument("--sheets", choices=list(SHEET_SETS), default="default",
                    help="the pair: default (5x4 and 3x3, every mode), or the stiff 6x6 pair in full space, "
                         "with 20 or with 8 modes")
    ap.add_argument("--tol", type=float, default=1e-10, help="implicit: relative tolerance on the interface residual")
    ap.add_argument("--max-iter", type=int, default=50, help="implicit: iterations per step at most")
    ap.add_argument("--hold", choices=["mean", "end"], default="mean",
                    help="implicit: A's load over a step is the mean of B's pull at its ends, or the pull at its end")
    ap.add_argument("--reuse", type=int, default=8, help="IQN-ILS: earlier steps whose columns are reused")
    args = ap.parse_args(argv)
    if args.max_iter < 1 or not args.tol > 0.0 or args.reuse < 0:
        ap.error("--max-iter must be at least 1, --tol above 0, --reuse not negative")
    scheme = "gauss-seidel" if args.coupling == "explicit" else args.coupling
    implicit = {}
    if scheme in IMPLICIT:
        implicit = {"tol": args.tol, "max_iter": args.max_iter, "hold": args.hold}
        if scheme == "iqn-ils":
            implicit["reuse"] = args.reuse
    try:
        r = run_master(args.fmu, args.step, args.stop_time, scheme=scheme, positions=True, sheets=args.sheets,
                       **implicit)
    except (StepRefused, coupling.NotConverged) as e:
        sys.exit(f"chain.py: {e}")
    e = total_energy(r)
    print(f"chain ({args.sheets} sheets), {scheme}, h = {args.step} s: at t = {r['time'][-1]:.2f} s A's load node sags "
          f"{r['A.loadNodeY'][0] - r['A.loadNodeY'][-1]:.4f} m, B pulls with {-r['A.loadY'][-1]:.4f} N "
          f"(B's weight {free_mass('B', args.sheets) * 9.81:.4f} N), energy {e[-1]:.5f} J")
    if scheme in IMPLICIT:
        st = r["stats"]
        print(f"iterations per step: mean {st['mean_iterations']:.2f}, max {st['max_iterations']} "
              f"({st['steps']} steps); fmi3GetFMUState {st['save_us']:.1f} us, fmi3SetFMUState "
              f"{st['restore_us']:.1f} us per sheet (median), {100 * st['state_share']:.1f} % of the time of a step "
              f"({st['step_ms']:.3f} ms, median)")
    plot(r, args.out, args.sheets)
    print(f"plot: {args.out}")


if __name__ == "__main__":
    main()
