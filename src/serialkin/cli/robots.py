"""Resolve the ROBOT argument of the command line.

``ROBOT`` is one of:

* a built-in model name (``serialkin models`` lists them; case-insensitive, aliases such
  as ``puma`` and ``planar<N>`` accepted), built by :func:`serialkin.models.get`;
  ``--param key=value`` passes keyword arguments to the model function;
* a robot file ``*.yaml`` / ``*.yml`` / ``*.json`` (:mod:`serialkin.formats.robotfile`);
* a URDF file ``*.urdf`` (:func:`serialkin.formats.urdf.robot_from_urdf`);
  ``--param base_link=NAME`` and ``--param tip_link=NAME`` choose the chain of a branching
  tree; without ``tip_link`` the tip is chosen by the rule of
  :func:`~serialkin.formats.urdf.choose_chain` (``--param srdf=FILE``: the SRDF's end
  effector; else a single leaf, a link named like a TCP/tool/flange/ee, the deepest
  chain), and the command says on stderr which it chose; ``package://`` mesh paths
  resolve from the file's ancestors and the ROS paths;
* a MuJoCo MJCF file ``*.xml`` / ``*.mjcf`` (:meth:`serialkin.Robot.from_mjcf`);
  ``--param base_body=NAME``, ``end_body=NAME`` and ``tool_site=NAME`` choose the chain;
* a xacro file ``*.xacro`` / ``*.urdf.xacro`` (:meth:`serialkin.Robot.from_xacro`, needs
  the ``xacro`` extra); ``base_link``/``tip_link`` as for URDF, ``arg:NAME=VALUE`` sets a
  ``<xacro:arg>``, ``package:NAME=FOLDER`` and ``search_path=FOLDER`` locate
  ``$(find NAME)`` and ``package://NAME`` paths.

An unknown name gets the nearest names suggested.
"""

from __future__ import annotations

import difflib
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import click

from serialkin._checks import short_repr
from serialkin.cli.io import CLIError
from serialkin.errors import SerialkinError

ROBOT_HELP = (
    "a built-in model name (see 'serialkin models'), a robot file (.yaml/.yml/.json), "
    "a URDF file (.urdf), an MJCF file (.xml/.mjcf) or a xacro file (.xacro)"
)

#: --param keys each description file takes (xacro also takes arg:NAME and package:NAME).
FILE_PARAMS = {
    ".urdf": ("base_link", "tip_link", "srdf"),
    ".xml": ("base_body", "end_body", "tool_site"),
    ".mjcf": ("base_body", "end_body", "tool_site"),
    ".xacro": ("base_link", "tip_link", "search_path", "arg:NAME", "package:NAME"),
}


def parse_params(params: Sequence[str]) -> dict[str, Any]:
    """Parse ``key=value`` pairs into a dict.

    Values are read as YAML scalars or lists (``l1=0.4``, ``lengths=[1, 0.5]``).

    Raises:
        CLIError: a pair without ``=``.
    """
    import yaml

    out: dict[str, Any] = {}
    for p in params:
        if "=" not in p:
            raise CLIError(f"--param {short_repr(p)}: expected key=value, e.g. --param l1=0.4")
        k, v = p.split("=", 1)
        try:
            out[k.strip()] = yaml.safe_load(v)
        except yaml.YAMLError:
            out[k.strip()] = v
    return out


def resolve_robot(spec: str, params: Sequence[str] = (), *, whole_tree: bool = False) -> Any:
    """Build the robot named by ``spec`` (see the module docstring).

    ``whole_tree`` (for the viewer): a URDF robot also carries the geometry of the links
    off its chain (fingers), posed at rest.

    Raises:
        CLIError: unknown model (nearest names suggested), unreadable or malformed file
            (the message names the file and the field).
    """
    suffix = Path(spec).suffix.lower()
    kwargs = parse_params(params)
    if suffix in (".yaml", ".yml", ".json"):
        if kwargs:
            raise CLIError("--param applies to built-in models and URDF/MJCF/xacro files only, "
                           "not to robot files")
        if not Path(spec).exists():
            raise CLIError(f"robot file {spec} not found")
        from serialkin.formats.robotfile import load_robot_file

        return _load(spec, load_robot_file, {})
    if suffix in FILE_PARAMS:
        if not Path(spec).exists():
            raise CLIError(f"robot file {spec} not found")
        file_kwargs = _file_kwargs(suffix, kwargs)
        if suffix == ".urdf":
            from serialkin.formats.urdf import choose_chain, robot_from_urdf

            chain_kwargs = {k: file_kwargs[k] for k in ("base_link", "tip_link", "srdf")
                            if k in file_kwargs}
            announce_tip(spec, _load(spec, choose_chain, chain_kwargs))
            return _load(spec, robot_from_urdf, dict(file_kwargs, whole_tree=whole_tree))
        return _load(spec, _file_loader(suffix), file_kwargs)
    from serialkin import models

    try:
        return models.get(spec, **kwargs)
    except TypeError as exc:  # unknown keyword for the model function
        raise CLIError(f"model {short_repr(spec)} does not accept these --param options: "
                       f"{exc}") from exc
    except SerialkinError as exc:
        msg = str(exc)
        unknown = msg.startswith("unknown robot model")
        if unknown and "did you mean" not in msg.lower():
            near = difflib.get_close_matches(spec.lower()[:200], list(models.names()), n=3,
                                             cutoff=0.4)
            if near:
                msg += f" Nearest: {', '.join(near)}."
        if unknown and Path(spec[:4096]).suffix:
            msg += (f" (A file {short_repr(spec)}? Robot files end in .yaml, .yml or .json; "
                    "URDF in .urdf, MJCF in .xml or .mjcf, xacro in .xacro.)")
        raise CLIError(msg) from exc


def announce_tip(spec: str, choice: Any) -> None:
    """Say on stderr which tip link a rule chose for a branching URDF (not with --quiet)."""
    if choice.rule in ("given", "single_leaf"):
        return
    ctx = click.get_current_context(silent=True)
    if ctx is not None and ctx.params.get("quiet"):
        return
    others = f"; other ends: {', '.join(choice.others[:6])}" + (
        f" and {len(choice.others) - 6} more" if len(choice.others) > 6 else "") \
        if choice.others else ""
    click.echo(f"serialkin: {Path(spec).name}: chain {choice.base} -> {choice.tip}: tip "
               f"{choice.reason}{others} (another: --param tip_link=NAME)", err=True)


def _file_loader(suffix: str) -> Any:
    from serialkin.model.robot import Robot

    if suffix == ".urdf":
        return Robot.from_urdf
    if suffix == ".xacro":
        return Robot.from_xacro
    return Robot.from_mjcf


def _file_kwargs(suffix: str, kwargs: dict[str, Any]) -> dict[str, Any]:
    """The loader's keyword arguments from the --param pairs of a description file."""
    allowed = FILE_PARAMS[suffix]
    out: dict[str, Any] = {}
    mappings: dict[str, str] = {}
    packages: dict[str, str] = {}
    for key, value in kwargs.items():
        kind, colon, name = key.partition(":")
        if suffix == ".xacro" and colon and kind in ("arg", "package") and name:
            (mappings if kind == "arg" else packages)[name] = (
                str(value).lower() if isinstance(value, bool) else str(value))
        elif key in allowed:
            if key == "search_path":
                out[key] = [str(v) for v in value] if isinstance(value, list) else [str(value)]
            else:
                out[key] = str(value)
        else:
            raise CLIError(f"--param {short_repr(key)} is not an option for a {suffix} file; "
                           f"it takes {', '.join(f'{k}=...' for k in allowed)}")
    if mappings:
        out["mappings"] = mappings
    if packages:
        out["package_map"] = packages
    return out


def _load(spec: str, loader: Any, kwargs: dict[str, Any]) -> Any:
    """Call ``loader(spec, **kwargs)``, turning library and OS errors into CLIError."""
    try:
        return loader(spec, **kwargs)
    except SerialkinError as exc:
        msg = str(exc)
        for key in ("tip_link", "end_body"):  # a branching tree: say how to choose
            if f"pass {key}=" in msg and key not in kwargs:
                msg += f" (on the command line: --param {key}=NAME)"
        if "root element must be <mujoco>, got <robot>" in msg:
            msg += " (a URDF? name it .urdf)"
        raise CLIError(msg) from exc
    except OSError as exc:
        raise CLIError(f"{spec}: cannot read ({exc.strerror or exc})") from exc


robot_argument = click.argument("robot", metavar="ROBOT")
param_option = click.option(
    "--param", "params", multiple=True, metavar="KEY=VALUE",
    help="Keyword argument for a built-in model (e.g. --param l1=0.4); base_link=/tip_link= "
         "for a URDF or xacro file (URDF also srdf=FILE: its end effector is the tip; "
         "xacro also arg:NAME=, package:NAME=, search_path=); "
         "base_body=/end_body=/tool_site= for an MJCF file; repeatable.",
)
