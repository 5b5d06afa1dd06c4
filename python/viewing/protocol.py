"""The view server's guard on viser's incoming messages (viser==1.1.1, as
setup pins it): viser decodes each websocket message of a page and, when
the bytes are not a message of its protocol, ends that page's connection
(and so its FMU instance). With the guard such bytes are refused — a line on
the server's stderr says why — and the page, its instance and its run go on.
"""

import sys

import viser.infra._infra as infra

REFUSED = []


async def _guarded_consumer(websocket, handle_message, message_class):
    """viser's message loop, with undecodable messages refused instead of fatal."""
    while True:
        raw = await websocket.recv()
        try:
            if not isinstance(raw, bytes):
                raise TypeError(f"a {type(raw).__name__} frame where bytes are expected")
            message = message_class.deserialize(raw)
        except Exception as e:  # whatever the decoder raises, the bytes are refused
            REFUSED.append(str(e))
            del REFUSED[:-20]
            print(f"view: refused a message that is not viser's protocol ({type(e).__name__}: {e})", file=sys.stderr)
            continue
        handle_message(message)


def guard():
    """Installs the guard (idempotent)."""
    infra._message_consumer = _guarded_consumer
