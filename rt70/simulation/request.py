"""What a simulation request must satisfy before any work: methods, tolerances, times.

:func:`checked_request` is shared by every method of
:func:`rt70.simulation.simulate.simulate`, the compiled generalized-α method
(:mod:`rt70.simulation.compiled_run`) included, so that each refuses the same bad
arguments with the same message.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from rt70.errors import Rt70Error
from rt70.model.sides import check_side
from rt70.simulation.integrators import COMPILED_BDF, GENERALIZED_ALPHA, METHODS, MIN_RTOL

#: Every method :func:`rt70.simulation.simulate.simulate` takes.
ALL_METHODS = (*METHODS, GENERALIZED_ALPHA, COMPILED_BDF)

Event = Callable[[float, np.ndarray, np.ndarray], float]


def checked_request(
    side: str,
    method: str,
    rtol: float,
    atol: float | None,
    t_span: tuple[float, float],
    t_eval: np.ndarray | None,
    events: Sequence[Event],
) -> tuple[float, float, np.ndarray | None]:
    """``(t0, t1, t_eval)`` of :func:`~rt70.simulation.simulate.simulate`'s arguments, checked.

    Parameters
    ----------
    side : str
        The side (:data:`rt70.model.sides.SIDES`).
    method : str
        One of :data:`ALL_METHODS`.
    rtol, atol : float
        Tolerances (``atol`` None: the method's default).
    t_span : (t0, t1)
        Time interval, s.
    t_eval : array or None
        Output times, s.
    events : sequence of callable
        Event functions g(t, q, q̇).

    Raises
    ------
    Rt70Error
        Naming the first argument that is out of range.
    """
    check_side(side)
    if method not in ALL_METHODS:
        raise Rt70Error(f"unknown method '{method}' (choose from {', '.join(ALL_METHODS)})")
    if not all(callable(g) for g in events):
        raise Rt70Error("events must be callables g(t, q, qd)")
    if not (np.isfinite(rtol) and MIN_RTOL <= rtol < 1.0):
        raise Rt70Error(f"rtol must lie in [{MIN_RTOL:.3g}, 1), got {rtol!r}")
    if atol is not None and not (np.isfinite(atol) and atol > 0.0):
        raise Rt70Error(f"atol must be a positive finite number, got {atol!r}")
    t0, t1 = map(float, t_span)
    if not (np.isfinite(t0) and np.isfinite(t1) and t1 > t0):
        raise Rt70Error(f"bad time span {t_span!r}")
    if t_eval is not None:
        t_eval = np.asarray(t_eval, dtype=float)
        if t_eval.ndim != 1 or not np.all((t_eval >= t0) & (t_eval <= t1)):
            raise Rt70Error(f"t_eval must be a vector of times within [{t0:g}, {t1:g}]")
        if np.any(np.diff(t_eval) <= 0.0):
            raise Rt70Error("t_eval must be increasing")
    return t0, t1, t_eval
