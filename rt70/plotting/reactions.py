"""The figure of the RT-70's bearing and reducer loads against elevation.

Four panels from plain arrays (:mod:`rt70.telescope.bearing_loads` computes them): the azimuth
bearing's axial force and overturning moment, the elevation bearings' radial force
(the sector's mesh force taken out) and the elevation reducer's torque, one line per
wind case. Agg-safe: the figure is returned, never shown.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib.figure import Figure

#: (row key, panel title, y label, scale to the plotted unit).
PANELS = (
    ("az_axial_kN", "azimuth bearing: axial force", "axial force, MN", 1e-3),
    ("az_overturning_kNm", "azimuth bearing: overturning moment", "|M_xy|, MN·m", 1e-3),
    ("el_radial_kN", "elevation bearings: radial force (mesh force out)", "|F_yz|, MN", 1e-3),
    ("el_reducer_kNm", "elevation reducer: torque K_el", "K_el, MN·m", 1e-3),
)


def bearing_loads_figure(
    elevations: Sequence[float], rows: Mapping[str, Sequence[Mapping[str, float]]], title: str = ""
) -> Figure:
    """The four loads against elevation (degrees), one line per case of ``rows``.

    Parameters
    ----------
    elevations : sequence of float
        The elevations of the rows, degrees (0 horizon to 90 zenith).
    rows : mapping of str to sequence of mapping
        Per case label (a wind case), one
        :meth:`rt70.telescope.bearing_loads.BearingLoads.row` per elevation: the loads
        in kN and kN·m, plotted in MN and MN·m.
    title : str, optional
        The figure's title (default: "bearing and reducer loads against elevation").

    Returns
    -------
    matplotlib.figure.Figure
        Four panels (:data:`PANELS`), not shown.
    """
    e = np.asarray(elevations, dtype=float)
    fig = Figure(figsize=(10, 7), constrained_layout=True)
    axes = fig.subplots(2, 2, sharex=True).ravel()
    styles = ("-o", "--s", "-.^", ":D")
    for ax, (key, name, ylabel, scale) in zip(axes, PANELS, strict=True):
        for k, (label, values) in enumerate(rows.items()):
            y = np.array([float(r[key]) for r in values]) * scale
            ax.plot(e, y, styles[k % len(styles)], ms=4, label=label)
        ax.set_title(name, fontsize=10)
        ax.set_ylabel(ylabel)
        ax.grid(True, alpha=0.3)
    for ax in axes[2:]:
        ax.set_xlabel("elevation, degrees")
        ax.set_xticks(np.arange(0, 91, 15))
    axes[0].legend(fontsize=8)
    fig.suptitle(title or "bearing and reducer loads against elevation", fontsize=11)
    return fig
