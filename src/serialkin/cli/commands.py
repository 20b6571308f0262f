"""The ``models``, ``fk``, ``jacobian`` and ``ik`` subcommands.

Conventions of the command line: lengths in metres; angles in radians unless
``--degrees`` is given (then joint angles, rpy and φ are read and shown in degrees);
JSON output (``--json`` or ``--out *.json``) is always in SI units (m, rad) and strict
JSON (no NaN/inf). Exit codes: 0 success, 1 an IK target not reached, 2 bad input.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click
import numpy as np

from serialkin._checks import beyond_a_turn, short_repr
from serialkin.cli.io import (
    EXIT_NOT_REACHED,
    CLIError,
    command_help,
    dumps_json,
    format_matrix,
    format_table,
    parse_numbers,
    read_csv_rows,
    write_output,
)
from serialkin.cli.robots import ROBOT_HELP, param_option, resolve_robot, robot_argument
from serialkin.errors import SerialkinError
from serialkin.model.tasks import TASK_COORDINATES, TASK_NAMES, get_task

#: Longest error message printed [characters]: a message is one line, cut beyond this.
MAX_ERROR_CHARS = 2000


def one_line(message: str) -> str:
    """``message`` on one line, at most :data:`MAX_ERROR_CHARS` characters.

    Line breaks, tabs and runs of spaces become one space.
    """
    text = " ".join(str(message).split())
    if len(text) > MAX_ERROR_CHARS:
        text = text[: MAX_ERROR_CHARS - 3] + "..."
    return text


def cli_error(exc: BaseException) -> CLIError:
    """The one-line ``Error: ...`` (exit 2) for an exception raised under a subcommand.

    Library errors (:class:`~serialkin.errors.SerialkinError`) keep their message; OS
    errors name the file and the reason (a full disk, a read-only folder...); running out
    of memory or recursion depth, and any other exception, are described in one line.
    """
    if isinstance(exc, CLIError):
        return CLIError(one_line(exc.message))
    if isinstance(exc, SerialkinError):
        return CLIError(one_line(str(exc)))
    if isinstance(exc, PermissionError):
        return CLIError(one_line(f"permission denied: {exc.filename or exc}"))
    if isinstance(exc, OSError):
        where = f"{exc.filename}: " if exc.filename else ""
        return CLIError(one_line(f"{where}{exc.strerror or exc}"))
    if isinstance(exc, MemoryError):
        return CLIError("out of memory; reduce the sizes asked for (samples, cells, path "
                        "points) or the memory budget (--memory-budget, "
                        "SERIALKIN_MEMORY_BUDGET)")
    if isinstance(exc, RecursionError):
        return CLIError("the input is nested too deeply")
    return CLIError(one_line(f"unexpected {type(exc).__name__}: {exc}"))


#: Exceptions that pass through :func:`handle_errors` unchanged: click's own exits and
#: usage errors, a closed output pipe, Ctrl-C, sys.exit.
PASS_THROUGH = (click.exceptions.Exit, click.exceptions.Abort, click.UsageError,
                BrokenPipeError, KeyboardInterrupt, SystemExit, GeneratorExit)


def handle_errors(fn: Callable[..., Any]) -> Callable[..., Any]:
    """Turn every error under a subcommand into one clear ``Error:`` line (exit 2).

    See :func:`cli_error`; click's usage errors, exits and a broken pipe pass through.
    """

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            refuse_output_over_input(kwargs)
            return fn(*args, **kwargs)
        except PASS_THROUGH:
            raise
        except click.ClickException as exc:
            if isinstance(exc, CLIError):
                raise cli_error(exc) from exc
            raise CLIError(one_line(exc.format_message())) from exc
        except Exception as exc:
            raise cli_error(exc) from exc

    return wrapper


#: The options of the subcommands that name files or folders they write.
OUTPUT_OPTIONS = {"out": "--out", "report": "--report", "save": "--save", "urdf": "--urdf"}


def _paths(value: Any) -> list[str]:
    """The strings of an option value (one, or several for a repeatable option)."""
    if isinstance(value, str):
        return [value]
    if isinstance(value, list | tuple):
        return [v for v in value if isinstance(v, str)]
    return []


def _same(a: str, b: str) -> bool:
    """Whether paths ``a`` and ``b`` name one file (links followed; b exists)."""
    try:
        return os.path.samefile(a, b)
    except (OSError, ValueError):
        return False


def refuse_output_over_input(params: dict[str, Any]) -> None:
    """Refuse, before any work, an output option that names a file the command reads.

    Every other option or argument that names an existing file is an input; an output
    (:data:`OUTPUT_OPTIONS`) naming the same file (also through a link or another
    spelling) would overwrite it: CLIError naming both.
    """
    for key, flag in OUTPUT_OPTIONS.items():
        for out in _paths(params.get(key)):
            if not os.path.lexists(out):
                continue
            for name, value in params.items():
                if name in OUTPUT_OPTIONS:
                    continue
                for path in _paths(value):
                    if path and os.path.isfile(path) and _same(out, path):
                        raise CLIError(
                            f"{flag} {short_repr(out, 120)} is the file read as "
                            f"{name.replace('_', '-')} ({short_repr(path, 120)}): writing "
                            "would destroy the input; choose another output path")


def one_shot(fn: Callable[..., Any]) -> Callable[..., Any]:
    """A one-shot command (fk, jacobian, ik): its small kernel calls run as Python.

    Loading the first compiled kernels costs a process about half a second, more than a
    few calls take as Python (:func:`serialkin._background.answer_first`); a command
    with many rows loads them once its Python time passes that.
    """

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        from serialkin._background import answer_first

        with answer_first():
            return fn(*args, **kwargs)

    return wrapper


def check_out_folder(folder: str | os.PathLike[str]) -> Path:
    """Check that ``folder`` is a writable folder or can be created, creating nothing.

    :func:`~serialkin.cli.io.ensure_dir` creates it later, just before the first file is
    written, so a run refused by a later check leaves nothing behind. Returns ``folder``.

    Raises:
        CLIError: ``folder`` (or a parent) is a file, or the nearest existing parent is
            not a writable folder.
    """
    d = Path(folder) if str(folder) else Path(".")
    probe = d
    while not probe.exists():
        if probe.parent == probe:
            break
        probe = probe.parent
    if probe.exists() and not probe.is_dir():
        raise CLIError(f"output folder {d} exists and is not a folder" if probe == d else
                       f"cannot create output folder {d}: {probe} is a file")
    if probe.exists() and not os.access(probe, os.W_OK | os.X_OK):
        raise CLIError(f"output folder {d} is not writable" if probe == d else
                       f"cannot create output folder {d}: {probe} is not writable")
    return d


def set_budget(ctx: click.Context, param: click.Parameter, value: str | None) -> None:
    """Callback of ``--memory-budget``: set (or, when absent, reset) the process budget."""
    from serialkin._budget import set_memory_budget
    from serialkin.errors import InputError

    if value is None and ctx.parent is not None:
        return  # a subcommand without the option keeps what the group set
    try:
        set_memory_budget(value)
    except InputError as exc:
        raise CLIError(f"--memory-budget: {exc}") from None


#: ``--memory-budget SIZE`` on a subcommand (the group has it too): see :mod:`serialkin._budget`.
memory_budget_option = click.option(
    "--memory-budget", metavar="SIZE", expose_value=False, callback=set_budget,
    help="Largest memory this run may plan to allocate, e.g. 8G, 500M or unlimited "
         "(default: half the available memory, or $SERIALKIN_MEMORY_BUDGET).")

json_option = click.option("--json", "as_json", is_flag=True,
                           help="Print the results as JSON (SI units) instead of a table.")
_QUIET_HELP = "Print nothing but errors (and JSON with --json); no progress bar."
quiet_option = click.option("--quiet", "-q", is_flag=True, help=_QUIET_HELP)
#: For commands with a --q option, where a short -q would be confusing.
quiet_long_option = click.option("--quiet", is_flag=True, help=_QUIET_HELP)
degrees_option = click.option("--degrees", "-d", is_flag=True,
                              help="Joint angles, rpy and φ in degrees (input and table); "
                                   "without it they are radians, and a value beyond a full "
                                   "turn is refused as a likely slip.")
out_option = click.option("--out", "-o", "out", type=click.Path(dir_okay=False),
                          help="Also write the results to this file (.json or .csv), "
                               "atomically.")


def q_options(fn: Callable[..., Any]) -> Callable[..., Any]:
    """The ``--q`` (repeatable) and ``--q-file`` options, read by :func:`read_q`."""
    fn = click.option("--q-file", type=click.Path(dir_okay=False),
                      help="CSV file with one configuration per row (n columns; '-' = "
                           "stdin).")(fn)
    return click.option("--q", "q_texts", multiple=True, metavar="Q1,Q2,...",
                        help="Joint values (repeatable for several configurations). "
                             "Default: zeros.")(fn)


def _angle_factor(robot: Any, degrees: bool) -> np.ndarray:
    """Per-joint factor from the user's unit to SI: π/180 for revolute joints with --degrees."""
    f = np.ones(robot.n)
    if degrees:
        f[robot.revolute] = np.pi / 180.0
    return f


def refuse_joint_turns(robot: Any, Q: np.ndarray, option: str) -> None:
    """Refuse joint values read as radians that only make sense as degrees.

    A revolute value beyond a full turn and outside the joint's limits is almost surely
    in degrees: CLIError naming ``option``, the joint and the value, with the hint
    ``--degrees``.
    """
    Q = np.asarray(Q, dtype=float).reshape(-1, robot.n)
    lo, hi = robot.qlim[:, 0], robot.qlim[:, 1]
    wild = robot.revolute & beyond_a_turn(Q) & ((Q < lo) | (Q > hi))
    if wild.any():
        i, j = np.argwhere(wild)[0]
        raise CLIError(f"{option}: joint {j + 1} = {Q[i, j]:g} rad is beyond a full turn and "
                       f"its limits [{lo[j]:g}, {hi[j]:g}]; values are radians (for "
                       "degrees add --degrees)")


def refuse_angle_turns(values: Any, option: str, what: str = "angle", *,
                       hint: str = "add --degrees") -> None:
    """Refuse fixed angles (rpy, φ, a yaw) read as radians beyond a full turn (2π).

    Such a value is almost surely in degrees: CLIError naming ``option``, what it is and
    the value, ending with ``hint`` (how to give degrees).
    """
    v = np.asarray(values, dtype=float)
    wild = beyond_a_turn(v)
    if wild.any():
        raise CLIError(f"{option}: {what} {v[wild].flat[0]:g} rad is beyond a full turn (2π); "
                       f"it is read in radians (are these degrees? {hint})")


def read_q(robot: Any, q_texts: tuple[str, ...], q_file: str | None, degrees: bool) -> np.ndarray:
    """Configurations (N, n) [SI] from ``--q`` options and/or a CSV file (zeros if neither)."""
    rows = [parse_numbers(t, "--q", robot.n) for t in q_texts]
    Q = np.array(rows).reshape(-1, robot.n)
    if q_file:
        Q = np.vstack([Q, read_csv_rows(q_file, "q", robot.n)])
    if Q.shape[0] == 0:
        Q = np.zeros((1, robot.n))
    if not degrees:  # radians are read: a value beyond a turn and the limits is a slip
        refuse_joint_turns(robot, Q, "--q")
    return Q * _angle_factor(robot, degrees)


def fmt_vector(v: np.ndarray, decimals: int = 6) -> str:
    """A vector as ``[a, b, c]`` with fixed decimals (no wrapping, no scientific notation)."""
    return "[" + ", ".join(f"{0.0 if abs(x) < 0.5 * 10**-decimals else x:.{decimals}f}"
                           for x in np.asarray(v, dtype=float)) + "]"


def _robot_info(robot: Any) -> dict[str, Any]:
    return {"name": robot.name, "n": robot.n, "joint_types": "".join(robot.joint_types),
            "joint_names": list(robot.joint_names), "convention": robot.convention,
            "source": robot.source}


def _emit(text: str, quiet: bool) -> None:
    if not quiet:
        click.echo(text)


def _emit_results(data: dict[str, Any], out: str | None,
                  csv: Callable[[], tuple[list[str], np.ndarray]], as_json: bool,
                  quiet: bool) -> bool:
    """Write ``data`` to ``--out`` and print it as JSON with ``--json``.

    ``csv()`` gives the (header, rows) of a ``.csv`` output file; it is called only
    with ``--out``. Says ``wrote <path>`` unless ``--json`` or ``--quiet``.

    Returns:
        True when nothing more goes to standard output (``--json`` or ``--quiet``).
    """
    if out:
        path = write_output(out, data, csv())
        if not as_json:
            _emit(f"wrote {path}", quiet)
    if as_json:
        click.echo(dumps_json(data), nl=False)
    return as_json or quiet


def _exit_if_unreached(recs: list[dict[str, Any]], why: Callable[[dict[str, Any]], str]
                       ) -> None:
    """One stderr line ``target k not reached: why(rec)`` per failed record; exit code 1."""
    for rec in recs:
        if not rec["success"]:
            click.echo(f"target {rec['index']} not reached: {why(rec)}", err=True)
    if not all(rec["success"] for rec in recs):
        raise SystemExit(EXIT_NOT_REACHED)


# ---------------------------------------------------------------------------- models
_MODELS_CMD_HELP = command_help(
    "List the built-in robot models: DOF, joint types, convention and source.\n\n"
    "With ROBOT (a model name, robot file or URDF), show that robot: its DH table or joint "
    "axes, limits, base and tool; --save writes it as a robot file (.yaml/.yml/.json, DH "
    "robots) or a URDF (.urdf), e.g. to start your own robot from a built-in one.",
    ["serialkin models", "serialkin models --json", "serialkin models puma560",
     "serialkin models ur5 --save my_ur5.yaml", "serialkin models panda --save panda.urdf"],
)


def _frames_record(name: str) -> dict[str, Any] | None:
    """The documented base/flange frames of zoo model ``name`` (None for other robots)."""
    from serialkin.models.frames import FRAMES, VENDOR_SUFFIX

    f = FRAMES.get(name.removesuffix(VENDOR_SUFFIX))
    if f is None:
        return None
    rec: dict[str, Any] = {"base": f.base, "flange": f.flange}
    if f.vendor is not None:
        v = f.vendor
        rec["vendor"] = {"description": v.description, "base_link": v.base_link,
                         "tip_link": v.tip_link, "T_vbase_base": v.T_vbase_base,
                         "T_flange_vtip": v.T_flange_vtip, "note": v.note,
                         "variant": name.removesuffix(VENDOR_SUFFIX) + VENDOR_SUFFIX
                         if f.variant else None}
    else:
        rec["vendor"] = None
        rec["no_vendor"] = f.no_vendor
    return rec


def _show_frames(rec: dict[str, Any], indent: str = "") -> None:
    click.echo(f"{indent}base frame: {rec['base']}")
    click.echo(f"{indent}flange frame: {rec['flange']}")
    v = rec["vendor"]
    if v is None:
        click.echo(f"{indent}vendor frames: none ({rec['no_vendor']})")
        return
    click.echo(f"{indent}vendor frames ({v['description']}): {v['base_link']} -> "
               f"{v['tip_link']} = T_vbase_base . fk(q) . T_flange_vtip; {v['note']}"
               + (f"; in these frames: {v['variant']}" if v["variant"] else ""))


def _robot_detail(r: Any, spec: str = "") -> dict[str, Any]:
    info = _robot_info(r)
    info["qlim"] = r.qlim
    info["base"] = r.base
    info["tool"] = r.tool
    frames = _frames_record(_zoo_name(spec)) if spec else None
    if frames is not None:
        info["frames"] = frames
    if r.dh is not None:
        info["dh"] = [{"a": d.a, "alpha": d.alpha, "d": d.d, "theta": d.theta, "type": d.type,
                       "qlim": list(d.qlim), "name": d.name} for d in r.dh]
    else:
        info["joints"] = [{"name": j.name, "type": j.type, "axis": j.axis, "origin": j.origin,
                           "offset": j.offset, "qlim": list(j.qlim)} for j in r.joints]
    return info


def _zoo_name(spec: str) -> str:
    """The catalog name of a ROBOT argument naming a zoo model ('' for a file)."""
    from pathlib import Path

    from serialkin.models import canonical_name

    return "" if Path(spec).suffix else (canonical_name(spec) or "")


def _show_robot(r: Any, spec: str = "") -> None:
    click.echo(f"{r.name}: {r.n} joints {''.join(r.joint_types)}"
               + (f", {r.convention} DH" if r.convention else ""))
    if r.source:
        click.echo(f"source: {r.source}")
    frames = _frames_record(_zoo_name(spec)) if spec else None
    if frames is not None:
        _show_frames(frames)

    def lim(lo: float, hi: float, revolute: bool) -> str:
        if not (np.isfinite(lo) and np.isfinite(hi)):
            return "unlimited"
        return (f"[{np.degrees(lo):.1f}, {np.degrees(hi):.1f}] deg" if revolute
                else f"[{lo:.4g}, {hi:.4g}] m")

    if r.dh is not None:
        rows = [(d.name, d.type, d.a, np.degrees(d.alpha), d.d, np.degrees(d.theta),
                 lim(*d.qlim, rev)) for d, rev in zip(r.dh, r.revolute)]
        click.echo(format_table(rows, ["joint", "type", "a [m]", "alpha [deg]", "d [m]",
                                       "theta [deg]", "limits"]))
    else:
        rows = [(j.name, j.type, fmt_vector(j.axis, 3), fmt_vector(j.origin[:3, 3], 4),
                 lim(*j.qlim, rev)) for j, rev in zip(r.joints, r.revolute)]
        click.echo(format_table(rows, ["joint", "type", "axis", "origin xyz [m]", "limits"]))
    for key in ("base", "tool"):
        T = getattr(r, key)
        if not np.allclose(T, np.eye(4)):
            click.echo(f"{key}:")
            click.echo(format_matrix(T))


@click.command("models", help=_MODELS_CMD_HELP,
               short_help="List the built-in robots: DOF, joint types, source.")
@click.argument("robot", metavar="[ROBOT]", required=False)
@click.option("--save", "save", type=click.Path(dir_okay=False), default=None,
              help="Write ROBOT to a robot file (.yaml/.yml/.json) or URDF (.urdf).")
@click.option("--angle-unit", type=click.Choice(["deg", "rad"]), default="deg",
              show_default=True, help="Angle unit of a saved robot file.")
@click.option("--length-unit", type=click.Choice(["m", "cm", "mm"]), default="m",
              show_default=True, help="Length unit of a saved robot file.")
@param_option
@json_option
@memory_budget_option
@handle_errors
def models_cmd(robot: str | None, save: str | None, angle_unit: str, length_unit: str,
               params: tuple[str, ...], as_json: bool) -> None:
    """List the built-in robot models, or show / save one robot."""
    from serialkin import models

    if robot is not None:
        r = resolve_robot(robot, params)
        if save:
            from pathlib import Path

            from serialkin.cli.io import ensure_dir, write_text_atomic

            p = Path(save)
            ensure_dir(p.parent)
            if p.suffix.lower() == ".urdf":
                write_text_atomic(p, r.to_urdf())
            else:
                from serialkin.formats.robotfile import ROBOT_FILE_SUFFIXES, save_robot_file

                if p.suffix.lower() not in ROBOT_FILE_SUFFIXES:
                    raise CLIError(f"--save {p}: use .yaml, .yml, .json or .urdf")
                save_robot_file(r, p, angle_unit=angle_unit, length_unit=length_unit)
            if not as_json:
                click.echo(f"wrote {p}")
        if as_json:
            click.echo(dumps_json(_robot_detail(r, robot)), nl=False)
        elif not save:
            _show_robot(r, robot)
        return
    if save:
        raise CLIError("--save needs ROBOT, e.g. serialkin models ur5 --save ur5.yaml")
    entries = []
    for info in models.catalog():
        built = info.build() if info.dof is not None else None
        entries.append({
            "name": info.name,
            "dof": built.n if built else None,
            "joint_types": "".join(built.joint_types) if built else "R…",
            "convention": info.convention,
            "summary": info.summary,
            "source": built.source if built else "planar<N>: N unit links (or --param "
                                                 "lengths=[...])",
            "frames": _frames_record(info.name),
        })
    if as_json:
        click.echo(dumps_json({"models": entries}), nl=False)
        return
    rows = [(e["name"], e["dof"] if e["dof"] is not None else "any", e["joint_types"],
             e["convention"], e["summary"]) for e in entries]
    click.echo(format_table(rows, ["name", "DOF", "joints", "DH", "description"]))
    click.echo("\nSources:")
    for e in entries:
        click.echo(f"  {e['name']}: {e['source']}")
    click.echo("\nFrames (fk(q) is the flange frame in the base frame):")
    for e in entries:
        click.echo(f"  {e['name']}:")
        _show_frames(e["frames"], indent="    ")
    click.echo(f"\nIn the vendor's frames: {', '.join(models.vendor_variants())} "
               "(e.g. serialkin fk ur5_vendor). Also: planar<N> (e.g. planar6), a robot file "
               "(.yaml/.json) or a URDF. Details of one: serialkin models <name>.")


# ---------------------------------------------------------------------------- fk
def _fk_records(robot: Any, Q: np.ndarray, frames: bool) -> list[dict[str, Any]]:
    """One record per row of ``Q`` (m, n), from one batched FK call (and one fk_all)."""
    from serialkin.spatial import matrix_to_rpy

    T = robot.fk(Q)
    rpy = matrix_to_rpy(T[:, :3, :3], check=False)
    F = robot.fk_all(Q) if frames else None
    recs: list[dict[str, Any]] = []
    for k, q in enumerate(Q):
        rec: dict[str, Any] = {"q": q, "T": T[k], "position": T[k, :3, 3], "rpy": rpy[k]}
        if F is not None:
            rec["frames"] = F[k]
        recs.append(rec)
    return recs


_FK_CMD_HELP = command_help(
    "Forward kinematics: the tool pose T = base·A1(q1)···An(qn)·tool (eqs 10-11).\n\n"
    "ROBOT is " + ROBOT_HELP + ".",
    ['serialkin fk puma560 --q "0, 0.5, -0.3, 0, 0.2, 0"',
     'serialkin fk two_link --q "30,45" --degrees --json',
     "serialkin fk examples/robots/two_link.yaml --q-file q.csv --out poses.csv"],
)


@click.command("fk", help=_FK_CMD_HELP,
               short_help="Forward kinematics: the tool pose for q.")
@robot_argument
@q_options
@click.option("--frames", is_flag=True, help="Also give every link frame 0..n (eq 11).")
@degrees_option
@param_option
@json_option
@out_option
@quiet_long_option
@memory_budget_option
@handle_errors
@one_shot
def fk_cmd(robot: str, q_texts: tuple[str, ...], q_file: str | None, frames: bool,
           degrees: bool, params: tuple[str, ...], as_json: bool, out: str | None,
           quiet: bool) -> None:
    """Forward kinematics: the tool pose T = base·A1(q1)···An(qn)·tool (eqs 10-11)."""
    r = resolve_robot(robot, params)
    Q = read_q(r, q_texts, q_file, degrees)
    recs = _fk_records(r, Q, frames)
    data = {"robot": _robot_info(r), "units": {"length": "m", "angle": "rad"},
            "results": recs}

    def csv() -> tuple[list[str], np.ndarray]:
        header = ([f"q{i + 1}" for i in range(r.n)] + ["x", "y", "z", "roll", "pitch", "yaw"]
                  + [f"T{i}{j}" for i in range(3) for j in range(4)])
        rows = np.array([np.concatenate([rec["q"], rec["position"], rec["rpy"],
                                         rec["T"][:3].ravel()]) for rec in recs])
        return header, rows

    if _emit_results(data, out, csv, as_json, quiet):
        return
    f = _angle_factor(r, degrees)
    unit = "deg" if degrees else "rad"
    if len(recs) == 1:
        rec = recs[0]
        click.echo(f"{r.name} ({r.n} joints {''.join(r.joint_types)}), "
                   f"q = {fmt_vector(rec['q'] / f)}")
        click.echo("T (world from tool):")
        click.echo(format_matrix(rec["T"]))
        click.echo(f"position [m]: {fmt_vector(rec['position'])}")
        rpy = np.degrees(rec["rpy"]) if degrees else rec["rpy"]
        click.echo(f"rpy [{unit}]: {fmt_vector(rpy)}")
        if frames:
            for k, Fk in enumerate(rec["frames"]):
                click.echo(f"frame {k}:")
                click.echo(format_matrix(Fk))
        return
    rows = []
    for k, rec in enumerate(recs):
        rpy = np.degrees(rec["rpy"]) if degrees else rec["rpy"]
        rows.append([k + 1, *rec["position"], *rpy])
    click.echo(format_table(rows, ["#", "x [m]", "y [m]", "z [m]", f"roll [{unit}]",
                                   f"pitch [{unit}]", f"yaw [{unit}]"]))




# ---------------------------------------------------------------------------- jacobian
_JACOBIAN_CMD_HELP = command_help(
    "Geometric Jacobian J(q) (eqs 33-36), rows [vx, vy, vz, wx, wy, wz].\n\n"
    "Also prints the manipulability sqrt(det(J_t J_tᵀ)) (eq 43) of the task rows "
    "(--task), the condition number and the rank. ROBOT is " + ROBOT_HELP + ".",
    ['serialkin jacobian two_link --q "0.3,0.9"',
     'serialkin jacobian ur5 --q "0,-1.2,1.4,0,0.5,0" --frame ee --json',
     'serialkin jacobian puma560 --link 3 --point "0,0,0.1"'],
)


@click.command("jacobian", help=_JACOBIAN_CMD_HELP,
               short_help="Geometric Jacobian, manipulability, condition number.")
@robot_argument
@q_options
@click.option("--frame", type=click.Choice(["base", "ee"]), default="base", show_default=True,
              help="Express J in the world/base frame or in the tool frame.")
@click.option("--link", type=int, default=None,
              help="Jacobian of a point on link frame k (0..n) instead of the tool.")
@click.option("--point", default=None, metavar="X,Y,Z",
              help="The point on --link, in that link frame [m] (default its origin).")
@click.option("--planar", is_flag=True,
              help="Planar task Jacobian: rows vx, vy, wz (eqs 30-32, 38).")
@click.option("--task", type=click.Choice(["auto", *TASK_NAMES]), default="auto",
              show_default=True,
              help="Task rows for manipulability and condition number (auto: planar/"
                   "planar_pose for planar robots, full with >= 6 joints, else position).")
@degrees_option
@param_option
@json_option
@out_option
@quiet_long_option
@memory_budget_option
@handle_errors
@one_shot
def jacobian_cmd(robot: str, q_texts: tuple[str, ...], q_file: str | None, frame: str,
                 link: int | None, point: str | None, planar: bool, task: str, degrees: bool,
                 params: tuple[str, ...], as_json: bool, out: str | None, quiet: bool) -> None:
    """Geometric Jacobian J(q) (eqs 33-36), rows [vx, vy, vz, wx, wy, wz]."""
    r = resolve_robot(robot, params)
    Q = read_q(r, q_texts, q_file, degrees)
    pt = parse_numbers(point, "--point", 3) if point is not None else None
    if pt is not None and link is None:
        raise CLIError("--point needs --link (the link frame the point is fixed on)")
    from serialkin.workspace.sampling import manipulability_task

    rows_sel = list(get_task("planar_pose" if planar else "pose").rows)
    names = list(TASK_COORDINATES)
    task_name = manipulability_task(r, bool(r.is_planar)) if task == "auto" else task
    task_rows = list(get_task(task_name).rows)
    recs = []
    for q in Q:
        J6 = r.jacobian(q, frame=frame, link=link, point=pt)
        J = J6[rows_sel]
        Jt = J6[task_rows]
        s = np.linalg.svd(Jt, compute_uv=False)
        w = r.manipulability(q, task_name, frame=frame, link=link, point=pt)
        cond = float(s[0] / s[-1]) if s[-1] > 1e-15 * max(s[0], 1e-300) else float("inf")
        rank = int(np.sum(s > 1e-10 * max(s[0], 1e-300)))
        recs.append({"q": q, "J": J, "manipulability": w, "condition_number": cond,
                     "rank": rank, "singular_values": s})
    data = {"robot": _robot_info(r), "frame": frame, "link": link, "point": pt,
            "rows": [names[i] for i in rows_sel], "task": task_name,
            "task_rows": [names[i] for i in task_rows], "results": recs}

    def csv() -> tuple[list[str], np.ndarray]:
        header = [f"q{i + 1}" for i in range(r.n)] + [
            f"J_{names[i]}_{j + 1}" for i in rows_sel for j in range(r.n)
        ] + ["manipulability", "condition_number"]
        table = np.array([np.concatenate([rec["q"], rec["J"].ravel(),
                                          [rec["manipulability"], rec["condition_number"]]])
                          for rec in recs])
        return header, table

    if _emit_results(data, out, csv, as_json, quiet):
        return
    f = _angle_factor(r, degrees)
    for k, rec in enumerate(recs):
        click.echo(f"{r.name}: q = {fmt_vector(rec['q'] / f)}"
                   f"  (J in the {frame} frame"
                   + (f", point on link {link}" if link is not None else "") + ")")
        click.echo(format_table([[names[i], *rec["J"][k2]] for k2, i in enumerate(rows_sel)],
                                ["row"] + [f"q{j + 1}" for j in range(r.n)]))
        click.echo(f"{task_name} task ({', '.join(names[i] for i in task_rows)}): "
                   f"manipulability {rec['manipulability']:.6g}, condition number "
                   f"{rec['condition_number']:.6g}, rank {rec['rank']}")
        if k + 1 < len(recs):
            click.echo("")




# ---------------------------------------------------------------------------- ik
def _target_rows(robot: Any, values: list[np.ndarray], degrees: bool, planar: bool,
                 option: str = "--target") -> list[Any]:
    """Turn rows of numbers into IK targets (see ``serialkin ik --help``).

    Angles (roll, pitch, yaw; a planar φ) are degrees with ``degrees``, else radians, and
    then a value beyond a full turn is refused (CLIError hinting at --degrees).
    """
    from serialkin.spatial import make_transform, rpy_to_matrix

    out: list[Any] = []
    for i, row in enumerate(values):
        k = row.shape[0]
        where = f"{option} {i + 1}" if len(values) > 1 else option
        if k == 16:
            out.append(row.reshape(4, 4))
        elif k == 6:
            if not degrees:
                refuse_angle_turns(row[3:], where, "roll/pitch/yaw")
            rpy = np.radians(row[3:]) if degrees else row[3:]
            out.append(make_transform(rpy_to_matrix(rpy), row[:3]))
        elif k == 3 and planar:
            if not degrees:
                refuse_angle_turns(row[2], where, "φ")
            out.append(np.array([row[0], row[1], np.radians(row[2]) if degrees else row[2]]))
        elif k in (2, 3):
            out.append(row.copy())
        else:  # pragma: no cover - counts are validated by the readers
            raise CLIError(f"a target needs 2, 3, 6 or 16 numbers, got {k}")
    return out


def _target_sizes(planar: bool) -> tuple[int, ...]:
    return (2, 3, 6, 16) if planar else (3, 6, 16)


def _ik_options(options: tuple[str, ...]) -> dict[str, Any]:
    from serialkin.cli.robots import parse_params

    try:
        return parse_params(options)
    except CLIError as exc:
        raise CLIError(str(exc).replace("--param", "--option")) from exc


def _methods_table() -> str:
    from serialkin.ik import METHODS, available_methods

    rows = [(m, METHODS[m].family, METHODS[m].summary) for m in available_methods()]
    text = format_table(rows, ["method", "family", "description"])
    opts = [f"  {m}: " + ", ".join(f"{k}={v}" for k, v in METHODS[m].options.items())
            for m in available_methods() if METHODS[m].options]
    return text + ("\n\nOptions (--option key=value):\n" + "\n".join(opts) if opts else "")


_IK_CMD_HELP = command_help(
    "Inverse kinematics: joint values that put the tool on a target (sections 4, 5.3).\n\n"
    "ROBOT is " + ROBOT_HELP + ". Exit code 1 when a target is not reached (the output "
    "still lists every result, with success false and the reason); 2 on bad input.",
    ['serialkin ik puma560 --target "0.5,0.2,0.3,0,90,0" --degrees',
     'serialkin ik two_link --target "1.2,0.4" --all',
     "serialkin ik ur5 --target-file targets.csv --method dls --option damping=0.05 --json",
     "serialkin ik --list-methods"],
)


@click.command("ik", help=_IK_CMD_HELP,
               short_help="Inverse kinematics by any method, with every option.")
@click.argument("robot", metavar="ROBOT", required=False)
@click.option("--target", "-t", "targets", multiple=True, metavar="NUMBERS",
              help="Target (repeatable): x,y,z (position); x,y,z,roll,pitch,yaw (pose); 16 "
                   "numbers (4x4 row-major); planar robots: x,y or x,y,phi.")
@click.option("--target-file", type=click.Path(dir_okay=False),
              help="CSV file with one target per row (same forms as --target).")
@click.option("--method", "-m", default="lm", show_default=True,
              help="IK method (see --list-methods).")
@click.option("--q0", default=None, metavar="Q1,Q2,...",
              help="Initial guess (n values); the answer is the 2π-representative nearest "
                   "it (nearest zero without --q0) on joints whose range exceeds a turn.")
@click.option("--mask", default=None, metavar="W1,...,W6",
              help="Weights of [vx,vy,vz,wx,wy,wz] (0 drops a coordinate).")
@click.option("--tol", type=float, default=None, help="Tolerance on position [m] and "
              "orientation [rad] errors (default 1e-9).")
@click.option("--max-iter", type=int, default=None, help="Iterations per attempt.")
@click.option("--restarts", type=int, default=None,
              help="Restarts from random configurations.")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of random starts.")
@click.option("--no-limits", is_flag=True, help="Do not enforce the joint limits.")
@click.option("--option", "options", multiple=True, metavar="KEY=VALUE",
              help="Method-specific option, repeatable (e.g. --option damping=0.05).")
@click.option("--all", "all_solutions", is_flag=True,
              help="Every closed-form solution (section 4.1) instead of one numerical solve.")
@click.option("--list-methods", is_flag=True, help="List the IK methods and their options.")
@degrees_option
@param_option
@json_option
@out_option
@quiet_option
@memory_budget_option
@handle_errors
@one_shot
def ik_cmd(robot: str | None, targets: tuple[str, ...], target_file: str | None, method: str,
           q0: str | None, mask: str | None, tol: float | None, max_iter: int | None,
           restarts: int | None, seed: int, no_limits: bool, options: tuple[str, ...],
           all_solutions: bool, list_methods: bool, degrees: bool, params: tuple[str, ...],
           as_json: bool, out: str | None, quiet: bool) -> None:
    """Inverse kinematics: joint values that put the tool on a target (sections 4, 5.3)."""
    if list_methods:
        click.echo(_methods_table())
        return
    if robot is None:
        raise CLIError("missing ROBOT: " + ROBOT_HELP)
    r = resolve_robot(robot, params)
    planar = bool(r.is_planar)
    sizes = _target_sizes(planar)
    rows = [parse_numbers(t, "--target", sizes) for t in targets]
    if target_file:
        rows += list(read_csv_rows(target_file, "targets", sizes))
    if not rows:
        raise CLIError("no target: give --target (repeatable) or --target-file")
    tgts = _target_rows(r, rows, degrees, planar)
    f = _angle_factor(r, degrees)
    q0v = parse_numbers(q0, "--q0", r.n) if q0 is not None else None
    if q0v is not None and not degrees:
        refuse_joint_turns(r, q0v, "--q0")
    q0v = q0v * f if q0v is not None else None
    maskv = parse_numbers(mask, "--mask", 6) if mask is not None else None
    opts = _ik_options(options)
    info = _robot_info(r)

    if all_solutions:
        _ik_all(r, tgts, info, as_json, out, quiet, f, degrees)
        return

    results = _solve_all(r, tgts, method, q0v, maskv, tol, max_iter, restarts, seed,
                         not no_limits, opts, quiet)
    recs = []
    poses = r.fk(np.array([res.q for res in results]))  # one batched FK call
    for k, (tg, res) in enumerate(zip(tgts, results)):
        recs.append({"index": k + 1, "target": tg, "success": bool(res.success), "q": res.q,
                     "position_error": float(res.position_error),
                     "orientation_error": float(res.orientation_error),
                     "iterations": int(res.iterations), "restarts": int(res.restarts),
                     "reason": str(res.reason), "T": poses[k]})
    ok = all(rec["success"] for rec in recs)
    data = {"robot": info, "method": method, "success": ok,
            "solved": sum(rec["success"] for rec in recs), "count": len(recs),
            "units": {"length": "m", "angle": "rad"}, "results": recs}

    def csv() -> tuple[list[str], np.ndarray]:
        header = ["success"] + [f"q{i + 1}" for i in range(r.n)] + [
            "position_error", "orientation_error", "iterations", "restarts"]
        table = np.array([[float(rec["success"]), *rec["q"], rec["position_error"],
                           rec["orientation_error"], rec["iterations"], rec["restarts"]]
                          for rec in recs])
        return header, table

    if not _emit_results(data, out, csv, as_json, quiet):
        unit = "deg" if degrees else "rad"
        trows = [[rec["index"], "yes" if rec["success"] else "NO",
                  fmt_vector(rec["q"] / f, 4),
                  rec["position_error"], rec["orientation_error"], rec["iterations"],
                  rec["restarts"]] for rec in recs]
        click.echo(f"{r.name}, method {method}:")
        click.echo(format_table(trows, ["#", "ok", f"q [{unit}/m]", "pos err [m]",
                                        "ori err [rad]", "iters", "restarts"], digits=3))
    _exit_if_unreached(recs, lambda rec: f"{rec['reason']} (position error "
                                         f"{rec['position_error']:.3g} m, orientation error "
                                         f"{rec['orientation_error']:.3g} rad)")




def _solve_all(r: Any, tgts: list[Any], method: str, q0: np.ndarray | None,
               mask: np.ndarray | None, tol: float | None, max_iter: int | None,
               restarts: int | None, seed: int, respect_limits: bool, opts: dict[str, Any],
               quiet: bool) -> list[Any]:
    """Solve every target, in batches when they have one shape (compiled batch kernel).

    A progress bar is shown on a terminal for long runs (more than one batch).
    """
    from tqdm import tqdm

    kw = dict(method=method, mask=mask, tol=tol, max_iter=max_iter, restarts=restarts,
              seed=seed, respect_limits=respect_limits, **opts)
    shapes = {np.shape(t) for t in tgts}
    if len(tgts) == 1:
        return [r.ik(tgts[0], q0=q0, **kw)]
    if len(shapes) != 1:
        return [r.ik(t, q0=q0, **kw) for t in tgts]
    stack = np.array(tgts)
    out: list[Any] = []
    chunk = 256
    bar = tqdm(total=len(tgts), desc="ik", unit="target",
               disable=True if quiet or len(tgts) <= chunk else None, leave=False)
    try:
        for s in range(0, len(tgts), chunk):
            res = r.ik(stack[s:s + chunk], q0=q0, **kw)
            out.extend(res[k] for k in range(len(res)))
            bar.update(min(chunk, len(tgts) - s))
    finally:
        bar.close()
    return out


def _ik_all(r: Any, tgts: list[Any], info: dict[str, Any], as_json: bool, out: str | None,
            quiet: bool, f: np.ndarray, degrees: bool) -> None:
    recs = []
    for k, tg in enumerate(tgts):
        sols = np.asarray(r.ik_all(tg), dtype=float).reshape(-1, r.n)
        recs.append({"index": k + 1, "target": tg, "success": bool(len(sols)),
                     "solutions": sols, "count": int(len(sols))})
    ok = all(rec["success"] for rec in recs)
    data = {"robot": info, "method": "closed form (all solutions)", "success": ok,
            "units": {"length": "m", "angle": "rad"}, "results": recs}

    def csv() -> tuple[list[str], np.ndarray]:
        header = ["target"] + [f"q{i + 1}" for i in range(r.n)]
        table = np.array([[rec["index"], *q] for rec in recs for q in rec["solutions"]])
        return header, table.reshape(-1, r.n + 1)

    if not _emit_results(data, out, csv, as_json, quiet):
        unit = "deg" if degrees else "rad"
        for rec in recs:
            click.echo(f"target {rec['index']}: {rec['count']} solution(s) [{unit}/m]")
            for q in rec["solutions"]:
                click.echo("  " + fmt_vector(q / f))
    _exit_if_unreached(recs, lambda rec: "no closed-form solution inside the joint limits")
