"""Reading the parts of an SRDF (MoveIt's semantic robot description) that collision needs.

Only two elements are read; every other element is ignored:

* ``<disable_collisions link1="A" link2="B" reason="..."/>`` — link pairs never checked;
* ``<group_state name="..." group="..."><joint name="..." value="..."/>...</group_state>``
  — named joint configurations (values in rad or m).

The XML is parsed with the standard library (:mod:`xml.etree.ElementTree`) through the
reader URDF import uses (:func:`serialkin.formats.xmlfile.read_robot_xml`); the root
element must be ``<robot>``.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

from serialkin._checks import short_repr
from serialkin.errors import RobotDefinitionError
from serialkin.formats.xmlfile import read_robot_xml

__all__ = ["Srdf", "read_srdf"]


@dataclass(frozen=True)
class Srdf:
    """The collision-relevant content of an SRDF.

    Attributes:
        disabled: ``(link1, link2, reason)`` for each ``<disable_collisions>``.
        group_states: ``{state name: {joint name: value}}`` (values in rad or m).
        source: file path or ``<string>``.
    """

    disabled: tuple[tuple[str, str, str], ...]
    group_states: dict[str, dict[str, float]]
    source: str = ""

    def group_state(self, name: str) -> dict[str, float]:
        """Joint values of the group state ``name``; RobotDefinitionError listing the names."""
        try:
            return dict(self.group_states[name])
        except KeyError:
            raise RobotDefinitionError(
                f"{self.source}: no group_state named {short_repr(name, 80)}; group states: "
                f"{', '.join(self.group_states) or '(none)'}") from None


def read_srdf(path_or_string: str | os.PathLike[str]) -> Srdf:
    """Read an SRDF file (or an XML string starting with ``<``).

    Raises:
        RobotDefinitionError: unreadable XML, a root other than ``<robot>``, a
            ``<disable_collisions>`` without both links, a joint value that is not a
            finite number (the message names the element).
    """
    root, source = read_robot_xml(path_or_string, "SRDF")
    disabled = []
    for k, el in enumerate(root.findall("disable_collisions")):
        a, b = el.get("link1"), el.get("link2")
        if not a or not b:
            raise RobotDefinitionError(
                f"{source}: disable_collisions #{k + 1} must name link1 and link2, got "
                f"link1={short_repr(a, 80)}, link2={short_repr(b, 80)}")
        disabled.append((a, b, el.get("reason", "")))
    states: dict[str, dict[str, float]] = {}
    for el in root.findall("group_state"):
        name = el.get("name", "")
        values = {}
        for j in el.findall("joint"):
            text = j.get("value", "")
            try:
                v = float(text)
            except ValueError:
                v = math.nan
            if not math.isfinite(v):
                raise RobotDefinitionError(
                    f"{source}: group_state {short_repr(name, 80)}, joint "
                    f"{short_repr(j.get('name'), 80)}: value must be a finite number, got "
                    f"{short_repr(text, 80)}")
            values[j.get("name", "")] = v
        states[name] = values
    return Srdf(tuple(disabled), states, source)
