"""The tables of the compiled elements: the joints between two frames, read once from Pinocchio.

:mod:`rt70.reference.element_kernels` computes every bushing by walking the joints
between its two frames (:mod:`rt70.reference.joint_walk`). What that walk needs is
constant for a model and is read here, once, from Pinocchio's model: for each pair of
frames the joints from their lowest common ancestor down to each frame (frame 1's
branch first), each joint's kind (:data:`REVOLUTE`, :data:`PRISMATIC`,
:data:`CONTINUOUS`, from its motion subspace), its q and v indices, unit axis and
placement in its parent joint, and the frames' placements in their joints
(:func:`paths`); with the gains of the bushings and of the joint springs these are the
:class:`Tables` (:func:`tables`), which :func:`pack` flattens into the two arrays the
kernel takes. A pair joined through any other joint kind has no tables (None).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rt70.reference.forces import ELEMENTS
from rt70.reference.model import ReferenceModel

#: The element kinds the kernels compute (the keys of rt70.reference.forces.ELEMENTS they
#: cover): a model is only given kernels while these are all the kinds there are.
COVERED = ("joint_springs", "bushings")
#: Joint kinds of the tables.
REVOLUTE, PRISMATIC, CONTINUOUS = 0, 1, 2


@dataclass(frozen=True)
class Tables:
    """Plain arrays describing every element, for the kernels.

    Bushing b owns the joint entries ``start[b]:start[b + 1]`` (frame 1's branch first,
    ``split[b]`` is where frame 2's begins), each top-down from the common ancestor.

    Attributes
    ----------
    start, split : numpy.ndarray
        int64, shapes (n_b + 1,) and (n_b,).
    kind, q_index, v_index : numpy.ndarray
        int64 per entry: :data:`REVOLUTE` / :data:`PRISMATIC` / :data:`CONTINUOUS`, the
        joint's first index in Pinocchio's q and its index in v.
    axis : numpy.ndarray
        (n, 3) unit axis of each joint in its own frame.
    place_R, place_p : numpy.ndarray
        (n, 3, 3), (n, 3): the joint's placement in its parent joint's frame.
    frame_R, frame_p : numpy.ndarray
        (n_b, 2, 3, 3), (n_b, 2, 3): each bushing's frames in their joints' frames.
    stiffness, damping : numpy.ndarray
        (n_b, 6, 6): C and D of each bushing.
    spring_q, spring_v, spring_kind : numpy.ndarray
        int64 per joint spring: q index, v index, :data:`CONTINUOUS` or not.
    spring_k, spring_d : numpy.ndarray
        Joint springs' stiffness and damping.
    """

    start: np.ndarray
    split: np.ndarray
    kind: np.ndarray
    q_index: np.ndarray
    v_index: np.ndarray
    axis: np.ndarray
    place_R: np.ndarray
    place_p: np.ndarray
    frame_R: np.ndarray
    frame_p: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    spring_q: np.ndarray
    spring_v: np.ndarray
    spring_kind: np.ndarray
    spring_k: np.ndarray
    spring_d: np.ndarray


def _joint_kind(model: ReferenceModel, joint: int) -> tuple[int, np.ndarray] | None:
    """(kind, unit axis) of a Pinocchio joint from its motion subspace; None if other."""
    import pinocchio as pin

    pm = model.pin_model
    jm = pm.joints[joint]
    if jm.nv != 1 or jm.nq not in (1, 2):
        return None
    jd = jm.createData()
    jm.calc(jd, pin.neutral(pm))
    S = np.asarray(jd.S).reshape(6)
    lin, ang = S[:3], S[3:]
    if jm.nq == 1 and np.allclose(ang, 0.0) and not np.allclose(lin, 0.0):
        return PRISMATIC, lin / np.linalg.norm(lin)
    if np.allclose(lin, 0.0) and not np.allclose(ang, 0.0):
        return (REVOLUTE if jm.nq == 1 else CONTINUOUS), ang / np.linalg.norm(ang)
    return None


def _chain(parents, joint: int) -> list[int]:
    """Joints from ``joint`` up to the universe (0), ``joint`` first."""
    out = [joint]
    while out[-1] != 0:
        out.append(parents[out[-1]])
    return out


def paths(model: ReferenceModel, frames1, frames2) -> dict[str, np.ndarray] | None:
    """The joints between each pair of frames ``(joint, SE3)``, as the kernels' arrays.

    Returns the fields ``start`` … ``frame_p`` of :class:`Tables`, or None when a pair is
    joined through a joint that is not revolute, prismatic or continuous.

    Parameters
    ----------
    model : ReferenceModel
        The reference model whose Pinocchio joints join the frames.
    frames1, frames2 : sequence of (int, pinocchio.SE3)
        Frame 1 and frame 2 of each pair: Pinocchio's parent joint and the frame's
        placement in it (m); pair b is ``frames1[b]``, ``frames2[b]``.
    """
    pm = model.pin_model
    parents = list(pm.parents)
    rows: list[tuple[int, int, int, np.ndarray, object]] = []
    start, split, frame_R, frame_p = [0], [], [], []
    for (j1, P1), (j2, P2) in zip(frames1, frames2, strict=True):
        up1, up2 = _chain(parents, j1), _chain(parents, j2)
        common = set(up1) & set(up2)
        for branch, up in enumerate((up1, up2)):
            if branch == 1:
                split.append(len(rows))
            for joint in reversed([j for j in up if j not in common]):  # top-down
                found = _joint_kind(model, joint)
                if found is None:
                    return None
                jm = pm.joints[joint]
                rows.append((found[0], jm.idx_q, jm.idx_v, found[1], pm.jointPlacements[joint]))
        start.append(len(rows))
        frame_R.append([P1.rotation, P2.rotation])
        frame_p.append([P1.translation, P2.translation])
    n_b, i64 = len(frames1), np.int64
    return dict(
        start=np.array(start, dtype=i64),
        split=np.array(split, dtype=i64),
        kind=np.array([r[0] for r in rows], dtype=i64),
        q_index=np.array([r[1] for r in rows], dtype=i64),
        v_index=np.array([r[2] for r in rows], dtype=i64),
        axis=np.array([r[3] for r in rows], dtype=float).reshape(-1, 3),
        place_R=np.array([r[4].rotation for r in rows], dtype=float).reshape(-1, 3, 3),
        place_p=np.array([r[4].translation for r in rows], dtype=float).reshape(-1, 3),
        frame_R=np.array(frame_R, dtype=float).reshape(n_b, 2, 3, 3),
        frame_p=np.array(frame_p, dtype=float).reshape(n_b, 2, 3),
    )


def tables(model: ReferenceModel) -> Tables | None:
    """The kernels' tables of the model's bushings and joint springs; None if unsupported.

    Unsupported: a bushing whose frames are joined through a joint that is not
    revolute, prismatic or continuous; such a model keeps :mod:`rt70.reference.forces`.
    So does every model once :data:`~rt70.reference.forces.ELEMENTS` lists a kind the
    kernels do not cover (:data:`COVERED`). Like that module the kernels work in
    Pinocchio's own (q, v).
    """
    if tuple(ELEMENTS) != COVERED:
        return None
    found = paths(model, model.frames1, model.frames2)
    if found is None:
        return None
    pm = model.pin_model
    n_b = len(model.frames1)
    by_v = {pm.joints[j].idx_v: pm.joints[j] for j in range(1, pm.njoints) if pm.joints[j].nv}
    spring_q = [by_v[int(v)].idx_q for v in model.spring_v]
    spring_kind = [CONTINUOUS if by_v[int(v)].nq == 2 else REVOLUTE for v in model.spring_v]
    i64 = np.int64
    return Tables(
        **found,
        stiffness=np.ascontiguousarray(model.stiffness, dtype=float).reshape(n_b, 6, 6),
        damping=np.ascontiguousarray(model.damping, dtype=float).reshape(n_b, 6, 6),
        spring_q=np.array(spring_q, dtype=i64),
        spring_v=np.array(model.spring_v, dtype=i64),
        spring_kind=np.array(spring_kind, dtype=i64),
        spring_k=np.asarray(model.spring_k, dtype=float),
        spring_d=np.asarray(model.spring_d, dtype=float),
    )


def pack(found: Tables, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The tables as one int64 and one float64 array, for the kernel's dispatch.

    :func:`rt70.reference.joint_walk.evaluate_packed` unpacks them. Two arguments
    instead of seventeen: numba's dispatch costs about 0.2 µs per array argument, a
    tenth of the kernel. ``theta`` are the q indices of the angles that must stay away
    from ±π/2 (the book's Euler pairs).
    """
    t = found
    counts = [len(t.split), len(t.kind), len(t.spring_v), len(theta)]
    ints = [counts, t.start, t.split, t.kind, t.q_index, t.v_index, t.spring_q, t.spring_v]
    ints += [t.spring_kind, theta]
    floats = [t.axis, t.place_R, t.place_p, t.frame_R, t.frame_p, t.stiffness, t.damping]
    floats += [t.spring_k, t.spring_d]
    return (
        np.concatenate([np.ravel(np.asarray(a, dtype=np.int64)) for a in ints]),
        np.concatenate([np.ravel(np.asarray(a, dtype=float)) for a in floats]),
    )
