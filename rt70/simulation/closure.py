"""Whether a scene's loops can close at all, and the refusal of a model whose loops cannot.

:func:`closure_search` looks for a closed configuration from q = 0 and seeded random
starts; :func:`require_closable` refuses a model whose loops cannot close (lengths that
do not reach, loops that contradict each other) with
:class:`~rt70.errors.LoopClosureError` naming the file, the loops and the residual,
rather than failing later as a Newton iteration or a disagreement between the sides.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np

from rt70.errors import LoopClosureError, Rt70Error
from rt70.model.scene import Scene
from rt70.simulation.loop_constraints import (
    CLOSURE_TOL,
    closed_test,
    newton,
    residual_and_jacobian,
    scene_constraints,
    stacked,
)
from rt70.urdf.description import Loop

#: Seeded random starts of :func:`closure_search` after q = 0 (each coordinate uniform
#: in ±π): a reproducible search, not a proof — a loop that closes only in a region these
#: miss would be refused.
CLOSURE_STARTS = 12

#: Residual evaluations of the least-squares descent from each start.
MAX_DESCENT = 100

#: Newton steps after the descent (quadratic convergence from near closure).
MAX_POLISH = 8


@dataclass(frozen=True)
class Closure:
    """What :func:`closure_search` found.

    Attributes
    ----------
    q : numpy.ndarray
        A closed configuration, or the least-squares minimum with the smallest ``|Φ|``.
    phi : numpy.ndarray
        Φ there (the rows searched).
    closed : bool
        Whether ``q`` closes the loops (:data:`~rt70.simulation.loop_constraints.CLOSURE_TOL`).
    starts : int
        Starts tried.
    """

    q: np.ndarray
    phi: np.ndarray
    closed: bool
    starts: int


def closure_search(
    scene: Scene,
    side: str = "textbook",
    loops: Sequence[str] | None = None,
    tol: float = CLOSURE_TOL,
) -> Closure:
    """Look for a configuration that closes the scene's loops (all, or those named).

    From q = 0 and :data:`CLOSURE_STARTS` seeded random configurations, a trust-region
    least-squares descent of ``½|Φ|²`` (``scipy.optimize.least_squares``, with B_c as its
    Jacobian) then Newton's method; the first closed configuration is returned, or the
    least-squares minimum with the smallest ``|Φ|`` — the loops' frames come no closer
    than that from any start tried.

    Parameters
    ----------
    scene : Scene
        The scene with loops.
    side : {"textbook", "reference"}
        Whose kinematics compute Φ and B_c.
    loops : sequence of str, optional
        Names of the loops to close (default all).
    tol : float
        Closure tolerance (:data:`~rt70.simulation.loop_constraints.CLOSURE_TOL`).

    Raises
    ------
    Rt70Error
        If Φ or B_c is not finite at every start.
    """
    constraints = scene_constraints(scene, side)
    n = scene.textbook.nv
    residual_jacobian = residual_and_jacobian(constraints, _rows_of(scene, loops))
    closed = closed_test(scene, side, tol)
    rng = np.random.default_rng(0)
    starts = [np.zeros(n)] + [rng.uniform(-np.pi, np.pi, n) for _ in range(CLOSURE_STARTS)]
    best: Closure | None = None
    for k, start in enumerate(starts, start=1):
        descent = _descend(residual_jacobian, start)
        if descent is None:  # not finite at the start
            continue
        q, phi = descent
        q, phi, ok = (q, phi, True) if closed(q, phi) else _polish(residual_jacobian, q, closed)
        if ok:
            return Closure(q, phi, True, k)
        if best is None or np.linalg.norm(descent[1]) < np.linalg.norm(best.phi):
            best = Closure(*descent, False, len(starts))  # a least-squares minimum
    if best is None:
        raise Rt70Error(f"{scene.path}: the loops' Φ is not finite at any start of the search")
    return best


def _rows_of(scene: Scene, names: Sequence[str] | None) -> np.ndarray | slice:
    """Rows of Φ that belong to the loops named (all without names)."""
    if names is None:
        return slice(None)
    rows, at = [], 0
    for loop in scene.description.loops:
        if loop.name in names:
            rows += range(at, at + loop.rows)
        at += loop.rows
    return np.array(rows, dtype=int)


def _descend(residual_jacobian, start: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """``(q, Φ)`` at the local minimum of ``½|Φ|²`` a trust-region descent reaches from ``start``.

    None if Φ or B_c is not finite at the start.
    """
    import scipy.optimize  # a closed loop's start only: not every run's import

    cache: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}

    def evaluate(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # Φ and B_c in one pass
        key = q.tobytes()
        if key not in cache:
            cache.clear()
            cache[key] = residual_jacobian(q)
        return cache[key]

    try:
        fit = scipy.optimize.least_squares(
            lambda q: evaluate(q)[0],
            start,
            jac=lambda q: evaluate(q)[1],
            method="trf",
            max_nfev=MAX_DESCENT,
        )
    except (ValueError, np.linalg.LinAlgError):
        return None
    return fit.x, evaluate(fit.x)[0]


def _polish(residual_jacobian, q: np.ndarray, closed) -> tuple:
    """Newton (:data:`MAX_POLISH` steps) from near closure: ``(q, Φ, closed)``."""
    return newton(residual_jacobian, q, np.arange(q.size), closed, MAX_POLISH)


def require_closable(
    scene: Scene, sides: Sequence[str] = ("textbook", "reference"), tol: float = CLOSURE_TOL
) -> None:
    """Refuse a scene whose loops cannot close, naming the file, the loops and the residual.

    Each side in ``sides`` searches (:func:`closure_search`); the scene is refused when
    no side finds a closed configuration. The loops that cannot close on their own are
    named as such; if each closes alone, the loops contradict each other.

    Parameters
    ----------
    scene : Scene
        The scene, its ``<rt70:loop>`` elements (without loops nothing is checked).
    sides : sequence of {"textbook", "reference"}
        The sides that search; the first one's closest configuration is reported.
    tol : float
        Closure tolerance (:data:`~rt70.simulation.loop_constraints.CLOSURE_TOL`).

    Raises
    ------
    LoopClosureError
        If the loops cannot close on any side in ``sides``.
    """
    loops = scene.description.loops
    if not loops:
        return
    found: dict[str, Closure] = {}
    for side in sides:
        found[side] = closure_search(scene, side, tol=tol)
        if found[side].closed:
            return
    side = sides[0]
    closure = found[side]
    alone = (
        {loops[0].name: closure}
        if len(loops) == 1
        else {loop.name: closure_search(scene, side, [loop.name], tol) for loop in loops}
    )
    stuck = [name for name, c in alone.items() if not c.closed]
    what = (
        _names(stuck) + " cannot close"
        if stuck
        else _names([loop.name for loop in loops]) + " contradict each other: each closes alone"
    )
    by_loop = ", ".join(_apart(loop, part) for loop, part in _per_loop(scene, closure.phi))
    there = [  # every other side's Φ at the same configuration
        f"{_SIDE_NAMES[s]} there: "
        + ", ".join(
            _apart(loop, part) for loop, part in _per_loop(scene, _phi(scene, s, closure.q))
        )
        for s in sides
        if s != side
    ]
    raise LoopClosureError(
        f"{scene.path}: {what}; the closest configuration found ({closure.starts} starts, "
        f"{' and '.join(_SIDE_NAMES[s] for s in sides)}) leaves {by_loop}"
        + (f" ({'; '.join(there)})" if there else "")
        + ": the model contradicts itself (check the link lengths and the loops' xyz/rpy)"
    )


#: How messages name the sides.
_SIDE_NAMES = {"textbook": "the textbook", "reference": "Pinocchio"}


def _phi(scene: Scene, side: str, q: np.ndarray) -> np.ndarray:
    """Φ(q) of every loop on ``side``."""
    return stacked(scene_constraints(scene, side), q)[0]


def _names(names: Sequence[str]) -> str:
    """``loop 'a'`` or ``loops 'a', 'b'``."""
    quoted = ", ".join(f"'{n}'" for n in names)
    return f"loop {quoted}" if len(names) == 1 else f"loops {quoted}"


def _per_loop(scene: Scene, phi: np.ndarray) -> Iterator[tuple[Loop, np.ndarray]]:
    """``(loop, its rows of Φ)`` for every loop."""
    at = 0
    for loop in scene.description.loops:
        yield loop, phi[at : at + loop.rows]
        at += loop.rows


def _apart(loop: Loop, phi: np.ndarray) -> str:
    """``loop 'a' 0.15 m apart`` (and the angle for a ``frame`` loop)."""
    text = f"loop '{loop.name}' {np.linalg.norm(phi[:3]):.3g} m apart"
    if loop.rows == 6:
        text += f" and {np.linalg.norm(phi[3:]):.3g} rad turned"
    return text
