"""Coordinates that move no mass: a singular mass matrix found when the model is built.

The diagonal entry ``A_ii = σ_iᵀ Θᶜ σ_i`` (4.79) is twice the kinetic energy of a unit
velocity of coordinate i alone: ``Σ_j m_j |v_j|² + ω_jᵀ I_j ω_j`` over the bodies it moves
(the subtree of its pair, ``Θᶜ`` their composite inertia, ``σ_i`` its mobility axis).
It is zero exactly when every body that coordinate moves is left without kinetic energy:

- a translation (prismatic, or x/y/z of a floating or planar pair) moves no mass when
  the subtree has no mass at all — rotational inertia alone does not resist it;
- a rotation moves no mass when, in addition, no mass lies off its axis and no body has
  rotational inertia about it: a mesh-only subtree, a point mass on the joint's axis, a
  thin rod along it.

Then A is singular and forward dynamics undefined. Less obviously, a *combination* of
coordinates can move no mass while each one alone does (two coaxial revolute joints
with nothing between them: ``q̇₁ = −q̇₂`` moves nothing); then A is singular with a
non-zero diagonal.

Both are decided numerically at one generic configuration (:data:`PROBE_SEED`) with the
structured mass matrix (:mod:`rt70.textbook.structured`). Rounding makes "zero" a
tolerance: ``A_ii`` is computed from terms of size ``B_i = 2 (M |v|² + |ω|² tr J)``
(``M`` the subtree's mass, ``J`` its rotational inertia about the ground frame's origin,
``σ_i = [v; ω]``), so values below :data:`MASSLESS_RTOL` ``· B_i`` are rounding, not
mass; a combination is found as a pivot of the Cholesky factor of the diagonally scaled
A below the same tolerance.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from rt70.errors import MasslessCoordinateError, Rt70Error
from rt70.textbook import structured
from rt70.textbook.model import Model

#: Below this fraction of its terms' size a diagonal entry (or scaled pivot) of A is zero.
MASSLESS_RTOL = 1e3 * np.finfo(float).eps

#: Seed of the generic configuration at which A is probed (uniform in ±0.5 rad or m).
PROBE_SEED = 20240807


def probe_configuration(model: Model) -> np.ndarray:
    """The generic configuration of the check (fixed, so the check is reproducible)."""
    return np.random.default_rng(PROBE_SEED).uniform(-0.5, 0.5, model.nv)


def _term_scale(model: Model, q: np.ndarray, bdata: structured.BatchData) -> np.ndarray:
    """``B_i``: the size of the terms summed into each diagonal entry ``A_ii``.

    ``bdata`` is a :class:`~rt70.textbook.structured.BatchData` of ``model`` for one
    configuration (its topology is reused).
    """
    topo, work = bdata.topology, bdata.work(1)
    structured.forward_kinematics_batch(model, work, model.expand(q)[None, :])
    theta0 = structured.ground_inertias(model, work)[0]
    theta_c = (topo.anc @ theta0.reshape(model.nb, 36)).reshape(model.nb, 6, 6)
    sigma = work.sigma[0]  # (n_full, 6): [v; ω] of each full coordinate
    body = theta_c[topo.dof_body]
    mass = body[:, 0, 0]
    rot_trace = np.trace(body[:, 3:, 3:], axis1=1, axis2=2)
    v2 = np.sum(sigma[:, :3] ** 2, axis=1)
    w2 = np.sum(sigma[:, 3:] ** 2, axis=1)
    full = 2.0 * (mass * v2 + w2 * rot_trace)
    scale = full if model.G is None else (np.abs(model.G).T @ np.sqrt(full)) ** 2
    if not model.modal:
        return scale
    modal = [np.diag(mb.invariants.modal_mass) for mb in model.modal]  # M_ηη's own terms
    return np.concatenate([scale, *modal])


def singular_coordinates(model: Model) -> tuple[list[str], list[str]]:
    """Coordinates that move no mass, and coordinates of a combination that moves none.

    Returns
    -------
    massless : list of str
        Coordinates whose ``A_ii`` is rounding (module docstring).
    combination : list of str
        When no coordinate is massless but A is singular: the coordinates of the
        combination that moves no mass (the null vector's entries above a tenth of its
        largest); empty otherwise.
    """
    if model.nv == 0:
        return [], []
    q = probe_configuration(model)
    bdata = structured.BatchData(model, 1)
    A = structured.mass_matrix(model, bdata, q)
    diag = np.diag(A).copy()
    names = model.coordinate_names
    massless = diag <= MASSLESS_RTOL * _term_scale(model, q, bdata)
    if np.any(massless):
        return [n for n, m in zip(names, massless, strict=True) if m], []
    scale = 1.0 / np.sqrt(diag)
    scaled = A  # the work buffer, scaled in place (no n × n temporaries)
    scaled *= scale[:, None]
    scaled *= scale[None, :]
    try:
        factor = scipy.linalg.cholesky(scaled, lower=True)
        if np.min(np.diag(factor)) ** 2 > MASSLESS_RTOL:
            return [], []
    except np.linalg.LinAlgError:
        pass
    _, vectors = np.linalg.eigh(scaled)
    null = np.abs(vectors[:, 0])
    return [], [n for n, x in zip(names, null, strict=True) if x >= 0.1 * null.max()]


def check_moves_mass(model: Model, source: str) -> None:
    """Raise :class:`~rt70.errors.MasslessCoordinateError` if A is singular (module doc).

    ``source`` (the URDF file) starts the message; the coordinates are named by their
    joints (``joint`` or ``joint:x`` … for multi-coordinate joints).
    """
    massless, combination = singular_coordinates(model)
    if massless:
        raise MasslessCoordinateError(
            f"{source}: joint coordinate(s) {', '.join(massless)} move no mass (every link "
            "they move has zero mass, or its mass lies on the joint axis): the mass matrix "
            "is singular; give a moved link an <inertial> with mass, or make the joint fixed"
        )
    if combination:
        raise MasslessCoordinateError(
            f"{source}: a combination of joint coordinates {', '.join(combination)} moves no "
            "mass (redundant joints, e.g. coaxial joints with no mass between them): the "
            "mass matrix is singular; remove or fix one of them"
        )


def require_diagonal(
    A: np.ndarray, names: list[str], where: str, error: type[Rt70Error] = Rt70Error
) -> None:
    """Raise ``error`` naming every coordinate whose diagonal entry of ``A`` is not > 0.

    The check at one given configuration (a simulation's start, a linearisation's
    equilibrium), beside the model-wide :func:`check_moves_mass`: a zero (or NaN)
    ``A_ii`` means no mass moves with coordinate i there.

    Parameters
    ----------
    A : numpy.ndarray, shape (n, n)
        A mass matrix.
    names : list of str
        The name of each coordinate, in A's order.
    where : str
        The start of the message, e.g. the scene's name and a colon (``"rt70: "``), or empty.
    error : type
        The exception raised, a subclass of :class:`~rt70.errors.Rt70Error`.
    """
    massless = [n for n, a in zip(names, np.diag(A), strict=True) if not a > 0.0]
    if massless:
        raise error(
            f"{where}mass matrix is singular: no mass moves with coordinate(s) "
            f"{', '.join(massless)}"
        )
