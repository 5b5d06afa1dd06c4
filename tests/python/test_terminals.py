"""terminalsAndIcons/terminalsAndIcons.xml in the FMU (FMI 3.0, section
2.4.9; the convention in docs/terminals.md): valid against the official
FMI 3.0 schema (fmpy's copy of fmi3TerminalsAndIcons.xsd, with lxml), one
terminal per holder whose variables are in the model description and one
for the load node, every member a variable of the model description with
the causality its kind needs; fmpy's validation passes with it.

fmpy 0.3.32 ships the schema but does not read terminals
(read_model_description has no terminals), so they are read here with lxml.
"""

import re
import subprocess
import sys
import zipfile
from pathlib import Path

import fmpy
import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu
from lxml import etree

ENTRY = "terminalsAndIcons/terminalsAndIcons.xml"
SCHEMA = Path(fmpy.__file__).parent / "schema" / "fmi3" / "fmi3TerminalsAndIcons.xsd"

# A holder's variables after "anchor" (holder 1) or "anchor{k}": member name, variableKind, causality.
HOLDER = {
    "X": ("x", "signal", "input"), "Y": ("y", "signal", "input"), "Z": ("z", "signal", "input"),
    "RX": ("rx", "signal", "input"), "RY": ("ry", "signal", "input"), "RZ": ("rz", "signal", "input"),
    "ForceX": ("forceX", "outflow", "output"), "ForceY": ("forceY", "outflow", "output"),
    "ForceZ": ("forceZ", "outflow", "output"), "TorqueX": ("torqueX", "outflow", "output"),
    "TorqueY": ("torqueY", "outflow", "output"), "TorqueZ": ("torqueZ", "outflow", "output"),
}
LOAD_NODE = {
    "loadX": ("forceX", "inflow", "input"), "loadY": ("forceY", "inflow", "input"), "loadZ": ("forceZ", "inflow", "input"),
    "loadNodeX": ("x", "signal", "output"), "loadNodeY": ("y", "signal", "output"), "loadNodeZ": ("z", "signal", "output"),
    "loadNodeVX": ("vx", "signal", "output"), "loadNodeVY": ("vy", "signal", "output"), "loadNodeVZ": ("vz", "signal", "output"),
}
HOLDER_VARIABLE = re.compile(r"anchor([0-9]*)(" + "|".join(HOLDER) + r")")


def read_terminals(path):
    with zipfile.ZipFile(path) as z:
        assert ENTRY in z.namelist(), f"{path} has no {ENTRY}"
        return etree.fromstring(z.read(ENTRY))


def expected_terminals(md):
    """{terminal name: {variable: (member, kind, causality)}} by the naming
    convention, from the variable names of the model description."""
    holders = set()
    for v in md.modelVariables:
        m = HOLDER_VARIABLE.fullmatch(v.name)
        if m:
            holders.add(int(m.group(1) or 1))
    out = {}
    for k in sorted(holders):
        prefix = "anchor" if k == 1 else f"anchor{k}"
        out[f"holder{k}"] = {prefix + suffix: member for suffix, member in HOLDER.items()}
    out["loadNode"] = dict(LOAD_NODE)
    return out


def problems(root, md):
    """What is wrong with the terminals `root` of an FMU whose model
    description is `md`: the terminals the convention asks for, their
    members, kinds and matching rule, each member a scalar Float64 variable
    of the causality its kind needs."""
    variables = {v.name: v for v in md.modelVariables}
    want = expected_terminals(md)
    terminals = root.findall("Terminals/Terminal")
    out = []
    if [t.get("name") for t in terminals] != list(want):
        out.append(f"terminals {[t.get('name') for t in terminals]}, the convention gives {list(want)}")
    for t in terminals:
        name = t.get("name")
        kind = "_ModalMassSpring_loadNode" if name == "loadNode" else "_ModalMassSpring_holder"
        if (t.get("matchingRule"), t.get("terminalKind")) != ("bus", kind):
            out.append(f"{name}: matchingRule {t.get('matchingRule')}, terminalKind {t.get('terminalKind')}")
        members = t.findall("TerminalMemberVariable")
        member_names = [m.get("memberName") for m in members]
        if len(set(member_names)) != len(member_names):
            out.append(f"{name}: member names repeat (bus matches by name)")
        got = {m.get("variableName"): (m.get("memberName"), m.get("variableKind")) for m in members}
        if got != {v: w[:2] for v, w in want.get(name, {}).items()}:
            out.append(f"{name}: members {got}")
        for variable, (member, _, causality) in want.get(name, {}).items():
            v = variables.get(variable)
            if v is None or (v.type, v.causality, len(v.dimensions)) != ("Float64", causality, 0):
                out.append(f"{name}.{member}: {variable} is not a scalar Float64 {causality}")
    return out


def test_valid_against_the_fmi3_schema(any_fmu):
    root = read_terminals(any_fmu)
    schema = etree.XMLSchema(file=str(SCHEMA))
    assert schema.validate(root), schema.error_log
    assert root.get("fmiVersion") == read_model_description(any_fmu).fmiVersion == "3.0"
    # the schema can refuse a file: a member without its variableKind
    broken = etree.fromstring(etree.tostring(root))
    del broken.find(".//TerminalMemberVariable").attrib["variableKind"]
    assert not schema.validate(broken)


def test_every_member_is_a_variable_with_its_causality(any_fmu):
    md = read_model_description(any_fmu)
    root = read_terminals(any_fmu)
    assert problems(root, md) == []
    names = [t.get("name") for t in root.findall("Terminals/Terminal")]
    assert names[0] == "holder1" and names[-1] == "loadNode"
    print(f"\n{Path(any_fmu).name}: terminals {names}")


@pytest.mark.parametrize("change", ["unknown variable", "wrong causality", "holder left out"])
def test_the_comparison_can_fail(default_fmu, change):
    md = read_model_description(default_fmu)
    root = read_terminals(default_fmu)
    if change == "unknown variable":
        root.find(".//TerminalMemberVariable").set("variableName", "anchorW")
    elif change == "wrong causality":
        # a model description in which the holder's force were set by the importer
        next(v for v in md.modelVariables if v.name == "anchorForceX").causality = "input"
    else:
        root.find("Terminals").remove(root.find("Terminals/Terminal[@name='holder1']"))
    assert problems(root, md) != []


def test_fmpy_validate_passes_and_does_not_read_terminals(default_fmu):
    assert ENTRY in zipfile.ZipFile(default_fmu).namelist()
    assert validate_fmu(default_fmu) == []
    r = subprocess.run([sys.executable, "-m", "fmpy", "validate", default_fmu], capture_output=True, text=True)
    assert r.returncode == 0 and "No problems found." in r.stdout, r.stdout + r.stderr
    md = read_model_description(default_fmu)
    assert not any("terminal" in a.lower() for a in dir(md))
