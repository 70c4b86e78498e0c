"""Work–precision report of the integrators: error against run time for each method.

Problems: the RT-70's 10 s transient of issue 13 (stiff methods, rtol 1e-4 … 1e-8), the
RT-70 over 2 s (listing damping and the book's ξ = 0.05 variant), the double pendulum
and a 50-body chain; the methods of rt70.simulation.simulate.METHODS but RK23 over rtol 1e-3 … 1e-9,
each against a reference of another method at rtol 1e-12, with the state error and the
centre-of-mass error in metres (see rt70/reports/work_precision.py); then the issue-13
targets (rt70/reports/simulation_targets.py). Writes
validation/results/work_precision.{csv,png}.
Run: ``python validation/work_precision.py [--quick]`` (under 10 minutes; --quick a few
seconds).
"""

import argparse
import sys
import time
from pathlib import Path

from rt70.reports import simulation_targets, work_precision, work_precision_results

OUT = Path(__file__).resolve().parent / "results"


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a smoke run of a few seconds")
    quick = parser.parse_args(argv).quick
    start = time.perf_counter()

    def say(msg: str) -> None:
        print(f"  [{time.perf_counter() - start:6.1f} s] {msg}", file=sys.stderr, flush=True)

    rows = work_precision.run(quick=quick, progress=say)
    print(work_precision_results.format_table(rows))
    for check in simulation_targets.check(rows, quick=quick, progress=say):
        print(check.line())
    for path in work_precision_results.write_results(rows, OUT):
        print(f"wrote {path}")
    print(f"total run time {time.perf_counter() - start:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
