"""Mass-matrix benchmark: textbook S·Θ·Sᵀ (structured, batched, dense) against pin.crba.

Same as ``rt70 bench``; writes validation/results/mass_matrix_bench.{csv,png}.
Run: ``python validation/bench_mass_matrix.py`` (about 2–4 minutes).
"""

import sys

from rt70.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", *sys.argv[1:]]))
