"""Headless Chromium for the browser tests (Debian's ``chromium`` and ``chromium-driver``).

Selenium is given explicit paths to the browser and the driver, so Selenium Manager never
runs and nothing is downloaded. :func:`start_chromium` returns a driver with a fresh
profile in a temporary directory and the DevTools performance log enabled
(:func:`network_requests` reads the URLs the page requested from it).

Use :func:`require_chromium` at the start of a fixture: it skips the test when Chromium
is absent on a developer machine, but fails loudly when the environment variable ``CI``
is set, so a CI job cannot pass by skipping the browser tests.
"""

from __future__ import annotations

import io
import json
import os
import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

CHROMIUM = Path("/usr/bin/chromium")
CHROMEDRIVER = Path("/usr/bin/chromedriver")
CHROMIUM_FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--enable-unsafe-swiftshader",
    "--use-angle=swiftshader",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
)


def chromium_missing() -> str | None:
    """Why the browser tests cannot run here, or ``None`` if Chromium and its driver are present."""
    for path in (CHROMIUM, CHROMEDRIVER):
        if not (path.is_file() and os.access(path, os.X_OK)):
            return f"{path} is missing (scripts/install_browser.sh installs Debian's chromium and its driver)"
    try:
        import selenium  # noqa: F401
    except ImportError:
        return "selenium is not installed (pip install -e '.[test]')"
    return None


def require_chromium() -> None:
    """Skip (developer machine) or fail (``CI`` set) when Chromium cannot run."""
    import pytest

    reason = chromium_missing()
    if reason is None:
        return
    if os.environ.get("CI"):
        pytest.fail(f"browser tests must run in CI: {reason}", pytrace=False)
    pytest.skip(reason)


@contextmanager
def start_chromium(width: int = 800, height: int = 500) -> Iterator[Any]:
    """A headless Chromium WebDriver with a throw-away profile; quits it on exit.

    Args:
        width: Window width [px].
        height: Window height [px].
    """
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    profile = tempfile.mkdtemp(prefix="twolink-chromium-")
    options = webdriver.ChromeOptions()
    options.binary_location = str(CHROMIUM)
    for flag in CHROMIUM_FLAGS:
        options.add_argument(flag)
    options.add_argument(f"--user-data-dir={profile}")
    options.add_argument(f"--window-size={width},{height}")
    options.set_capability("goog:loggingPrefs", {"performance": "ALL", "browser": "ALL"})
    service = Service(executable_path=str(CHROMEDRIVER))  # explicit path: Selenium Manager is skipped
    driver = webdriver.Chrome(service=service, options=options)
    try:
        driver.set_script_timeout(30)
        yield driver
    finally:
        driver.quit()
        shutil.rmtree(profile, ignore_errors=True)


BROWSER_PAGES = ("chrome://", "chrome-untrusted://", "devtools://")
"""Documents of the browser's own UI (its new-tab page loads at start-up); not the test's."""


def network_requests(driver: Any) -> list[str]:
    """URLs of every request made since the last call by any document but the browser's own
    pages (DevTools ``Network`` events: HTTP(S), file:, data: and WebSocket)."""
    urls = []
    for entry in driver.get_log("performance"):
        message = json.loads(entry["message"])["message"]
        params = message.get("params", {})
        if params.get("documentURL", "").startswith(BROWSER_PAGES):
            continue
        if message.get("method") == "Network.requestWillBeSent":
            urls.append(params["request"]["url"])
        elif message.get("method") == "Network.webSocketCreated":
            urls.append(params["url"])
    return urls


def screenshot(driver: Any) -> np.ndarray:
    """The window as an RGB(A) array of floats in [0, 1], shape (height, width, 3 or 4)."""
    import matplotlib.image

    return np.asarray(matplotlib.image.imread(io.BytesIO(driver.get_screenshot_as_png()), format="png"))


SCENE_HELPERS = """
function node(path) {
  var n = viewer.scene_tree;
  for (var i = 0; i < path.length; i++) { n = n.children[path[i]]; if (n === undefined) return null; }
  return n;
}
function visual(root, name) { return node(['meshcat', root, 'visuals', name, '<object>']).object; }
function ours(object, local) {  // a point of object's frame, in our (x, y, z) [m]
  viewer.scene.updateMatrixWorld(true);
  var v = object.localToWorld(object.position.clone().set(local[0], local[1], local[2]));
  return viewer.scene.worldToLocal(v).toArray();
}
function pose(object) {  // object's 4x4 transform in our frame, column-major
  viewer.scene.updateMatrixWorld(true);
  return object.matrixWorld.clone().premultiply(viewer.scene.matrixWorld.clone().invert()).elements;
}
function bounds(object) {  // bounding box of the drawn vertices in our frame: [min, max] [m]
  var m = object.matrixWorld.clone().premultiply(viewer.scene.matrixWorld.clone().invert());
  var p = object.geometry.attributes.position, v = object.position.clone(), lo = [1e9, 1e9, 1e9], hi = [-1e9, -1e9, -1e9];
  for (var i = 0; i < p.count; i++) {
    v.set(p.getX(i), p.getY(i), p.getZ(i)).applyMatrix4(m);
    var a = v.toArray();
    for (var k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], a[k]); hi[k] = Math.max(hi[k], a[k]); }
  }
  return [lo, hi];
}
function onScreen(points) {  // our points [m] -> normalised device coordinates of the camera
  viewer.scene.updateMatrixWorld(true); viewer.camera.updateMatrixWorld(true);
  return points.map(function (p) {
    var v = viewer.camera.position.clone().set(p[0], p[1], p[2]);
    return viewer.scene.localToWorld(v).project(viewer.camera).toArray();
  });
}
function link2End(root) {
  var mesh = visual(root, 'link2_0');
  return ours(mesh, [mesh.geometry.parameters.width / 2, 0, 0]);
}
function visibleTrail() {
  var pieces = node(['meshcat', 'trail']).children, shown = 0, total = 0;
  for (var k in pieces) { total += 1; if (pieces[k].object.visible) shown += 1; }
  return [shown, total];
}
function seek(t) { viewer.animator.pause(); viewer.animator.seek(t); }
"""
"""JavaScript helpers for reading a meshcat scene in the page (``viewer`` is meshcat's
``Viewer``): ``node(path)`` walks the scene tree; ``visual(root, name)`` is a link's mesh;
``ours`` / ``pose`` / ``bounds`` map the drawn objects back to our (x, y, z) frame [m]
(three.js draws ``(x, y, z)`` as ``(x, z, −y)`` and the scene root is shifted);
``onScreen`` projects our points; ``link2End(root)`` is the end of the twolink's link 2;
``visibleTrail()`` counts the trail's shown pieces; ``seek(t)`` pauses the animation at
``t`` [s]."""


def scene_js(driver: Any, body: str, *args: Any) -> Any:
    """Run ``body`` in the page (or the frame the driver is in) with :data:`SCENE_HELPERS` defined."""
    return driver.execute_script(SCENE_HELPERS + body, *args)
