"""The ``collide`` subcommand: the closest pairs of a configuration, by name and distance.

Also what every command that checks collisions shares: the ``--srdf`` / ``--skip-links``
options (:data:`srdf_options`, read by :func:`srdf_acm`) and the ``--scene`` file reader
(:func:`read_scene`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import click
import numpy as np

from serialkin._checks import short_repr
from serialkin.cli.commands import (
    _angle_factor,
    degrees_option,
    handle_errors,
    json_option,
    quiet_long_option,
    refuse_joint_turns,
)
from serialkin.cli.io import CLIError, command_help, dumps_json, parse_numbers
from serialkin.cli.robots import ROBOT_HELP, param_option, resolve_robot, robot_argument

_COLLIDE_HELP = command_help(
    "Print the closest collision pairs of one configuration, with their names and signed "
    "distances (negative: the capsules overlap).\n\n"
    "ROBOT is " + ROBOT_HELP + "; it needs a collision model (the built-in arms carry one). "
    "Every checked pair of the robot's own bodies is measured (pairs allowed by the model, "
    "and by --srdf's <disable_collisions>, are skipped) and, with --scene, the closest body "
    "to each obstacle. The exit status is 0 whatever the result; the verdict is the first "
    "line ('in collision' or 'free').",
    ["serialkin collide panda --q \"0,-0.78,0,-2.36,0,1.57,0.78\"",
     "serialkin collide ur5 --degrees --q \"0,-90,150,0,0,0\" --count 3",
     "serialkin collide panda --srdf panda.srdf --skip-links panda_hand_tcp --q 0,0,0,-3,0,0.5,0",
     "serialkin collide ur5 --q 0,-1.2,1.4,0,0.5,0 --scene table.yaml --json"],
)


def read_scene(path: str | None) -> list[Any] | None:
    """Obstacles of a YAML/JSON scene file (world frame [m]).

    The file holds a list, or ``{obstacles: [...]}``, of mappings
    ``{type: sphere|capsule|circle|cylinder, ...}`` (as in scenario files).
    """
    if path is None:
        return None
    from serialkin._files import load_document
    from serialkin.redundancy.obstacles import obstacle_from_dict

    doc = load_document(path, what="scene file")
    items = doc.get("obstacles") if isinstance(doc, dict) else doc
    if not isinstance(items, list) or not items:
        raise CLIError(f"scene file {path}: expected a list of obstacles (or a mapping with "
                       "'obstacles: [...]'), each {type: sphere, center: [x, y, z], radius: r}")
    return [obstacle_from_dict(d, f"{path}: obstacles[{i}]") if isinstance(d, dict) else
            _not_a_mapping(path, i, d) for i, d in enumerate(items)]


def _not_a_mapping(path: str, i: int, d: object) -> Any:
    raise CLIError(f"scene file {path}: obstacles[{i}] must be a mapping, got {short_repr(d)}")


def srdf_options(fn: Callable[..., Any]) -> Callable[..., Any]:
    """``--srdf FILE`` and ``--skip-links A,B`` (combinable), read by :func:`srdf_acm`."""
    fn = click.option("--skip-links", "skip_links", default=None, metavar="LINK1,LINK2",
                      help="SRDF links without a collision body (fingers off the chain, a "
                           "TCP frame): pairs naming them are skipped. Needs --srdf.")(fn)
    return click.option("--srdf", type=click.Path(exists=True, dir_okay=False), default=None,
                        help="SRDF whose <disable_collisions> pairs are not checked.")(fn)


def srdf_acm(robot: Any, srdf: str | None, skip_links: str | None) -> Any:
    """The allowed-collision matrix of ``--srdf`` / ``--skip-links``, or None (the default).

    Raises:
        CLIError: --skip-links without --srdf, a robot without a collision model, or an
            SRDF that cannot be read or names a link that is not a body (the message
            starts with ``--srdf``).
    """
    skip = [s.strip() for s in (skip_links or "").split(",") if s.strip()]
    if srdf is None:
        if skip:
            raise CLIError("--skip-links names links of an SRDF: give --srdf too")
        return None
    if robot.collision is None:
        raise CLIError(f"--srdf: robot {short_repr(robot.name)} has no collision model to "
                       "apply it to")
    from serialkin.collision import acm_from_srdf
    from serialkin.errors import RobotDefinitionError

    try:
        return acm_from_srdf(robot.collision, srdf, skip_links=skip)
    except RobotDefinitionError as exc:  # malformed XML, a link that is not a body
        raise CLIError(f"--srdf: {exc}") from exc


@click.command("collide", help=_COLLIDE_HELP,
               short_help="Closest collision pairs of a configuration.")
@robot_argument
@click.option("--q", "q_text", default=None, metavar="Q1,Q2,...",
              help="Joint values (default: zeros).")
@degrees_option
@click.option("--scene", default=None, type=click.Path(dir_okay=False),
              help="Obstacle file (YAML/JSON, world frame [m]).")
@srdf_options
@click.option("--count", "-n", type=click.IntRange(min=1), default=5, show_default=True,
              help="Pairs printed, closest first.")
@click.option("--margin", type=float, default=0.0, show_default=True,
              help="A pair closer than this [m] counts as a collision.")
@param_option
@json_option
@quiet_long_option
@handle_errors
def collide_cmd(robot: str, q_text: str | None, degrees: bool, scene: str | None,
                srdf: str | None, skip_links: str | None, count: int, margin: float,
                params: tuple[str, ...], as_json: bool, quiet: bool) -> None:
    """Print the closest pairs of one configuration."""
    from serialkin.collision import closest_pairs

    r = resolve_robot(robot, params)
    if r.collision is None:
        raise CLIError(f"robot {short_repr(r.name)} has no collision model (built-in arms "
                       "carry one; for a URDF see 'serialkin view --collision', which fits "
                       "capsules, or Robot.fit_collision)")
    q = parse_numbers(q_text, "--q", r.n) if q_text else np.zeros(r.n)
    if q_text and not degrees:
        refuse_joint_turns(r, q, "--q")
    q = q * _angle_factor(r, degrees)
    acm = srdf_acm(r, srdf, skip_links)
    obstacles = read_scene(scene)
    pairs = closest_pairs(r, q, obstacles, count=count, acm=acm)
    hit = bool(pairs) and pairs[0].distance < margin
    if as_json:
        click.echo(dumps_json({
            "robot": r.name, "q": q.tolist(), "in_collision": hit, "margin": margin,
            "pairs": [{"first": p.first, "second": p.second, "distance": p.distance,
                       "obstacle": p.with_scene} for p in pairs]}))
        return
    if quiet:
        return
    click.echo(f"{r.name}: {'in collision' if hit else 'free'}"
               + (f" (margin {margin * 1e3:g} mm)" if margin else ""))
    if not pairs:
        click.echo("no pair is checked")
        return
    w = max(len(p.first) for p in pairs)
    v = max(len(p.second) for p in pairs)
    click.echo(f"{'body':<{w}}  {'other':<{v}}  distance [mm]")
    for p in pairs:
        click.echo(f"{p.first:<{w}}  {p.second:<{v}}  {p.distance * 1e3:10.1f}")
