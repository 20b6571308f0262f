"""The ``calibrate`` subcommand: identify a robot's geometry from measurements, or simulate them."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import click
import numpy as np

from serialkin.cli.commands import handle_errors, json_option, quiet_option
from serialkin.cli.io import (
    EXIT_NOT_REACHED,
    CLIError,
    command_help,
    csv_text,
    dumps_json,
    write_output,
    write_text_atomic,
)
from serialkin.cli.robots import ROBOT_HELP, param_option, resolve_robot, robot_argument

_HELP = command_help(
    "Calibrate ROBOT: fit its geometry (DH with Hayati's β for parallel axes, or joint "
    "origin errors for URDF robots; base and tool) to measured tool positions or poses, "
    "say which parameters the measurements cannot identify, and write the calibrated robot."
    "\n\nThe measurement CSV has a header q1..qn,x,y,z (positions, metres) and optionally "
    "quat_w,quat_x,quat_y,quat_z (poses) and weight. With --simulate N the robot is "
    "perturbed instead and N noisy measurements of it are written to --measurements (and "
    "the perturbed robot to --truth). A URDF ROBOT is written by patching its file: only "
    "the changed joint origins differ. A robot file (.yaml/.json) holds a DH table; when "
    "the calibrated axes make it unphysical (nearly parallel axes) a .urdf is written "
    "instead, and the output says so. ROBOT is " + ROBOT_HELP + ".",
    ["serialkin calibrate ur5 --simulate 60 --measurements meas.csv --truth real.urdf",
     "serialkin calibrate ur5 --measurements meas.csv --out calibrated.yaml",
     "serialkin calibrate arm.urdf --measurements meas.csv --out cal.urdf --report res.csv",
     "serialkin calibrate ur5 --measurements poses.csv --loss soft_l1 --json"],
)


@click.command("calibrate", help=_HELP,
               short_help="Calibrate a robot's geometry from measurements.")
@robot_argument
@click.option("--measurements", "-m", "measurements", type=click.Path(dir_okay=False),
              required=True, help="Measurement CSV to read (or, with --simulate, to write).")
@click.option("--out", "-o", type=click.Path(dir_okay=False), default=None,
              help="Write the calibrated robot (.yaml/.yml/.json robot file or .urdf).")
@click.option("--urdf", type=click.Path(dir_okay=False), default=None,
              help="Also write the calibrated robot as URDF.")
@click.option("--report", type=click.Path(dir_okay=False), default=None,
              help="Write per-measurement errors before/after (.csv) or the full report (.json).")
@click.option("--model", "kind", type=click.Choice(["auto", "dh", "joints"]), default="auto",
              show_default=True, help="Error model: the DH table, or joint origin/axis errors.")
@click.option("--hayati", type=click.Choice(["auto", "none"]), default="auto",
              show_default=True, help="Hayati's β on links with (nearly) parallel axes.")
@click.option("--no-base", is_flag=True, help="Keep the base pose fixed.")
@click.option("--no-tool", is_flag=True, help="Keep the tool pose (marker offset) fixed.")
@click.option("--scale", "encoder_scale", is_flag=True,
              help="Also identify each joint's encoder scale.")
@click.option("--frame", "frame", type=click.Choice(["nominal", "unknown"]), default="nominal",
              show_default=True,
              help="The measuring device's frame: near the robot's base, or anywhere.")
@click.option("--loss", type=click.Choice(["linear", "huber", "soft_l1", "cauchy", "arctan"]),
              default="linear", show_default=True, help="Least squares or a robust loss.")
@click.option("--loss-scale", type=float, default=3.0, show_default=True,
              help="Residual size in sigmas where a robust loss bends.")
@click.option("--sigma-position", type=float, default=1e-4, show_default=True,
              help="Standard deviation of a measured coordinate [m].")
@click.option("--sigma-rotation", type=float, default=1e-3, show_default=True,
              help="Standard deviation of a measured rotation [rad].")
@click.option("--max-evaluations", type=int, default=200, show_default=True,
              help="Residual evaluations before giving up (exit code 1).")
@click.option("--simulate", type=int, default=None, metavar="N",
              help="Simulation mode: perturb ROBOT and write N noisy measurements.")
@click.option("--kind", "sim_kind", type=click.Choice(["position", "pose"]), default="position",
              show_default=True, help="Simulation: what is measured.")
@click.option("--noise-position", type=float, default=5e-5, show_default=True,
              help="Simulation: noise of each coordinate [m].")
@click.option("--noise-rotation", type=float, default=1e-4, show_default=True,
              help="Simulation: noise of each rotation [rad] (poses).")
@click.option("--perturb-length", type=float, default=1e-3, show_default=True,
              help="Simulation: largest length error [m].")
@click.option("--perturb-angle", type=float, default=0.5, show_default=True,
              help="Simulation: largest angle error [deg].")
@click.option("--select", "select", type=int, default=None, metavar="N_CANDIDATES",
              help="Simulation: pick the N poses out of this many random candidates by O1.")
@click.option("--truth", type=click.Path(dir_okay=False), default=None,
              help="Simulation: write the perturbed robot (.yaml/.json/.urdf).")
@click.option("--seed", type=int, default=0, show_default=True, help="Simulation: random seed.")
@param_option
@json_option
@quiet_option
@handle_errors
def calibrate_cmd(robot: str, measurements: str, out: str | None, urdf: str | None,
                  report: str | None, kind: str, hayati: str, no_base: bool, no_tool: bool,
                  encoder_scale: bool, frame: str, loss: str, loss_scale: float,
                  sigma_position: float, sigma_rotation: float,
                  max_evaluations: int, simulate: int | None, **opts: Any) -> None:
    """Calibrate a robot from measurements, or simulate measurements (see the help)."""
    from serialkin.calibration import calibrate, error_model, read_measurements

    if simulate is not None:
        given = [o for o, v in (("--out", out), ("--urdf", urdf), ("--report", report)) if v]
        if given:
            raise CLIError(f"{', '.join(given)} write a calibration; with --simulate nothing "
                           "is calibrated (run again without --simulate)")
    else:
        given = [o for o in ("truth", "select") if opts[o] is not None]
        if given:
            raise CLIError(f"{', '.join('--' + o for o in given)} only apply with --simulate")
    _check_suffix("--out", out, (".yaml", ".yml", ".json", ".urdf"))
    _check_suffix("--report", report, (".csv", ".json"))
    _check_suffix("--truth", opts["truth"], (".yaml", ".yml", ".json", ".urdf"))
    params = opts.pop("params")
    r = resolve_robot(robot, params)
    as_json, quiet = opts.pop("as_json"), opts.pop("quiet")
    say = (lambda text: None) if quiet or as_json else click.echo
    if simulate is not None:
        model = error_model(r, kind, hayati=hayati, base=not no_base, tool=not no_tool,
                            scale=encoder_scale)
        _simulate(model, _Simulation(simulate, kind=opts.pop("sim_kind"), **opts),
                  measurements, say, as_json)
        return
    meas = read_measurements(measurements, r, sigma_position=sigma_position,
                             sigma_rotation=sigma_rotation)
    markers = int(meas.markers.max()) + 1 if len(meas) else 1
    model = error_model(r, kind, hayati=hayati, base=not no_base, tool=not no_tool,
                        scale=encoder_scale, markers=markers)
    res = calibrate(model, meas, loss=loss, loss_scale=loss_scale,
                    max_evaluations=max_evaluations, frame=frame)
    notes: list[str] = []
    source = robot if Path(robot).suffix.lower() == ".urdf" else None
    links = _link_params(params)
    written = []
    for option, path in (("--out", out), ("--urdf", urdf)):
        if path:
            written.append(_write_robot(res, path, option, source, links, [robot, measurements],
                                        notes))
    data = _report(res)
    data["notes"] = notes
    data["written"] = [str(w) for w in written]
    if report:
        if Path(report).suffix.lower() == ".csv":
            header, rows = res.residual_table()
            written.append(write_text_atomic(report, csv_text(header, rows)))
        else:
            written.append(write_output(report, data))
    if as_json:
        click.echo(dumps_json(data))
    else:
        say(res.summary())
        say(_parameter_lines(res))
        for note in notes:
            say(f"note: {note}")
        for w in written:
            say(f"wrote {w}")
    if not res.success:
        raise SystemExit(EXIT_NOT_REACHED)


def _link_params(params: Any) -> dict[str, str]:
    """base_link / tip_link of the --param pairs (how a URDF robot was read)."""
    out = {}
    for p in params or ():
        k, _, v = str(p).partition("=")
        if k.strip() in ("base_link", "tip_link"):
            out[k.strip()] = v.strip()
    return out


def _write_robot(res: Any, path: str, option: str, source: str | None,
                 links: dict[str, str], inputs: list[str], notes: list[str]) -> Path:
    """Write the calibrated robot for ``option``: the URDF patched, a URDF, or a robot file.

    A robot file whose DH table would not be physical becomes a .urdf beside it (never
    over an input), and ``notes`` says so.
    """
    from serialkin.calibration.export import patch_urdf, save_robot, unphysical_dh

    p = Path(path)
    if p.suffix.lower() != ".urdf":
        if option == "--urdf":
            p = p.with_suffix(".urdf")
        else:
            dh, why = unphysical_dh(res.robot)
            if dh is not None:
                return save_robot(dh, p)
            alt = p.with_suffix(".urdf")
            for given in inputs:
                if alt.exists() and Path(given).exists() and alt.samefile(given):
                    raise CLIError(f"{option} {path}: {why}; and {alt} is an input")
            notes.append(f"{path} not written: {why}; wrote {alt} (per-joint origins) instead")
            p = alt
    if source is not None:
        patch = patch_urdf(source, res, p, base_link=links.get("base_link"),
                           tip_link=links.get("tip_link"))
        notes.extend(n for n in patch.notes if n not in notes)
        return patch.path
    return save_robot(res.robot, p)


def _check_suffix(option: str, path: str | None, allowed: tuple[str, ...]) -> None:
    if path is not None and Path(path).suffix.lower() not in allowed:
        raise CLIError(f"{option} {path}: unsupported file type {Path(path).suffix!r}; use "
                       f"{', '.join(allowed)}")


def _report(res: Any) -> dict[str, Any]:
    header, rows = res.residual_table()
    pb, rb = res.rms_before
    pa, ra = res.rms_after
    return {"success": res.success, "reason": res.reason, "model": repr(res.model),
            "measurements": len(res.errors_before), "kind": res.identifiability.kind,
            "rms_position_before": pb, "rms_position_after": pa,
            "rms_rotation_before": None if math.isnan(rb) else rb,
            "rms_rotation_after": None if math.isnan(ra) else ra,
            "condition_number": res.identifiability.condition_number,
            "chi_square": _chi_square(res),
            "encoder_scale": res.encoder_scale.tolist(),
            "marker_offsets": res.marker_offsets.tolist(),
            "predicted_error": _finite(res.predicted_error(count=200)),
            "not_identifiable": list(res.identifiability.reasons),
            "parameters": [{k: (None if isinstance(v, float) and math.isnan(v) else v)
                            for k, v in row.items()} for row in res.parameter_table()],
            "residuals": {"columns": header, "rows": rows.tolist()}}


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def _chi_square(res: Any) -> dict[str, Any]:
    """The chi-square test of the residual (fit.ChiSquare) with its verdict, for JSON."""
    from serialkin.calibration.fit import SIGNIFICANCE

    c = res.chi_square
    return {"chi2": _finite(c.chi2), "dof": c.dof, "p_value": _finite(c.p_value),
            "noise_ratio": _finite(c.noise_ratio), "outliers": c.outliers,
            "significance": SIGNIFICANCE, "consistent_with_noise": not c.verdict(SIGNIFICANCE),
            "verdict": c.verdict(SIGNIFICANCE)}


def _parameter_lines(res: Any) -> str:
    lines = ["fitted parameters (change from nominal ± standard error):"]
    for row in res.parameter_table():
        if not row["fitted"]:
            continue
        if row["unit"] == "m":
            lines.append(f"  {row['name']:<22} {row['change'] * 1e3:+.4f} mm "
                         f"± {row['std_error'] * 1e3:.4f}")
        elif row["unit"] == "1":
            lines.append(f"  {row['name']:<22} {row['change'] * 1e6:+.2f} ppm "
                         f"± {row['std_error'] * 1e6:.2f}")
        else:
            lines.append(f"  {row['name']:<22} {math.degrees(row['change']):+.5f}° "
                         f"± {math.degrees(row['std_error']):.5f}")
    return "\n".join(lines)


@dataclass(frozen=True)
class _Simulation:
    """The simulation options of ``serialkin calibrate --simulate N`` (see their help).

    Attributes:
        count: poses to measure (``--simulate``).
        kind: 'position' or 'pose' (``--kind``).
        noise_position: noise of each coordinate [m].
        noise_rotation: noise of each rotation [rad].
        perturb_length: largest length error [m].
        perturb_angle: largest angle error [deg].
        select: candidates the poses are picked from by O1 (None: random poses).
        truth: file to write the perturbed robot to, or None.
        seed: random seed.
    """

    count: int
    kind: str
    noise_position: float
    noise_rotation: float
    perturb_length: float
    perturb_angle: float
    select: int | None
    truth: str | None
    seed: int


def _simulate(model: Any, sim: _Simulation, path: str, say: Any, as_json: bool) -> None:
    """Perturb ``model``'s robot, measure it as ``sim`` says and write the measurements."""
    from serialkin._checks import check_int
    from serialkin.calibration import (
        perturb,
        save_robot,
        select_poses,
        simulate_measurements,
        write_measurements,
    )

    kind = sim.kind
    count = check_int(sim.count, "--simulate", minimum=1)
    rng = np.random.default_rng(sim.seed)
    params = perturb(model, length=sim.perturb_length, angle=math.radians(sim.perturb_angle),
                     seed=rng)
    real = model.calibrated_robot(params, name=f"{model.robot.name} (simulated real)")
    if sim.select is not None:
        cand = model.robot.random_q(check_int(sim.select, "--select", minimum=1), seed=rng)
        if count > len(cand):
            raise CLIError(f"--simulate {count} poses cannot be picked out of --select "
                           f"{len(cand)} candidates")
        q: Any = cand[select_poses(model, cand, count, kind=kind, seed=rng)]
    else:
        q = count
    meas = simulate_measurements(real, q, kind=kind, noise_position=sim.noise_position,
                                 noise_rotation=sim.noise_rotation, seed=rng)
    written = [write_measurements(path, meas)]
    if sim.truth:
        written.append(save_robot(real, sim.truth))
    if as_json:
        click.echo(dumps_json({"measurements": len(meas), "kind": kind,
                               "written": [str(w) for w in written],
                               "parameters": dict(zip(model.names, params.tolist()))}))
    for w in written:
        say(f"wrote {w}")
