"""Resolve the ROBOT argument of the command line.

``ROBOT`` is one of:

* a built-in model name (``serialkin models`` lists them; case-insensitive, aliases such
  as ``puma`` and ``planar<N>`` accepted), built by :func:`serialkin.models.get`;
  ``--param key=value`` passes keyword arguments to the model function;
* a robot file ``*.yaml`` / ``*.yml`` / ``*.json`` (:mod:`serialkin.model.robotfile`);
* a URDF file ``*.urdf`` (:meth:`serialkin.Robot.from_urdf`); ``--param base_link=NAME``
  and ``--param tip_link=NAME`` choose the chain of a branching tree.

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
    "a built-in model name (see 'serialkin models'), a robot file (.yaml/.yml/.json) "
    "or a URDF file (.urdf)"
)


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


def resolve_robot(spec: str, params: Sequence[str] = ()) -> Any:
    """Build the robot named by ``spec`` (see the module docstring).

    Raises:
        CLIError: unknown model (nearest names suggested), unreadable or malformed file
            (the message names the file and the field).
    """
    suffix = Path(spec).suffix.lower()
    kwargs = parse_params(params)
    if suffix in (".yaml", ".yml", ".json", ".urdf"):
        urdf_keys = {"base_link", "tip_link"}
        if suffix == ".urdf" and set(kwargs) - urdf_keys:
            raise CLIError(f"--param for a URDF takes base_link=NAME and tip_link=NAME only, got "
                           f"{', '.join(sorted(set(kwargs) - urdf_keys))}")
        if suffix != ".urdf" and kwargs:
            raise CLIError("--param applies to built-in models and URDF links only, not to "
                           "robot files")
        if not Path(spec).exists():
            raise CLIError(f"robot file {spec} not found")
        try:
            if suffix == ".urdf":
                from serialkin.model.robot import Robot

                links = {k: str(v) for k, v in kwargs.items()}
                try:
                    return Robot.from_urdf(spec, **links)
                except SerialkinError as exc:
                    if "tip_link" in str(exc) and "tip_link" not in links:
                        raise CLIError(f"{exc} (on the command line: --param tip_link=NAME)") \
                            from exc
                    raise
            from serialkin.model.robotfile import load_robot_file

            return load_robot_file(spec)
        except SerialkinError as exc:
            raise CLIError(str(exc)) from exc
        except OSError as exc:
            raise CLIError(f"{spec}: cannot read ({exc.strerror or exc})") from exc
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
                    "URDF in .urdf.)")
        raise CLIError(msg) from exc


robot_argument = click.argument("robot", metavar="ROBOT")
param_option = click.option(
    "--param", "params", multiple=True, metavar="KEY=VALUE",
    help="Keyword argument for a built-in model (e.g. --param l1=0.4), or base_link=/tip_link= "
         "for a URDF; repeatable.",
)
