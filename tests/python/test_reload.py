"""A host that closes and reopens the FMU's library while instances live.

Ecos closes the binary (dlclose) and opens it again (dlopen) to make a
second instance of the same FMU file while the first one lives. A library
that is really unloaded forgets its instances, so every later call on the
first one would be refused. The FMU pins itself in memory at its first
instantiation (RTLD_NODELETE), so instances made before a reload keep
working; a pointer it does not know is refused with a line on stderr,
since no instance means no logger. Reproduced here with ctypes alone.
"""

import subprocess
import sys
import textwrap
from pathlib import Path

from conftest import fmu_path

OK, ERROR = 0, 3

SCRIPT = textwrap.dedent(
    """
    import ctypes, _ctypes, sys
    path, token = sys.argv[1], sys.argv[2].encode()

    def open_library():
        lib = ctypes.CDLL(path)
        lib.fmi3InstantiateCoSimulation.restype = ctypes.c_void_p
        lib.fmi3InstantiateCoSimulation.argtypes = [ctypes.c_char_p, ctypes.c_char_p, ctypes.c_char_p] + [ctypes.c_bool] * 4 + [
            ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p]
        lib.fmi3EnterInitializationMode.argtypes = [ctypes.c_void_p, ctypes.c_bool, ctypes.c_double, ctypes.c_double, ctypes.c_bool, ctypes.c_double]
        lib.fmi3ExitInitializationMode.argtypes = [ctypes.c_void_p]
        lib.fmi3FreeInstance.argtypes = [ctypes.c_void_p]
        lib.fmi3FreeInstance.restype = None
        return lib

    def instantiate(lib, name):
        return lib.fmi3InstantiateCoSimulation(name, token, None, False, False, False, False, None, 0, None, None, None)

    first_lib = open_library()
    first = instantiate(first_lib, b"first")
    assert first
    _ctypes.dlclose(first_lib._handle)  # what Ecos does before its second instance
    lib = open_library()
    second = instantiate(lib, b"second")
    assert second
    statuses = [lib.fmi3EnterInitializationMode(first, False, 0.0, 0.0, False, 0.0), lib.fmi3ExitInitializationMode(first)]
    # A pointer no instance of this library ever had.
    stranger = ctypes.create_string_buffer(64)
    statuses.append(lib.fmi3ExitInitializationMode(ctypes.addressof(stranger)))
    lib.fmi3FreeInstance(second)
    lib.fmi3FreeInstance(first)
    print(*statuses)
    """
)


def test_instances_survive_a_reload_of_the_library(tmp_path):
    from fmpy import extract, read_model_description

    fmu = fmu_path()
    md = read_model_description(str(fmu))
    unzipped = Path(extract(str(fmu), str(tmp_path / "fmu")))
    binary = unzipped / "binaries" / "x86_64-linux" / f"{md.coSimulation.modelIdentifier}.so"
    # A fresh process: the library must be loaded by nobody but this script.
    run = subprocess.run([sys.executable, "-c", SCRIPT, str(binary), md.instantiationToken], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    enter, exit_, stranger = (int(s) for s in run.stdout.split())
    assert (enter, exit_) == (OK, OK), f"the first instance was lost when the library was reopened: {enter}, {exit_}"
    assert stranger == ERROR
    assert "not a live instance of this FMU" in run.stderr, run.stderr
