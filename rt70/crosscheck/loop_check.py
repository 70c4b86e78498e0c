"""The loop-closure rows of ``rt70 validate`` (docs/loops.md), for scenes with loops.

Both sides' :mod:`rt70.textbook.loops` and :mod:`rt70.reference.loops` at the sampled
(random, generally not closed) state:

* ``loop_residual`` Φ(q), ``loop_jacobian`` B_c, ``loop_bias`` C = Ḃ_c q̇;
* ``loop_dynamics`` q̈ and ``loop_reaction`` the generalised reaction ``B_cᵀ λ`` of the
  constrained equations (14) with the default Baumgarte stabilisation
  (:class:`rt70.physics.baumgarte.Baumgarte`): the KKT system by the range-space method against
  ``pin.constraintDynamics``. Off the manifold every term of (2.2) is active, so the
  stabilisation is compared too. ``B_cᵀ λ`` rather than λ: with dependent rows (a
  planar loop closed in 3-D, a weld) λ is not unique — rt70.physics.kkt returns the
  least-norm one, Pinocchio's proximal iterations head for it from zero but its
  regularised factorisation leaks rounding/μ into the dependent directions (docs/loops.md);
  each side's own ``B_c`` times its own λ still checks λ's frame and sign.

A scene with a ``frame`` loop is compared at the sampled state closed by
:func:`rt70.simulation.closed_chains.assemble` (Newton from it): Pinocchio's ``CONTACT_6D`` rows
are the relative twist at frame 1's origin (``ṗ₁ − v₂(p₁)``), its error ``−log₆(c₁Mc₂)``
and its drift the derivative of the twist in a moving frame, which equal the textbook's
``ṗ₁ − ṗ₂``, ``(p₁ − p₂, log₃)`` and ``Ḃ_c q̇`` on ``Φ = 0``, ``B_c q̇ = 0`` only. Point
loops are compared at the random state itself, off the manifold, every term active.

Each row is measured against its own max-norm (Pinocchio's value), floored as every
row of :mod:`rt70.crosscheck.validate`: ``loop_residual`` by the largest distance of a loop frame
from the ground origin, ``loop_bias`` by that distance times ``‖q̇‖²`` plus ``|C|``,
``loop_dynamics`` by the unconstrained q̈'s scale, ``loop_reaction`` by ``|B_cᵀ λ|``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from rt70.model.scene import Scene
from rt70.physics.baumgarte import Baumgarte
from rt70.simulation.closed_chains import assemble

#: Rows compared for a scene with ``<rt70:loop>`` elements, after the others.
LOOP_QUANTITIES = ("loop_residual", "loop_jacobian", "loop_bias", "loop_dynamics", "loop_reaction")


def loop_quantities(scene: Scene) -> tuple[str, ...]:
    """:data:`LOOP_QUANTITIES` if the scene has loops, else none."""
    return LOOP_QUANTITIES if scene.description.loops else ()


def loop_pairs(scene: Scene, q: np.ndarray, qd: np.ndarray) -> dict[str, tuple[Callable, Callable]]:
    """(textbook, reference) evaluations of the loop rows at (q, q̇); empty without loops.

    Parameters
    ----------
    scene : Scene
        The scene compared.
    q : numpy.ndarray, shape (nv,)
        The sampled coordinates in the file's order, rad or m.
    qd : numpy.ndarray, shape (nv,)
        The sampled velocities, rad/s or m/s.
    """
    if not scene.description.loops:
        return {}
    from rt70.reference import loops as rl
    from rt70.textbook import loops as tl

    if any(loop.type == "frame" for loop in scene.description.loops):
        q, qd = assemble(scene, q, qd)  # Pinocchio's 6-D rows equal ours on the manifold
    tm, td = scene.textbook, scene.textbook_data
    ref, rd = scene.reference, scene.reference_data
    gains = Baumgarte()
    return {
        "loop_residual": (
            lambda: tl.loop_residual(tm, td, q),
            lambda: rl.loop_residual(ref, rd, q),
        ),
        "loop_jacobian": (
            lambda: tl.loop_jacobian(tm, td, q),
            lambda: rl.loop_jacobian(ref, rd, q),
        ),
        "loop_bias": (
            lambda: tl.loop_bias(tm, td, q, qd),
            lambda: rl.loop_bias(ref, rd, q, qd),
        ),
        "loop_dynamics": (
            lambda: tl.constrained_forward_dynamics(tm, td, q, qd, stabilization=gains)[0],
            lambda: rl.constrained_forward_dynamics(ref, rd, q, qd, stabilization=gains)[0],
        ),
        "loop_reaction": (
            lambda: (
                tl.loop_jacobian(tm, td, q).T
                @ tl.constrained_forward_dynamics(tm, td, q, qd, stabilization=gains)[1]
            ),
            lambda: (
                rl.loop_jacobian(ref, rd, q).T
                @ rl.constrained_forward_dynamics(ref, rd, q, qd, stabilization=gains)[1]
            ),
        ),
    }


def loop_scales(
    scene: Scene, values: dict, q: np.ndarray, qd: np.ndarray, qdd_scale: np.ndarray
) -> dict:
    """Natural scales of the loop rows (see the module docstring); empty without loops.

    Parameters
    ----------
    scene : Scene
        The scene compared.
    values : dict of str to (numpy.ndarray, numpy.ndarray)
        Every row's ``(textbook value, reference value)`` at this state (the loop rows
        among them when the scene has loops).
    q : numpy.ndarray, shape (nv,)
        The sampled coordinates in the file's order, rad or m.
    qd : numpy.ndarray, shape (nv,)
        The sampled velocities, rad/s or m/s.
    qdd_scale : numpy.ndarray, shape (nv,)
        The tree's q̈ scale per coordinate (:mod:`rt70.crosscheck.scales`), rad/s² or
        m/s²: the scale of ``loop_dynamics``.
    """
    if "loop_residual" not in values:
        return {}
    from rt70.reference import points as ref_points

    ref, rd = scene.reference, scene.reference_data
    located = [
        (f.link, f.xyz) for loop in scene.description.loops for f in (loop.frame1, loop.frame2)
    ]
    reach = float(np.max(np.linalg.norm(ref_points.point_positions(ref, rd, q, located), axis=1)))
    speed2 = float(np.max(np.abs(qd), initial=0.0)) ** 2

    def norm(name: str) -> float:
        x = values[name][1]
        return float(np.max(np.abs(x))) if x.size else 0.0

    return {
        "loop_residual": reach,
        "loop_jacobian": max(reach, norm("loop_jacobian")),
        "loop_bias": reach * speed2 + norm("loop_bias"),
        "loop_dynamics": qdd_scale,
        "loop_reaction": norm("loop_reaction"),
    }
