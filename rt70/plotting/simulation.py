"""The figure of a simulation: coordinates, energies and the energy-balance residual.

Agg-safe: the figure is returned, never shown; the caller saves it (``rt70 simulate
--out``, :mod:`rt70.cli.main`).
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure


def simulation_figure(result):
    """Coordinates, energies and the energy-balance residual of a simulation result."""
    fig = Figure(figsize=(9, 8), constrained_layout=True)
    ax_q, ax_e, ax_b = fig.subplots(3, 1, sharex=True)
    ax_q.plot(result.t, result.q, lw=0.8)
    ax_q.set_ylabel("q (m, rad)")
    ax_q.set_title(f"{result.scene}: {result.method} ({result.side}), rtol {result.rtol:g}")
    for name, values in (
        ("kinetic T", result.kinetic),
        ("gravity U_g − U_g(0)", result.gravity - result.gravity[0]),
        ("elastic U_c", result.elastic),
        ("dissipated E_ψ", result.dissipated),
        ("input work W_u", result.input_work),
    ):
        if np.any(values):
            ax_e.plot(result.t, values, label=name)
    ax_e.set_ylabel("energy, J")
    ax_e.legend(fontsize=8)
    ax_b.plot(result.t, result.balance / result.balance_scale)
    ax_b.set_ylabel("balance / exchanged")
    ax_b.set_xlabel("t, s")
    ax_b.set_title(
        f"T + U_g + U_c + E_ψ − W_u − E(0): max {result.relative_drift:.2e} of "
        f"{result.balance_scale:.4g} J",
        fontsize=9,
    )
    for ax in (ax_q, ax_e, ax_b):
        ax.grid(True, alpha=0.3)
    return fig
