"""What a page may send the view's server: JSON objects, each with a "type"
and exactly the fields of that type, each of its kind (a finite number in
its range, a string of a set, a list of so many numbers). Anything else —
text that is not JSON, a binary frame, an unknown type, a missing or extra
field, NaN, 1e308 where a slider goes to 30 — is Refused with the reason,
before the session sees it; the page gets the reason back and the server's
stderr a line, and the connection goes on.

Ranges here are the controls' own; the session checks again what the FMU
takes (viewing/session.py)."""

import json
import math

from viewing.session import Refused

CLASSES = ("in-plane", "out-of-plane", "symmetric", "antisymmetric")
# The largest message a page sends (a holder drag: well under 1 kB).
LONGEST = 4096


def number(lo, hi):
    def check(name, v):
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise Refused(f"{name}: {v!r} is not a number")
        if not math.isfinite(v):
            raise Refused(f"{name}: {v!r} is not finite")
        if not lo <= v <= hi:
            raise Refused(f"{name}: {v!r} is outside [{lo}, {hi}]")
        return float(v)

    return check


def integer(lo, hi):
    def check(name, v):
        if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
            raise Refused(f"{name}: {v!r} is not a whole number in [{lo}, {hi}]")
        return v

    return check


def vector(count, lo, hi):
    each = number(lo, hi)

    def check(name, v):
        if not isinstance(v, list) or len(v) != count:
            raise Refused(f"{name}: {v!r} is not a list of {count} numbers")
        return [each(f"{name}[{i}]", x) for i, x in enumerate(v)]

    return check


def flag(name, v):
    if not isinstance(v, bool):
        raise Refused(f"{name}: {v!r} is not true or false")
    return v


def text(longest=100):
    def check(name, v):
        if not isinstance(v, str) or len(v) > longest:
            raise Refused(f"{name}: {v!r} is not a name")
        return v

    return check


def one_of(names):
    def check(name, v):
        if v not in names:
            raise Refused(f"{name}: {v!r} is not one of {', '.join(names)}")
        return v

    return check


def optional(check):
    return lambda name, v: None if v is None else check(name, v)


# type -> {field: check}
MESSAGES = {
    "play": {"playing": flag},
    "reset": {},
    "scene": {"name": text()},
    "gravity": {"size": number(0.0, 30.0), "turn": number(-180.0, 180.0), "out": number(-90.0, 90.0)},
    "damping": {"alpha": number(0.0, 5.0), "beta": number(0.0, 0.01)},
    "classWeight": {"class": one_of(CLASSES), "value": number(0.0, 2.0)},
    "modeWeight": {"mode": integer(0, 100_000), "value": number(0.0, 2.0)},
    # A holder's handle where the page has it: its position (world, m) and turn (unit quaternion x, y, z, w).
    "holder": {"holder": integer(0, 64), "position": vector(3, -1e3, 1e3), "quaternion": vector(4, -1.0, 1.0)},
    # The load node's handle while dragged (null: let go).
    "pull": {"position": optional(vector(3, -1e3, 1e3))},
}


def parse(raw):
    """A page's message (a text frame) as (type, {field: value}), or Refused saying why not."""
    if not isinstance(raw, str):
        raise Refused(f"a {type(raw).__name__} frame where a JSON text message is expected")
    if len(raw) > LONGEST:
        raise Refused(f"a message of {len(raw)} characters (at most {LONGEST})")
    try:
        message = json.loads(raw, parse_constant=lambda c: c)
    except ValueError as e:
        raise Refused(f"not JSON ({e})") from None
    if not isinstance(message, dict):
        raise Refused(f"{message!r:.80} is not an object with a type")
    kind = message.get("type")
    if kind not in MESSAGES:
        raise Refused(f"type {kind!r:.40}: not one of {', '.join(MESSAGES)}")
    fields = MESSAGES[kind]
    extra = set(message) - set(fields) - {"type"}
    missing = set(fields) - set(message)
    if extra or missing:
        raise Refused(f"{kind}: fields {sorted(fields)} expected ({'extra ' + str(sorted(extra)) if extra else 'missing ' + str(sorted(missing))})")
    out = {name: check(f"{kind}.{name}", message[name]) for name, check in fields.items()}
    if kind == "holder":
        q = out["quaternion"]
        if abs(math.fsum(x * x for x in q) - 1.0) > 1e-3:
            raise Refused(f"holder.quaternion: {q} is not of unit length")
    return kind, out
