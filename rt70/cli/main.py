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

import importlib
import os
import sys
import warnings
from typing import TYPE_CHECKING

from rt70.cli import session, warm_client
from rt70.cli.session import EXIT_BROKEN_PIPE, EXIT_CODES, EXIT_INTERRUPTED, EXIT_TERMINATED
from rt70.errors import Rt70Error

if TYPE_CHECKING:  # argparse itself is imported by the parser, not by a command served warm
    import argparse

#: Every command: its module of this folder (``add_parser(sub)``, ``run(args)``), in the
#: order of ``rt70 --help``; those marked take the pointing arguments as a second argument.
COMMANDS = {
    "validate": ("validate", False),
    "bench": ("bench", False),
    "modes": ("modes", False),
    "plant": ("plant", False),
    "pointing": ("pointing", True),
    "reactions": ("reactions", False),
    "servo": ("servo", False),
    "simulate": ("simulate", True),
    "sweep": ("sweep", False),
    "cart": ("cart", False),
    "new": ("new", False),
    "impact": ("impact", False),
    "warm": ("warm", False),
}


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The argument parser of the ``rt70`` command (errors: one line, exit 2).

    Parameters
    ----------
    only : str, optional
        Build the parser of this command alone (its module alone is imported: a command
        pays for what it uses); ``""``: of none (``rt70 --version``); None: of every
        command (``rt70 --help``, an unknown command's error).
    """
    from rt70.cli import options  # here, not above: a command served warm never needs it

    parser = options.Parser(
        prog="rt70",
        description="Models of flexible structures, cross-checked against Pinocchio.",
        epilog="exit codes: " + "; ".join(f"{code} {what}" for code, what in EXIT_CODES.items()),
    )
    parser.add_argument("--version", action=options.PrintVersion)
    sub = parser.add_subparsers(dest="command", required=True)
    for name, (module, pointing) in COMMANDS.items():
        if only is not None and name != only:
            continue
        command = importlib.import_module(f"rt70.cli.{module}")
        if pointing:
            command.add_parser(sub, options.add_pointing_arguments)
        else:
            command.add_parser(sub)
    return parser


def command_of(argv: list[str]) -> str | None:
    """The command ``argv`` asks for, ``""`` for ``--version`` alone, or None (build all).

    The first word that is not an option names the command; ``--version`` before any
    command needs none. Anything else (help, an unknown command) gets every command's
    parser, so ``--help`` lists them all and a misspelt command is named in the error.
    """
    for word in argv:
        if word == "--version":
            return ""
        if not word.startswith("-"):
            return word if word in COMMANDS else None
        if word in ("-h", "--help"):
            return None
    return None


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit code.

    In a worker of the warm process when one serves this request
    (:mod:`rt70.cli.warm_client`), else here (:func:`run_here`).
    """
    argv = sys.argv[1:] if argv is None else argv
    try:
        code = warm_client.run(argv)
    except KeyboardInterrupt:  # Ctrl-C while asking the warm process, before any work
        print("rt70: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    return run_here(argv) if code is None else code


def run_here(argv: list[str]) -> int:
    """Run the command line in this process; return the exit code.

    Parameters
    ----------
    argv : list of str
        The command's words (``sys.argv[1:]``).
    """
    from rt70.cli import options

    parser = build_parser(command_of(argv))
    args = parser.parse_args(argv)  # bad options: one line, exit 2 (options.Parser)
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
