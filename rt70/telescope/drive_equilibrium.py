"""The static equilibrium a scene's own drives hold: encoders at a pointing, the rest free.

One job: solve ``Q_g(q) + Q_c(q) + Q_l(q) + Σ_d K_d ∂θ_d/∂q = 0`` for the coordinates not
held and the drives' reducer torques K_d (:func:`scene_equilibrium`), the start of a
servo run, of the linear loops and of the bearing loads. The sector's force has
components besides its joint's coordinate, so the coordinate equilibrium alone would
start a drive-held run with a transient.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.linalg

from rt70.errors import Rt70Error
from rt70.linear import linearize as lin
from rt70.linear.linearize import STEP_TOL, equilibrium, newton_stiffness, static_force
from rt70.model.couplings import SceneCoupling
from rt70.model.scene import Scene

#: Force tolerance of the static equilibria (relative): rt70_servo's Newton residual
#: stalls at its rounding floor, 1.2e-10 at elevation 30° (above equilibrium's default
#: 1e-10); 1e-9 of the ~1e7 N·m gravity torque is 0.01 N·m, nothing to the pointing.
EQUILIBRIUM_TOL = 1e-9


#: Newton steps of :func:`scene_equilibrium` at most.
MAX_ITER = 30


def scene_equilibrium(
    scene: Scene,
    couplings: list[SceneCoupling],
    held: dict[str, float],
    tol: float = EQUILIBRIUM_TOL,
    load: Callable[[np.ndarray], np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray, float]:
    """Static equilibrium held by the scene's drives, encoders at ``held``.

    Solves ``R(q, K) = Q_g(q) + Q_c(q) + Q_l(q) + Σ_d K_d ∂θ_d/∂q = 0`` for the coordinates not
    held and the drives' reducer torques K_d (one per coupling): n equations, n unknowns
    when each held coordinate is a drive's joint. Newton's method with the stiffness
    matrix (:func:`rt70.linear.linearize.newton_stiffness`) and the columns ∂θ_d/∂q for
    the K_d, leaving out the term ``K_d ∂²θ_d/∂q²`` (the sector's geometric stiffness,
    some 10⁻⁴ of the structure's: it slows the convergence, not the answer). ``Q_l`` is
    an external static load; its stiffness is left out of Newton's matrix likewise.

    Parameters
    ----------
    scene : Scene
        A scene with ``<rt70:drive>`` elements.
    couplings : list of SceneCoupling
        The drives' couplings to the structure (:meth:`SceneServoFactory.couplings`).
    held : dict of str to float
        The encoders' readings: each driven joint's coordinate, rad.
    tol : float
        Convergence: ``max |R|`` relative to the force scale (below).
    load : callable q -> Q_l, optional
        An external static generalised force, shape (nv,), N·m or N (a steady wind's);
        default none.

    Returns
    -------
    q : numpy.ndarray
        The configuration.
    torques : numpy.ndarray
        K_d, N·m on θ_d, in the order of ``couplings``.
    residual : float
        ``max |R|`` relative to the static force of the undeformed structure (the
        weights: the scale of :func:`rt70.linear.linearize.equilibrium`). Newton also
        stops, as there, when its step moves no coordinate by more than ``STEP_TOL``.

    Raises
    ------
    Rt70Error
        If a held coordinate is not a drive's joint, or Newton does not converge.
    """
    names = scene.coordinate_names
    joints = sorted(names[c.index] for c in couplings)
    if sorted(held) != joints:
        raise Rt70Error(
            f"{scene.name}: the drives hold {', '.join(joints)}, asked to hold "
            f"{', '.join(sorted(held)) or 'nothing'}"
        )
    q = equilibrium(scene, held, tol=tol)  # the coordinate equilibrium: a close start
    Q = static_force(scene, q)
    K = np.array([-float(Q[c.index]) for c in couplings])
    scale = _force_scale(scene, held)
    free = np.array([i for i in range(len(names)) if names[i] not in held])
    S = newton_stiffness(scene, q)

    def force(q: np.ndarray) -> np.ndarray:
        return static_force(scene, q) if load is None else static_force(scene, q) + load(q)

    return _drives_newton(scene, couplings, force, (q, K), (S, free), scale, tol)


def _force_scale(scene: Scene, held: dict[str, float]) -> float:
    """The force scale of :func:`rt70.linear.linearize.equilibrium`, at least 1.

    The static force of the undeformed structure (the weights) at the held pointing;
    the held torques alone have none at the zenith.
    """
    names = scene.coordinate_names
    undeformed = np.zeros(len(names))
    for name, value in held.items():
        undeformed[names.index(name)] = value
    return max(float(np.max(np.abs(static_force(scene, undeformed)))), 1.0)


def _drives_newton(
    scene: Scene,
    couplings: list[SceneCoupling],
    force: Callable[[np.ndarray], np.ndarray],
    start: tuple[np.ndarray, np.ndarray],
    jacobian: tuple[np.ndarray, np.ndarray],
    scale: float,
    tol: float,
) -> tuple[np.ndarray, np.ndarray, float]:
    """Newton's iteration of :func:`scene_equilibrium`: ``(q, K, residual)``.

    From ``start = (q, K)``; ``jacobian = (S, free)``, the stiffness matrix at the start
    (kept throughout) and the coordinates that move. Stops when ``max |R| / scale ≤ tol``
    or when a step moves no coordinate by more than ``STEP_TOL``.
    """
    q, K = start
    S, free = jacobian
    size = np.inf
    for k in range(MAX_ITER):
        with np.errstate(over="ignore", invalid="ignore"):  # checked just below
            G = np.column_stack([c.angle_gradient(q)[1] for c in couplings])
            R = force(q) + G @ K
        size = float(np.max(np.abs(R))) / scale
        if not np.isfinite(size):
            raise Rt70Error(
                f"{scene.name}: drives' equilibrium: the static forces are not finite after "
                f"{k} Newton step(s): the load (a wind?) deforms the structure beyond any "
                "equilibrium its stiffness can give"
            )
        if size <= tol:
            return q, K, size
        step = _newton_step(scene, np.column_stack([-S[:, free], G]), R)
        q[free] += step[: free.size]
        K += step[free.size :]
        if np.abs(step[: free.size]).max() <= STEP_TOL * max(1.0, np.abs(q).max()):
            # the configuration is fixed to rounding (as equilibrium() stops)
            R = force(q) + np.column_stack([c.angle_gradient(q)[1] for c in couplings]) @ K
            return q, K, float(np.max(np.abs(R))) / scale
    raise Rt70Error(
        f"{scene.name}: drives' equilibrium not found in {MAX_ITER} Newton steps "
        f"(residual {size:.2g} of the force scale)"
    )


def _newton_step(scene: Scene, J: np.ndarray, R: np.ndarray) -> np.ndarray:
    """``J⁻¹(−R)`` with J's columns scaled to unit max-norm first.

    The columns mix units (a coordinate's stiffness, N·m/rad, against a sector's angle
    gradient, 1/m): scaled, the solve's conditioning is the equations', not the units'.
    """
    scale = np.max(np.abs(J), axis=0)
    scale[scale == 0.0] = 1.0
    try:
        step = scipy.linalg.solve(J / scale, -R) / scale
    except (np.linalg.LinAlgError, ValueError):
        raise Rt70Error(
            f"{scene.name}: drives' equilibrium: Newton's matrix is singular or not finite "
            "(a coordinate nothing holds?)"
        ) from None
    return step


def drive_held_linearization(scene: Scene, held: dict[str, float]) -> lin.Linearization:
    """The structure linearised, every coordinate free, at the equilibrium its drives hold.

    :func:`scene_equilibrium` with every ``<rt70:drive>`` (reference side) and the
    encoders at ``held``; the starting point of the servo's linear loops.
    """
    couplings = [SceneCoupling(scene, d, "reference") for d in scene.description.drives]
    q0, _, _ = scene_equilibrium(scene, couplings, held)
    return lin.linearize(scene, q0)
