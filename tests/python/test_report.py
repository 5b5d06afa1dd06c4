"""Checks of the error-against-run-time study in quick mode
(`cargo xtask report --quick`), which `cargo xtask test` runs first and
points to with MMS_REPORT_DIR."""
import csv
import math
import os
from pathlib import Path

import pytest

COLUMNS = ["scene", "method", "integrator", "modes", "step", "internal_steps", "setup_s",
           "run_s_per_sim_s", "error", "max_node_error", "stable"]


@pytest.fixture(scope="module")
def rows():
    folder = os.environ.get("MMS_REPORT_DIR")
    if not folder:
        pytest.fail("MMS_REPORT_DIR is not set: run through `cargo xtask test`, which makes the quick report")
    path = Path(folder) / "error_vs_runtime.csv"
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        assert reader.fieldnames[:len(COLUMNS)] == COLUMNS
        return list(reader)


def test_every_way_of_running_is_there(rows):
    for scene in {r["scene"] for r in rows}:
        rs = [r for r in rows if r["scene"] == scene]
        for integrator in ("newmark-explicit", "newmark-implicit"):
            assert any(r["method"] == "full" and r["integrator"] == integrator for r in rs)
            modes = {int(r["modes"]) for r in rs if r["method"] == "modal" and r["integrator"] == integrator}
            assert {1, 2, 4, 8} <= modes, (scene, integrator, modes)
        assert {r["method"] for r in rs} == {"modal", "full"}


def test_stable_runs_have_finite_errors_and_times(rows):
    stable = [r for r in rows if r["stable"] == "true"]
    assert len(stable) >= len(rows) * 0.9
    for r in stable:
        for column in ("error", "max_node_error", "run_s_per_sim_s", "setup_s"):
            assert math.isfinite(float(r[column])), (r, column)
        assert float(r["error"]) >= 0
        assert int(r["internal_steps"]) >= 1
    for r in rows:
        assert r["stable"] in ("true", "false")
        if r["stable"] == "false":
            assert r["note"], r


def test_all_modes_modal_matches_full_space_to_round_off(rows):
    all_modes = [r for r in rows if r["method"] == "modal" and r["modes"] == r["dofs"]]
    assert len(all_modes) >= 4
    for r in all_modes:
        assert float(r["vs_full"]) < 1e-10, r
        full = next(f for f in rows if f["method"] == "full" and f["scene"] == r["scene"]
                    and f["integrator"] == r["integrator"] and f["step"] == r["step"] and not f["note"])
        assert float(r["error"]) == pytest.approx(float(full["error"]), rel=1e-8)


def test_report_readme_and_plots(rows):
    folder = Path(os.environ["MMS_REPORT_DIR"])
    text = (folder / "README.md").read_text()
    for scene in {r["scene"] for r in rows}:
        assert f"## {scene}" in text
        assert (folder / f"{scene}.png").stat().st_size > 10_000
    assert "Pareto front" in text and "Speed-up" in text
