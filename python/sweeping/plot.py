"""The plots of a sweep: the summary numbers against the swept parameters,
and E over the predictability window against run time when a reference run
was compared."""

import math
import os

from .output import cell

PLOTTED = [
    ("meanSag", "bottom row's sag, time-averaged over the run [m]"),
    ("maxKineticEnergy", "largest kinetic energy [J]"),
    ("maxSag", "bottom row's largest sag over the run [m]"),
    ("wallTime", "wall time of the run [s]"),
]


def plot(path, rows, axes, title):
    """One panel per summary number against the first swept parameter that
    takes more than one number (else the first that takes more than one
    value), one line per combination of the others."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    varying = [(n, v) for n, v in axes if len(v) > 1]

    def is_number(v):
        return isinstance(v, (int, float)) and not isinstance(v, bool)

    varying.sort(key=lambda axis: not all(is_number(v) for v in axis[1]))  # stable: numbers first
    if varying:
        xname, xvalues = varying[0]
    else:
        xname, xvalues = "run", list(range(len(rows)))
    others = [n for n, _ in varying[1:]]
    numeric = all(is_number(v) for v in xvalues)
    labels = [cell(v) for v in xvalues]

    def xpos(row):
        value = row[xname]
        return value if numeric else labels.index(cell(value))

    series = {}
    for r in rows:
        series.setdefault(tuple(cell(r[n]) for n in others), []).append(r)
    fig, panels = plt.subplots(2, 2, figsize=(11, 7.5), sharex=True)
    for ax, (metric, ylabel) in zip(panels.flat, PLOTTED, strict=True):
        for key, rs in series.items():
            ok = sorted((r for r in rs if r["status"] in ("ok", "warning") and not math.isnan(r[metric])), key=xpos)
            label = ", ".join(f"{n}={k}" for n, k in zip(others, key, strict=True)) or None
            ax.plot([xpos(r) for r in ok], [r[metric] for r in ok], "o-", ms=4, label=label)
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3)
        if numeric and min(xvalues) > 0 and max(xvalues) >= 10 * min(xvalues):
            ax.set_xscale("log")
    for ax in panels[1]:
        ax.set_xlabel(xname)
        if not numeric:
            ax.set_xticks(range(len(labels)), labels)
    if others and len(series) <= 12:
        panels[0, 0].legend(fontsize=8)
    refused = [r for r in rows if r["status"] not in ("ok", "warning")]
    fig.suptitle(title + (f"\n{len(refused)} of {len(rows)} runs refused (their messages are in the CSV)" if refused else ""))
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)


def plot_error(path, rows, title):
    """Error against run time: E over the predictability window [0, T_p]
    (E_window; the whole run when the scene has no horizon) of every
    completed run of the grid against its wall time, and the twins' E over
    the same window, the floor below which the scene itself decides."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    done = [r for r in rows if isinstance(r["run"], int) and not math.isnan(r["E_window"]) and r["E_window"] > 0]
    ref = rows[-1]
    horizon, floor = ref.get("horizon", math.nan), ref.get("twinsE_window", math.nan)
    window = "the whole run (no predictability horizon)" if math.isnan(horizon) else f"[0, T_p = {horizon:g} s] (predictability horizon)"
    fig, ax = plt.subplots(figsize=(7, 5))
    ax.loglog([r["wallTime"] for r in done], [r["E_window"] for r in done], "o")
    for r in done:
        ax.annotate(str(r["run"]), (r["wallTime"], r["E_window"]), fontsize=7, xytext=(3, 3), textcoords="offset points")
    if floor > 0:
        ax.axhline(floor, color="0.5", ls="--", lw=1, label="twins' E over the window (floor)")
        ax.legend(fontsize=8)
    ax.set_xlabel("wall time of the run [s]")
    ax.set_ylabel("E against the reference over " + ("the whole run" if math.isnan(horizon) else "[0, T_p]"))
    ax.grid(alpha=0.3, which="both")
    ax.set_title(f"{title}\nE over {window}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
