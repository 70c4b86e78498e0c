"""Work–precision report of the integrators: error against run time for each method.

Problems: the RT-70 (listing damping and the book's ξ = 0.05 variant), the double
pendulum and a 50-body chain; methods RK45, DOP853, Radau, BDF, LSODA over rtol 1e-3 …
1e-9, each against a reference of another method at rtol 1e-12 (see
rt70/reports/work_precision.py). Writes validation/results/work_precision.{csv,png}.
Run: ``python validation/work_precision.py [--quick]`` (under 10 minutes; --quick a few
seconds).
"""

import sys
import time
from pathlib import Path

from rt70.reports import work_precision

OUT = Path(__file__).resolve().parent / "results"


def main(argv: list[str]) -> int:
    quick = "--quick" in argv
    start = time.perf_counter()

    def say(msg: str) -> None:
        print(f"  [{time.perf_counter() - start:6.1f} s] {msg}", file=sys.stderr, flush=True)

    rows = work_precision.run(quick=quick, progress=say)
    print(work_precision.format_table(rows))
    for path in work_precision.write_results(rows, OUT):
        print(f"wrote {path}")
    print(f"total run time {time.perf_counter() - start:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
