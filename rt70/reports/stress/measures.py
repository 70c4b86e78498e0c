"""Measurements of a stress case: cond(A), spring frequencies, cross-check, momenta.

- ``cond(A)``: the 2-norm condition number of the mass matrix ``A = S Θ Sᵀ`` at the
  case's initial state (``numpy.linalg.cond`` of the dense textbook A; for nv > 2000 the
  LAPACK ``dpocon`` 1-norm estimate from a Cholesky factor, marked ``≈``);
- the cross-check error: the largest relative error over the ten quantities of
  :func:`rt70.crosscheck.validate.cross_check` (textbook against Pinocchio) on a few random states;
- the eigenfrequencies of the springs-only stiffness, and the linear and angular momentum
  of the structure on both sides.
"""

from __future__ import annotations

import math

import numpy as np
import scipy
import scipy.linalg

from rt70.crosscheck.samples import random_state
from rt70.crosscheck.validate import cross_check
from rt70.model.scene import Scene
from rt70.textbook import dynamics, forces, structured
from rt70.textbook.kinematics import update_structure

#: Random states of each cross-check.
CROSS_CHECK_SAMPLES = 3


def condition_number(scene: Scene, q: np.ndarray) -> float:
    """``cond(A)`` at q: ``numpy.linalg.cond`` (2-norm), or a 1-norm estimate for nv > 2000.

    The estimate (``dpocon`` on the Cholesky factor of the structured A) avoids an SVD of
    a 6000 × 6000 matrix; it is returned as is (the report marks it ``≈``). A matrix that
    is not positive definite gives ``inf``.
    """
    model = scene.textbook
    if model.nv <= 2000:
        return float(np.linalg.cond(dynamics.mass_matrix(model, scene.textbook_data, q)))
    A = structured.mass_matrix(model, structured.BatchData(model, 1), q)
    anorm = float(np.max(np.sum(np.abs(A), axis=0)))
    c, info = scipy.linalg.lapack.dpotrf(A, lower=False)
    if info != 0:
        return math.inf
    rcond, info = scipy.linalg.lapack.dpocon(c, anorm)
    return math.inf if info != 0 or rcond == 0.0 else 1.0 / float(rcond)


def spring_stiffness(scene: Scene, q: np.ndarray) -> np.ndarray:
    """``Σ Jᵀ C J`` of every spring at q (textbook side): the exact stiffness where δ = 0."""
    model, data = scene.textbook, scene.textbook_data
    update_structure(model, data, q)
    K = np.zeros((model.nv, model.nv))
    if model.spring_coords.size:
        K_full = np.zeros((model.n_full, model.n_full))
        np.add.at(K_full, (model.spring_coords, model.spring_coords), model.spring_stiffness)
        G = np.eye(model.n_full) if model.G is None else model.G
        K += G.T @ K_full @ G
    for b in model.bushings:
        jac = forces.bushing_deformation(data, b).jacobian
        K += jac.T @ b.stiffness @ jac
    return 0.5 * (K + K.T)


def frequencies_hz(scene: Scene, q: np.ndarray | None = None) -> np.ndarray:
    """Eigenfrequencies (Hz, ascending) of ``K v = ω² M v`` with ``M = A(q)``, ``K = Σ JᵀCJ``.

    At q = 0 (default) every spring is undeformed, so K is the exact stiffness of the
    springs (no finite differences, no gravity): the frequencies of the undeformed
    structure. Rigid-body modes come out as 0 (``|ω²| ≤ 1e-10 max ω²``).
    """
    model = scene.textbook
    q = np.zeros(model.nv) if q is None else q
    M = dynamics.mass_matrix(model, scene.textbook_data, q)
    w2 = scipy.linalg.eigh(spring_stiffness(scene, q), M, eigvals_only=True)
    w2 = np.where(np.abs(w2) <= 1e-10 * np.max(np.abs(w2)), 0.0, w2)
    return np.sqrt(np.clip(w2, 0.0, None)) / (2.0 * np.pi)


def cross_check_error(scene: Scene, samples: int = CROSS_CHECK_SAMPLES, seed: int = 0):
    """Largest relative error of :func:`rt70.crosscheck.validate.cross_check` and its quantity.

    Parameters
    ----------
    scene : Scene
        The scene checked, textbook against Pinocchio.
    samples : int, optional
        Random states (:func:`rt70.crosscheck.validate.random_state`: q within ±0.5,
        q̇ within ±1).
    seed : int, optional
        Seed of the random states.

    Returns
    -------
    tuple of (float, str, dict of str to float)
        The largest relative error, its quantity, and each quantity's largest error.
    """
    records = cross_check(scene, samples=samples, seed=seed, repeat=0)
    worst = max(records, key=lambda r: r.max_rel_err)
    return worst.max_rel_err, worst.quantity, {r.quantity: r.max_rel_err for r in records}


def translational(scene: Scene) -> np.ndarray:
    """Mask of the coordinates that are lengths (the others are angles)."""
    model = scene.textbook
    mask = np.zeros(model.n_full, dtype=bool)
    for j, kind in enumerate(model.kind):
        start = int(model.q_start[j])
        if kind == "euler6":
            mask[start : start + 3] = True
        elif kind == "planar":
            mask[start : start + 2] = True
        elif kind == "prismatic":
            mask[start] = True
    if model.G is None:
        return mask
    return np.array([mask[np.flatnonzero(model.G[:, i])[0]] for i in range(model.nv)])


def rel_error(a: np.ndarray, b: np.ndarray) -> float:
    """``max|a − b| / max|b|`` (0 if both vanish, inf if only b does)."""
    scale = float(np.max(np.abs(b)))
    err = float(np.max(np.abs(a - b)))
    return err / scale if scale > 0 else (0.0 if err == 0 else math.inf)


def per_body_qdd_error(scene: Scene, samples: int = CROSS_CHECK_SAMPLES, seed: int = 0) -> float:
    """Largest error of q̈ (textbook against Pinocchio) relative to each body's own ``|q̈|``.

    Parameters
    ----------
    scene : Scene
        The scene checked; springs and dampers act, no load.
    samples : int, optional
        Random states (q within ±0.5, q̇ within ±1).
    seed : int, optional
        Seed of the random states.

    Returns
    -------
    float
        Over the states and the bodies with coordinates, the largest
        ``max|q̈_tb − q̈_pin| / max|q̈_pin|`` over each body's own coordinates.
    """
    from rt70 import reference

    model, data = scene.textbook, scene.textbook_data
    ref, rd = scene.reference, scene.reference_data
    rng = np.random.default_rng(seed)
    worst = 0.0
    for _ in range(samples):
        q, qd = random_state(model.nv, rng)
        Qc, Qd = forces.spring_damper_force(model, data, q, qd)
        a = dynamics.forward_dynamics(model, data, q, qd, Qc + Qd)
        b = reference.forward_dynamics(ref, rd, q, qd)
        for j in range(model.nb):
            rows = model.coords(j)
            if rows.stop > rows.start:
                worst = max(worst, rel_error(a[rows], b[rows]))
    return worst


def momentum_textbook(scene: Scene, q: np.ndarray, qd: np.ndarray):
    """Linear momentum and angular momentum about the ground origin, textbook side.

    ``Σ_k [c_k F_k; p_k × c_k F_k + c_k K_k]`` with ``[F_k; K_k] = Θ_k V_k``, ``V = Sᵀ q̇``:
    each body's momentum about its own origin (4.77), moved to the ground frame.

    Parameters
    ----------
    scene : Scene
        The scene; its textbook Data is updated at ``q``.
    q : ndarray, shape (nv,)
        Generalised coordinates, rad or m.
    qd : ndarray, shape (nv,)
        Generalised velocities, rad/s or m/s.

    Returns
    -------
    P, L_O : ndarray, shape (3,)
        Linear momentum (kg·m/s) and angular momentum about the ground origin
        (kg·m²/s), ground axes.
    """
    model, data = scene.textbook, scene.textbook_data
    update_structure(model, data, q)
    V = (data.S.T @ qd).reshape(model.nb, 6)
    h = np.einsum("kij,kj->ki", model.Theta, V)
    F = np.einsum("kij,kj->ki", data.R, h[:, :3])
    K = np.einsum("kij,kj->ki", data.R, h[:, 3:])
    return F.sum(axis=0), (np.cross(data.p, F) + K).sum(axis=0)


def momentum_pinocchio(scene: Scene, q: np.ndarray, qd: np.ndarray):
    """Linear momentum P and angular momentum about the ground origin, from Pinocchio.

    ``pin.computeCentroidalMomentum`` gives ``h_G = [P; L_G]`` at the centre of mass c;
    ``L_O = L_G + c × P``.

    Parameters
    ----------
    scene : Scene
        The scene; its Pinocchio data is updated at the state.
    q : ndarray, shape (nv,)
        Generalised coordinates in the textbook's order, rad or m.
    qd : ndarray, shape (nv,)
        Generalised velocities, rad/s or m/s.

    Returns
    -------
    P, L_O : ndarray, shape (3,)
        Linear momentum (kg·m/s) and angular momentum about the ground origin
        (kg·m²/s), ground axes.
    """
    import pinocchio as pin

    from rt70 import reference

    ref, pd = scene.reference, scene.reference_data.pin_data
    qp, vp, _, _ = reference.to_pinocchio(ref, q, qd)
    pin.computeCentroidalMomentum(ref.pin_model, pd, qp, vp)
    P = np.array(pd.hg.linear)
    L = np.array(pd.hg.angular) + np.cross(pd.com[0], P)
    return P, L
