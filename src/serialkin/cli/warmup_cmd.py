"""The ``warmup`` subcommand: compile the kernels ahead of time (serialkin.warmup)."""

from __future__ import annotations

import json
import sys

import click

from serialkin.cli.commands import handle_errors
from serialkin.cli.io import CLIError, command_help

_WARMUP_HELP = command_help(
    "Compile serialkin's kernels into numba's on-disk cache ahead of time, one process per "
    "feature, as many at a time as there are cores, with a progress bar and the time "
    "left. Later processes load the compiled kernels in about a second instead of "
    "compiling them on their first call. Without FEATURE, --all is implied; --list "
    "shows the features and their cold compile times.",
    ["serialkin warmup", "serialkin warmup kinematics ik", "serialkin warmup --list",
     "serialkin warmup --all --jobs 2 --json"],
)


@click.command("warmup", help=_WARMUP_HELP)
@click.argument("features", nargs=-1, metavar="[FEATURE]...")
@click.option("--all", "all_", is_flag=True, help="Every feature (the default).")
@click.option("--list", "list_", is_flag=True, help="List the features and exit.")
@click.option("--jobs", "-j", type=click.IntRange(1, 64), default=None,
              help="Processes compiling side by side (default: the usable CPUs).")
@click.option("--json", "as_json", is_flag=True, help="Print the time of each feature as JSON.")
@click.option("--quiet", "-q", is_flag=True, help="No progress bar.")
@handle_errors
def warmup_cmd(features: tuple[str, ...], all_: bool, list_: bool, jobs: int | None,
               as_json: bool, quiet: bool) -> None:
    """Compile the kernels of FEATURE... (default: all) into the on-disk cache."""
    from serialkin.warmup import FEATURES, warmup

    if list_:
        for f in FEATURES.values():
            click.echo(f"{f.name:<11} {f.seconds:5.0f} s  {f.summary}")
        return
    if all_ and features:
        raise CLIError("give FEATURE names or --all, not both")
    times = warmup(None if all_ or not features else features, jobs=jobs,
                   progress=False if quiet or as_json else None)
    if as_json:
        click.echo(json.dumps({"seconds": times}))
    elif not quiet:
        done = ", ".join(f"{n} {t:.1f} s" for n, t in times.items())
        click.echo(f"compiled: {done}", err=not sys.stdout.isatty())
