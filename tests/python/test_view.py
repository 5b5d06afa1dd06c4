"""The live view (python/view.py, docs/view.md): one FMU instance per page,
steered from the page, values checked before the FMU sees them.

- A session alone (no server): hostile values are refused with the reason
  and leave its run bit for bit as a twin's that never got them; weights,
  gravity and a holder reach the FMU and change the motion.
- The server with bare protocol clients (what a page sends, and what a
  hostile one might): bound to 127.0.0.1 only; two pages get two instances,
  a page that goes frees its own; a dragged holder handle moves the held
  nodes, a pulled load handle loads the load node; malformed, out-of-range
  and unknown messages and bytes that are not messages are refused with the
  reason and leave the run bit for bit as a twin session's, and the
  instance and the server keep running.
- Debian's Chromium, headless: the page loads and draws the sheet, a weight
  typed into the page changes the motion (read back from the FMU), the
  holder dragged with the mouse moves the held nodes, Pause stops the run;
  the positions the page expands from the modal coordinates are the FMU's
  with a holder moved and turned; the mode gallery draws six modes; a
  screenshot into $MMS_VIEW_SCREENSHOTS when set.
- A page's server side alone: cloth 100 x 100 with static correction
  expands to the FMU's positions, an adaptive run is sent positions; the
  page's libraries are the pinned ones."""

import math
import os
import socket
import subprocess
import sys
import time

import numpy as np
import pytest

from conftest import ROOT

sys.path.insert(0, str(ROOT / "python"))
from sheet import Fmu  # noqa: E402
from view import Viewer, scene_table  # noqa: E402
from viewing.session import Refused, Session  # noqa: E402

clients = pytest.importorskip("viewing.clients", reason="aiohttp, selenium (cargo xtask setup --for test)")


@pytest.fixture(scope="module")
def fmu(default_fmu):
    f = Fmu(default_fmu)
    yield f
    f.close()


@pytest.fixture(scope="module")
def scenes(fmu):
    return scene_table(fmu, {})


def test_hostile_values_are_refused_and_change_nothing(fmu, scenes):
    a, b = Session(fmu, scenes["paper-3d-sheet"]), Session(fmu, scenes["paper-3d-sheet"])
    try:
        hostile = [
            (lambda: a.set_gravity([math.nan, -9.81, 0.0]), "gravity: not finite"),
            (lambda: a.set_gravity([0.0, -9.81]), "gravity: 2 values where 3"),
            (lambda: a.set_gravity("down"), "gravity: not numbers"),
            (lambda: a.set_gravity([0.0, -1e9, 0.0]), "gravity: outside"),
            (lambda: a.set_weights([1.0] * (a.r + 1)), "modeWeights"),
            (lambda: a.set_weights([math.inf] * a.r), "modeWeights: not finite"),
            (lambda: a.set_weights([-1.0] * a.r), "modeWeights: outside"),
            (lambda: a.set_damping(-1.0, 0.0), "dampingAlpha: outside"),
            (lambda: a.set_damping(0.0, None), "dampingBeta: not"),
            (lambda: a.set_anchor(3, [0.0] * 3), "holder 3"),
            (lambda: a.set_anchor(0, [1e6, 0.0, 0.0]), "holder translation: outside"),
            (lambda: a.set_anchor(0, [0.0] * 3, [math.nan] * 3), "holder rotation: not finite"),
            (lambda: a.set_load([1e12, 0.0, 0.0]), "point load: outside"),
            (lambda: a.set_load({"x": 1}), "point load"),
        ]
        for k in range(40):
            if k < len(hostile):
                action, why = hostile[k]
                with pytest.raises(Refused, match=why.replace("(", r"\(")):
                    action()
            a.step()
            b.step()
        assert a.positions().tobytes() == b.positions().tobytes()
        assert a.readouts() == b.readouts()
    finally:
        a.close()
        b.close()


def test_adaptive_run_refuses_weights_with_the_reason(fmu, scenes):
    s = Session(fmu, {**scenes["default"], "reduction": "adaptive"})
    try:
        with pytest.raises(Refused, match="only a modal run"):
            s.set_weights(np.zeros(s.r))
        s.step()
    finally:
        s.close()


def mean_load_height(session, steps):
    ys = []
    for _ in range(steps):
        session.step()
        ys.append(session.positions()[session.load_node, 1])
    return float(np.mean(ys))


def test_weights_gravity_and_holder_reach_the_fmu(fmu, scenes):
    s = Session(fmu, scenes["default"])
    try:
        rest = s.start[s.load_node, 1]
        sag = rest - mean_load_height(s, 100)
        assert sag > 1e-3
        s.set_weights(np.zeros(s.r))
        assert list(fmu.get(s.inst, "modeWeights", s.r)) == [0.0] * s.r
        # Deleted modes: gravity no longer drives them, the sheet swings about its rest shape.
        assert abs(rest - mean_load_height(s, 200)) < 0.2 * sag
        s.set_weights(np.ones(s.r))
        s.set_gravity([0.0, -2 * 9.81, 0.0])
        assert list(fmu.get(s.inst, "gravity", 3)) == [0.0, -2 * 9.81, 0.0]
        held = np.asarray(s.holders[0])
        before = s.positions()[held].copy()
        for k in range(1, 21):
            s.set_anchor(0, [0.05 * k / 20, 0.0, 0.0])
            s.step()
        moved = s.positions()[held] - before
        assert np.allclose(moved[:, 0], 0.05, atol=1e-12) and np.allclose(moved[:, 1], 0.0, atol=1e-12)
    finally:
        s.close()


@pytest.fixture
def viewer(default_fmu):
    v = Viewer(default_fmu, "default", port=clients.free_port(), fps=60.0)
    yield v
    v.close()


def page_of(viewer, count=1):
    pages = clients.until(lambda: len(viewer.pages) >= count and dict(viewer.pages))
    return list(pages.values())


def outside_address():
    """An address of this machine other than loopback, if it has one."""
    out = subprocess.run(["hostname", "-I"], capture_output=True, text=True).stdout.split()
    return next((a for a in out if ":" not in a and not a.startswith("127.")), None)


def test_server_listens_on_loopback_only(viewer):
    with socket.create_connection(("127.0.0.1", viewer.port), timeout=2):
        pass
    address = outside_address()
    if address is None:
        pytest.skip("no address but loopback here")
    with pytest.raises(OSError):
        socket.create_connection((address, viewer.port), timeout=2).close()


def test_two_pages_two_instances_and_a_page_that_goes_frees_its_own(viewer):
    one, two = clients.Bare(viewer.url()), clients.Bare(viewer.url())
    try:
        first, second = page_of(viewer, 2)
        assert first.session is not second.session
        clients.until(lambda: first.status()["time"] > 0.1 and second.status()["time"] > 0.1)
        two.close()
        clients.until(lambda: len(viewer.pages) == 1)
        (stays,) = viewer.pages.values()
        gone = second if stays is first else first
        clients.until(lambda: gone.session is None)
        gone.thread.join(5)
        assert not gone.thread.is_alive()
        t = stays.status()["time"]
        clients.until(lambda: stays.status()["time"] > t + 0.1)
    finally:
        one.close()


def holder_message(page, offset, quaternion=(0.0, 0.0, 0.0, 1.0)):
    return {"type": "holder", "holder": 0, "position": (page.pivots[0] + np.asarray(offset)).tolist(), "quaternion": list(quaternion)}


def test_dragging_a_holder_moves_its_nodes(viewer):
    bare = clients.Bare(viewer.url())
    try:
        (page,) = page_of(viewer)
        clients.until(lambda: bare.find("instance") and bare.binary)
        held = np.asarray(page.session.holders[0])
        start = page.session.start[held]
        bare.send(holder_message(page, [0.05, 0.02, 0.0]))
        clients.until(lambda: np.allclose(page.status()["anchors"][0][:2], [0.05, 0.02], atol=1e-6), timeout=10)
        with page.lock:
            moved = page.session.positions()[held] - start
        assert np.allclose(moved[:, 0], 0.05, atol=1e-6) and np.allclose(moved[:, 1], 0.02, atol=1e-6)
        force = page.status()["holder_force"]
        assert math.isfinite(force[1]) and force[1] < 0
        # The load node pulled by its handle 0.1 m below it: a load of one sheet weight down, gone when let go.
        below = page.status()["load_node"] + np.array([0.0, -0.1])
        bare.send({"type": "pull", "position": [*below.tolist(), 0.0]})
        (load,) = clients.until(lambda: np.any(page.session.load != 0.0) and [page.session.load.copy()])
        assert load[1] < -0.5 * page.session.weight and abs(load[2]) == 0.0
        bare.send({"type": "pull", "position": None})
        clients.until(lambda: np.all(page.session.load == 0.0))
    finally:
        bare.close()


HOSTILE = [
    {"type": "gravity", "size": "NaN", "turn": 0.0, "out": 0.0},
    '{"type": "gravity", "size": NaN, "turn": 0, "out": 0}',
    {"type": "gravity", "size": 1e308, "turn": 0.0, "out": 0.0},
    {"type": "gravity", "size": [1, 2, 3], "turn": 0.0, "out": 0.0},
    {"type": "gravity", "size": 9.81, "turn": 0.0, "out": 30.0},
    {"type": "damping", "alpha": -1.0, "beta": 0.0},
    {"type": "classWeight", "class": "in-plane", "value": -5.0},
    {"type": "classWeight", "class": "no-such-class", "value": 1.0},
    {"type": "modeWeight", "mode": 99, "value": 1.0},
    {"type": "modeWeight", "mode": 0, "value": 1.0, "extra": 1},
    {"type": "holder", "holder": 0, "position": [1e9, 0.0, 0.0], "quaternion": [0.0, 0.0, 0.0, 1.0]},
    {"type": "holder", "holder": 0, "position": [0.0, 0.0, 0.0], "quaternion": ["NaN", 0.0, 0.0, 0.0]},
    {"type": "holder", "holder": 7, "position": [0.0, 0.0, 0.0], "quaternion": [0.0, 0.0, 0.0, 1.0]},
    {"type": "pull", "position": [1e308, 0.0, 0.0]},
    {"type": "scene", "name": "no-such-scene"},
    {"type": "no-such-type"},
    {"no": "type"},
    [1, 2, 3],
    "not json",
    '{"type": "reset", "padding": "' + "x" * 100_000 + '"}',
    b"\x00\xffbinary garbage",
]


def test_hostile_messages_are_refused_and_change_nothing(viewer, fmu, scenes):
    bare = clients.Bare(viewer.url())
    twin = Session(fmu, scenes["default"])
    try:
        (page,) = page_of(viewer)
        bare.send({"type": "play", "playing": False})
        clients.until(lambda: not page.status()["playing"])
        before = len(bare.seen)
        for message in HOSTILE:
            bare.send(message)
        refused = clients.until(lambda: len(r := [m for m in bare.seen[before:] if m["type"] == "refused"]) >= len(HOSTILE) and r, timeout=10)
        assert len(refused) == len(HOSTILE), refused
        assert all(r["why"] for r in refused)
        bare.send({"type": "play", "playing": True})
        clients.until(lambda: page.status()["time"] > 0.5)
        bare.send({"type": "play", "playing": False})
        clients.until(lambda: not page.status()["playing"])
        # The twin never got them: stepped as far, it is where the page's instance is, bit for bit.
        while twin.time < page.session.time - 1e-9:
            twin.step()
        with page.lock:
            assert page.session.positions().tobytes() == twin.positions().tobytes()
            assert page.session.readouts() == twin.readouts()
            assert np.array_equal(page.session.weights, twin.weights) and np.array_equal(page.session.gravity, twin.gravity)
        # The page, its instance and the server go on; a second page gets an instance of its own.
        assert list(viewer.pages.values()) == [page] and page.session is not None
        bare.send({"type": "play", "playing": True})
        t = page.status()["time"]
        clients.until(lambda: page.status()["time"] > t + 0.2)
        other = clients.Bare(viewer.url())
        try:
            fresh = next(p for p in page_of(viewer, 2) if p is not page)
            clients.until(lambda: fresh.status()["time"] > 0.2)
        finally:
            other.close()
    finally:
        twin.close()
        bare.close()


def pixels_of(png, colour, tolerance=12):
    """Pixels of about `colour` in the drawing: left of the control panel, above the readouts."""
    from io import BytesIO

    import matplotlib.image as mpimg

    image = (mpimg.imread(BytesIO(png), format="png")[..., :3] * 255).astype(int)
    h, w = image.shape[:2]
    drawing = image[: h - 120, : w - 320]
    return int(np.count_nonzero(np.all(np.abs(drawing - np.array(colour)) < tolerance, axis=-1)))


@pytest.fixture
def browser():
    driver = clients.chromium()
    yield driver
    driver.quit()


def test_the_page_expands_the_modes_as_the_fmu_places_its_nodes(default_fmu, browser):
    from selenium.webdriver.common.by import By

    viewer = Viewer(default_fmu, "paper-3d-sheet", port=clients.free_port())
    try:
        browser.get(viewer.url())
        (page,) = page_of(viewer)
        clients.until(lambda: browser.execute_script("return window.view && window.view.frame") > 0, timeout=30)
        turn = np.array([0.08, 0.0, 0.05])
        quaternion = [*np.sin(np.linalg.norm(turn) / 2) * turn / np.linalg.norm(turn), np.cos(np.linalg.norm(turn) / 2)]
        browser.execute_script("view.send(arguments[0])", holder_message(page, [0.03, -0.02, 0.04], quaternion))
        clients.until(lambda: np.allclose(page.status()["anchors"][0], page.target[0], atol=1e-6) and page.status()["time"] > 1.0, timeout=20)
        browser.find_element(By.XPATH, "//button[contains(., 'Pause')]").click()
        clients.until(lambda: not page.status()["playing"])
        # Paused, the server sends no more frames: the page draws the last one, of the paused state.
        clients.until(lambda: browser.execute_script("return view.frame") == page.status()["frames"] - 1, timeout=10)
        drawn = np.asarray(browser.execute_script("return Array.from(view.positions)")).reshape(-1, 3)
        with page.lock:
            x = page.session.positions()
            assert np.abs(page.session.anchors[0][3:]).max() > 0.04
            assert np.abs(x - page.session.start).max() > 0.03
        assert page.modal and np.abs(drawn - x).max() < 1e-5, np.abs(drawn - x).max()
        # The mode gallery: six modes with their frequencies beside the sheet.
        clients.type_into(browser, "from mode", "1")
        clients.until(lambda: browser.execute_script("return view.ghosts") == 6, timeout=10)
        shown = clients.until(lambda: browser.execute_script("return [...document.querySelectorAll('.mode-label')].map(e => e.textContent)"))
        assert shown == [f"mode {j}: {page.session.frequencies[j - 1]:.2f} Hz" for j in range(1, 7)]
        clients.type_into(browser, "from mode", "0")
        clients.until(lambda: browser.execute_script("return view.ghosts") == 0, timeout=10)
    finally:
        viewer.close()


def test_the_page_in_chromium(viewer, browser):
    from selenium.webdriver.common.by import By

    browser.get(viewer.url())
    (page,) = page_of(viewer)
    clients.until(lambda: "frames/s" in browser.find_element(By.TAG_NAME, "body").text, timeout=30)
    time.sleep(1.0)
    shot = browser.get_screenshot_as_png()
    # The springs (60, 120, 200) and the held nodes (220, 40, 40) are on the screen.
    assert pixels_of(shot, (60, 120, 200)) > 200 and pixels_of(shot, (220, 40, 40)) > 20
    out = os.environ.get("MMS_VIEW_SCREENSHOTS")
    if out:
        os.makedirs(out, exist_ok=True)
        with open(os.path.join(out, "default.png"), "wb") as f:
            f.write(shot)
    received, drawn = clients.counted(browser)
    assert len(received) > 10 and len(drawn) > 10
    rest = page.session.start[page.session.load_node, 1]

    def mean_height(seconds):
        ys, end = [], time.time() + seconds
        while time.time() < end:
            ys.append(page.status()["load_node"][1])
            time.sleep(0.005)
        return float(np.mean(ys))

    sag = rest - mean_height(1.5)
    assert sag > 1e-3
    # Type 0 into the in-plane class's number box: both modes of the 2D sheet are deleted.
    clients.type_into(browser, "in-plane (2)", "0")
    clients.until(lambda: np.all(page.status()["weights"] == 0.0), timeout=10)
    assert list(viewer.fmu.get(page.session.inst, "modeWeights", page.session.r)) == [0.0] * page.session.r
    time.sleep(0.5)
    assert abs(rest - mean_height(1.5)) < 0.2 * sag
    # Drag the holder by its handle's x arrow with the mouse: the held nodes follow.
    held = np.asarray(page.session.holders[0])
    start = page.session.start[held]
    at = aim_at_x_arrow(browser)
    clients.mouse_drag(browser, at, (48, 0))
    clients.until(lambda: page.target[0][0] > 0.02, timeout=10)
    time.sleep(1.0)
    moved = page.status()["anchors"][0]
    assert np.allclose(moved, page.target[0], atol=1e-9) and abs(moved[1]) < 1e-9
    with page.lock:
        x = page.session.positions()[held]
    assert np.allclose(x[:, 0] - start[:, 0], moved[0], atol=1e-9)
    # Pause: the page's button reads Play and the run stops.
    browser.find_element(By.XPATH, "//button[contains(., 'Pause')]").click()
    clients.until(lambda: browser.find_elements(By.XPATH, "//button[contains(., 'Play')]"), timeout=10)
    t = page.status()["time"]
    time.sleep(0.3)
    assert page.status()["time"] == t and not page.status()["playing"]


def aim_at_x_arrow(browser):
    """A canvas pixel over holder 1's x arrow: the mouse moved right from the handle's centre until the handle says X."""
    from selenium.webdriver.common.action_chains import ActionChains

    x0, y0 = browser.execute_script("return view.onScreen(view.pivot(0))")
    canvas = browser.find_element("tag name", "canvas")
    size = canvas.size
    for dx in range(8, 120, 4):
        ActionChains(browser).move_to_element_with_offset(canvas, int(x0 + dx - size["width"] / 2), int(y0 - size["height"] / 2)).perform()
        if browser.execute_script("return view.hovered(0)") == "X":
            return x0 + dx, y0
    raise AssertionError("no x arrow right of holder 1's handle")


def test_the_page_libraries_are_the_pinned_ones():
    """What the page loads is the pinned version of each package; bytes other than the pinned tarball's are refused."""
    import json

    from viewing import assets

    root = assets.ensure()
    for package, (version, _) in assets.PINNED.items():
        with open(os.path.join(root, package, "package.json")) as f:
            assert json.load(f)["version"] == version
        with pytest.raises(ValueError, match="is not the pinned"):
            assets.checked(package, b"not the tarball")


def test_static_correction_expands_and_adaptive_runs_get_positions(fmu, scenes):
    """Cloth 100 x 100 (16 load modes with static correction), its holder moved and turned: the
    expansion the page makes (Page.expanded, as view.js) is the FMU's positions; an adaptive run gets positions."""
    from viewing.page import MODAL, POSITIONS, Page

    adaptive = {**scenes["default"], "reduction": "adaptive"}
    for name, values, kind in (("cloth-3d-100x100", scenes["cloth-3d-100x100"], MODAL), ("adaptive", adaptive, POSITIONS)):
        sent = []
        page = Page(sent.append, fmu, {name: values}, name)
        try:
            with page.lock:
                s = page.session
                page.target[0] = s.checked_anchor(0, [0.05, 0.02, 0.03 * (s.dim - 2)], [0.02 * (s.dim - 2), 0.0, 0.03])
            clients.until(lambda: np.allclose(page.status()["anchors"][0], page.target[0], atol=1e-9), timeout=30)  # noqa: B023
            with page.lock:
                frames = {int.from_bytes(m[:4], "little") for m in sent if isinstance(m, bytes)} - {0}
                assert frames == {kind} and page.status()["refusals"] == []
                if kind == MODAL:
                    assert page.modal and np.abs(page.expanded(page._coordinates()) - s.positions()).max() < 1e-12
        finally:
            page.close()
