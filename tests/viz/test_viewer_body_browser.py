"""The robot's body in headless Chromium: shapes drawn and moving, toggles, in-page collisions.

Needs the Debian packages ``chromium`` and ``chromium-driver`` and selenium (see
``tests/_browser.py``); the mesh tests also need trimesh (the ``mesh`` extra).
"""

from __future__ import annotations

import shutil
import time
from pathlib import Path

import numpy as np
import pytest

from serialkin import models
from serialkin.collision import self_clearance
from serialkin.viz.viewer import Scene, write_viewer
from tests._browser import start_chromium
from tests.erd import urdf as erd_urdf
from tests.viz._body import SHAPES, body_robot

pytestmark = pytest.mark.browser

FOLDED = np.array([0.0, 0.0, 0.0, -3.0, 0.0, 0.5, 0.0])  # the Panda's elbow folded
READY = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])  # the SRDF's 'default' state


@pytest.fixture(scope="module")
def driver():
    """A headless Chromium session, or a skip that names what is missing."""
    drv, profile = start_chromium()
    yield drv
    drv.quit()
    shutil.rmtree(profile, ignore_errors=True)


def _load(driver, page: Path) -> None:
    driver.get_log("browser")
    driver.get(page.resolve().as_uri())
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        if driver.execute_script("return !!(window.serialkin && window.serialkin.ready)"):
            return
        time.sleep(0.05)
    raise AssertionError(f"viewer did not become ready; log: {driver.get_log('browser')}")


def _severe(driver) -> list:
    return [e for e in driver.get_log("browser") if e.get("level") == "SEVERE"]


def _drawn(driver) -> dict:
    return driver.execute_script("return window.serialkin.drawn()")


def _click(driver, box_id: str) -> None:
    driver.find_element("id", box_id).click()


def _slide(driver, i: int, value: float) -> None:
    driver.execute_script(
        "const s = document.getElementById(arguments[0]);"
        "s.value = arguments[1]; s.dispatchEvent(new Event('input', {bubbles: true}));",
        f"sk-joint-{i}", float(value))


def test_shapes_drawn_follow_the_sliders_and_toggles(driver, tmp_path):
    """Every visual shape is drawn at fk_all[frame]·origin after slider moves; toggles hide it."""
    robot = body_robot(tmp_path)
    P = np.random.default_rng(0).uniform(-0.5, 0.5, (200, 3))
    page = write_viewer(Scene(robot, points=P, points_label="cloud"), tmp_path / "body.html")
    _load(driver, page)
    d = _drawn(driver)
    assert (d["shapes"], d["meshes"], d["primitives"]) == (5, 1, 4)
    assert d["triangles"] == 320 and d["points"] == 200 and d["skeleton"] is False
    origins = [s.origin for lg in robot.geometry for s in lg.visual]
    frames = [lg.frame for lg in robot.geometry for _ in lg.visual]
    for q in ([0.4, -0.3], [-1.2, 1.1]):
        for i, v in enumerate(q):
            _slide(driver, i, v)
        F = robot.fk_all(np.array(q))
        poses = np.array(driver.execute_script("return window.serialkin.shapePoses()"))
        for k, (_, kind) in enumerate(SHAPES):
            if kind in ("box", "mesh", "sphere"):  # cylinders/capsules carry the y->z turn
                np.testing.assert_allclose(poses[k], F[frames[k]] @ origins[k], atol=1e-9)
    assert "cloud (200)" in driver.find_element("id", "sk-points-label").text
    _click(driver, "sk-show-visual")
    _click(driver, "sk-show-skeleton")
    _click(driver, "sk-show-points")
    d = _drawn(driver)
    assert (d["shapes"], d["triangles"], d["points"], d["skeleton"]) == (0, 0, 0, True)
    assert not driver.find_element("id", "sk-show-collision").is_displayed()  # no model
    assert _severe(driver) == []


def test_folded_panda_highlights_the_pair_self_clearance_reports(driver, tmp_path):
    """Sliding the Panda into a folded pose: the page's closest pair and distance are Python's."""
    panda = models.panda()
    model = panda.collision
    page = write_viewer(Scene(panda, q=READY), tmp_path / "panda.html")
    _load(driver, page)
    clear = driver.execute_script("return window.serialkin.clearance()")
    ref = self_clearance(panda, model, READY)
    assert ref.distance > 0 and clear["colliding"] == []
    assert clear["distance"] == pytest.approx(float(ref.distance), abs=1e-9)
    assert driver.find_element("id", "sk-collision").text.startswith("clear")
    assert _drawn(driver)["capsules"] == 0
    _click(driver, "sk-show-collision")
    assert _drawn(driver)["capsules"] == len(model.radius)
    for i, v in enumerate(FOLDED):
        _slide(driver, i, v)
    q = np.array(driver.execute_script("return window.serialkin.getJoints()"))
    ref = self_clearance(panda, model, q)
    pair = list(ref.names(model)[0])
    clear = driver.execute_script("return window.serialkin.clearance()")
    assert ref.distance < 0
    assert clear["pair"] == pair
    assert clear["distance"] == pytest.approx(float(ref.distance), abs=1e-9)
    assert pair in [c[:2] for c in clear["colliding"]]
    text = driver.find_element("id", "sk-collision").text
    assert text.startswith("colliding") and f"{pair[0]} – {pair[1]}" in text
    assert "sk-hit" in driver.find_element("id", "sk-collision").get_attribute("class")
    assert _severe(driver) == []


def test_panda_meshes_drawn_and_turn_red(driver, tmp_path):
    """The Panda of example-robot-data: nine meshes drawn; folded, the colliding links' go red."""
    pytest.importorskip("trimesh", reason='needs the mesh extra (serialkin[mesh])')
    path = erd_urdf("panda_description/urdf/panda.urdf")
    if path is None:
        pytest.skip("example-robot-data (bench extra) is not installed")
    from serialkin import Robot

    robot, _ = Robot.from_urdf(str(path), "panda_link0", "panda_hand",
                               package_map={"example-robot-data": Path(path).parents[3]},
                               resolve_meshes=True).fit_collision()
    page = write_viewer(Scene(robot, q=READY), tmp_path / "panda.html")
    _load(driver, page)
    d = _drawn(driver)
    assert d["meshes"] == 9 and d["skeleton"] is False and 0 < d["triangles"] <= 60_000
    assert d["highlighted"] == [] and d["capsulesHit"] == 0
    state = driver.execute_script("return window.serialkin.state")
    assert state["webgl"] is True and state["renders"] >= 1
    _slide(driver, 3, -1.5)
    np.testing.assert_allclose(
        driver.execute_script("return window.serialkin.endEffector().matrix"),
        robot.fk(np.r_[READY[:3], -1.5, READY[4:]]), atol=1e-9)
    driver.execute_script("window.serialkin.setJoints(arguments[0])", FOLDED.tolist())
    pair = self_clearance(robot, robot.collision, FOLDED).names(robot.collision)[0]
    colliding = driver.execute_script("return window.serialkin.clearance().colliding")
    red = set(_drawn(driver)["highlighted"])
    assert set(pair) <= red
    assert red == {name for c in colliding for name in c[:2]}
    assert _drawn(driver)["capsulesHit"] > 0  # red even while hidden
    assert _severe(driver) == []
