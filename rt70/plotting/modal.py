"""Figures of the modal analysis: Bode diagram, step responses and mode shapes.

Each helper draws on given axes or returns a new :class:`matplotlib.figure.Figure` (no
pyplot state, safe with the Agg backend; saving files is left to the caller). The data
come from :mod:`rt70.linear.modal` (modes) and :mod:`rt70.linear.responses`
(frequency and step responses).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from rt70.linear.checks import _names
from rt70.linear.modal import Modes
from rt70.linear.responses import FrequencyResponse


def _new_figure(nrows: int = 1, sharex: bool = False) -> tuple[Figure, list[Axes]]:
    fig = Figure(figsize=(7.0, 2.6 * nrows + 0.8), layout="constrained")
    axes = fig.subplots(nrows, 1, sharex=sharex, squeeze=False)[:, 0]
    return fig, list(axes)


def plot_bode(
    fr: FrequencyResponse,
    output_index: int = 0,
    input_index: int = 0,
    axes: tuple[Axes, Axes] | None = None,
    label: str | None = None,
    **kwargs: object,
) -> Figure:
    """Bode diagram (ЛАХ/ЛФХ) of one output/input pair: dB and degrees vs log frequency.

    Parameters
    ----------
    fr : FrequencyResponse
        From :func:`rt70.linear.responses.frequency_response`.
    output_index, input_index : int, optional
        Indices of the pair (default 0, 0).
    axes : (Axes, Axes), optional
        Magnitude and phase axes to draw on; default a new figure with two rows.
    label : str, optional
        Legend label (default ``"output / input"``).
    **kwargs
        Passed to :meth:`matplotlib.axes.Axes.semilogx`.

    Returns
    -------
    Figure
        The figure holding the axes.
    """
    if axes is None:
        fig, (ax_m, ax_p) = _new_figure(2, sharex=True)
    else:
        ax_m, ax_p = axes
        fig = ax_m.figure
    label = label or f"{fr.output_names[output_index]} / {fr.input_names[input_index]}"
    ax_m.semilogx(fr.freq_hz, fr.magnitude_db[:, output_index, input_index], label=label, **kwargs)
    ax_p.semilogx(fr.freq_hz, fr.phase_deg[:, output_index, input_index], label=label, **kwargs)
    ax_m.set_ylabel("magnitude, dB")
    ax_p.set_ylabel("phase, deg")
    ax_p.set_xlabel("frequency, Hz")
    for ax in (ax_m, ax_p):
        ax.grid(True, which="both", alpha=0.3)
    ax_m.legend(loc="best", fontsize="small")
    return fig


def plot_step(
    t: np.ndarray,
    y: np.ndarray,
    ax: Axes | None = None,
    labels: Sequence[str] | None = None,
    **kwargs: object,
) -> Figure:
    """Plot step responses: ``y`` of shape (nt,), (nt, p) or (nt, p, m) against t.

    Parameters
    ----------
    t : ndarray, shape (nt,)
        Times (s).
    y : ndarray
        Responses from :func:`rt70.linear.responses.step_response` (every output/input
        pair is drawn).
    ax : Axes, optional
        Axes to draw on; default a new figure.
    labels : sequence of str, optional
        One label per drawn curve.
    **kwargs
        Passed to :meth:`matplotlib.axes.Axes.plot`.

    Returns
    -------
    Figure
        The figure holding the axes.
    """
    if ax is None:
        fig, (ax,) = _new_figure()
    else:
        fig = ax.figure
    y = np.asarray(y)
    curves = y.reshape(y.shape[0], -1)
    for i in range(curves.shape[1]):
        lab = labels[i] if labels is not None else None
        ax.plot(t, curves[:, i], label=lab, **kwargs)
    ax.set_xlabel("time, s")
    ax.set_ylabel("response")
    ax.grid(True, alpha=0.3)
    if labels is not None:
        ax.legend(loc="best", fontsize="small")
    return fig


def plot_mode_shapes(
    modes: Modes,
    names: Sequence[str] | None = None,
    n_modes: int | None = None,
    ax: Axes | None = None,
    include_rigid: bool = False,
) -> Figure:
    """Mode shapes as lines over the coordinates, each scaled to ``max |v| = 1``.

    Parameters
    ----------
    modes : Modes
        From :func:`rt70.linear.modal.modes`.
    names : sequence of str, optional
        Coordinate names for the x axis (default ``q1…``).
    n_modes : int, optional
        Number of modes drawn (default all selected).
    ax : Axes, optional
        Axes to draw on; default a new figure.
    include_rigid : bool, optional
        Also draw rigid modes (default False).

    Returns
    -------
    Figure
        The figure holding the axes; each mode is labelled with its frequency.
    """
    if ax is None:
        fig, (ax,) = _new_figure()
    else:
        fig = ax.figure
    names = _names(names, "q", modes.n, "coordinate")
    idx = np.flatnonzero(np.ones(modes.n, bool) if include_rigid else ~modes.rigid)
    if n_modes is not None:
        idx = idx[:n_modes]
    x = np.arange(modes.n)
    for i in idx:
        v = modes.shapes[:, i]
        ax.plot(x, v / np.max(np.abs(v)), marker="o", label=f"{modes.freq_hz[i]:.4g} Hz")
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.set_xticks(x, names)
    ax.set_ylabel("normalised shape")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    return fig
