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

    Parameters
    ----------
    speeds : sequence of float
        Mean wind speeds, m/s, ascending (the x ticks).
    steady, gust : mapping of float to sequence of float
        Per elevation E (degrees), the steady error and the gust rms error at
        ``speeds``, arcseconds (″).
    target : float, optional
        A horizontal line at this error, ″ (e.g. a tenth of the beam width).
    title : str, optional
        The axes' title (default: "wind pointing error against wind speed").

    Returns
    -------
    matplotlib.figure.Figure
        Log–log axes with the v² law drawn for reference, not shown.
    """
    from matplotlib.ticker import FixedLocator, NullFormatter, ScalarFormatter

    v = np.asarray(speeds, dtype=float)
    fig = Figure(figsize=(8.5, 6), constrained_layout=True)
    ax = fig.subplots()
    markers = "osD^vP*X"
    for k, elevation in enumerate(sorted(steady)):
        c, m = f"C{k}", markers[k % len(markers)]
        ax.loglog(
            v, steady[elevation], "-", marker=m, color=c, ms=5, label=f"steady, E = {elevation:g}°"
        )
        ax.loglog(
            v, gust[elevation], "--", marker=m, color=c, ms=4, mfc="none",
            label=f"gust rms, E = {elevation:g}°",
        )  # fmt: skip
    # the v² law, drawn below the lowest curve so it hides none
    low = min(float(np.min(np.asarray(gust[e]))) for e in gust)
    ax.loglog(v, 0.4 * low * (v / v[0]) ** 2, ":", color="0.3", lw=1.5, label="∝ v² (slope 2)")
    ax.xaxis.set_major_locator(FixedLocator(v))
    ax.xaxis.set_major_formatter(ScalarFormatter())
    ax.xaxis.set_minor_formatter(NullFormatter())
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

    Parameters
    ----------
    elevations : sequence of float
        The rows' elevations, degrees.
    directions : sequence of float
        The columns' wind directions relative to the dish's azimuth, degrees (0: wind
        from the front).
    frequency : ndarray, shape (len(elevations), len(directions))
        The first locked-rotor frequency at each point, Hz.
    pointing : ndarray, shape (len(elevations), len(directions))
        The pointing error at each point, ″ (total: steady and gust rms in quadrature,
        or as the caller says).
    speed : float
        The mean wind speed of ``pointing``, m/s (in its panel's label).
    title : str, optional
        The figure's title (default: "RT-70 over elevation × wind direction").

    Returns
    -------
    matplotlib.figure.Figure
        Two panels side by side, not shown.
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


def mode_shares_figure(
    cases: Sequence[tuple[str, Sequence[tuple[str, float, float]]]], title: str = ""
) -> Figure:
    """Bar charts of the modes' shares of the gust variance, one panel per case.

    ``cases``: ``(case title, [(label, frequency Hz or None, share), …])``; a frequency
    of None prints no frequency (the quasi-static part). Each bar carries its share.
    """
    fig = Figure(figsize=(4.2 * len(cases), 4.8), constrained_layout=True)
    axes = np.atleast_1d(fig.subplots(1, len(cases), sharey=True))
    for ax, (name, shares) in zip(axes, cases, strict=True):
        labels = [label if f is None else f"{label}\n{f:.3g} Hz" for label, f, _ in shares]
        values = [100.0 * s for _, _, s in shares]
        bars = ax.bar(range(len(values)), values, color=["C0" if v >= 0 else "C3" for v in values])
        ax.bar_label(bars, labels=[f"{v:.1f} %" for v in values], fontsize=7)
        ax.set_xticks(range(len(values)), labels, fontsize=7, rotation=20)
        ax.axhline(0.0, color="k", lw=0.6)
        ax.set_title(name, fontsize=9)
        ax.grid(True, axis="y", alpha=0.3)
    axes[0].set_ylabel("share of the gust variance, %")
    fig.suptitle(title or "which modes make the gust pointing error", fontsize=10)
    return fig


def gust_check_figure(runs: Sequence[tuple[dict, Mapping[str, np.ndarray]]]) -> Figure:
    """Nonlinear gust records against the linear loop, and the rms against Lyapunov.

    ``runs``: ``(info, records)`` per wind speed as validation/gust_check.py writes
    them (the JSON's values and the NPZ's arrays ``t``, ``nonlinear_<output>``,
    ``linear_<output>``, ``linear_exact_load_<output>``). Top: a window of the main
    mirror's error (its largest component) in each model; bottom: the record's rms in
    each model against the Lyapunov (ensemble) rms with ±2 standard errors of a record
    of that length.
    """
    name = "main_mirror_error"
    fig = Figure(figsize=(11, 4 + 2.6 * len(runs)), constrained_layout=True)
    axes = fig.subplots(len(runs) + 1, 1)
    for ax, (info, rec) in zip(axes[:-1], runs, strict=False):
        t = rec["t"]
        window = t <= min(t[-1], 200.0)
        nl = rec[f"nonlinear_{name}"]
        k = int(np.argmax(np.abs(nl).max(axis=0)))
        comp = "xyz"[k]
        ax.plot(t[window], nl[window, k], color="k", lw=1.4, label="nonlinear model")
        ax.plot(
            t[window], rec[f"linear_{name}"][window, k], color="C0", lw=0.9,
            label="linear loop, gust 2v̄v′",
        )  # fmt: skip
        ax.plot(
            t[window], rec[f"linear_exact_load_{name}"][window, k], "--", color="C3", lw=0.9,
            label="linear loop, exact load law v′ + v′²/2v̄",
        )  # fmt: skip
        ax.set_ylabel(f"{name}:{comp}, ″")
        ax.set_title(
            f"{info['wind_speed']:g} m/s front wind, elevation {info['elevation_deg']:g}°: "
            f"first {t[window][-1]:.0f} s of the {info['duration_s']:.0f} s record "
            f"(seed {info['seed']})",
            fontsize=9,
        )
        ax.legend(fontsize=7, loc="upper right")
        ax.grid(True, alpha=0.3)
    axes[-2].set_xlabel("time, s")
    ax = axes[-1]
    width = 0.2
    for i, (info, _) in enumerate(runs):
        lyap, err = info["rms_lyapunov"][name], info["rms_statistical_error"][name]
        values = (
            info["rms_nonlinear"][name],
            info["rms_linear_same_gusts"][name],
            info["rms_linear_exact_load_law"][name],
            lyap,
        )
        labels = (
            "nonlinear",
            "linear, same gusts",
            "linear, exact load law",
            "Lyapunov (ensemble)",
        )
        for j, (val, label, color) in enumerate(
            zip(values, labels, ("k", "C0", "C3", "C2"), strict=True)
        ):
            bar = ax.bar(
                i + (j - 1.5) * width, val / lyap, width, color=color,
                label=label if i == 0 else None,
            )  # fmt: skip
            ax.bar_label(bar, labels=[f"{val:.3g}″"], fontsize=7)
        ax.errorbar(i + 1.5 * width, 1.0, yerr=2 * err / lyap, color="k", capsize=4, lw=1)
    ax.set_xticks(range(len(runs)), [f"{info['wind_speed']:g} m/s" for info, _ in runs])
    ax.set_ylabel(f"rms of |{name}| / Lyapunov rms")
    ax.set_ylim(0.0, 1.35)
    ax.set_title(
        "record rms (value on the bar) against the ensemble rms ± 2 standard errors of a "
        "record this long",
        fontsize=9,
    )
    ax.legend(fontsize=7, ncol=4, loc="lower center")
    ax.grid(True, axis="y", alpha=0.3)
    return fig
