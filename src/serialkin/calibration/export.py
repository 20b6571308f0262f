"""Writing a calibrated robot: the user's URDF patched, a URDF, or a robot file, atomically.

**Patching a URDF** (:func:`patch_urdf`): the calibrated model goes into a copy of the
user's own file, of which only the ``<origin>`` attributes ``xyz``/``rpy`` of the joints
that changed are rewritten, in the text itself: visuals, collision geometry, inertials,
names, comments, formatting and the joints' ``<axis>`` stay byte for byte. Joint i's new
origin is ``U'_i = F_i⁻¹ · post_{i−1} · O_i · M_i(offset_i)`` with ``O_i``, ``post``,
``offset`` and ``M_i`` the calibrated robot's (:class:`~serialkin.model.joint.Joint`)
and ``F_i`` the product of the file's fixed joints between joint i−1's child and joint i
(they are kept), so that every link frame, and with it its geometry, follows the
identified joint axes; the joint offsets, which URDF has no place for, go into the next
origin. The identified **base** pose is the robot's place in the measuring device's
frame, not part of the robot: it is not written (the URDF stays in its root link's
frame). The identified **tool** change is written into the last fixed joint on the chain
to the tip link only when it is identified (all six tool errors fitted: full-pose
measurements); from positions the tool translation is the measured marker, which is no
part of the robot. Encoder scales and marker offsets have no URDF element: the
:class:`UrdfPatch` says so.

**Physical exports.** A robot file holds a DH table. For a calibrated robot with Hayati's
β or joint errors the table is extracted from the calibrated axes
(:func:`serialkin.model.dh_extract.to_dh_robot`, exact); but for nearly parallel axes its
common normals lie far away (d ≈ a / tan(tilt): ±30–40 m for a UR5 tilted by 0.3°).
:func:`save_robot` refuses such a table (a length beyond :data:`DH_LENGTH_LIMIT` × the
robot's size) and says to write the per-joint origins as a URDF instead, which keeps each
joint where it was identified.
"""

from __future__ import annotations

import os
import re
import xml.parsers.expat
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from serialkin.errors import InputError, RobotDefinitionError
from serialkin.model.robot import Robot, robot_scale

#: A DH table whose a or d exceeds this multiple of the robot's size (and of its nominal
#: value) is not physical: the robot file is refused for a URDF of per-joint origins.
DH_LENGTH_LIMIT = 2.0


def unphysical_dh(robot: Robot) -> tuple[Robot | None, str]:
    """The robot's DH form, or why a DH table would not be physical.

    Returns:
        (the DH robot, '') or (None, the reason naming the longest offset).
    """
    if robot.dh is not None:
        return robot, ""
    from serialkin.model.dh_extract import to_dh_robot

    try:
        dh = to_dh_robot(robot, "standard")
    except RobotDefinitionError as exc:
        return None, f"no DH table reproduces its joints ({exc})"
    limit = DH_LENGTH_LIMIT * robot_scale(robot)
    worst, where = 0.0, ""
    for i, r in enumerate(dh.dh):
        for field in ("a", "d"):
            v = float(getattr(r, field))
            if abs(v) > worst:
                worst, where = abs(v), f"{field}{i + 1} = {v:.4g} m"
    if worst > limit:
        return None, (f"its DH table would need {where} (more than {DH_LENGTH_LIMIT:g} × the "
                      f"robot's size, {limit:.3g} m): consecutive joint axes are nearly "
                      "parallel and their common normal lies far away; write a .urdf "
                      "instead (per-joint origins, bounded)")
    return dh, ""


def save_robot(robot: Robot, path: str | os.PathLike[str]) -> Path:
    """Write ``robot`` to ``path`` by its suffix: ``.urdf``, or ``.yaml``/``.yml``/``.json``.

    A robot file needs a DH table; one extracted from calibrated axes must be physical
    (module docstring).

    Raises:
        InputError: another suffix, or a DH table that is not physical (the message says
            which offset and to write a URDF).
    """
    from serialkin._io import write_text_atomic
    from serialkin.formats.robotfile import ROBOT_FILE_SUFFIXES, save_robot_file

    p = Path(path)
    suffix = p.suffix.lower()
    if suffix == ".urdf":
        return write_text_atomic(p, robot.to_urdf())
    if suffix not in ROBOT_FILE_SUFFIXES:
        raise InputError(f"{p}: unknown robot file type {p.suffix!r}; expected .urdf or one "
                         f"of {', '.join(ROBOT_FILE_SUFFIXES)}")
    dh, why = unphysical_dh(robot)
    if dh is None:
        raise InputError(f"{p}: not written: robot {robot.name!r} cannot be a robot file, "
                         f"{why}")
    return save_robot_file(dh, p)


@dataclass(frozen=True)
class UrdfPatch:
    """What :func:`patch_urdf` wrote.

    Attributes:
        path: the file written.
        changed: names of the joints whose ``<origin>`` was rewritten (moving joints, and
            the fixed joint that took the tool change).
        tool_written: whether the identified tool change was written.
        notes: what the file does not hold (the base pose, encoder scales, the marker), one
            sentence each.
    """

    path: Path
    changed: tuple[str, ...]
    tool_written: bool
    notes: tuple[str, ...]


def _fmt(v: float) -> str:
    return repr(float(v) + 0.0)


def _joint_spans(data: bytes) -> dict[str, dict[str, Any]]:
    """Byte offsets of each ``<joint>``'s start tag and of its ``<origin>`` child's start tag.

    Returns:
        name -> {'start': offset of '<joint', 'origin': offset of its '<origin' or None}.
    """
    spans: dict[str, dict[str, Any]] = {}
    stack: list[tuple[str, str | None]] = []
    parser = xml.parsers.expat.ParserCreate()

    def start(tag: str, attrs: dict[str, str]) -> None:
        pos = parser.CurrentByteIndex
        if tag == "joint" and len(stack) == 1:
            name = attrs.get("name", "")
            spans[name] = {"start": pos, "origin": None}
            stack.append((tag, name))
            return
        if tag == "origin" and stack and stack[-1][0] == "joint":
            spans[str(stack[-1][1])]["origin"] = pos
        stack.append((tag, None))

    def end(tag: str) -> None:
        stack.pop()

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.Parse(data, True)
    return spans


_ATTR = r"""\s+([^\s=/>]+)\s*=\s*("[^"]*"|'[^']*')"""
_TAG = re.compile(rb"<([A-Za-z_][\w.:-]*)((?:" + _ATTR.encode() + rb")*)\s*(/?)>")


def _set_origin(data: bytes, spans: dict[str, Any], xyz: str, rpy: str) -> bytes:
    """``data`` with the joint's origin start tag given ``xyz``/``rpy`` (inserted if absent)."""
    if spans["origin"] is None:  # no <origin>: the identity; add one after the start tag
        m = _TAG.match(data, spans["start"])
        if m is None:
            raise RobotDefinitionError("a <joint> start tag could not be read for patching")
        new = f'<origin xyz="{xyz}" rpy="{rpy}"/>'.encode()
        end = m.end()
        if m.group(3) == b"/":  # <joint .../> cannot be a joint of a chain (no parent)
            raise RobotDefinitionError("an empty <joint/> element cannot be patched")
        return data[:end] + new + data[end:]
    m = _TAG.match(data, spans["origin"])
    if m is None or m.group(1) != b"origin":
        raise RobotDefinitionError("an <origin> start tag could not be read for patching")
    tag = m.group(0)
    for attr, value in ((b"xyz", xyz), (b"rpy", rpy)):
        pat = re.compile(rb"(\s" + attr + rb"\s*=\s*)(\"[^\"]*\"|'[^']*')")
        if pat.search(tag):
            tag = pat.sub(lambda mm, v=value: mm.group(1) + b'"' + v.encode() + b'"', tag,
                          count=1)
        else:
            close = len(tag) - (2 if tag.endswith(b"/>") else 1)
            tag = tag[:close].rstrip() + b" " + attr + b'="' + value.encode() + b'"' + \
                tag[close:]
    return data[:m.start()] + tag + data[m.end():]


def _chain(root: Any, base: str, tip: str) -> list[dict[str, Any]]:
    """The joints from ``base`` to ``tip`` (name, type, origin (4, 4)), in order."""
    from serialkin.formats.urdf import rpy_to_matrix
    from serialkin.formats.xmlfile import parse_floats
    from serialkin.spatial.transforms import make_transform

    by_child = {}
    for el in root.findall("joint"):
        child = el.find("child")
        if child is not None:
            by_child[child.get("link")] = el
    out = []
    link = tip
    while link != base:
        el = by_child[link]
        o = el.find("origin")
        where = f"joint {el.get('name')!r}"
        xyz = parse_floats(None if o is None else o.get("xyz"), 3, (0.0, 0.0, 0.0), where)
        rpy = parse_floats(None if o is None else o.get("rpy"), 3, (0.0, 0.0, 0.0), where)
        out.append({"name": el.get("name"), "type": el.get("type"),
                    "origin": make_transform(rpy_to_matrix(rpy), xyz)})
        link = el.find("parent").get("link")
    return out[::-1]


def _result_notes(result: Any, tool: bool | None) -> tuple[bool, list[str]]:
    """Whether to write the tool change of a calibration ``result``, and what is not written.

    ``tool`` None: write it when the result identified all six tool errors. The notes name
    the encoder scales, marker offsets and tool change that the URDF will not hold.
    """
    params = result.model.parameters
    tool_params = [k for k, p in enumerate(params) if p.group == "tool"]
    identified = len(tool_params) == 6 and all(
        result.identifiability.identifiable[k] for k in tool_params)
    if tool is None:
        tool = identified
    notes: list[str] = []
    scale = result.encoder_scale
    if np.any(scale != 1.0):
        notes.append("encoder scales are not part of a URDF: drive the robot with the "
                     "joint values times " + ", ".join(f"{s:.8g}" for s in scale))
    if result.model.markers > 1:
        notes.append("the marker offsets are not written (they are no part of the "
                     "robot)")
    if not tool and tool_params:
        notes.append("the identified tool change is not written (the tool translation "
                     "of position measurements is the marker)" if not identified else
                     "the identified tool change is not written (tool=False)")
    return tool, notes


def _calibrated_robot(calibrated: Any, tool: bool | None) -> tuple[Robot, bool, list[str]]:
    """The calibrated robot of ``calibrated``, whether to write its tool, and the notes.

    Raises:
        InputError: ``calibrated`` is neither a CalibrationResult nor a Robot.
    """
    from serialkin.calibration.fit import CalibrationResult

    if isinstance(calibrated, CalibrationResult):
        tool, notes = _result_notes(calibrated, tool)
        return calibrated.robot, tool, notes
    if isinstance(calibrated, Robot):
        return calibrated, bool(tool), []
    raise InputError(f"calibrated must be a CalibrationResult or a Robot, got "
                     f"{type(calibrated).__name__}")


def _check_same_joints(robot: Robot, nominal: Robot, src: Path) -> None:
    """Refuse a calibrated robot whose joints (count, types, local axes) are not the file's.

    Raises:
        InputError: naming the first difference.
    """
    if robot.n != nominal.n or [j.type for j in robot.joints] != \
            [j.type for j in nominal.joints]:
        raise InputError(f"the calibrated robot's joints ({robot.n}: "
                         f"{''.join(j.type for j in robot.joints)}) are not those of {src} "
                         f"({nominal.n}: {''.join(j.type for j in nominal.joints)})")
    for i, (a, b) in enumerate(zip(robot.joints, nominal.joints)):
        if not np.allclose(a.axis, b.axis, atol=1e-9):
            raise InputError(f"joint {i + 1} of the calibrated robot turns about "
                             f"{a.axis.round(6).tolist()} in its frame, the URDF's about "
                             f"{b.axis.round(6).tolist()}: calibrate with the 'joints' error "
                             "model of this URDF")


def _joint_edits(chain: list[dict[str, Any]], robot: Robot,
                 ) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """The new origins (4, 4) of the moving joints whose origin changed, by joint name.

    A moving joint's new origin absorbs the fixed joints before it (their origins stay)
    and the calibrated joint's pre-transform and offset; also returns the last moving
    joint's post-transform (4, 4), which the tool change starts from.
    """
    from serialkin.calibration.models import _motion

    edits: dict[str, np.ndarray] = {}
    fixed = np.eye(4)
    prev_post = np.eye(4)
    i = 0
    for j in chain:
        if j["type"] == "fixed":
            fixed = fixed @ j["origin"]
            continue
        cj = robot.joints[i]
        new = np.linalg.inv(fixed) @ prev_post @ cj.origin @ _motion(cj, cj.offset)
        if not np.allclose(new, j["origin"], rtol=0.0, atol=1e-13):
            edits[j["name"]] = new
        prev_post, fixed, i = cj.post, np.eye(4), i + 1
    return edits, prev_post


def _tool_edit(chain: list[dict[str, Any]], robot: Robot, prev_post: np.ndarray,
               src: Path) -> tuple[str, np.ndarray | None]:
    """The last fixed joint before the tip and its new origin (None: unchanged).

    The fixed joints after the last moving one keep their origins but the last, which
    takes the tool change.

    Raises:
        RobotDefinitionError: no fixed joint after the last moving one.
    """
    tail = []
    for j in reversed(chain):
        if j["type"] != "fixed":
            break
        tail.append(j)
    if not tail:
        raise RobotDefinitionError(
            f"{src}: no fixed joint after the last moving one to take the tool change "
            "(pass tool=False)")
    last = tail[0]
    rest = np.eye(4)
    for j in reversed(tail[1:]):
        rest = rest @ j["origin"]
    new = np.linalg.inv(rest) @ prev_post @ robot.tool
    if np.allclose(new, last["origin"], rtol=0.0, atol=1e-13):
        return last["name"], None
    return last["name"], new


def _rewrite_origins(data: bytes, spans: dict[str, Any], edits: dict[str, np.ndarray],
                     ) -> bytes:
    """``data`` with each edited joint's origin set to its new (4, 4) transform."""
    from serialkin.spatial import matrix_to_rpy

    # rewrite from the end of the file backwards: earlier offsets stay valid
    for name in sorted(edits, key=lambda n: spans[n]["start"], reverse=True):
        T = edits[name]
        xyz = " ".join(_fmt(v) for v in T[:3, 3])
        rpy = " ".join(_fmt(v) for v in matrix_to_rpy(T[:3, :3], check=False))
        data = _set_origin(data, spans[name], xyz, rpy)
    return data


def patch_urdf(original: str | os.PathLike[str], calibrated: Any,
               path: str | os.PathLike[str], *, base_link: str | None = None,
               tip_link: str | None = None, tool: bool | None = None) -> UrdfPatch:
    """Write the calibrated robot as a patched copy of the user's URDF (module docstring).

    Args:
        original: the URDF file the nominal robot was read from.
        calibrated: a :class:`~serialkin.calibration.CalibrationResult` of a model of that
            robot, or a calibrated :class:`~serialkin.Robot` with the same joints (count,
            types and local axes: the 'joints' error model's robot).
        path: the file to write; never ``original`` itself (nothing written may replace
            an input).
        base_link: the chain's base link, as when the robot was read.
        tip_link: the chain's tip link, as when the robot was read.
        tool: write the tool change into the last fixed joint before the tip; None: when
            the result identified all six tool errors (never for a bare robot).

    Returns:
        :class:`UrdfPatch`.

    Raises:
        InputError: ``path`` is the original, or the calibrated robot does not have the
            file's joints.
        RobotDefinitionError: an unreadable or malformed URDF; a tool change asked for
            with no fixed joint after the last moving one to hold it.
    """
    from serialkin._files import parse_xml, read_bytes
    from serialkin._io import write_bytes_atomic
    from serialkin.formats.urdf import robot_from_urdf

    src, out = Path(original), Path(path)
    if out.exists() and src.exists() and os.path.samefile(src, out):
        raise InputError(f"patch_urdf: path {str(out)!r} is the original URDF; writing it "
                         "would replace the input; choose another path")
    robot, tool, notes = _calibrated_robot(calibrated, tool)
    nominal = robot_from_urdf(str(src), base_link, tip_link)
    _check_same_joints(robot, nominal, src)
    if not np.allclose(robot.base, nominal.base, atol=1e-12):
        notes.append("the identified base pose (the robot in the measuring device's frame) "
                     "is not written: the URDF stays in its root link's frame")
    data = read_bytes(src, what="URDF file", error=RobotDefinitionError)
    root = parse_xml(data, str(src), error=RobotDefinitionError)
    names = nominal.link_names
    chain = _chain(root, names[0], names[-1])
    spans = _joint_spans(data)
    edits, prev_post = _joint_edits(chain, robot)
    if tool:
        name, new = _tool_edit(chain, robot, prev_post, src)
        if new is not None:
            edits[name] = new
    data = _rewrite_origins(data, spans, edits)
    written = write_bytes_atomic(out, data)
    changed = tuple(j["name"] for j in chain if j["name"] in edits)
    return UrdfPatch(Path(written), changed, bool(tool), tuple(notes))
