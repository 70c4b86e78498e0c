"""The generalized-α method on the compiled kernels against BDF (issue 26, item 4).

Two checks of ``simulate(..., method="generalized-alpha")`` against scipy's BDF on the
reference side (Pinocchio) at rtol 1e-10, the error being the largest
``|q − q_BDF|`` over the method's steps (BDF's cubic Hermite between its own steps):

1. a hanging chain of 20 bodies on 6-DOF elastic pairs (120 coordinates, every bushing
   on one pair: the iteration matrix is exact but for gravity's stiffness and the
   velocity terms), from rest over 1 s, at each rtol;
2. the scenes whose bushings span several pairs (left out of the iteration matrix:
   Newton converges on them more slowly), from a start displaced by 1e-3 (seed 1) over
   2 s at rtol 1e-6.

Each row gives the error, the motion's scale, the steps (rejected), the residual
evaluations, the energy balance's drift and both wall times (one run each: the
machine's load moves them). Written to ``validation/results/generalized_alpha.md``.

    python validation/generalized_alpha.py [--rtols 1e-6 1e-8]
"""

from __future__ import annotations

import argparse
import subprocess
from datetime import date
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicHermiteSpline

from rt70.guards.atomic import atomic_write
from rt70.model.scene import load_scene, scene_from_text
from rt70.scenes.synthetic import elastic_chain
from rt70.simulation.simulate import simulate

OUT = Path(__file__).parent / "results" / "generalized_alpha.md"
#: Scenes with bushings across pairs (``MotionData.local`` False).
ACROSS = ("three_masses", "gear_reducer", "rt70_azimuth", "rt70_elevation")


def compare(scene, span: float, x0, rtol: float) -> str:
    """One table row: the method at ``rtol`` against BDF at 1e-10 (module docstring).

    Parameters
    ----------
    scene : rt70.model.scene.Scene
        The scene.
    span : float
        Simulated time, s.
    x0 : (q0, q̇0) or None
        The start (None: rest at q = 0).
    rtol : float
        The method's relative tolerance.
    """
    ga = simulate(scene, (0.0, span), x0, method="generalized-alpha", rtol=rtol)
    bdf = simulate(scene, (0.0, span), x0, method="BDF", rtol=1e-10)
    spline = CubicHermiteSpline(bdf.t, bdf.q, bdf.qd, axis=0)
    error = float(np.max(np.abs(ga.q - spline(ga.t))))
    scale = float(np.max(np.abs(bdf.q)))
    rejected = ga.message.split(", ")[1].split()[0]
    return (
        f"| {scene.name} | {scene.textbook.nv} | {rtol:g} | {error:.2e} | {scale:.2e} | "
        f"{ga.n_steps} ({rejected}) | {ga.nfev} | {ga.relative_drift:.1e} | "
        f"{ga.wall_time_s:.2f} | {bdf.wall_time_s:.2f} |"
    )


def main() -> None:
    """Run both checks, print the table and write it."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rtols", type=float, nargs="+", default=[1e-6, 1e-8])
    args = parser.parse_args()
    head = (
        "| scene | nv | rtol | max abs error | motion's scale | steps (rejected) | "
        "evaluations | energy drift | generalized-α s | BDF 1e-10 s |\n"
        "|---|---|---|---|---|---|---|---|---|---|"
    )
    chain = scene_from_text(elastic_chain(20, hanging=True), "hanging_chain_20")
    rows = [compare(chain, 1.0, None, rtol) for rtol in args.rtols]
    for name in ACROSS:
        scene = load_scene(name)
        n = scene.textbook.nv
        x0 = (1e-3 * np.random.default_rng(1).standard_normal(n), np.zeros(n))
        rows.append(compare(scene, 2.0, x0, 1e-6))
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True, cwd=Path(__file__).parent).stdout.strip()  # fmt: skip
    text = "\n".join([
        "# The generalized-α method against BDF",
        "",
        f"> `python validation/generalized_alpha.py` · commit {commit} · {date.today()}",
        "",
        head,
        *rows,
        "",
    ])  # fmt: skip
    print(text)
    atomic_write(OUT, lambda tmp: tmp.write_text(text, encoding="utf-8"))


if __name__ == "__main__":
    main()
