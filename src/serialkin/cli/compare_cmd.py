"""The ``ik-compare`` subcommand: every IK method on the same targets (serialkin.ik.compare)."""

from __future__ import annotations

from typing import Any

import click
import numpy as np

from serialkin._budget import check_allocation
from serialkin._checks import check_int, short_repr
from serialkin.cli.commands import (
    _target_rows,
    _target_sizes,
    degrees_option,
    handle_errors,
    json_option,
    memory_budget_option,
    out_option,
    quiet_option,
)
from serialkin.cli.io import (
    CLIError,
    command_help,
    dumps_json,
    read_csv_rows,
    write_output,
    write_text_atomic,
)
from serialkin.cli.robots import ROBOT_HELP, param_option, parse_params, resolve_robot
from serialkin.model.tasks import TARGET_TASKS

_COMPARE_HELP = command_help(
    "Solve the same targets with several IK methods and tabulate success rate, times, "
    "iterations and final errors.\n\n"
    "Targets are reachable by construction (FK of seeded random configurations inside the "
    "joint limits) unless --target-file is given. ROBOT is " + ROBOT_HELP + ".",
    ["serialkin ik-compare ur5 --targets 50",
     "serialkin ik-compare three_link --targets 100 --methods lm,dls,ccd,fabrik",
     "serialkin ik-compare panda --kind position --option dls:damping=0.05 --json"],
)


def random_targets(robot: Any, count: int, kind: str, seed: int) -> np.ndarray:
    """Reachable targets of a kind from FK of seeded random configurations."""
    T = robot.fk(robot.random_q(count, seed=seed))
    if kind == "pose":
        return T
    if kind == "position":
        return T[:, :3, 3].copy()
    xy = T[:, :2, 3]
    if kind == "planar":
        return xy.copy()
    phi = np.arctan2(T[:, 1, 0], T[:, 0, 0])
    return np.column_stack([xy, phi])


def _write_table(out: str, data: dict[str, Any]) -> Any:
    """Write the comparison as JSON or as a CSV with one row per method (SI units)."""
    import csv
    import io
    from pathlib import Path

    if Path(out).suffix.lower() != ".csv":
        return write_output(out, data)
    rows = data["rows"]
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    keys = list(rows[0]) if rows else ["method"]
    w.writerow(keys)
    for row in rows:
        w.writerow([repr(float(v)) if isinstance(v, float) else v for v in row.values()])
    return write_text_atomic(out, buf.getvalue())


@click.command("ik-compare", help=_COMPARE_HELP,
               short_help="Compare IK methods on the same targets.")
@click.argument("robot", metavar="ROBOT")
@click.option("--targets", "count", type=int, default=50, show_default=True,
              help="Number of random reachable targets.")
@click.option("--kind", type=click.Choice(["auto", *TARGET_TASKS]), default="auto",
              show_default=True, help="Target kind (auto: planar_pose / planar for planar "
                                      "robots, pose otherwise).")
@click.option("--target-file", type=click.Path(dir_okay=False),
              help="CSV of targets instead (forms as 'serialkin ik --target').")
@click.option("--methods", default=None, metavar="M1,M2,...",
              help="Methods to compare (default: every numerical method).")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of targets and "
              "random starts.")
@click.option("--tol", type=float, default=1e-9, show_default=True,
              help="Success tolerance on position [m] and orientation [rad] errors.")
@click.option("--max-iter", type=int, default=None, help="Iterations per attempt.")
@click.option("--restarts", type=int, default=None, help="Restarts per target.")
@click.option("--no-limits", is_flag=True, help="Do not enforce the joint limits.")
@click.option("--option", "options", multiple=True, metavar="METHOD:KEY=VALUE",
              help="A method-specific option, e.g. dls:damping=0.05 (repeatable).")
@degrees_option
@param_option
@json_option
@out_option
@quiet_option
@memory_budget_option
@handle_errors
def compare_cmd(robot: str, count: int, kind: str, target_file: str | None,
                methods: str | None, seed: int, tol: float, max_iter: int | None,
                restarts: int | None, no_limits: bool, options: tuple[str, ...],
                degrees: bool, params: tuple[str, ...], as_json: bool, out: str | None,
                quiet: bool) -> None:
    """Compare IK methods on the same targets."""
    from serialkin.ik.compare import compare

    r = resolve_robot(robot, params)
    planar = bool(r.is_planar)
    if target_file:
        rows = list(read_csv_rows(target_file, "targets", _target_sizes(planar)))
        targets: Any = np.array(_target_rows(r, rows, degrees, planar, "--target-file row"))
    else:
        count = check_int(count, "--targets", minimum=1)
        check_allocation("the random targets", (count, r.n + 16), 8, setting="--targets")
        if kind == "auto":
            kind = ("planar_pose" if r.n >= 3 else "planar") if planar else "pose"
        if kind.startswith("planar") and not planar:
            raise CLIError(f"--kind {kind} needs a planar robot; {short_repr(r.name)} is spatial")
        targets = random_targets(r, count, kind, seed)
    per_method: dict[str, dict[str, Any]] = {}
    for o in options:
        if ":" not in o:
            raise CLIError(f"--option {short_repr(o)}: expected METHOD:KEY=VALUE, "
                           "e.g. dls:damping=0.05")
        m, kv = o.split(":", 1)
        per_method.setdefault(m.strip(), {}).update(parse_params([kv]))
    common: dict[str, Any] = {"respect_limits": not no_limits}
    if max_iter is not None:
        common["max_iter"] = max_iter
    if restarts is not None:
        common["restarts"] = restarts
    names = [m.strip() for m in methods.split(",") if m.strip()] if methods else None
    table = compare(r, targets, methods=names, seed=seed, tol=tol,
                    method_options=per_method or None, **common)
    data = {"robot": table.robot, "target_kind": table.target_kind,
            "targets": table.n_targets, "tol": table.tol, "rows": table.to_dicts(),
            "skipped": [{"method": m, "reason": why} for m, why in table.skipped]}
    if out:
        path = _write_table(out, data)
        if not as_json and not quiet:
            click.echo(f"wrote {path}")
    if as_json:
        click.echo(dumps_json(data), nl=False)
    elif not quiet:
        click.echo(table.to_text())
