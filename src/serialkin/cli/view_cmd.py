"""The ``view`` subcommand: write (and open) the interactive viewer page."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click
import numpy as np

from serialkin._checks import short_repr
from serialkin.cli.collide_cmd import srdf_acm, srdf_options
from serialkin.cli.commands import (
    _angle_factor,
    check_out_folder,
    handle_errors,
    json_option,
    memory_budget_option,
    quiet_long_option,
    refuse_joint_turns,
)
from serialkin.cli.io import CLIError, command_help, dumps_json, ensure_dir, parse_numbers
from serialkin.cli.robots import ROBOT_HELP, param_option, resolve_robot
from serialkin.errors import SerialkinError

#: ``serialkin.viz.viewer.MESH_BUDGET``, repeated so that the command line does not import
#: the viewer at start-up (a test checks they agree).
_MESH_BUDGET = 60_000

_VIEW_HELP = command_help(
    "Write the interactive 3D viewer page of a robot, a configuration or a trajectory.\n\n"
    "A self-contained HTML file (no server, no network): rotate and zoom, a slider per "
    "joint (forward kinematics in the page), play through a trajectory, the target path "
    "and obstacles. ROBOT is " + ROBOT_HELP + "; with --scenario it may be omitted. "
    "--trajectory reads a trajectory written by 'serialkin track' (.csv/.npz) or a CSV of "
    "joint values (one configuration per row). A robot with link geometry (a URDF) is "
    "drawn with its visual meshes (the 'mesh' extra: pip install \"serialkin[mesh]\"), "
    "decimated to --mesh-budget triangles; --package and --mesh-path say where a URDF's "
    "package:// and relative mesh paths are. A robot with a collision model (the built-in "
    "models) gets its capsules as a toggle (--collision shows them at once, and fits them "
    "to a URDF's collision geometry) and the colliding pairs turn red while you move the "
    "sliders (--srdf: skip the pairs an SRDF disables). --points draws a CSV of "
    "x,y,z[,r,g,b] rows (colours in [0, 1]) as a point cloud.",
    ["serialkin view ur5 --q \"0,-1.2,1.4,0,0.5,0\" --out ur5.html --open",
     "serialkin view --scenario six_link_circle --out six.html",
     "serialkin view planar20 --trajectory out/track/twenty_link_free.npz",
     "serialkin view panda --collision --q \"0,0,0,-3,0,0.5,0\" --out folded.html",
     "serialkin view robots/panda.urdf --package example-robot-data=share/example-robot-data "
     "--param tip_link=panda_hand --out panda.html"],
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


def _parse_packages(packages: tuple[str, ...]) -> dict[str, str]:
    """``NAME=FOLDER`` pairs of --package into a package map (the folders must exist)."""
    out: dict[str, str] = {}
    for item in packages:
        name, sep, folder = item.partition("=")
        if not sep or not name.strip() or not folder.strip():
            raise CLIError(f"--package {short_repr(item)}: expected NAME=FOLDER, e.g. "
                           "--package my_description=/opt/ros/share/my_description")
        if not Path(folder).is_dir():
            raise CLIError(f"--package {short_repr(item)}: folder {folder} not found")
        out[name.strip()] = folder
    return out


def _urdf_with_meshes(spec: str, params: tuple[str, ...], packages: tuple[str, ...],
                      mesh_paths: tuple[str, ...]) -> Any:
    """A URDF robot whose mesh paths are looked up with --package and --mesh-path."""
    from serialkin.cli.robots import parse_params

    if Path(spec).suffix.lower() != ".urdf":
        raise CLIError(f"--package and --mesh-path apply to a URDF file (.urdf), not "
                       f"{short_repr(spec)}")
    if not Path(spec).is_file():
        raise CLIError(f"robot file {spec} not found")
    for folder in mesh_paths:
        if not Path(folder).is_dir():
            raise CLIError(f"--mesh-path {folder}: folder not found")
    from serialkin.cli.robots import announce_tip
    from serialkin.formats.urdf import choose_chain, robot_from_urdf

    links = {k: str(v) for k, v in parse_params(params).items()}
    keys = {"base_link", "tip_link", "srdf"}
    if set(links) - keys:
        raise CLIError(f"--param for a URDF takes base_link=, tip_link= and srdf= only, got "
                       f"{', '.join(sorted(set(links) - keys))}")
    announce_tip(spec, choose_chain(spec, **links))
    return robot_from_urdf(spec, **links, package_map=_parse_packages(packages),
                           search_path=list(mesh_paths), whole_tree=True)


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
@click.option("--meshes/--no-meshes", default=True, show_default=True,
              help="Draw the visual mesh files of the robot's links (else primitives only, "
                   "or the skeleton).")
@click.option("--mesh-budget", type=click.IntRange(min=4), default=None, metavar="TRIANGLES",
              help=f"Most triangles of all meshes together [default: {_MESH_BUDGET}]; about "
                   "12 bytes of page each.")
@click.option("--package", "packages", multiple=True, metavar="NAME=FOLDER",
              help="Folder of a ROS package, for a URDF's package://NAME/... mesh paths; "
                   "repeatable.")
@click.option("--mesh-path", "mesh_paths", multiple=True, type=click.Path(file_okay=False),
              metavar="FOLDER", help="Folder where a URDF's package://NAME/... is looked up "
                   "as FOLDER/NAME/... and relative mesh paths as FOLDER/...; repeatable.")
@click.option("--collision", "show_collision", is_flag=True,
              help="Show the collision capsules when the page opens; a robot without a "
                   "collision model gets capsules fitted to its links' collision geometry "
                   "(Robot.fit_collision).")
@srdf_options
@click.option("--points", "points_file", type=click.Path(dir_okay=False), default=None,
              help="CSV of x,y,z or x,y,z,r,g,b rows [m; colours in 0..1] drawn as points.")
@click.option("--points-label", default=None, help="Name of the point layer in the page "
              "[default: the file name].")
@param_option
@json_option
@quiet_long_option
@memory_budget_option
@handle_errors
def view_cmd(robot: str | None, q_text: str | None, trajectory: str | None,
             scenario: str | None, title: str | None, out: str, open_browser: bool,
             degrees: bool, meshes: bool, mesh_budget: int | None, packages: tuple[str, ...],
             mesh_paths: tuple[str, ...], show_collision: bool, srdf: str | None,
             skip_links: str | None,
             points_file: str | None, points_label: str | None, params: tuple[str, ...],
             as_json: bool, quiet: bool) -> None:
    """Write the interactive viewer page (and open it with --open)."""
    r, sc = _view_robot(robot, scenario, params, packages, mesh_paths)
    obstacles = tuple(sc.obstacles) if sc is not None else ()
    if sc is not None:
        title = title or sc.name
    # every input is checked before the scenario runs and before the page is written
    q = parse_numbers(q_text, "--q", r.n) if q_text else None
    if q is not None and not degrees:
        refuse_joint_turns(r, q, "--q")
    q = q * _angle_factor(r, degrees) if q is not None else None
    if Path(out).is_dir():
        raise CLIError(f"--out {out}: is a folder; give the page's file name (.html)")
    check_out_folder(Path(out).parent)
    Q, path_points = _view_motion(r, sc, trajectory)
    r, fitted = _with_collision(r, show_collision)
    acm = srdf_acm(r, srdf, skip_links)
    points, colors, points_label = _point_layer(points_file, points_label)
    ensure_dir(Path(out).parent)
    from serialkin.viz.scene import Scene, ViewerOptions

    scene = Scene(r, q=q, trajectory=Q, path_points=path_points, obstacles=obstacles,
                  acm=acm, points=points, point_colors=colors,
                  points_label=points_label or "points", title=title)
    options = ViewerOptions(meshes=meshes, show_collision=show_collision,
                            mesh_budget=_MESH_BUDGET if mesh_budget is None else mesh_budget)
    path = _write_page(scene, out, options)
    info = {"file": str(path), "robot": r.name, "n": r.n,
            "frames": int(Q.shape[0]) if Q is not None else 0,
            "collision": r.collision is not None, "capsules_fitted": fitted,
            "points": 0 if points is None else int(points.shape[0])}
    if as_json:
        click.echo(dumps_json(info), nl=False)
    elif not quiet:
        click.echo(f"wrote {path}")
    if open_browser:
        _open_page(path)


def _view_robot(robot: str | None, scenario: str | None, params: tuple[str, ...],
                packages: tuple[str, ...], mesh_paths: tuple[str, ...]) -> tuple[Any, Any]:
    """The robot shown and the scenario (None without --scenario)."""
    if scenario is not None:
        from serialkin.tracking import load_scenario

        sc = load_scenario(scenario)
        return (resolve_robot(robot, params) if robot is not None else sc.robot), sc
    if robot is None:
        raise CLIError("missing ROBOT (or --scenario): " + ROBOT_HELP)
    if packages or mesh_paths:
        return _urdf_with_meshes(robot, params, packages, mesh_paths), None
    return resolve_robot(robot, params, whole_tree=True), None


def _view_motion(r: Any, sc: Any, trajectory: str | None,
                 ) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Joint values (p, n) and path points (p, 3): from --trajectory, else the scenario's run."""
    if trajectory is not None:
        return _load_trajectory(trajectory, r)
    if sc is not None:
        traj = sc.run()
        return traj.q, traj.targets[:, :3, 3]
    return None, None


def _with_collision(r: Any, show_collision: bool) -> tuple[Any, bool]:
    """The robot, with capsules fitted to its collision geometry when --collision needs them.

    Returns the robot and whether capsules were fitted.
    """
    if not show_collision or r.collision is not None:
        return r, False
    if not any(lg.collision for lg in r.geometry):
        raise CLIError(f"--collision: robot {short_repr(r.name)} has no collision model "
                       "and no collision geometry to fit one to")
    fitted, _ = r.fit_collision()  # bounding capsules of the links' collision shapes
    return fitted, True


def _point_layer(points_file: str | None, points_label: str | None,
                 ) -> tuple[np.ndarray | None, np.ndarray | None, str | None]:
    """Positions (N, 3) [m], colours (N, 3) or None and the label of --points."""
    if points_file is None:
        if points_label is not None:
            raise CLIError("--points-label needs --points FILE")
        return None, None, None
    from serialkin.cli.io import read_csv_rows

    rows = read_csv_rows(points_file, "points", (3, 6))
    colors = rows[:, 3:] if rows.shape[1] == 6 else None
    label = points_label if points_label is not None else Path(points_file).name
    return rows[:, :3], colors, label


def _write_page(scene: Any, out: str, options: Any) -> Path:
    """Write the page; a visual mesh that cannot be read gets the command line's hint."""
    from serialkin.viz.viewer import write_viewer

    try:
        return write_viewer(scene, out, options)
    except SerialkinError as exc:
        if "visual mesh" in str(exc):
            raise CLIError(f"{exc} (on the command line: --package NAME=FOLDER or --mesh-path "
                           "FOLDER, or --no-meshes)") from exc
        raise


def _open_page(path: Path) -> None:
    """Open the written page in a web browser, or say where it is."""
    import webbrowser

    if not webbrowser.open(Path(path).resolve().as_uri()):
        click.echo(f"could not open a browser; open {Path(path).resolve()} by hand", err=True)
