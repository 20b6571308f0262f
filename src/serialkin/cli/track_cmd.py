"""The ``track`` subcommand: run a path-tracking scenario (section 5.3) and write its outputs."""

from __future__ import annotations

import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import click
import numpy as np

from serialkin._checks import check_int, check_positive
from serialkin.cli.collide_cmd import srdf_acm, srdf_options
from serialkin.cli.commands import (
    check_out_folder,
    handle_errors,
    json_option,
    memory_budget_option,
    quiet_option,
    refuse_angle_turns,
)
from serialkin.cli.io import (
    EXIT_NOT_REACHED,
    CLIError,
    command_help,
    dumps_json,
    ensure_dir,
    write_bytes_atomic,
    write_text_atomic,
)

#: Largest --max-frames: an animation longer than this is not a sensible GIF.
MAX_FRAMES = 100_000

_TRACK_HELP = command_help(
    "Track the path of a scenario file and write the trajectory, figures and animation.\n\n"
    "SCENARIO is a scenario file (.yaml/.json: robot, path, obstacles, limits, solver; see "
    "serialkin.tracking.scenario) or the name of a shipped scenario (--list). Writes "
    "<name>.csv and/or <name>.npz (the trajectory), <name>.png (motion, joint variables, "
    "tracking error, clearance in one figure) and each of them alone (<name>_motion.png, "
    "_joints.png, _error.png, _clearance.png with obstacles), <name>.gif (and .mp4 with "
    "--mp4 when ffmpeg is present) and, with --viewer, <name>.html (the interactive "
    "viewer). --solver qp replaces the scenario's solver by the differential-IK quadratic "
    "program with hard joint limits and collision constraints (serialkin.diffik); "
    "--max-joint-step reports (and with qp forbids) larger joint jumps between path points. "
    "--self-collision makes the QP keep the robot's own bodies apart (the body pairs of "
    "its collision model that the allowed-collision matrix checks, as in 'serialkin "
    "collide'; a robot without a collision model: its link segments), and --srdf adds the "
    "SRDF's <disable_collisions> pairs to the pairs it skips (a scenario whose solver has "
    "self_collision: true needs no --self-collision). "
    "Exit code 1 when a path point is not reached within the tolerance; 2 on bad input.",
    ["serialkin track six_link_circle --out out/track",
     "serialkin track twenty_link_obstacles --format npz --viewer",
     "serialkin track my_scenario.yaml --no-animation --json",
     "serialkin track twenty_link_obstacles --solver qp --max-joint-step 0.2",
     "serialkin track ur5_path.yaml --solver qp --self-collision --srdf ur5.srdf",
     "serialkin track --list"],
)


@click.command("track", help=_TRACK_HELP,
               short_help="Track a scenario's path: trajectory, figures, GIF.")
@click.argument("scenario", required=False)
@click.option("--out", "-o", "out", type=click.Path(file_okay=False), default="out/track",
              show_default=True, help="Output folder.")
@click.option("--format", "fmt", type=click.Choice(["csv", "npz", "both"]), default="both",
              show_default=True, help="Trajectory file format.")
@click.option("--no-figures", is_flag=True, help="Do not draw the summary figure.")
@click.option("--no-animation", is_flag=True, help="Do not render the GIF animation.")
@click.option("--mp4", is_flag=True, help="Also render an MP4 (needs ffmpeg).")
@click.option("--fps", type=float, default=15.0, show_default=True, help="Animation frame rate.")
@click.option("--max-frames", type=int, default=150, show_default=True,
              help="At most this many animation frames (evenly spread).")
@click.option("--viewer", is_flag=True, help="Also write the interactive viewer page.")
@click.option("--solver", "solver", type=click.Choice(["scenario", "qp"]), default="scenario",
              show_default=True,
              help="The scenario's own solver, or the QP with hard constraints.")
@click.option("--max-joint-step", type=float, default=None,
              help="Report joint jumps between path points above this [rad]; a hard bound "
                   "with --solver qp.")
@click.option("--max-joint-step-deg", type=float, default=None,
              help="The same in degrees.")
@click.option("--self-collision", is_flag=True,
              help="Keep the robot's own bodies apart (the QP solver: --solver qp or a "
                   "scenario with method: qp).")
@srdf_options
@click.option("--list", "list_only", is_flag=True, help="List the shipped scenarios.")
@click.option("--verbose", "-v", is_flag=True,
              help="List every failed point and joint jump in the summary (default: the "
                   "first three of each and how many more).")
@json_option
@quiet_option
@memory_budget_option
@handle_errors
def track_cmd(scenario: str | None, out: str, fmt: str, no_figures: bool, no_animation: bool,
              mp4: bool, fps: float, max_frames: int, viewer: bool, solver: str,
              max_joint_step: float | None, max_joint_step_deg: float | None,
              self_collision: bool, srdf: str | None, skip_links: str | None,
              list_only: bool, verbose: bool, as_json: bool, quiet: bool) -> None:
    """Track a scenario's path and write trajectory, figures and animation."""
    from serialkin.tracking import list_scenarios, load_scenario

    if list_only:
        _echo_scenarios(list_scenarios(), as_json)
        return
    if scenario is None:
        raise CLIError("missing SCENARIO: a scenario file or a shipped name (see --list)")
    # every option is checked before anything is computed or written
    fps = check_positive(fps, "--fps")
    max_frames = check_int(max_frames, "--max-frames", minimum=1, maximum=MAX_FRAMES)
    if max_joint_step is not None and max_joint_step_deg is not None:
        raise CLIError("--max-joint-step and --max-joint-step-deg are both given; use one "
                       "(radians or degrees)")
    if max_joint_step_deg is not None:
        max_joint_step = np.radians(check_positive(max_joint_step_deg, "--max-joint-step-deg"))
    elif max_joint_step is not None:
        max_joint_step = check_positive(max_joint_step, "--max-joint-step")
        refuse_angle_turns(max_joint_step, "--max-joint-step", "joint step",
                           hint="use --max-joint-step-deg")
    check_out_folder(out)
    sc = _with_solver(load_scenario(scenario), solver, max_joint_step)
    sc = _with_self_collision(sc, self_collision, srdf_acm(sc.robot, srdf, skip_links))
    stem = Path(scenario).stem if Path(scenario).suffix else scenario
    show = not quiet and not as_json and sys.stderr.isatty()
    if show:
        click.echo(f"tracking {sc.name}: {len(sc.path)} path points, robot {sc.robot.name} "
                   f"({sc.robot.n} joints) ...", err=True)
    traj = sc.run()
    run = _Outputs(sc, traj, ensure_dir(out), stem)
    _write_trajectory(run, ("csv", "npz") if fmt == "both" else (fmt,))
    if not no_figures or not no_animation:
        import matplotlib

        matplotlib.use("Agg")
    if not no_figures:
        _write_figures(run)
    if not no_animation:
        _write_animation(run, fps=fps, max_frames=max_frames, mp4=mp4, progress=show)
    if viewer:
        _write_viewer(run)
    files = run.files
    summary = _summary(sc, traj, files)
    write_text_atomic(run.folder / f"{stem}.json", dumps_json(summary))
    files["summary"] = str(run.folder / f"{stem}.json")
    if as_json:
        click.echo(dumps_json(summary), nl=False)
    elif not quiet:
        click.echo(traj.summary(verbose=verbose))
        for v in files.values():
            click.echo(f"  wrote {v}")
    for items, what in ((traj.failures, "path points not reached"),
                        (traj.jumps, "joint jumps at points")):
        if items:
            idx = [x.index for x in items]
            more = f" and {len(idx) - 10} more" if len(idx) > 10 else ""
            click.echo(f"{len(idx)} {what}: {', '.join(map(str, idx[:10]))}{more}", err=True)
    if not traj.complete:
        raise SystemExit(EXIT_NOT_REACHED)


def _echo_scenarios(names: list[str], as_json: bool) -> None:
    """Print the shipped scenarios' names (--list), one a line or as JSON."""
    if as_json:
        click.echo(dumps_json({"scenarios": names}), nl=False)
    else:
        for n in names:
            click.echo(n)


@dataclass(frozen=True, eq=False)
class _Outputs:
    """A tracked scenario and where its outputs go.

    Attributes:
        sc: the scenario.
        traj: its trajectory.
        folder: the output folder (exists).
        stem: the file name stem of every output.
        files: what was written so far, key -> path (filled in by the writers).
    """

    sc: Any
    traj: Any
    folder: Path
    stem: str
    files: dict[str, str] = field(default_factory=dict)

    def write(self, key: str, suffix: str, data: bytes) -> None:
        """Write ``data`` atomically to ``<stem><suffix>`` and record it as ``key``."""
        self.files[key] = str(write_bytes_atomic(self.folder / f"{self.stem}{suffix}", data))


def _write_trajectory(run: _Outputs, extensions: tuple[str, ...]) -> None:
    """Save the trajectory once per extension ('csv', 'npz'); CLIError when it cannot."""
    for ext in extensions:
        p = run.folder / f"{run.stem}.{ext}"
        try:
            run.traj.save(p)
        except OSError as exc:
            raise CLIError(f"cannot write {p} ({exc.strerror or exc})") from exc
        run.files[ext] = str(p)


def _write_figures(run: _Outputs) -> None:
    """The summary figure and each of its panels alone, as PNG files."""
    import io

    import matplotlib.pyplot as plt

    from serialkin.viz.trajectory import (
        plot_clearance,
        plot_joint_trajectories,
        plot_motion,
        plot_tracking_error,
        tracking_figure,
    )

    sc, traj = run.sc, run.traj

    def save(fig: Any, key: str, suffix: str) -> None:
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=100, bbox_inches="tight")
        plt.close(fig)
        run.write(key, suffix, buf.getvalue())

    save(tracking_figure(traj, sc.robot, obstacles=sc.obstacles, title=sc.name),
         "figure", ".png")
    save(plot_motion(sc.robot, traj, obstacles=sc.obstacles,
                     title=f"{sc.name}: motion").figure, "motion", "_motion.png")
    save(plot_joint_trajectories(traj, robot=sc.robot).figure, "joints", "_joints.png")
    save(plot_tracking_error(traj).figure, "error", "_error.png")
    if traj.clearance.size:
        save(plot_clearance(traj).figure, "clearance", "_clearance.png")


def _write_animation(run: _Outputs, *, fps: float, max_frames: int, mp4: bool,
                     progress: bool) -> None:
    """The GIF animation, and the MP4 with ``mp4`` when ffmpeg is present (else a note)."""
    from serialkin.viz.animate import AnimationOptions, animate_trajectory, ffmpeg_available

    sc = run.sc
    formats = ["gif"] + (["mp4"] if mp4 else [])
    if mp4 and not ffmpeg_available():
        click.echo("note: --mp4 skipped, ffmpeg is not installed", err=True)
        formats = ["gif"]
    for f in formats:
        options = AnimationOptions(fps=fps, max_frames=max_frames, title=sc.name,
                                   progress=progress)
        data = animate_trajectory(sc.robot, run.traj, options, fmt=f, obstacles=sc.obstacles)
        run.write(f, f".{f}", data)


def _write_viewer(run: _Outputs) -> None:
    """The interactive viewer page of the trajectory; CLIError when it cannot be written."""
    from serialkin.viz.viewer import Scene, write_viewer

    sc, traj = run.sc, run.traj
    p = run.folder / f"{run.stem}.html"
    try:
        write_viewer(Scene(sc.robot, trajectory=traj.q, path_points=traj.targets[:, :3, 3],
                           obstacles=sc.obstacles, title=sc.name), p)
    except OSError as exc:
        raise CLIError(f"cannot write {p} ({exc.strerror or exc})") from exc
    run.files["viewer"] = str(p)


def _with_solver(sc: Any, solver: str, max_joint_step: float | None) -> Any:
    """The scenario with --solver and --max-joint-step applied."""
    from dataclasses import replace

    from serialkin.diffik.resolver import QPResolver

    if solver == "qp" and not isinstance(sc.solver, QPResolver):
        sc = replace(sc, solver=QPResolver(task=sc.path.task, obstacles=sc.obstacles,
                                           link_radius=sc.link_radius), options={})
    if max_joint_step is not None:
        if isinstance(sc.solver, QPResolver):
            sc = replace(sc, solver=sc.solver.with_options(max_joint_step=max_joint_step))
        sc = replace(sc, options={**sc.options, "max_joint_step": max_joint_step})
    return sc


def _with_self_collision(sc: Any, self_collision: bool, acm: Any) -> Any:
    """The scenario with --self-collision and the allowed pairs of --srdf (``acm``) applied.

    Raises:
        CLIError: --self-collision or --srdf when the solver is not the QP (the only one
            that checks self-collision), --srdf when the QP checks none.
    """
    from dataclasses import replace

    from serialkin.diffik.resolver import QPResolver

    qp = isinstance(sc.solver, QPResolver)
    if self_collision:
        if not qp:
            raise CLIError(f"--self-collision needs the QP solver, the one that checks it: "
                           f"add --solver qp (the scenario's solver is {_solver_name(sc)})")
        sc = replace(sc, solver=sc.solver.with_options(self_collision=True))
    if acm is not None:
        if not (qp and sc.solver.self_collision):
            raise CLIError("--srdf lists the pairs a self-collision check skips: add "
                           "--self-collision" + ("" if qp else " and --solver qp"))
        # the command line's --srdf replaces the scenario's srdf / skip_links
        kept = {k: v for k, v in sc.options.items() if k not in ("srdf", "skip_links")}
        sc = replace(sc, options={**kept, "acm": acm})
    return sc


def _solver_name(sc: Any) -> str:
    """The scenario's solver as a scenario file names it ('dls', 'multitask', ...)."""
    from serialkin.redundancy.multitask import MultiTaskResolver

    if isinstance(sc.solver, MultiTaskResolver):
        return "'multitask'"
    return repr(sc.solver) if isinstance(sc.solver, str) else type(sc.solver).__name__


def _summary(sc: Any, traj: Any, files: dict[str, str]) -> dict[str, Any]:
    return {
        "scenario": sc.name,
        "robot": {"name": sc.robot.name, "n": sc.robot.n,
                  "joint_types": "".join(sc.robot.joint_types)},
        "success": bool(traj.complete),
        "path_points": int(traj.path_length),
        "computed": len(traj),
        "reached": int(np.sum(traj.reached)),
        "tolerance": traj.tolerance,
        "failed_points": [f.index for f in traj.failures],
        "max_error": traj.max_error,
        "max_position_error_m": float(traj.position_errors.max()) if len(traj) else None,
        "max_orientation_error_rad": (float(traj.orientation_errors.max())
                                      if len(traj) and traj.orientation_errors is not None
                                      else None),
        "min_clearance": traj.min_clearance,
        "min_limit_margin": traj.min_limit_margin,
        "solver": traj.solver,
        "stopped": traj.stopped,
        "failures": [{"index": f.index, "error": f.error, "target": list(f.target)}
                     for f in traj.failures],
        "jumps": [{"index": j.index, "joint": j.joint, "size": j.size} for j in traj.jumps],
        "files": dict(files),
    }
