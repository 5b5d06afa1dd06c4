"""`cargo xtask modes` draws the gallery of the modes the FMU keeps: on a 2D
and the 3D canonical scene it writes the PNG and a Markdown table of nModes
rows whose frequencies, modeOutOfPlane and modeSymmetry are those the FMU
reports through fmpy, and whose classes follow from them."""

import csv
import subprocess

import numpy as np
import pytest
from fmpy import extract, read_model_description

from conftest import ROOT, Instance, cargo_available, fmu_path

# (scene, nModes: the scene's own where small, 12 of the 3D sheet's 126)
CASES = [("paper-2d-top-corners", None), ("paper-3d-sheet", 12)]


def fmu_modes(scene, n_modes, tmp):
    """modeFrequencies, modeOutOfPlane and modeSymmetry of the scene's FMU."""
    path = str(fmu_path(scene))
    md = read_model_description(path)
    d = tmp / "fmu"
    extract(path, str(d))
    inst = Instance(md, str(d), name=scene)
    try:
        if n_modes is not None:
            inst.set_u64("nModes", n_modes)
        inst.initialize()
        r = inst.u64("nModes")
        return {name: inst.f64(name, r) for name in ("modeFrequencies", "modeOutOfPlane", "modeSymmetry")}
    finally:
        inst.free()


def markdown_rows(path):
    """The table rows of modes.md, as lists of cells."""
    lines = [line for line in open(path).read().splitlines() if line.startswith("|")]
    return [[c.strip() for c in line.strip("|").split("|")] for line in lines[2:]]


@pytest.mark.skipif(not cargo_available(), reason="cargo is needed to run `cargo xtask modes`")
@pytest.mark.parametrize("scene,n_modes", CASES)
def test_gallery_matches_the_fmu(scene, n_modes, tmp_path):
    out = tmp_path / "modes"
    cmd = ["cargo", "xtask", "modes", "--scene", scene, "--out", str(out)]
    if n_modes is not None:
        cmd += ["--modes", str(n_modes)]
    r = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    for name in ("modes.png", "modes.md", "modes.csv", "shapes.csv"):
        assert (out / name).stat().st_size > 0, name
    assert open(out / "modes.png", "rb").read(8) == b"\x89PNG\r\n\x1a\n"

    fmu = fmu_modes(scene, n_modes, tmp_path)
    r = len(fmu["modeFrequencies"])
    table = list(csv.DictReader(open(out / "modes.csv")))
    rows = markdown_rows(out / "modes.md")
    assert len(table) == r and len(rows) == r
    # The same set-up: the same numbers, to the last bit in the CSV.
    for column, name in (("omega", "modeFrequencies"), ("out_of_plane", "modeOutOfPlane"), ("symmetry", "modeSymmetry")):
        assert [float(t[column]) for t in table] == list(fmu[name]), column
    # The Markdown table: mode numbers, frequencies (10 digits) and the classes of the CSV.
    assert [int(row[0]) for row in rows] == list(range(1, r + 1))
    np.testing.assert_allclose([float(row[1]) for row in rows], fmu["modeFrequencies"], rtol=1e-9)
    assert [row[5] for row in rows] == [t["class"] for t in table]
    # The classes read as the FMU's numbers say: out of the plane above one
    # half, symmetric / antisymmetric at +-0.9 or beyond, mixed between.
    for row, out_of_plane, symmetry in zip(rows, fmu["modeOutOfPlane"], fmu["modeSymmetry"], strict=True):
        plane, mirror = row[5].split()
        assert plane == ("out-of-plane" if out_of_plane > 0.5 else "in-plane"), row
        assert mirror == ("symmetric" if symmetry >= 0.9 else "antisymmetric" if symmetry <= -0.9 else "mixed"), row
    # What the scene is: in 2D every mode in the plane and of one parity
    # (the grid is mirror-symmetric); the 3D sheet's 12 lowest are its out-of-plane cluster.
    classes = [row[5] for row in rows]
    if scene.startswith("paper-2d"):
        assert all(c in ("in-plane symmetric", "in-plane antisymmetric") for c in classes), classes
    else:
        assert all(c.startswith("out-of-plane") for c in classes), classes
