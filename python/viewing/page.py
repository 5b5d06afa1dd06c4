"""What one browser page sees and steers: its own FMU instance (a Session),
a thread that steps it in real time, and what goes to the page.

To the page (viewing/static/view.js draws it): once per instance a JSON
"instance" message (grid, springs, holders, the load node, the modes'
frequencies and classes, the controls' values) and one binary message of
the rest shape x* and the modeShapes Phi (float32); then each frame a small
binary message. For a modal run that is q (modalCoordinates) and each
holder's placement (R, t): the page draws node i at R_h (x*_i + Phi_i q) + t_h,
h its holder (holder 1 for a free node), the `positions` the FMU reports
(Phi is 0 on held nodes; the sheet is integrated in holder 1's frame,
src/physics/run/simulator/outputs.rs). A run that does not expand so (full
space, adaptive, or a modal run whose expansion is found off the FMU's
positions by more than EXPANDS m) gets its positions each frame instead.
Readouts, the FMU's warnings and every refusal go as JSON twice a second.

From the page: the JSON control messages of viewing/protocol.py."""

import math
import struct
import sys
import threading
import time

import numpy as np

from viewing.protocol import CLASSES, parse
from viewing.session import STRONGEST_PULL, Clock, Refused, Session

PULL_LENGTH = 0.1
# Highest speed [m/s], turn rate [rad/s] and time constant [s] of a holder following its handle (the turn
# rate also at most HOLDER_SPEED over the sheet's reach from the pivot)
# (the FMU refuses a holder whose velocity jumps by more than a step can take).
HOLDER_SPEED = 1.0
HOLDER_TURN = 0.5
HOLDER_LAG = 0.05
MODE_SLIDERS = 24
# The part of a frame's time the stepping may take.
STEPPING = 0.7
# How far [m] the page's expansion may be from the FMU's positions (else positions are sent).
EXPANDS = 1e-6
# Binary messages: a uint32 kind and a uint32 frame number, then float32 values.
SHAPES, MODAL, POSITIONS = 0, 1, 2


def rotation_vector(xyzw):
    """The rotation vector (axis times angle) of a unit quaternion (x, y, z, w)."""
    v, w = np.asarray(xyzw[:3], dtype=float), float(xyzw[3])
    s = np.linalg.norm(v)
    if s < 1e-12:
        return np.zeros(3)
    angle = 2.0 * np.arctan2(s, w)
    if angle > np.pi:
        angle -= 2.0 * np.pi
    return v / s * angle


def rotation(theta):
    """The rotation matrix of a rotation vector (Rodrigues), as the FMU's frame.rs makes it."""
    angle = float(np.linalg.norm(theta))
    if angle == 0.0:
        return np.eye(3)
    k = np.asarray(theta, dtype=float) / angle
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * (K @ K)


def in_class(session, name):
    """Which modes belong to a class (modeOutOfPlane and modeSymmetry, variables.toml)."""
    return {
        "in-plane": session.out_of_plane < 0.5,
        "out-of-plane": session.out_of_plane >= 0.5,
        "symmetric": session.symmetry > 0.5,
        "antisymmetric": session.symmetry < -0.5,
    }[name]


def as3(x):
    """Positions as (nodes, 3) (z = 0 in 2D)."""
    out = np.zeros((len(x), 3))
    out[:, : x.shape[1]] = x
    return out


class Page:
    """One page: its session, its stepping thread and what it sends (`send(bytes | dict)`, thread-safe)."""

    def __init__(self, send, fmu, scenes, scene_name, fps=60.0, label="page"):
        self.send, self.fmu, self.scenes, self.fps, self.label = send, fmu, scenes, fps, label
        self.lock = threading.RLock()
        self.playing, self.stopped = True, False
        self.refusals = []
        self.frames_sent, self.rate, self.rtf = 0, 0.0, 0.0
        self.session = None
        self.start(scene_name)
        self.thread = threading.Thread(target=self._loop, name=label, daemon=True)
        self.thread.start()

    # ---- set-up -------------------------------------------------------

    def start(self, scene_name):
        """A new instance of the scene (the old one freed)."""
        with self.lock:
            try:
                fresh = Session(self.fmu, self.scenes[scene_name], label=self.label)
            except Refused as e:
                self.refuse(f"scene {scene_name}: {e}")
                return
            if self.session is not None:
                self.session.close()
            self.session, self.scene_name = fresh, scene_name
            s = fresh
            self.clock = Clock(s.h)
            self.target = np.zeros((s.n_holders, 6))
            self.pull = None
            self.pivots = [as3(s.start[h[:1]])[0] if len(h) else np.zeros(3) for h in s.holders]
            # How far the sheet reaches from each pivot: a turn moves its far end at most HOLDER_SPEED.
            self.reach = [float(np.linalg.norm(as3(s.start) - p, axis=1).max()) or 1.0 for p in self.pivots]
            self.holder_of = np.zeros(s.n, dtype=np.int64)
            for k, nodes in enumerate(s.holders):
                self.holder_of[np.asarray(nodes, dtype=np.int64)] = k
            self.shapes = s.mode_shapes() if s.r else np.zeros((0, s.n, s.dim))
            q0 = self._coordinates()
            self.rest = s.start - np.tensordot(q0, self.shapes, 1)
            self.modal = s.reduction == 1 and s.r > 0
            self._send_instance()
            self.send(self.frame())
            self.frames_sent += 1
            self.sent_time = s.time

    def _coordinates(self):
        s = self.session
        return np.atleast_1d(np.asarray(self.fmu.get(s.inst, "modalCoordinates", s.r), dtype=float)) if s.r else np.zeros(0)

    def _send_instance(self):
        s = self.session
        members = {c: int(np.count_nonzero(in_class(s, c))) for c in CLASSES}
        self.send(
            {
                "type": "instance",
                "scene": self.scene_name,
                "scenes": list(self.scenes),
                "nx": s.nx, "ny": s.ny, "dim": s.dim, "nodes": s.n, "modes": s.r,
                "modal": self.modal,
                "springs": s.springs.tolist(),
                "holders": [[int(i) for i in h] for h in s.holders],
                "holderOf": self.holder_of.tolist(),
                "loadNode": int(s.load_node),
                "pivots": [p.tolist() for p in self.pivots],
                "frequencies": s.frequencies.tolist(),
                "classes": members,
                "takesWeights": s.reduction == 1,
                "modeSliders": min(s.r, MODE_SLIDERS) if s.reduction == 1 else 0,
                "pullLength": PULL_LENGTH,
                **self._controls(),
            }
        )
        self.send(self._binary(SHAPES, np.concatenate([as3(self.rest).ravel(), np.stack([as3(p) for p in self.shapes]).ravel() if s.r else []])))

    def _controls(self):
        """The controls as the session has them (after a change or a refusal)."""
        s = self.session
        g = s.gravity
        size = float(np.linalg.norm(g))
        turn = math.degrees(math.atan2(g[0], -g[1])) if size else 0.0
        out = math.degrees(math.asin(max(-1.0, min(1.0, g[2] / size)))) if size else 0.0
        return {
            "gravity": {"size": size, "turn": turn, "out": out},
            "damping": {"alpha": float(s.damping[0]), "beta": float(s.damping[1])},
            "weights": s.weights.tolist(),
            "playing": self.playing,
        }

    def _binary(self, kind, values):
        return struct.pack("<II", kind, self.frames_sent) + np.asarray(values, dtype="<f4").tobytes()

    # ---- controls -----------------------------------------------------

    def refuse(self, why):
        self.refusals.append(why)
        del self.refusals[:-5]
        print(f"view: {self.label}: refused: {why}", file=sys.stderr)
        self.send({"type": "refused", "why": why})

    def receive(self, raw):
        """A message from the page: checked (viewing/protocol.py), then acted on; a refusal changes nothing."""
        with self.lock:
            try:
                kind, m = parse(raw)
                if self.session is None:
                    return
                getattr(self, "_on_" + kind)(**m)
            except Refused as e:
                self.refuse(str(e))
            if self.session is not None:
                self.send({"type": "controls", **self._controls()})

    def _on_play(self, playing):
        self.playing = playing
        self.clock.resume(self.session.time)

    def _on_reset(self):
        self.start(self.scene_name)

    def _on_scene(self, name):
        if name not in self.scenes:
            raise Refused(f"scene {name!r}: not one of {', '.join(self.scenes)}")
        self.start(name)

    def _on_gravity(self, size, turn, out):
        t, o = math.radians(turn), math.radians(out)
        if self.session.dim == 2 and out != 0.0:
            raise Refused("gravity: a 2D sheet takes no gravity out of its plane")
        self.session.set_gravity(size * np.array([math.sin(t) * math.cos(o), -math.cos(t) * math.cos(o), math.sin(o)]))

    def _on_damping(self, alpha, beta):
        self.session.set_damping(alpha, beta)

    def _on_classWeight(self, **m):  # noqa: N802 (the protocol's name)
        w = self.session.weights.copy()
        w[in_class(self.session, m["class"])] = m["value"]
        self.session.set_weights(w)

    def _on_modeWeight(self, mode, value):  # noqa: N802
        if not mode < min(self.session.r, MODE_SLIDERS):
            raise Refused(f"modeWeight.mode: {mode} is not one of the {min(self.session.r, MODE_SLIDERS)} modes with a slider")
        w = self.session.weights.copy()
        w[mode] = value
        self.session.set_weights(w)

    def _on_holder(self, holder, position, quaternion):
        s = self.session
        if holder >= s.n_holders:
            raise Refused(f"holder {holder}: the scene has {s.n_holders}")
        offset = np.asarray(position) - self.pivots[holder]
        turn = rotation_vector(quaternion)
        if s.dim == 2 and (offset[2] != 0.0 or np.any(turn[:2] != 0.0)):
            raise Refused("holder: a 2D sheet's holder moves in its plane and turns about z only")
        self.target[holder] = s.checked_anchor(holder, offset, turn)

    def _on_pull(self, position):
        s = self.session
        if position is None:
            self.pull = None
            s.set_load(np.zeros(3))
        else:
            self.pull = np.asarray(position)[: s.dim]

    # ---- stepping -----------------------------------------------------

    def _follow(self):
        """Holders toward their handles at a bounded speed; the load node's pull."""
        s = self.session
        a = 1.0 - np.exp(-s.h / HOLDER_LAG)
        for k in range(s.n_holders):
            step = a * (self.target[k] - s.anchors[k])
            most = HOLDER_SPEED * s.h
            reach = np.linalg.norm(step[:3])
            if reach > most:
                step[:3] *= most / reach
            turn, most = np.linalg.norm(step[3:]), min(HOLDER_TURN, HOLDER_SPEED / self.reach[k]) * s.h
            if turn > most:
                step[3:] *= most / turn
            s.set_anchor(k, s.anchors[k][:3] + step[:3], s.anchors[k][3:] + step[3:])
        if self.pull is not None:
            x = s.positions()[s.load_node]
            pull = np.zeros(3)
            pull[: s.dim] = (self.pull - x) * (s.weight / PULL_LENGTH)
            limit = 0.9 * STRONGEST_PULL * s.weight
            norm = np.linalg.norm(pull)
            s.set_load(pull * min(1.0, limit / norm) if norm > 0 else pull)

    def _advance(self):
        """The steps the clock asks for, for at most STEPPING of a frame's time (a run too slow
        for real time falls behind, and the page still gets its frames)."""
        s = self.session
        due = self.clock.due(s.time) if self.playing else 0
        end = time.perf_counter() + STEPPING / self.fps
        for _ in range(due):
            if time.perf_counter() > end:
                break
            anchors = s.anchors.copy()
            self._follow()
            try:
                s.step()
            except Refused as e:
                # The FMU kept its last good state, its holders where they were: so do the session and the handles.
                s.anchors[:] = anchors
                self.target[:] = anchors
                self.playing = False
                self.refuse(str(e) + " (paused at the last good state)")
                self.send({"type": "controls", **self._controls(), "anchors": s.anchors.tolist()})  # the handles back too
                break

    def placements(self):
        """Each holder's (R, t): world = R x + t for x in holder 1's frame (holder 1) or at rest (the others)."""
        s, out = self.session, []
        for k in range(s.n_holders):
            r = rotation(s.anchors[k][3:])
            out.append((r, self.pivots[k] + s.anchors[k][:3] - r @ self.pivots[k]))
        return out

    def expanded(self, q):
        """The positions the page draws from q (what view.js computes), (nodes, dimension)."""
        s = self.session
        x = as3(self.rest + np.tensordot(q, self.shapes, 1))
        for k, (r, t) in enumerate(self.placements()):
            on = self.holder_of == k  # holder 1's frame: its nodes and every free node
            x[on] = x[on] @ r.T + t
        return x[:, : s.dim]

    def frame(self):
        """This frame's binary message."""
        s = self.session
        if self.modal:
            q = self._coordinates()
            placed = np.concatenate([np.concatenate([r.ravel(), t]) for r, t in self.placements()])
            return self._binary(MODAL, np.concatenate([q, placed]))
        return self._binary(POSITIONS, as3(s.positions()).ravel())

    def _check_expansion(self):
        """A modal run whose expansion is off the FMU's positions gets positions from now on."""
        if self.modal:
            off = float(np.abs(self.expanded(self._coordinates()) - self.session.positions()).max())
            if off > EXPANDS:
                self.modal = False
                self.send({"type": "note", "text": f"the modes expand {off:.2g} m off the FMU's positions: positions are sent"})

    def _read_out(self):
        s = self.session
        r = s.readouts()
        self.send(
            {
                "type": "readouts",
                "time": s.time,
                "rtf": self.rtf,
                "rate": self.rate,
                "playing": self.playing,
                "readouts": finite(r),
                "warnings": [f"{status}: {text}" for status, _, text in s.messages if status != "OK"][-5:],
                "refusals": self.refusals[-5:],
                "expanded": self.modal,
            }
        )

    def _loop(self):
        period = 1.0 / self.fps
        mark, frames0, sim0 = time.perf_counter(), 0, 0.0
        next_frame = time.perf_counter()
        while not self.stopped:
            with self.lock:
                if self.session is None:
                    break
                self._advance()
                if self.session.time != self.sent_time:  # paused: nothing new to draw
                    self.send(self.frame())
                    self.frames_sent += 1
                    self.sent_time = self.session.time
                now = time.perf_counter()
                if now - mark >= 0.5:
                    self.rate = (self.frames_sent - frames0) / (now - mark)
                    self.rtf = (self.session.time - sim0) / (now - mark) if self.playing else 0.0
                    self._check_expansion()
                    self._read_out()
                    mark, frames0, sim0 = now, self.frames_sent, self.session.time
            next_frame += period
            delay = next_frame - time.perf_counter()
            if delay > 0:
                time.sleep(delay)
            else:
                next_frame = time.perf_counter()

    def close(self):
        """Stops the thread and frees the instance (the page disconnected)."""
        self.stopped = True
        if threading.current_thread() is not self.thread:
            self.thread.join(timeout=5.0)
        with self.lock:
            if self.session is not None:
                self.session.close()
                self.session = None

    def status(self):
        """What a test reads: the instance's time, playing, frames sent, the rates, the refusals."""
        with self.lock:
            s = self.session
            return {
                "time": s.time if s else None,
                "playing": self.playing,
                "frames": self.frames_sent,
                "rate": self.rate,
                "rtf": self.rtf,
                "refusals": list(self.refusals),
                "anchors": s.anchors.copy() if s else None,
                "weights": s.weights.copy() if s else None,
                "load_node": s.positions()[s.load_node].copy() if s else None,
                "holder_force": s.readouts()["holder 1 force"] if s else None,
            }


def finite(value):
    """Numbers that are not finite as null (JSON has no NaN)."""
    if isinstance(value, dict):
        return {k: finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [finite(v) for v in value]
    return value if not isinstance(value, float) or math.isfinite(value) else None
