"""The chain of python/chain.py as an SSP 1.0 archive (`cargo xtask ssp`:
target/ssp/chain.ssp, relative anchor, and chain-absolute.ssp), run by Ecos
(ecospy 0.7.2) from the archive alone, `EcosSimulation(h, ssp_path=...)`
with the parameter set "chain": bit for bit chain.run_master (Jacobi) with
the sheets of chain.SHEETS, over the run of test_ecos.py's chain test
(h = 1/256 s up to 3 s).

The archive: SystemStructure.ssd with the components A and B and the
connections of chain.LINKS (relative anchor: an ssc:LinearTransformation,
offset -A.loadNode(0), on the links into B's anchor), one parameter set per
sheet (resources/A.ssv, B.ssv: chain.SHEETS and chain.COMMON without the
structural parameters) and one FMU per grid, its grid baked into its start
values (`cargo xtask fmu --nx --ny --modes`).

What Ecos does with an SSP (its loader, src/ecos/ssp/ssp.cpp and
ssp_loader.cpp, and the tests here):

- it can: unzip the archive and load the components' FMUs from it, two
  files with the same model identifier side by side (so each sheet has its
  own grid, where test_ecos.py's chain, one file for both, gives B A's
  grid); apply the components' SSV parameter sets (Real, Integer, Boolean,
  String) by the name given to init(); connect Real connectors with an
  ssc:LinearTransformation (value * factor + offset: with factor 1 and
  offset -p0 the relative anchor v - p0, bit for bit);
- it cannot: apply a parameter set before Initialization Mode (it sets the
  values after fmi3EnterInitializationMode, where the FMU refuses
  structural parameters, hence the baked grids); read SSP 2.0 (any version
  but "1.0" is refused) or ssv:Enumeration (the archive does not load; an
  enumeration is no variable of an Ecos model anyway); read the files with
  other namespace prefixes than ssd:, ssc:, ssv: (it matches element names
  as written); use units, parameter mappings, bindings or connectors of the
  system itself, nested systems or the default experiment (but for a
  scenario in its annotations): the step is EcosSimulation's argument.
  Only scalar outputs are recorded (arrays: test_ecos.py).

Skipped when ecospy cannot be loaded, except on CI (CI=true), where that fails.
"""

import re
import shutil
import subprocess
import sys
import zipfile

import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.ssp.ssd import read_ssd
from lxml import etree

from conftest import ROOT, fmu_path, target_dir

sys.path.insert(0, str(ROOT / "python"))
import chain  # noqa: E402
# ecospy's import and the skip, the helpers of the programmatic chain test
from test_ecos import EcosLib, EcosSimulation, assert_bitwise, fmu_messages, recorded_run  # noqa: E402

NS = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
}
GRID = ("nx", "ny", "nModes")
PARAMETER_SET = "chain"
H, STOP = 2.0**-8, 3.0


def chain_ssp(anchor):
    """target/ssp/chain[-absolute].ssp, made by `cargo xtask ssp` when
    missing or older than the default FMU or python/chain.py."""
    path = target_dir() / "ssp" / ("chain.ssp" if anchor == "relative" else "chain-absolute.ssp")
    newest = max(p.stat().st_mtime for p in (fmu_path(), ROOT / "python" / "chain.py"))
    if not path.exists() or path.stat().st_mtime < newest:
        subprocess.run(["cargo", "xtask", "ssp", "--anchor", anchor], cwd=ROOT, check=True)
    return path


@pytest.fixture(scope="module", params=["relative", "absolute"])
def ssp(request):
    """(anchor convention, archive, chain.run_master's Jacobi run with it)"""
    anchor = request.param
    ref = chain.run_master(fmu_path(), H, STOP, scheme="jacobi", anchor=anchor)
    assert ref["messages"] == []
    return anchor, chain_ssp(anchor), ref


def ecos_ssp_run(path, h, stop, recorded, parameter_set=PARAMETER_SET):
    """Runs the archive in Ecos at the fixed step h up to stop; {"time": ...,
    name: ...} for every "instance::name" of recorded at every
    communication point (t = 0 after initialization included)."""
    EcosLib.set_log_level("debug")
    with EcosSimulation(step_size=h, ssp_path=str(path)) as sim:
        return recorded_run(sim, h, stop, recorded, parameter_set)


def test_the_archive_is_chain_py(ssp, tmp_path):
    """The SSD and the SSVs are valid SSP 1.0 (fmpy's reader validates them
    against the standard's schemas); the connections are chain.LINKS, the
    parameter sets chain.SHEETS and chain.COMMON less the grid, and each
    sheet's FMU has its grid as start values."""
    anchor, path, ref = ssp
    ssd = read_ssd(str(path))
    assert ssd.version == "1.0"
    components = {c.name: c for c in ssd.system.elements}
    assert sorted(components) == sorted(chain.SHEETS)
    assert [(c.startElement, c.startConnector, c.endElement, c.endConnector) for c in ssd.system.connections] == chain.LINKS

    root = etree.fromstring(zipfile.ZipFile(path).read("SystemStructure.ssd"))
    for c in root.findall(".//ssd:Connection", NS):
        t = c.find("ssc:LinearTransformation", NS)
        if anchor == "relative" and c.get("endConnector").startswith("anchor"):
            axis = "XY".index(c.get("endConnector")[-1])
            assert (float(t.get("factor")), float(t.get("offset"))) == (1.0, -ref["A.restNode"][axis])
        else:
            assert t is None

    zipfile.ZipFile(path).extractall(tmp_path)
    for name, c in components.items():
        [binding] = c.parameterBindings
        [ps] = binding.parameterValues
        assert ps.name == PARAMETER_SET
        values = {p.name: (p.type, p.value) for p in ps.parameters}
        want = {k: v for k, v in {**chain.SHEETS[name], **chain.COMMON}.items() if k not in GRID}
        assert sorted(values) == sorted(want)
        for k, v in want.items():
            ty, text = values[k]
            assert (ty, float(text)) == ("Integer" if isinstance(v, int) else "Real", v), f"{name}.{k}"
        md = {v.name: v for v in read_model_description(str(tmp_path / c.source)).modelVariables}
        assert [int(md[k].start) for k in GRID] == [chain.SHEETS[name][k] for k in GRID], name
    # the two sheets have grids of their own
    assert [chain.SHEETS["A"][k] for k in GRID] != [chain.SHEETS["B"][k] for k in GRID]


def test_ecos_runs_the_archive_as_the_jacobi_master_bit_for_bit(ssp, capfd):
    """Every recorded value (chain.RECORDED, inputs included) at every
    communication point is chain.run_master's with the same anchor
    convention, B on its own 3 x 3 grid; nothing logged by the FMUs."""
    anchor, path, ref = ssp
    recorded = [n.replace(".", "::") for n in chain.RECORDED]
    e = ecos_ssp_run(path, H, STOP, recorded)
    logged = fmu_messages(capfd.readouterr().out)
    assert logged == []
    assert np.array_equal(e["time"], ref["time"])
    assert_bitwise(e, ref, chain.RECORDED, lambda n: n.replace(".", "::"))
    print(f"\nEcos, {path.name} ({anchor} anchor): bit for bit chain.run_master (Jacobi) over {len(ref['time'])} points; "
          f"A's load node swings {np.ptp(ref['A.loadNodeX']):.3g} m sideways, B's pull {np.ptp(ref['B.anchorForceY']):.3g} N")
    # a motion, with A's loadColumn = 1 from the parameter set: the pair swings sideways
    assert np.ptp(ref["A.loadNodeX"]) > 1e-3 and np.ptp(ref["B.loadNodeY"]) > 1e-3


def rewritten(path, tmp_path, name, edit):
    """A copy of the archive with the file `name` passed through edit(text)."""
    out = tmp_path / path.name
    with zipfile.ZipFile(path) as src, zipfile.ZipFile(out, "w") as dst:
        for item in src.infolist():
            data = src.read(item.filename)
            if item.filename == name:
                new = edit(data.decode())
                assert new != data.decode()
                data = new.encode()
            dst.writestr(item, data)
    return out


@pytest.mark.parametrize("change", ["SSP 2.0", "an enumeration"])
def test_what_ecos_refuses(ssp, tmp_path, change):
    """Ecos refuses an SSD of another version than 1.0, and a parameter set
    with an enumeration (ssv:Enumeration, SSV 1.0)."""
    _, path, _ = ssp
    if change == "SSP 2.0":
        broken = rewritten(path, tmp_path, "SystemStructure.ssd", lambda s: s.replace(' version="1.0" generationTool', ' version="2.0" generationTool'))
        message = "Unsupported SSP version"
    else:
        item = '<ssv:Parameter name="integrator"><ssv:Enumeration value="newmark-explicit"/></ssv:Parameter>'
        broken = rewritten(path, tmp_path, "resources/A.ssv", lambda s: s.replace("<ssv:Parameters>", "<ssv:Parameters>" + item, 1))
        message = "Unknown XML node in ssv:Parameter"
    with pytest.raises(Exception, match=re.escape(message)):
        EcosSimulation(step_size=H, ssp_path=str(broken))
    shutil.rmtree(tmp_path, ignore_errors=True)
