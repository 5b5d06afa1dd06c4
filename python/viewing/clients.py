"""Clients of the view's server for the tests and the measurements: Debian's
Chromium driven headless through selenium (chromium-driver), and a bare
websocket client that speaks viser's protocol the way its page does (so a
test can send what a page sends, and what a hostile page might).

viser's wire format: a page sends each message as msgpack of its fields
plus "type"; the server sends windows of messages as
[8-byte size][8-byte compressed size][zstd msgpack {"messages": [...]}][binary buffers]."""

import shutil
import socket
import time

import msgspec
import numpy as np
import viser
import zstandard
from viser import _messages as messages
from websockets.sync.client import connect

CHROMIUM = ("/usr/bin/chromium", "/usr/bin/chromium-browser")
DRIVER = ("/usr/bin/chromedriver", "/usr/lib/chromium/chromedriver")


def until(condition, timeout=20.0, every=0.005):
    """The first true value of `condition()`, polled; TimeoutError after `timeout` seconds."""
    end = time.time() + timeout
    while time.time() < end:
        value = condition()
        if value:
            return value
        time.sleep(every)
    raise TimeoutError(f"not within {timeout} s")


def free_port():
    """A port on 127.0.0.1 free now."""
    with socket.socket() as so:
        so.bind(("127.0.0.1", 0))
        return so.getsockname()[1]


def find(paths, name):
    for p in paths:
        if shutil.which(p):
            return p
    found = shutil.which(name)
    if found is None:
        raise FileNotFoundError(f"{name} is not installed (cargo xtask setup installs Debian's chromium and chromium-driver)")
    return found


def chromium(width=1280, height=800):
    """A headless Chromium (software WebGL) that counts what its pages receive and draw."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    for a in (
        "--headless=new",
        "--no-sandbox",
        "--disable-dev-shm-usage",
        f"--window-size={width},{height}",
        "--use-angle=swiftshader",
        "--enable-unsafe-swiftshader",
    ):
        options.add_argument(a)
    options.binary_location = find(CHROMIUM, "chromium")
    driver = webdriver.Chrome(service=Service(find(DRIVER, "chromedriver")), options=options)
    count_in_page(driver)
    return driver


# Counts, in the page, every message its websockets and workers hand it and
# every frame it draws (performance.now() in ms), from before viser's client loads.
COUNTERS = """
window.__received = []; window.__drawn = [];
for (const name of ["WebSocket", "Worker"]) {
  const Open = window[name];
  window[name] = function (...args) {
    const opened = new Open(...args);
    opened.addEventListener("message", () => window.__received.push(performance.now()));
    return opened;
  };
  window[name].prototype = Open.prototype;
  Object.assign(window[name], Open);
}
const draw = () => { window.__drawn.push(performance.now()); requestAnimationFrame(draw); };
requestAnimationFrame(draw);
"""


def count_in_page(driver):
    """Installs the counters into every page `driver` loads from now on."""
    driver.execute_cdp_cmd("Page.addScriptToEvaluateOnNewDocument", {"source": COUNTERS})


def counted(driver):
    """(messages received, frames drawn) since the last call: their times in s."""
    got = driver.execute_script("return [window.__received.splice(0), window.__drawn.splice(0)];")
    return [np.asarray(t) / 1000.0 for t in got]


def encode(message):
    return msgspec.msgpack.encode(message.as_serializable_dict())


def packed(fields):
    """Any dict as a page would pack a message (msgpack), whether or not viser knows it."""
    return msgspec.msgpack.encode(fields)


def decode(raw):
    size, packed = int.from_bytes(raw[:8], "little"), int.from_bytes(raw[8:16], "little")
    inner = zstandard.ZstdDecompressor().decompress(raw[16 : 16 + packed], max_output_size=size)
    return msgspec.msgpack.decode(inner)["messages"]


class Bare:
    """A page without a browser: connects, says where its camera is (which
    makes it a client to the server) and reads what the server sends."""

    def __init__(self, url):
        self.ws = connect(url.replace("http", "ws"), subprotocols=["viser-v" + viser.__version__], max_size=None)
        self.seen = []
        self.send(
            messages.ViewerCameraMessage(
                wxyz=(1.0, 0.0, 0.0, 0.0),
                position=(0.0, 0.0, 1.0),
                fov=1.0,
                near=0.01,
                far=100.0,
                image_height=600,
                image_width=800,
                look_at=(0.0, 0.0, 0.0),
                up_direction=(0.0, 1.0, 0.0),
            )
        )

    def send(self, message):
        self.ws.send(encode(message) if not isinstance(message, bytes) else message)

    def read(self, seconds):
        """Every message the server sent in `seconds` (dicts with their "type")."""
        end = time.time() + seconds
        while time.time() < end:
            try:
                raw = self.ws.recv(timeout=max(0.01, end - time.time()))
            except TimeoutError:
                break
            self.seen += decode(raw)
        return self.seen

    def find(self, kind, **fields):
        """The first message of `kind` seen whose fields (or label) match."""
        for m in self.seen:
            if m.get("type") == kind and all(m.get(k) == v or m.get("props", {}).get(k) == v for k, v in fields.items()):
                return m
        return None

    def close(self):
        self.ws.close()


def gui_update(uuid, value):
    return messages.GuiUpdateMessage(uuid=uuid, updates={"value": value})


def drag(name, owner, position, wxyz=(1.0, 0.0, 0.0, 0.0)):
    return messages.TransformControlsUpdateMessage(name=name, wxyz=tuple(wxyz), position=tuple(float(x) for x in np.asarray(position)), owner=owner)


def on_screen(camera, point):
    """Where the page draws world `point` (pixels from the canvas's top left), from
    the camera the page reported (viser's CameraHandle: position, look_at, up, vertical fov)."""
    pos, up = np.asarray(camera.position, dtype=float), np.asarray(camera.up_direction, dtype=float)
    forward = np.asarray(camera.look_at, dtype=float) - pos
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, up)
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    d = np.asarray(point, dtype=float) - pos
    x, y, z = d @ right, d @ up, d @ forward
    w, h, t = camera.image_width, camera.image_height, np.tan(camera.fov / 2)
    return (x / (z * t * w / h) + 1) / 2 * w, (1 - y / (z * t)) / 2 * h


def mouse_drag(driver, start, pixels):
    """Presses the mouse at canvas pixel `start`, moves it by `pixels` (dx, dy) in a few moves, releases."""
    from selenium.webdriver.common.action_chains import ActionChains

    canvas = driver.find_element("tag name", "canvas")
    size = canvas.size
    chain = ActionChains(driver).move_to_element_with_offset(canvas, int(start[0] - size["width"] / 2), int(start[1] - size["height"] / 2))
    chain.click_and_hold()
    for _ in range(4):
        chain.move_by_offset(int(pixels[0] / 4), int(pixels[1] / 4))
    chain.release().perform()
