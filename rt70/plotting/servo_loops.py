"""Figures of the servo loops: open-loop Bode with margins, closed-loop Bode compared.

Each helper returns a new :class:`matplotlib.figure.Figure` (no pyplot state; saving is
left to the caller). The data come from :mod:`rt70.control.loop_measures` (frequency
responses, :class:`rt70.control.loop_measures.Margins`) and :mod:`rt70.control.lqg`.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from matplotlib.figure import Figure

from rt70.control.loop_measures import Margins


def _bode_axes(title: str) -> tuple[Figure, object, object]:
    fig = Figure(figsize=(8.0, 6.4), layout="constrained")
    mag, phase = fig.subplots(2, 1, sharex=True)
    fig.suptitle(title)
    mag.set_ylabel("magnitude, dB")
    phase.set_ylabel("phase, degrees")
    phase.set_xlabel("frequency, Hz")
    for ax in (mag, phase):
        ax.grid(True, which="both", alpha=0.3)
    return fig, mag, phase


def plot_open_loops(
    freq_hz: np.ndarray,
    responses: Mapping[str, np.ndarray],
    margins: Mapping[str, Margins],
    title: str,
) -> Figure:
    """Open-loop Bode of several loops, each with its gain and phase crossovers marked.

    Parameters
    ----------
    freq_hz : ndarray
        Frequencies, Hz.
    responses : mapping of label to complex ndarray
        Loop transfers ``L(j2πf)`` broken at their errors (or at the plant input).
    margins : mapping of label to Margins
        The margins of each loop (same labels); the legend gives GM and PM.
    title : str
        The figure's title.
    """
    fig, mag, phase = _bode_axes(title)
    mag.axhline(0.0, color="k", lw=0.8)
    phase.axhline(-180.0, color="k", lw=0.8)
    for label, H in responses.items():
        m = margins[label]
        db = 20 * np.log10(np.abs(H))
        deg = np.degrees(np.unwrap(np.angle(H)))
        # the phase is shown in (−360°, 0°] at high frequency, where the margins are read
        deg -= 360.0 * np.ceil(deg[-1] / 360.0)
        line = mag.semilogx(
            freq_hz,
            db,
            label=f"{label}: GM {m.gm_db:.1f} dB, PM {m.pm_deg:.0f}° at {m.f_gc_hz:.2f} Hz",
        )[0]
        phase.semilogx(freq_hz, deg, color=line.get_color())
        if np.isfinite(m.f_gc_hz):
            mag.plot(m.f_gc_hz, 0.0, "o", color=line.get_color())
            k = np.argmin(np.abs(freq_hz - m.f_gc_hz))
            phase.plot(m.f_gc_hz, deg[k], "o", color=line.get_color())
        if np.isfinite(m.f_pc_hz):
            mag.plot(m.f_pc_hz, -m.gm_db, "s", color=line.get_color())
    mag.set_ylim(-80, 120)
    mag.legend(fontsize=8, loc="lower left")
    return fig


def plot_closed_loops(
    freq_hz: np.ndarray,
    responses: Mapping[str, np.ndarray],
    title: str,
    unit: str = "dB",
) -> Figure:
    """Closed-loop Bode of several controllers on one channel (e.g. reference → axis angle).

    Parameters
    ----------
    freq_hz : ndarray
        Frequencies, Hz.
    responses : mapping of label to complex ndarray
        ``T(j2πf)`` per controller.
    title : str
        The figure's title.
    unit : str
        The magnitude's unit in the axis label (``dB`` of what the title says).
    """
    fig, mag, phase = _bode_axes(title)
    mag.set_ylabel(f"magnitude, {unit}")
    mag.axhline(-3.0, color="k", lw=0.8, ls=":", label="−3 dB")
    for label, H in responses.items():
        line = mag.semilogx(freq_hz, 20 * np.log10(np.abs(H)), label=label)[0]
        phase.semilogx(freq_hz, np.degrees(np.unwrap(np.angle(H))), color=line.get_color())
    mag.set_ylim(-60, 10)  # the servo band; the roll-off far below says little
    mag.legend(fontsize=8, loc="lower left")
    return fig
