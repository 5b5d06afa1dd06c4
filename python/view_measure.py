"""Frame rates and latency of the live view (python/view.py) in Debian's
Chromium, headless (software WebGL: no GPU here), per scene:

- frames/s the server sends to the page and the real-time factor of its run;
- messages/s the page receives and frames/s it draws (counted in the page),
  and the time its script spends a frame expanding the modes and in all of
  its draw() with three.js's calls (the rest of a frame is the browser's);
- control -> FMU: a weight typed into the page until the FMU has it;
- control -> screen: Pause clicked until the page's button reads Play (the
  round trip through the server to the page's DOM), and a weight typed into
  the page until the page draws a frame of the FMU's having it;
- frames/s the page draws while paused (no frames arrive: its drawing alone).

    .venv/bin/python python/view_measure.py [FMU] [--scene default --scene cloth-3d-100x100] [--seconds 5] [--screenshots DIR] [--antialias]
"""

import argparse
import os
import sys
import time

import numpy as np

from view import DEFAULT_FMU, Viewer
from viewing import clients
from viewing.page import in_class


def measure(fmu, scene, seconds, screenshots, fps=60.0, antialias=False):
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys

    viewer = Viewer(fmu, scene, port=clients.free_port(), fps=fps)
    driver = clients.chromium()
    try:
        driver.get(viewer.url() + ("/?antialias=1" if antialias else ""))
        clients.until(lambda: viewer.pages, timeout=120)
        (page,) = viewer.pages.values()
        clients.until(lambda: "frames/s" in driver.find_element(By.TAG_NAME, "body").text, timeout=120)
        time.sleep(2.0)
        clients.counted(driver)
        script = "return [view.drawn, view.expanding, view.drawing]"
        f0, t0, w0, s0 = page.frames_sent, page.status()["time"], time.perf_counter(), driver.execute_script(script)
        time.sleep(seconds)
        received, drawn = clients.counted(driver)
        wall, s1 = time.perf_counter() - w0, driver.execute_script(script)
        frames = max(s1[0] - s0[0], 1)
        row = {
            "scene": scene,
            "nodes": page.session.n,
            "sent/s": (page.frames_sent - f0) / wall,
            "real-time factor": (page.status()["time"] - t0) / wall,
            "received/s": len(received) / wall,
            "drawn/s": len(drawn) / wall,
            "expanding [ms/frame]": (s1[1] - s0[1]) / frames,
            "draw() [ms/frame]": (s1[2] - s0[2]) / frames,
        }
        if screenshots:
            os.makedirs(screenshots, exist_ok=True)
            driver.save_screenshot(os.path.join(screenshots, f"{scene}.png"))
        # control -> FMU: a class weight typed into the page; -> screen: the page draws a frame sent after it.
        s = page.session
        label = next(c for c in ("out-of-plane", "in-plane") if np.any(in_class(s, c)))
        box = clients.number_box(driver, f"{label} (")
        box.send_keys(Keys.CONTROL, "a")
        before = s.weights.copy()
        start = time.perf_counter()
        box.send_keys("0")
        clients.until(lambda: not np.array_equal(s.weights, before), timeout=10, every=0.0005)
        row["control -> FMU [ms]"] = 1e3 * (time.perf_counter() - start)
        after = page.frames_sent
        clients.until(lambda: driver.execute_script("return view.frame") > after, timeout=10, every=0.0005)
        row["control -> screen [ms]"] = 1e3 * (time.perf_counter() - start)
        # Pause until the button reads Play.
        button = driver.find_element(By.XPATH, "//button[contains(., 'Pause')]")
        start = time.perf_counter()
        button.click()
        clients.until(lambda: driver.find_elements(By.XPATH, "//button[contains(., 'Play')]"), timeout=10)
        row["Pause -> button [ms]"] = 1e3 * (time.perf_counter() - start)
        # Paused: the server sends no frames; what the page draws then is its drawing alone.
        time.sleep(0.5)
        clients.counted(driver)
        time.sleep(seconds)
        row["drawn/s paused"] = len(clients.counted(driver)[1]) / seconds
        return row
    finally:
        driver.quit()
        viewer.close()


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("fmu", nargs="?", default=DEFAULT_FMU)
    p.add_argument("--scene", action="append", default=None, help="default: default and cloth-3d-100x100")
    p.add_argument("--seconds", type=float, default=5.0)
    p.add_argument("--screenshots", default=None, help="a directory for a screenshot per scene")
    p.add_argument("--fps", type=float, default=60.0, help="frames a second the server sends (default 60)")
    p.add_argument("--antialias", action="store_true", help="the page multisampled (?antialias=1)")
    args = p.parse_args(argv)
    rows = [measure(args.fmu, s, args.seconds, args.screenshots, args.fps, args.antialias) for s in args.scene or ["default", "cloth-3d-100x100"]]
    keys = list(rows[0])
    print("| " + " | ".join(keys) + " |")
    print("|" + "---|" * len(keys))
    for r in rows:
        print("| " + " | ".join(f"{r[k]:.1f}" if isinstance(r[k], float) else str(r[k]) for k in keys) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
