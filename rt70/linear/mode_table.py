"""The rows ``rt70 modes`` prints: one per mode, with its kind, damping and dominant coordinate.

One builder for the unconstrained spectrum (:func:`rt70.cli.modes.run`) and the spectrum on a
constraint manifold (:mod:`rt70.linear.constrained_scene`), whose shapes live in the full
coordinates while the eigenproblem was solved in reduced ones.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from rt70.linear.damped import DampedModes
from rt70.linear.modal import Modes


def mode_rows(
    result: Modes,
    shapes: np.ndarray,
    M: np.ndarray,
    coordinates: Sequence[str],
    with_shapes: bool = True,
) -> list[dict]:
    """One dict per mode, as ``rt70 modes --json`` lists them.

    Parameters
    ----------
    result : Modes
        The eigen-solution (frequencies, masks, damping ratios).
    shapes : ndarray, shape (n, k)
        The mode shapes in the coordinates named by ``coordinates`` (``result.shapes``,
        or ``N φ`` on a constraint manifold), M-orthonormal.
    M : ndarray, shape (n, n)
        The mass matrix of those coordinates: ``shape * (M @ shape)`` is each
        coordinate's share of the mode's kinetic energy (it sums to 1); the largest
        share names the dominant coordinate.
    coordinates : sequence of str
        Names of the n coordinates.
    with_shapes : bool
        Give each row its ``shape`` (the text table does not print them: n² numbers for
        a model of n coordinates).

    Returns
    -------
    list of dict
        ``mode`` (1-based), ``freq_hz`` (None when unstable), ``kind`` (``elastic``,
        ``rigid``, ``unstable``, or ``overdamped`` when ξ ≥ 1), ``divergence_rate``
        (``√(−ω²)`` of an unstable mode, else None), ``zeta`` (None when undefined),
        ``dominant`` and ``shape`` (``{coordinate: value}``).
    """
    energy = shapes * (M @ shapes)  # kinetic-energy share per coordinate
    rows = []
    for i in range(len(result.freq_hz)):
        unstable = bool(result.negative[i])
        zeta = None
        if result.zeta is not None and not np.isnan(result.zeta[i]):
            zeta = float(result.zeta[i])
        kind = "unstable" if unstable else "rigid" if result.rigid[i] else "elastic"
        if kind == "elastic" and zeta is not None and zeta >= 1.0:
            kind = "overdamped"  # ζ ≥ 1: it creeps back, it does not ring
        rows.append(
            {
                "mode": i + 1,
                "freq_hz": None if unstable else float(result.freq_hz[i]),
                "kind": kind,
                # an unstable mode diverges as exp(λt), λ = √(−ω²)
                "divergence_rate": float(np.sqrt(-result.omega2[i])) if unstable else None,
                "zeta": zeta,
                "dominant": coordinates[int(np.argmax(np.abs(energy[:, i])))],
            }
        )
        if with_shapes:
            rows[-1]["shape"] = dict(zip(coordinates, shapes[:, i].tolist(), strict=True))
    return rows


def damped_summary(result: Modes, damped: DampedModes, n: int | None = None) -> dict:
    """The damped system's oscillatory pairs and real eigenvalues, as ``rt70 modes`` lists them.

    Parameters
    ----------
    result : Modes
        The undamped modes (their damping's proportionality).
    damped : DampedModes
        The damped system's eigenvalues (all, or those found nearest zero).
    n : int, optional
        The number of coordinates (default: the modes of ``result``, all of them).
    """
    return {
        "oscillatory": [
            {"freq_hz": float(f), "zeta": float(z)}
            for f, z in zip(damped.frequencies_hz, damped.zeta, strict=True)
        ],
        "real_eigenvalues": damped.real.tolist(),
        "proportional": bool(result.proportional),
        # how many of the state matrix's 2n eigenvalues these are (rt70.linear.damped_lowest)
        "eigenvalues_found": len(damped.eigenvalues),
        "eigenvalues_total": 2 * (len(result.freq_hz) if n is None else n),
    }
