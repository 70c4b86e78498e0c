"""The ``reactions`` row of ``rt70 validate``: joint reaction wrenches on both sides.

At each sampled state (q, q̇) of :func:`rt70.crosscheck.validate.cross_check` both sides compute the
wrench across every URDF joint (:mod:`rt70.textbook.reactions`,
:mod:`rt70.reference.reactions`: ``[F; M]`` in the joint frame about its origin) under
gravity, with accelerations q̈ drawn from the state (:func:`state_acceleration`) and the
state's random load (:func:`rt70.crosscheck.samples.state_wrench`); the row stacks them in the
textbook's joint order. Kept here so that rt70/crosscheck/validate.py holds only the row's hunks.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from rt70.errors import Rt70Error
from rt70.model.scene import Scene
from rt70.physics.loads import Wrench
from rt70.textbook import reactions as tb_reactions

#: The row's name in the report.
REACTIONS = "reactions"


def state_acceleration(q: np.ndarray) -> np.ndarray:
    """The accelerations compared at the state q: uniform in ±1, seeded from the bits of q.

    Reproducible, new at every state, apart from the other streams drawn from q
    (:func:`rt70.crosscheck.samples.state_wrench` and its siblings use other orders of the bits).
    """
    bits = np.frombuffer(np.ascontiguousarray(q, dtype=float).tobytes(), dtype=np.uint32)
    rng = np.random.default_rng(np.roll(bits, 2)[::-1].copy())
    return rng.uniform(-1.0, 1.0, q.size)


def joint_names(scene: Scene) -> list[str]:
    """The URDF joints whose reactions are compared, in the textbook's pair order."""
    return [name for names in scene.textbook.pair_joints for name in names]


def stacked(scene: Scene, reactions: dict[str, np.ndarray]) -> np.ndarray:
    """One side's reactions stacked in :func:`joint_names` order (6 values per joint).

    Raises
    ------
    Rt70Error
        If the side's joints are not the compared ones (a joint missing on one side).
    """
    names = joint_names(scene)
    if sorted(reactions) != sorted(names):
        odd = sorted(set(reactions) ^ set(names))
        raise Rt70Error(f"{scene.name}: the sides' joints differ: {', '.join(odd[:5])}")
    return np.concatenate([reactions[n] for n in names]) if names else np.zeros(0)


def reaction_pair(
    scene: Scene, q: np.ndarray, qd: np.ndarray, wrench: Wrench
) -> tuple[Callable[[], np.ndarray], Callable[[], np.ndarray]]:
    """(textbook, reference) evaluations of the row at (q, q̇) with the load ``wrench``.

    Parameters
    ----------
    scene : Scene
        The scene compared.
    q : numpy.ndarray, shape (nv,)
        The sampled coordinates in the file's order, rad or m.
    qd : numpy.ndarray, shape (nv,)
        The sampled velocities, rad/s or m/s.
    wrench : rt70.physics.loads.Wrench
        The state's random load (:func:`rt70.crosscheck.samples.state_wrench`), N and N·m.
    """
    from rt70.reference import reactions as ref_reactions

    tm, td = scene.textbook, scene.textbook_data
    ref, rd = scene.reference, scene.reference_data
    qdd = state_acceleration(q)
    return (
        lambda: stacked(scene, tb_reactions.joint_reactions(tm, td, q, qd, qdd, [wrench])),
        lambda: stacked(scene, ref_reactions.joint_reactions(ref, rd, q, qd, qdd, [wrench])),
    )


def reaction_scale(scene: Scene, q: np.ndarray, qd: np.ndarray, wrench: Wrench) -> float:
    """The size of the row's terms before they cancel: Pinocchio's reactions of each apart.

    The largest entry of the reactions of the accelerations alone, the velocity
    products alone, gravity alone and the load alone (reference side): the reactions
    are their sum, so rounding is ε times these, not times the (possibly cancelling)
    total.

    Parameters
    ----------
    scene : Scene
        The scene compared.
    q : numpy.ndarray, shape (nv,)
        The sampled coordinates in the file's order, rad or m.
    qd : numpy.ndarray, shape (nv,)
        The sampled velocities, rad/s or m/s.
    wrench : rt70.physics.loads.Wrench
        The state's random load, N and N·m.
    """
    from rt70.reference import reactions as ref_reactions

    ref, rd = scene.reference, scene.reference_data
    zero = np.zeros(ref.nv)
    parts = [
        ref_reactions.joint_reactions(ref, rd, q, zero, state_acceleration(q), gravity=False),
        ref_reactions.joint_reactions(ref, rd, q, qd, zero, gravity=False),
        ref_reactions.joint_reactions(ref, rd, q, zero, zero),
        ref_reactions.joint_reactions(ref, rd, q, zero, zero, [wrench], gravity=False),
    ]
    return max(float(np.max(np.abs(stacked(scene, p)), initial=0.0)) for p in parts)
