"""URDF import and export: kinematics and link geometry (meshes are named, never loaded).

Parsing uses the standard library's :mod:`xml.etree.ElementTree`: URDF is plain XML, the
parser is well kept and adds no dependency. The serial chain between ``base_link`` and
``tip_link`` is extracted; fixed joints are merged into the neighbouring transforms
(those before the first moving joint into its origin, those after the last into the tool).

Which chain: ``base_link`` defaults to the tree's root. Without ``tip_link`` the tip is
chosen by a stated rule (:func:`choose_chain`, its reason in ``robot.source``):

1. the ``parent_link`` of the ``<end_effector>`` of an SRDF, when ``srdf=`` is given;
2. the single leaf, when the tree below the base does not branch;
3. a link named like a tool point: ``tcp``, then ``tool``/``tool0``, then ``flange``, then
   ``ee``/``eef``/``end_effector`` (a word of its name, e.g. ``panda_hand_tcp``,
   ``tool0``); the deepest such link when several share the best kind;
4. else the leaf at the end of the chain with the most moving joints (the deepest chain),
   when it is the only one that deep.

``package://NAME/rest`` mesh paths resolve (:class:`MeshResolver`) from ``package_map``,
then the search folders, then an ancestor folder of the file named ``NAME`` or holding a
``package.xml`` whose ``<name>`` is ``NAME``, then ``$ROS_PACKAGE_PATH`` (``ROOT/NAME``,
or ``ROOT`` or a folder just below it whose ``package.xml`` names it) and
``$AMENT_PREFIX_PATH`` (``PREFIX/share/NAME``).

URDF conventions: a joint's ``<origin xyz rpy>`` is the pose of the joint frame in the
parent link frame with ``R = Rz(yaw)·Ry(pitch)·Rx(roll)``; the motion is about/along
``<axis xyz>`` (default x) in the joint frame; the child link frame is the joint frame
after the motion. That is exactly :class:`~serialkin.model.joint.Joint` with
``origin`` = the URDF origin and ``post`` = identity.
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from serialkin._checks import beyond_a_turn, short_repr
from serialkin._files import MAX_NUMBER
from serialkin.errors import NotSupportedError, RobotDefinitionError
from serialkin.formats.xmlfile import parse_floats, read_robot_xml
from serialkin.model.geometry import Box, Capsule, Cylinder, LinkGeometry, Mesh, Shape, Sphere
from serialkin.model.joint import Joint
from serialkin.model.robot import Robot
from serialkin.spatial.transforms import make_transform, rotx, roty, rotz

__all__ = ["ChainChoice", "MeshResolver", "choose_chain", "package_folders", "robot_from_urdf",
           "robot_to_urdf", "rpy_to_matrix"]

_MOVING = {"revolute": "R", "continuous": "R", "prismatic": "P"}
_UNSUPPORTED = {"floating", "planar"}


@dataclass
class _UJoint:
    name: str
    type: str
    parent: str
    child: str
    origin: np.ndarray
    axis: np.ndarray
    lower: float
    upper: float
    unsupported: str = ""
    velocity: float = np.inf


def rpy_to_matrix(rpy: np.ndarray) -> np.ndarray:
    """URDF rotation ``Rz(yaw)·Ry(pitch)·Rx(roll)`` for ``rpy = (roll, pitch, yaw)`` [rad]."""
    return rotz(rpy[2]) @ roty(rpy[1]) @ rotx(rpy[0])


def _origin(el: ET.Element | None, where: str) -> np.ndarray:
    if el is None:
        return np.eye(4)
    xyz = parse_floats(el.get("xyz"), 3, (0.0, 0.0, 0.0), f"{where} <origin xyz>", MAX_NUMBER)
    rpy = parse_floats(el.get("rpy"), 3, (0.0, 0.0, 0.0), f"{where} <origin rpy>", MAX_NUMBER)
    if beyond_a_turn(rpy).any():  # URDF angles are radians
        raise RobotDefinitionError(
            f"{where} <origin rpy>: {' '.join(f'{v:g}' for v in rpy)} has an angle beyond a "
            "full turn; URDF angles are radians (are these degrees?)")
    return make_transform(rpy_to_matrix(rpy), xyz)


def _parse_joint(el: ET.Element, source: str) -> _UJoint:
    name = el.get("name")
    if not name:
        raise RobotDefinitionError(f"{source}: a <joint> has no name attribute")
    where = f"{source}: joint {short_repr(name)}"
    jtype = el.get("type")
    if jtype is None:
        raise RobotDefinitionError(f"{where} has no type attribute")
    unsupported = ""
    if jtype in _UNSUPPORTED:
        unsupported = (f"{where} is of type {short_repr(jtype)}, which is not supported "
                       "(serial chains of revolute, continuous, prismatic and fixed joints)")
    elif el.find("mimic") is not None:
        unsupported = f"{where} has a <mimic> element; mimic joints are not supported"
    if jtype not in _MOVING and jtype != "fixed" and not unsupported:
        raise RobotDefinitionError(
            f"{where} has unknown type {short_repr(jtype)}; expected revolute, continuous, "
            "prismatic or fixed"
        )
    parent, child = el.find("parent"), el.find("child")
    if parent is None or parent.get("link") is None:
        raise RobotDefinitionError(f"{where} has no <parent link=...>")
    if child is None or child.get("link") is None:
        raise RobotDefinitionError(f"{where} has no <child link=...>")
    axis = parse_floats(el.find("axis").get("xyz") if el.find("axis") is not None else None, 3,
                   (1.0, 0.0, 0.0), f"{where} <axis xyz>", MAX_NUMBER)
    if jtype in _MOVING and np.linalg.norm(axis) < 1e-12:
        raise RobotDefinitionError(f"{where} has a zero <axis xyz>; expected a nonzero 3-vector")
    lower, upper = -np.inf, np.inf
    lim = el.find("limit")
    if jtype in ("revolute", "prismatic") and lim is not None:
        lower = float(parse_floats(lim.get("lower"), 1, (-np.inf,), f"{where} <limit lower>")[0]) \
            if lim.get("lower") is not None else -np.inf
        upper = float(parse_floats(lim.get("upper"), 1, (np.inf,), f"{where} <limit upper>")[0]) \
            if lim.get("upper") is not None else np.inf
        if lower > upper:
            raise RobotDefinitionError(
                f"{where}: <limit> lower {lower:g} is greater than upper {upper:g}"
            )
    velocity = np.inf
    if jtype in _MOVING and lim is not None and lim.get("velocity") is not None:
        v = float(parse_floats(lim.get("velocity"), 1, (np.inf,),
                               f"{where} <limit velocity>")[0])
        # URDF requires the attribute, so files without a known limit write a
        # placeholder 0 (serialkin's own export did, before it kept the limits): zero or
        # a negative value states no limit.
        velocity = v if v > 0.0 else np.inf
    return _UJoint(name, jtype, parent.get("link"), child.get("link"),
                   _origin(el.find("origin"), where), axis, lower, upper, unsupported,
                   velocity)


def robot_from_urdf(path_or_string: str | os.PathLike[str], base_link: str | None = None,
                    tip_link: str | None = None, *,
                    package_map: Mapping[str, str | os.PathLike[str]] | None = None,
                    search_path: Sequence[str | os.PathLike[str]] = (),
                    resolve_meshes: bool = False,
                    srdf: str | os.PathLike[str] | None = None,
                    whole_tree: bool = False) -> Robot:
    """Build a :class:`~serialkin.Robot` from the serial chain of a URDF.

    Args:
        path_or_string: a URDF file path, or the XML text itself.
        base_link: link whose frame is the robot's base (default: the tree's root).
        tip_link: link whose frame is the tool (default: chosen by the rule of
            :func:`choose_chain`, stated in ``robot.source``).
        package_map: package name -> folder, for mesh paths ``package://NAME/rest``.
        search_path: folders where ``package://NAME/rest`` is looked up as
            ``FOLDER/NAME/rest`` and a relative mesh path as ``FOLDER/path`` (after the
            URDF's own folder); ancestors and ROS paths are searched after them
            (:class:`MeshResolver`).
        resolve_meshes: if true, a mesh path that does not resolve to an existing file is
            an error; otherwise it is kept as written.
        srdf: an SRDF (path or text) whose ``<end_effector parent_link>`` is the default tip.
        whole_tree: also give the geometry of the links off the chain that hang on it
            through moving joints (a gripper's fingers), posed with those joints at 0
            (or the nearest limit): for a viewer of the whole robot.

    Returns:
        Robot with one joint per moving (revolute, continuous, prismatic) URDF joint,
        limits read (continuous: unlimited), ``velocity_limits`` from ``<limit
        velocity>`` [rad/s or m/s] (``inf`` for a joint whose value is 0 or missing; None
        when no joint states one; URDF has no acceleration limits, so
        ``acceleration_limits`` is None), joint names kept, ``link_names`` set, and
        ``geometry``: one :class:`~serialkin.model.geometry.LinkGeometry` per link of the
        chain or fixed to it through fixed joints, with ``<visual>``/``<collision>``
        shapes posed in the chain frame the link is merged into.

    Raises:
        RobotDefinitionError: malformed XML (with line), a joint referring to a missing link,
            a loop, a branching tree without ``tip_link``, a zero axis, lower > upper, a
            negative or non-finite geometry size, an unresolved mesh with ``resolve_meshes``.
        NotSupportedError: mimic, floating or planar joints on the chain.
    """
    root, source = read_robot_xml(path_or_string)
    tree = _read_tree(root, source)
    choice = _choose(tree, base_link, tip_link, srdf, source)
    base, tip = choice.base, choice.tip
    chain = _chain_between(tree, base, tip, source)
    out, link_names, fixed = _moving_joints(chain, base, tip, source)
    speeds = [j.velocity for j in chain if j.type != "fixed"]
    folder = None if source == "<string>" else Path(source).resolve().parent
    places = _link_frames(base, chain, tree.children, tree.by_child, whole_tree)
    resolver = MeshResolver(folder, package_map or {}, search_path, resolve_meshes)
    geometry = tuple(
        _link_geometry(el, places[el.get("name")], source, resolver)
        for el in root.findall("link") if el.get("name") in places)
    how = "" if choice.rule == "given" else f"; tip: {choice.reason}"
    return Robot(out, tool=fixed, name=root.get("name") or "urdf_robot",
                 source=f"URDF {source} ({base} -> {tip}{how})",
                 link_names=tuple(link_names) + ((tip,) if link_names[-1] != tip else ()),
                 geometry=geometry,
                 velocity_limits=speeds if np.isfinite(speeds).any() else None)


@dataclass(frozen=True, eq=False)
class _Tree:
    """The links and joints of a URDF, checked to form one tree.

    Attributes:
        links: link names, in file order.
        link_set: the same names, as a set.
        by_child: the joint whose child each link is (every link but the root).
        children: the child links of each link.
        root: the root link.
    """

    links: list[str]
    link_set: set[str]
    by_child: dict[str, _UJoint]
    children: dict[str, list[str]]
    root: str


def _read_tree(root: ET.Element, source: str) -> _Tree:
    """The link tree of the ``<robot>`` element ``root``; RobotDefinitionError if not a tree."""
    links = [el.get("name") for el in root.findall("link")]
    if any(n is None for n in links):
        raise RobotDefinitionError(f"{source}: a <link> has no name attribute")
    link_set = set(links)
    if len(link_set) != len(links):
        raise RobotDefinitionError(f"{source}: duplicate link names")
    joints = [_parse_joint(el, source) for el in root.findall("joint")]
    by_child: dict[str, _UJoint] = {}
    children: dict[str, list[str]] = {n: [] for n in links}
    for j in joints:
        for role, link in (("parent", j.parent), ("child", j.child)):
            if link not in link_set:
                raise RobotDefinitionError(
                    f"{source}: joint {short_repr(j.name)} refers to {role} link "
                    f"{short_repr(link)}, "
                    "which does not exist"
                )
        if j.child in by_child:
            raise RobotDefinitionError(
                f"{source}: link {short_repr(j.child)} is the child of two joints "
                f"({short_repr(by_child[j.child].name)} and {short_repr(j.name)}); the "
                "description has a loop"
            )
        by_child[j.child] = j
        children[j.parent].append(j.child)
    roots = [n for n in links if n not in by_child]
    if len(roots) != 1:
        raise RobotDefinitionError(
            f"{source}: expected one root link, found {len(roots)}"
            + (f" ({_names(roots)})" if roots else "; the joints form a loop")
        )
    _check_tree(roots[0], children, source)
    return _Tree(links, link_set, by_child, children, roots[0])


@dataclass(frozen=True)
class ChainChoice:
    """The chain of a URDF a robot is built on, and why that tip.

    Attributes:
        base: the base link.
        tip: the tip link.
        rule: 'given', 'srdf', 'single_leaf', 'named' or 'deepest'.
        reason: the rule in words, e.g. "'panda_hand_tcp', a link named like a TCP".
        others: the other leaves below the base (empty when the tree does not branch).
    """

    base: str
    tip: str
    rule: str
    reason: str
    others: tuple[str, ...] = ()


#: Kinds of tool-point link names, best first: (kind, words of a link name that match).
TIP_NAMES = (("a TCP", ("tcp",)), ("a tool", ("tool",)), ("a flange", ("flange",)),
             ("an end effector", ("ee", "eef", "end_effector", "endeffector")))


def _tip_kind(name: str) -> int | None:
    """Index in :data:`TIP_NAMES` of the kind ``name`` is named like, or None."""
    low = name.lower()
    words = [re.sub(r"\d+$", "", w) for w in re.split(r"[^a-z0-9]+", low) if w]
    for k, (_, keys) in enumerate(TIP_NAMES):
        for key in keys:
            if "_" in key:
                if key in low:
                    return k
            elif key in words:
                return k
    return None


def _srdf_tip(srdf: str | os.PathLike[str], source: str) -> str:
    """The ``parent_link`` of the first ``<end_effector>`` of an SRDF."""
    root, where = read_robot_xml(srdf)
    for el in root.iter("end_effector"):
        link = el.get("parent_link")
        if link:
            return link
    raise RobotDefinitionError(f"{where}: the SRDF has no <end_effector parent_link=...>; "
                               f"pass tip_link= for {source}")


def _depth(link: str, base: str, by_child: dict[str, _UJoint]) -> tuple[int, int]:
    """(moving joints, all joints) from ``base`` down to ``link``."""
    moving = total = 0
    while link != base and link in by_child:
        j = by_child[link]
        total += 1
        moving += j.type != "fixed"
        link = j.parent
    return moving, total


def choose_chain(path_or_string: str | os.PathLike[str], base_link: str | None = None,
                 tip_link: str | None = None, *,
                 srdf: str | os.PathLike[str] | None = None) -> ChainChoice:
    """The base and tip links :func:`robot_from_urdf` uses, and the rule that chose the tip.

    The rule (without ``tip_link``): the SRDF's end effector; the single leaf; a link
    named like a TCP, a tool, a flange, an end effector (in that order, the deepest of
    the best kind); the deepest chain (most moving joints). See the module docstring.

    Raises:
        RobotDefinitionError: an unknown link, an SRDF without an end effector, or two
            chains equally deep and no link named like a tool point (the message lists the
            leaves and says to pass ``tip_link=``).
    """
    root, source = read_robot_xml(path_or_string)
    return _choose(_read_tree(root, source), base_link, tip_link, srdf, source)


def _choose(tree: _Tree, base_link: str | None, tip_link: str | None,
            srdf: str | os.PathLike[str] | None, source: str) -> ChainChoice:
    base = base_link or tree.root
    if base not in tree.link_set:
        raise RobotDefinitionError(
            f"{source}: base_link {short_repr(base)} is not a link of the robot")
    leaves = [n for n in tree.links if not tree.children[n] and n != base
              and _is_below(n, base, tree.by_child)]
    if tip_link is not None:
        if tip_link not in tree.link_set:
            raise RobotDefinitionError(
                f"{source}: tip_link {short_repr(tip_link)} is not a link of the robot")
        return ChainChoice(base, tip_link, "given", f"{tip_link!r}, as given")
    if srdf is not None:
        tip = _srdf_tip(srdf, source)
        if tip not in tree.link_set:
            raise RobotDefinitionError(
                f"{source}: the SRDF's end effector link {short_repr(tip)} is not a link of "
                "the robot")
        return ChainChoice(base, tip, "srdf", f"{tip!r}, the SRDF's end effector",
                           tuple(n for n in leaves if n != tip))
    if len(leaves) == 1:
        return ChainChoice(base, leaves[0], "single_leaf", f"{leaves[0]!r}, the single leaf")
    below = [n for n in tree.links if n != base and _is_below(n, base, tree.by_child)
             and _depth(n, base, tree.by_child)[0] > 0]
    named = [(k, n) for n in below if (k := _tip_kind(n)) is not None]
    if named:
        best = min(k for k, _ in named)
        tip = max((n for k, n in named if k == best),
                  key=lambda n: _depth(n, base, tree.by_child))
        return ChainChoice(base, tip, "named", f"{tip!r}, a link named like "
                           f"{TIP_NAMES[best][0]}", tuple(n for n in leaves if n != tip))
    depth = {n: _depth(n, base, tree.by_child)[0] for n in leaves}
    deepest = max(depth.values(), default=0)
    top = [n for n in leaves if depth[n] == deepest]
    if len(top) == 1:
        return ChainChoice(base, top[0], "deepest", f"{top[0]!r}, the end of the deepest "
                           f"chain ({deepest} moving joints)",
                           tuple(n for n in leaves if n != top[0]))
    raise RobotDefinitionError(
        f"{source}: the tree below {short_repr(base)} branches into {len(leaves)} leaves "
        f"({_names(leaves)}), {len(top)} of them equally deep and none named like a tool "
        "point (tcp, tool, flange, ee); pass tip_link= one of them"
    )


def _chain_between(tree: _Tree, base: str, tip: str, source: str) -> list[_UJoint]:
    """The joints from ``base`` to ``tip``, in order; NotSupportedError for one on it."""
    chain: list[_UJoint] = []
    link = tip
    seen = {tip}
    while link != base:
        if link not in tree.by_child:
            raise RobotDefinitionError(
                f"{source}: tip_link {short_repr(tip)} is not below base_link {short_repr(base)}"
            )
        j = tree.by_child[link]
        chain.append(j)
        link = j.parent
        if link in seen:
            raise RobotDefinitionError(
                f"{source}: the joints form a loop at link {short_repr(link)}")
        seen.add(link)
    chain.reverse()
    for j in chain:
        if j.unsupported:
            raise NotSupportedError(j.unsupported)
    return chain


def _moving_joints(chain: list[_UJoint], base: str, tip: str,
                   source: str) -> tuple[list[Joint], list[str], np.ndarray]:
    """The chain's moving joints (fixed ones merged), their link names from ``base``, the tool.

    Fixed joints before a moving joint go into its origin, those after the last into the
    tool (4, 4); RobotDefinitionError when no joint moves.
    """
    out: list[Joint] = []
    link_names = [base]
    fixed = np.eye(4)
    for j in chain:
        if j.type == "fixed":
            fixed = fixed @ j.origin
            continue
        out.append(Joint(axis=j.axis, type=_MOVING[j.type], origin=fixed @ j.origin,
                         qlim=(j.lower, j.upper), name=j.name))
        link_names.append(j.child)
        fixed = np.eye(4)
    if not out:
        raise RobotDefinitionError(
            f"{source}: no moving joint between {short_repr(base)} and {short_repr(tip)}"
        )
    return out, link_names, fixed


def _at_rest(j: _UJoint) -> np.ndarray:
    """The pose of ``j``'s child in its parent with the joint at 0 (clamped to its limits)."""
    if j.type == "fixed":
        return j.origin
    v = min(max(0.0, j.lower), j.upper)
    if j.type == "prismatic":
        return j.origin @ make_transform(p=j.axis / np.linalg.norm(j.axis) * v)
    c, s = np.cos(v), np.sin(v)
    k = j.axis / np.linalg.norm(j.axis)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return j.origin @ make_transform(np.eye(3) + s * K + (1.0 - c) * (K @ K))


def _link_frames(base: str, chain: list[_UJoint], children: dict[str, list[str]],
                 by_child: dict[str, _UJoint], whole_tree: bool = False
                 ) -> dict[str, tuple[int, np.ndarray]]:
    """Chain frame index and pose in it of every chain link and its fixed-joint descendants.

    With ``whole_tree``, links below through moving joints too, those joints at rest
    (:func:`_at_rest`).
    """
    places: dict[str, tuple[int, np.ndarray]] = {base: (0, np.eye(4))}
    frame, T = 0, np.eye(4)
    for j in chain:
        if j.type == "fixed":
            T = T @ j.origin
        else:
            frame, T = frame + 1, np.eye(4)
        places[j.child] = (frame, T)
    todo = list(places)
    while todo:
        link = todo.pop()
        frame, T = places[link]
        for c in children[link]:
            j = by_child[c]
            if c not in places and (j.type == "fixed" or (whole_tree and j.type in _MOVING)):
                places[c] = (frame, T @ _at_rest(j))
                todo.append(c)
    return places


def _package_xml_name(folder: Path) -> str | None:
    """The ``<name>`` of ``folder/package.xml``, or None (no file, unreadable, no name)."""
    f = folder / "package.xml"
    try:
        if not f.is_file() or f.stat().st_size > 1_000_000:
            return None
        m = re.search(r"<name>\s*([^<\s]+)\s*</name>", f.read_text(encoding="utf-8",
                                                                   errors="replace"))
    except (OSError, ValueError):
        return None
    return m.group(1) if m else None


def package_folders(name: str, start: Path | None) -> list[Path]:
    """Folders that may be ROS package ``name``, in the order :class:`MeshResolver` tries them.

    An ancestor of ``start`` (the description's folder, itself included) named ``name`` or
    holding a ``package.xml`` whose ``<name>`` is ``name``; then for each root of
    ``$ROS_PACKAGE_PATH``: ``ROOT/name``, ``ROOT`` or a folder just below it whose
    ``package.xml`` names it; then ``PREFIX/share/name`` for each prefix of
    ``$AMENT_PREFIX_PATH``.
    """
    out: list[Path] = []
    if start is not None:
        for d in (start, *start.parents):
            if d.name == name or _package_xml_name(d) == name:
                out.append(d)
    for root in filter(None, os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep)):
        r = Path(root)
        out.append(r / name)
        if _package_xml_name(r) == name:
            out.append(r)
        try:
            subs = sorted(p for p in r.iterdir() if p.is_dir())[:10_000] if r.is_dir() else []
        except OSError:
            subs = []
        out.extend(p for p in subs if p.name != name and _package_xml_name(p) == name)
    for prefix in filter(None, os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep)):
        out.append(Path(prefix) / "share" / name)
    return list(dict.fromkeys(out))


class MeshResolver:
    """Turn a mesh path into an existing absolute path (or keep it, or refuse it).

    Used by URDF import and robot files: ``package://NAME/rest`` is looked up in
    ``package_map[NAME]/rest``, then ``FOLDER/NAME/rest`` for each search folder, then in
    the package folders found from the description's folder and the ROS environment
    (:func:`package_folders`: an ancestor named ``NAME`` or with a ``package.xml`` naming
    it, ``$ROS_PACKAGE_PATH``, ``$AMENT_PREFIX_PATH``); a relative path in ``folder``
    (the description's folder) then in each search folder; ``file://`` and absolute paths
    as they are.
    """

    def __init__(self, folder: Path | None, package_map: Mapping[str, object],
                 search_path: Sequence[object], strict: bool,
                 nowhere: str = "nowhere: give package_map= or search_path=") -> None:
        self.nowhere = nowhere
        self.folder = folder
        self.package_map = {str(k): Path(str(v)) for k, v in package_map.items()}
        if isinstance(search_path, str | os.PathLike):
            search_path = [search_path]
        self.search = [Path(str(p)) for p in search_path]
        self.strict = strict
        self._found: dict[str, list[Path]] = {}

    def candidates(self, name: str) -> list[Path]:
        """The files ``name`` may denote, in the order they are tried."""
        if name.startswith("package://"):
            pkg, _, rest = name[len("package://"):].partition("/")
            out = [self.package_map[pkg] / rest] if pkg in self.package_map else []
            out += [d / pkg / rest for d in self.search]
            if pkg and pkg not in self._found:
                self._found[pkg] = package_folders(pkg, self.folder)
            return out + [d / rest for d in self._found.get(pkg, [])]
        if name.startswith("file://"):
            return [Path(name[len("file://"):])]
        p = Path(name)
        if p.is_absolute():
            return [p]
        return ([self.folder / p] if self.folder is not None else []) + [d / p for d in self.search]

    def __call__(self, name: str, where: str) -> str:
        """The resolved absolute path of ``name`` (or ``name`` itself when not strict).

        Raises:
            RobotDefinitionError: strict, and no candidate is a file; the message starts
                with ``where`` and lists every place looked in.
        """
        tried = self.candidates(name)
        for p in tried:
            try:
                if p.is_file():
                    return str(p.resolve())
            except (OSError, ValueError):  # a name too long, a loop of links: not a file
                continue
        if self.strict:
            looked = ", ".join(short_repr(str(p), 400) for p in tried) or self.nowhere
            raise RobotDefinitionError(
                f"{where}: mesh {short_repr(name, 120)} does not resolve to a file; looked in "
                f"{looked}")
        return name


def _link_geometry(el: ET.Element, place: tuple[int, np.ndarray], source: str,
                   resolve: MeshResolver) -> LinkGeometry:
    """The ``<visual>`` and ``<collision>`` shapes of one link, posed in its chain frame."""
    name = el.get("name")
    frame, T = place
    shapes: dict[str, list[Shape]] = {"visual": [], "collision": []}
    for kind, out in shapes.items():
        for k, sub in enumerate(el.findall(kind)):
            where = f"{source}: link {short_repr(name)} <{kind}> #{k + 1}"
            geo = sub.find("geometry")
            if geo is None or len(geo) != 1:
                raise RobotDefinitionError(f"{where}: expected one element in <geometry>")
            try:
                geometry = _geometry(geo[0], where, resolve)
            except RobotDefinitionError as exc:
                msg = str(exc)
                raise RobotDefinitionError(
                    msg if msg.startswith(where) else f"{where}: {msg}") from None
            material, rgba = None, None
            mat = sub.find("material")
            if mat is not None:
                material = mat.get("name")
                color = mat.find("color")
                if color is not None and color.get("rgba") is not None:
                    rgba = tuple(parse_floats(color.get("rgba"), 4, (0, 0, 0, 1),
                                         f"{where} <color rgba>"))
            try:
                out.append(Shape(geometry, T @ _origin(sub.find("origin"), where),
                                 name=sub.get("name") or "", material=material, rgba=rgba))
            except RobotDefinitionError as exc:
                raise RobotDefinitionError(f"{where}: {exc}") from None
    return LinkGeometry(name, frame, tuple(shapes["visual"]), tuple(shapes["collision"]))


def _geometry(g: ET.Element, where: str, resolve: MeshResolver):
    """One URDF geometry element as a :mod:`~serialkin.model.geometry` object."""
    def num(attr: str) -> float:
        if g.get(attr) is None:
            raise RobotDefinitionError(f"<{g.tag}> has no {attr} attribute")
        return float(parse_floats(g.get(attr), 1, (0.0,), f"{where} <{g.tag} {attr}>")[0])

    if g.tag == "box":
        if g.get("size") is None:
            raise RobotDefinitionError("<box> has no size attribute")
        return Box(tuple(parse_floats(g.get("size"), 3, (0, 0, 0), f"{where} <box size>")))
    if g.tag == "sphere":
        return Sphere(num("radius"))
    if g.tag == "cylinder":
        return Cylinder(num("radius"), num("length"))
    if g.tag == "capsule":
        return Capsule(num("radius"), num("length"))
    if g.tag == "mesh":
        filename = g.get("filename")
        if not filename:
            raise RobotDefinitionError("<mesh> has no filename attribute")
        scale = parse_floats(g.get("scale"), 3, (1.0, 1.0, 1.0), f"{where} <mesh scale>")
        return Mesh(resolve(filename, where), tuple(scale))
    raise RobotDefinitionError(
        f"unknown geometry <{g.tag}>; expected box, cylinder, sphere, capsule or mesh")


def _names(names: list[str]) -> str:
    """At most ten names, each shown bounded (messages stay short for any file)."""
    def bare(name: str) -> str:  # the repr without its quotes (escapes kept)
        r = short_repr(name, 40)
        return r[1:-1] if len(r) > 1 and r[0] == r[-1] and r[0] in "'\"" else r[1:]

    shown = ", ".join(bare(n) for n in names[:10])
    return shown + (f" ... ({len(names)} in all)" if len(names) > 10 else "")


def _check_tree(root: str, children: dict[str, list[str]], source: str) -> None:
    """Refuse links not reachable from the root: with one parent per link, they form a loop.

    A loop anywhere in the description is refused, on the chain or off it.
    """
    reached = {root}
    todo = [root]
    while todo:
        for c in children[todo.pop()]:
            if c not in reached:
                reached.add(c)
                todo.append(c)
    if len(reached) != len(children):
        loop = sorted(set(children) - reached)
        raise RobotDefinitionError(
            f"{source}: the joints form a loop through link(s) {_names(loop)} (not reachable from "
            f"the root link {short_repr(root)}); a URDF must be a tree")


def _is_below(link: str, base: str, by_child: dict[str, _UJoint]) -> bool:
    seen = set()
    while link != base:
        if link not in by_child or link in seen:
            return False
        seen.add(link)
        link = by_child[link].parent
    return True


def _fmt(v: float) -> str:
    return repr(float(v))


#: Characters XML 1.0 cannot hold at all (even escaped): most C0 controls, surrogates.
_NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")


def _xml_name(text: str, what: str) -> str:
    """A name for an XML attribute; refuse characters no XML document can contain."""
    m = _NOT_XML.search(text)
    if m is not None:
        raise RobotDefinitionError(
            f"{what} {short_repr(text, 60)} contains the character U+{ord(m.group()):04X}, "
            "which XML (and so URDF) cannot hold; rename it")
    return text


def _origin_el(parent: ET.Element, T: np.ndarray) -> None:
    import warnings

    from scipy.spatial.transform import Rotation

    with warnings.catch_warnings():  # at gimbal lock scipy picks roll = 0: still exact
        warnings.simplefilter("ignore", UserWarning)
        rpy = Rotation.from_matrix(T[:3, :3]).as_euler("xyz")  # extrinsic xyz = Rz·Ry·Rx
    ET.SubElement(parent, "origin", xyz=" ".join(_fmt(v) for v in T[:3, 3]),
                  rpy=" ".join(_fmt(v) for v in rpy))


def _geometry_els(robot, link_els: list[ET.Element]) -> None:
    """Write ``robot.geometry`` into the link elements of frames 0..n."""
    L = robot.chain.L
    for lg in getattr(robot, "geometry", ()):
        if lg.frame > robot.n:
            raise RobotDefinitionError(
                f"link {short_repr(lg.link_name)} geometry is on frame {lg.frame}; the robot "
                f"has frames 0..{robot.n}")
        for kind, shapes in (("visual", lg.visual), ("collision", lg.collision)):
            for shape in shapes:
                el = ET.SubElement(link_els[lg.frame], kind)
                if shape.name:
                    el.set("name", _xml_name(str(shape.name), f"{kind} name"))
                _origin_el(el, L[lg.frame] @ shape.origin)
                _geometry_el(ET.SubElement(el, "geometry"), shape.geometry)
                if kind == "visual" and (shape.material is not None or shape.rgba is not None):
                    mat = ET.SubElement(el, "material",
                                        name=_xml_name(shape.material or "", "material name"))
                    if shape.rgba is not None:
                        ET.SubElement(mat, "color", rgba=" ".join(_fmt(c) for c in shape.rgba))


def _geometry_el(parent: ET.Element, g) -> None:
    """One geometry as its URDF element (``capsule`` is the common non-standard extension)."""
    if isinstance(g, Box):
        ET.SubElement(parent, "box", size=" ".join(_fmt(v) for v in g.size))
    elif isinstance(g, Sphere):
        ET.SubElement(parent, "sphere", radius=_fmt(g.radius))
    elif isinstance(g, Cylinder | Capsule):
        ET.SubElement(parent, "cylinder" if isinstance(g, Cylinder) else "capsule",
                      radius=_fmt(g.radius), length=_fmt(g.length))
    else:
        ET.SubElement(parent, "mesh", filename=_xml_name(g.filename, "mesh filename"),
                      scale=" ".join(_fmt(v) for v in g.scale))


def robot_to_urdf(robot: Robot) -> str:
    """The robot's kinematics and geometry as a URDF string (no inertia).

    Joint *i*'s origin is the chain's fixed transform before its motion (``chain.F[i-1]``,
    base included for the first joint) composed with the joint offset, so that
    :func:`robot_from_urdf` reproduces the same forward kinematics; the tool becomes a
    fixed joint to a link named ``tool``. The shapes of ``robot.geometry`` are written to
    the link of their frame (a link merged into a chain frame is written into that
    frame's link, so its own name is not kept), with origin
    ``L[frame] @ origin`` since the exported link frame is the compiled frame (its joint
    axis turned onto z): world poses are kept. Infinite revolute limits export as
    ``continuous`` joints. ``robot.velocity_limits`` become ``<limit velocity>`` (0,
    URDF's placeholder, where none is stated); URDF has no element for acceleration
    limits, so they are not written. The document is built with :mod:`xml.etree.ElementTree`,
    which escapes every name (``&``, ``<``, quotes, newlines): no name can add markup.

    Raises:
        RobotDefinitionError: a robot, joint or link name holds a character XML cannot
            represent (a control character other than tab, newline and carriage return);
            a geometry on a frame the robot does not have.
    """
    from scipy.spatial.transform import Rotation

    F, meta = robot.chain.F, robot.chain.meta
    vel = robot.velocity_limits
    names = robot.link_names
    if names is None or len(names) < robot.n + 1:
        names = ["base_link"] + [f"link{i + 1}" for i in range(robot.n)]
    names = [_xml_name(str(n), "link name") for n in names[: robot.n + 1]]
    tool_link = "tool"
    while tool_link in names:  # a robot whose own links include 'tool'
        tool_link = "_" + tool_link
    joint_names = [_xml_name(str(n), "joint name") for n in robot.joint_names]
    tool_joint = "tool_fixed"
    while tool_joint in joint_names:
        tool_joint = "_" + tool_joint
    root = ET.Element("robot", name=_xml_name(str(robot.name), "robot name"))
    link_els = [ET.SubElement(root, "link", name=n) for n in [*names, tool_link]]
    _geometry_els(robot, link_els)
    for i, j in enumerate(robot.joints):
        M = np.eye(4)
        if j.type == "R":
            M[:3, :3] = Rotation.from_rotvec(meta[i, :3] * j.offset).as_matrix()
        else:
            M[:3, 3] = meta[i, :3] * j.offset
        lo, hi = j.qlim
        continuous = j.type == "R" and not (np.isfinite(lo) or np.isfinite(hi))
        jtype = "continuous" if continuous else ("revolute" if j.type == "R" else "prismatic")
        el = ET.SubElement(root, "joint", name=joint_names[i], type=jtype)
        ET.SubElement(el, "parent", link=names[i])
        ET.SubElement(el, "child", link=names[i + 1])
        _origin_el(el, F[i] @ M)
        ET.SubElement(el, "axis", xyz=" ".join(_fmt(v) for v in meta[i, :3]))
        speed = "0" if vel is None or not np.isfinite(vel[i]) else _fmt(vel[i])
        if not continuous:
            ET.SubElement(el, "limit", lower=_fmt(lo if np.isfinite(lo) else -1e9),
                          upper=_fmt(hi if np.isfinite(hi) else 1e9), effort="0",
                          velocity=speed)
        elif speed != "0":
            ET.SubElement(el, "limit", effort="0", velocity=speed)
    el = ET.SubElement(root, "joint", name=tool_joint, type="fixed")
    ET.SubElement(el, "parent", link=names[robot.n])
    ET.SubElement(el, "child", link=tool_link)
    _origin_el(el, F[robot.n])
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") \
        + "\n"
