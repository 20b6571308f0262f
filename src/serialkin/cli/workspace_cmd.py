"""The ``workspace`` subcommand: compute, measure and plot a robot's workspace (section 1)."""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import click
import numpy as np

from serialkin._checks import check_positive, short_repr
from serialkin.cli.commands import (
    check_out_folder,
    handle_errors,
    json_option,
    memory_budget_option,
    quiet_option,
    refuse_angle_turns,
)
from serialkin.cli.io import (
    CLIError,
    command_help,
    dumps_json,
    ensure_dir,
    parse_numbers,
    write_bytes_atomic,
)
from serialkin.cli.robots import ROBOT_HELP, param_option, resolve_robot, robot_argument


def save_figure(fig: Any, path: Path) -> Path:
    """Save a matplotlib figure as PNG atomically and close it."""
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=120, bbox_inches="tight")
    plt.close(fig)
    return write_bytes_atomic(path, buf.getvalue())


def _orientation(text: str | None, planar: bool, degrees: bool) -> Any:
    if text is None:
        return None
    if planar:
        v = parse_numbers(text, "--orientation", (1, 9))
    else:
        v = parse_numbers(text, "--orientation", (3, 9))
    if v.size == 9:
        return v.reshape(3, 3)
    if degrees:
        v = np.radians(v)
    else:
        refuse_angle_turns(v, "--orientation", "φ" if planar else "roll/pitch/yaw")
    if planar:
        return float(v[0])
    from serialkin.spatial import rpy_to_matrix

    return rpy_to_matrix(v)


def _parse_slice(text: str) -> tuple[str, float]:
    if "=" not in text:
        raise CLIError(f"--slice {short_repr(text)}: expected AXIS=VALUE, e.g. --slice z=0.4")
    axis, val = text.split("=", 1)
    axis = axis.strip().lower()
    if axis not in ("x", "y", "z"):
        raise CLIError(f"--slice {short_repr(text)}: axis must be x, y or z, got "
                       f"{short_repr(axis)}")
    return axis, float(parse_numbers(val, "--slice", 1)[0])


_WORKSPACE_CMD_HELP = command_help(
    "Compute a workspace by sampling, with its area/volume and sampling error.\n\n"
    "Writes to the output folder: workspace_<kind>.png (2D with the boundary for planar "
    "robots, a 3D point cloud otherwise), manipulability_<kind>.png with -w, "
    "slice_<axis>_<value>.png per --slice, workspace_<kind>.npz (points, grid; q with "
    "--save-q) and workspace_<kind>.json (summary). ROBOT is " + ROBOT_HELP + ".",
    ["serialkin workspace two_link --out out/ws",
     "serialkin workspace three_link --kind constant --orientation 30 --degrees",
     "serialkin workspace three_link --kind dexterous --orientations 12",
     "serialkin workspace puma560 --samples 300000 --slice z=0.4 -w --json"],
)


@click.command("workspace", help=_WORKSPACE_CMD_HELP,
               short_help="Workspace by sampling: area/volume ± error, plots.")
@robot_argument
@click.option("--kind", "-k", type=click.Choice(["reachable", "constant", "inclusive", "total",
                                                 "dexterous"]),
              default="reachable", show_default=True, help="Workspace kind (chapter section 1).")
@click.option("--samples", "-n", type=int, default=None,
              help="Joint-space samples (per orientation for total/dexterous).")
@click.option("--seed", type=int, default=0, show_default=True, help="Random seed.")
@click.option("--cell", type=float, default=None, help="Grid cell edge [m] (default: automatic).")
@click.option("--resolution", type=int, default=None,
              help="Cells along the largest extent (default 200 planar, 50 spatial).")
@click.option("--orientation", default=None, metavar="PHI | R,P,Y | 9 NUMBERS",
              help="Tool orientation for constant/inclusive: planar angle φ, roll-pitch-yaw, "
                   "or a rotation matrix row-major.")
@click.option("--max-angle", type=float, default=None,
              help="Inclusive kind: half-width of the orientation range (rad, or deg with -d).")
@click.option("--orientations", type=int, default=None,
              help="Total/dexterous: number of sampled orientations.")
@click.option("--margin", type=float, default=0.05, show_default=True,
              help="Dexterous: singularity margin, fraction of the largest manipulability.")
@click.option("--manipulability", "-w", is_flag=True,
              help="Compute the manipulability map (eq 43) and plot it.")
@click.option("--slice", "slices", multiple=True, metavar="AXIS=VALUE",
              help="Spatial robots: also plot the slice AXIS=VALUE [m] (repeatable).")
@click.option("--degrees", "-d", is_flag=True, help="Angles of --orientation/--max-angle in "
              "degrees.")
@click.option("--out", "-o", "out", type=click.Path(file_okay=False), default="out/workspace",
              show_default=True, help="Output folder for figures, points and summary.")
@click.option("--no-plot", is_flag=True, help="Do not draw figures.")
@click.option("--points/--no-points", default=True, show_default=True,
              help="Save the sampled positions and the grid to workspace_<kind>.npz.")
@click.option("--save-q", is_flag=True, help="Also save each sample's configuration q in "
              "the .npz (large for big runs).")
@param_option
@json_option
@quiet_option
@memory_budget_option
@handle_errors
def workspace_cmd(robot: str, kind: str, samples: int | None, seed: int, cell: float | None,
                  resolution: int | None, orientation: str | None, max_angle: float | None,
                  orientations: int | None, margin: float, manipulability: bool,
                  slices: tuple[str, ...], degrees: bool, out: str, no_plot: bool,
                  points: bool, save_q: bool, params: tuple[str, ...], as_json: bool,
                  quiet: bool) -> None:
    """Compute a workspace by sampling, with its area/volume and sampling error."""
    from serialkin.workspace import compute_workspace

    r = resolve_robot(robot, params)
    planar = bool(r.is_planar)
    # every option is checked before anything is computed or written
    margin = check_positive(margin, "--margin", allow_zero=True)
    if max_angle is not None:
        max_angle = check_positive(max_angle, "--max-angle", allow_zero=True)
        if not degrees:
            refuse_angle_turns(max_angle, "--max-angle")
    if slices and planar:
        raise CLIError("--slice applies to spatial robots; this robot is planar")
    parsed_slices = [_parse_slice(s) for s in slices]
    progress = False if quiet or as_json else None
    opts: dict[str, Any] = {"seed": seed, "cell": cell, "resolution": resolution,
                            "progress": progress}
    ori = _orientation(orientation, planar, degrees)
    opts.update(_kind_options(kind, ori, max_angle=max_angle, orientations=orientations,
                              margin=margin, manipulability=manipulability, degrees=degrees))
    if samples is not None:
        opts["samples"] = samples
    check_out_folder(out)
    ws = compute_workspace(r, kind, **opts)
    folder = ensure_dir(out)
    files: dict[str, str] = {}

    if points or save_q:
        files["points"] = str(_save_points(ws, folder / f"workspace_{kind}.npz", save_q))
    if not no_plot:
        _save_plots(ws, kind, folder, manipulability, files)
    slice_summaries = _save_slices(ws, parsed_slices, folder, files, plot=not no_plot)
    summary = ws.summary()
    summary["slices"] = slice_summaries
    summary["files"] = files
    from serialkin.cli.io import write_text_atomic

    files["summary"] = str(folder / f"workspace_{kind}.json")
    write_text_atomic(folder / f"workspace_{kind}.json", dumps_json(summary))
    if as_json:
        click.echo(dumps_json(summary), nl=False)
        return
    if quiet:
        return
    _echo_report(r.name, kind, ws, seed, slice_summaries, files)


def _kind_options(kind: str, ori: Any, *, max_angle: float | None, orientations: int | None,
                  margin: float, manipulability: bool, degrees: bool) -> dict[str, Any]:
    """The keywords of ``compute_workspace`` that depend on ``--kind`` (checked options)."""
    opts: dict[str, Any] = {}
    if kind in ("constant", "inclusive"):
        if ori is None:
            raise CLIError(f"--kind {kind} needs --orientation (planar: an angle φ; spatial: "
                           "roll,pitch,yaw)")
        opts["orientation"] = ori
        opts["manipulability"] = manipulability
        if kind == "inclusive":
            if max_angle is None:
                raise CLIError("--kind inclusive needs --max-angle")
            opts["max_angle"] = float(np.radians(max_angle) if degrees else max_angle)
    elif kind in ("total", "dexterous"):
        if orientations is not None:
            opts["orientations"] = orientations
        if kind == "dexterous":
            opts["singularity_margin"] = margin
    else:
        opts["manipulability"] = manipulability
    return opts


def _save_points(ws: Any, path: Path, save_q: bool) -> Path:
    """Write the samples, the grid (and q with ``save_q``) of ``ws`` as a compressed .npz."""
    arrays = {"points": ws.points, "grid_counts": ws.grid.counts,
              "grid_lower": ws.grid.lower, "grid_cell": np.array(ws.grid.cell)}
    if ws.manipulability is not None:
        arrays["manipulability"] = ws.manipulability
    if save_q:
        arrays["q"] = ws.q
    buf = io.BytesIO()
    np.savez_compressed(buf, **arrays)
    return write_bytes_atomic(path, buf.getvalue())


def _save_plots(ws: Any, kind: str, folder: Path, manipulability: bool,
                files: dict[str, str]) -> None:
    """Plot the workspace (and its manipulability map) into ``folder``, adding to ``files``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from serialkin.workspace.plot import plot_manipulability_map, plot_workspace

    ax = plot_workspace(ws)
    files["figure"] = str(save_figure(ax.figure, folder / f"workspace_{kind}.png"))
    if ws.manipulability is not None and (manipulability or kind == "dexterous"):
        ax = plot_manipulability_map(ws)
        files["manipulability"] = str(save_figure(ax.figure,
                                                  folder / f"manipulability_{kind}.png"))
    plt.close("all")


def _save_slices(ws: Any, slices: list[tuple[str, float]], folder: Path,
                 files: dict[str, str], *, plot: bool) -> list[dict[str, Any]]:
    """Each --slice's area (and, with ``plot``, its figure, added to ``files``): summaries."""
    summaries = []
    for axis, value in slices:
        from serialkin.workspace import workspace_slice

        sl = workspace_slice(ws, axis, value)
        summaries.append({"axis": axis, "value": value, "area": sl.estimate.as_dict()})
        if plot:
            from serialkin.workspace.plot import plot_slice

            ax = plot_slice(sl)
            key = f"slice_{axis}_{value:g}"
            files[key] = str(save_figure(ax.figure, folder / f"{key}.png"))
    return summaries


def _echo_report(name: str, kind: str, ws: Any, seed: int,
                 slice_summaries: list[dict[str, Any]], files: dict[str, str]) -> None:
    """Print the estimate, the slices' areas and the files written."""
    click.echo(f"{name}: {kind} workspace from {ws.samples} samples "
               f"({ws.points.shape[0]} accepted, seed {seed})")
    click.echo(f"  {ws.estimate}")
    click.echo(f"  bounds [{ws.estimate.lower:.6g}, {ws.estimate.upper:.6g}] "
               f"{ws.estimate.unit}")
    for s in slice_summaries:
        a = s["area"]
        click.echo(f"  slice {s['axis']} = {s['value']:g} m: area {a['value']:.6g} ± "
                   f"{a['error']:.2g} m^2")
    for k, v in files.items():
        click.echo(f"  wrote {v}" if k != "summary" else f"  wrote {v}")
