"""Mass-matrix benchmark: textbook S·Θ·Sᵀ (structured, batched, dense) against pin.crba.

Same as ``rt70 bench``, but writes the committed
validation/results/mass_matrix_bench.{csv,png} (``rt70 bench`` alone writes to
./rt70-results). Run: ``python validation/bench_mass_matrix.py [--quick]`` (about a
minute); another ``--out DIR`` overrides the directory.
"""

import argparse
import sys
from pathlib import Path

from rt70.cli.main import main
from rt70.cli.options import batch_size

OUT = Path(__file__).resolve().parent / "results"

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "what",
        nargs="?",
        choices=("mass-matrix", "simulate"),
        metavar="WHAT",
        help="as `rt70 bench`: mass-matrix (default) or simulate (the work-precision report)",
    )
    parser.add_argument("--K", type=batch_size, help="batch size (default: rt70 bench's)")
    parser.add_argument("--quick", action="store_true", help="small sizes, few rounds")
    parser.add_argument(
        "--out", default=str(OUT), metavar="DIR", help="output directory (validation/results)"
    )
    args = parser.parse_args()
    forwarded = [] if args.what is None else [args.what]
    forwarded += [] if args.K is None else ["--K", str(args.K)]
    forwarded += ["--quick"] if args.quick else []
    sys.exit(main(["bench", *forwarded, "--out", args.out]))
