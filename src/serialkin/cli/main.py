"""Entry point of the ``serialkin`` command line.

Built on click (well kept, composable subcommands, ``--help`` for free). Each subcommand
lives in its own module of this package and is registered on :data:`cli` here.
"""

from __future__ import annotations

import sys

import click

from serialkin._checks import short_repr
from serialkin.cli.commands import handle_errors, memory_budget_option, set_budget
from serialkin.cli.io import EXIT_INPUT, CLIError, command_help, ensure_dir
from serialkin.errors import SerialkinError

# click keeps example blocks unwrapped only after a real backspace character, which a raw
# docstring does not contain: the help texts are built by command_help instead.
_CLI_HELP = command_help(
    "serialkin: kinematics of serial robot manipulators.\n\n"
    "Every subcommand has --help with examples. ROBOT arguments take a built-in model name "
    "(serialkin models), a robot file (.yaml/.yml/.json) or a URDF file. Exit codes: 0 "
    "success, 1 a target or path point not reached, 2 bad input.",
    ["serialkin models", 'serialkin fk puma560 --q "0,0.5,-0.3,0,0.2,0"',
     'serialkin ik two_link --target "1.2,0.4" --all',
     "serialkin workspace two_link --out out/ws", "serialkin track six_link_circle",
     "serialkin view ur5 --open", "serialkin chapter --out out/chapter"],
)


class SerialkinGroup(click.Group):
    """The ``serialkin`` group: whatever a subcommand raises becomes one ``Error:`` line.

    Every subcommand also wraps itself in :func:`~serialkin.cli.commands.handle_errors`;
    this is the last guard, for errors raised outside a command body (e.g. while click
    converts an option value, or in a subcommand added later).
    """

    def invoke(self, ctx: click.Context) -> object:
        """Invoke the subcommand, mapping errors as :func:`handle_errors` does."""
        from serialkin.cli.commands import PASS_THROUGH, cli_error

        try:
            return super().invoke(ctx)
        except PASS_THROUGH:
            raise
        except click.ClickException as exc:
            if isinstance(exc, CLIError) or exc.exit_code == EXIT_INPUT:
                raise cli_error(exc if isinstance(exc, CLIError) else CLIError(
                    exc.format_message())) from exc
            raise CLIError(exc.format_message()) from exc
        except Exception as exc:
            raise cli_error(exc) from exc


@click.group(cls=SerialkinGroup, context_settings={"help_option_names": ["-h", "--help"]},
             help=_CLI_HELP)
@click.version_option(package_name="serialkin")
@click.option("--memory-budget", metavar="SIZE", expose_value=False, is_eager=True,
              callback=set_budget,
              help="Largest memory a run may plan to allocate, e.g. 8G or 500M or unlimited "
                   "(default: half the available memory, or $SERIALKIN_MEMORY_BUDGET). "
                   "Sizes beyond it are refused before allocation.")
def cli() -> None:
    r"""serialkin: kinematics of serial robot manipulators.

    \b
    Examples:
      serialkin chapter --out out/chapter
      serialkin models
    """


@cli.command(help=command_help("Reproduce the chapter's worked examples into an HTML report.",
                               ["serialkin chapter --out out/chapter",
                                "serialkin chapter --section workspace --out out/ch1"]))
@click.option("--out", "out", default="out/chapter", show_default=True,
              type=click.Path(file_okay=False), help="Output folder for report.html and figures.")
@click.option("--quiet", "-q", is_flag=True, help="No progress bar.")
@click.option("--section", "sections", multiple=True,
              help="Build only this section (repeatable), e.g. --section forward.")
@click.option("--jobs", "-j", type=click.IntRange(1, 64), default=None,
              help="Worker processes building sections side by side (default: the cores "
                   "other processes leave free).")
@memory_budget_option
@handle_errors
def chapter(out: str, quiet: bool, sections: tuple[str, ...], jobs: int | None) -> None:
    r"""Reproduce the chapter's worked examples into an HTML report.

    \b
    Example:
      serialkin chapter --out out/chapter
    """
    from serialkin.chapter.report import SECTION_MODULES, build_report

    unknown = [s for s in sections if s not in SECTION_MODULES]
    if unknown:
        raise CLIError(
            f"--section: unknown section(s) {', '.join(short_repr(u, 40) for u in unknown)}; "
            f"expected: {', '.join(SECTION_MODULES)}"
        )
    ensure_dir(out)  # a file, a read-only or uncreatable folder: refused before any work
    try:
        path = build_report(out, quiet=quiet, sections=sections or None, jobs=jobs)
    except (OSError, SerialkinError) as exc:
        raise CLIError(f"cannot write the report to {short_repr(str(out))}: "
                       f"{getattr(exc, 'strerror', None) or exc}") from exc
    click.echo(f"wrote {path}")


def _register() -> None:
    """Add the subcommands of this package to :data:`cli`."""
    from serialkin.cli.calibrate_cmd import calibrate_cmd
    from serialkin.cli.collide_cmd import collide_cmd
    from serialkin.cli.commands import fk_cmd, ik_cmd, jacobian_cmd, models_cmd
    from serialkin.cli.compare_cmd import compare_cmd
    from serialkin.cli.path_cmd import path_cmd
    from serialkin.cli.reach_cmd import base_placement_cmd, reach_cmd
    from serialkin.cli.track_cmd import track_cmd
    from serialkin.cli.view_cmd import view_cmd
    from serialkin.cli.warmup_cmd import warmup_cmd
    from serialkin.cli.workspace_cmd import workspace_cmd

    for command in (models_cmd, fk_cmd, jacobian_cmd, ik_cmd, compare_cmd, track_cmd,
                    path_cmd, workspace_cmd, view_cmd, calibrate_cmd, reach_cmd, base_placement_cmd,
                    warmup_cmd, collide_cmd):
        cli.add_command(command)


_register()


def main() -> None:
    """Console entry point."""
    cli(prog_name="serialkin")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
