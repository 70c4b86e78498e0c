"""A cubic spline's pieces, evaluated one point at a time in plain floats.

scipy's ``PPoly`` (a ``CubicSpline``) evaluates an array per call, with an array's
overhead; a simulation's right-hand side asks for one point per evaluation (a wind
coefficient at the angle of attack, a gust at the time). :class:`CubicPieces` keeps the
spline's coefficients per interval as Python floats, finds the interval as scipy does
and evaluates the piece by Horner's rule (:func:`horner`). Imports nothing of rt70
(tests/test_import_rules.py, ``SHARED``).
"""

from __future__ import annotations

from bisect import bisect_right

import numpy as np


def horner(c, dx: float) -> float:
    """``c₀ dx³ + c₁ dx² + c₂ dx + c₃`` by Horner's rule (one piece's four coefficients)."""
    return ((c[0] * dx + c[1]) * dx + c[2]) * dx + c[3]


class CubicPieces:
    """The pieces of a cubic spline, per interval, in plain floats.

    Parameters
    ----------
    x : array_like, shape (m + 1,)
        The breakpoints, increasing.
    c : array_like, shape (4, m, ...)
        scipy's coefficients (``PPoly.c``: highest power first, then the interval, then
        the values' own axes).

    Attributes
    ----------
    knots : list of float
        The breakpoints.
    pieces : list
        Per interval, the four coefficients (nested per value axis:
        ``pieces[i][k] = [c₀, c₁, c₂, c₃]`` for a spline of several values).
    """

    def __init__(self, x, c) -> None:
        self.knots = np.asarray(x, dtype=float).tolist()
        self.pieces = np.moveaxis(np.asarray(c, dtype=float), 0, -1).tolist()

    def locate(self, x: float) -> tuple[int, float]:
        """``(i, x − x_i)``: scipy's interval ``x_i ≤ x < x_{i+1}``, the end ones extended."""
        knots = self.knots
        i = min(max(bisect_right(knots, x) - 1, 0), len(knots) - 2)
        return i, x - knots[i]
