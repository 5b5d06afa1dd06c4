"""The examples in python/examples/ run as a user runs them (a subprocess
on the default FMU) and show what their docstrings say."""

import re
import subprocess
import sys

import pytest

from conftest import ROOT, fmu_path

EXAMPLES = ROOT / "python" / "examples"


def run(script, *args):
    r = subprocess.run([sys.executable, str(EXAMPLES / script), *args], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 0, r.stdout + r.stderr
    return r.stdout


def displacements(text):
    """(x, y, z) of the line 'largest displacement of a node ...'."""
    m = re.search(r"x (\S+) m, y (\S+) m, z (\S+) m", text)
    return [float(v) for v in m.groups()]


@pytest.mark.parametrize("keep,count", [("in-plane", 84), ("out-of-plane", 42), ("symmetric", 42), ("antisymmetric", 42), ("all", 126)])
def test_choose_by_class(default_fmu, keep, count):
    out = run("choose_by_class.py", default_fmu, "--keep", keep, "--seconds", "0.5")
    assert f"kept {count} of 126 modes ({keep})" in out
    x, y, z = displacements(out)
    if keep == "in-plane":
        assert z < 1e-13 and max(x, y) > 1e-2
    elif keep == "out-of-plane":
        assert z > 1e-2 and max(x, y) < 1e-13
    else:
        assert max(x, y) > 1e-3


def test_weights_mid_run(default_fmu):
    out = run("weights_mid_run.py", default_fmu, "--at", "0.5", "--seconds", "1")
    m = re.search(r"bottom rows: (\S+) m up to t = 0.50 s, (\S+) m after", out)
    before, after = float(m.group(1)), float(m.group(2))
    assert before == 0.0 and after > 1e-2, out


def test_mode_gallery(default_fmu, tmp_path):
    png = tmp_path / "gallery.png"
    out = run("mode_gallery.py", default_fmu, "--out", str(png))
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    lines = [line for line in out.splitlines() if line.startswith("mode ")]
    assert len(lines) == 6
    # Gravity down and sideways in the plane loads in-plane modes of both parities.
    assert all("out of plane 0.000" in line for line in lines)
    assert any("symmetry +1.000" in line for line in lines) and any("symmetry -1.000" in line for line in lines)
    out = run("mode_gallery.py", default_fmu, "--dimension", "2", "--modes", "4", "--mode-selection", "lowest", "--out", str(png))
    assert len([line for line in out.splitlines() if line.startswith("mode ")]) == 4


def test_two_hands(default_fmu, tmp_path):
    gif, png = tmp_path / "two_hands.gif", tmp_path / "two_hands.png"
    out = run("two_hands.py", default_fmu, "--seconds", "0.5", "--out", str(gif), "--still", str(png))
    assert gif.read_bytes()[:6] == b"GIF89a" and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", out
    # Settled, the two hands carry the weight of the cloth between them.
    m = re.search(r"add up to \((\S+), (\S+)\) N, the weight of the cloth's free nodes is \((\S+), (\S+)\) N", out)
    fx, fy, wx, wy = (float(v) for v in m.groups())
    assert wx == 0.0 and wy < -10.0 and abs(fx) < 1e-3 and abs(fy / wy - 1) < 1e-3, out
    # The cloth pulls each hand down and inwards: the left one (holder 1) along +x, the right one along -x.
    for hand, inwards in (("anchorForce", 1.0), ("anchor2Force", -1.0)):
        m = re.search(rf"\({hand}\): x (\S+) to (\S+), y (\S+) to (\S+) N", out)
        x_lo, x_hi, y_lo, y_hi = (float(v) for v in m.groups())
        assert max(inwards * x_lo, inwards * x_hi) > 1.0 and min(inwards * x_lo, inwards * x_hi) > -0.1, out
        assert y_lo < -1.0 and y_hi < 0.0, out
    m = re.search(r"reduced against full: largest node distance (\S+) m", out)
    assert float(m.group(1)) < 0.02, out
    # The 3D variant: the hands swing across the plane, and the forces have a z component.
    out = run("two_hands.py", default_fmu, "--dimension", "3", "--seconds", "0.5", "--out", "", "--still", "")
    assert "nodes in 3D" in out and re.search(r"\(anchor2Force\): x \S+ to \S+, y \S+ to \S+, z ", out), out


def test_adaptive_check():
    """Through fmpy, cloth 30 x 30 against full space at 0.0005 s: inside the
    training program E <= 0.01 with at least 90 % of the steps reduced, far
    outside it E <= 0.02; errorEstimate within [E/3, 3E] (or both below a
    tenth of the tolerance, 0.001)."""
    out = run("adaptive_check.py", str(fmu_path("cloth-3d")))
    rows = re.findall(r"^(.+?): E (\S+) errorEstimate (\S+) reducedFraction (\S+)", out, re.M)
    assert len(rows) == 4, out
    for name, e, estimate, reduced in rows:
        e, estimate, reduced = float(e), float(estimate), float(reduced)
        inside = name in ("canonical", "0.85 g tilted 10 deg")
        assert e <= (0.01 if inside else 0.02), out
        assert reduced >= 0.9 if inside else reduced == 0.0, out
        assert estimate >= e / 3 and (estimate <= 3 * e or estimate <= 0.001), out
