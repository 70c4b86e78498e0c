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


def uncovered(scene, method: str) -> Rt70Error:
    """The error of a compiled method on a scene its kernels do not cover.

    Parameters
    ----------
    scene : Scene
        The scene (its name leads the message).
    method : str
        The compiled method (:data:`GENERALIZED_ALPHA` or :data:`COMPILED_BDF`).
    """
    return Rt70Error(
        f"{scene.name}: method '{method}' runs on the compiled kernels, which do not "
        "cover modal bodies, mimic joints or closed loops; use BDF or LSODA"
    )


def run_compiled(
    method: str,
    scene,
    x0: tuple[np.ndarray, np.ndarray] | None,
    tolerances: tuple[float, float | None],
    refused: dict,
    outputs: tuple,
    integrate: Callable,
):
    """What the compiled methods do around their integration, the same for each.

    Refuses what the method does not take (naming it), checks the outputs at the initial
    state before any work, defaults ``atol`` to ``1e-3 rtol`` (as the other methods'),
    integrates, and evaluates the outputs on the trajectory.

    Parameters
    ----------
    method : str
        The compiled method, named in the refusal.
    scene : Scene
        The scene.
    x0 : (q0, q̇0) or None
        Initial state (the outputs are checked at q0; default q = 0).
    tolerances : (rtol, atol or None)
        The request's tolerances.
    refused : dict
        The request's arguments the method does not take, by name (keys of
        :data:`REFUSED`): each must be None or empty.
    outputs : (outputs, side)
        The quantities evaluated on the trajectory, and the side that evaluates them.
    integrate : callable
        ``integrate((rtol, atol)) -> SimulationResult``.
    """
    from rt70.model.outputs import evaluate, evaluate_trajectory

    asked = [name for name, value in refused.items() if _given(value)]
    if asked:
        raise Rt70Error(
            f"method '{method}' takes no {', '.join(REFUSED[name] for name in refused)}: "
            f"{', '.join(asked)} given; use BDF or LSODA"
        )
    wanted, side = outputs
    if wanted:
        evaluate(scene, np.zeros(scene.textbook.nv) if x0 is None else x0[0], wanted, side)
    rtol, atol = tolerances
    result = integrate((rtol, 1e-3 * rtol if atol is None else atol))
    result.outputs = evaluate_trajectory(scene, result.q, wanted, side)
    result.output_units = {o.name: o.unit for o in wanted}
    return result


#: What each argument :func:`run_compiled` may refuse is, in its message.
REFUSED = {
    "inputs": "input forces",
    "components": "extra state components (drives, servos)",
    "events": "events",
}


def _given(value) -> bool:
    """Whether a refused argument was given: neither None nor an empty sequence."""
    if value is None:
        return False
    try:
        return len(value) > 0
    except TypeError:  # a callable
        return True
