"""The RT-70's wind pointing budget over wind speeds and elevations, and its figures.

One job: run :func:`rt70.telescope.pointing.pointing_budget` over the budget table (wind 5, 10,
15, 20 m/s × elevation 15°, 45°, 90°, front wind) and over a finer grid for the figure
of error against speed, and turn the results into a table (Markdown) and the figures of
:mod:`rt70.plotting.wind`. Used by validation/pointing_budget.py and the notebook.
"""

from __future__ import annotations

from collections.abc import Sequence

from rt70.model.scene import Scene
from rt70.telescope.pointing import (
    BUDGET_OUTPUTS,
    TITLES,
    PointingBudget,
    PointingCase,
    pointing_budget,
)

#: The budget table's wind speeds (m/s) and elevations (°).
TABLE_SPEEDS = (5.0, 10.0, 15.0, 20.0)
TABLE_ELEVATIONS = (15.0, 45.0, 90.0)
#: A useful pointing error at 300 GHz: a tenth of the 70-m dish's beam, arc seconds
#: (docs/wind.md; /work spec antenna-servo.md: 1.22 λ/D ≈ 3.6″).
TARGET_ARCSEC = 0.36


def budget_table(
    scene: Scene,
    speeds: Sequence[float] = TABLE_SPEEDS,
    elevations: Sequence[float] = TABLE_ELEVATIONS,
    azimuth_deg: float = 0.0,
    direction_deg: float | None = None,
) -> list[PointingBudget]:
    """Budgets of every (elevation, speed) pair, elevation-major.

    Parameters
    ----------
    scene : Scene
        The control object, ``load_scene("rt70_servo")``.
    speeds : sequence of float, optional
        Mean wind speeds, m/s (> 0).
    elevations : sequence of float, optional
        Elevations of the pointing, degrees.
    azimuth_deg : float, optional
        Azimuth of the pointing, degrees.
    direction_deg : float or None, optional
        Azimuth the wind blows from, degrees; None: the pointing's azimuth, a front wind
        into the dish.

    Returns
    -------
    list of PointingBudget
        One budget per case, the speeds varying fastest.
    """
    return [
        pointing_budget(scene, PointingCase(e, azimuth_deg, v, direction_deg))
        for e in elevations
        for v in speeds
    ]


def format_table(budgets: Sequence[PointingBudget]) -> str:
    """A Markdown table: one row per case, steady and gust rms of each output."""
    head = ["elevation, °", "wind, m/s"]
    for name, unit in BUDGET_OUTPUTS.items():
        head += [f"{TITLES[name]}: steady, {unit}", f"gust rms, {unit}"]
    head += ["quasi-static share", "loop mode with the largest share"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for b in budgets:
        row = [f"{b.case.elevation_deg:g}", f"{b.case.speed:g}"]
        for name in BUDGET_OUTPUTS:
            row += [f"{b.steady[name]:.3g}", f"{b.gust_rms[name]:.3g}"]
        m = b.modes[0] if b.modes else None
        row += [f"{100 * b.extra['quasi_static_share']:.1f} %"]
        row += [f"{m.label} {m.frequency_hz:.3g} Hz ({100 * m.share:.1f} %)" if m else "—"]
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines)
