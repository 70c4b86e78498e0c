"""The slewing truss: a modal body in the tree against its FE model with the hub.

The scene ``slewing_truss`` (a 6 × 2 × 2 steel space frame from rt70.fe.truss, clamped to
a hub on a torsion spring) with k of the truss's fixed-interface modes, gravity off,
against the same structure assembled directly from the FE model (rt70.reports.
slewing_truss): the relative error of the first six frequencies as k grows to every
mode (60). Writes validation/results/slewing_truss.{md,png}.
Run: ``python validation/slewing_truss.py`` (a few seconds).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from rt70.guards.atomic import atomic_write_all  # noqa: E402
from rt70.reports.provenance import command_line, headed, run_header  # noqa: E402
from rt70.reports.slewing_truss import (  # noqa: E402
    direct_frequencies,
    interior_dofs,
    modal_frequencies,
)

OUT = Path(__file__).resolve().parent / "results"
COMPARED = 6


def main(argv: list[str] | None = None) -> int:
    """Measure the errors for each k, print and write the table and the figure."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.parse_args(argv)
    start = time.perf_counter()
    exact = direct_frequencies(COMPARED)
    counts = [6, 8, 12, 16, 24, 32, 48, interior_dofs()]
    with tempfile.TemporaryDirectory() as tmp:
        errors = np.array([modal_frequencies(k, Path(tmp), COMPARED) / exact - 1.0 for k in counts])
    head = " | ".join(f"f{j + 1} {exact[j]:.3f} Hz" for j in range(COMPARED))
    lines = [
        "Relative error of each frequency of the scene with k modes against the direct FE",
        "model (hub rotation and every interior DOF, 61 coordinates).",
        "",
        f"| modes k | {head} |",
        "|---:|" + "---:|" * COMPARED,
    ]
    for k, e in zip(counts, errors, strict=True):
        lines.append(f"| {k} | " + " | ".join(f"{x:.1e}" for x in e) + " |")
    table = "\n".join(lines) + "\n"
    print(table)
    fig, ax = plt.subplots(figsize=(7.0, 4.5))
    for j in range(COMPARED):
        ax.semilogy(counts, np.maximum(np.abs(errors[:, j]), 1e-17), "o-", label=f"f{j + 1}")
    ax.set_xlabel("truss modes kept, k")
    ax.set_ylabel("|f_scene / f_FE − 1|")
    ax.set_title("Slewing truss: modal body in the tree against the direct FE model")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(ncol=2)
    fig.tight_layout()
    page = headed(
        "# Slewing truss\n\nA modal body in the tree against its FE model with the hub "
        "(docs/fe-models.md); figure: slewing_truss.png.\n\n" + table,
        run_header(command_line()),
    )
    OUT.mkdir(parents=True, exist_ok=True)
    paths = atomic_write_all(
        {
            OUT / "slewing_truss.md": lambda tmp: tmp.write_text(page),
            OUT / "slewing_truss.png": lambda tmp: fig.savefig(tmp, dpi=110, format="png"),
        }
    )
    for path in paths:
        print(f"wrote {path}")
    print(f"total run time {time.perf_counter() - start:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
