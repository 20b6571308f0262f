"""Headless Chromium for the browser tests (selenium), shared by every test that drives it.

Needs the Debian packages ``chromium`` and ``chromium-driver`` (``make browser-deps``) and
selenium (``dev`` extra); :func:`start_chromium` skips the calling test, saying why, when
one is missing.
"""

import shutil
import tempfile

import pytest

CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-dev-shm-usage",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    # software WebGL (SwiftShader) must be asked for explicitly since Chromium 137
    "--enable-unsafe-swiftshader",
    "--window-size=1100,760",
]


def _find(*names):
    for name in names:
        path = shutil.which(name)
        if path:
            return path
    return None


def start_chromium(extra_flags=()):
    """Start headless Chromium; return (driver, profile dir) or skip saying what is missing."""
    webdriver = pytest.importorskip(
        "selenium.webdriver", reason="selenium is not installed (pip install -e '.[dev]')"
    )
    from selenium.webdriver.chrome.service import Service

    chromium = _find("chromium", "chromium-browser", "google-chrome")
    chromedriver = _find("chromedriver")
    if chromium is None or chromedriver is None:
        missing = " and ".join(
            n for n, p in (("chromium", chromium), ("chromedriver", chromedriver)) if p is None
        )
        pytest.skip(f"{missing} not found on PATH (install Debian packages chromium and "
                    "chromium-driver, e.g. `make browser-deps`)")
    profile = tempfile.mkdtemp(prefix="serialkin-chromium-")
    options = webdriver.ChromeOptions()
    options.binary_location = chromium
    for flag in [*CHROMIUM_FLAGS, *extra_flags]:
        options.add_argument(flag)
    options.add_argument(f"--user-data-dir={profile}")
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    try:
        drv = webdriver.Chrome(options=options, service=Service(chromedriver))
    except Exception as exc:  # noqa: BLE001 - any start-up failure means: cannot test here
        shutil.rmtree(profile, ignore_errors=True)
        pytest.skip(f"headless Chromium could not start: {str(exc).splitlines()[0]}")
    return drv, profile


