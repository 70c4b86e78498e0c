"""Time to build the RT-70 plant for one pointing (issue 10 target: ≤ 0.2 s).

``rt70_servo`` at elevation 45°, azimuth 0: static equilibrium + linearisation + output
rows (the inputs and outputs ``rt70 plant`` builds: the axis torques in; the axis angles,
the optical points, the focal offset and the pointing corrections out), once with the
stiffness differenced on the reference side (the default) and once on the textbook side
(the path before issue 10's second session). Prints the median of ``--repeat`` runs, in
CPU seconds (this process) and wall seconds; the machine is shared, so CPU time is the
figure to quote. Run: ``python validation/bench_plant.py [--repeat N]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from rt70.linear import linearize as lin
from rt70.linear import plant as pl
from rt70.model.outputs import optical_point_outputs
from rt70.model.scene import load_scene
from rt70.scenes.rt70_optics import rt70_mirror_outputs
from rt70.scenes.rt70_state import rt70_pointing

ELEVATION, AZIMUTH = 45.0, 0.0


def build(scene, side: str):
    """Equilibrium, linearisation and output rows: one plant."""
    held = rt70_pointing(ELEVATION, AZIMUTH)
    inputs = [pl.CoordinateInput(f"torque:{a}", a) for a in held]
    outputs = [pl.CoordinateOutput(f"angle:{a}", a) for a in held]
    outputs += optical_point_outputs(scene)
    mirror = rt70_mirror_outputs(scene, ELEVATION, AZIMUTH)
    outputs += [o for o in mirror if o.name in ("focal_offset", "pointing_correction")]
    q0 = lin.equilibrium(scene, held, side=side)
    original = lin.linearize
    lin.linearize = lambda *a, **k: original(*a, **k, side=side)
    try:
        return pl.plant(scene, q0, inputs, outputs)
    finally:
        lin.linearize = original


def main() -> None:
    """Print the median CPU and wall time of each path."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    scene = load_scene("rt70_servo")
    build(scene, "reference")  # warm-up: Pinocchio model, caches
    for side in ("textbook", "reference"):
        cpu, wall = [], []
        for _ in range(args.repeat):
            c, w = time.process_time(), time.perf_counter()
            ss = build(scene, side)
            cpu.append(time.process_time() - c)
            wall.append(time.perf_counter() - w)
        print(
            f"side={side:9s}: {ss.nstates} states, {ss.ninputs} inputs, {ss.noutputs} "
            f"outputs; median {np.median(cpu):.3f} s CPU, {np.median(wall):.3f} s wall "
            f"(of {args.repeat})"
        )


if __name__ == "__main__":
    main()
