"""The slewing truss: a modal body in the tree against its FE model with the hub.

The scene ``slewing_truss`` (a 6 × 2 × 2 steel space frame from rt70.fe.truss, clamped to
a hub on a torsion spring) with k of the truss's fixed-interface modes, gravity off,
against the same structure assembled directly from the FE model (rt70.reports.
slewing_truss): the relative error of the first six frequencies as k grows to every
mode (60). Writes validation/results/slewing_truss.{md,png}; with ``--tip-mass KG`` a
point mass hangs on the truss's far top corner (a link on the node, ``<rt70:interface>``;
in the direct model a mass on the node) and the files are slewing_truss_tip.{md,png}.
Run: ``python validation/slewing_truss.py [--tip-mass 150]`` (a few seconds).
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
    parser.add_argument(
        "--tip-mass", type=float, default=0.0, metavar="KG",
        help="a point mass on the truss's far top corner, kg (default: none)",
    )  # fmt: skip
    args = parser.parse_args(argv)
    if not 0.0 <= args.tip_mass < 1e9:
        parser.error(f"--tip-mass {args.tip_mass!r}: must be ≥ 0 and < 1e9 kg")
    tip = args.tip_mass
    stem = "slewing_truss_tip" if tip > 0.0 else "slewing_truss"
    start = time.perf_counter()
    exact = direct_frequencies(COMPARED, tip)
    counts = [6, 8, 12, 16, 24, 32, 48, interior_dofs()]
    bases = [("fixed-interface modes of the clamped truss", False)]
    if tip > 0.0:
        bases.append(("the corner a boundary node: its 3 constraint modes + k − 3 modes", True))
    errors = []
    with tempfile.TemporaryDirectory() as tmp:
        for _, corner in bases:
            found = [
                modal_frequencies(k - 3 if corner else k, Path(tmp), COMPARED, tip, corner)
                for k in counts
            ]
            errors.append(np.array(found) / exact - 1.0)
    head = " | ".join(f"f{j + 1} {exact[j]:.3f} Hz" for j in range(COMPARED))
    carried = f", a {tip:g} kg mass on the far top corner" if tip > 0.0 else ""
    lines = [
        "Relative error of each frequency of the scene with k modal coordinates against the",
        f"direct FE model (hub rotation and every interior DOF, 61 coordinates{carried}).",
    ]
    for (title, _), err in zip(bases, errors, strict=True):
        lines += ["", f"Basis: {title}.", "", f"| k | {head} |", "|---:|" + "---:|" * COMPARED]
        for k, e in zip(counts, err, strict=True):
            lines.append(f"| {k} | " + " | ".join(f"{x:.1e}" for x in e) + " |")
    table = "\n".join(lines) + "\n"
    print(table)
    fig, axes = plt.subplots(1, len(bases), figsize=(7.0 * len(bases), 4.5), squeeze=False)
    for ax, (title, _), err in zip(axes[0], bases, errors, strict=True):
        for j in range(COMPARED):
            ax.semilogy(counts, np.maximum(np.abs(err[:, j]), 1e-17), "o-", label=f"f{j + 1}")
        ax.set_xlabel("modal coordinates of the truss, k")
        ax.set_ylabel("|f_scene / f_FE − 1|")
        ax.set_title(title, fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(ncol=2)
    fig.suptitle(
        "Slewing truss" + (f", {tip:g} kg on its corner" if tip > 0.0 else "")
        + ": scene against the direct FE model"
    )  # fmt: skip
    fig.tight_layout()
    page = headed(
        "# Slewing truss\n\nA modal body in the tree against its FE model with the hub "
        f"(docs/fe-models.md); figure: {stem}.png.\n\n" + table,
        run_header(command_line()),
    )
    OUT.mkdir(parents=True, exist_ok=True)
    paths = atomic_write_all(
        {
            OUT / f"{stem}.md": lambda tmp: tmp.write_text(page),
            OUT / f"{stem}.png": lambda tmp: fig.savefig(tmp, dpi=110, format="png"),
        }
    )
    for path in paths:
        print(f"wrote {path}")
    print(f"total run time {time.perf_counter() - start:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
