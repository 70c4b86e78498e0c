"""A modal body's truncation error against its nodal model as the number of modes grows.

The space frame of rt70.fe.truss (6 × 5 nodes a layer, 60 nodes, 180 DOF, lumped masses)
as a floating-frame modal body (rt70.textbook.flexible) held by a 3-2-1 support at three
bottom corners, with k of its held modes (rt70.reports.modal_truncation): the relative
error of its first ten elastic free–free frequencies against the FE model's own, for k
from 10 to every mode (174). Writes validation/results/modal_truncation.{md,png}.
Run: ``python validation/modal_truncation.py`` (a few seconds).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from rt70.fe.truss import space_frame  # noqa: E402
from rt70.guards.atomic import atomic_write_all  # noqa: E402
from rt70.reports.modal_truncation import (  # noqa: E402
    body_frequencies,
    held_modes,
    nodal_frequencies,
)
from rt70.reports.provenance import command_line, headed, run_header  # noqa: E402

OUT = Path(__file__).resolve().parent / "results"
COMPARED = 10


def main(argv: list[str] | None = None) -> int:
    """Measure the errors for each k, print and write the table and the figure."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.parse_args(argv)
    start = time.perf_counter()
    fe = space_frame(6, 5)
    index = {node: i for i, node in enumerate(fe.node_ids)}
    support = tuple(index[fe.interfaces[f"corner_{c}"]] for c in (1, 2, 4))
    held = held_modes(fe, support)
    reference = nodal_frequencies(fe)[6 : 6 + COMPARED]
    counts = [10, 15, 20, 30, 40, 60, 80, 100, 120, 150, held.omega2.size]
    errors = np.array([body_frequencies(held, k)[6 : 6 + COMPARED] / reference - 1 for k in counts])
    lines = [
        f"FE model: {fe.name}, {fe.node_xyz.shape[0]} nodes, {3 * fe.node_xyz.shape[0]} DOF; "
        f"frame held at corners 1, 2, 4; first elastic frequency {reference[0]:.4f} Hz.",
        "",
        "| modes k | f1 error | f5 error | f10 error | largest of f1…f10 |",
        "|---:|---:|---:|---:|---:|",
    ]
    for k, e in zip(counts, errors, strict=True):
        lines.append(f"| {k} | {e[0]:.2e} | {e[4]:.2e} | {e[9]:.2e} | {np.abs(e).max():.2e} |")
    table = "\n".join(lines) + "\n"
    print(table)
    fig, ax = plt.subplots(figsize=(7.0, 4.5))
    for j in (0, 4, 9):
        ax.semilogy(counts, np.maximum(np.abs(errors[:, j]), 1e-17), "o-", label=f"f{j + 1}")
    ax.set_xlabel("modes kept, k")
    ax.set_ylabel("|f_body / f_FE − 1|")
    ax.set_title("Modal body against its nodal model: free–free frequencies of the space frame")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    page = headed(
        "# Modal truncation\n\nThe floating-frame modal body against its nodal model "
        "(docs/fe-models.md); figure: modal_truncation.png.\n\n" + table,
        run_header(command_line()),
    )
    OUT.mkdir(parents=True, exist_ok=True)
    paths = atomic_write_all(
        {
            OUT / "modal_truncation.md": lambda tmp: tmp.write_text(page),
            OUT / "modal_truncation.png": lambda tmp: fig.savefig(tmp, dpi=110, format="png"),
        }
    )
    for path in paths:
        print(f"wrote {path}")
    print(f"total run time {time.perf_counter() - start:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
