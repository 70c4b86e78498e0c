"""Mass-matrix benchmark: textbook S·Θ·Sᵀ (structured, batched, dense) against pin.crba.

Same as ``rt70 bench``, but writes the committed
validation/results/mass_matrix_bench.{csv,png} (``rt70 bench`` alone writes to
./rt70-results). Run: ``python validation/bench_mass_matrix.py [--quick]`` (about a
minute); another ``--out DIR`` overrides the directory.
"""

import sys
from pathlib import Path

from rt70.cli.main import main

OUT = Path(__file__).resolve().parent / "results"

if __name__ == "__main__":
    args = sys.argv[1:]
    if not any(a == "--out" or a.startswith("--out=") for a in args):
        args += ["--out", str(OUT)]
    sys.exit(main(["bench", *args]))
