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
