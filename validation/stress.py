"""Stress cases (stiff, extreme, singular): writes validation/results/stress.md.

Run: ``python validation/stress.py [OUT_DIR] [--quick]`` (about 3 minutes; ``--quick``
runs the reduced smoke-test set in seconds). Each simulation is capped at
``rt70.reports.stress.runs.TIME_CAP_S`` seconds of wall time.
"""

import argparse
import time
from pathlib import Path

from rt70.reports.stress.report import write_report

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "out",
        nargs="?",
        type=Path,
        default=Path(__file__).parent / "results",
        metavar="OUT_DIR",
        help="output directory (default: validation/results)",
    )
    parser.add_argument("--quick", action="store_true", help="the reduced smoke-test set")
    args = parser.parse_args()
    start = time.perf_counter()
    path = write_report(args.out, quick=args.quick, log=print)
    print(f"wrote {path} in {time.perf_counter() - start:.0f} s")
