"""The control experiments of docs/control.md, through the FMU with fmpy
(python/control.py): the paper's Fig. 7 (2 modes close to full space), Fig. 8
(three mode sets, three different motions), Fig. 9 (every mode of the 3D
sheet is full space) and control of the 3D sheet by mode class (in-plane
modes keep it in its plane to round-off, out-of-plane modes alone move it
out of it, a weight changed mid-run acts from that step on). Then the
command itself writes every picture and the GIF."""

import subprocess
import sys

import numpy as np
import pytest

from conftest import ROOT, cargo_available

sys.path.insert(0, str(ROOT / "python"))
import control  # noqa: E402


@pytest.fixture(scope="module")
def fmu(default_fmu):
    with control.Fmu(default_fmu) as f:
        yield f


def test_fig7_two_modes_follow_full_space(fmu):
    runs = control.fig7_runs(fmu)
    full, modal = runs["full"], runs["modal"]
    assert modal.setup["nModes"] == 2
    # The sheet moves (it bounces some 0.1 m) and 2 modes follow it: E over 2 s
    # is 0.087 (measured); the paper saw "no large error".
    assert control.largest_displacement(full) > 0.05
    e = control.error(modal, full)
    assert 1e-3 < e < 0.1, e


def test_fig8_three_mode_sets_three_motions(fmu):
    runs = control.fig8_runs(fmu)
    for k, (_, r, weights) in control.FIG8_SETS.items():
        assert runs[k].setup["nModes"] == r and len(weights) == r
        assert control.largest_displacement(runs[k]) > 1e-3, k
    # Disjoint mode sets: the three motions share nothing, whatever their
    # sizes (sqrt(2) = orthogonal, measured 1.414 for each pair).
    for p, q in (("a", "b"), ("a", "c"), ("b", "c")):
        assert control.shape_distance(runs[p], runs[q]) > 1.3, (p, q)
    # Visibly different sizes too (measured 32x and 6.4x).
    size = {k: control.largest_displacement(runs[k]) for k in "abc"}
    assert size["a"] > 3 * size["b"] > 9 * size["c"], size
    # The paper: heavier nodes deform the sheet more than Fig. 7's (0.11 m).
    fig7 = control.fig7_runs(fmu)["modal"]
    assert control.largest_displacement(runs["a"]) > 3 * control.largest_displacement(fig7)
    # The measure: one motion against itself reads 0.
    assert control.shape_distance(runs["a"], runs["a"]) == 0.0


def test_fig9_every_mode_is_full_space(fmu):
    runs = control.fig9_runs(fmu)
    full, modal = runs["full"], runs["modal"]
    assert modal.setup["nModes"] == 126
    assert control.largest_displacement(full) > 1e-3
    assert control.error(modal, full) < 1e-10
    assert control.largest_node_error(modal, full) < 1e-10


def test_3d_control_by_mode_class(fmu):
    runs = control.control3d_runs(fmu)
    assert control.SIDE_GRAVITY[2] != 0.0
    inp, out = runs["in"], runs["out"]
    # The classification splits the 126 modes into the 42 of the auxiliary
    # springs' cluster (one per free node) and the 84 in the plane.
    assert int(control.out_of_plane(inp.setup).sum()) == 42
    # Every mode: full space, out of the plane as well.
    assert control.error(runs["every"], runs["full"]) < 1e-10
    assert control.largest_out_of_plane(runs["full"]) > 0.1
    # In-plane modes only: the sheet moves in its plane and stays in it to
    # round-off, although gravity pushes across it (measured 8e-16 m).
    assert control.largest_displacement(inp, slice(0, 2)) > 0.01
    assert control.largest_out_of_plane(inp) < 1e-13
    # Out-of-plane modes only: it leaves the plane and nothing moves in it.
    assert control.largest_out_of_plane(out) > 0.05
    assert control.largest_displacement(out, slice(0, 2)) < 1e-13
    # Doubling the out-of-plane modes is another motion.
    assert control.error(runs["double"], runs["every"]) > 0.1
    # The weights changed at t = 1 s: the in-plane run to the last bit before,
    # out of the plane within 0.1 s after.
    k = int(round(control.SWITCH_AT / control.STEP))
    switch = runs["switch"]
    assert np.array_equal(switch.frames[:k], inp.frames[:k])
    assert np.abs(switch.frames[k : k + 10, :, 2]).max() > 1e-3


def test_the_command_writes_every_picture(default_fmu, tmp_path):
    r = subprocess.run([sys.executable, str(ROOT / "python" / "control.py"), default_fmu, "--out", str(tmp_path)], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    for name in ("fig7.png", "fig8.png", "fig9.png", "control-3d.png"):
        assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name
    from PIL import Image

    for name in ("fig8.gif", "control-3d.gif"):
        assert (tmp_path / name).read_bytes()[:6] == b"GIF89a"
        # every 8th step of the 2 s and the start: 12.5 pictures a second
        frames = Image.open(tmp_path / name).n_frames
        assert frames == int(round(control.STOP / (8 * control.STEP))) + 1, (name, frames)
    numbers = (tmp_path / "numbers.txt").read_text()
    for name in ("fig7:", "fig8:", "fig9:", "3d:"):
        assert name in numbers
    bad = subprocess.run(
        [sys.executable, str(ROOT / "python" / "control.py"), default_fmu, "--figure", "fig10", "--out", str(tmp_path)], capture_output=True, text=True
    )
    assert bad.returncode != 0 and "unknown figure fig10" in bad.stderr


@pytest.mark.skipif(not cargo_available(), reason="cargo is needed to run `cargo xtask control`")
def test_the_xtask_command(tmp_path):
    """`cargo xtask control`, as docs/control.md gives it: one figure."""
    r = subprocess.run(["cargo", "xtask", "control", "--figure", "fig7", "--out", str(tmp_path)], cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert (tmp_path / "fig7.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (tmp_path / "numbers.txt").read_text().startswith("fig7: 2 lowest modes against full space")
