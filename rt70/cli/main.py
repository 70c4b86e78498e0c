"""The ``rt70`` command line.

Exit codes: :data:`rt70.cli.session.EXIT_CODES` (the epilog of ``rt70 --help``); ``bench``
prints each target as met or not and exits 0 either way (timings are the machine's, not
a verdict). Input read with a caveat (:class:`~rt70.errors.Rt70Warning`) prints one
``rt70: warning: ...`` line on stderr each. Robots of example-robot-data that rt70
cannot load are listed as ``not loaded: <name>: <reason>`` lines, no error by themselves.

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
import json
import os
import sys
import warnings

from rt70.cli import cart as cli_cart
from rt70.cli import impact as cli_impact
from rt70.cli import modes as cli_modes
from rt70.cli import options, session
from rt70.cli import plant as cli_plant
from rt70.cli import pointing as cli_pointing
from rt70.cli import reactions as cli_reactions
from rt70.cli import simulate as cli_simulate
from rt70.cli import sweep as cli_sweep
from rt70.cli.session import EXIT_BROKEN_PIPE, EXIT_CODES, EXIT_INTERRUPTED, EXIT_TERMINATED
from rt70.errors import Rt70Error


def _validate(args: argparse.Namespace) -> int:
    from rt70.crosscheck.robots import UNEXPECTED, survey
    from rt70.crosscheck.validate import cross_check, format_table
    from rt70.model.scene import URDF_DIR, load_scene, require_coordinates, scene_names

    targets = args.targets or scene_names()
    if not targets:
        raise Rt70Error(f"no target to check: no scene files in {URDF_DIR}")
    balance = args.balance_inertia
    scenes, not_loaded = [], {}
    for t in targets:  # read everything first: bad input exits 2
        if t == "robots" or t.startswith("robot:"):  # example-robot-data (rt70.crosscheck.robots)
            names = None if t == "robots" else [t.removeprefix("robot:")]
            loaded, failed = survey(names, balance_inertia=balance)
            scenes += loaded
            not_loaded.update(failed)
        else:
            scenes.append(load_scene(t, balance_inertia=balance))
    bug = any(reason.startswith(UNEXPECTED) for reason in not_loaded.values())
    if not scenes:  # every robot asked for failed to load: nothing was checked
        reasons = "; ".join(f"{name}: {why}" for name, why in not_loaded.items())
        if bug:
            print(f"rt70: no target could be checked, a bug in rt70: {reasons}", file=sys.stderr)
            return 1
        raise Rt70Error(f"no target could be checked ({reasons})")
    for scene in scenes:  # build both sides first: a model rt70 refuses exits 2
        scene.reference  # noqa: B018  Pinocchio's guards first: cheaper than the mass check
        scene.textbook  # noqa: B018
        require_coordinates(scene)
    records = [r for scene in scenes for r in cross_check(scene, args.samples, args.seed)]
    if args.json:
        print(json.dumps([r.as_dict() for r in records], indent=2))
    else:
        print(format_table(records, args.tolerance))
        print(
            f"\n{len(scenes)} target(s), {args.samples} random states each, seed {args.seed}; "
            f"tolerance {args.tolerance:g} relative to the reference's max-norm."
        )
    for name, reason in not_loaded.items():  # reported, not an error by itself
        print(f"not loaded: {name}: {reason}", file=sys.stderr if args.json else sys.stdout)
    return 0 if all(r.passed(args.tolerance) for r in records) and not bug else 1


def _bench(args: argparse.Namespace) -> int:
    from pathlib import Path

    if args.what == "simulate":
        from rt70.reports import simulation_targets, work_precision, work_precision_results

        say = lambda msg: print(f"  {msg}", file=sys.stderr, flush=True)  # noqa: E731
        rows = work_precision.run(quick=args.quick, progress=say)
        print(work_precision_results.format_table(rows))
        for check in simulation_targets.check(rows, quick=args.quick, progress=say):
            print(check.line())
        for path in work_precision_results.write_results(rows, Path(args.out)):
            print(f"wrote {path}")
        return 0

    from rt70.reports import bench

    sizes = (10, 20, 50) if args.quick else (10, 20, 50, 100, 200, 400)
    rounds = 3 if args.quick else 7
    rows = bench.run(
        sizes=sizes,
        K=args.K,
        rounds=rounds,
        progress=lambda msg: print(f"  {msg}", file=sys.stderr, flush=True),
    )
    print(bench.format_report(rows))
    for path in bench.write_results(rows, Path(args.out)):
        print(f"wrote {path}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``rt70`` command (errors: one line, exit 2)."""
    parser = options.Parser(
        prog="rt70",
        description="Models of flexible structures, cross-checked against Pinocchio.",
        epilog="exit codes: " + "; ".join(f"{code} {what}" for code, what in EXIT_CODES.items()),
    )
    parser.add_argument("--version", action=options.PrintVersion)
    sub = parser.add_subparsers(dest="command", required=True)
    _add_validate_parser(sub)
    _add_bench_parser(sub)
    cli_modes.add_parser(sub)
    cli_plant.add_parser(sub)
    cli_pointing.add_parser(sub, options.add_pointing_arguments)
    cli_reactions.add_parser(sub)
    cli_simulate.add_parser(sub, options.add_pointing_arguments)
    cli_sweep.add_parser(sub)
    cli_cart.add_parser(sub)
    cli_impact.add_parser(sub)
    return parser


def _add_validate_parser(sub: argparse._SubParsersAction) -> None:
    """``rt70 validate``: the cross-check (run by :func:`_validate`)."""
    val = sub.add_parser(
        "validate",
        help="cross-check the textbook algorithm against Pinocchio",
        description="Compare mass matrix, bias, gravity, spring/damper forces, forward "
        "dynamics and energies of the textbook algorithm and Pinocchio on random states.",
    )
    val.add_argument(
        "targets",
        nargs="*",
        metavar="TARGET",
        help="scene name, URDF path, 'robots' (every robot of example-robot-data that "
        "loads) or 'robot:NAME' (default: every scene in urdf/)",
    )
    val.add_argument(
        "--samples", type=options.positive_int, default=10, help="random states per target"
    )
    val.add_argument("--seed", type=options.seed, default=0, help="random seed (≥ 0)")
    val.add_argument(
        "--tolerance", type=options.non_negative_float, default=1e-10, help="relative tolerance"
    )
    val.add_argument("--json", action="store_true", help="print the records as JSON")
    val.add_argument(
        "--balance-inertia",
        action="store_true",
        help="repair rotational inertias of moving links that are not positive definite or "
        "break the triangle inequality (principal moments set to their mean, as MuJoCo's "
        "balanceinertia) instead of refusing them; each repair is reported",
    )
    val.set_defaults(func=_validate)


def _add_bench_parser(sub: argparse._SubParsersAction) -> None:
    """``rt70 bench``: the benchmarks and the work-precision report (run by :func:`_bench`)."""
    ben = sub.add_parser(
        "bench",
        help="benchmark the textbook mass matrix against pin.crba (ratios, one run)",
        description="Per-call and batched textbook A(q) against pin.crba on rt70, ur5, panda "
        "and talos_full, and the growth of its cost on serial chains and balanced trees; "
        "writes CSV and a log-log plot.",
    )
    ben.add_argument(
        "what",
        nargs="?",
        default="mass-matrix",
        choices=("mass-matrix", "simulate"),
        help="mass-matrix (default) or simulate (the work-precision report)",
    )
    ben.add_argument("--K", type=options.batch_size, default=1000, help="batch size")
    ben.add_argument("--quick", action="store_true", help="small sizes, few rounds (a smoke run)")
    ben.add_argument(
        "--out",
        default="rt70-results",
        help="directory for CSV and PNG output (default: rt70-results in the current "
        "directory; validation/*.py write the committed validation/results)",
    )
    ben.set_defaults(func=_bench)


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
