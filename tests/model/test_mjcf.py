"""MJCF import: poses against MuJoCo's own kinematics, orientation forms, defaults, bad input."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin import Robot
from serialkin.errors import NotSupportedError, RobotDefinitionError
from serialkin.model.geometry import Box, Capsule, Cylinder, Mesh, Sphere
from serialkin.spatial.rotations import quaternion_to_matrix

DATA = Path(__file__).parent / "data"
ARM = DATA / "mjcf_arm_degree.xml"  # degrees, eulerseq zyx, defaults, childclass, frame
FLOATING = DATA / "mjcf_floating_radian.xml"  # radians, XyZ, free root, include
PANDA_MJCF = DATA / "mjcf_panda_from_urdf.xml"
_ERD = (Path(sys.prefix) / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}"
        / "site-packages" / "cmeel.prefix" / "share" / "example-robot-data")
PANDA_URDF = _ERD / "robots" / "panda_description" / "urdf" / "panda.urdf"


def _pose(pos, mat):
    T = np.eye(4)
    T[:3, :3] = np.asarray(mat).reshape(3, 3)
    T[:3, 3] = pos
    return T


def _body_id(m, name: str) -> int:
    """MuJoCo's id of a body by name; ``bodyN`` is the reader's name of unnamed body N."""
    try:
        return m.body(name).id
    except KeyError:
        return int(name.removeprefix("body"))


def _mujoco_agrees(path: Path, robot: Robot, tool_site: str | None, count: int = 20):
    """Largest difference to MuJoCo's body, site and geom poses at random configurations."""
    mujoco = pytest.importorskip("mujoco")
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    adr = [m.joint(name).qposadr[0] for name in robot.joint_names]
    rng = np.random.default_rng(7)
    lo = np.where(np.isfinite(robot.qlim[:, 0]), robot.qlim[:, 0], -math.pi)
    hi = np.where(np.isfinite(robot.qlim[:, 1]), robot.qlim[:, 1], math.pi)
    worst, checked = 0.0, 0
    for _ in range(count):
        q = rng.uniform(lo, hi)
        d.qpos[:] = m.qpos0
        d.qpos[adr] = q
        mujoco.mj_kinematics(m, d)
        frames = robot.fk_all(q)
        for i, link in enumerate(robot.link_names):
            if "#" in link:  # a frame between two joints of one body: not a MuJoCo body
                continue
            b = _body_id(m, link)
            worst = max(worst, np.abs(frames[i] - _pose(d.xpos[b], d.xmat[b])).max())
            checked += 1
        for lg in robot.geometry:
            for s in lg.visual + lg.collision:
                if not s.name:
                    continue
                g = m.geom(s.name).id
                worst = max(worst, np.abs(frames[lg.frame] @ s.origin
                                          - _pose(d.geom_xpos[g], d.geom_xmat[g])).max())
                checked += 1
        if tool_site is not None:
            s = m.site(tool_site).id
            tool = _pose(d.site_xpos[s], d.site_xmat[s])
        else:
            b = _body_id(m, robot.link_names[-1])
            tool = _pose(d.xpos[b], d.xmat[b])
        worst = max(worst, np.abs(robot.fk(q) - tool).max())
    return worst, checked


def test_degree_file_agrees_with_mujoco():
    """Degree file (defaults, childclass, all orientations): poses equal mj_kinematics's."""
    robot = Robot.from_mjcf(ARM, tool_site="tcp")
    worst, checked = _mujoco_agrees(ARM, robot, "tcp")
    assert checked > 100
    assert worst < 1e-10


def test_radian_file_with_free_root_agrees_with_mujoco():
    """Radian file (XyZ, include, free root skipped): poses equal mj_kinematics's."""
    robot = Robot.from_mjcf(FLOATING, tool_site="tool")
    assert robot.joint_names == ("s1", "s2", "e1", "w1")
    assert robot.link_names[0] == "torso"
    worst, checked = _mujoco_agrees(FLOATING, robot, "tool")
    assert checked > 50
    assert worst < 1e-10


def test_mujoco_testdata_model_leg_agrees():
    """A leg of the mujoco package's test model (unnamed bodies, classes) gives MuJoCo's poses."""
    mujoco = pytest.importorskip("mujoco")
    path = Path(mujoco.__file__).parent / "testdata" / "model.xml"
    robot = Robot.from_mjcf(path, end_body="body6")
    assert robot.joint_names == ("hipz_1", "hipy_1", "wheel_1")
    np.testing.assert_allclose(robot.qlim[0], np.radians([-60, 60]))
    worst, _ = _mujoco_agrees(path, robot, None)
    assert worst < 1e-10
    with pytest.raises(NotSupportedError, match="wheel_0.*ball"):
        Robot.from_mjcf(path, end_body="body4")


def test_arm_chain_limits_and_units():
    """Hinge ranges in degrees, slide in metres, limited=false drops a range; fingers branch off."""
    robot = Robot.from_mjcf(ARM)
    assert robot.name == "arm_degree"
    assert robot.joint_names == ("j1", "j2", "j3", "j4", "j5")
    assert robot.joint_types == ("R", "R", "P", "R", "R")
    assert robot.link_names == ("world", "link1", "link2", "link3#1", "link3", "link4")
    np.testing.assert_allclose(robot.qlim[:4], np.array(
        [np.radians([-170, 170]), np.radians([-170, 170]), [-0.1, 0.2], np.radians([-90, 120])]))
    assert np.isinf(robot.qlim[4]).all()
    assert "flange" in robot.source
    finger = Robot.from_mjcf(ARM, end_body="finger_l")
    assert finger.joint_names[-1] == "fl" and finger.n == 6


def test_hinge_with_pos_and_ref_by_hand():
    """A hinge at p with ref r moves its body by Tr(p)·Rz(q − r)·Tr(−p) (file pose at q = r)."""
    xml = """<mujoco><compiler angle="radian"/><worldbody>
      <body name="a" pos="1 0 0"><joint name="h" pos="0.5 0 0" ref="0.4"/>
        <geom size="0.1"/></body></worldbody></mujoco>"""
    robot = Robot.from_mjcf(xml)
    q = 1.1
    c, s = math.cos(q - 0.4), math.sin(q - 0.4)
    expected = np.array([[c, -s, 0, 1.5 - 0.5 * c], [s, c, 0, -0.5 * s], [0, 0, 1, 0],
                         [0, 0, 0, 1]])
    np.testing.assert_allclose(robot.fk([q]), expected, atol=1e-15)
    np.testing.assert_allclose(robot.fk([0.4]), _pose([1, 0, 0], np.eye(3)), atol=1e-15)


def _rotation_of(orientation: str, compiler: str = 'angle="radian"') -> np.ndarray:
    xml = (f"<mujoco><compiler {compiler}/><worldbody><body name='b' {orientation}>"
           "<joint name='j'/><geom size='0.1'/></body></worldbody></mujoco>")
    return Robot.from_mjcf(xml).fk([0.0])[:3, :3]


@pytest.mark.parametrize("seed", range(4))
def test_orientation_forms_agree(seed):
    """quat, axisangle, euler (any case, both units), xyaxes, zaxis of one rotation agree."""
    from scipy.spatial.transform import Rotation

    rot = Rotation.random(random_state=seed)
    R = rot.as_matrix()
    x, y, z = R[:, 0], R[:, 1], R[:, 2]
    w, v = rot.as_quat()[3], rot.as_quat()[:3]
    vec = rot.as_rotvec()
    angle = float(np.linalg.norm(vec))

    def fmt(a):
        return " ".join(repr(float(t)) for t in a)

    forms = {
        "quat": (f"quat='{fmt([2 * w, *(2 * v)])}'", 'angle="radian"'),  # not unit
        "axisangle rad": (f"axisangle='{fmt([*(3 * vec / angle), angle])}'", 'angle="radian"'),
        "axisangle deg": (f"axisangle='{fmt([*(vec / angle), math.degrees(angle)])}'", ""),
        # scipy's case convention is MuJoCo's reversed: scipy 'XYZ' is intrinsic
        "euler xyz": (f"euler='{fmt(rot.as_euler('XYZ'))}'", 'angle="radian"'),
        "euler XYZ": (f"euler='{fmt(rot.as_euler('xyz'))}'",
                      'angle="radian" eulerseq="XYZ"'),
        "euler zyx deg": (f"euler='{fmt(np.degrees(rot.as_euler('ZYX')))}'",
                          'eulerseq="zyx"'),
        "euler ZXZ deg": (f"euler='{fmt(np.degrees(rot.as_euler('zxz')))}'",
                          'angle="degree" eulerseq="ZXZ"'),
        "xyaxes": (f"xyaxes='{fmt([*(2 * x), *(y + 0.3 * x)])}'", 'angle="radian"'),
    }
    for name, (orientation, compiler) in forms.items():
        np.testing.assert_allclose(_rotation_of(orientation, compiler), R, atol=1e-12,
                                   err_msg=name)
    Rz = _rotation_of(f"zaxis='{fmt(3 * z)}'")
    np.testing.assert_allclose(Rz[:, 2], z, atol=1e-12)  # zaxis fixes only the z axis


def test_zaxis_is_the_smallest_rotation():
    """zaxis="0 0 -1" is a half turn about x, zaxis="1 0 0" a quarter turn about y."""
    np.testing.assert_allclose(_rotation_of("zaxis='0 0 -1'"), np.diag([1.0, -1.0, -1.0]),
                               atol=1e-15)
    np.testing.assert_allclose(_rotation_of("zaxis='2 0 0'"),
                               [[0, 0, 1], [0, 1, 0], [-1, 0, 0]], atol=1e-15)


def test_geometry_kinds_sizes_and_appearance():
    """MuJoCo half sizes become full sizes; contype=conaffinity=0 is visual only; rgba, material."""
    robot = Robot.from_mjcf(ARM)
    by_link = {lg.link_name: lg for lg in robot.geometry}
    assert set(by_link) == {"world", "base", "link1", "link2", "link3", "link4", "flange"}
    assert by_link["world"].visual == () and by_link["world"].collision == ()  # plane
    assert by_link["base"].frame == 0 and by_link["flange"].frame == 5
    base = by_link["base"].collision[0]
    assert base.geometry == Cylinder(0.06, 0.2)
    R_base = quaternion_to_matrix(np.array([0.9, 0.1, -0.2, 0.3]), normalize=True)
    np.testing.assert_allclose(base.origin[:3, 3], R_base @ [0, 0, 0.1] + [0.1, -0.2, 0.3],
                               atol=1e-15)
    assert isinstance(by_link["link1"].collision[0].geometry, Capsule)
    assert by_link["link3"].collision[0].geometry == Box((0.06, 0.04, 0.02))
    link4 = by_link["link4"]
    assert [s.name for s in link4.visual] == ["g_link4", "g_link4b"]
    assert [s.name for s in link4.collision] == ["g_link4b"]
    assert link4.visual[0].geometry == Sphere(0.05)
    assert by_link["link2"].visual[0].rgba == (0.1, 0.2, 0.3, 1.0)  # over the material's
    assert by_link["link1"].visual[0].rgba == (0.8, 0.2, 0.2, 1.0)  # from the class
    assert by_link["flange"].visual[0].rgba == (0.6, 0.6, 0.7, 1.0)
    assert by_link["flange"].visual[0].material == "steel"


def test_mesh_assets_resolve_through_meshdir(tmp_path):
    """A mesh geom names its file under meshdir with the asset's scale; missing ones are named."""
    (tmp_path / "assets").mkdir()
    (tmp_path / "assets" / "link.stl").write_bytes(b"solid x\nendsolid x\n")
    xml = """<mujoco><compiler meshdir="assets"/>
      <asset><mesh file="link.stl" scale="0.001 0.001 0.001"/><mesh name="gone" file="no.obj"/>
      </asset><worldbody><body name="a"><joint name="j"/>
        <geom type="mesh" mesh="link" pos="0 0 0.1"/>{extra}</body></worldbody></mujoco>"""
    path = tmp_path / "m.xml"
    path.write_text(xml.format(extra=""))
    robot = Robot.from_mjcf(path, resolve_meshes=True)
    mesh = robot.geometry[1].visual[0]
    assert mesh.geometry == Mesh(str((tmp_path / "assets" / "link.stl").resolve()),
                                 (0.001, 0.001, 0.001))
    np.testing.assert_allclose(mesh.origin[:3, 3], [0, 0, 0.1])
    path.write_text(xml.format(extra='<geom type="mesh" mesh="gone"/>'))
    assert Robot.from_mjcf(path).geometry[1].visual[1].geometry.filename.endswith("no.obj")
    with pytest.raises(RobotDefinitionError, match="<geom>: mesh file .no.obj. does not .*assets"):
        Robot.from_mjcf(path, resolve_meshes=True)


@pytest.mark.skipif(not PANDA_URDF.is_file(), reason="example-robot-data is not installed")
def test_panda_urdf_and_mjcf_agree():
    """example-robot-data's Panda URDF and an MJCF from its numbers give the same poses."""
    urdf = Robot.from_urdf(str(PANDA_URDF), tip_link="panda_hand_tcp")
    mjcf = Robot.from_mjcf(PANDA_MJCF, tool_site="panda_hand_tcp")
    Q = urdf.random_q(200, seed=1)
    np.testing.assert_allclose(mjcf.fk(Q), urdf.fk(Q), atol=1e-12)
    np.testing.assert_allclose(mjcf.fk_all(Q), urdf.fk_all(Q), atol=1e-12)
    np.testing.assert_array_equal(mjcf.qlim, urdf.qlim)
    assert mjcf.joint_names == urdf.joint_names


SIX_R_URDF = """<robot name="six">
  <link name="world"/><link name="l1"/><link name="l2"/><link name="l3"/><link name="l4"/>
  <link name="l5"/><link name="l6"/>
  <joint name="a1" type="revolute"><parent link="world"/><child link="l1"/>
    <origin xyz="0 0 0.089" rpy="0 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3"/></joint>
  <joint name="a2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0.136 0" rpy="0 1.5707963267948966 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3"/></joint>
  <joint name="a3" type="revolute"><parent link="l2"/><child link="l3"/>
    <origin xyz="0 -0.12 0.425" rpy="0 0 0"/><axis xyz="0 1 0"/><limit lower="-3" upper="3"/>
    </joint>
  <joint name="a4" type="revolute"><parent link="l3"/><child link="l4"/>
    <origin xyz="0 0 0.392" rpy="0 1.5707963267948966 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3"/></joint>
  <joint name="a5" type="revolute"><parent link="l4"/><child link="l5"/>
    <origin xyz="0 0.093 0" rpy="0.1 0.2 0.3"/><axis xyz="0 0 1"/><limit lower="-3" upper="3"/>
    </joint>
  <joint name="a6" type="continuous"><parent link="l5"/><child link="l6"/>
    <origin xyz="0 0 0.095" rpy="0 0 0"/><axis xyz="0 1 0"/></joint>
</robot>"""

SIX_R_MJCF = """<mujoco model="six"><compiler angle="degree" eulerseq="XYZ"/>
  <default><joint axis="0 1 0" range="-171.88733853924697 171.88733853924697"/></default>
  <worldbody>
    <body name="l1" pos="0 0 0.089"><joint name="a1" axis="0 0 1"/>
      <body name="l2" pos="0 0.136 0" quat="0.7071067811865476 0 0.7071067811865476 0">
        <joint name="a2"/>
        <body name="l3" pos="0 -0.12 0.425"><joint name="a3"/>
          <body name="l4" pos="0 0 0.392" axisangle="0 1 0 90"><joint name="a4"/>
            <body name="l5" pos="0 0.093 0"
                  euler="5.729577951308232 11.459155902616464 17.188733853924695">
              <joint name="a5" axis="0 0 1"/>
              <body name="l6" pos="0 0 0.095"><joint name="a6" limited="false"/></body>
            </body>
          </body>
        </body>
      </body>
    </body>
  </worldbody></mujoco>"""


def test_six_r_urdf_and_mjcf_agree():
    """A 6R arm written as URDF and as MJCF gives the same poses and limits."""
    urdf, mjcf = Robot.from_urdf(SIX_R_URDF), Robot.from_mjcf(SIX_R_MJCF)
    Q = urdf.random_q(100, seed=2)
    np.testing.assert_allclose(mjcf.fk_all(Q), urdf.fk_all(Q), atol=1e-12)
    np.testing.assert_allclose(mjcf.qlim, urdf.qlim, atol=1e-12)


# ------------------------------------------------------------------------------ bad input
def _one(body: str = "<body name='a'><joint name='j'/><geom size='0.1'/></body>",
         head: str = "") -> str:
    return f"<mujoco>{head}<worldbody>{body}</worldbody></mujoco>"


@pytest.mark.parametrize("xml, error, pattern", [
    (_one("<body name='a'><joint name='knee' type='ball'/></body>"), NotSupportedError,
     "knee.*ball"),
    (_one("<body name='a'><joint name='j'/><body name='b'><freejoint name='fj'/></body>"
          "</body>"), NotSupportedError, "fj.*free"),
    (_one("<body name='a'><joint name='j' class='arm'/></body>"), RobotDefinitionError,
     "<joint 'j'>.*unknown default class 'arm'"),
    (_one("<body name='a' childclass='nope'><joint name='j'/></body>"), RobotDefinitionError,
     "unknown default class 'nope'"),
    (_one("<body name='a' pos='1 2'><joint name='j'/></body>"), RobotDefinitionError,
     "<body 'a'> attribute 'pos'.*3 finite numbers.*'1 2'"),
    (_one("<body name='a' quat='1 0 zero 0'><joint name='j'/></body>"), RobotDefinitionError,
     "'quat'.*4 finite numbers"),
    (_one("<body name='a'><joint name='j' range='-1 nan'/></body>"), RobotDefinitionError,
     "'range'"),
    (_one("<body name='a' quat='1 0 0 0' euler='0 0 1'><joint name='j'/></body>"),
     RobotDefinitionError, "quat and euler.*at most one"),
    (_one(head="<compiler angle='grad'/>"), RobotDefinitionError, "'angle'.*degree"),
    (_one(head="<compiler eulerseq='xyw'/>"), RobotDefinitionError, "'eulerseq'"),
    (_one("<body name='a'><joint name='j' range='0 1'/></body>",
          head="<compiler autolimits='false'/>"), RobotDefinitionError, "autolimits"),
    (_one("<body name='a'><joint name='j' limited='true'/></body>"), RobotDefinitionError,
     "lower < upper"),
    (_one("<body name='a'><joint name='j' axis='0 0 0'/></body>"), RobotDefinitionError,
     "axis is zero"),
    (_one("<body name='a'><geom type='blob'/><joint name='j'/></body>"), RobotDefinitionError,
     "unknown geom type 'blob'"),
    (_one("<body name='a'><joint name='j'/><geom type='mesh' mesh='m'/></body>"),
     RobotDefinitionError, "<geom>: mesh 'm' is not an <asset><mesh>"),
    (_one("<body name='a'><joint name='j'/><geom size='-1'/></body>"), RobotDefinitionError,
     "sphere radius"),
    (_one("<body name='a'/>"), RobotDefinitionError, "no hinge or slide joint"),
    (_one("<body name='a'><joint name='j'/></body><body name='b'><joint name='k'/></body>"),
     RobotDefinitionError, "branches into a, b; pass end_body="),
    ("<robot name='r'/>", RobotDefinitionError, "root element must be <mujoco>"),
    ("<mujoco><worldbody>", RobotDefinitionError, "malformed XML at line 1"),
])
def test_bad_input_is_named(xml, error, pattern):
    """Bad MJCF raises the library's error naming the element, attribute or joint."""
    with pytest.raises(error, match=pattern):
        Robot.from_mjcf(xml)


def test_bad_chain_selection_is_named():
    """A missing end body or site, or an end body not below the base, is named."""
    with pytest.raises(RobotDefinitionError, match="end_body 'flang' is not a body.*'flange'"):
        Robot.from_mjcf(ARM, end_body="flang")
    with pytest.raises(RobotDefinitionError, match="tool_site 'tpc' is not a named site"):
        Robot.from_mjcf(ARM, tool_site="tpc")
    with pytest.raises(RobotDefinitionError, match="not below base body 'link3'"):
        Robot.from_mjcf(ARM, base_body="link3", end_body="link2")
    with pytest.raises(RobotDefinitionError, match="not fixed to the end body"):
        Robot.from_mjcf(ARM, end_body="link3", tool_site="tcp")
    with pytest.raises(RobotDefinitionError, match="does not exist"):
        Robot.from_mjcf(DATA / "no_such_file.xml")


def test_include_loop_is_refused(tmp_path):
    """A file that includes itself is refused instead of recursing."""
    (tmp_path / "a.xml").write_text("<mujoco><include file='a.xml'/></mujoco>")
    with pytest.raises(RobotDefinitionError, match="includes itself"):
        Robot.from_mjcf(tmp_path / "a.xml")


def test_base_body_starts_the_chain():
    """base_body makes that body's frame the base: poses are relative to it."""
    full = Robot.from_mjcf(ARM)
    sub = Robot.from_mjcf(ARM, base_body="link2")
    assert sub.joint_names == ("j3", "j4", "j5")
    q = np.array([0.3, -0.4, 0.05, 0.2, 0.7])
    np.testing.assert_allclose(full.fk_all(q)[2] @ sub.fk(q[2:]), full.fk(q), atol=1e-14)


# ------------------------------------------------------------------ random chains vs MuJoCo
# Numbers on a grid: MuJoCo snaps a geom whose rotation is below ~1e-5 rad onto its body
# frame (geom_sameframe), an approximation this reader does not make.
_num = st.integers(-20, 20).map(lambda i: i / 20)
_vec = st.lists(_num, min_size=3, max_size=3).filter(lambda v: np.linalg.norm(v) > 0.2)


@st.composite
def _orientation(draw):
    """One MJCF orientation attribute (or none) with random values."""
    kind = draw(st.sampled_from(["", "quat", "axisangle", "euler", "xyaxes", "zaxis"]))
    if kind == "quat":
        return f"quat='{draw(_num) + 1.2} {_fmt(draw(_vec))}'"
    if kind == "axisangle":
        return f"axisangle='{_fmt(draw(_vec))} {draw(_num) * 200}'"
    if kind == "euler":
        return f"euler='{_fmt(draw(_vec))}'"
    if kind == "xyaxes":
        x, y = np.array(draw(_vec)), np.array(draw(_vec))
        if np.linalg.norm(np.cross(x, y)) < 0.1 * np.linalg.norm(x) * np.linalg.norm(y):
            y = y + np.cross(x, [0.3, 0.5, 0.7]) + 0.5  # keep y off the line of x
        return f"xyaxes='{_fmt(x)} {_fmt(y)}'"
    if kind == "zaxis":
        return f"zaxis='{_fmt(draw(_vec))}'"
    return ""


def _fmt(v) -> str:
    return " ".join(repr(float(t)) for t in v)


@st.composite
def _random_chain(draw):
    """An MJCF string of a random serial chain: orientations, joint pos/axis/ref, units."""
    angle = draw(st.sampled_from(["degree", "radian"]))
    seq = "".join(draw(st.lists(st.sampled_from("xyzXYZ"), min_size=3, max_size=3)))
    depth = draw(st.integers(1, 4))
    xml, close, count = "", "", 0
    for b in range(depth):
        xml += f"<body name='b{b}' pos='{_fmt(draw(_vec))}' {draw(_orientation())}>"
        for _ in range(draw(st.integers(0 if b else 1, 2))):
            kind = draw(st.sampled_from(["hinge", "slide"]))
            xml += (f"<joint name='j{count}' type='{kind}' axis='{_fmt(draw(_vec))}' "
                    f"pos='{_fmt(draw(_vec))}' ref='{draw(_num)}'/>")
            count += 1
        xml += f"<geom size='0.05' {draw(_orientation())} pos='{_fmt(draw(_vec))}' name='g{b}'/>"
        close = "</body>" + close
    # armature keeps MuJoCo's mass matrix regular (no warning log) for any joint axes
    return (f"<mujoco><compiler angle='{angle}' eulerseq='{seq}'/>"
            f"<default><joint armature='0.1'/></default><worldbody>{xml}{close}"
            "</worldbody></mujoco>")


@settings(max_examples=30, deadline=None)
@given(xml=_random_chain(), seed=st.integers(0, 2**16))
def test_random_chains_agree_with_mujoco(xml, seed):
    """Random chains (any orientation form, eulerseq, unit, joint pos/axis/ref) match MuJoCo."""
    mujoco = pytest.importorskip("mujoco")
    robot = Robot.from_mjcf(xml)
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    q = np.random.default_rng(seed).uniform(-2.0, 2.0, robot.n)
    d.qpos[[m.joint(name).qposadr[0] for name in robot.joint_names]] = q
    mujoco.mj_kinematics(m, d)
    frames = robot.fk_all(q)
    for i, link in enumerate(robot.link_names):
        if "#" not in link:
            b = m.body(link).id
            np.testing.assert_allclose(frames[i], _pose(d.xpos[b], d.xmat[b]), atol=1e-10)
    for lg in robot.geometry:
        for s in lg.collision:
            g = m.geom(s.name).id
            np.testing.assert_allclose(frames[lg.frame] @ s.origin,
                                       _pose(d.geom_xpos[g], d.geom_xmat[g]), atol=1e-10)


def _tetrahedron_stl(size: float) -> bytes:
    """A binary STL (what MuJoCo reads) of the tetrahedron 0, size·e_x, size·e_y, size·e_z."""
    import struct

    v = np.array([[0, 0, 0], [size, 0, 0], [0, size, 0], [0, 0, size]], dtype=float)
    faces = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    data = bytearray(80) + struct.pack("<I", len(faces))
    for f in faces:
        n = np.cross(v[f[1]] - v[f[0]], v[f[2]] - v[f[0]])
        data += struct.pack("<12fH", *(n / np.linalg.norm(n)), *v[list(f)].ravel(), 0)
    return bytes(data)


_MESH_ARM = """<mujoco model="mesh_arm">
  <compiler angle="radian" meshdir="parts" autolimits="true"/>
  <default>
    <default class="arm">
      <joint axis="0 0 1" range="-2.5 2.5"/>
      <mesh scale="0.5 0.5 0.5"/>
      <default class="visual"><geom type="mesh" contype="0" conaffinity="0" group="2"/></default>
      <default class="collision"><geom type="mesh" group="3"/>
        <default class="pad"><geom type="box" size="0.01 0.02 0.03" pos="0 0.01 0.04"/></default>
      </default>
    </default>
  </default>
  <asset>
    <material class="arm" name="blue" rgba="0 0 1 1"/>
    <mesh class="arm" file="shell.stl"/>
    <mesh class="arm" name="shell_c" file="shell.stl" scale="1 1 1"/>
  </asset>
  <worldbody>
    <body name="base" childclass="arm">
      <geom mesh="shell" class="visual" material="blue"/>
      <geom mesh="shell_c" class="collision"/>
      <body name="upper" pos="0 0 0.3" quat="1 -1 0 0">
        <joint name="shoulder"/>
        <geom mesh="shell" class="visual"/>
        <geom name="upper_pad" class="pad"/>
        <body name="fore" pos="0 -0.3 0" quat="1 1 0 0">
          <joint name="elbow" range="-1 1"/>
          <geom mesh="shell_c" class="collision"/>
          <geom name="fore_pad" class="pad" quat="0 0 0 1"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>"""


def test_menagerie_style_classes_and_meshes(tmp_path):
    """Visual/collision classes, mesh class defaults, meshdir and materials read as MuJoCo does."""
    (tmp_path / "parts").mkdir()
    (tmp_path / "parts" / "shell.stl").write_bytes(_tetrahedron_stl(0.1))
    path = tmp_path / "mesh_arm.xml"
    path.write_text(_MESH_ARM)
    robot = Robot.from_mjcf(path, resolve_meshes=True)
    assert robot.joint_names == ("shoulder", "elbow")
    np.testing.assert_allclose(robot.qlim, [[-2.5, 2.5], [-1.0, 1.0]])
    by_link = {lg.link_name: lg for lg in robot.geometry}
    shell = str((tmp_path / "parts" / "shell.stl").resolve())
    base = by_link["base"]
    assert base.visual[0].geometry == Mesh(shell, (0.5, 0.5, 0.5))  # scale from the class
    assert base.visual[0].rgba == (0.0, 0.0, 1.0, 1.0) and base.visual[0].material == "blue"
    assert [s.geometry for s in base.collision] == [Mesh(shell, (1.0, 1.0, 1.0))]
    assert by_link["upper"].collision[0].geometry == Box((0.02, 0.04, 0.06))
    assert by_link["upper"].visual[0].geometry.scale == (0.5, 0.5, 0.5)
    assert [len(by_link["fore"].visual), len(by_link["fore"].collision)] == [0, 2]
    worst, checked = _mujoco_agrees_primitives(path, robot)
    assert checked >= 10 and worst < 1e-10


def _mujoco_agrees_primitives(path: Path, robot: Robot):
    """Like :func:`_mujoco_agrees`, over named (primitive) geoms and bodies only."""
    mujoco = pytest.importorskip("mujoco")
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    worst, checked = 0.0, 0
    for q in robot.random_q(5, seed=3):
        d.qpos[[m.joint(name).qposadr[0] for name in robot.joint_names]] = q
        mujoco.mj_kinematics(m, d)
        frames = robot.fk_all(q)
        for i, link in enumerate(robot.link_names):
            b = m.body(link).id
            worst = max(worst, np.abs(frames[i] - _pose(d.xpos[b], d.xmat[b])).max())
            checked += 1
        for lg in robot.geometry:
            for s in lg.collision:
                if s.name:
                    g = m.geom(s.name).id
                    worst = max(worst, np.abs(frames[lg.frame] @ s.origin
                                              - _pose(d.geom_xpos[g], d.geom_xmat[g])).max())
                    checked += 1
    return worst, checked
