"""A serialized FMU state written by an earlier build of the FMU still loads
and resumes the run bit for bit.

``data/fmu_state_format5.bin`` was written by the default FMU as built at
commit 69a8742 (serialized-state format 5): default scene, 30 steps of
0.01 s from rest with gravity turned to (2, -9.81, 0) m/s^2 before the
11th, then fmi3GetFMUState and fmi3SerializeFMUState. That build then took
50 more steps of 0.01 s; ``RESUMED_SHA256`` is the SHA-256 of the node
positions after each of them (little-endian float64, in order), as the
build of commit c9cb41d takes them: its Phi^T f (faer's matrix-vector
product) moves them by at most 2.2e-16 m from the recording build's
(84b03c70...). The FMU
under test must deserialize the bytes and take the same 50 steps to the
bit. A change of the byte format or of the arithmetic of the default run
fails here: the first must keep reading format-5 states (or refuse them
with a reason, and this record be regenerated on purpose), the second is a
change of behaviour the trajectories test names too.
"""

import hashlib
from pathlib import Path

import numpy as np

DATA = Path(__file__).parent / "data" / "fmu_state_format5.bin"
SAVED_AT = 0.3000000000000001  # the FMU time in the state: 30 steps of 0.01 s
RESUMED_SHA256 = "1d6134a5ff8f5d112fb97aded31a4a24fb8b1500ae58be655365db1e48f14b84"


def test_a_state_serialized_by_an_earlier_build_resumes_bit_for_bit(new_instance):
    inst = new_instance()
    inst.initialize()
    state = inst.slave.deserializeFMUState(DATA.read_bytes())
    inst.slave.setFMUState(state)
    inst.slave.freeFMUState(state)
    digest = hashlib.sha256()
    for k in range(50):
        inst.slave.doStep(currentCommunicationPoint=SAVED_AT + 0.01 * k, communicationStepSize=0.01)
        digest.update(np.asarray(inst.positions(), dtype="<f8").tobytes())
    assert digest.hexdigest() == RESUMED_SHA256
