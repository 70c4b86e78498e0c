"""The spin-up beam: geometric stiffening of <rt70:beam>, and a linear-modes model's divergence.

Kane, Ryan & Banerjee (J. Guidance 10(2):139–151, 1987), with the beam's data as the
benchmark is reproduced in the literature (e.g. AeroBeams.jl's ``spinupRobotArm``
example; :mod:`rt70.reports.spin_up` has the models): the tip deflection in the hub's
frame of the rigid-finite-element beam (5, 10, 20 segments) and of the linear-modes model
(10 segments) for Ω_s = 4, 6, 10 rad/s, T = 15 s, over 20 s. The linear model's effective
stiffness ``K − Ω² M`` loses its first mode once Ω passes the first frequency, 3.8 rad/s:
it diverges at all three speeds, while the beam stays bounded.

Writes validation/results/spin_up_beam.{md,png}. Run: ``python validation/spin_up_beam.py``.
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

from rt70.guards.atomic import atomic_write_all  # noqa: E402
from rt70.reports.provenance import command_line, headed, run_header  # noqa: E402
from rt70.reports.spin_up import DURATION, T_UP, tip_linear_modes, tip_rigid_elements  # noqa: E402

OUT = Path(__file__).resolve().parent / "results"
SPEEDS = (4.0, 6.0, 10.0)
SEGMENTS = (5, 10, 20)


def main(argv: list[str] | None = None) -> int:
    """Simulate both models at each spin rate; write the table and the figure."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.parse_args(argv)
    start = time.perf_counter()
    times = np.linspace(0.0, DURATION, 401)
    rfem = {(n, w): tip_rigid_elements(n, w, times) for w in SPEEDS for n in SEGMENTS}
    linear = {w: tip_linear_modes(10, w, times) for w in SPEEDS}
    lines = [
        "| Ω_s, rad/s | model | segments | min tip v, m | at t, s | tip v at 20 s, m |",
        "|---:|---|---:|---:|---:|---:|",
    ]
    for w in SPEEDS:
        for n in SEGMENTS:
            v = rfem[(n, w)]
            k = int(np.argmin(v))
            row = f"| {w:g} | rigid finite elements | {n} | {v[k]:.4f} | {times[k]:.2f} |"
            lines.append(f"{row} {v[-1]:.4f} |")
        v = linear[w]
        k = int(np.nanargmax(np.abs(v)))
        lines.append(
            f"| {w:g} | linear modes | 10 | {np.nanmin(v):.4g} | {times[k]:.2f} | {v[-1]:.4g} |"
        )
    table = "\n".join(lines) + "\n"
    print(table)
    fig, axes = plt.subplots(1, len(SPEEDS), figsize=(5.0 * len(SPEEDS), 4.2))
    for ax, w in zip(axes, SPEEDS, strict=True):
        for n in SEGMENTS:
            ax.plot(times, rfem[(n, w)], label=f"rigid finite elements, {n} segments")
        ax.plot(times, linear[w], "k--", label="linear modes (10 segments)")
        bound = 1.5 * np.abs(rfem[(SEGMENTS[-1], w)]).max()
        ax.set_ylim(-bound, bound)
        ax.set_title(f"Ω_s = {w:g} rad/s, T = {T_UP:g} s")
        ax.set_xlabel("time, s")
        ax.grid(True, alpha=0.3)
    axes[0].set_ylabel("tip deflection in the hub frame, m")
    axes[0].legend(fontsize=8, loc="upper right")
    fig.suptitle(
        "Spin-up beam (Kane, Ryan & Banerjee 1987): geometric stiffening against linear modes"
    )
    fig.tight_layout()
    page = headed(
        "# Spin-up beam\n\nTip deflection of the spin-up beam (docs/beams.md); figure: "
        "spin_up_beam.png.\n\n" + table,
        run_header(command_line()),
    )
    OUT.mkdir(parents=True, exist_ok=True)
    paths = atomic_write_all(
        {
            OUT / "spin_up_beam.md": lambda tmp: tmp.write_text(page),
            OUT / "spin_up_beam.png": lambda tmp: fig.savefig(tmp, dpi=110, format="png"),
        }
    )
    for path in paths:
        print(f"wrote {path}")
    print(f"total run time {time.perf_counter() - start:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
