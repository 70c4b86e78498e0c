"""A body's wind wrench spread over its surface nodes as a pressure: the same totals.

One job: nodal forces over a reflector's surface nodes whose resultant force and moment
are exactly a given wrench — the wind's, from the dish's coefficient table
(:func:`rt70.physics.aerodynamics.wind_wrench`) — so that the wind that moves the
structure also deforms the surface (docs/surface.md, "Wind on the surface").

The pressure is the lowest-order field that carries a force and a moment, weighted by
each node's share of the aperture ``w̄_n`` (normalised weights):

    f_n = w̄_n (F + Ω × ρ_n),    ρ_n = x_n − c,    c = Σ w̄_n x_n,

a uniform part that carries the force F, and a part linear in the position that carries
the moment about the weighted centre c, ``M_c = M + (x_F − c) × F`` (F acting at
``x_F`` plus the free moment M): ``Σ ρ_n × w̄_n (Ω × ρ_n) = J Ω`` with
``J = Σ w̄_n (|ρ_n|² 1 − ρ_n ρ_nᵀ)``, so ``Ω = J⁻¹ M_c``. The uniform part adds no
moment about c (``Σ w̄_n ρ_n = 0``) and the linear part no force, so the totals are
exact. The real distribution over a dish (wind-tunnel pressure maps) has more shape;
this field is the one fixed by the coefficient table alone.
"""

from __future__ import annotations

import numpy as np

from rt70.errors import Rt70Error

#: A node set whose ``J`` has a condition number above this cannot carry every moment
#: (all nodes on a line): refused.
CONDITION_LIMIT = 1e12


def nodal_forces(
    force: np.ndarray, moment: np.ndarray, point: np.ndarray, nodes: np.ndarray, weights: np.ndarray
) -> np.ndarray:
    """The forces (S, 3) on the nodes whose totals are the wrench ``(force at point, moment)``.

    All vectors in one set of axes (module docstring).

    Parameters
    ----------
    force : array_like, shape (3,)
        The resultant force, N.
    moment : array_like, shape (3,)
        The free moment, N·m.
    point : array_like, shape (3,)
        Where ``force`` acts, m.
    nodes : array_like, shape (S, 3)
        The nodes' positions, m.
    weights : array_like, shape (S,)
        Their shares of the aperture (any scale, > 0).

    Raises
    ------
    Rt70Error
        Wrong shapes, weights that are not positive, or nodes that cannot carry a moment
        (on one line).
    """
    x = np.asarray(nodes, dtype=float)
    w = np.asarray(weights, dtype=float)
    if x.ndim != 2 or x.shape[1] != 3 or w.shape != (x.shape[0],):
        raise Rt70Error(f"nodes (S, 3) and weights (S,) expected, got {x.shape} and {w.shape}")
    if not (np.all(np.isfinite(w)) and np.all(w > 0.0)):
        raise Rt70Error("the nodes' weights must be finite and > 0")
    w = w / w.sum()
    c = w @ x
    rho = x - c
    J = np.einsum("n,n->", w, np.einsum("ni,ni->n", rho, rho)) * np.eye(3)
    J -= np.einsum("n,ni,nj->ij", w, rho, rho)
    if np.linalg.cond(J) > CONDITION_LIMIT:
        raise Rt70Error("the surface nodes lie on a line: they cannot carry every moment")
    F = np.asarray(force, dtype=float)
    M_c = np.asarray(moment, dtype=float) + np.cross(np.asarray(point, dtype=float) - c, F)
    omega = np.linalg.solve(J, M_c)
    return w[:, None] * (F + np.cross(omega, rho))
