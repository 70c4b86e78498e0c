"""Stress cases (stiff, extreme, singular): writes validation/results/stress.md.

Run: ``python validation/stress.py [OUT_DIR] [--quick]`` (about 3 minutes; ``--quick``
runs the reduced smoke-test set in seconds). Each simulation is capped at
``rt70.reports.stress.runs.TIME_CAP_S`` seconds of wall time.
"""

import sys
import time
from pathlib import Path

from rt70.reports.stress.report import write_report

if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--quick"]
    out = Path(args[0]) if args else Path(__file__).parent / "results"
    start = time.perf_counter()
    path = write_report(out, quick="--quick" in sys.argv[1:], log=print)
    print(f"wrote {path} in {time.perf_counter() - start:.0f} s")
