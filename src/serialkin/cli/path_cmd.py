"""``serialkin path``: a scenario's pose path as a branch-consistent, timed joint trajectory."""

from __future__ import annotations

import io
import math
from pathlib import Path

import click

from serialkin.cli.commands import check_out_folder, handle_errors, json_option, quiet_option
from serialkin.cli.io import (
    EXIT_NOT_REACHED,
    CLIError,
    command_help,
    dumps_json,
    ensure_dir,
    write_bytes_atomic,
    write_text_atomic,
)
from serialkin.errors import InputError

_HELP = command_help(
    "Follow the pose path of a scenario file with one joint configuration per sample, "
    "without branch flips or 2π jumps, and time it under joint limits.\n\n"
    "SCENARIO is a scenario file (.yaml/.json) whose path is a 'line', 'arc' or "
    "'waypoints' of poses (or a shipped scenario's name). The configuration of each sample "
    "is chosen over all IK solutions by dynamic programming (least joint motion, no step "
    "above --max-joint-step). Writes <name>_joints.csv (the joint path with its pose "
    "errors), <name>_path.json (the summary) and, with --timing or any joint-rate "
    "limit, the time-optimal trajectory <name>_trajectory.csv and .json (t, q, q̇, q̈; "
    "toppra, the 'paths' extra) and <name>_timing.png; with --jerk the jerk-limited one "
    "(ruckig). A velocity or acceleration limit not given is the robot's own (a URDF's "
    "<limit velocity>, the zoo's data sheets); URDF has no acceleration limits. Every "
    "angle option says its unit: "
    "--max-joint-step in radians or --max-joint-step-deg in degrees, and so on. Exit 1 "
    "when the path cannot be followed (stderr says at which sample and why; the files "
    "hold the path up to there).",
    ["serialkin path weld.yaml --max-joint-step-deg 10",
     "serialkin path weld.yaml --velocity-deg 90 --acceleration-deg 180 "
     "--cartesian-speed 0.1",
     "serialkin path panda_seam.yaml --timing --jerk 500"],
)


def _angle(rad: float | None, deg: float | None, name: str) -> float | None:
    """An angle option given in radians or in degrees (not both), in radians."""
    if rad is not None and deg is not None:
        raise CLIError(f"--{name} and --{name}-deg are both given; use one (radians or "
                       "degrees)")
    value = math.radians(deg) if deg is not None else rad
    if value is not None and not (value > 0.0 and math.isfinite(value)):
        raise CLIError(f"--{name}{'-deg' if deg is not None else ''} must be a positive "
                       f"number, got {deg if deg is not None else rad!r}")
    return value


@click.command("path", help=_HELP, short_help="A pose path as a timed joint trajectory.")
@click.argument("scenario")
@click.option("--out", "-o", "out", type=click.Path(file_okay=False), default="out/path",
              show_default=True, help="Output folder.")
@click.option("--max-joint-step", type=float, default=None,
              help="Largest joint change between samples [rad] (default 0.5 rad).")
@click.option("--max-joint-step-deg", type=float, default=None,
              help="The same in degrees.")
@click.option("--velocity", type=float, default=None, help="Joint speed limit [rad/s].")
@click.option("--velocity-deg", type=float, default=None, help="Joint speed limit [deg/s].")
@click.option("--acceleration", type=float, default=None,
              help="Joint acceleration limit [rad/s²].")
@click.option("--acceleration-deg", type=float, default=None,
              help="Joint acceleration limit [deg/s²].")
@click.option("--jerk", type=float, default=None,
              help="Joint jerk limit [rad/s³]: a jerk-limited timing (ruckig).")
@click.option("--jerk-deg", type=float, default=None, help="Joint jerk limit [deg/s³].")
@click.option("--timing", is_flag=True,
              help="Time the path with the robot's own joint limits where none is given.")
@click.option("--cartesian-speed", type=float, default=None,
              help="Largest tool speed [m/s] (with the joint limits).")
@click.option("--dt", type=float, default=0.01, show_default=True,
              help="Time step of the written trajectory [s].")
@click.option("--no-figures", is_flag=True, help="Do not draw the timing figure.")
@json_option
@quiet_option
@handle_errors
def path_cmd(scenario: str, out: str, max_joint_step: float | None,
             max_joint_step_deg: float | None, velocity: float | None,
             velocity_deg: float | None, acceleration: float | None,
             acceleration_deg: float | None, jerk: float | None, jerk_deg: float | None,
             timing: bool, cartesian_speed: float | None, dt: float,
             no_figures: bool, as_json: bool, quiet: bool) -> None:
    """Follow a scenario's pose path: joint path, timing, figure, summary."""
    from serialkin.paths import jerk_limited, joint_path, time_optimal
    from serialkin.tracking import load_scenario

    step = _angle(max_joint_step, max_joint_step_deg, "max-joint-step") or 0.5
    v = _angle(velocity, velocity_deg, "velocity")
    a = _angle(acceleration, acceleration_deg, "acceleration")
    j = _angle(jerk, jerk_deg, "jerk")
    timed_too = timing or v is not None or a is not None or j is not None
    if cartesian_speed is not None and not timed_too:
        raise CLIError("--cartesian-speed needs a timing: --timing (the robot's limits) or "
                       "--velocity and --acceleration")
    if cartesian_speed is not None and j is not None:
        raise CLIError("--cartesian-speed and --jerk cannot go together: the jerk-limited "
                       "timing (ruckig) has no Cartesian speed limit")
    if not (dt > 0.0 and math.isfinite(dt)):
        raise CLIError(f"--dt must be a positive time step in seconds, got {dt!r}")
    check_out_folder(out)
    sc = load_scenario(scenario)
    if sc.path.task != "pose":
        raise CLIError(f"scenario {sc.name!r} has a {sc.path.task!r} path; 'serialkin path' "
                       "follows pose paths (path type 'line', 'arc' or 'waypoints')")
    robot = sc.robot
    jp = joint_path(robot, sc.path, q0=sc.q0, max_joint_step=step)
    folder = ensure_dir(out)
    stem = Path(scenario).stem if Path(scenario).suffix else scenario
    files = {"joints": str(_write_joints(folder / f"{stem}_joints.csv", robot, jp))}
    summary = {"scenario": sc.name, "robot": robot.name, "samples": len(sc.path),
               "success": jp.success, "followed": len(jp), "failed_at": jp.failed_at,
               "reason": jp.reason, "method": jp.method,
               "max_joint_step_rad": jp.max_joint_step,
               "largest_step_rad": jp.largest_step,
               "max_position_error_m": float(jp.position_error.max()) if len(jp) else None,
               "max_orientation_error_rad": (float(jp.orientation_error.max()) if len(jp)
                                             else None)}
    if timed_too and jp.success:
        try:
            timed = (jerk_limited(jp.q, j, v, a, robot=robot, dt=dt) if j is not None else
                     time_optimal(jp.q, v, a, robot=robot, cartesian_speed=cartesian_speed,
                                  dt=dt))
        except InputError as exc:
            raise CLIError(f"{exc} (options --velocity, --acceleration, in rad or with "
                           "-deg)") from None
        files["trajectory_csv"] = str(timed.to_csv(folder / f"{stem}_trajectory.csv"))
        files["trajectory_json"] = str(timed.to_json(folder / f"{stem}_trajectory.json"))
        summary["duration_s"] = timed.duration
        summary["timing"] = timed.method
        if not no_figures:
            files["figure"] = str(_figure(folder / f"{stem}_timing.png", timed, robot))
    summary["files"] = files
    files["summary"] = str(write_text_atomic(folder / f"{stem}_path.json",
                                             dumps_json(summary)))
    if as_json:
        click.echo(dumps_json(summary), nl=False)
    elif not quiet:
        state = (f"followed all {len(jp)} samples" if jp.success else
                 f"followed {len(jp)} of {len(sc.path)} samples")
        click.echo(f"{sc.name}: {state} ({jp.method}); largest joint step "
                   f"{math.degrees(jp.largest_step):.3g} deg (bound "
                   f"{math.degrees(jp.max_joint_step):.3g} deg)")
        if len(jp):
            click.echo(f"pose error: max {jp.position_error.max() * 1e3:.3g} mm, "
                       f"{math.degrees(jp.orientation_error.max()):.3g} deg")
        if "duration_s" in summary:
            kind = "jerk-limited" if timed.method == "ruckig" else "time-optimal"
            click.echo(f"{kind} duration {summary['duration_s']:.4g} s")
        for f in files.values():
            click.echo(f"  wrote {f}")
    if not jp.success:
        click.echo(f"cannot follow the path: {jp.reason}", err=True)
        raise SystemExit(EXIT_NOT_REACHED)


def _write_joints(path: Path, robot, jp) -> Path:
    """The joint path as CSV: sample, q [rad or m], position error [m], orientation error [rad]."""
    names = list(robot.joint_names)
    head = ["sample"] + [f"{n} [rad]" if r else f"{n} [m]" for n, r in
                         zip(names, robot.revolute)] + ["position_error [m]",
                                                       "orientation_error [rad]"]
    rows = [",".join([str(i)] + [repr(float(x)) for x in q]
                     + [repr(float(jp.position_error[i])), repr(float(jp.orientation_error[i]))])
            for i, q in enumerate(jp.q)]
    return write_text_atomic(path, "\n".join([",".join(head), *rows]) + "\n")


def _figure(path: Path, timed, robot) -> Path:
    """The timing figure (positions, velocities, accelerations against limits) as PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from serialkin.paths.plot import plot_timing

    fig = plot_timing(timed, robot.qlim)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    return write_bytes_atomic(path, buf.getvalue())


__all__ = ["path_cmd"]
