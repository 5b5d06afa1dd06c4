"""The sheet live in a browser: a local server (aiohttp, bound to 127.0.0.1
only) that loads the FMU with fmpy, runs one instance per page in real time
and sends it the modal coordinates each frame; the page (three.js,
viewing/static/) expands them with the mode shapes and draws the sheet in 3D
(2D scenes flat), with its controls beside it.

    .venv/bin/python python/view.py [FMU] [--scene NAME] [--set NAME=VALUE ...] [--port 8080] [--no-open]
    cargo xtask view -- --scene cloth-3d

Scenes: `default` (the FMU's start values), the canonical scenes of
modelDescription/variables.toml and `cloth-3d-100x100` (cloth 100 x 100 on
16 load modes with static correction). --set NAME=VALUE sets any parameter
or structural parameter on top, in every scene the picker offers
(Enumerations by item name, Booleans true/false, arrays as values separated
by spaces). Every scene is set up with anchorMotion and anchorRotation, so a
modal basis of load modes holds the holders' motion.

Each page gets its own FMU instance (freed when the page closes); a value a
page sends is checked before the FMU sees it and a refused one is shown on
the page with the reason, the instance keeping its last good state; a message that is not one of
the protocol's (viewing/protocol.py) is refused with the reason and the page
goes on.
"""

import argparse
import asyncio
import collections
import json
import os
import sys
import threading
import time
import webbrowser

from sheet import Fmu, scene

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_FMU = os.path.join(ROOT, "target", "fmu", "ModalMassSpring.fmu")
BIG = {"nx": 100, "ny": 100, "dimension": 3, "fixedNodes": 1, "auxStiffness": 0.05, "loadColumn": 50}
BIG.update({"nModes": 16, "modeSelection": "load", "staticCorrection": True})
PREPARED = {"anchorMotion": True, "anchorRotation": True}


def parse_value(var, text):
    """A --set value as the variable's type wants it."""
    if var.type == "Boolean":
        if text.lower() not in ("true", "false", "1", "0"):
            raise ValueError(f"{var.name}: true or false, not {text!r}")
        return text.lower() in ("true", "1")
    if var.type == "Enumeration":
        return int(text) if text.isdigit() else text
    if var.type in ("UInt64", "Int64"):
        return int(text)
    values = [float(x) for x in text.split()]
    return values if len(values) > 1 or var.dimensions else values[0]


def scene_table(fmu, overrides):
    """Scene name -> the values its instance is set up with."""
    with open(os.path.join(ROOT, "modelDescription", "variables.toml"), "rb") as f:
        import tomllib

        names = list(tomllib.load(f)["scenes"])
    table = {"default": {}}
    for name in names:
        table[name] = scene(name)
    table["cloth-3d-100x100"] = dict(BIG)
    for values in table.values():
        values.update(PREPARED)
        values.update(overrides)
    for name, values in table.items():
        unknown = [n for n in values if n not in fmu.vars]
        if unknown:
            raise ValueError(f"scene {name}: no variables {', '.join(unknown)}")
    return table


def overrides_of(fmu, sets):
    out = {}
    for item in sets:
        name, eq, text = item.partition("=")
        if not eq or name not in fmu.vars:
            raise ValueError(f"--set {item}: NAME=VALUE with a variable of the FMU")
        var = fmu.vars[name]
        if var.causality not in ("parameter", "structuralParameter"):
            raise ValueError(f"--set {name}: not a parameter ({var.causality})")
        out[name] = parse_value(var, text)
    return out


STATIC = os.path.join(ROOT, "python", "viewing", "static")
# Binary frames of these kinds only the newest counts (a slow page skips frames, never lags).
FRAMES = (1, 2)


class Connection:
    """One page's websocket: what its Page sends queued (control messages in
    order, of the frames only the newest) and sent from the server's loop."""

    def __init__(self, loop):
        self.loop, self.outbox, self.latest = loop, collections.deque(), None
        self.ready = asyncio.Event()

    def push(self, message):
        """Thread-safe: a dict (JSON) or bytes (binary) for the page."""
        if isinstance(message, bytes) and int.from_bytes(message[:4], "little") in FRAMES:
            self.latest = message
        else:
            if isinstance(message, dict) and message.get("type") == "instance":
                self.latest = None  # a frame of the instance before
            self.outbox.append(json.dumps(message) if isinstance(message, dict) else message)
        self.loop.call_soon_threadsafe(self.ready.set)

    async def pump(self, ws):
        try:
            while not ws.closed:
                await self.ready.wait()
                self.ready.clear()
                while self.outbox:
                    m = self.outbox.popleft()
                    await (ws.send_str(m) if isinstance(m, str) else ws.send_bytes(m))
                frame, self.latest = self.latest, None
                if frame is not None:
                    await ws.send_bytes(frame)
        except ConnectionError:
            pass  # the page went: its handler frees the instance


class Viewer:
    """The server (aiohttp on 127.0.0.1: the page, its libraries, a websocket per page) and its pages."""

    def __init__(self, fmu_path, scene_name="default", sets=(), port=8080, fps=60.0):
        from aiohttp import web

        from viewing import assets

        self.assets = assets.ensure()
        self.fmu = Fmu(fmu_path)
        self.scenes = scene_table(self.fmu, overrides_of(self.fmu, sets))
        if scene_name not in self.scenes:
            raise ValueError(f"--scene {scene_name}: one of {', '.join(self.scenes)}")
        self.scene_name, self.fps = scene_name, fps
        self.pages, self.sockets, self.lock, self.count = {}, set(), threading.Lock(), 0
        app = web.Application()
        async def index(_):
            return web.FileResponse(os.path.join(STATIC, "index.html"))

        app.router.add_get("/", index)
        app.router.add_get("/ws", self._page)
        app.router.add_static("/static/", STATIC)
        app.router.add_static("/three/", os.path.join(self.assets, "three"))
        app.router.add_static("/lil-gui/", os.path.join(self.assets, "lil-gui"))
        self.loop = asyncio.new_event_loop()
        self.runner = web.AppRunner(app, access_log=None)
        self.loop.run_until_complete(self.runner.setup())
        for self.port in range(port, port + 20):
            site = web.TCPSite(self.runner, "127.0.0.1", self.port)
            try:
                self.loop.run_until_complete(site.start())
                break
            except OSError:
                continue
        else:
            raise OSError(f"no free port in {port}..{port + 19} on 127.0.0.1")
        self.thread = threading.Thread(target=self.loop.run_forever, name="view-server", daemon=True)
        self.thread.start()

    async def _page(self, request):
        from aiohttp import WSMsgType, web

        from viewing.page import Page

        # Messages up to 4 MiB reach the protocol's check (and its refusal); larger ones end the connection.
        ws = web.WebSocketResponse(max_msg_size=1 << 22, heartbeat=None)
        await ws.prepare(request)
        self.sockets.add(ws)
        connection = Connection(asyncio.get_running_loop())
        with self.lock:
            self.count += 1
            label = f"page {self.count}"
        page = await asyncio.to_thread(Page, connection.push, self.fmu, self.scenes, self.scene_name, self.fps, label)
        with self.lock:
            self.pages[label] = page
        pump = asyncio.create_task(connection.pump(ws))
        try:
            async for message in ws:
                if message.type in (WSMsgType.TEXT, WSMsgType.BINARY):
                    await asyncio.to_thread(page.receive, message.data)
        finally:
            pump.cancel()
            self.sockets.discard(ws)
            with self.lock:
                self.pages.pop(label, None)
            await asyncio.to_thread(page.close)
        return ws

    def url(self):
        return f"http://127.0.0.1:{self.port}"

    def close(self):
        async def stop():
            for ws in list(self.sockets):
                await ws.close()
            await self.runner.cleanup()

        asyncio.run_coroutine_threadsafe(stop(), self.loop).result(timeout=20)
        with self.lock:
            pages, self.pages = list(self.pages.values()), {}
        for page in pages:
            page.close()
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(timeout=5)
        self.fmu.close()


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("fmu", nargs="?", default=DEFAULT_FMU, help="default: target/fmu/ModalMassSpring.fmu")
    p.add_argument("--scene", default="default", help="the scene a page opens with (default: the FMU's start values)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help="a parameter on top of every scene (repeatable)")
    p.add_argument("--port", type=int, default=8080, help="the port on 127.0.0.1 (default 8080; the next free one if taken)")
    p.add_argument("--fps", type=float, default=60.0, help="frames a second sent to each page (default 60)")
    p.add_argument("--no-open", action="store_true", help="do not open a browser")
    args = p.parse_args(argv)
    try:
        viewer = Viewer(args.fmu, args.scene, args.set, args.port, args.fps)
    except (ValueError, OSError) as e:
        print(f"view: {e}", file=sys.stderr)
        return 2
    print(f"view: {viewer.url()} (Ctrl-C stops)", flush=True)
    if not args.no_open:
        webbrowser.open(viewer.url())
    try:
        while True:
            time.sleep(1.0)
    except KeyboardInterrupt:
        pass
    finally:
        viewer.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
