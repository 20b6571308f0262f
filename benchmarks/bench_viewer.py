"""The viewer page with the robot's meshes: build time, file size, open time in Chromium.

Run by hand: ``.venv/bin/python benchmarks/bench_viewer.py [--repeat 5]``. Needs the
``mesh`` extra (trimesh, fast-simplification) and example-robot-data (``bench`` extra)
for the Panda and UR5 URDFs; the open time needs Chromium, chromedriver and selenium
(``tests/_browser.py``) and is skipped without them.

For each robot, the page at the default mesh budget (``MESH_BUDGET`` triangles) and the
same robot without meshes (``meshes=False``: the skeleton, the baseline) in the same run:

* build cold: ``viewer_html`` with the mesh cache cleared (files parsed, decimated,
  encoded); build warm: meshes cached (decimation and encoding only);
* file size [MB] of the page (goal 12.5: the Panda at most 5 MB);
* open: headless Chromium (software WebGL, SwiftShader) loading the file from
  ``file://``, from the start of navigation to a drawn, scriptable page
  (``window.serialkin.state.readyMs``: parse, three.js import, mesh decoding and the first
  render; goal 12.5: under 2 s).

No peer writes a comparable self-contained page (meshcat and viser serve a scene from a
Python process), so the baseline is the page without meshes. Figures are the median
[min-max] of the runs.
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from _common import Stat, header, record, wall_s  # noqa: E402
from tests.erd import robots_dir, urdf  # noqa: E402

import serialkin as sk  # noqa: E402

ROBOTS = (("Panda", "panda_description/urdf/panda.urdf", "panda_link0", "panda_hand"),
          ("UR5", "ur_description/urdf/ur5_robot.urdf", None, "tool0"))
#: Goal 12.5 (issue 12 item 5): the Panda's page with meshes.
SIZE_TARGET_MB = 5.0
OPEN_TARGET_S = 2.0


class _Browser:
    """A headless Chromium for the open-time rows, or None when it cannot start."""

    def __init__(self) -> None:
        self.driver = None
        self.profile = None
        try:
            from selenium import webdriver
            from selenium.webdriver.chrome.service import Service
            from tests._browser import CHROMIUM_FLAGS, _find
        except ImportError as exc:
            self.why = f"selenium missing ({exc})"
            return
        chromium, chromedriver = _find("chromium", "chromium-browser"), _find("chromedriver")
        if chromium is None or chromedriver is None:
            self.why = "chromium or chromedriver not on PATH"
            return
        self.profile = tempfile.mkdtemp(prefix="serialkin-bench-")
        options = webdriver.ChromeOptions()
        options.binary_location = chromium
        for flag in [*CHROMIUM_FLAGS, f"--user-data-dir={self.profile}"]:
            options.add_argument(flag)
        self.driver = webdriver.Chrome(options=options, service=Service(chromedriver))
        self.why = ""

    def open_s(self, page: Path, repeat: int) -> Stat:
        """Seconds from navigation start to the viewer's ready state, ``repeat`` loads."""
        out = []
        for _ in range(repeat + 1):  # the first load warms the browser's caches
            self.driver.get("about:blank")
            self.driver.get(page.resolve().as_uri())
            deadline = time.monotonic() + 60
            ms = None
            while time.monotonic() < deadline:
                ms = self.driver.execute_script(
                    "return window.serialkin && window.serialkin.state.readyMs")
                if ms:
                    break
                time.sleep(0.02)
            if not ms:
                raise RuntimeError(f"{page} did not become ready")
            out.append(ms / 1000.0)
        return Stat(out[1:])

    def close(self) -> None:
        if self.driver is not None:
            self.driver.quit()
        if self.profile:
            shutil.rmtree(self.profile, ignore_errors=True)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="runs per figure")
    args = ap.parse_args(argv)
    try:
        import trimesh  # noqa: F401
    except ImportError:
        print("skipped: the viewer's meshes need the mesh extra (pip install -e '.[mesh]')")
        return 0
    if robots_dir() is None:
        print("skipped: example-robot-data is not installed (pip install -e '.[bench]')")
        return 0
    from serialkin.formats.mesh import clear_mesh_cache
    from serialkin.viz import Scene, ViewerOptions
    from serialkin.viz.viewer import MESH_BUDGET, viewer_html

    print(header())
    print(f"mesh budget {MESH_BUDGET} triangles; median [min-max] of {args.repeat} runs")
    browser = _Browser()
    if browser.driver is None:
        print(f"open times skipped: {browser.why}")
    pkg = {"example-robot-data": robots_dir().parent}
    head = (f"{'page':26s} {'build cold [s]':>22s} {'build warm [s]':>22s} {'size [MB]':>9s} "
            f"{'open [s]':>22s}")
    print(head)
    print("-" * len(head))
    try:
        with tempfile.TemporaryDirectory() as tmp:
            for name, rel, base, tip in ROBOTS:
                robot = sk.Robot.from_urdf(str(urdf(rel)), base, tip, package_map=pkg,
                                           resolve_meshes=True)
                for meshes in (True, False):

                    def cold(r=robot, m=meshes):
                        clear_mesh_cache()
                        return viewer_html(Scene(r), ViewerOptions(meshes=m))

                    t_cold = wall_s(cold, args.repeat)
                    t_warm = wall_s(lambda r=robot, m=meshes: viewer_html(
                        Scene(r), ViewerOptions(meshes=m)),
                                    args.repeat)
                    page = Path(tmp) / f"{name}_{meshes}.html"
                    text = viewer_html(Scene(robot), ViewerOptions(meshes=meshes))
                    page.write_text(text, encoding="utf-8")
                    mb = len(text.encode("utf-8")) / 1e6
                    t_open = browser.open_s(page, args.repeat) if browser.driver else None
                    label = f"{name} {'meshes' if meshes else 'no meshes (baseline)'}"
                    print(f"{label:26s} {t_cold.fmt(3):>22s} {t_warm.fmt(3):>22s} {mb:9.2f} "
                          f"{t_open.fmt(3) if t_open else '-':>22s}")
                    if not meshes:
                        continue
                    record("12.5", f"{name} viewer page with meshes, file size", mb, "MB",
                           f"<= {SIZE_TARGET_MB:g} MB", mb <= SIZE_TARGET_MB)
                    if t_open is not None:
                        record("12.5", f"{name} viewer page opens in headless Chromium (median)",
                               t_open.median, "s", f"< {OPEN_TARGET_S:g} s",
                               t_open.median < OPEN_TARGET_S)
    finally:
        browser.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
