"""Parameter sweeps (python/sweep.py): a sweep on a LocalCluster of two worker
processes on the loopback interface gives the serial sweep's numbers bit for
bit; refused configurations are rows with their error; the command line
writes the CSV and the plot, also through --scheduler."""

import csv
import math
import os
import subprocess
import sys
import time

import numpy as np
import pytest
from fmpy import read_model_description

from conftest import ROOT

sys.path.insert(0, str(ROOT / "python"))
import sweep  # noqa: E402

distributed = pytest.importorskip("distributed", reason="dask.distributed is installed by cargo xtask setup")

STOP = 0.3
# 6 runs: two stiffnesses and an out-of-range one, two numbers of modes.
GRID = ["springStiffness=50,200,-1", "nModes=2,4"]


def deterministic(rows):
    """The rows without the columns that may differ between executions;
    floats as their exact repr, so that NaN equals NaN and nothing is rounded."""
    return [{k: sweep.cell(v) for k, v in r.items() if k not in sweep.NONDETERMINISTIC} for r in rows]


@pytest.fixture(scope="module")
def md(default_fmu):
    return read_model_description(default_fmu)


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None)
    c = distributed.Client(cluster)
    c.wait_for_workers(2)
    yield c
    c.close()
    cluster.close()


@pytest.fixture(scope="module")
def sweeps(default_fmu, md, client):
    """The same sweep serially and on the cluster, with their wall times."""
    axes = sweep.parse_grid(md, GRID)
    t0 = time.perf_counter()
    serial = sweep.run_sweep(default_fmu, axes, stop_time=STOP, progress=False)
    t1 = time.perf_counter()
    on_cluster = sweep.run_sweep(default_fmu, axes, stop_time=STOP, client=client, progress=False)
    t2 = time.perf_counter()
    print(f"\nsweep of {len(serial)} runs: serial {t1 - t0:.2f} s, 2 workers {t2 - t1:.2f} s")
    return axes, serial, on_cluster


def test_grid_from_the_command_line(md):
    axes = sweep.parse_grid(
        md, ["springStiffness=100,200", "nModes=4,8", "modeSelection=load,1", "staticCorrection=true,false", "step=0.01", "gravity=0 -9.81 0,2 -9.81 0"]
    )
    assert axes == [
        ("springStiffness", [100.0, 200.0]),
        ("nModes", [4, 8]),
        ("modeSelection", ["load", "lowest"]),
        ("staticCorrection", [True, False]),
        ("step", [0.01]),
        ("gravity", [[0.0, -9.81, 0.0], [2.0, -9.81, 0.0]]),
    ]
    points = sweep.grid_points(axes)
    assert len(points) == 2 * 2 * 2 * 2 * 2
    assert points[0]["springStiffness"] == 100.0 and points[-1]["gravity"] == [2.0, -9.81, 0.0]
    assert len({tuple(map(str, p.values())) for p in points}) == len(points)
    bad_grids = (["positions=1"], ["noSuchParameter=1"], ["modeSelection=nearest"], ["staticCorrection=maybe"])
    bad_grids += (["step=0"], ["nModes"], ["nModes=2", "nModes=4"])
    for bad in bad_grids:
        with pytest.raises(ValueError):
            sweep.parse_grid(md, bad)


def test_cluster_gives_the_serial_numbers(sweeps):
    axes, serial, on_cluster = sweeps
    assert len(serial) == len(on_cluster) == 6
    assert deterministic(on_cluster) == deterministic(serial)
    # the runs did go to the two worker processes, not to this one
    workers = {r["worker"] for r in on_cluster}
    assert len(workers) == 2, workers
    assert not any(w.endswith(f":{os.getpid()}") for w in workers)
    assert all(r["wallTime"] > 0 for r in serial + on_cluster)


def test_each_run_has_its_own_parameters(sweeps):
    _, serial, _ = sweeps
    ok = {(r["springStiffness"], r["nModes"]): r for r in serial if r["status"] == "ok"}
    assert sorted(ok) == [(50.0, 2), (50.0, 4), (200.0, 2), (200.0, 4)]
    for r in ok.values():
        assert r["finalTime"] == pytest.approx(STOP) and r["outputPoints"] == 30
        assert r["maxSag"] > 0 and r["maxKineticEnergy"] > 0 and r["finalPotentialEnergy"] < 0
    # the modes of K phi = lambda M phi: four times the stiffness, twice the frequency
    for m in (2, 4):
        assert ok[200.0, m]["lowestFrequency"] / ok[50.0, m]["lowestFrequency"] == pytest.approx(2.0, rel=1e-9)
    # a stiffer sheet swings less; more modes, another trajectory
    assert ok[200.0, 2]["maxSag"] < ok[50.0, 2]["maxSag"]
    assert ok[50.0, 4]["meanSag"] != ok[50.0, 2]["meanSag"]



def test_plotted_sag_falls_with_stiffness(default_fmu, md):
    """The sag the plot shows first, the bottom row's sag averaged over the
    whole run, falls as the springs stiffen (50, 100, 200 N/m over the
    default experiment, serially): the undamped sheet swings about its
    equilibrium, and the average sits near the static sag. The sag at the
    stop time catches each swing at another phase and need not fall."""
    from sweeping.plot import PLOTTED

    assert PLOTTED[0][0] == "meanSag"
    rows = sweep.run_sweep(default_fmu, sweep.parse_grid(md, ["springStiffness=50,100,200"]), progress=False)
    assert [r["status"] for r in rows] == ["ok"] * 3, [r["message"] for r in rows]
    mean, settled, final = ([r[k] for r in rows] for k in ("meanSag", "settledSag", "finalSag"))
    print(f"\nspringStiffness 50, 100, 200 N/m: meanSag {mean}, settledSag {settled}, finalSag {final}")
    assert mean[0] > mean[1] > mean[2] > 0.0
    assert settled[0] > settled[1] > settled[2] > 0.0
    # as the static sag, about 1/k (measured 0.0562, 0.0286, 0.0140 m); released
    # from rest the sheet swings to about twice it (maxSag)
    assert mean[0] / mean[1] == pytest.approx(2.0, rel=0.1) and mean[1] / mean[2] == pytest.approx(2.0, rel=0.1)
    for r in rows:
        assert r["maxSag"] / r["meanSag"] == pytest.approx(2.0, rel=0.1)

def test_refused_configurations_are_rows(sweeps, default_fmu, md, client):
    _, serial, on_cluster = sweeps
    for rows in (serial, on_cluster):
        refused = [r for r in rows if r["springStiffness"] == -1.0]
        assert len(refused) == 2
        for r in refused:
            assert r["status"] == "error"
            assert "springStiffness" in r["message"] and "refused" in r["message"]
            assert math.isnan(r["meanSag"]) and math.isnan(r["finalSag"]) and r["outputPoints"] == 0
    # set-up refuses more modes than the scene has degrees of freedom (180), on a
    # worker too; the run beside it is not disturbed
    rows = sweep.run_sweep(default_fmu, sweep.parse_grid(md, ["nModes=500,2"]), stop_time=0.1, client=client, progress=False)
    assert [r["status"] for r in rows] == ["error", "ok"]
    assert "nModes = 500" in rows[0]["message"], rows[0]["message"]
    assert rows[1]["outputPoints"] == 10 and np.isfinite(rows[1]["meanSag"])


def read_csv(path):
    with open(path, newline="") as f:
        return [{k: v for k, v in r.items() if k not in sweep.NONDETERMINISTIC} for r in csv.DictReader(f)]


def test_command_line_serial_and_scheduler(sweeps, default_fmu, client, tmp_path):
    axes, serial, _ = sweeps
    expected = tmp_path / "expected.csv"
    sweep.write_csv(expected, serial, sweep.columns(axes))
    args = [str(default_fmu), "--stop-time", str(STOP), "--quiet"] + [a for g in GRID for a in ("--param", g)]
    outputs = {}
    for mode in (["--serial"], ["--scheduler", client.scheduler.address]):
        out = tmp_path / mode[0].lstrip("-") / "sweep.csv"
        run = subprocess.run([sys.executable, str(ROOT / "python" / "sweep.py"), *args, *mode, "--out", str(out)], capture_output=True, text=True, timeout=120)
        assert run.returncode == 0, run.stderr
        assert "6 runs" in run.stdout and "2 error, 4 ok" in run.stdout, run.stdout
        assert out.with_suffix(".png").stat().st_size > 10_000
        try:
            import pyarrow  # noqa: F401

            assert out.with_suffix(".parquet").exists()
        except ImportError:
            assert not out.with_suffix(".parquet").exists()
        outputs[mode[0]] = read_csv(out)
    assert outputs["--serial"] == read_csv(expected)
    assert outputs["--scheduler"] == read_csv(expected)
    assert list(outputs["--serial"][0]) == ["run", "springStiffness", "nModes"] + sweep.METRICS


def test_documented_sweeps_parse(md):
    """The sweep commands of the README and docs/usage.md name real parameters and values."""
    import shlex

    lines = [line.strip().strip("`") for doc in ("README.md", "docs/usage.md") for line in (ROOT / doc).read_text().splitlines()]
    commands = [line for line in lines if line.startswith(("cargo xtask sweep --", ".venv/bin/python python/sweep.py"))]
    assert len(commands) >= 4, commands
    for command in commands:
        args = shlex.split(command)
        params = [args[i + 1] for i, a in enumerate(args) if a == "--param"]
        assert params, command
        assert sweep.parse_grid(md, params)
        references = [args[i + 1] for i, a in enumerate(args) if a == "--reference"]
        assert all(len(values) == 1 for _, values in sweep.parse_grid(md, references))


def test_error_against_a_reference_run(default_fmu, md, client):
    """With a reference run (full space, short internal steps) every run gets
    E of docs/method.md section 6 against it: 0 for the reference itself,
    falling as modes are added, and the same numbers on the cluster as
    serially (the study's independent runs, spread over workers)."""
    axes = sweep.parse_grid(md, ["nModes=2,8,32"])
    reference = {name: values[0] for name, values in sweep.parse_grid(md, ["reduction=full", "maxInternalStep=1e-4"])}
    serial = sweep.run_sweep(default_fmu, axes, stop_time=0.5, progress=False, reference=reference)
    on_cluster = sweep.run_sweep(default_fmu, axes, stop_time=0.5, client=client, progress=False, reference=reference)
    assert deterministic(on_cluster) == deterministic(serial)
    ref = serial[-1]
    assert ref["run"] == "reference" and ref["E"] == 0.0 and ref["maxNodeError"] == 0.0
    errors = [r["E"] for r in serial[:-1]]
    print("E against full space at 1e-4 s, nModes = 2, 8, 32:", errors)
    assert all(np.isfinite(errors)) and errors[0] > errors[1] > errors[2] > 0.0


CLOTH_12 = ["nx=12", "ny=12", "nModes=12"]


def test_twins_find_the_cloth_horizon_and_the_window(tmp_path):
    """Cloth 12 x 12 is chaotic: the three twins of the full-space reference,
    started 1e-7 m away (the default --twins 3), part within a second; the
    window [0, T_p] ends where the first of them reaches E = 1e-3, and a run
    judged over it is judged on what the scene makes predictable: its
    E_window is far below its E over the whole run, which the twins
    themselves reach. Through the command line, serially."""
    from conftest import fmu_path

    fmu = fmu_path("cloth-3d")
    out = tmp_path / "sweep.csv"
    grid = CLOTH_12 + ["reduction=modal,full", "modeSelection=load", "integrator=newmark-implicit"]
    args = [str(fmu), "--serial", "--quiet", "--out", str(out)]
    args += [a for g in grid for a in ("--param", g)] + [a for r in CLOTH_12 + ["reduction=full"] for a in ("--reference", r)]
    run = subprocess.run([sys.executable, str(ROOT / "python" / "sweep.py"), *args], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    summary = [line for line in run.stdout.splitlines() if line.startswith("predictability:")]
    print(run.stdout)
    rows = read_csv(out)
    assert [r["run"] for r in rows] == ["0", "1", "twin1", "twin2", "twin3", "reference"]
    assert all(r["status"] in ("ok", "warning") for r in rows), [r["message"] for r in rows]

    def num(r, k):
        return float(r[k])

    horizon = num(rows[-1], "horizon")
    assert 0.05 < horizon < 1.5, horizon
    assert len(summary) == 1 and f"T_p = {horizon:g} s" in summary[0] and "3 of 3 twins" in summary[0], run.stdout
    assert all(num(r, "horizon") == horizon for r in rows)
    twins = rows[2:5]
    # the twins are apart from the reference and from each other
    assert len({r["E"] for r in twins}) == 3
    floor, floor_window = num(rows[-1], "twinsE"), num(rows[-1], "twinsE_window")
    assert floor == max(num(r, "E") for r in twins) and floor > 1e-2, floor
    # the window ends at the first output time a twin's E reaches 1e-3: that twin is just past it there
    assert floor_window == max(num(r, "E_window") for r in twins) and 1e-3 <= floor_window < 2e-3, floor_window
    assert f"{floor_window:.3g}" in summary[0] and f"{floor:.3g}" in summary[0]
    for r in rows[:2]:
        e, e_window = num(r, "E"), num(r, "E_window")
        print(f"run {r['run']} ({r['reduction']}): E {e:.3g}, E over [0, {horizon} s] {e_window:.3g}")
        assert floor_window < e_window < e, (r["run"], e_window, e)
    # the full-space run with the implicit scheme follows the reference until the scene parts them
    assert num(rows[1], "E_window") < 0.2 * num(rows[1], "E")
    assert out.with_name("sweep-error.png").stat().st_size > 10_000


def test_no_horizon_on_the_paper_sheet_the_window_is_the_whole_run(md, client):
    """paper-2d-top-row (the default FMU's scene) is regular: over the whole
    default experiment (2 s) its twins stay near their 1e-7 m start, no
    horizon, and E_window is E over the whole run, for every row; serially and
    on the cluster, the same numbers."""
    from conftest import fmu_path

    fmu = str(fmu_path("paper-2d-top-row"))
    axes = sweep.parse_grid(md, ["nModes=2,8"])
    reference = {"reduction": "full"}
    serial = sweep.run_sweep(fmu, axes, progress=False, reference=reference, twins=2)
    on_cluster = sweep.run_sweep(fmu, axes, client=client, progress=False, reference=reference, twins=2)
    assert deterministic(on_cluster) == deterministic(serial)
    assert [r["run"] for r in serial] == [0, 1, "twin1", "twin2", "reference"]
    ref = serial[-1]
    print(f"paper-2d-top-row: twins' E over 2 s {ref['twinsE']:.3g}; E of nModes = 2, 8: {serial[0]['E']:.3g}, {serial[1]['E']:.3g}")
    assert ref["finalTime"] == pytest.approx(2.0) and ref["outputPoints"] == 200
    for r in serial:
        assert math.isnan(r["horizon"]), r
        assert r["E_window"] == r["E"] and r["twinsE_window"] == r["twinsE"]
    assert 0.0 < ref["twinsE"] < 1e-4
    assert serial[2]["E"] > 0.0 and serial[3]["E"] > 0.0 and serial[2]["E"] != serial[3]["E"]
    assert serial[0]["E"] > serial[1]["E"] > ref["twinsE"]
    # without twins there is no floor, and the window is the whole run
    plain = sweep.run_sweep(fmu, axes, stop_time=0.2, progress=False, reference=reference)
    assert [r["run"] for r in plain] == [0, 1, "reference"]
    assert all(math.isnan(r["twinsE"]) and math.isnan(r["horizon"]) and r["E_window"] == r["E"] for r in plain)


def test_start_offset_through_fmpy(default_fmu, md):
    """startOffset as a swept start value: 0 is the canonical run bit for bit,
    1e-7 m another run, beyond 1e-3 m and below 0 refused, naming it."""
    axes = sweep.parse_grid(md, ["startOffset=0,1e-7,2e-3,-1e-9"])
    rows = sweep.run_sweep(default_fmu, axes, stop_time=0.1, progress=False)
    canonical = sweep.run_sweep(default_fmu, [], stop_time=0.1, progress=False)[0]
    assert [r["status"] for r in rows] == ["ok", "ok", "error", "error"], [r["message"] for r in rows]
    assert deterministic([rows[0]])[0] | {"startOffset": ""} == deterministic([canonical])[0] | {"startOffset": ""}
    assert rows[1]["finalSag"] != canonical["finalSag"]
    assert all("startOffset" in r["message"] for r in rows[2:])
