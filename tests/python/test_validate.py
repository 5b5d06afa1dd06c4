"""Point 4 of the issue from Python: fmpy validates every FMU with no problem,
and the model description carries the public interface with its fixed names."""

import subprocess
import sys
import zipfile

from fmpy import read_model_description
from fmpy.validation import validate_fmu

# name -> (type, causality, variability) of the public interface
INTERFACE = {
    "time": ("Float64", "independent", "continuous"),
    "nx": ("UInt64", "structuralParameter", "fixed"),
    "ny": ("UInt64", "structuralParameter", "fixed"),
    "dimension": ("UInt64", "structuralParameter", "fixed"),
    "nModes": ("UInt64", "structuralParameter", "fixed"),
    "spacing": ("Float64", "parameter", "fixed"),
    "nodeMass": ("Float64", "parameter", "fixed"),
    "springStiffness": ("Float64", "parameter", "fixed"),
    "shearSprings": ("Boolean", "parameter", "fixed"),
    "bendingSprings": ("Boolean", "parameter", "fixed"),
    "auxStiffness": ("Float64", "parameter", "fixed"),
    "maxInternalStep": ("Float64", "parameter", "fixed"),
    "threads": ("UInt64", "parameter", "fixed"),
    "fixedNodes": ("Enumeration", "parameter", "fixed"),
    "reduction": ("Enumeration", "parameter", "fixed"),
    "integrator": ("Enumeration", "parameter", "fixed"),
    "modeSelection": ("Enumeration", "parameter", "fixed"),
    "staticCorrection": ("Boolean", "parameter", "fixed"),
    "linearization": ("Enumeration", "parameter", "fixed"),
    "forceEvaluation": ("Enumeration", "parameter", "fixed"),
    "cubatureTolerance": ("Float64", "parameter", "fixed"),
    "errorTolerance": ("Float64", "parameter", "tunable"),
    "forceResidualLimit": ("Float64", "parameter", "tunable"),
    "gravity": ("Float64", "parameter", "tunable"),
    "dampingAlpha": ("Float64", "parameter", "tunable"),
    "dampingBeta": ("Float64", "parameter", "tunable"),
    "modeWeights": ("Float64", "parameter", "tunable"),
    "loadX": ("Float64", "input", "continuous"),
    "loadY": ("Float64", "input", "continuous"),
    "loadZ": ("Float64", "input", "continuous"),
    "loadRow": ("UInt64", "parameter", "fixed"),
    "loadColumn": ("UInt64", "parameter", "fixed"),
    "anchorX": ("Float64", "input", "continuous"),
    "anchorY": ("Float64", "input", "continuous"),
    "anchorZ": ("Float64", "input", "continuous"),
    "anchorRX": ("Float64", "input", "continuous"),
    "anchorRY": ("Float64", "input", "continuous"),
    "anchorRZ": ("Float64", "input", "continuous"),
    "trainingScale": ("Float64", "parameter", "fixed"),
    "trainingTilt": ("Float64", "parameter", "fixed"),
    "trainingTime": ("Float64", "parameter", "fixed"),
    "trainingRangeLimit": ("Float64", "parameter", "tunable"),
    "trainingRange": ("Float64", "output", "continuous"),
    "errorEstimate": ("Float64", "output", "continuous"),
    "reducedFraction": ("Float64", "output", "continuous"),
    "basisSize": ("Float64", "output", "continuous"),
    "anchorMotion": ("Boolean", "parameter", "fixed"),
    "anchorRotation": ("Boolean", "parameter", "fixed"),
    "positions": ("Float64", "output", "continuous"),
    "velocities": ("Float64", "output", "continuous"),
    "modalCoordinates": ("Float64", "output", "continuous"),
    "kineticEnergy": ("Float64", "output", "continuous"),
    "potentialEnergy": ("Float64", "output", "continuous"),
    "forceResidual": ("Float64", "output", "continuous"),
    "loadNodeX": ("Float64", "output", "continuous"),
    "loadNodeY": ("Float64", "output", "continuous"),
    "loadNodeZ": ("Float64", "output", "continuous"),
    "loadNodeVX": ("Float64", "output", "continuous"),
    "loadNodeVY": ("Float64", "output", "continuous"),
    "loadNodeVZ": ("Float64", "output", "continuous"),
    "anchorForceX": ("Float64", "output", "continuous"),
    "anchorForceY": ("Float64", "output", "continuous"),
    "anchorForceZ": ("Float64", "output", "continuous"),
    "anchorTorqueX": ("Float64", "output", "continuous"),
    "anchorTorqueY": ("Float64", "output", "continuous"),
    "anchorTorqueZ": ("Float64", "output", "continuous"),
    "cubatureSprings": ("UInt64", "calculatedParameter", "fixed"),
    "modeFrequencies": ("Float64", "calculatedParameter", "fixed"),
    "springNeighbours": ("UInt64", "calculatedParameter", "fixed"),
    "startOffset": ("Float64", "parameter", "fixed"),
    "startSeed": ("UInt64", "parameter", "fixed"),
    "modeOutOfPlane": ("Float64", "calculatedParameter", "fixed"),
    "modeSymmetry": ("Float64", "calculatedParameter", "fixed"),
    "modeShapes": ("Float64", "calculatedParameter", "fixed"),
    "nHolders": ("UInt64", "structuralParameter", "fixed"),
    "holderOfNode": ("UInt64", "parameter", "fixed"),
}
# holders 2 to 4: their inputs and the force and torque on them
for _k in (2, 3, 4):
    for _c in ("X", "Y", "Z", "RX", "RY", "RZ"):
        INTERFACE[f"anchor{_k}{_c}"] = ("Float64", "input", "continuous")
    for _c in ("ForceX", "ForceY", "ForceZ", "TorqueX", "TorqueY", "TorqueZ"):
        INTERFACE[f"anchor{_k}{_c}"] = ("Float64", "output", "continuous")

ENUMERATIONS = {
    "fixedNodes": ["top-row", "top-corners", "custom"],
    "reduction": ["modal", "full", "adaptive"],
    "integrator": ["newmark-explicit", "newmark-implicit", "trigonometric"],
    "modeSelection": ["lowest", "load", "trained"],
    "linearization": ["rest", "equilibrium"],
}

# array variables and the structural parameters (or fixed sizes) of their dimensions
DIMENSIONS = {
    "gravity": [3],
    "modeWeights": ["nModes"],
    "positions": ["ny", "nx", "dimension"],
    "velocities": ["ny", "nx", "dimension"],
    "modalCoordinates": ["nModes"],
    "modeFrequencies": ["nModes"],
    "springNeighbours": ["ny", "nx", 6],
    "modeOutOfPlane": ["nModes"],
    "modeSymmetry": ["nModes"],
    "modeShapes": ["nModes", "ny", "nx", "dimension"],
    "holderOfNode": ["ny", "nx"],
}


def test_validate_fmu_reports_no_problem(any_fmu):
    assert validate_fmu(any_fmu) == []


def test_fmpy_validate_command(any_fmu):
    """The command line `fmpy validate` (exit code = number of problems)."""
    r = subprocess.run([sys.executable, "-m", "fmpy", "validate", any_fmu], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "No problems found." in r.stdout


def test_archive_layout(any_fmu):
    names = set(zipfile.ZipFile(any_fmu).namelist())
    assert "modelDescription.xml" in names
    assert "binaries/x86_64-linux/ModalMassSpring.so" in names
    assert any(n.startswith("documentation/") for n in names)


def test_interface(any_fmu):
    md = read_model_description(any_fmu)
    assert md.fmiVersion == "3.0"
    assert md.modelName == "ModalMassSpring"
    assert md.coSimulation is not None and md.modelExchange is None and md.scheduledExecution is None
    cs = md.coSimulation
    assert cs.modelIdentifier == "ModalMassSpring"
    assert cs.canGetAndSetFMUstate and cs.canSerializeFMUstate
    assert cs.canHandleVariableCommunicationStepSize
    assert md.defaultExperiment.startTime in ("0", "0.0", 0, 0.0, None) or float(md.defaultExperiment.startTime) == 0
    assert float(md.defaultExperiment.stopTime) == 2
    assert float(md.defaultExperiment.stepSize) == 0.01

    variables = {v.name: v for v in md.modelVariables}
    assert set(variables) == set(INTERFACE)
    for name, (ty, causality, variability) in INTERFACE.items():
        v = variables[name]
        assert (v.type, v.causality, v.variability) == (ty, causality, variability), name
        assert v.description, f"{name} has no description"
    vrs = [v.valueReference for v in md.modelVariables]
    assert len(set(vrs)) == len(vrs)

    for name, dims in DIMENSIONS.items():
        got = [d.variable.name if d.variable is not None else int(d.start) for d in variables[name].dimensions]
        assert got == dims, name

    types = {t.name: t for t in md.typeDefinitions}
    for name, items in ENUMERATIONS.items():
        t = variables[name].declaredType
        assert t is not None and t.type == "Enumeration", name
        assert [i.name for i in t.items] == items, name
        assert [int(i.value) for i in t.items] == list(range(1, len(items) + 1)), name
        assert t.name in types

    units = {
        "time": "s", "spacing": "m", "nodeMass": "kg", "springStiffness": "N/m", "auxStiffness": "N/m",
        "maxInternalStep": "s", "gravity": "m/s2", "dampingAlpha": "1/s", "dampingBeta": "s",
        "positions": "m", "velocities": "m/s", "kineticEnergy": "J", "potentialEnergy": "J",
        "modeFrequencies": "rad/s",
        "loadX": "N", "loadY": "N", "loadZ": "N",
        "anchorX": "m", "anchorY": "m", "anchorZ": "m",
        "loadNodeX": "m", "loadNodeY": "m", "loadNodeZ": "m",
        "loadNodeVX": "m/s", "loadNodeVY": "m/s", "loadNodeVZ": "m/s",
        "anchorForceX": "N", "anchorForceY": "N", "anchorForceZ": "N",
        "anchorTorqueX": "N.m", "anchorTorqueY": "N.m", "anchorTorqueZ": "N.m",
        "anchorRX": "rad", "anchorRY": "rad", "anchorRZ": "rad",
        "anchor2X": "m", "anchor4RZ": "rad", "anchor2ForceY": "N", "anchor3TorqueZ": "N.m",
    }
    defined = {u.name for u in md.unitDefinitions}
    for name, unit in units.items():
        v = variables[name]
        got = v.unit or (v.declaredType.unit if v.declaredType is not None else None)
        assert got == unit, name
        assert unit in defined


def test_default_start_values(default_fmu):
    """The default FMU is the paper's Fig. 7 set-up: paper-2d-top-row, 2 modes,
    explicit Newmark, no damping."""
    md = read_model_description(default_fmu)
    s = {v.name: v.start for v in md.modelVariables}
    assert (int(s["nx"]), int(s["ny"]), int(s["dimension"]), int(s["nModes"])) == (10, 10, 2, 2)
    assert int(s["fixedNodes"]) == 1 and int(s["reduction"]) == 1 and int(s["integrator"]) == 1
    assert float(s["dampingAlpha"]) == 0 and float(s["dampingBeta"]) == 0
    assert [float(x) for x in s["gravity"].split()] == [0.0, -9.81, 0.0]
    assert [float(x) for x in s["modeWeights"].split()] == [1.0, 1.0]


def test_scene_fmu_start_values(scene_fmu):
    """A scene-baked FMU's array start values match its structural parameters,
    so plain simulate_fmu needs nothing set."""
    _, path = scene_fmu
    md = read_model_description(path)
    v = {x.name: x for x in md.modelVariables}
    n_modes = int(v["nModes"].start)
    assert len(v["modeWeights"].start.split()) == n_modes
    assert v["positions"].shape == (int(v["ny"].start), int(v["nx"].start), int(v["dimension"].start))
