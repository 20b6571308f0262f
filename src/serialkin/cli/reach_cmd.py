"""The ``reach`` and ``base-placement`` subcommands: reachability maps and base placement."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import click
import numpy as np

from serialkin._checks import short_repr
from serialkin.cli.collide_cmd import read_scene, srdf_acm, srdf_options
from serialkin.cli.commands import (
    check_out_folder,
    handle_errors,
    json_option,
    memory_budget_option,
    quiet_option,
    refuse_angle_turns,
)
from serialkin.cli.io import CLIError, command_help, dumps_json, ensure_dir, parse_numbers
from serialkin.cli.robots import ROBOT_HELP, param_option, resolve_robot, robot_argument
from serialkin.cli.workspace_cmd import _parse_slice, save_figure


def _executor(scheduler: str | None, cluster: str | None, quiet: bool) -> Any:
    """A Dask client for --scheduler / --cluster, or None (embedded)."""
    if scheduler and cluster:
        raise CLIError("give either --scheduler or --cluster, not both")
    from serialkin.reach import connect, local_cluster

    if scheduler:
        return connect(scheduler)
    if cluster:
        m = re.fullmatch(r"local:(\d{1,4})", cluster.strip())
        if m is None or int(m.group(1)) < 1:
            raise CLIError(f"--cluster {short_repr(cluster)}: expected local:N with N >= 1 "
                           "worker processes, e.g. --cluster local:2")
        return local_cluster(int(m.group(1)))
    return None


_REACH_HELP = command_help(
    "Reachability map: for every voxel of a grid, the fraction of N tool orientations the "
    "robot reaches (closed-form IK where the robot has one, else the batch numerical IK), "
    "with the number of solutions and manipulability statistics.\n\n"
    "Chunks stream to OUT/chunks/ as they finish; OUT/map.npz holds the assembled map, "
    "OUT/metadata.json the summary and per-chunk timings, OUT/reach_points.png the point "
    "cloud coloured by index (and slice_<axis>_<value>.png per --slice). An interrupted run "
    "continues with --resume. Runs in this process on every free core by default, on a "
    "Dask cluster with --scheduler or --cluster (extra serialkin[dist]). ROBOT is "
    + ROBOT_HELP + ".",
    ["serialkin reach ur5 --resolution 0.05 --orientations 50 --out maps/ur5",
     "serialkin reach ur5 --resolution 0.05 --out maps/ur5 --resume",
     "serialkin reach panda --resolution 0.1 --self-collision --srdf panda.srdf --out maps/p",
     "serialkin reach ur5 --resolution 0.1 --cluster local:2 --out maps/ur5_coarse",
     "serialkin reach panda --resolution 0.1 --scheduler tcp://10.0.0.5:8786 --out maps/p",
     "serialkin reach three_link --resolution 0.02 --orientations 36 --out maps/3link"],
)


@click.command("reach", help=_REACH_HELP, short_help="Reachability map (6-D workspace).")
@robot_argument
@click.option("--resolution", "-r", type=float, required=True, help="Voxel edge [m].")
@click.option("--orientations", "-n", type=int, default=50, show_default=True,
              help="Orientations per voxel (approach directions with --sampling approach; "
                   "headings for planar arms).")
@click.option("--sampling", type=click.Choice(["uniform", "approach"]), default="uniform",
              show_default=True, help="uniform on SO(3) (super-Fibonacci) or approach "
                                      "directions × --rolls.")
@click.option("--rolls", type=int, default=1, show_default=True,
              help="Rolls per approach direction.")
@click.option("--bounds", default=None, metavar="X0,X1,Y0,Y1,Z0,Z1",
              help="Box of the grid [m] (default: the robot's reach box).")
@click.option("--task", type=click.Choice(["pose", "position", "planar_pose", "planar"]),
              default=None, help="What a target fixes (default from the robot).")
@click.option("--solver", type=click.Choice(["auto", "closed_form", "numerical"]),
              default="auto", show_default=True, help="IK used for every target.")
@click.option("--restarts", type=int, default=5, show_default=True,
              help="Numerical solver: random restarts.")
@click.option("--seed", type=int, default=0, show_default=True, help="Root seed (>= 0).")
@click.option("--scene", default=None, type=click.Path(dir_okay=False),
              help="Obstacle file (YAML/JSON) for the collision-aware numerical IK.")
@click.option("--self-collision", is_flag=True,
              help="A target counts only with a solution free of self-collision (the "
                   "robot's collision model; --srdf adds the vendor's allowed pairs).")
@srdf_options
@click.option("--clearance", type=float, default=0.0, show_default=True,
              help="Distance [m] a solution keeps from collisions (self and --scene).")
@click.option("--chunk-voxels", type=int, default=512, show_default=True,
              help="Voxels per chunk (the unit of work, streaming and resume).")
@click.option("--out", "-o", "out", type=click.Path(file_okay=False), required=True,
              help="Output folder of the map.")
@click.option("--resume", is_flag=True, help="Continue the map in --out (same settings).")
@click.option("--scheduler", default=None, metavar="ADDRESS",
              help="Dask scheduler, e.g. tcp://host:8786.")
@click.option("--cluster", default=None, metavar="local:N",
              help="Start a local Dask cluster of N worker processes.")
@click.option("--slice", "slices", multiple=True, metavar="AXIS=VALUE",
              help="Also plot the index on the slice AXIS=VALUE [m] (repeatable).")
@click.option("--no-plot", is_flag=True, help="Do not draw figures.")
@param_option
@json_option
@quiet_option
@memory_budget_option
@handle_errors
def reach_cmd(robot: str, resolution: float, orientations: int, sampling: str, rolls: int,
              bounds: str | None, task: str | None, solver: str, restarts: int, seed: int,
              scene: str | None, self_collision: bool, srdf: str | None,
              skip_links: str | None, clearance: float, chunk_voxels: int, out: str,
              resume: bool,
              scheduler: str | None, cluster: str | None, slices: tuple[str, ...],
              no_plot: bool, params: tuple[str, ...], as_json: bool, quiet: bool) -> None:
    """Compute a reachability map."""
    from serialkin.reach.execute import make_job, run_job

    r = resolve_robot(robot, params)
    box = None if bounds is None else parse_numbers(bounds, "--bounds", 6).reshape(3, 2)
    parsed_slices = [_parse_slice(s) for s in slices]
    obstacles = read_scene(scene)
    acm = srdf_acm(r, srdf, skip_links)
    if acm is not None and not self_collision:
        raise CLIError("--srdf lists the pairs a self-collision check skips: add "
                       "--self-collision")
    check_out_folder(out)
    job = make_job(r, resolution, orientations, sampling=sampling, rolls=rolls, bounds=box,
                   task=task, solver=solver, restarts=restarts, seed=seed, scene=obstacles,
                   chunk_voxels=chunk_voxels, self_collision=self_collision, acm=acm,
                   clearance=clearance)
    client = _executor(scheduler, cluster, quiet)
    try:
        m = run_job(job, out=out, resume=resume, client=client,
                    progress=False if quiet or as_json else None)
    finally:
        if client is not None:
            client.close()
            if cluster:
                client.cluster.close()
    folder = ensure_dir(out)
    files = {"map": str(folder / "map.npz"), "metadata": str(folder / "metadata.json")}
    if not no_plot:
        import matplotlib

        matplotlib.use("Agg")
        from serialkin.reach.plot import plot_map_points, plot_map_slice

        if job.task.startswith("planar"):
            files["figure"] = str(save_figure(plot_map_slice(m, "z", m.grid.axes()[2][0]).figure,
                                              folder / "reach_slice.png"))
        else:
            files["figure"] = str(save_figure(plot_map_points(m).figure,
                                              folder / "reach_points.png"))
        for axis, value in parsed_slices:
            files[f"slice_{axis}"] = str(save_figure(plot_map_slice(m, axis, value).figure,
                                                     folder / f"slice_{axis}_{value:g}.png"))
    summary = dict(m.summary(), robot=r.name, task=job.task, solver=job.solver, files=files)
    if as_json:
        click.echo(dumps_json(summary))
    elif not quiet:
        t = summary["chunk_seconds_total"]
        click.echo(f"{r.name}: {summary['voxels']} voxels × {m.orientations} orientations "
                   f"({job.solver} IK), {summary['reachable_voxels']} reachable, "
                   f"{summary['fully_reachable_voxels']} fully reachable"
                   + (f"; {t:.3g} s of chunk time" if t is not None else ""))
        click.echo(f"map: {files['map']}")


def read_tasks(path: str, degrees: bool = False) -> np.ndarray:
    """Task poses from a .npy file ((M, 4, 4)) or a YAML/JSON list.

    The list (or ``{tasks: [...]}``) holds 4×4 matrices (nested or 16 numbers
    row-major) or ``[x, y, z, roll, pitch, yaw]`` [m, and rad, or deg with ``degrees``
    or a ``units: {angle: deg}`` key beside ``tasks``]. Angles read as radians beyond a
    full turn are refused (most likely degrees).
    """
    if Path(path).suffix.lower() == ".npy":
        try:
            a = np.load(path, allow_pickle=False)
        except (OSError, ValueError) as exc:
            raise CLIError(f"--tasks {path}: cannot read: {exc}") from exc
        return np.asarray(a, dtype=float)
    from serialkin._files import load_document
    from serialkin.spatial import rpy_to_matrix

    doc = load_document(path, what="tasks file")
    items = doc.get("tasks") if isinstance(doc, dict) else doc
    if not isinstance(items, list) or not items:
        raise CLIError(f"--tasks {path}: expected a list of poses (or 'tasks: [...]')")
    units = doc.get("units") if isinstance(doc, dict) else None
    if units is not None:
        unit = units.get("angle") if isinstance(units, dict) else None
        if unit not in ("rad", "deg") or set(units) - {"angle", "length"} or \
                units.get("length", "m") != "m":
            raise CLIError(f"--tasks {path}: units must be {{angle: rad | deg}} (lengths are "
                           f"metres), got {short_repr(units)}")
        if unit == "deg" and not degrees:
            degrees = True
        elif unit == "rad" and degrees:
            raise CLIError(f"--tasks {path}: the file says units: {{angle: rad}} but "
                           "--degrees is given; drop one")
    out = []
    for i, item in enumerate(items):
        try:
            v = np.asarray(item, dtype=float).reshape(-1)
        except (TypeError, ValueError):
            raise CLIError(f"--tasks {path}: tasks[{i}] is not a list of numbers") from None
        if v.size == 16:
            out.append(v.reshape(4, 4))
        elif v.size == 6:
            if not degrees:
                refuse_angle_turns(v[3:], f"--tasks {path}: tasks[{i}]", "roll/pitch/yaw",
                                   hint="add --degrees or units: {angle: deg} to the file")
            T = np.eye(4)
            rpy = np.radians(v[3:]) if degrees else v[3:]
            T[:3, :3], T[:3, 3] = rpy_to_matrix(rpy), v[:3]
            out.append(T)
        else:
            raise CLIError(f"--tasks {path}: tasks[{i}] has {v.size} numbers; expected 16 "
                           "(a 4x4 pose) or 6 (x, y, z, roll, pitch, yaw)")
    return np.array(out)


_BASE_HELP = command_help(
    "Base placement (inverse reachability): the base poses on a floor plane, on a grid of "
    "--resolution with --yaws headings, from which the robot reaches every task pose with "
    "a collision-free solution (self-collision when the robot has a collision model, "
    "--scene obstacles in the tasks' frame), and the best one: most task poses reached, "
    "then the largest margin (each task's distance from the edge of the reachable set, "
    "read on a reachability map: the smallest over the tasks, then the median), then the "
    "largest worst-case manipulability.\n\n"
    "The map is computed at --map-resolution and saved as OUT/reach_map.npz, or a saved "
    "one is reused with --map (a folder written by `serialkin reach` or a .npz; it must be "
    "of the same robot and self-collision settings, and is refused otherwise, naming each "
    "difference). Writes OUT/base_placement.npz, OUT/base_placement.json and "
    "OUT/base_placement.png. ROBOT is " + ROBOT_HELP + ".",
    ["serialkin base-placement ur5 --tasks tasks.yaml --out out/base",
     "serialkin base-placement ur5 --tasks tasks.npy --resolution 0.05 --yaws 16",
     "serialkin base-placement ur5 --tasks tasks.yaml --map out/base/reach_map.npz",
     "serialkin base-placement panda --tasks tasks.yaml --srdf panda.srdf --scene table.yaml"],
)


@click.command("base-placement", help=_BASE_HELP,
               short_help="Where to place the base to reach task poses.")
@robot_argument
@click.option("--tasks", "tasks_file", required=True, type=click.Path(dir_okay=False),
              help="Task poses: .npy (M, 4, 4) or YAML/JSON list.")
@click.option("--resolution", "-r", type=float, default=0.1, show_default=True,
              help="Floor grid spacing [m].")
@click.option("--yaws", type=int, default=8, show_default=True,
              help="Base headings tried (1: no yaw).")
@click.option("--region", default=None, metavar="X0,X1,Y0,Y1",
              help="Floor region [m] (default: the tasks' box widened by the reach).")
@click.option("--floor-z", type=float, default=0.0, show_default=True,
              help="Height of the floor plane [m].")
@click.option("--solver", type=click.Choice(["auto", "closed_form", "numerical"]),
              default="auto", show_default=True, help="IK used for every target.")
@click.option("--seed", type=int, default=0, show_default=True, help="Root seed (>= 0).")
@click.option("--scene", default=None, type=click.Path(dir_okay=False),
              help="Obstacle file (YAML/JSON, the tasks' frame [m]): solutions must be "
                   "clear of it.")
@click.option("--self-collision/--no-self-collision", default=None,
              help="Solutions must be free of self-collision [default: when the robot "
                   "has a collision model].")
@srdf_options
@click.option("--clearance", type=float, default=0.0, show_default=True,
              help="Distance [m] a solution keeps from collisions.")
@click.option("--map", "map_path", default=None, type=click.Path(exists=True),
              help="Reuse a saved reachability map (folder of `serialkin reach`, or .npz) "
                   "for the margins instead of computing one.")
@click.option("--map-resolution", type=float, default=None,
              help="Voxel edge [m] of the computed map [default: --resolution].")
@click.option("--map-orientations", type=int, default=12, show_default=True,
              help="Orientations per voxel of the computed map.")
@click.option("--out", "-o", "out", type=click.Path(file_okay=False), default="out/base",
              show_default=True, help="Output folder.")
@click.option("--no-plot", is_flag=True, help="Do not draw the figure.")
@click.option("--degrees", "-d", is_flag=True,
              help="Roll, pitch, yaw of the --tasks file in degrees (or units: {angle: deg} "
                   "in the file); the printed yaw is always in degrees, JSON in radians.")
@param_option
@json_option
@quiet_option
@memory_budget_option
@handle_errors
def base_placement_cmd(robot: str, tasks_file: str, resolution: float, yaws: int,
                       region: str | None, floor_z: float, solver: str, seed: int,
                       scene: str | None, self_collision: bool | None, srdf: str | None,
                       skip_links: str | None, clearance: float, map_path: str | None,
                       map_resolution: float | None, map_orientations: int, out: str,
                       no_plot: bool, degrees: bool, params: tuple[str, ...], as_json: bool,
                       quiet: bool) -> None:
    """Find base poses that reach every task pose."""
    import io
    import json

    from serialkin.cli.io import write_bytes_atomic, write_text_atomic
    from serialkin.reach import base_placement

    r = resolve_robot(robot, params)
    T = read_tasks(tasks_file, degrees)
    reg = None if region is None else parse_numbers(region, "--region", 4).reshape(2, 2)
    obstacles = read_scene(scene)
    acm = srdf_acm(r, srdf, skip_links)
    if acm is not None and self_collision is False:
        raise CLIError("--srdf lists the pairs a self-collision check skips; it cannot go "
                       "with --no-self-collision")
    check_out_folder(out)
    bp = base_placement(r, T, resolution=resolution, yaws=yaws, region=reg, floor_z=floor_z,
                        solver=solver, seed=seed, scene=obstacles,
                        self_collision=True if acm is not None else self_collision, acm=acm,
                        clearance=clearance, reach_map=map_path, map_resolution=map_resolution,
                        map_orientations=map_orientations,
                        progress=False if quiet or as_json else None)
    folder = ensure_dir(out)
    buf = io.BytesIO()
    np.savez_compressed(buf, xs=bp.xs, ys=bp.ys, yaws=bp.yaws, reached=bp.reached,
                        dexterity=bp.dexterity, margin=bp.margin, best=bp.best, tasks=T)
    files = {"data": str(write_bytes_atomic(folder / "base_placement.npz", buf.getvalue()))}
    if map_path is None and bp.reach_map is not None:
        files["reach_map"] = str(bp.reach_map.save(folder / "reach_map.npz"))
    summary = dict(bp.summary(), robot=r.name, files=files,
                   map=str(map_path) if map_path else None)
    if not no_plot:
        import matplotlib

        matplotlib.use("Agg")
        from serialkin.reach.plot import plot_base_placement

        files["figure"] = str(save_figure(plot_base_placement(bp, tasks=T).figure,
                                          folder / "base_placement.png"))
    write_text_atomic(folder / "base_placement.json", json.dumps(summary, indent=1))
    if as_json:
        click.echo(dumps_json(summary))
    elif not quiet:
        b = summary["best"]
        click.echo(f"{r.name}: {summary['feasible_candidates']} of {summary['candidates']} "
                   f"base poses reach all {bp.tasks} tasks; best x={b['x']:.3f} m "
                   f"y={b['y']:.3f} m yaw={np.degrees(b['yaw']):.1f}° (reaches {b['reached']}, "
                   f"margin {b['margin_min'] * 1e3:.0f} mm smallest, "
                   f"{b['margin_median'] * 1e3:.0f} mm median, "
                   f"worst-case manipulability {b['dexterity']:.4g})")
        if "reach_map" in files:
            click.echo(f"reach map: {files['reach_map']} (reuse it with --map)")
