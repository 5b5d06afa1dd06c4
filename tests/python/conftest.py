"""Fixtures for the fmpy tests of the ModalMassSpring FMU.

The FMUs are found in ``$MMS_FMU_DIR`` if set, else in ``$CARGO_TARGET_DIR/fmu``
or ``<repo>/target/fmu``. ``cargo xtask test`` builds them before running
pytest; when one is missing here it is built with ``cargo xtask fmu``.

The reference importer fmusim is ``$MMS_FMUSIM`` if set, else
``<target>/tools/fmusim`` (``cargo xtask fmusim`` builds it, ``cargo xtask
test`` does so before pytest). Without it its tests are skipped, except on CI
(``CI=true``), where they fail.

The canonical scenes are read from ``modelDescription/variables.toml`` (the
single source of the variables and scenes), so a new scene gets tested
without touching this file.
"""

import os
import shutil
import subprocess
import tomllib
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi3 import FMU3Slave

ROOT = Path(__file__).resolve().parents[2]
MODEL_IDENTIFIER = "ModalMassSpring"


def scene_names():
    with open(ROOT / "modelDescription" / "variables.toml", "rb") as f:
        spec = tomllib.load(f)
    return sorted(spec.get("scenes", {}))


SCENES = scene_names()


def target_dir() -> Path:
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    return target if target.is_absolute() else ROOT / target


def fmu_dir() -> Path:
    if os.environ.get("MMS_FMU_DIR"):
        return Path(os.environ["MMS_FMU_DIR"])
    return target_dir() / "fmu"


def on_ci() -> bool:
    return os.environ.get("CI", "").lower() in ("true", "1")


@pytest.fixture(scope="session")
def fmusim() -> str:
    """Path of the fmusim binary; skips the test when it is missing, fails it on CI."""
    path = Path(os.environ.get("MMS_FMUSIM") or target_dir() / "tools" / "fmusim")
    if not (path.is_file() and os.access(path, os.X_OK)):
        reason = f"fmusim not found at {path}: build it with `cargo xtask setup && cargo xtask fmusim`"
        if on_ci():
            pytest.fail(f"{reason} (CI=true: the fmusim tests must run)")
        pytest.skip(reason)
    return str(path)


def fmu_path(scene=None) -> Path:
    """Path of the default FMU (scene None) or of a scene-baked FMU; built if missing."""
    name = scene or MODEL_IDENTIFIER
    path = fmu_dir() / f"{name}.fmu"
    if not path.exists():
        cmd = ["cargo", "xtask", "fmu"] + (["--scene", scene, "--out", str(path)] if scene else [])
        subprocess.run(cmd, cwd=ROOT, check=True)
    assert path.exists(), f"{path} was not built"
    return path


@pytest.fixture(scope="session")
def default_fmu() -> str:
    return str(fmu_path())


@pytest.fixture(scope="session", params=SCENES)
def scene_fmu(request) -> tuple:
    """(scene name, path of its scene-baked FMU)"""
    return request.param, str(fmu_path(request.param))


@pytest.fixture(scope="session", params=[None] + SCENES, ids=["default"] + SCENES)
def any_fmu(request) -> str:
    """The default FMU and every scene-baked FMU."""
    return str(fmu_path(request.param))


@pytest.fixture(scope="session")
def default_md(default_fmu):
    return read_model_description(default_fmu)


@pytest.fixture(scope="session")
def unzipped(default_fmu, tmp_path_factory):
    """The default FMU extracted once for the low-level tests."""
    d = tmp_path_factory.mktemp("fmu")
    extract(default_fmu, str(d))
    return str(d)


class Instance:
    """A thin wrapper around fmpy's FMU3Slave: value references by name, and
    Float64 reads with an explicit number of values."""

    def __init__(self, md, unzipdir, name="instance", log=None):
        self.md = md
        self.vars = {v.name: v for v in md.modelVariables}
        self.vr = {name: v.valueReference for name, v in self.vars.items()}
        self.messages = []

        def logger(env, status, category, message):
            self.messages.append((status, category.decode(), message.decode()))

        self.slave = FMU3Slave(
            guid=md.guid,
            unzipDirectory=unzipdir,
            modelIdentifier=md.coSimulation.modelIdentifier,
            instanceName=name,
        )
        self.slave.instantiate(logMessage=logger if log is None else log)
        self.time = 0.0
        self.freed = False

    # -- access by name ------------------------------------------------------
    def f64(self, name, n):
        return np.array(self.slave.getFloat64([self.vr[name]], nValues=n))

    def f64s(self, name):
        return float(self.slave.getFloat64([self.vr[name]])[0])

    def set_f64(self, name, values):
        self.slave.setFloat64([self.vr[name]], list(np.atleast_1d(values).astype(float)))

    def u64(self, name):
        return int(self.slave.getUInt64([self.vr[name]])[0])

    def set_u64(self, name, value):
        self.slave.setUInt64([self.vr[name]], [int(value)])

    def sizes(self):
        return self.u64("nx"), self.u64("ny"), self.u64("dimension"), self.u64("nModes")

    def positions(self):
        nx, ny, dim, _ = self.sizes()
        return self.f64("positions", nx * ny * dim).reshape(ny, nx, dim)

    def modal(self):
        return self.f64("modalCoordinates", self.u64("nModes"))

    # -- life cycle ------------------------------------------------------------
    def initialize(self, start=0.0):
        self.slave.enterInitializationMode(startTime=start)
        self.slave.exitInitializationMode()
        self.time = start

    def step(self, h, n=1):
        for _ in range(n):
            self.slave.doStep(currentCommunicationPoint=self.time, communicationStepSize=h)
            self.time += h

    def free(self):
        if not self.freed:
            self.freed = True
            try:
                self.slave.terminate()
            except Exception:
                pass
            self.slave.freeInstance()
            # the shared library stays loaded for other instances of this process


@pytest.fixture
def new_instance(default_md, unzipped):
    """Factory of low-level instances of the default FMU, freed after the test."""
    made = []

    def make(name="instance"):
        inst = Instance(default_md, unzipped, name=name)
        made.append(inst)
        return inst

    yield make
    for inst in made:
        inst.free()


def cargo_available() -> bool:
    return shutil.which("cargo") is not None
