"""The fmpy examples of the README and docs/usage.md work as written."""

import re
import subprocess
import sys

import numpy as np
import pytest
from fmpy import simulate_fmu

from conftest import ROOT, cargo_available, fmu_path

README = (ROOT / "README.md").read_text()
USAGE = (ROOT / "docs" / "usage.md").read_text()


def snippet(name):
    m = re.search(rf"<!-- snippet: {name} -->\s*```python\n(.*?)```\s*<!-- end snippet -->", README, re.S)
    assert m, f"snippet {name} not found in README.md"
    return m.group(1)


def test_configuration_mode_snippet(default_fmu):
    code = snippet("configuration-mode")
    assert '"target/fmu/ModalMassSpring.fmu"' in code
    code = code.replace('"target/fmu/ModalMassSpring.fmu"', repr(default_fmu))
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    m = re.search(r"t = ([\d.]+) s, bottom row at y = (-?[\d.]+) m, lowest mode ([\d.]+) rad/s", r.stdout)
    assert m, r.stdout
    t, y, w = (float(g) for g in m.groups())
    assert t == pytest.approx(2.0)
    assert -3.0 < y < -1.39  # 15 rows of 0.1 m: the bottom row starts at -1.4 m and hangs below
    assert w > 0


def test_scene_baked_fmu_example(tmp_path):
    line = next(l for l in USAGE.splitlines() if l.startswith("cargo xtask fmu --scene paper-2d-top-corners"))
    args = line.split()[3:]  # --scene paper-2d-top-corners --nx 12 --modes 5
    assert "target/fmu/paper-2d-top-corners-nx12-modes5.fmu" in USAGE
    out = tmp_path / "scene.fmu"
    if not cargo_available():
        pytest.skip("cargo not on PATH")
    subprocess.run(["cargo", "xtask", "fmu", *args, "--out", str(out)], cwd=ROOT, check=True)
    result = simulate_fmu(str(out), output=["positions"])
    assert result["positions"].shape == (201, 10, 12, 2)
    x = result["positions"]
    assert np.all(np.isfinite(x)) and x[:, -1, :, 1].mean() < x[0, -1, :, 1].mean()
