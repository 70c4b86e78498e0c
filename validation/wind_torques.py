"""Steady wind torques about the RT-70's elevation and azimuth axes (docs/wind.md).

The generalised forces on ``base_rx`` (elevation) and ``platform_rz`` (azimuth) of the
``rt70_servo`` scene held undeformed at ``rt70_pointing(E, A = 0)``, in a steady wind of
10 and 20 m/s, both sides of the cross-check; the front wind (direction = azimuth) and
the largest magnitude over wind directions 0°, 5°, …, 355°; and the speed at which each
reaches the book's nominal wind torque 5·10⁵ kgf·m (formalism §4.5). Nothing is tuned.
Run: ``python validation/wind_torques.py`` (a few seconds).
"""

import argparse

import numpy as np

from rt70.model.scene import load_scene
from rt70.physics.aerodynamics import WindCondition
from rt70.reference import wind as ref_wind
from rt70.scenes.rt70_drives import KGF_M
from rt70.scenes.rt70_state import rt70_pointing
from rt70.textbook import wind as tb_wind

#: The book's nominal wind torque, N·m (5·10⁵ kgf·m).
NOMINAL = 5.0e5 * KGF_M

DIRECTIONS = np.arange(0.0, 360.0, 5.0)


def main(argv: list[str] | None = None) -> None:
    """Print the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.parse_args(argv)
    scene = load_scene("rt70_servo")
    names = scene.coordinate_names
    axes = {"elevation": names.index("base_rx"), "azimuth": names.index("platform_rz")}
    ref, rd = scene.reference, scene.reference_data
    tm, td = scene.textbook, scene.textbook_data
    print(f"nominal wind torque 5e5 kgf·m = {NOMINAL:.4g} N·m; azimuth A = 0")
    print(
        f"{'E deg':>5} {'v m/s':>5} {'axis':>9} {'front N·m':>11} {'max|.| N·m':>11} "
        f"{'at dir':>6} {'v_nom front':>11} {'v_nom max':>9} {'tb-ref rel':>10}"
    )
    for E in (15.0, 45.0, 90.0):
        q = np.zeros(len(names))
        for name, value in rt70_pointing(E, 0.0).items():
            q[names.index(name)] = value
        for v in (10.0, 20.0):
            front = ref_wind.wind_force(ref, rd, q, WindCondition(v, 0.0))
            tb = tb_wind.wind_force(tm, td, q, WindCondition(v, 0.0))
            rel = np.abs(tb - front).max() / np.abs(front).max()
            around = np.array(
                [ref_wind.wind_force(ref, rd, q, WindCondition(v, d)) for d in DIRECTIONS]
            )
            for axis, k in axes.items():
                worst = int(np.argmax(np.abs(around[:, k])))
                peak = abs(around[worst, k])

                def reach(torque: float, v=v) -> str:
                    return f"{v * np.sqrt(NOMINAL / abs(torque)):.1f}" if abs(torque) > 1.0 else "-"

                print(
                    f"{E:5.0f} {v:5.0f} {axis:>9} {front[k]:+11.4g} {peak:11.4g} "
                    f"{DIRECTIONS[worst]:6.0f} {reach(front[k]):>11} {reach(peak):>9} {rel:10.1e}"
                )
    print("\nfront wind 10 m/s, elevation torque by element (N·m):")
    for E in (15.0, 45.0, 90.0):
        q = np.zeros(len(names))
        for name, value in rt70_pointing(E, 0.0).items():
            q[names.index(name)] = value
        parts = ref_wind.wind_forces(ref, rd, q, WindCondition(10.0, 0.0))
        row = "  ".join(f"{name} {Q[axes['elevation']]:+.4g}" for name, Q in parts.items())
        print(f"E = {E:2.0f}: {row}")


if __name__ == "__main__":
    main()
