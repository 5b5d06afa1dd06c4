"""What one browser page sees and steers: its own FMU instance (a
Session), the sheet drawn with viser's scene nodes and its controls in
viser's GUI panel, and a thread that steps the instance in real time and
sends a frame at the page's frame rate.

Drawn: the springs as line segments and every node as a point (sheets up to
LINE_NODES nodes), larger sheets as a surface through the nodes; the held
nodes in red with a handle per holder (drag it to move the holder: its
anchor inputs), the load node in orange with a handle (drag it to pull the
node: the load inputs, a spring of one sheet weight per PULL_LENGTH).
Readouts: simulated time, real-time factor, frames per second, kinetic and
potential energy, each holder's force, forceResidual, trainingRange,
errorEstimate, reducedFraction; the FMU's warnings and every refused value
below them."""

import threading
import time

import numpy as np

from viewing.session import STRONGEST_PULL, Clock, Refused, Session

LINE_NODES = 2500
PULL_LENGTH = 0.1
# Highest speed [m/s] and time constant [s] of a holder following its handle
# (the FMU refuses a holder whose velocity jumps by more than a step can take).
HOLDER_SPEED = 1.0
HOLDER_LAG = 0.05
MODE_SLIDERS = 24
# Modes the gallery shows at once.
GALLERY = 6
CLASSES = ("in-plane", "out-of-plane", "symmetric", "antisymmetric")


def rotation_vector(wxyz):
    """The rotation vector (axis times angle) of a unit quaternion (w, x, y, z)."""
    w, v = float(wxyz[0]), np.asarray(wxyz[1:], dtype=float)
    s = np.linalg.norm(v)
    if s < 1e-12:
        return np.zeros(3)
    angle = 2.0 * np.arctan2(s, w)
    if angle > np.pi:
        angle -= 2.0 * np.pi
    return v / s * angle


def in_class(session, name):
    """Which modes belong to a class (modeOutOfPlane and modeSymmetry, variables.toml)."""
    return {
        "in-plane": session.out_of_plane < 0.5,
        "out-of-plane": session.out_of_plane >= 0.5,
        "symmetric": session.symmetry > 0.5,
        "antisymmetric": session.symmetry < -0.5,
    }[name]


def grid_faces(nx, ny):
    """Two triangles per grid cell (node i = row * nx + col)."""
    r, c = np.meshgrid(np.arange(ny - 1), np.arange(nx - 1), indexing="ij")
    a = (r * nx + c).ravel()
    return np.concatenate([np.stack([a, a + 1, a + nx], 1), np.stack([a + 1, a + nx + 1, a + nx], 1)]).astype(np.uint32)


def as3(x):
    """Positions as (nodes, 3) float32 (z = 0 in 2D)."""
    out = np.zeros((len(x), 3), dtype=np.float32)
    out[:, : x.shape[1]] = x
    return out


class Page:
    """One page: its session, scene nodes, controls and stepping thread."""

    def __init__(self, client, fmu, scenes, scene_name, fps=60.0):
        self.client, self.fmu, self.scenes, self.fps = client, fmu, scenes, fps
        self.lock = threading.RLock()
        self.playing, self.stopped = True, False
        self.refusals = []
        self.frames_sent, self.rate, self.rtf = 0, 0.0, 0.0
        self.session = None
        self.gui_nodes = []
        self._build_run_panel(scene_name)
        self.start(scene_name)
        self.thread = threading.Thread(target=self._loop, name=f"page-{client.client_id}", daemon=True)
        self.thread.start()

    # ---- set-up -------------------------------------------------------

    def start(self, scene_name):
        """A new instance of `scene_name` (a structural change makes a new instance)."""
        with self.lock:
            old, self.session = self.session, None
            if old is not None:
                old.close()
            self.scene_name = scene_name
            values = self.scenes[scene_name]
            self.session = Session(self.fmu, values, label=f"page {self.client.client_id}")
            self.clock = Clock(self.session.h)
            s = self.session
            self.target = s.anchors.copy()
            self.dragging_load = False
            self._build_scene()
            self._build_controls()
            self._note(f"scene {scene_name}: {s.nx} x {s.ny} nodes, {s.dim}D, {s.r} modes, {len(s.springs)} springs")

    def _build_run_panel(self, scene_name):
        gui = self.client.gui
        with gui.add_folder("Run"):
            self.play = gui.add_button("Pause")
            self.play.on_click(lambda _: self.toggle())
            reset = gui.add_button("Reset")
            reset.on_click(lambda _: self.start(self.scene_name))
            self.picker = gui.add_dropdown("Scene", tuple(self.scenes), initial_value=scene_name)
            self.picker.on_update(lambda _: self._pick(self.picker.value))
            self.readout = gui.add_markdown("starting")
            self.log = gui.add_markdown("")

    def _pick(self, name):
        if name not in self.scenes:
            self.refuse(f"scene {name!r}: not one of {', '.join(self.scenes)}")
            return
        self.start(name)

    def _build_scene(self):
        s, scene = self.session, self.client.scene
        # (no set_up_direction: it also turns the world about the up axis; the camera says where up is)
        x = as3(s.start)
        self.big = s.n > LINE_NODES
        if self.big:
            self.faces = grid_faces(s.nx, s.ny)
            self.sheet = scene.add_mesh_simple("/sheet", x, self.faces, color=(90, 160, 230), side="double", flat_shading=False)
            self.nodes = None
        else:
            self.sheet = scene.add_line_segments("/sheet", x[s.springs], (60, 120, 200), thickness=0.004)
            self.nodes = scene.add_point_cloud("/nodes", x, (20, 40, 90), point_size=0.012, point_shape="circle", precision="float32")
        size = 0.02 if not self.big else 0.01
        held = np.concatenate([np.asarray(h, dtype=int) for h in s.holders]) if s.holders else np.zeros(0, int)
        self.held = held
        self.held_points = scene.add_point_cloud("/held", x[held], (220, 40, 40), point_size=2 * size, point_shape="circle")
        self.load_point = scene.add_point_cloud("/load", x[[s.load_node]], (240, 150, 20), point_size=2.5 * size, point_shape="circle")
        extent = float(np.ptp(x, axis=0).max()) or 1.0
        self.pivots = [x[np.asarray(h, dtype=int)].mean(axis=0) if len(h) else np.zeros(3) for h in s.holders]
        self.handles = []
        for k, pivot in enumerate(self.pivots):
            handle = scene.add_transform_controls(f"/holder{k + 1}", scale=0.15 * extent, position=pivot, disable_rotations=s.dim == 2)
            handle.on_update(lambda h, k=k: self._drag_holder(k, h.target))
            self.handles.append(handle)
        self.load_handle = scene.add_transform_controls("/pull", scale=0.08 * extent, position=x[s.load_node], disable_rotations=True)
        self.load_handle.on_update(lambda e: self._set_dragging(e.phase != "end"))
        self.extent = extent
        for node in getattr(self, "ghosts", []):
            node.remove()
        self.ghosts, self.shapes = [], None
        # The camera on the sheet: square on for a 2D sheet, from the front and above one side for 3D.
        center = x.mean(axis=0)
        view = np.array([0.0, 0.0, 2.2]) if s.dim == 2 else np.array([1.1, 0.5, 1.6])
        # (viser moves look_at with position: position first.)
        self.client.camera.position = center + extent * view
        self.client.camera.look_at = center
        self.client.camera.up_direction = (0.0, 1.0, 0.0)

    def _build_controls(self):
        for node in self.gui_nodes:
            node.remove()
        self.gui_nodes = []
        s, gui = self.session, self.client.gui
        g = float(np.linalg.norm(s.gravity))
        with gui.add_folder("Gravity and damping") as folder:
            self.gui_nodes.append(folder)
            self.g_size = gui.add_slider("|g| [m/s²]", 0.0, 30.0, 0.01, round(g, 2))
            self.g_good = (round(g, 2), 0.0, 0.0)
            self.g_turn = gui.add_slider("turned in plane [°]", -180.0, 180.0, 1.0, 0.0)
            self.g_out = gui.add_slider("out of plane [°]", -90.0, 90.0, 1.0, 0.0, disabled=s.dim == 2)
            for c in (self.g_size, self.g_turn, self.g_out):
                c.on_update(lambda _: self._gravity())
            self.alpha = gui.add_slider("damping α [1/s]", 0.0, 5.0, 0.01, float(s.damping[0]))
            self.beta = gui.add_slider("damping β [s]", 0.0, 0.01, 0.0001, float(s.damping[1]))
            for c in (self.alpha, self.beta):
                c.on_update(lambda _: self._damping())
        with gui.add_folder("Mode weights") as folder:
            self.gui_nodes.append(folder)
            modal = s.reduction == 1
            if not modal:
                gui.add_markdown("Mode weights act on a modal run only (reduction = modal).")
            self.class_sliders = {}
            for name in CLASSES:
                members = int(np.count_nonzero(in_class(s, name)))
                slider = gui.add_slider(f"{name} ({members})", 0.0, 2.0, 0.01, 1.0, disabled=not modal or members == 0)
                slider.on_update(lambda _, name=name: self._class_weight(name))
                self.class_sliders[name] = slider
            self.mode_sliders = []
            for j in range(min(s.r, MODE_SLIDERS) if modal else 0):
                slider = gui.add_slider(f"mode {j + 1}: {s.frequencies[j]:.2f} Hz", 0.0, 2.0, 0.01, float(s.weights[j]))
                slider.on_update(lambda _, j=j: self._mode_weight(j))
                self.mode_sliders.append(slider)
        with gui.add_folder("Mode gallery") as folder:
            self.gui_nodes.append(folder)
            self.gallery = gui.add_slider(f"from mode (0: none; {GALLERY} shown)", 0, s.r, 1, 0)
            self.gallery.on_update(lambda _: self._guarded(lambda: self._show_modes(int(self.gallery.value))))

    # ---- controls -----------------------------------------------------

    def refuse(self, why):
        self.refusals.append(why)
        del self.refusals[:-5]
        self.client.add_notification("Refused", why, auto_close_seconds=5.0, color="red")

    def _note(self, text):
        self.refusals.append(text)
        del self.refusals[:-5]

    def _guarded(self, action, restore=None):
        """Runs `action`; a refused value is reported and its controls put back (`restore`)."""
        with self.lock:
            try:
                action()
            except Refused as e:
                self.refuse(str(e))
                if restore is not None:
                    restore()

    def toggle(self):
        with self.lock:
            self.playing = not self.playing
            self.clock.resume(self.session.time)
            self.play.label = "Pause" if self.playing else "Play"

    def _gravity(self):
        sliders = (self.g_size, self.g_turn, self.g_out)
        size, turn, out = (float(c.value) for c in sliders)
        t, o = np.radians(turn), np.radians(out)
        g = size * np.array([np.sin(t) * np.cos(o), -np.cos(t) * np.cos(o), np.sin(o)])

        def restore():
            for c, v in zip(sliders, self.g_good, strict=True):
                c.value = v

        with self.lock:
            self._guarded(lambda: self.session.set_gravity(g), restore)
            if np.array_equal(self.session.gravity, g):
                self.g_good = (size, turn, out)

    def _damping(self):
        def restore():
            self.alpha.value, self.beta.value = self.session.damping

        self._guarded(lambda: self.session.set_damping(self.alpha.value, self.beta.value), restore)

    def _show_weights(self):
        """The sliders as the session's weights are (after a refusal or a class change)."""
        for j, slider in enumerate(self.mode_sliders):
            slider.value = float(self.session.weights[j])

    def _mode_weight(self, j):
        w = self.session.weights.copy()
        w[j] = self.mode_sliders[j].value
        self._guarded(lambda: self.session.set_weights(w), self._show_weights)

    def _class_weight(self, name):
        w = self.session.weights.copy()
        w[in_class(self.session, name)] = self.class_sliders[name].value

        def restore():
            self.class_sliders[name].value = 1.0

        self._guarded(lambda: self.session.set_weights(w), restore)
        self._show_weights()

    def _drag_holder(self, k, handle):
        offset = np.asarray(handle.position, dtype=float) - self.pivots[k]
        turn = rotation_vector(handle.wxyz)
        with self.lock:
            try:
                self.target[k] = self.session.checked_anchor(k, offset, turn)
            except Refused as e:
                self.refuse(str(e))

    def _set_dragging(self, on):
        with self.lock:
            self.dragging_load = on
            if not on:
                self._guarded(lambda: self.session.set_load(np.zeros(3)))

    def _show_modes(self, first):
        """Modes first .. first + GALLERY - 1 (modeShapes), each at 0.45 of the sheet's size in a grid beside it,
        with its frequency; 0: none."""
        s = self.session
        for node in self.ghosts:
            node.remove()
        self.ghosts = []
        if not 1 <= first <= s.r:
            return
        if self.shapes is None:
            self.shapes = s.mode_shapes()
        for k, j in enumerate(range(first, min(first + GALLERY, s.r + 1))):
            phi = self.shapes[j - 1]
            scale = 0.2 * self.extent / (np.abs(phi).max() or 1.0)
            # Left of the sheet (the control panel covers the right of the page), three to a row.
            center = as3(s.start).mean(axis=0)
            at = center + np.array([-(2.25 - 0.62 * (k % 3)) * self.extent, 0.25 * self.extent - 0.65 * self.extent * (k // 3), 0.0], dtype=np.float32)
            x = 0.45 * (as3(s.start + scale * phi) - center) + at
            name = f"/gallery/mode {j}"
            if self.big:
                self.ghosts.append(self.client.scene.add_mesh_simple(name, x, self.faces, color=(150, 150, 150), side="double"))
            else:
                self.ghosts.append(self.client.scene.add_line_segments(name, x[s.springs], (150, 150, 150), thickness=0.002))
            top = at + np.array([0.0, 0.28 * self.extent, 0.0], dtype=np.float32)
            self.ghosts.append(self.client.scene.add_label(f"/gallery/label {j}", f"mode {j}: {s.frequencies[j - 1]:.2f} Hz", position=top))

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
            s.set_anchor(k, s.anchors[k][:3] + step[:3], s.anchors[k][3:] + step[3:])
        if self.dragging_load:
            x = s.positions()[s.load_node]
            pull = np.zeros(3)
            pull[: s.dim] = (np.asarray(self.load_handle.position)[: s.dim] - x) * (s.weight / PULL_LENGTH)
            limit = 0.9 * STRONGEST_PULL * s.weight
            norm = np.linalg.norm(pull)
            s.set_load(pull * min(1.0, limit / norm) if norm > 0 else pull)

    def _advance(self):
        s = self.session
        due = self.clock.due(s.time) if self.playing else 0
        for _ in range(due):
            self._follow()
            try:
                s.step()
            except Refused as e:
                self.playing = False
                self.play.label = "Play"
                self.refuse(str(e) + " (paused at the last good state)")
                break

    def _draw(self):
        s = self.session
        x = as3(s.positions())
        with self.client.atomic():
            if self.big:
                self.sheet.vertices = x
            else:
                self.sheet.points = x[s.springs]
                self.nodes.points = x
            self.held_points.points = x[self.held]
            self.load_point.points = x[[s.load_node]]
            if not self.dragging_load:
                self.load_handle.position = x[s.load_node]
        self.frames_sent += 1

    def _read_out(self):
        s = self.session
        r = s.readouts()
        lines = [
            f"**t** = {s.time:.2f} s · **real-time factor** {self.rtf:.2f} · **frames/s** {self.rate:.0f}",
            f"kinetic {r['kineticEnergy']:.4g} J · potential {r['potentialEnergy']:.4g} J",
        ]
        for k in range(s.n_holders):
            f = r[f"holder {k + 1} force"]
            lines.append(f"holder {k + 1} force ({f[0]:.3g}, {f[1]:.3g}, {f[2]:.3g}) N")
        lines.append(
            f"forceResidual {r['forceResidual']:.3g} · trainingRange {r['trainingRange']:.3g} · "
            f"errorEstimate {r['errorEstimate']:.3g} · reducedFraction {r['reducedFraction']:.3g}"
        )
        lines.append("paused" if not self.playing else "running")
        self.readout.content = "  \n".join(lines)
        shown = [f"{status}: {text}" for status, _, text in s.messages if status != "OK"][-5:] + self.refusals[-5:]
        self.log.content = "  \n".join(shown)

    def _loop(self):
        period = 1.0 / self.fps
        mark, frames0, sim0 = time.perf_counter(), 0, 0.0
        next_frame = time.perf_counter()
        while not self.stopped:
            with self.lock:
                if self.session is None:
                    break
                self._advance()
                self._draw()
                now = time.perf_counter()
                if now - mark >= 0.5:
                    self.rate = (self.frames_sent - frames0) / (now - mark)
                    self.rtf = (self.session.time - sim0) / (now - mark) if self.playing else 0.0
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

