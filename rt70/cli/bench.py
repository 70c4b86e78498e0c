"""``rt70 bench``: the mass-matrix benchmark and the integrators' work-precision report.

Timings are the machine's: each target is printed as met or not and the command exits 0
either way (docs: 'Performance', docs/performance.md). The runs:
:mod:`rt70.reports.bench` and :mod:`rt70.reports.work_precision`.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from rt70.cli import options


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """The ``bench`` subcommand: benchmarks and the work-precision report (run by :func:`run`)."""
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
        choices=("mass-matrix", "simulate", "large"),
        help="mass-matrix (default), simulate (the work-precision report) or large (modes, "
        "plant and simulate on a 2004-coordinate chain)",
    )
    ben.add_argument("--K", type=options.batch_size, default=1000, help="batch size")
    ben.add_argument("--quick", action="store_true", help="small sizes, few rounds (a smoke run)")
    ben.add_argument(
        "--out",
        default="rt70-results",
        help="directory for CSV and PNG output (default: rt70-results in the current "
        "directory; validation/*.py write the committed validation/results)",
    )
    ben.set_defaults(func=run)
    return ben


def run(args: argparse.Namespace) -> int:
    """Run the benchmark asked for, print its report and write its files; always 0."""
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

    if args.what == "large":
        from rt70.reports import large_targets

        say = lambda msg: print(f"  {msg}", file=sys.stderr, flush=True)  # noqa: E731
        for check in large_targets.check(quick=args.quick, progress=say):
            print(check.line())
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
