"""The ``rt70`` command line.

Exit codes: :data:`rt70.cli.session.EXIT_CODES` (the epilog of ``rt70 --help``); ``bench``
prints each target as met or not and exits 0 either way (timings are the machine's, not
a verdict). Input read with a caveat (:class:`~rt70.errors.Rt70Warning`) prints one
``rt70: warning: ...`` line on stderr each. Each command is one module of this folder
with ``add_parser(sub)`` and ``run(args)``.

Every option is checked before any work starts (:mod:`rt70.cli.options`); SIGTERM becomes a
normal exit, so outputs being written are cleaned up (:mod:`rt70.guards.atomic`;
the run's guards: :mod:`rt70.cli.session`).

Numerical trouble is an error, never a stray warning beside a result: inside a command
every ``RuntimeWarning`` (numpy's overflow, invalid value, division by zero; scipy's
``LinAlgWarning`` and the Lyapunov solver's marginal eigenvalues) is raised and printed
as the one ``rt70: error:`` line, exit 2 (:func:`rt70.cli.session.warning_guards`); code
that expects such values says so with ``np.errstate`` and checks them. The solvers'
warnings join the run's message, and every integration but ``bench``'s has an evaluation
budget: a run its method cannot integrate stops with one line (:mod:`rt70.simulation.integrators`).
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings

from rt70.cli import bench as cli_bench
from rt70.cli import cart as cli_cart
from rt70.cli import impact as cli_impact
from rt70.cli import modes as cli_modes
from rt70.cli import new as cli_new
from rt70.cli import options, session
from rt70.cli import plant as cli_plant
from rt70.cli import pointing as cli_pointing
from rt70.cli import reactions as cli_reactions
from rt70.cli import servo as cli_servo
from rt70.cli import simulate as cli_simulate
from rt70.cli import sweep as cli_sweep
from rt70.cli import validate as cli_validate
from rt70.cli.session import EXIT_BROKEN_PIPE, EXIT_CODES, EXIT_INTERRUPTED, EXIT_TERMINATED
from rt70.errors import Rt70Error


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``rt70`` command (errors: one line, exit 2)."""
    parser = options.Parser(
        prog="rt70",
        description="Models of flexible structures, cross-checked against Pinocchio.",
        epilog="exit codes: " + "; ".join(f"{code} {what}" for code, what in EXIT_CODES.items()),
    )
    parser.add_argument("--version", action=options.PrintVersion)
    sub = parser.add_subparsers(dest="command", required=True)
    cli_validate.add_parser(sub)
    cli_bench.add_parser(sub)
    cli_modes.add_parser(sub)
    cli_plant.add_parser(sub)
    cli_pointing.add_parser(sub, options.add_pointing_arguments)
    cli_reactions.add_parser(sub)
    cli_servo.add_parser(sub)
    cli_simulate.add_parser(sub, options.add_pointing_arguments)
    cli_sweep.add_parser(sub)
    cli_cart.add_parser(sub)
    cli_new.add_parser(sub)
    cli_impact.add_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit code."""
    argv = sys.argv[1:] if argv is None else argv
    args = build_parser().parse_args(argv)  # bad options: one line, exit 2 (options.Parser)
    guards = session.warning_guards(args.command)  # module docstring
    with (
        session.stop_signals(EXIT_TERMINATED),
        session.checked_stdout(),  # '> file' on a full disk: one line, exit 2
        warnings.catch_warnings(),
        guards,
    ):
        try:
            options.check_outputs(args)  # before any work: a bad output path exits 2 at once
            code = args.func(args)
            sys.stdout.flush()  # a closed pipe shows here, inside the try, not at shutdown
            return code
        except Rt70Error as exc:
            print(f"rt70: error: {exc}", file=sys.stderr)
            return 2
        except RuntimeWarning as exc:  # numpy's floating-point warnings, scipy's LinAlgWarning
            print(f"rt70: error: {session.numerical_failure(argv, exc)}", file=sys.stderr)
            return 2
        except BrokenPipeError:
            # the reader went away (``| head``); Python flushes stdout again at exit:
            # point it at /dev/null (the Python docs' recipe for SIGPIPE)
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
            return EXIT_BROKEN_PIPE
        except KeyboardInterrupt:
            print("rt70: interrupted", file=sys.stderr)
            return EXIT_INTERRUPTED


if __name__ == "__main__":
    sys.exit(main())
