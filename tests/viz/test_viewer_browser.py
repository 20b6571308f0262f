"""The viewer page in headless Chromium (selenium): loads, draws, in-page FK agrees.

The drawn end effector must sit where ``Robot.fk`` says, to 1e-9.

Needs the Debian packages ``chromium`` and ``chromium-driver`` (``make browser-deps``) and
selenium (``dev`` extra); every test here skips, saying why, when one is missing.
"""

import io
import shutil
import time

import numpy as np
import pytest

from serialkin import Joint, Robot
from serialkin.viz.plot import robot_points
from serialkin.viz.viewer import Scene, write_viewer
from tests._browser import start_chromium as _start

pytestmark = pytest.mark.browser

@pytest.fixture(scope="module")
def driver():
    """A headless Chromium session, or a skip that names what is missing."""
    drv, profile = _start()
    yield drv
    drv.quit()
    shutil.rmtree(profile, ignore_errors=True)


def _general_robot():
    """A robot in general joint form (URDF-like): tilted axes, a prismatic joint, base, tool."""
    def T(p, rz=0.0):
        c, s = np.cos(rz), np.sin(rz)
        M = np.eye(4)
        M[:3, :3] = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
        M[:3, 3] = p
        return M

    tilt = np.array([0.3, -0.4, 0.866])
    joints = [
        Joint(axis=np.array([0.0, 0.0, 1.0]), origin=T([0, 0, 0.3])),
        Joint(axis=np.array([0.0, 1.0, 0.0]), origin=T([0.05, 0, 0.2], 0.4), offset=0.2),
        Joint(axis=tilt / np.linalg.norm(tilt), origin=T([0.4, 0, 0])),
        Joint(axis=np.array([1.0, 0.0, 0.0]), type="P", origin=T([0.1, 0.05, 0]),
              qlim=(0.0, 0.25)),
        Joint(axis=np.array([0.0, 0.0, 1.0]), origin=T([0.1, 0, 0.05], -0.3),
              post=T([0.02, 0, 0.0])),
    ]
    return Robot.from_joints(joints, base=T([0.2, -0.1, 0.05], 0.5), tool=T([0, 0, 0.08]),
                             name="general5")


def _load(driver, tmp_path, robot, **kwargs):
    page = write_viewer(Scene(robot, **kwargs), tmp_path / f"{robot.name}.html")
    driver.get_log("browser")  # drop what earlier pages logged
    driver.get(page.resolve().as_uri())
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        if driver.execute_script("return !!(window.serialkin && window.serialkin.ready)"):
            return
        time.sleep(0.05)
    logs = driver.get_log("browser")
    raise AssertionError(f"viewer did not become ready; browser log: {logs}")


def _severe(driver):
    return [e for e in driver.get_log("browser") if e.get("level") == "SEVERE"]


def _end_effector(driver):
    return np.array(driver.execute_script("return window.serialkin.endEffector().matrix"))


def test_loads_without_console_errors_and_draws(driver, tmp_path, spatial4):
    """The page loads with no console errors, WebGL runs, and the canvas is not blank."""
    from PIL import Image

    Q = spatial4.random_q(8, seed=2)
    _load(driver, tmp_path, spatial4, trajectory=Q, path_points=spatial4.fk(Q)[:, :3, 3],
          obstacles=[dict(center=[0.3, 0.3, 0.4], radius=0.08),
                     dict(center=[-0.3, 0, 0.2], radius=0.05, height=0.4),
                     dict(a=[0, -0.4, 0], b=[0.3, -0.4, 0.3], radius=0.04)])
    assert _severe(driver) == []
    state = driver.execute_script("return window.serialkin.state")
    assert state["webgl"] is True and state["error"] is None and state["renders"] >= 1
    canvas = driver.find_element("id", "sk-canvas")
    img = np.asarray(Image.open(io.BytesIO(canvas.screenshot_as_png)).convert("RGB"))
    assert img.shape[0] > 100 and img.shape[1] > 100
    colours = np.unique(img.reshape(-1, 3), axis=0)
    assert len(colours) > 50, "canvas looks blank"
    assert img.std() > 5.0


def test_slider_input_moves_end_effector_to_fk(driver, tmp_path, spatial4):
    """Setting a joint slider and firing 'input' moves the drawn end effector to robot.fk."""
    _load(driver, tmp_path, spatial4, q=[0.1, 0.2, 0.05, -0.3])
    before = _end_effector(driver)
    for i, value in enumerate([0.7, -0.45, 0.21, 1.3]):
        driver.execute_script(
            "const s = document.getElementById(arguments[0]);"
            "s.value = arguments[1]; s.dispatchEvent(new Event('input', {bubbles: true}));",
            f"sk-joint-{i}", value)
        q = np.array(driver.execute_script("return window.serialkin.getJoints()"))
        assert q[i] == pytest.approx(value, abs=1e-12)
        np.testing.assert_allclose(_end_effector(driver), spatial4.fk(q), atol=1e-9)
    assert not np.allclose(before, _end_effector(driver))
    assert _severe(driver) == []


def test_dragging_slider_with_mouse(driver, tmp_path, planar3):
    """A real click on a joint slider changes q, the readout and the drawn end effector."""
    from selenium.webdriver.common.action_chains import ActionChains

    _load(driver, tmp_path, planar3, q=[0.0, 0.0, 0.0])
    slider = driver.find_element("id", "sk-joint-1")
    width = slider.size["width"]
    ActionChains(driver).move_to_element_with_offset(slider, int(width * 0.3), 0).click().perform()
    q = np.array(driver.execute_script("return window.serialkin.getJoints()"))
    assert q[1] > 0.5  # 80 % of [-pi, pi]
    assert float(slider.get_attribute("value")) == pytest.approx(q[1], abs=1e-12)
    np.testing.assert_allclose(_end_effector(driver), planar3.fk(q), atol=1e-9)
    x = planar3.fk(q)[0, 3]
    assert f"x {x:.4f}" in driver.find_element("id", "sk-ee").text


def test_set_joint_api_matches_fk_for_general_robot(driver, tmp_path):
    """setJoint/setJoints put a general robot's drawn tool and links at fk/fk_all (1e-9)."""
    robot = _general_robot()
    _load(driver, tmp_path, robot)
    for q in robot.random_q(10, seed=7):
        driver.execute_script("window.serialkin.setJoints(arguments[0])", q.tolist())
        np.testing.assert_allclose(_end_effector(driver), robot.fk(q), atol=1e-9)
        drawn = np.array(driver.execute_script("return window.serialkin.linkOrigins()"))
        np.testing.assert_allclose(drawn, robot_points(robot, q), atol=1e-9)
    q = robot.random_q(1, seed=8)[0]
    driver.execute_script("window.serialkin.setJoints(arguments[0])", q.tolist())
    q[3] = 0.17
    driver.execute_script("window.serialkin.setJoint(3, 0.17)")
    np.testing.assert_allclose(_end_effector(driver), robot.fk(q), atol=1e-9)
    assert _severe(driver) == []


def test_trajectory_frames_and_play(driver, tmp_path, planar3):
    """setFrame(k) shows trajectory row k; Play advances the frame by itself."""
    Q = np.linspace([0.0, 0.0, 0.0], [1.0, -1.0, 0.5], 12)
    _load(driver, tmp_path, planar3, trajectory=Q)
    for k in (0, 5, 11):
        driver.execute_script("window.serialkin.setFrame(arguments[0])", k)
        np.testing.assert_allclose(_end_effector(driver), planar3.fk(Q[k]), atol=1e-9)
        assert driver.find_element("id", "sk-frame-label").text == f"{k + 1} / 12"
    driver.execute_script("window.serialkin.setFrame(0)")
    driver.find_element("id", "sk-play").click()
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline:
        if driver.execute_script("return window.serialkin.state.frame") > 0:
            break
        time.sleep(0.05)
    driver.execute_script("window.serialkin.pause()")
    k = driver.execute_script("return window.serialkin.state.frame")
    assert k > 0
    np.testing.assert_allclose(_end_effector(driver), planar3.fk(Q[k]), atol=1e-9)
    assert _severe(driver) == []


def test_keyboard_and_limit_highlight(driver, tmp_path, spatial4):
    """Arrow keys move a slider by 1/200 of its range; leaving the limits turns it red."""
    from selenium.webdriver.common.keys import Keys

    _load(driver, tmp_path, spatial4, q=[0.0, 0.0, 0.1, 0.0])
    slider = driver.find_element("id", "sk-joint-0")
    slider.send_keys(Keys.ARROW_RIGHT)
    q = np.array(driver.execute_script("return window.serialkin.getJoints()"))
    assert q[0] == pytest.approx(2 * np.pi / 200, abs=1e-12)
    np.testing.assert_allclose(_end_effector(driver), spatial4.fk(q), atol=1e-9)
    unit = driver.find_element("id", "sk-unit-2")
    assert "sk-outside" not in unit.get_attribute("class")
    driver.execute_script("window.serialkin.setJoint(2, 0.5)")  # limits (0, 0.3) m
    assert "sk-outside" in unit.get_attribute("class")
    assert _severe(driver) == []


def test_without_webgl_page_still_computes(tmp_path, planar3):
    """With WebGL disabled the page says so, logs no error, and still computes FK."""
    drv, profile = _start(["--disable-webgl", "--disable-3d-apis"])
    try:
        _load(drv, tmp_path, planar3)
        state = drv.execute_script("return window.serialkin.state")
        assert state["webgl"] is False
        message = drv.find_element("id", "sk-message")
        assert message.is_displayed() and "WebGL" in message.text
        drv.execute_script("window.serialkin.setJoint(1, 0.4)")
        np.testing.assert_allclose(_end_effector(drv), planar3.fk([0.0, 0.4, 0.0]), atol=1e-9)
        assert _severe(drv) == []
    finally:
        drv.quit()
        shutil.rmtree(profile, ignore_errors=True)


@pytest.mark.slow
def test_random_dh_robots_both_conventions(driver, tmp_path):
    """Random DH robots (both conventions, R/P, base, tool): page FK equals robot.fk."""
    rng = np.random.default_rng(11)
    for k in range(6):
        n = int(rng.integers(2, 8))
        rows = []
        for _ in range(n):
            kind = "P" if rng.random() < 0.25 else "R"
            rows.append(dict(a=float(rng.uniform(-0.5, 0.5)),
                             alpha=float(rng.uniform(-np.pi, np.pi)),
                             d=float(rng.uniform(-0.3, 0.3)),
                             theta=float(rng.uniform(-np.pi, np.pi)), type=kind,
                             qlim=(-0.4, 0.4) if kind == "P" else (-np.inf, np.inf)))
        base, tool = np.eye(4), np.eye(4)
        base[:3, 3] = rng.uniform(-0.2, 0.2, 3)
        tool[:3, 3] = rng.uniform(-0.1, 0.1, 3)
        convention = ("standard", "modified")[k % 2]
        robot = Robot.from_dh(rows, convention, base=base, tool=tool, name=f"random{k}")
        _load(driver, tmp_path, robot)
        for q in robot.random_q(3, seed=k):
            driver.execute_script("window.serialkin.setJoints(arguments[0])", q.tolist())
            np.testing.assert_allclose(_end_effector(driver), robot.fk(q), atol=1e-9)
            page_fk = np.array(driver.execute_script("return window.serialkin.fk(arguments[0])",
                                                     q.tolist()))
            np.testing.assert_allclose(page_fk, robot.fk(q), atol=1e-12)
    assert _severe(driver) == []
