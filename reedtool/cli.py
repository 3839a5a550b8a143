"""The click layer: parse options, call one api function, print, exit.

Subcommands are imported lazily so that `reedtool --help` does not pay for numpy,
trimesh or Pinocchio. Each entry in SUBCOMMANDS names the module that defines a click
command called `command` and the one-line summary shown by --help.
"""

from __future__ import annotations

import gc
import importlib
import os
import sys
import warnings

import click

from reedtool import __version__

# name -> (module, one-line summary). Only subcommands that exist are listed here.
SUBCOMMANDS: dict[str, tuple[str, str]] = {
    "expand": ("reedtool.commands.expand", "Expand a xacro model to URDF without ROS ($(find), package://, source lines)."),
    "validate": ("reedtool.commands.validate", "Check URDF/xacro/SDF models (files, dirs, packages, globs) for mistakes that break them in Gazebo."),
    "import-stl": ("reedtool.commands.import_stl", "Import a CAD STL into a package: metres, FLU, inertia about the COM."),
    "inertia": ("reedtool.commands.inertia", "Compare declared link inertia with the geometry's; whole-robot mass properties."),
    "new-package": ("reedtool.commands.new_package", "Scaffold a ROS 1/2 package (multirotor or ground robot) that validates and hovers."),
    "rules": ("reedtool.commands.rules", "List validate's rules (codes, names, severities), filtered by family or prefix."),
    "hover-test": ("reedtool.commands.hover_test", "Trim a multirotor for hover and fly it headless: does it settle and stay?"),
    "authority": ("reedtool.commands.authority", "Control authority (ACAI) about hover, intact and after each single rotor failure."),
    "layout": ("reedtool.commands.layout", "Draw the rotor layout seen from above (SVG/PNG): numbers, spin, COM, arms."),
    "migrate": ("reedtool.commands.migrate", "Port a Gazebo Classic multirotor to Gazebo Sim and prove the port flies the same."),
    "view": ("reedtool.commands.view", "Show a model in 3-D as Gazebo places it (GLB/PNG/HTML): rotor spins, COM, scale."),
}


class LazyGroup(click.Group):
    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted(SUBCOMMANDS)

    def get_command(self, ctx: click.Context, name: str) -> click.Command | None:
        if name not in SUBCOMMANDS:
            return None
        module_name, summary = SUBCOMMANDS[name]
        command = importlib.import_module(module_name).command
        command.short_help = summary
        return command

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        # Summaries come from the table, so --help imports no subcommand module.
        rows = [(name, SUBCOMMANDS[name][1]) for name in self.list_commands(ctx)]
        if rows:
            with formatter.section("Commands"):
                formatter.write_dl(rows)


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="reedtool")
def cli() -> None:
    """Check, trim and package multirotor models for ROS/Gazebo, without ROS or Gazebo."""


def _usage_error_line(exc: click.UsageError) -> str:
    """A click usage error as one line, like every other reedtool error."""
    from reedtool.errors import shorten_names

    text = shorten_names(" ".join(exc.format_message().split()))
    command = exc.ctx.command_path if exc.ctx is not None else "reedtool"
    return f"reedtool: error: {text} (see '{command} --help')"


def main(argv: list[str] | None = None) -> None:
    """Console-script entry: user errors become one line and exit 2, never a traceback."""
    from reedtool.errors import ReedtoolError, os_error, shorten
    from reedtool.io.fileio import reset_inputs

    if argv is None:     # reedtool's own process (the console script), not a caller's
        _one_blas_thread()
        _fewer_collections()
    reset_inputs()
    try:
        with warnings.catch_warnings():
            if not os.environ.get("REEDTOOL_DEBUG"):
                # numpy's "invalid value" chatter on NaN input: the NaN itself is reported
                # (a finding or an error naming its line); the warning only adds noise.
                warnings.simplefilter("ignore", RuntimeWarning)
            # Commands return their exit code (0 ok, 1 findings/failed check); --help and
            # --version return None through click's Exit.
            exit_code = cli.main(args=argv, prog_name="reedtool", standalone_mode=False)
            sys.stdout.flush()   # a full disk or closed pipe on stdout is reported here
    except click.exceptions.Abort:
        click.echo("reedtool: aborted", err=True)
        sys.exit(130)
    except click.exceptions.NoArgsIsHelpError as exc:
        exc.show()   # `reedtool` alone: the help text, not an error line
        sys.exit(2)
    except click.UsageError as exc:
        click.echo(_usage_error_line(exc), err=True)
        sys.exit(2)
    except click.ClickException as exc:
        click.echo(f"reedtool: error: {' '.join(exc.format_message().split())}", err=True)
        sys.exit(exc.exit_code if exc.exit_code else 2)
    except ReedtoolError as exc:
        click.echo(f"reedtool: error: {exc.one_line()}", err=True)
        sys.exit(2)
    except KeyboardInterrupt:
        sys.exit(130)
    except BrokenPipeError:
        # `reedtool expand M | head`: the reader has what it wanted; not an error.
        _quiet_stdout()
        sys.exit(141 if argv is None else 2)
    except OSError as exc:
        # The user's environment (full disk, long name, permissions, read-only fs), not a bug.
        target = exc.filename if exc.filename is not None else "<standard output>"
        click.echo(f"reedtool: error: {os_error(exc, target).one_line()}", err=True)
        _quiet_stdout()
        sys.exit(2)
    except UnicodeDecodeError as exc:
        click.echo(f"reedtool: error: cannot decode a file as text: {shorten(str(exc), 200)} "
                   "(is a binary file where a text file is expected? save it as UTF-8)",
                   err=True)
        sys.exit(2)
    except MemoryError:
        click.echo("reedtool: error: out of memory (the input or the options ask for more "
                   "than this machine has: use a smaller model, mesh or --samples)", err=True)
        sys.exit(2)
    except Exception as exc:  # noqa: BLE001 - the last line of defence against tracebacks
        if os.environ.get("REEDTOOL_DEBUG"):
            raise
        detail = " ".join(str(exc).split()) or type(exc).__name__
        click.echo(f"reedtool: internal error: {type(exc).__name__}: {detail} "
                   "(this is a reedtool bug; rerun with REEDTOOL_DEBUG=1 for the traceback "
                   "and report it)", err=True)
        sys.exit(2)
    sys.exit(exit_code if isinstance(exit_code, int) else 0)


def _one_blas_thread() -> None:
    """One OpenBLAS thread, unless the user chose a number.

    numpy's OpenBLAS starts a pool of one thread per core when numpy is imported, and the
    idle pool spins: about half of check_urdf's whole run in CPU time, before validate's
    first finding (issue 29 item 7). reedtool's products are small (3x3 to 6xN) or a
    mesh's N x 3 vertices times a 3x3 rotation, which memory bounds, not threads; the
    parallel paths (--jobs processes, numba's threads) have workers of their own, which a
    second pool per process would only crowd. It must be
    set before numpy is first imported: OpenBLAS reads it once, when it loads (the first of
    these names that is set counts).
    """
    chosen = ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS")
    if "numpy" not in sys.modules and not any(name in os.environ for name in chosen):
        os.environ["OPENBLAS_NUM_THREADS"] = "1"


# Container allocations between two young-generation collections of the cycle collector
# (CPython's default is 700; mypy's main sets 200 000 for the same reason).
GC_YOUNG_THRESHOLD = 100_000


def _fewer_collections() -> None:
    """Collect reference cycles every GC_YOUNG_THRESHOLD allocations, not every 700.

    Start-up builds some 100 000 objects that live until the process exits (numpy, click,
    xacro, the rule registry, ~60 dataclasses); at the default threshold the collector
    walks them again and again before validate's first finding: about 80 collections,
    a fifth of check_urdf's whole run in CPU time (issue 29 item 7). Cycles are still
    collected (an expansion's DOM), every GC_YOUNG_THRESHOLD allocations, so a run over
    many models keeps its memory bounded.
    """
    _young, *older = gc.get_threshold()
    gc.set_threshold(GC_YOUNG_THRESHOLD, *older)


def _quiet_stdout() -> None:
    """Point stdout at /dev/null so the interpreter's final flush of a dead stdout is silent."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError):
        pass
