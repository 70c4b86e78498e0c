"""The impact rows of ``rt70 validate``: a random brake and a random stow pin per state.

At every sampled state ``(q, q̇⁻)`` of :func:`rt70.crosscheck.validate.cross_check` a brake on a
1-DOF joint and a stow pin on a moving link, drawn from a generator seeded with the bits
of q (:func:`state_locks`), engage one after the other from the same state, each with a
restitution e drawn in [0, 1]. Both sides solve (15) (:func:`rt70.mechanics.locks.engage`: the
textbook's A, rows and KKT solve, against Pinocchio's ``impulseDynamics``), and two rows
compare them:

- ``impact``: the post-impact velocities q̇⁺ of both impacts, stacked;
- ``impulse``: their impulses Λ (least-norm where rows are dependent), stacked.

Their natural scales (:func:`impact_scales`) are the first-order rounding bounds, the
analogue of the forward dynamics' row.
"""

from __future__ import annotations

import numpy as np

from rt70.mechanics.locks import BRAKE_JOINT_TYPES, Brake, Lock, StowPin, constraint_rows, engage
from rt70.model.scene import Scene
from rt70.physics.kkt import schur_pinv

#: The rows, in report order.
IMPACT_ROWS = ("impact", "impulse")


def state_locks(scene: Scene, q: np.ndarray) -> list[tuple[list[Lock], float]]:
    """The impacts compared at the state q: ``[([Brake], e), ([StowPin], e)]``.

    Seeded from the bits of q (every other word, apart from the streams of
    :func:`rt70.crosscheck.samples.state_wrench` and the others): the brake on a 1-DOF joint
    drawn uniformly (none when the scene has none), the pin on a moving link at a point
    within ±1 m of its origin, each restitution uniform in [0, 1].
    """
    bits = np.frombuffer(np.ascontiguousarray(q, dtype=float).tobytes(), dtype=np.uint32)
    rng = np.random.default_rng(bits[::2].copy())
    following = scene.description.node_joints  # they move with the modes: no brake
    joints = [
        j.name
        for j in scene.description.joints
        if j.type in BRAKE_JOINT_TYPES and j.name not in following
    ]
    links = [n for n, (b, _, _) in scene.textbook.link_frames.items() if b >= 0]
    brake = joints[int(rng.integers(len(joints)))] if joints else None
    link = links[int(rng.integers(len(links)))]
    xyz = rng.uniform(-1.0, 1.0, 3)
    e_brake, e_pin = rng.uniform(0.0, 1.0, 2)
    impacts: list[tuple[list[Lock], float]] = []
    if brake is not None:
        impacts.append(([Brake(brake)], float(e_brake)))
    impacts.append(([StowPin(link, xyz)], float(e_pin)))
    return impacts


def impact_values(scene: Scene, q: np.ndarray, qd: np.ndarray, side: str) -> dict:
    """One side's ``{"impact": stacked q̇⁺, "impulse": stacked Λ}`` at the state.

    Parameters
    ----------
    scene : Scene
        The scene compared.
    q : numpy.ndarray, shape (nv,)
        The sampled coordinates in the file's order, rad or m.
    qd : numpy.ndarray, shape (nv,)
        The sampled velocities before the impacts, rad/s or m/s.
    side : {"textbook", "reference"}
        Which side solves the impacts of :func:`state_locks`.
    """
    results = [engage(scene, q, qd, locks, side, e) for locks, e in state_locks(scene, q)]
    return {
        "impact": np.concatenate([r.qd_after for r in results]),
        "impulse": np.concatenate([r.impulses for r in results]),
    }


def impact_pairs(scene: Scene, q: np.ndarray, qd: np.ndarray) -> dict:
    """``{row: (textbook evaluation, reference evaluation)}`` for :mod:`rt70.crosscheck.validate`.

    One solve per side gives both rows: each side's first evaluation is kept for the
    other row's first (value) call; every later (timed) call solves afresh.

    Parameters
    ----------
    scene : Scene
        The scene compared.
    q : numpy.ndarray, shape (nv,)
        The sampled coordinates in the file's order, rad or m.
    qd : numpy.ndarray, shape (nv,)
        The sampled velocities before the impacts, rad/s or m/s.
    """
    kept: dict[tuple[str, str], np.ndarray] = {}

    def evaluate(side: str, name: str) -> np.ndarray:
        if (side, name) in kept:
            return kept.pop((side, name))
        values = impact_values(scene, q, qd, side)
        other = IMPACT_ROWS[1 - IMPACT_ROWS.index(name)]
        kept.setdefault((side, other), values[other])
        return values[name]

    return {
        name: (
            lambda name=name: evaluate("textbook", name),
            lambda name=name: evaluate("reference", name),
        )
        for name in IMPACT_ROWS
    }


def impact_scales(
    scene: Scene, q: np.ndarray, qd: np.ndarray, reference_values: dict | None = None
) -> dict:
    """Natural scales of the rows: first-order rounding bounds, entry by entry.

    From Pinocchio's A, the reference side's rows B_c and its results, with
    ``Δq̇ = q̇⁺ − q̇⁻ = A⁻¹ B_cᵀ Λ`` and ``W = B_c A⁻¹ B_cᵀ`` (``W⁺`` its pseudo-inverse
    for dependent rows): how far roundings ``|δA| ≤ ε|A|``, ``|δB_c| ≤ ε|B_c|`` of the
    data move the solution, over ε (as the forward dynamics' scale, Higham §7.1):

    - ``impact`` (q̇⁺), per coordinate: ``|A⁻¹| (|A| (|q̇⁻| + |q̇⁺|) + |B_c|ᵀ |Λ|)``;
    - ``impulse`` (Λ), per row: ``|W⁺ B_c A⁻¹| (|A| |Δq̇| + |B_c|ᵀ |Λ|)
      + |W⁺| |B_c| ((1 + e) |q̇⁻| + |Δq̇|)``, from ``δΛ = W⁺ (δr − δW Λ)`` with
      ``r = −(1 + e) B_c q̇⁻``.

    Parameters
    ----------
    scene : Scene
        The scene compared.
    q : numpy.ndarray, shape (nv,)
        The sampled coordinates in the file's order, rad or m.
    qd : numpy.ndarray, shape (nv,)
        The sampled velocities before the impacts, rad/s or m/s.
    reference_values : dict, optional
        The reference side's ``{"impact": q̇⁺ (rad/s or m/s), "impulse": Λ (N·s or
        N·m·s)}`` at this state (:func:`impact_values`), if already computed.
    """
    from rt70 import reference

    A = reference.mass_matrix(scene.reference, scene.reference_data, q)
    A_inv = np.linalg.inv(A)
    absA, absq = np.abs(A), np.abs(qd)
    if reference_values is None:
        reference_values = impact_values(scene, q, qd, "reference")
    speeds, impulses = [], []
    at_v, at_l = 0, 0
    for locks, e in state_locks(scene, q):
        B = constraint_rows(scene, q, locks, "reference")
        qd_after = reference_values["impact"][at_v : at_v + q.size]
        lam = np.abs(reference_values["impulse"][at_l : at_l + B.shape[0]])
        at_v, at_l = at_v + q.size, at_l + B.shape[0]
        dv = np.abs(qd_after - qd)
        speeds.append(np.abs(A_inv) @ (absA @ (absq + np.abs(qd_after)) + np.abs(B).T @ lam))
        W_pinv = schur_pinv(A, B)
        through_A = np.abs(W_pinv @ B @ A_inv) @ (absA @ dv + np.abs(B).T @ lam)
        impulses.append(through_A + np.abs(W_pinv) @ (np.abs(B) @ ((1.0 + e) * absq + dv)))
    return {"impact": np.concatenate(speeds), "impulse": np.concatenate(impulses)}
