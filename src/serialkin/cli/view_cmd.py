"""The ``view`` subcommand: write (and open) the interactive viewer page."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click
import numpy as np

from serialkin._checks import short_repr
from serialkin.cli.commands import (
    _angle_factor,
    check_out_folder,
    handle_errors,
    json_option,
    memory_budget_option,
    quiet_long_option,
)
from serialkin.cli.io import CLIError, command_help, dumps_json, ensure_dir, parse_numbers
from serialkin.cli.robots import ROBOT_HELP, param_option, resolve_robot

_VIEW_HELP = command_help(
    "Write the interactive 3D viewer page of a robot, a configuration or a trajectory.\n\n"
    "A self-contained HTML file (no server, no network): rotate and zoom, a slider per "
    "joint (forward kinematics in the page), play through a trajectory, the target path "
    "and obstacles. ROBOT is " + ROBOT_HELP + "; with --scenario it may be omitted. "
    "--trajectory reads a trajectory written by 'serialkin track' (.csv/.npz) or a CSV of "
    "joint values (one configuration per row).",
    ["serialkin view ur5 --q \"0,-1.2,1.4,0,0.5,0\" --out ur5.html --open",
     "serialkin view --scenario six_link_circle --out six.html",
     "serialkin view planar20 --trajectory out/track/twenty_link_free.npz"],
)


def _load_trajectory(path: str, robot: Any) -> tuple[np.ndarray, np.ndarray | None]:
    """Joint values (p, n) and path points (p, 3) or None from a trajectory or q CSV file."""
    from serialkin.cli.io import read_csv_rows

    p = Path(path)
    if not p.exists():
        raise CLIError(f"trajectory file {path} not found")
    if p.suffix.lower() == ".npz" or _is_serialkin_csv(p):
        from serialkin.tracking import Trajectory

        traj = Trajectory.load(p)
        if traj.q.shape[1] != robot.n:
            raise CLIError(f"{path}: trajectory has {traj.q.shape[1]} joints but robot "
                           f"{short_repr(robot.name)} has {robot.n}")
        return traj.q, traj.targets[:, :3, 3]
    return read_csv_rows(p, "q", robot.n), None


def _is_serialkin_csv(p: Path) -> bool:
    try:
        with p.open(encoding="utf-8") as f:
            return f.readline().startswith("# serialkin trajectory")
    except (OSError, UnicodeDecodeError):
        return False


@click.command("view", help=_VIEW_HELP,
               short_help="Write (and open) the interactive 3D viewer page.")
@click.argument("robot", metavar="ROBOT", required=False)
@click.option("--q", "q_text", default=None, metavar="Q1,Q2,...",
              help="Configuration shown first (default zeros).")
@click.option("--trajectory", type=click.Path(dir_okay=False),
              help="Trajectory (.csv/.npz from 'serialkin track') or CSV of q rows.")
@click.option("--scenario", default=None,
              help="Scenario file or shipped name: its robot, path and obstacles (its "
                   "trajectory is computed unless --trajectory is given).")
@click.option("--title", default=None, help="Page title.")
@click.option("--out", "-o", "out", type=click.Path(dir_okay=False), default="viewer.html",
              show_default=True, help="The HTML file to write.")
@click.option("--open", "open_browser", is_flag=True, help="Open the page in a web browser.")
@click.option("--degrees", "-d", is_flag=True, help="--q angles in degrees.")
@param_option
@json_option
@quiet_long_option
@memory_budget_option
@handle_errors
def view_cmd(robot: str | None, q_text: str | None, trajectory: str | None,
             scenario: str | None, title: str | None, out: str, open_browser: bool,
             degrees: bool, params: tuple[str, ...], as_json: bool, quiet: bool) -> None:
    """Write the interactive viewer page (and open it with --open)."""
    from serialkin.viz.viewer import write_viewer

    obstacles: tuple[Any, ...] = ()
    path_points = None
    Q = None
    if scenario is not None:
        from serialkin.tracking import load_scenario

        sc = load_scenario(scenario)
        r = resolve_robot(robot, params) if robot is not None else sc.robot
        obstacles = tuple(sc.obstacles)
        title = title or sc.name
    elif robot is None:
        raise CLIError("missing ROBOT (or --scenario): " + ROBOT_HELP)
    else:
        r = resolve_robot(robot, params)
    # every input is checked before the scenario runs and before the page is written
    q = parse_numbers(q_text, "--q", r.n) * _angle_factor(r, degrees) if q_text else None
    if Path(out).is_dir():
        raise CLIError(f"--out {out}: is a folder; give the page's file name (.html)")
    check_out_folder(Path(out).parent)
    if trajectory is not None:
        Q, pts = _load_trajectory(trajectory, r)
        path_points = pts
    elif scenario is not None:
        traj = sc.run()
        Q, path_points = traj.q, traj.targets[:, :3, 3]
    ensure_dir(Path(out).parent)
    path = write_viewer(r, out, q=q, trajectory=Q, path_points=path_points,
                        obstacles=obstacles or None, title=title)
    info = {"file": str(path), "robot": r.name, "n": r.n,
            "frames": int(Q.shape[0]) if Q is not None else 0}
    if as_json:
        click.echo(dumps_json(info), nl=False)
    elif not quiet:
        click.echo(f"wrote {path}")
    if open_browser:
        import webbrowser

        if not webbrowser.open(Path(path).resolve().as_uri()):
            click.echo(f"could not open a browser; open {Path(path).resolve()} by hand",
                       err=True)
