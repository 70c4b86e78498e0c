"""Outputs: named quantities computed from the state, on either side of the cross-check.

An :class:`Output` is a small formula of the ground-axis positions of a few points of
bodies (``(link, xyz)``, ``xyz`` in the link's frame): each side computes the positions
by its own kinematics (:func:`rt70.textbook.points.point_positions` from the book's
forward pass, :func:`rt70.reference.points.point_positions` from Pinocchio's), and the
formula turns them into the output. The first user is the mirror system's optical
points (``<rt70:optical_point>``, formalism §4.6): each is its own position.

To add an output, write a function that returns an :class:`Output` with its points and
its formula — e.g. a focal-axis direction ``n = (r_f − r_v)/|r_f − r_v|`` (4.155) is
the formula ``lambda p: (p[0] − p[1]) / norm(p[0] − p[1])`` of the focus and the vertex
— and hand it to :func:`evaluate`, :func:`evaluate_trajectory` or
``rt70.simulation.simulate.simulate(..., outputs=...)``; ``rt70 validate`` compares the optical
points on both sides.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from rt70.errors import Rt70Error, ShapeError
from rt70.model.scene import Scene
from rt70.model.sides import check_side, side_of

#: A point of a body: link name and position in the link's frame (m).
Point = tuple[str, tuple[float, float, float]]


def _first_point(positions: np.ndarray) -> np.ndarray:
    return positions[0]


@dataclass(frozen=True)
class Output:
    """A named quantity computed from the positions of some points of bodies.

    Attributes
    ----------
    name : str
        Unique name (a key of the results, a column prefix in saved files).
    unit : str
        Unit of every component ("m", "rad", "1").
    size : int
        Number of components.
    points : tuple of (link, xyz)
        The points the output is computed from.
    formula : callable (positions (len(points), 3)) -> (size,)
        The output from the ground-axis positions of ``points``, in order.
    """

    name: str
    unit: str
    size: int
    points: tuple[Point, ...]
    formula: Callable[[np.ndarray], np.ndarray] = _first_point


def column_labels(name: str, size: int) -> list[str]:
    """Column labels of an output in a table: ``name:x``, ``name:y``, ``name:z`` (size 3).

    ``name:0``, ``name:1``, … for any other size.
    """
    labels = ("x", "y", "z") if size == 3 else [str(i) for i in range(size)]
    return [f"{name}:{c}" for c in labels]


def position_output(name: str, link: str, xyz: Sequence[float]) -> Output:
    """The ground-axis position (3 components, m) of the point ``xyz`` of ``link``.

    Parameters
    ----------
    name : str
        The output's name (its key in the results).
    link : str
        The link the point is fixed to.
    xyz : sequence of float, shape (3,)
        The point in the link's frame, m.
    """
    point = (link, tuple(float(x) for x in np.asarray(xyz, dtype=float).reshape(3)))
    return Output(name, "m", 3, (point,))


def optical_point_outputs(scene: Scene) -> list[Output]:
    """The position of every ``<rt70:optical_point>`` of the scene, in file order (§4.6)."""
    return [position_output(p.name, p.link, p.xyz) for p in scene.description.optical_points]


def _positions(scene: Scene, side: str) -> Callable[[np.ndarray, list[Point]], np.ndarray]:
    """``positions(q, points)`` on the chosen side."""
    s = side_of(scene, side)
    point_positions = s.points.point_positions
    return lambda q, points: point_positions(s.model, s.data, q, points)


def _check(outputs: Sequence[Output], side: str) -> None:
    """Refuse an unknown side (:func:`rt70.model.sides.check_side`) or two outputs of one name."""
    check_side(side)
    counts = Counter(o.name for o in outputs)
    repeated = sorted(n for n, k in counts.items() if k > 1)
    if repeated:
        raise Rt70Error(f"outputs named more than once: {', '.join(repeated)}")


def _apply(outputs: Sequence[Output], positions: np.ndarray) -> dict[str, np.ndarray]:
    """Each output's formula on its slice of the stacked positions."""
    out, start = {}, 0
    for o in outputs:
        value = np.asarray(o.formula(positions[start : start + len(o.points)]), dtype=float)
        if value.shape != (o.size,):
            raise ShapeError(f"output '{o.name}': expected shape ({o.size},), got {value.shape}")
        out[o.name] = value
        start += len(o.points)
    return out


def evaluate(
    scene: Scene, q: np.ndarray, outputs: Sequence[Output], side: str = "textbook"
) -> dict[str, np.ndarray]:
    """Every output at the configuration q, by name, computed on ``side``.

    One kinematics pass for all the outputs' points.

    Parameters
    ----------
    scene : Scene
        The scene, its two sides built from one file.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates in the file's order, rad or m.
    outputs : sequence of Output
        The outputs, their names distinct.
    side : {"textbook", "reference"}
        Whose kinematics place the points.

    Raises
    ------
    UnknownLinkError
        If an output's point is on a link the side has no frame for.
    Rt70Error
        If ``side`` is unknown or two outputs share a name.
    """
    _check(outputs, side)
    if not outputs:
        return {}
    points = [p for o in outputs for p in o.points]
    return _apply(outputs, _positions(scene, side)(q, points))


def evaluate_trajectory(
    scene: Scene, q: np.ndarray, outputs: Sequence[Output], side: str = "textbook"
) -> dict[str, np.ndarray]:
    """Every output along a trajectory ``q`` (n_t × nv), by name: arrays (n_t, size).

    Parameters
    ----------
    scene : Scene
        The scene, its two sides built from one file.
    q : numpy.ndarray, shape (n_t, nv)
        The trajectory's coordinates, one row per sample, rad or m.
    outputs : sequence of Output
        The outputs, their names distinct.
    side : {"textbook", "reference"}
        Whose kinematics place the points.
    """
    _check(outputs, side)
    if not outputs:
        return {}
    positions = _positions(scene, side)
    points = [p for o in outputs for p in o.points]
    q = np.asarray(q, dtype=float)
    out = {o.name: np.empty((len(q), o.size)) for o in outputs}
    for k, qk in enumerate(q):
        for name, value in _apply(outputs, positions(qk, points)).items():
            out[name][k] = value
    return out


# --- linearised outputs: the linear plant's rows C ---------------------------------------

#: Complex step of the formula in position space (m): exact to rounding for a formula
#: without abs/conjugation (:func:`output_matrix`).
COMPLEX_STEP = 1e-30
#: Central-difference step (m) of the check of the complex step; its error is
#: ≲ h²|f'''| + ε|f|/h ≈ 1e-8 relative for formulas over lengths of order 1 m.
CHECK_STEP = 1e-5


def _formula_gradient(o: Output, p: np.ndarray) -> np.ndarray:
    """∂formula/∂positions (size × n_points × 3) by complex step, checked by differences."""
    n = p.shape[0]
    G = np.empty((o.size, n, 3))
    D = np.empty((o.size, n, 3))
    for k in range(n):
        for i in range(3):
            e = np.zeros((n, 3))
            e[k, i] = 1.0
            G[:, k, i] = np.imag(np.asarray(o.formula(p + 1j * COMPLEX_STEP * e))) / COMPLEX_STEP
            plus = np.asarray(o.formula(p + CHECK_STEP * e), dtype=float)
            minus = np.asarray(o.formula(p - CHECK_STEP * e), dtype=float)
            D[:, k, i] = (plus - minus) / (2 * CHECK_STEP)
    scale = max(float(np.max(np.abs(D))), 1e-300)
    if not np.isfinite(G).all() or np.max(np.abs(G - D)) > 1e-5 * scale:
        raise Rt70Error(
            f"output '{o.name}' has no derivative at this state by complex step (it is not "
            "differentiable here — e.g. an angle magnitude at zero; use its vector form — "
            "or its formula takes abs/conjugates)"
        )
    return G


def output_matrix(
    scene: Scene, q0: np.ndarray, outputs: Sequence[Output], side: str = "textbook"
) -> np.ndarray:
    """Rows C (Σ sizes × nv) of the outputs' small-signal response ``δy = C δq`` at q0.

    Chain rule through the point Jacobians: ``C = Σ_k (∂f/∂p_k) J_v,k`` with the exact
    ``J_v`` of each point on ``side`` (:func:`rt70.textbook.points.point_jacobian` or
    :func:`rt70.reference.points.point_jacobian`) and ``∂f/∂p_k`` of the formula by a
    complex step (exact to rounding), checked against central differences
    (:data:`CHECK_STEP`). Rows in the order of ``outputs``, components in order;
    columns are the scene's coordinates (for a
    :class:`rt70.linear.linearize.Linearization` take the columns
    ``coordinate_indices(scene, lm.coordinates)``).

    Parameters
    ----------
    scene : Scene
        The scene, its two sides built from one file.
    q0 : numpy.ndarray, shape (nv,)
        The configuration linearised about, rad or m.
    outputs : sequence of Output
        The outputs, their names distinct.
    side : {"textbook", "reference"}
        Whose kinematics and point Jacobians are used.

    Raises
    ------
    Rt70Error
        If a formula has no derivative at q0 (e.g. an angle magnitude at zero).
    """
    evaluate(scene, q0, outputs, side)  # checks the side, the names, the links, the shapes
    s = side_of(scene, side)
    model, data = s.model, s.data
    point_jacobian, point_positions = s.points.point_jacobian, s.points.point_positions
    q0 = np.asarray(q0, dtype=float)
    jacobians: dict[tuple, np.ndarray] = {}  # J_v of each distinct point, computed once
    rows = []
    for o in outputs:
        p = point_positions(model, data, q0, list(o.points))
        G = _formula_gradient(o, p)
        C = np.zeros((o.size, q0.size))
        for k, (link, xyz) in enumerate(o.points):
            if not np.any(G[:, k]):
                continue
            key = (link, tuple(float(x) for x in xyz))
            if key not in jacobians:
                jacobians[key] = point_jacobian(model, data, q0, link, xyz)[0]
            C += G[:, k] @ jacobians[key]
        rows.append(C)
    return np.vstack(rows) if rows else np.zeros((0, q0.size))
