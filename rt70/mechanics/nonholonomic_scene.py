"""A scene's ``<rt70:no_slip>`` constraints, reduced or with multipliers, on either side.

Joins the sides' constraint rows (:mod:`rt70.textbook.no_slip`,
:mod:`rt70.reference.no_slip`) and dynamics to the plain algebra of
:mod:`rt70.physics.nonholonomic` (Algorithm 002-A of companion source 002):

- textbook side: ``A* = 𝔅ᵀ A 𝔅`` and ``a = 𝔅ᵀ (A 𝔅̇ q̇_ind + B q̇)`` from the book's
  mass matrix and velocity-product force (:mod:`rt70.textbook.dynamics`);
- reference side: ``𝔅ᵀ crba 𝔅`` and ``𝔅ᵀ rnea(q, 𝔅 q̇_ind, 𝔅̇ q̇_ind)``;

each with its own ``𝔅`` (from its own A(q)) and ``𝔅̇ q̇`` (from its own ``Ȧ q̇``).
``rt70 validate`` compares the two (rows ``no_slip`` and ``reduced_dynamics``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from rt70.errors import Rt70Error
from rt70.model.scene import Scene
from rt70.model.sides import side_of
from rt70.physics.kkt import KKTSolution
from rt70.physics.nonholonomic import (
    Projection,
    ReducedSystem,
    constrained_dynamics,
    partition,
)
from rt70.urdf.description import NoSlip


def elements(scene: Scene, names: Sequence[str] | None = None) -> list[NoSlip]:
    """The scene's ``<rt70:no_slip>`` elements, all or those called ``names`` (in that order).

    Raises
    ------
    Rt70Error
        If the scene has none, or a name is not one of them.
    """
    found = {e.name: e for e in scene.description.no_slips}
    if not found:
        raise Rt70Error(f"{scene.path}: the scene has no <rt70:no_slip> constraint")
    if names is None:
        return list(found.values())
    missing = [n for n in names if n not in found]
    if missing:
        raise Rt70Error(
            f"{scene.path}: no <rt70:no_slip> called {', '.join(missing)} "
            f"(there are: {', '.join(found)})"
        )
    return [found[n] for n in names]


def constraint_rows(
    scene: Scene, side: str, q: np.ndarray, qd: np.ndarray, names: Sequence[str] | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """``A(q)`` and ``Ȧ q̇`` of the constraints on one side.

    Parameters
    ----------
    scene : Scene
        A scene with ``<rt70:no_slip>`` elements.
    side : {"textbook", "reference"}
        Whose kinematics and dynamics: the book's algorithm or Pinocchio's.
    q : numpy.ndarray, shape (n,)
        Generalised coordinates in the book's order, m or rad.
    qd : numpy.ndarray, shape (n,)
        Generalised velocities, m/s or rad/s.
    names : sequence of str, optional
        The ``<rt70:no_slip>`` elements used, rows in this order (default: all, in the
        file's order).

    Returns
    -------
    tuple of numpy.ndarray
        A, shape (m, n), and ``Ȧ q̇``, shape (m,) in m/s² (rad/s² for an angular row).
    """
    s = side_of(scene, side)
    els = elements(scene, names)
    m, d, no_slip = s.model, s.data, s.no_slip
    return no_slip.constraint_matrix(m, d, q, els), no_slip.constraint_bias(m, d, q, qd, els)


@dataclass(frozen=True)
class SideDynamics:
    """One side's ``M``, velocity-product force ``h = B q̇`` and gravity force ``Q_g``."""

    M: np.ndarray
    h: np.ndarray
    gravity: np.ndarray


def side_dynamics(scene: Scene, side: str, q: np.ndarray, qd: np.ndarray) -> SideDynamics:
    """``M(q)``, ``B(q, q̇) q̇`` and ``Q_g(q)`` on one side (gravity on the right-hand side).

    Parameters
    ----------
    scene : Scene
        The scene.
    side : {"textbook", "reference"}
        Whose kinematics and dynamics: the book's algorithm or Pinocchio's.
    q : numpy.ndarray, shape (n,)
        Generalised coordinates in the book's order, m or rad.
    qd : numpy.ndarray, shape (n,)
        Generalised velocities, m/s or rad/s.
    """
    s = side_of(scene, side)
    m, d, dynamics = s.model, s.data, s.dynamics
    return SideDynamics(
        dynamics.mass_matrix(m, d, q),
        dynamics.bias_force(m, d, q, qd),
        dynamics.gravity_force(m, d, q),
    )


def reduced_system(
    scene: Scene,
    side: str,
    q: np.ndarray,
    qd_ind: np.ndarray,
    independent: Sequence[int],
    Q: np.ndarray | None = None,
    names: Sequence[str] | None = None,
) -> tuple[Projection, ReducedSystem]:
    """Algorithm 002-A on one side: the projection and ``A* q̈_ind + a = Q*``.

    ``Q`` is the generalised force in full coordinates besides gravity (default zero);
    ``Q*`` includes gravity, ``𝔅ᵀ (Q + Q_g)``.

    Parameters
    ----------
    scene : Scene
        A scene with ``<rt70:no_slip>`` elements.
    side : {"textbook", "reference"}
        Whose kinematics and dynamics: the book's algorithm or Pinocchio's.
    q : numpy.ndarray, shape (n,)
        Generalised coordinates in the book's order, m or rad.
    qd_ind : numpy.ndarray, shape (p,)
        The independent velocities, m/s or rad/s.
    independent : sequence of int
        Indices in q of the p independent coordinates (the others are dependent, one
        per constraint row).
    Q : numpy.ndarray, shape (n,), optional
        Generalised force besides gravity, N or N·m per coordinate (default zero).
    names : sequence of str, optional
        The ``<rt70:no_slip>`` elements used, rows in this order (default: all, in the
        file's order).
    """
    s = side_of(scene, side)
    q = np.asarray(q, dtype=float)
    A, _ = constraint_rows(scene, side, q, np.zeros(q.size), names)
    proj = partition(A, independent)
    qd = proj.basis @ np.asarray(qd_ind, dtype=float)
    _, A_dot_qd = constraint_rows(scene, side, q, qd, names)
    rate = proj.rate(A, A_dot_qd)
    Q = np.zeros(q.size) if Q is None else np.asarray(Q, dtype=float)
    A_star, a = s.no_slip.reduced_terms(s.model, s.data, q, qd, proj.basis, rate)
    g = s.dynamics.gravity_force(s.model, s.data, q)
    return proj, ReducedSystem(A_star, a, proj.basis.T @ (Q + g))


def reduced_forward_dynamics(
    scene: Scene,
    side: str,
    q: np.ndarray,
    qd_ind: np.ndarray,
    independent: Sequence[int],
    Q: np.ndarray | None = None,
    names: Sequence[str] | None = None,
) -> np.ndarray:
    """``q̈_ind = A*⁻¹ (Q* − a)`` of the reduced system on one side.

    Parameters
    ----------
    scene : Scene
        A scene with ``<rt70:no_slip>`` elements.
    side : {"textbook", "reference"}
        Whose kinematics and dynamics: the book's algorithm or Pinocchio's.
    q : numpy.ndarray, shape (n,)
        Generalised coordinates in the book's order, m or rad.
    qd_ind : numpy.ndarray, shape (p,)
        The independent velocities, m/s or rad/s.
    independent : sequence of int
        Indices in q of the p independent coordinates (the others are dependent, one
        per constraint row).
    Q : numpy.ndarray, shape (n,), optional
        Generalised force besides gravity, N or N·m per coordinate (default zero).
    names : sequence of str, optional
        The ``<rt70:no_slip>`` elements used, rows in this order (default: all, in the
        file's order).

    Returns
    -------
    numpy.ndarray, shape (p,)
        The independent accelerations, m/s² or rad/s².
    """
    return reduced_system(scene, side, q, qd_ind, independent, Q, names)[1].acceleration()


def constrained_forward_dynamics(
    scene: Scene,
    side: str,
    q: np.ndarray,
    qd: np.ndarray,
    Q: np.ndarray | None = None,
    names: Sequence[str] | None = None,
) -> KKTSolution:
    """``q̈`` and the contact forces λ of the full equations with the constraints' multipliers.

    ``M q̈ + B q̇ = Q_g + Q + Aᵀ λ``, ``A q̈ + Ȧ q̇ = 0``
    (:func:`rt70.physics.nonholonomic.constrained_dynamics`).

    Parameters
    ----------
    scene : Scene
        A scene with ``<rt70:no_slip>`` elements.
    side : {"textbook", "reference"}
        Whose kinematics and dynamics: the book's algorithm or Pinocchio's.
    q : numpy.ndarray, shape (n,)
        Generalised coordinates in the book's order, m or rad.
    qd : numpy.ndarray, shape (n,)
        Generalised velocities, m/s or rad/s (admissible: ``A q̇ = 0``).
    Q : numpy.ndarray, shape (n,), optional
        Generalised force besides gravity, N or N·m per coordinate (default zero).
    names : sequence of str, optional
        The ``<rt70:no_slip>`` elements used, rows in this order (default: all, in the
        file's order).
    """
    q = np.asarray(q, dtype=float)
    A, A_dot_qd = constraint_rows(scene, side, q, qd, names)
    dyn = side_dynamics(scene, side, q, qd)
    Q = np.zeros(q.size) if Q is None else np.asarray(Q, dtype=float)
    return constrained_dynamics(dyn.M, dyn.h, Q + dyn.gravity, A, A_dot_qd)


def choose_independent(A: np.ndarray) -> np.ndarray:
    """Independent coordinates for :func:`rt70.physics.nonholonomic.partition`.

    The dependent ones are the first pivots of a column-pivoted QR of A (the
    best-conditioned ``A₂``).
    """
    import scipy.linalg

    _, _, piv = scipy.linalg.qr(np.atleast_2d(A), pivoting=True, mode="economic")
    return np.sort(piv[np.atleast_2d(A).shape[0] :])


# --- rt70 validate's rows (rt70.crosscheck: validate.quantities(), scales.natural_scales())
#: Rows compared for a scene with ``<rt70:no_slip>`` elements.
ROWS = ("no_slip", "reduced_dynamics")


def validate_pairs(scene: Scene, q: np.ndarray, qd: np.ndarray) -> dict:
    """Per row: (textbook evaluation, reference evaluation) at the random state (q, q̇).

    ``no_slip``: ``A(q)`` and ``Ȧ q̇`` stacked. ``reduced_dynamics``: the reduced
    ``q̈_ind`` (002-A; the independent coordinates by :func:`choose_independent` of
    Pinocchio's A, the independent velocities those of q̇) and the multipliers λ of the
    full equations at the admissible ``q̇ = 𝔅 q̇_ind``.

    Parameters
    ----------
    scene : Scene
        A scene with ``<rt70:no_slip>`` elements.
    q : numpy.ndarray, shape (n,)
        The random state's coordinates, m or rad.
    qd : numpy.ndarray, shape (n,)
        Its velocities, m/s or rad/s (need not be admissible).
    """
    from rt70.reference import no_slip as ref_no_slip

    els = elements(scene)
    A_ref = ref_no_slip.constraint_matrix(scene.reference, scene.reference_data, q, els)
    ind = choose_independent(A_ref)
    qd_ind = qd[ind]

    def rows(side: str) -> np.ndarray:
        return np.concatenate([x.ravel() for x in constraint_rows(scene, side, q, qd)])

    def reduced(side: str) -> np.ndarray:
        proj, red = reduced_system(scene, side, q, qd_ind, ind)
        lam = constrained_forward_dynamics(scene, side, q, proj.basis @ qd_ind).lam
        return np.concatenate([red.acceleration(), lam])

    return {
        "no_slip": (lambda: rows("textbook"), lambda: rows("reference")),
        "reduced_dynamics": (lambda: reduced("textbook"), lambda: reduced("reference")),
    }


def simulate_constrained(
    scene: Scene,
    side: str,
    q0: np.ndarray,
    qd0: np.ndarray,
    times: np.ndarray,
    baumgarte: float = 0.0,
    rtol: float = 1e-12,
    atol: float = 1e-13,
):
    """Integrate ``M q̈ + B q̇ = Q_g + Aᵀ λ`` with all the scene's ``<rt70:no_slip>`` rows.

    The acceleration-level constraint is stabilised by a first-order perturbation
    equation (2.2): ``d/dt (A q̇) = −k (A q̇)``, k = ``baumgarte`` (0: none). The state
    is ``[q, q̇]``; returns scipy's solution (DOP853) at ``times``.

    Parameters
    ----------
    scene : Scene
        A scene with ``<rt70:no_slip>`` elements.
    side : {"textbook", "reference"}
        Whose kinematics and dynamics: the book's algorithm or Pinocchio's.
    q0 : numpy.ndarray, shape (n,)
        Initial coordinates, m or rad.
    qd0 : numpy.ndarray, shape (n,)
        Initial velocities, m/s or rad/s (admissible: ``A q̇ = 0``).
    times : numpy.ndarray
        Increasing output times from 0, s; the run ends at the last.
    baumgarte : float
        k, 1/s: the decay rate of the constraints' velocity error (0: none).
    rtol, atol : float
        DOP853's relative and absolute tolerances.
    """
    from scipy.integrate import solve_ivp

    n = len(q0)

    def rhs(_t, s):
        q, qd = s[:n], s[n:]
        A, A_dot_qd = constraint_rows(scene, side, q, qd)
        dyn = side_dynamics(scene, side, q, qd)
        sol = constrained_dynamics(dyn.M, dyn.h, dyn.gravity, A, A_dot_qd + baumgarte * A @ qd)
        return np.concatenate([qd, sol.x])

    times = np.asarray(times, dtype=float)
    return solve_ivp(
        rhs,
        (0.0, float(times[-1])),
        np.concatenate([q0, qd0]),
        method="DOP853",
        t_eval=times,
        rtol=rtol,
        atol=atol,
    )
