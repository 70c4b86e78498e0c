"""Figures of the wind pointing budget: what an antenna engineer looks at.

Three figures, each from plain arrays (:mod:`rt70.reports.pointing_budget` computes
them): the main mirror's pointing error against the mean wind speed for several
elevations (log–log, steady and gust rms, with the v² law drawn for reference); maps
over elevation × wind direction of the first locked-rotor frequency and of the pointing
error; and the share of each closed-loop mode in the gust error. Agg-safe: figures are
returned, never shown.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib.figure import Figure


def error_vs_speed_figure(
    speeds: Sequence[float],
    steady: Mapping[float, Sequence[float]],
    gust: Mapping[float, Sequence[float]],
    target: float | None = None,
    title: str = "",
) -> Figure:
    """Steady and gust pointing error (″) against wind speed (m/s), one line per elevation.

    ``steady[E]``, ``gust[E]``: values at ``speeds`` for elevation E (degrees).
    ``target``: a horizontal line (e.g. a tenth of the beam width).
    """
    v = np.asarray(speeds, dtype=float)
    fig = Figure(figsize=(8, 5.5), constrained_layout=True)
    ax = fig.subplots()
    for k, elevation in enumerate(sorted(steady)):
        c = f"C{k}"
        ax.loglog(v, steady[elevation], "-o", color=c, ms=4, label=f"steady, E = {elevation:g}°")
        ax.loglog(v, gust[elevation], "--s", color=c, ms=3, label=f"gust rms, E = {elevation:g}°")
    # the v² law through the largest steady value at the middle speed
    mid = len(v) // 2
    top = max(float(np.asarray(steady[e])[mid]) for e in steady)
    ax.loglog(v, top * (v / v[mid]) ** 2, ":", color="0.4", lw=1.0, label="∝ v² (reference)")
    if target is not None:
        ax.axhline(target, color="k", lw=0.8, ls="-.", label=f"{target:g}″ target")
    ax.set_xlabel("mean wind speed, m/s")
    ax.set_ylabel("main-mirror axis error against the source, ″")
    ax.set_title(title or "wind pointing error against wind speed", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    return fig


def maps_figure(
    elevations: Sequence[float],
    directions: Sequence[float],
    frequency: np.ndarray,
    pointing: np.ndarray,
    speed: float,
    title: str = "",
) -> Figure:
    """Maps over elevation × wind direction (relative to the dish's azimuth).

    ``frequency[i, j]`` (Hz) and ``pointing[i, j]`` (″, total: steady + gust rms in
    quadrature or as the caller says) at ``elevations[i]``, ``directions[j]``.
    """
    e = np.asarray(elevations, dtype=float)
    d = np.asarray(directions, dtype=float)
    fig = Figure(figsize=(11, 4.8), constrained_layout=True)
    ax_f, ax_p = fig.subplots(1, 2, sharey=True)
    for ax, data, label, cmap in (
        (ax_f, frequency, "first locked-rotor frequency, Hz", "viridis"),
        (ax_p, pointing, f"pointing error at {speed:g} m/s, ″", "magma"),
    ):
        mesh = ax.pcolormesh(d, e, np.asarray(data), shading="nearest", cmap=cmap)
        fig.colorbar(mesh, ax=ax, label=label)
        ax.set_xlabel("wind direction relative to the dish azimuth, ° (0: front wind)")
        ax.set_title(label, fontsize=9)
    ax_f.set_ylabel("elevation, °")
    fig.suptitle(title or "RT-70 over elevation × wind direction", fontsize=10)
    return fig


def mode_shares_figure(shares: Sequence[tuple[str, float, float]], title: str = "") -> Figure:
    """Bar chart of the modes' shares of the gust variance: ``(label, frequency Hz, share)``."""
    fig = Figure(figsize=(8, 4.5), constrained_layout=True)
    ax = fig.subplots()
    labels = [f"{name}\n{f:.3g} Hz" for name, f, _ in shares]
    values = [100.0 * s for _, _, s in shares]
    ax.bar(range(len(values)), values, color=["C0" if v >= 0 else "C3" for v in values])
    ax.set_xticks(range(len(values)), labels, fontsize=7)
    ax.set_ylabel("share of the gust variance, %")
    ax.set_xlabel("closed-loop mode (dominant state, frequency)")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_title(title or "which modes make the gust pointing error", fontsize=10)
    ax.grid(True, axis="y", alpha=0.3)
    return fig
