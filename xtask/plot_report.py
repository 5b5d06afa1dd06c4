"""Plots of the error-against-run-time study: error against run time
(log-log, one series per method and integrator) and error against the number
of modes, one figure per scene."""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

rows = list(csv.DictReader(open(sys.argv[1])))
out = sys.argv[2]
by_scene = defaultdict(list)
for r in rows:
    if r["stable"] == "true" and float(r["error"]) > 0:
        by_scene[r["scene"]].append(r)

for scene, rs in by_scene.items():
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 5))
    series = defaultdict(list)
    for r in rs:
        series[(r["method"], r["integrator"])].append(r)
    for (method, integ), pts in sorted(series.items()):
        a.loglog([float(p["run_s_per_sim_s"]) for p in pts], [float(p["error"]) for p in pts], "o" if method == "modal" else "s", label=f"{method} {integ}", alpha=0.7)
        if method == "modal":
            for step in sorted({p["step_label"] for p in pts}):
                sp = sorted((p for p in pts if p["step_label"] == step), key=lambda p: int(p["modes"]))
                b.loglog([int(p["modes"]) for p in sp], [float(p["error"]) for p in sp], "o-", label=f"{integ} step {step}")
    a.set_xlabel("run time per simulated second (s)")
    a.set_ylabel("trajectory error E")
    a.set_title(f"{scene}: error against run time")
    a.legend(fontsize=8)
    a.grid(True, which="both", alpha=0.3)
    b.set_xlabel("modes kept r")
    b.set_ylabel("trajectory error E")
    b.set_title(f"{scene}: error against modes")
    b.legend(fontsize=7)
    b.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(f"{out}/{scene}.png", dpi=90)
    plt.close(fig)
