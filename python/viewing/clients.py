"""Clients of the view's server for the tests and the measurements: Debian's
Chromium driven headless through selenium (chromium-driver), and a bare
websocket client that speaks the page's protocol (viewing/protocol.py) the
way the page does (so a test can send what a page sends, and what a hostile
page might)."""

import asyncio
import json
import shutil
import socket
import threading
import time

import aiohttp
import numpy as np

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


# Counts, in the page, every message its websocket hands it and every frame
# it draws (performance.now() in ms), from before the page's script loads.
COUNTERS = """
window.__received = []; window.__drawn = [];
const Open = window.WebSocket;
window.WebSocket = function (...args) {
  const opened = new Open(...args);
  opened.addEventListener("message", () => window.__received.push(performance.now()));
  return opened;
};
window.WebSocket.prototype = Open.prototype;
Object.assign(window.WebSocket, Open);
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


class Bare:
    """A page without a browser: a websocket to the server (aiohttp's client on
    a loop of its own) that sends what a page sends, or anything else, and keeps
    what the server sends: JSON messages in `seen`, binary ones in `binary`."""

    def __init__(self, url):
        self.loop = asyncio.new_event_loop()
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.thread.start()
        self.seen, self.binary = [], []
        self.ws = self._run(self._connect(url.replace("http", "ws") + "/ws"))
        self.reader = asyncio.run_coroutine_threadsafe(self._read(), self.loop)

    def _run(self, coroutine, timeout=30):
        return asyncio.run_coroutine_threadsafe(coroutine, self.loop).result(timeout)

    async def _connect(self, url):
        self.client = aiohttp.ClientSession()
        return await self.client.ws_connect(url, max_msg_size=0)

    async def _read(self):
        async for m in self.ws:
            if m.type == aiohttp.WSMsgType.TEXT:
                self.seen.append(json.loads(m.data))
            elif m.type == aiohttp.WSMsgType.BINARY:
                self.binary.append(m.data)
                del self.binary[:-50]

    def send(self, message):
        """A str or bytes as they are, anything else as JSON."""
        if not isinstance(message, (str, bytes)):
            message = json.dumps(message)
        self._run(self.ws.send_str(message) if isinstance(message, str) else self.ws.send_bytes(message))

    def find(self, kind):
        """The last message of `kind` seen."""
        return next((m for m in reversed(self.seen) if m.get("type") == kind), None)

    def close(self):
        async def close():
            await self.ws.close()
            await self.client.close()

        self._run(close())
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(5)


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


def number_box(driver, label):
    """The number box of the page's control named `label` (lil-gui), its folder opened."""
    xpath = f"//div[contains(@class, 'lil-controller')][.//div[@class='lil-name'][contains(., '{label}')]]//input"
    box = driver.find_element("xpath", xpath)
    if driver.execute_script(OPEN_FOLDERS, box):
        time.sleep(0.5)  # lil-gui's opening transition
    until(box.is_displayed, timeout=10)
    return box


OPEN_FOLDERS = """
let opened = false;
for (let e = arguments[0]; e; e = e.parentElement)
  if (e.classList.contains("lil-closed")) { e.querySelector(":scope > .lil-title").click(); opened = true; }
arguments[0].scrollIntoView({ block: "center" });
return opened;
"""


def type_into(driver, label, text):
    """Types `text` over the number in the box of the control named `label` (each key sets it)."""
    from selenium.webdriver.common.keys import Keys

    box = number_box(driver, label)
    box.send_keys(Keys.CONTROL, "a")
    box.send_keys(text, Keys.ENTER)
