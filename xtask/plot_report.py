"""Plots of the error-against-run-time study, one figure per scene: error
(E over the window up to the scene's predictability horizon, `error_window`)
against run time (log-log; full space in black, modal runs coloured by
variant, marker by integrator), error against the number of modes (explicit
and trigonometric runs at the shortest and longest step, coloured by variant) and error against
the largest forceResidual of each modal run (coloured by variant; Spearman's
rank correlation in the title). force_residual.png: E against the largest and
the mean forceResidual of the leave-out runs of every scene. adaptive_estimate.png:
each adaptive run's errorEstimate against its E (over the window and over the
whole run), with the bounds it is held to."""
import csv
import os
import sys
from collections import defaultdict

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt

# Spearman's rank correlation from the repository's one Python copy of the measures.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "python"))
from measures import spearman  # noqa: E402

rows = list(csv.DictReader(open(sys.argv[1])))
out = sys.argv[2]

# Colours by variant, in the order of examples/report.rs; others cycle.
VARIANTS = ["paper", "load", "load+static", "load+static@equilibrium", "load+cubature",
            "load+static+cubature", "load+static@equilibrium+cubature"]
PALETTE = plt.get_cmap("tab10").colors
COLOUR = {v: PALETTE[i % len(PALETTE)] for i, v in enumerate(VARIANTS)}
MARKER = {"newmark-explicit": "o", "newmark-implicit": "^", "trigonometric": "D"}


def variant(r):
    return r.get("variant") or ("full" if r["method"] == "full" else "paper")


def colour(v):
    if v == "full":
        return "black"
    if v not in COLOUR:
        COLOUR[v] = PALETTE[len(COLOUR) % len(PALETTE)]
    return COLOUR[v]


def f(r, column):
    try:
        return float(r.get(column) or "nan")
    except ValueError:
        return float("nan")


def e(r):
    """The headline E: over the window (older CSVs: the resolved window)."""
    return f(r, "error_window") if "error_window" in r else f(r, "error_resolved")


def label(ax, xlabel, title, ylabel="trajectory error E over the window"):
    """Axis labels, title, grid and legend of one panel."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)


def save(fig, name):
    fig.tight_layout()
    fig.savefig(f"{out}/{name}.png", dpi=90)
    plt.close(fig)


def leaves_out(r):
    return r["method"] == "modal" and int(r["modes"]) < int(r["dofs"])


by_scene = defaultdict(list)
for r in rows:
    if r["stable"] == "true" and e(r) > 0:
        by_scene[r["scene"]].append(r)

for scene, rs in by_scene.items():
    fig, (a, b, c) = plt.subplots(1, 3, figsize=(18, 5.5))
    series = defaultdict(list)
    for r in rs:
        series[(variant(r), r["integrator"])].append(r)
    order = {v: i for i, v in enumerate(["full"] + VARIANTS)}
    for (v, integ), pts in sorted(series.items(), key=lambda kv: (order.get(kv[0][0], 99), kv[0][1])):
        marker = "s" if v == "full" else "*" if v == "adaptive" else MARKER.get(integ, "o")
        a.loglog([f(p, "run_s_per_sim_s") for p in pts], [e(p) for p in pts], marker, color=colour(v),
                 label=f"{v} {integ.replace('newmark-', '')}", alpha=0.75, markersize=10 if v == "adaptive" else 5,
                 markerfacecolor="none" if integ == "newmark-implicit" else colour(v))
    modal = [r for r in rs if r["method"] == "modal" and r["integrator"] in ("newmark-explicit", "trigonometric")]
    steps = sorted({r["step_label"] for r in modal}, key=lambda s: float(s.split("/")[1]) if "/" in s else 0)
    shown = [steps[-1], steps[0]] if len(steps) > 1 else steps
    for v in [v for v in VARIANTS if any(variant(r) == v for r in modal)] + sorted({variant(r) for r in modal} - set(VARIANTS)):
        for k, step in enumerate(shown):
            for integ in ("newmark-explicit", "trigonometric"):
                sp = sorted((p for p in modal if variant(p) == v and p["step_label"] == step and p["integrator"] == integ),
                            key=lambda p: int(p["modes"]))
                if sp:
                    trig = integ == "trigonometric"
                    b.loglog([int(p["modes"]) for p in sp], [e(p) for p in sp],
                             ("D" if trig else "o" if k == 0 else "s") + (":" if trig else "-" if k == 0 else "--"), color=colour(v),
                             label=f"{v} {integ.replace('newmark-', '')} step {step}", alpha=0.8, markersize=4)
    fr = [r for r in rs if leaves_out(r) and np.isfinite(f(r, "force_residual_max"))]
    for v in sorted({variant(r) for r in fr}, key=lambda v: order.get(v, 99)):
        pts = [r for r in fr if variant(r) == v and f(r, "force_residual_max") > 0]
        c.loglog([f(p, "force_residual_max") for p in pts], [e(p) for p in pts], "o", color=colour(v), label=v, alpha=0.7, markersize=5)
    rho = spearman([f(r, "force_residual_max") for r in fr], [e(r) for r in fr])
    a.set_xlabel("run time per simulated second (s)")
    a.set_ylabel("trajectory error E over the window")
    a.set_title(f"{scene}: error against run time")
    a.legend(fontsize=6, ncol=2)
    b.set_xlabel("modes kept r")
    b.set_ylabel("trajectory error E over the window")
    b.set_title(f"{scene}: error against modes (explicit, trigonometric)")
    b.legend(fontsize=6, ncol=2)
    c.set_xlabel("largest forceResidual over the run")
    c.set_ylabel("trajectory error E over the window")
    c.set_title(f"{scene}: E against forceResidual (Spearman {rho:.2f})")
    c.legend(fontsize=6)
    for ax in (a, b, c):
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(f"{out}/{scene}.png", dpi=90)
    plt.close(fig)

# forceResidual against E, every scene.
fig, axes = plt.subplots(1, 2, figsize=(13, 5.5))
cmap = plt.get_cmap("tab10").colors
for ax, column, name in zip(axes, ["force_residual_max", "force_residual_mean"], ["largest", "mean"], strict=True):
    xs, ys = [], []
    for i, (scene, rs) in enumerate(by_scene.items()):
        pts = [r for r in rs if leaves_out(r) and np.isfinite(f(r, column))]
        x, y = [f(p, column) for p in pts], [e(p) for p in pts]
        xs += x
        ys += y
        ax.loglog([a for a in x if a > 0], [b for a, b in zip(x, y, strict=True) if a > 0], "o", color=cmap[i % len(cmap)], alpha=0.6, markersize=4,
                  label=f"{scene} (ρ = {spearman(x, y):.2f}, {len(x)} runs)")
    label(ax, f"{name} forceResidual over the run", f"E against the {name} forceResidual, leave-out runs (Spearman {spearman(xs, ys):.2f})")
save(fig, "force_residual")

# The adaptive runs' estimate against E.
adaptive = [r for rs in by_scene.values() for r in rs if r["method"] == "adaptive"]
if adaptive:
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.5))
    for ax, (error, estimate, name) in zip(axes, [("error_window", "estimate_window", "over the window"),
                                                  ("error", "error_estimate", "over the whole run")], strict=True):
        pts = [(f(r, error), f(r, estimate), r) for r in adaptive if f(r, error) > 0 and f(r, estimate) > 0]
        for i, scene in enumerate(sorted({r["scene"] for _, _, r in pts})):
            sp = [(x, y) for x, y, r in pts if r["scene"] == scene]
            ax.loglog([x for x, _ in sp], [y for _, y in sp], "o", color=cmap[i % len(cmap)], label=scene, markersize=6)
        if pts:
            lo = min(min(x, y) for x, y, _ in pts) / 3
            hi = max(max(x, y) for x, y, _ in pts) * 3
            line = np.array([lo, hi])
            ax.loglog(line, line, "k-", lw=0.8, label="estimate = E")
            ax.loglog(line, line / 3, "k:", lw=0.8, label="E / 3 and 3 E")
            ax.loglog(line, line * 3, "k:", lw=0.8)
        label(ax, f"E {name}", f"adaptive runs: estimate against E {name}", ylabel="errorEstimate at the same time")
    save(fig, "adaptive_estimate")
