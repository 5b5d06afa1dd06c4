"""The page's libraries, from the npm registry: three.js (with its
OrbitControls, TransformControls and CSS2DRenderer from examples/jsm) and
lil-gui, each tarball fetched once with urllib, checked against the sha512
integrity the registry published for the pinned version, and unpacked
under target/view-assets/<package>. No npm needed; without the network the
view says what to fetch and where."""

import base64
import hashlib
import io
import os
import shutil
import sys
import tarfile
import urllib.request

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ASSETS = os.path.join(ROOT, "target", "view-assets")
# package: (version, dist.integrity of https://registry.npmjs.org/<package>/<version>)
PINNED = {
    "three": ("0.187.0", "sha512-Qiu7R+Cmh8CstZsY1uJOSWnVlfo7ZtNLV7mF8Jltk3LB3AtDu9cRZlcnRKkAk8Y4z6KKw35z7Y7Urd7jWY8etA=="),
    "lil-gui": ("0.21.0", "sha512-tpvxN7v1GvE/Tv+GRopfOp0W7fVEjF4PltkuX8vOCIfim22rD1ztvfkoEMcv9lzQeuNUSeIrUmUjBwmlW/oUew=="),
}
# What the page imports of each package (a package is ready when these are there).
NEEDED = {"three": "build/three.module.js", "lil-gui": "dist/lil-gui.esm.js"}


def url(package):
    version, _ = PINNED[package]
    return f"https://registry.npmjs.org/{package}/-/{package}-{version}.tgz"


def checked(package, data):
    """The tarball's bytes if their sha512 is the pinned integrity, else ValueError."""
    _, integrity = PINNED[package]
    got = "sha512-" + base64.b64encode(hashlib.sha512(data).digest()).decode()
    if got != integrity:
        raise ValueError(f"{url(package)}: sha512 {got} is not the pinned {integrity}")
    return data


def unpack(package, data, root=ASSETS):
    """The tarball's package/ directory as root/<package> (replaced whole)."""
    into, partial = os.path.join(root, package), os.path.join(root, package + ".partial")
    shutil.rmtree(partial, ignore_errors=True)
    with tarfile.open(fileobj=io.BytesIO(data), mode="r:gz") as tar:
        tar.extractall(partial, filter="data")
    shutil.rmtree(into, ignore_errors=True)
    os.replace(os.path.join(partial, "package"), into)
    shutil.rmtree(partial)


def ready(root=ASSETS):
    return all(os.path.exists(os.path.join(root, p, f)) for p, f in NEEDED.items())


def ensure(root=ASSETS, timeout=60.0):
    """Fetches, checks and unpacks what is missing; OSError saying what failed (offline, say)."""
    for package, needed in NEEDED.items():
        if os.path.exists(os.path.join(root, package, needed)):
            continue
        print(f"view: fetching {url(package)} into {root}", file=sys.stderr)
        try:
            with urllib.request.urlopen(url(package), timeout=timeout) as r:
                data = checked(package, r.read())
        except (OSError, ValueError) as e:
            raise OSError(f"the page's {package} {PINNED[package][0]} could not be fetched ({e}); fetch {url(package)} with network once") from None
        unpack(package, data, root)
    return root


if __name__ == "__main__":
    print(ensure())
