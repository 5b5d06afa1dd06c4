"""Frame rates and latency of the live view (python/view.py) in Debian's
Chromium, headless (software WebGL: no GPU here), per scene:

- frames/s the server sends to the page and the real-time factor of its run;
- messages/s the page receives and frames/s it draws (counted in the page);
- control -> FMU: a weight typed into the page until the FMU has it;
- control -> screen: Pause clicked until the page's button reads Play (the
  round trip through the server to the page's DOM);
- frames/s the page draws while paused (its drawing alone).

With --yardstick, also a page of three.js alone (python/viewing/yardstick.html:
the sheet as a mesh, its positions expanded in the page from 16 modal
coordinates each frame, updated in place), in the same browser: what a page
of our own could draw here. three.js comes from the npm registry (`npm pack
three`, into target/view-yardstick/).

    .venv/bin/python python/view_measure.py [FMU] [--scene default --scene cloth-3d-100x100] [--seconds 5] [--screenshots DIR]
"""

import argparse
import functools
import http.server
import os
import subprocess
import sys
import tarfile
import threading
import time

import numpy as np

from view import DEFAULT_FMU, Viewer
from viewing import clients


def measure(fmu, scene, seconds, screenshots, fps=60.0):
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys

    viewer = Viewer(fmu, scene, port=clients.free_port(), fps=fps)
    driver = clients.chromium()
    try:
        driver.get(viewer.url())
        clients.until(lambda: viewer.pages, timeout=60)
        (page,) = viewer.pages.values()
        clients.until(lambda: "frames/s" in driver.find_element(By.TAG_NAME, "body").text, timeout=60)
        time.sleep(2.0)
        clients.counted(driver)
        f0, t0, w0 = page.frames_sent, page.status()["time"], time.perf_counter()
        time.sleep(seconds)
        received, drawn = clients.counted(driver)
        wall = time.perf_counter() - w0
        row = {
            "scene": scene,
            "nodes": page.session.n,
            "sent/s": (page.frames_sent - f0) / wall,
            "real-time factor": (page.status()["time"] - t0) / wall,
            "received/s": len(received) / wall,
            "drawn/s": len(drawn) / wall,
        }
        if screenshots:
            os.makedirs(screenshots, exist_ok=True)
            driver.save_screenshot(os.path.join(screenshots, f"{scene}.png"))
        # control -> FMU: a class weight typed into the page.
        label = next(s.label for s in page.class_sliders.values() if not s.disabled)
        box = driver.find_element(By.XPATH, f"//label[contains(., '{label}')]/following::input[not(@type='hidden')][1]")
        box.send_keys(Keys.CONTROL, "a")
        box.send_keys("0.5")
        before = page.session.weights.copy()
        start = time.perf_counter()
        box.send_keys(Keys.ENTER)
        clients.until(lambda: not np.array_equal(page.session.weights, before), timeout=10)
        row["control -> FMU [ms]"] = 1e3 * (time.perf_counter() - start)
        # control -> screen: Pause until the button reads Play.
        button = driver.find_element(By.XPATH, "//button[contains(., 'Pause')]")
        start = time.perf_counter()
        button.click()
        clients.until(lambda: driver.find_elements(By.XPATH, "//button[contains(., 'Play')]"), timeout=10)
        row["control -> screen [ms]"] = 1e3 * (time.perf_counter() - start)
        # Paused: the server sends the same frame on; what the page draws then is its drawing alone.
        time.sleep(0.5)
        clients.counted(driver)
        time.sleep(seconds)
        row["drawn/s paused"] = len(clients.counted(driver)[1]) / seconds
        return row
    finally:
        driver.quit()
        viewer.close()


YARDSTICK = os.path.join(os.path.dirname(os.path.abspath(__file__)), "viewing", "yardstick.html")


def three_js(root):
    """three.js unpacked under `root`/three (from the npm registry, once)."""
    if not os.path.exists(os.path.join(root, "three", "build", "three.module.js")):
        os.makedirs(root, exist_ok=True)
        name = subprocess.run(["npm", "pack", "three", "--silent"], cwd=root, check=True, capture_output=True, text=True).stdout.split()[-1]
        with tarfile.open(os.path.join(root, name)) as tar:
            tar.extractall(root, filter="data")
        os.replace(os.path.join(root, "package"), os.path.join(root, "three"))
    with open(YARDSTICK) as f, open(os.path.join(root, "yardstick.html"), "w") as g:
        g.write(f.read())
    return root


def yardstick(root, n, seconds, antialias):
    """Frames/s the yardstick page draws of an n x n sheet."""
    class Quiet(http.server.SimpleHTTPRequestHandler):
        def log_message(self, *_):
            pass

    handler = functools.partial(Quiet, directory=root)
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    driver = clients.chromium()
    try:
        driver.get(f"http://127.0.0.1:{server.server_address[1]}/yardstick.html?n={n}&r=16&antialias={int(antialias)}")
        time.sleep(2.0)
        driver.execute_script("window.__drawn.splice(0)")
        time.sleep(seconds)
        return len(driver.execute_script("return window.__drawn.splice(0)")) / seconds
    finally:
        driver.quit()
        server.shutdown()


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("fmu", nargs="?", default=DEFAULT_FMU)
    p.add_argument("--scene", action="append", default=None, help="default: default and cloth-3d-100x100")
    p.add_argument("--seconds", type=float, default=5.0)
    p.add_argument("--screenshots", default=None, help="a directory for a screenshot per scene")
    p.add_argument("--fps", type=float, default=60.0, help="frames a second the server sends (default 60)")
    p.add_argument("--yardstick", action="store_true", help="also three.js alone, expanding the modes in the page (npm)")
    args = p.parse_args(argv)
    rows = [measure(args.fmu, s, args.seconds, args.screenshots, args.fps) for s in args.scene or ["default", "cloth-3d-100x100"]]
    keys = list(rows[0])
    print("| " + " | ".join(keys) + " |")
    print("|" + "---|" * len(keys))
    for r in rows:
        print("| " + " | ".join(f"{r[k]:.1f}" if isinstance(r[k], float) else str(r[k]) for k in keys) + " |")
    if args.yardstick:
        root = three_js(os.path.join(os.path.dirname(DEFAULT_FMU), "..", "view-yardstick"))
        print("\nthree.js alone, modes expanded in the page (16 modes, a mesh updated in place):\n")
        print("| nodes | drawn/s, antialiased | drawn/s, without antialiasing |\n|---|---|---|")
        for n in (10, 30, 100):
            print(f"| {n * n} | {yardstick(root, n, args.seconds, True):.1f} | {yardstick(root, n, args.seconds, False):.1f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
