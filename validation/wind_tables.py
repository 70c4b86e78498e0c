"""Write the built-in wind coefficient tables rt70/wind_tables/{dish,cylinder}.csv.

The tables are derived, not measured: the derivation is in each file's header and in
docs/wind.md (tests/test_wind.py checks the files against the formulas below). Run:
``python validation/wind_tables.py`` (rewrites both files atomically).
"""

import argparse
from pathlib import Path

import numpy as np

from rt70.guards.atomic import atomic_write

OUT = Path(__file__).resolve().parents[1] / "rt70" / "wind_tables"

THETA_DEG = np.arange(0.0, 180.0 + 1e-9, 5.0)

DISH_HEADER = """\
# rt70 built-in wind coefficient table 'dish': a thin solid paraboloid (f/D ~ 0.3).
# AN ENGINEERING ESTIMATE, NOT A WIND-TUNNEL MEASUREMENT. Derivation (docs/wind.md):
# theta = angle between the dish axis a (boresight, out of the concave face) and the
# direction the wind comes from; theta = 0: the flow hits the concave face head-on.
# axial  C_A = 1.42 cos(theta) for theta <= 90 deg: hollow hemisphere concave to the
#        flow, C_D = 1.42 (Hoerner, Fluid-Dynamic Drag, 1965, ch. 3); 1.17 cos(theta)
#        for theta > 90 deg: the convex back of a shallow dish taken as a flat disc,
#        C_D = 1.17 (same source); cosine law of the normal flow component.
# moment C_M = 0.3 C_A (1 - |cos(theta)|): centre of pressure of an inclined plate at
#        (0.2 + 0.3 sin(a)) D from its leading edge (Joessel's formula, sin(a) =
#        |cos(theta)|), i.e. 0.3 (1 - sin(a)) D ahead of the centre; reference length D.
#        Peak 0.3 * 1.42 / 4 = 0.1065 at theta = 60 deg.
# normal C_N = 0.19 sin(theta)^2: cross-flow principle (Hoerner) on the dish's side
#        profile: depth/D = 1/(16 f/D) ~ 0.21 at f/D = 0.3, projected side area
#        ~ (2/3) D depth ~ 0.18 of the aperture area, times C_D ~ 1.1 -> 0.19.
# Reference area: the aperture pi D^2 / 4; reference length: D.
# The face-on drag 1.42 and the peak elevation-moment coefficient ~0.11 are of the
# magnitudes field-verified on DSN antennas (Gawronski & Mellstrom, TDA PR 42-119,
# 1994; Gawronski, Mellstrom & Bienkiewicz, IEEE AP Magazine 47(5), 2005: within 10 %
# of the JPL wind-tunnel values, Levy & Kurtz, JPL Publication 78-16, 1978, which are
# not available to this project). Users with measured data supply coefficients=FILE.
# Signs: C_A > 0 pushes the dish back along -a; C_N > 0 pushes along the cross-flow;
# C_M > 0 turns the face toward the wind. Written by validation/wind_tables.py.
"""

CYLINDER_HEADER = """\
# rt70 built-in wind coefficient table 'cylinder': a circular cylinder of length L and
# diameter d in cross-flow. AN ENGINEERING ESTIMATE, NOT A WIND-TUNNEL MEASUREMENT.
# theta = angle between the cylinder axis a and the direction the wind comes from.
# normal C_N = 1.2 sin(theta)^2: cross-flow principle (Hoerner, Fluid-Dynamic Drag,
#        1965): the normal flow component's dynamic pressure on a subcritical circular
#        cylinder, C_D = 1.2.  axial C_A = 0 and moment C_M = 0 (no end or skin
#        friction terms; the force acts at the reference point, the cylinder's centre).
# Reference area S = L d; reference length L. Written by validation/wind_tables.py.
"""


def dish_rows(theta_deg: np.ndarray) -> np.ndarray:
    """``[θ°, C_A, C_N, C_M]`` of the dish estimate (header above)."""
    c = np.cos(np.radians(theta_deg))
    c[theta_deg == 90.0] = 0.0
    axial = np.where(theta_deg <= 90.0, 1.42 * c, 1.17 * c)
    moment = 0.3 * axial * (1.0 - np.abs(c))
    normal = 0.19 * np.sin(np.radians(theta_deg)) ** 2
    normal[[0, -1]] = 0.0
    return np.column_stack([theta_deg, axial, normal, moment])


def cylinder_rows(theta_deg: np.ndarray) -> np.ndarray:
    """``[θ°, C_A, C_N, C_M]`` of the cylinder's cross-flow estimate (header above)."""
    normal = 1.2 * np.sin(np.radians(theta_deg)) ** 2
    normal[[0, -1]] = 0.0
    zero = np.zeros_like(theta_deg)
    return np.column_stack([theta_deg, zero, normal, zero])


def table_text(header: str, rows: np.ndarray) -> str:
    """The CSV text: the comment header, the column names, the rows (17 digits)."""
    lines = [header.rstrip("\n"), "theta_deg,axial,normal,moment"]
    lines += [",".join(f"{x:.17g}" for x in row) for row in rows]
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> None:
    """Write both tables."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.parse_args(argv)
    for name, header, rows in (
        ("dish", DISH_HEADER, dish_rows(THETA_DEG)),
        ("cylinder", CYLINDER_HEADER, cylinder_rows(THETA_DEG)),
    ):
        text = table_text(header, rows)
        path = atomic_write(OUT / f"{name}.csv", lambda tmp, t=text: tmp.write_text(t, "utf-8"))
        print(path)


if __name__ == "__main__":
    main()
