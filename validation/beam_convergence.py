"""Beams as rigid finite elements: frequency errors against beam theory as segments grow.

Three members, each ``<rt70:beam>`` read by both sides (the frequencies from the linear
model, every coordinate but the x–z bending locked, :mod:`rt70.scenes.beam_scenes`):

- a slender steel bar (10 mm square, L = 20 m) clamped and free–free, against
  Euler–Bernoulli's closed form (rotary inertia shifts its f3 by 3e-6);
- the same bar at L = 2 m against the exact Rayleigh beam (with the sections' rotary
  inertia), which the division converges to;
- a stubby one (0.2 m square, L = 2 m, L/h = 10, shear area 5/6 A), clamped, against the
  exact Timoshenko beam.

For each: the relative error of f1, f2, f3 at 5, 10, 20, 40 segments, the order measured
between the last two, and the number of coordinates. Writes
validation/results/beam_convergence.{md,png} (atomically).
Run: ``python validation/beam_convergence.py`` (about a minute).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import matplotlib
import matplotlib.ticker

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from rt70.fe.beam_theory import UniformBeam  # noqa: E402
from rt70.guards.atomic import atomic_write_all  # noqa: E402
from rt70.reports.provenance import command_line, headed, run_header  # noqa: E402
from rt70.scenes.beam_scenes import STEEL_BAR, beam_text, xz_bending_frequencies  # noqa: E402

OUT = Path(__file__).resolve().parent / "results"
SEGMENTS = (5, 10, 20, 40)
STUBBY = {**STEEL_BAR, "A": 4e-2, "Iy": 1.333e-4, "Iz": 1.333e-4, "J": 2.25e-4}
STUBBY_SHEAR = 4e-2 * 5 / 6


def cases() -> list[dict]:
    """Each case: its label, the beam text for n segments and the exact frequencies."""
    bar = STEEL_BAR
    slender = UniformBeam(20.0, bar["E"] * bar["Iy"], bar["rho"] * bar["A"])
    short = UniformBeam(2.0, bar["E"] * bar["Iy"], bar["rho"] * bar["A"], bar["rho"] * bar["Iy"])
    stubby = UniformBeam(
        2.0,
        STUBBY["E"] * STUBBY["Iy"],
        STUBBY["rho"] * STUBBY["A"],
        STUBBY["rho"] * STUBBY["Iy"],
        STUBBY["G"] * STUBBY_SHEAR,
    )
    shear = f'Asy="{STUBBY_SHEAR!r}" Asz="{STUBBY_SHEAR!r}"'
    return [
        dict(
            label="cantilever, L/r = 6900, vs Euler–Bernoulli",
            text=lambda n: beam_text(n, "cantilever", 20.0, bar, 'axial="false"'),
            exact=slender.euler_bernoulli("cantilever"),
        ),
        dict(
            label="free–free, L/r = 6900, vs Euler–Bernoulli",
            text=lambda n: beam_text(n, "free-free", 20.0, bar, 'axial="false"'),
            exact=slender.euler_bernoulli("free-free"),
        ),
        dict(
            label="cantilever, L/r = 690, vs Rayleigh (exact)",
            text=lambda n: beam_text(n, "cantilever", 2.0, bar, 'axial="false"'),
            exact=short.frequencies("cantilever"),
        ),
        dict(
            label="free–free, L/r = 690, vs Rayleigh (exact)",
            text=lambda n: beam_text(n, "free-free", 2.0, bar, 'axial="false"'),
            exact=short.frequencies("free-free"),
        ),
        dict(
            label="stubby cantilever, L/h = 10, vs Timoshenko (exact)",
            text=lambda n: beam_text(n, "cantilever", 2.0, STUBBY, f'axial="false" {shear}'),
            exact=stubby.frequencies("cantilever"),
        ),
    ]


def measure() -> list[dict]:
    """Relative errors of f1..f3 per case and segment count."""
    rows = []
    for case in cases():
        for n in SEGMENTS:
            f = xz_bending_frequencies(case["text"](n))
            rows.append(
                dict(case=case["label"], n=n, exact=case["exact"], error=f / case["exact"] - 1)
            )
    return rows


def table(rows: list[dict]) -> str:
    """The markdown table of errors and measured orders."""
    lines = [
        "| member | segments | f1 exact, Hz | f1 error | f2 error | f3 error |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        e = r["error"]
        lines.append(
            f"| {r['case']} | {r['n']} | {r['exact'][0]:.5g} | {e[0]:+.2e} | {e[1]:+.2e} | "
            f"{e[2]:+.2e} |"
        )
    lines += [
        "",
        "| member | order f1 | order f2 | order f3 (20 → 40 segments) |",
        "|---|---:|---:|---:|",
    ]
    for label in dict.fromkeys(r["case"] for r in rows):
        e20, e40 = (
            next(r["error"] for r in rows if r["case"] == label and r["n"] == n) for n in (20, 40)
        )
        order = np.log2(np.abs(e20 / e40))
        lines.append(f"| {label} | {order[0]:.2f} | {order[1]:.2f} | {order[2]:.2f} |")
    return "\n".join(lines) + "\n"


def figure(rows: list[dict]):
    """|error| of f1..f3 against segments, one panel per member."""
    labels = list(dict.fromkeys(r["case"] for r in rows))
    fig, axes = plt.subplots(1, len(labels), figsize=(4.0 * len(labels), 4.2), sharey=True)
    n = np.array(SEGMENTS, dtype=float)
    for ax, label in zip(axes, labels, strict=True):
        errs = np.array([r["error"] for r in rows if r["case"] == label])
        for k in range(3):
            ax.loglog(n, np.abs(errs[:, k]), "o-", label=f"f{k + 1}")
        ref = np.abs(errs[0, 2])
        ax.loglog(n, ref * (n[0] / n) ** 2, "k:", lw=1, label="slope −2")
        ax.loglog(n, ref * (n[0] / n) ** 4, "k--", lw=1, label="slope −4")
        ax.axhline(1e-3, color="r", lw=0.8, label="1e-3")
        ax.set_title(label.replace(", vs", "\nvs"), fontsize=9)
        ax.set_xticks(n, [str(int(v)) for v in n])
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_xlabel("primary segments n")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("|f_RFEM / f_exact − 1|")
    axes[0].legend(fontsize=8)
    fig.suptitle("<rt70:beam> as rigid finite elements: frequency error against segments")
    fig.tight_layout()
    return fig


def main(argv: list[str] | None = None) -> int:
    """Measure, print the table and write it with the figure."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.parse_args(argv)
    start = time.perf_counter()
    rows = measure()
    text = table(rows)
    print(text)
    fig = figure(rows)
    OUT.mkdir(parents=True, exist_ok=True)
    page = headed(
        "# Beam convergence\n\nRelative frequency errors of `<rt70:beam>` in x–z bending "
        "against beam theory (docs/beams.md); figure: beam_convergence.png.\n\n" + text,
        run_header(command_line()),
    )
    paths = atomic_write_all(
        {
            OUT / "beam_convergence.md": lambda tmp: tmp.write_text(page),
            OUT / "beam_convergence.png": lambda tmp: fig.savefig(tmp, dpi=110, format="png"),
        }
    )
    for path in paths:
        print(f"wrote {path}")
    print(f"total run time {time.perf_counter() - start:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
