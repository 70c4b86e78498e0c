"""Static equilibrium on a constraint manifold: ``Q(q) + B_cᵀ λ = 0``, ``Φ(q) = 0``.

One job: find the configuration q* on the manifold Φ(q) = 0 where the static force
(gravity and springs at rest) is balanced by the reactions, and the multipliers λ* that
balance it — the point about which :mod:`rt70.linear.constrained` linearises.

Newton's method in a null-space form (:func:`equilibrium`): λ are the least-norm
multipliers of the force, the step splits into a row-space part that closes Φ and a
null-space part that balances the force along the manifold, with the tangent stiffness
``K + G`` (the multipliers' geometric stiffness, :mod:`rt70.linear.manifold`).
Convention of :mod:`rt70.physics.kkt`: ``A q̈ + B q̇ = Q + B_cᵀ λ``, ``B_c = ∂Φ/∂q``;
docs/constrained-modes.md ("Equilibrium on the manifold").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rt70.errors import Rt70Error
from rt70.linear.manifold import (
    FD_STEP,
    STEP_TOL,
    Constraints,
    Subspaces,
    Vector,
    force_stiffness,
    force_vector,
    geometric_stiffness,
    subspaces,
)


@dataclass(frozen=True)
class Equilibrium:
    """A static equilibrium on the constraint manifold.

    Attributes
    ----------
    q : ndarray, shape (n,)
        The configuration, ``Φ(q) = 0``.
    lam : ndarray, shape (m,)
        The multipliers, ``Q(q) + B_cᵀ λ = 0`` (least-norm with dependent rows).
    force_residual : float
        ``max|Q + B_cᵀ λ|`` left (the force the reactions cannot balance).
    constraint_residual : float
        ``max|Φ(q)|`` left.
    iterations : int
        Newton steps taken.
    """

    q: np.ndarray
    lam: np.ndarray
    force_residual: float
    constraint_residual: float
    iterations: int


def equilibrium(
    force: Vector,
    constraints: Constraints,
    q_start: np.ndarray,
    stiffness: Vector | None = None,
    tol: float = 1e-10,
    max_iter: int = 50,
    h: float = FD_STEP,
    descend: bool = False,
) -> Equilibrium:
    """Solve ``Q(q) + B_cᵀ λ = 0``, ``Φ(q) = 0`` by Newton's method in null-space form.

    At each iterate: the SVD of B_c gives the row space R and null space N; λ are the
    least-norm multipliers of Q; ``K_t = K + G(q, λ)``; the step
    ``δq = R δy + N δz`` closes the constraints to first order (``B_c R δy = −Φ``) and
    balances the force along the manifold,
    ``Nᵀ K_t N δz = Nᵀ (Q + B_cᵀ λ) − Nᵀ K_t R δy``. Converged when the force left along
    the manifold is below ``tol`` times the force scale (max|Q| at the start, at least 1)
    and ``max|Φ|`` below ``tol`` times the coordinate scale (max|q|, at least 1), or when
    a step moves no coordinate by more than :data:`~rt70.linear.manifold.STEP_TOL` of that scale.

    Parameters
    ----------
    force : callable
        Static generalised force ``Q(q)`` (gravity and springs at rest).
    constraints : Constraints
        Φ and B_c.
    q_start : array_like
        Start (need not satisfy the constraints).
    stiffness : callable, optional
        ``K(q) = −∂Q/∂q``; default central differences of ``force``.
    tol : float
        Relative convergence tolerance (see above).
    max_iter : int
        Newton steps allowed.
    h : float
        Difference step of the geometric stiffness (and of K when not given).
    descend : bool
        Look for a stable equilibrium (a minimum of the potential): where the stiffness
        along the manifold has negative eigenvalues, step downhill along them
        (``|K_r|`` for ``K_r``, steps limited to :data:`MAX_DESCENT_STEP` of the
        coordinate scale) instead of toward the nearest stationary point. Near a stable
        equilibrium it is Newton's method unchanged.

    Returns
    -------
    Equilibrium

    Raises
    ------
    Rt70Error
        If the stiffness along the manifold is singular (a direction the constraints leave
        free and nothing holds), or Newton does not converge. Newton finds stationary
        points: an unstable equilibrium (an inverted pendulum) is one too, and its modes
        say so.
    """
    q = np.array(q_start, dtype=float)
    K_of = stiffness or (lambda x: force_stiffness(force, x, h))
    f_scale = max(_max(force_vector(force, q)), 1.0)
    for it in range(max_iter):
        phi, sub, lam, r_f = _balance(force, constraints, q)
        q_scale = max(float(np.max(np.abs(q), initial=0.0)), 1.0)
        f_left, c_left = _max(r_f), _max(phi)
        if f_left <= tol * f_scale and c_left <= tol * q_scale:
            return Equilibrium(q, lam, f_left, c_left, it)
        dq = sub.closing_step(phi)
        if sub.null.shape[1]:
            Kt = np.asarray(K_of(q), dtype=float) + geometric_stiffness(constraints, q, lam, h)
            dq = dq + _manifold_step(sub.null, Kt, r_f, dq, f_scale, descend, q_scale)
        if not np.isfinite(dq).all():
            raise Rt70Error("the equilibrium's Newton step is not finite")
        q = q + dq
        if _max(dq) <= STEP_TOL * q_scale:  # fixed to rounding: what is left is rounding
            phi, _, lam, r_f = _balance(force, constraints, q)
            return Equilibrium(q, lam, _max(r_f), _max(phi), it + 1)
    raise Rt70Error(
        f"equilibrium on the constraint manifold not found in {max_iter} Newton steps "
        f"(force left {f_left:.3g}, constraint residual {c_left:.3g})"
    )


def _balance(
    force: Vector, constraints: Constraints, q: np.ndarray
) -> tuple[np.ndarray, Subspaces, np.ndarray, np.ndarray]:
    """``(Φ, subspaces of B_c, λ, Q + B_cᵀ λ)`` at q: λ the least-norm multipliers of Q."""
    Q = force_vector(force, q)
    phi, B = constraints.evaluate(q)
    sub = subspaces(B)
    lam = sub.multipliers(Q)
    r_f = Q + B.T @ lam
    return phi, sub, lam, r_f


#: Largest step (times the coordinate scale, at least 1) of a descent toward a stable
#: equilibrium through a region of negative stiffness.
MAX_DESCENT_STEP = 0.25


def _manifold_step(
    N: np.ndarray,
    Kt: np.ndarray,
    r_f: np.ndarray,
    dq_row: np.ndarray,
    f_scale: float,
    descend: bool,
    q_scale: float,
) -> np.ndarray:
    """The part ``N δz`` of the Newton step along the manifold.

    Solves ``K_r δz = Nᵀ r_f − Nᵀ K_t δq_row`` with ``K_r = Nᵀ K_t N`` (N the null-space
    basis, ``K_t`` the tangent stiffness, ``r_f = Q + B_cᵀ λ``, ``δq_row`` the row-space
    step that closes Φ). Directions of zero stiffness (a mechanism that nothing holds, as
    a crank–slider in a horizontal plane) take no step if no force acts along them, and
    are refused if one does. With ``descend`` the negative stiffnesses count as positive
    (a step downhill).
    """
    Kr = N.T @ Kt @ N
    rhs = N.T @ r_f - N.T @ Kt @ dq_row
    w, V = np.linalg.eigh(0.5 * (Kr + Kr.T))
    scale = float(np.max(np.abs(w), initial=0.0))
    zero = np.abs(w) <= 1e-12 * max(scale, f_scale)
    b = V.T @ rhs
    if np.any(np.abs(b[zero]) > 1e-10 * f_scale):
        raise Rt70Error(
            "no equilibrium on the constraint manifold: the stiffness along it is "
            "singular (a motion the constraints allow that nothing holds) and a force "
            "acts along it"
        )
    stiff = np.where(zero, 1.0, np.abs(w) if descend else w)
    dz = V @ np.where(zero, 0.0, b / stiff)
    if descend and np.any(w[~zero] < 0):
        limit = MAX_DESCENT_STEP * q_scale
        size = float(np.max(np.abs(dz), initial=0.0))
        if size > limit:
            dz *= limit / size
    return N @ dz


def _max(x: np.ndarray) -> float:
    """``max|x|`` (0 for an empty x)."""
    return float(np.max(np.abs(x), initial=0.0))
