"""Compiled spring and damper forces of the reference side: the simulation's fast path.

:mod:`rt70.reference.forces` computes every element from Pinocchio's frame placements
and frame Jacobians — two dozen Python calls and a hundred small numpy operations per
evaluation of the RT-70, six times the cost of ``pin.aba`` itself. Here the same
deformations, forces, gains and potential come from one numba kernel that walks, for
each bushing, the joints between its two frames:

- ``frame i = Π_k (placement_k · X_k(q_k)) · P_i`` from the frames' lowest common
  ancestor down to each frame (the element depends on those joints only);
- ``δ = [r12; −rpy(c12ᵀ)]`` with ``c12 = R1ᵀ R2``, ``r12 = R1ᵀ (p2 − p1)`` — the
  definition of :func:`rt70.reference.forces.deformations`, so the two agree to rounding
  (tested on every scene);
- ``∂δ/∂q̇_k``: joint k moves one side relative to the other by the twist
  ``s_k (a_k, −a_k × o_k)`` (axis ``a_k`` through ``o_k``, in the ancestor's frame;
  ``s_k = +1`` on frame 2's branch, −1 on frame 1's), so ``ṙ12 = R1ᵀ (v + ω × p2)``
  and the rotation rows are ``J_W(ρ)⁻¹ R2ᵀ ω`` as on the Pinocchio path;
- ``τ_c = −Σ Jᵀ C δ``, ``τ_d = −Σ Jᵀ D δ̇``, gains ``Σ JᵀCJ``, ``Σ JᵀDJ`` (the
  Gauss–Newton part of ``−∂τ_c/∂q``, as :func:`rt70.reference.forces.element_gains`)
  and ``U_c = Σ ½ δᵀ C δ``, scattered only on each element's own joints.

Joint springs (δ = the joint's coordinate) are in the same kernel. The tables are
read once from Pinocchio's model (:func:`tables`); a model whose elements cross a joint
other than revolute, prismatic or continuous has no tables (None) and keeps the Python
path. Kernels are compiled on first use and cached on disk (``cache=True``): a second
process pays no compilation. They use no BLAS (explicit 3×3 loops), so they import
nothing beyond numba and numpy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from rt70.errors import SingularConfigurationError
from rt70.reference.forces import ELEMENTS, GIMBAL_LOCK_COS
from rt70.reference.model import ReferenceModel

#: The element kinds the kernels compute (the keys of rt70.reference.forces.ELEMENTS they
#: cover): a model is only given kernels while these are all the kinds there are.
COVERED = ("joint_springs", "bushings")
#: Joint kinds of the tables.
REVOLUTE, PRISMATIC, CONTINUOUS = 0, 1, 2
#: Size of the kernels' fixed scratch (3×3 and 3-, 6-vectors) after the per-entry part.
WORK_SMALL = 93


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
        (n_b, 6) diagonals of C and D.
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
        stiffness=np.ascontiguousarray(model.stiffness, dtype=float).reshape(n_b, 6),
        damping=np.ascontiguousarray(model.damping, dtype=float).reshape(n_b, 6),
        spring_q=np.array(spring_q, dtype=i64),
        spring_v=np.array(model.spring_v, dtype=i64),
        spring_kind=np.array(spring_kind, dtype=i64),
        spring_k=np.asarray(model.spring_k, dtype=float),
        spring_d=np.asarray(model.spring_d, dtype=float),
    )


@numba.njit(cache=True, inline="always")
def _walk(qp, lo, hi, kind, q_index, axis, place_R, place_p, R, p, origin, axis_out, T, X):
    """Compose ``placement_k · X_k(q_k)`` for entries lo…hi onto (R, p) in place.

    Records each joint's origin ``o_k`` and axis ``a_k`` in the starting frame; T and X
    are 3×3 scratch.
    """
    for k in range(lo, hi):
        for i in range(3):  # p += R placement_p;  R = R placement_R
            p[i] += R[i, 0] * place_p[k, 0] + R[i, 1] * place_p[k, 1] + R[i, 2] * place_p[k, 2]
        _mul(R, place_R[k], T)
        _copy(T, R)
        u = axis[k]
        for i in range(3):
            origin[k, i] = p[i]
            axis_out[k, i] = R[i, 0] * u[0] + R[i, 1] * u[1] + R[i, 2] * u[2]
        qi = q_index[k]
        if kind[k] == PRISMATIC:
            for i in range(3):
                p[i] += axis_out[k, i] * qp[qi]
            continue
        if kind[k] == CONTINUOUS:
            c, s = qp[qi], qp[qi + 1]
        else:
            c, s = math.cos(qp[qi]), math.sin(qp[qi])
        _rotation(u, c, s, X)  # R = R · Rot(u, angle)
        _mul(R, X, T)
        _copy(T, R)


@numba.njit(cache=True, inline="always")
def _copy(A, out):
    """``out = A`` for 3×3 arrays (an explicit loop: numba's slice assignment is slower)."""
    for i in range(3):
        for j in range(3):
            out[i, j] = A[i, j]


@numba.njit(cache=True, inline="always")
def _mul(A, B, out):
    """``out = A B`` for 3×3 arrays (no BLAS)."""
    for i in range(3):
        for j in range(3):
            out[i, j] = A[i, 0] * B[0, j] + A[i, 1] * B[1, j] + A[i, 2] * B[2, j]


@numba.njit(cache=True, inline="always")
def _rotation(u, c, s, out):
    """Rotation by the angle with cosine c and sine s about the unit axis u (Rodrigues)."""
    t = 1.0 - c
    out[0, 0], out[0, 1], out[0, 2] = (
        c + t * u[0] * u[0],
        t * u[0] * u[1] - s * u[2],
        t * u[0] * u[2] + s * u[1],
    )
    out[1, 0], out[1, 1], out[1, 2] = (
        t * u[1] * u[0] + s * u[2],
        c + t * u[1] * u[1],
        t * u[1] * u[2] - s * u[0],
    )
    out[2, 0], out[2, 1], out[2, 2] = (
        t * u[2] * u[0] - s * u[1],
        t * u[2] * u[1] + s * u[0],
        c + t * u[2] * u[2],
    )


@numba.njit(cache=True, inline="always")
def _frame(R, p, FR, Fp, R_out, p_out):
    """``(R_out, p_out) = (R, p) · (FR, Fp)``."""
    _mul(R, FR, R_out)
    for i in range(3):
        p_out[i] = p[i] + R[i, 0] * Fp[0] + R[i, 1] * Fp[1] + R[i, 2] * Fp[2]


@numba.njit(cache=True, inline="always")
def _pair_pose(
    qp, b, lo, mid, hi, kind, q_index, axis, place_R, place_p, frame_R, frame_p,
    R, p, R1, p1, R2, p2, origin, axis_w, T, X,
):  # fmt: skip
    """Poses (R1, p1), (R2, p2) of pair b's frames in their common ancestor's frame.

    Fills each entry's joint origin and axis in that frame; R, p, T, X are scratch.
    """
    for side in range(2):
        R[:, :] = 0.0
        R[0, 0] = R[1, 1] = R[2, 2] = 1.0
        p[:] = 0.0
        a, z = (lo, mid) if side == 0 else (mid, hi)
        _walk(qp, a, z, kind, q_index, axis, place_R, place_p, R, p, origin, axis_w, T, X)
        if side == 0:
            _frame(R, p, frame_R[b, 0], frame_p[b, 0], R1, p1)
        else:
            _frame(R, p, frame_R[b, 1], frame_p[b, 1], R2, p2)


@numba.njit(cache=True, inline="always")
def _translation_column(k, to_frame2, kind, origin, axis_w, R1, p2, w, lin, jac):
    """Entry k's ``∂r12/∂q̇_k = R1ᵀ s_k (v + ω × p2)`` into ``jac[k, :3]``; ω into w.

    Revolute: ``ω = a_k``, ``v + ω × p2 = a_k × (p2 − o_k)``; prismatic: ``ω = 0``,
    ``v = a_k``. ``s_k = +1`` on frame 2's branch, −1 on frame 1's.
    """
    sign = 1.0 if to_frame2 else -1.0
    if kind[k] == PRISMATIC:
        for i in range(3):
            w[i] = 0.0
            lin[i] = sign * axis_w[k, i]
    else:
        a0, a1, a2 = axis_w[k, 0], axis_w[k, 1], axis_w[k, 2]
        r0, r1, r2 = p2[0] - origin[k, 0], p2[1] - origin[k, 1], p2[2] - origin[k, 2]
        lin[0], lin[1], lin[2] = a1 * r2 - a2 * r1, a2 * r0 - a0 * r2, a0 * r1 - a1 * r0
        for i in range(3):
            w[i] = sign * axis_w[k, i]
            lin[i] *= sign
    for i in range(3):
        jac[k, i] = R1[0, i] * lin[0] + R1[1, i] * lin[1] + R1[2, i] * lin[2]


@numba.njit(cache=True, inline="always")
def _walk_scratch(work, n):
    """Views of one buffer for the joint walk of n entries: no allocation per call.

    ``work[:3n]`` origins, ``[3n:6n]`` axes (``[6n:12n]`` is :func:`evaluate`'s
    Jacobian), then :data:`WORK_SMALL` numbers: R, R1, R2 (and evaluate's c12) at 0,
    9, 18 (27); p, p1, p2 (d), w, lin at 36, 39, 42 (45), 48, 51; evaluate's δ, δ̇ and
    J_W⁻¹ at 54, 60, 66; T, X at 75, 84.
    """
    origin = work[: 3 * n].reshape((n, 3))
    axis_w = work[3 * n : 6 * n].reshape((n, 3))
    small = work[12 * n :]
    R, R1, R2 = (
        small[0:9].reshape((3, 3)),
        small[9:18].reshape((3, 3)),
        small[18:27].reshape((3, 3)),
    )
    p, p1, p2 = small[36:39], small[39:42], small[42:45]
    w, lin = small[48:51], small[51:54]
    T, X = small[75:84].reshape((3, 3)), small[84:93].reshape((3, 3))
    return origin, axis_w, R, R1, R2, p, p1, p2, w, lin, T, X


@numba.njit(cache=True)
def relative_points(
    qp, work, start, split, kind, q_index, axis, place_R, place_p, frame_R, frame_p, c, r, jac
):  # fmt: skip
    """Frame 2 in frame 1 for each pair b, and its Jacobian on the pair's joints.

    ``c12 = R1ᵀ R2`` into ``c[b]``, ``r12 = R1ᵀ (p2 − p1)`` into ``r[b]``; per joint
    entry k the columns ``∂r12/∂q̇_k`` into ``jac[k, :3]`` and frame 2's angular velocity
    relative to frame 1, in frame 1's axes, into ``jac[k, 3:]``.
    """
    origin, axis_w, R, R1, R2, p, p1, p2, w, lin, T, X = _walk_scratch(work, kind.shape[0])
    for b in range(start.shape[0] - 1):
        lo, mid, hi = start[b], split[b], start[b + 1]
        _pair_pose(qp, b, lo, mid, hi, kind, q_index, axis, place_R, place_p, frame_R, frame_p,
                   R, p, R1, p1, R2, p2, origin, axis_w, T, X)  # fmt: skip
        for i in range(3):
            r[b, i] = (
                R1[0, i] * (p2[0] - p1[0]) + R1[1, i] * (p2[1] - p1[1]) + R1[2, i] * (p2[2] - p1[2])
            )
            for j in range(3):
                c[b, i, j] = R1[0, i] * R2[0, j] + R1[1, i] * R2[1, j] + R1[2, i] * R2[2, j]
        for k in range(lo, hi):
            _translation_column(k, k >= mid, kind, origin, axis_w, R1, p2, w, lin, jac)
            for i in range(3):
                jac[k, 3 + i] = R1[0, i] * w[0] + R1[1, i] * w[1] + R1[2, i] * w[2]


@numba.njit(cache=True)
def evaluate(
    qp, vp, gains, tau_c, tau_d, K, D, work,
    start, split, kind, q_index, v_index, axis, place_R, place_p, frame_R, frame_p,
    stiffness, damping, spring_q, spring_v, spring_kind, spring_k, spring_d,
):  # fmt: skip
    """Add every element's forces (and with ``gains`` its ``JᵀCJ``, ``JᵀDJ``) in place.

    ``tau_c −= Σ Jᵀ C δ``, ``tau_d −= Σ Jᵀ D δ̇``; ``K += Σ JᵀCJ``, ``D += Σ JᵀDJ``.
    Returns ``(U_c, b)``: the elastic potential ``Σ ½ δᵀ C δ`` and −1, or the index b
    of a bushing at Euler-angle gimbal lock (then nothing is complete).
    """
    n = kind.shape[0]
    origin, axis_w, R, R1, R2, p, p1, p2, w, lin, T, X = _walk_scratch(work, n)
    jac = work[6 * n : 12 * n].reshape((n, 6))
    small = work[12 * n :]
    c12, d = small[27:36].reshape((3, 3)), small[45:48]
    delta, rate = small[54:60], small[60:66]
    inv = small[66:75].reshape((3, 3))
    inv[0, 2] = inv[1, 2] = 0.0
    U = 0.0
    for b in range(start.shape[0] - 1):
        lo, mid, hi = start[b], split[b], start[b + 1]
        _pair_pose(qp, b, lo, mid, hi, kind, q_index, axis, place_R, place_p, frame_R, frame_p,
                   R, p, R1, p1, R2, p2, origin, axis_w, T, X)  # fmt: skip
        for i in range(3):
            d[i] = p2[i] - p1[i]
        for i in range(3):  # c12 = R1ᵀ R2, r12 = R1ᵀ (p2 − p1)
            for j in range(3):
                c12[i, j] = R1[0, i] * R2[0, j] + R1[1, i] * R2[1, j] + R1[2, i] * R2[2, j]
        for i in range(3):
            delta[i] = R1[0, i] * d[0] + R1[1, i] * d[1] + R1[2, i] * d[2]
        # ρ = rpy of ct = c12ᵀ (Pinocchio's matrixToRpy): ct[i, j] = c12[j, i]
        pitch = math.atan2(-c12[0, 2], math.hypot(c12[0, 0], c12[0, 1]))
        roll = math.atan2(c12[1, 2], c12[2, 2])
        yaw = math.atan2(c12[0, 1], c12[0, 0])
        cp = math.cos(pitch)
        if abs(cp) < GIMBAL_LOCK_COS:
            return math.nan, b
        delta[3], delta[4], delta[5] = -roll, -pitch, -yaw
        cy, sy, tp = math.cos(yaw), math.sin(yaw), math.tan(pitch)
        inv[0, 0], inv[0, 1] = cy / cp, sy / cp
        inv[1, 0], inv[1, 1] = -sy, cy
        inv[2, 0], inv[2, 1], inv[2, 2] = cy * tp, sy * tp, 1.0
        rate[:] = 0.0
        for k in range(lo, hi):
            _translation_column(k, k >= mid, kind, origin, axis_w, R1, p2, w, lin, jac)
            w0 = R2[0, 0] * w[0] + R2[1, 0] * w[1] + R2[2, 0] * w[2]  # R2ᵀ ω
            w1 = R2[0, 1] * w[0] + R2[1, 1] * w[1] + R2[2, 1] * w[2]
            w2 = R2[0, 2] * w[0] + R2[1, 2] * w[1] + R2[2, 2] * w[2]
            for i in range(3):
                jac[k, 3 + i] = inv[i, 0] * w0 + inv[i, 1] * w1 + inv[i, 2] * w2
            vk = vp[v_index[k]]
            for i in range(6):
                rate[i] += jac[k, i] * vk
        for k in range(lo, hi):
            fc = 0.0
            fd = 0.0
            for i in range(6):
                fc += jac[k, i] * stiffness[b, i] * delta[i]
                fd += jac[k, i] * damping[b, i] * rate[i]
            tau_c[v_index[k]] -= fc
            tau_d[v_index[k]] -= fd
            if gains:
                for m in range(lo, hi):
                    kc = 0.0
                    kd = 0.0
                    for i in range(6):
                        kc += jac[k, i] * stiffness[b, i] * jac[m, i]
                        kd += jac[k, i] * damping[b, i] * jac[m, i]
                    K[v_index[k], v_index[m]] += kc
                    D[v_index[k], v_index[m]] += kd
        for i in range(6):
            U += 0.5 * stiffness[b, i] * delta[i] * delta[i]
    for e in range(spring_v.shape[0]):  # joint springs: δ = the joint's coordinate
        qi, vi = spring_q[e], spring_v[e]
        x = math.atan2(qp[qi + 1], qp[qi]) if spring_kind[e] == CONTINUOUS else qp[qi]
        tau_c[vi] -= spring_k[e] * x
        tau_d[vi] -= spring_d[e] * vp[vi]
        if gains:
            K[vi, vi] += spring_k[e]
            D[vi, vi] += spring_d[e]
        U += 0.5 * spring_k[e] * x * x
    return U, -1


def pack(found: Tables, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The tables as one int64 and one float64 array (:func:`evaluate_packed` unpacks).

    Two arguments instead of seventeen: numba's dispatch costs about 0.2 µs per array
    argument, a tenth of the kernel. ``theta`` are the q indices of the angles that
    must stay away from ±π/2 (the book's Euler pairs).
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


@numba.njit(cache=True)
def evaluate_packed(qp, vp, gains, tau_c, tau_d, K, D, work, ints, floats, theta_cos):
    """:func:`evaluate` on the tables of :func:`pack`; first the Euler pairs' guard.

    Returns ``(nan, -2)`` if a listed angle has ``|cos θ| < theta_cos``.
    """
    n_b, n, ns, nt = ints[0], ints[1], ints[2], ints[3]
    i = 4
    start = ints[i : i + n_b + 1]
    i += n_b + 1
    split = ints[i : i + n_b]
    i += n_b
    kind, q_index, v_index = ints[i : i + n], ints[i + n : i + 2 * n], ints[i + 2 * n : i + 3 * n]
    i += 3 * n
    spring_q, spring_v = ints[i : i + ns], ints[i + ns : i + 2 * ns]
    spring_kind, theta = ints[i + 2 * ns : i + 3 * ns], ints[i + 3 * ns : i + 3 * ns + nt]
    for k in range(nt):
        if abs(math.cos(qp[theta[k]])) < theta_cos:
            return math.nan, -2
    axis = floats[: 3 * n].reshape((n, 3))
    j = 3 * n
    place_R = floats[j : j + 9 * n].reshape((n, 3, 3))
    j += 9 * n
    place_p = floats[j : j + 3 * n].reshape((n, 3))
    j += 3 * n
    frame_R = floats[j : j + 18 * n_b].reshape((n_b, 2, 3, 3))
    j += 18 * n_b
    frame_p = floats[j : j + 6 * n_b].reshape((n_b, 2, 3))
    j += 6 * n_b
    stiffness = floats[j : j + 6 * n_b].reshape((n_b, 6))
    j += 6 * n_b
    damping = floats[j : j + 6 * n_b].reshape((n_b, 6))
    j += 6 * n_b
    spring_k, spring_d = floats[j : j + ns], floats[j + ns : j + 2 * ns]
    return evaluate(
        qp, vp, gains, tau_c, tau_d, K, D, work,
        start, split, kind, q_index, v_index, axis, place_R, place_p, frame_R, frame_p,
        stiffness, damping, spring_q, spring_v, spring_kind, spring_k, spring_d,
    )  # fmt: skip


class ElementKernels:
    """The compiled forces, gains and potential of one model's elements.

    Same results as :func:`rt70.reference.forces.element_torques`,
    :func:`~rt70.reference.forces.element_gains` and
    :func:`~rt70.reference.forces.spring_potential`, in Pinocchio's (q, v) spaces.
    Build with :meth:`of`, which gives None when the model is not supported.

    ``guard`` (optional): the indices ``theta`` of angles in q that must keep
    ``|cos θ| ≥ theta_cos`` and the function that raises the detailed error when one
    does not (the simulation passes the book's Euler-pair check, so that the check
    costs nothing beside the kernel).
    """

    def __init__(self, model: ReferenceModel, found: Tables, guard=None) -> None:
        self.nv = model.pin_model.nv
        self.tables = found
        theta, self._theta_cos, self._raise = (
            (np.zeros(0, dtype=int), 0.0, None) if guard is None else guard
        )
        self._ints, self._floats = pack(found, theta)
        self._none = np.zeros((0, 0))
        self._work = np.zeros(12 * len(found.kind) + WORK_SMALL)

    @classmethod
    def of(cls, model: ReferenceModel, guard=None) -> ElementKernels | None:
        """The kernels of ``model``, or None if :func:`tables` does not support it."""
        found = tables(model)
        return None if found is None else cls(model, found, guard)

    def _run(self, qp, vp, gains, tau_c, tau_d, K, D) -> float:
        qp, vp = np.ascontiguousarray(qp, dtype=float), np.ascontiguousarray(vp, dtype=float)
        U, bad = evaluate_packed(qp, vp, gains, tau_c, tau_d, K, D, self._work, self._ints,
                                 self._floats, self._theta_cos)  # fmt: skip
        if bad == -2:
            self._raise(qp)
        if bad >= 0:
            raise SingularConfigurationError("bushing at Euler-angle gimbal lock (θ = ±π/2)")
        return U

    def torques(self, qp: np.ndarray, vp: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Spring and damper forces ``τ_c``, ``τ_d`` (as ``element_torques``)."""
        tau_c, tau_d = np.zeros(self.nv), np.zeros(self.nv)
        self._run(qp, vp, False, tau_c, tau_d, self._none, self._none)
        return tau_c, tau_d

    def torques_and_gains(
        self, qp: np.ndarray, vp: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``τ_c``, ``τ_d``, ``Σ JᵀCJ`` and ``Σ JᵀDJ`` in one pass (for a Jacobian)."""
        n = self.nv
        tau_c, tau_d, K, D = np.zeros(n), np.zeros(n), np.zeros((n, n)), np.zeros((n, n))
        self._run(qp, vp, True, tau_c, tau_d, K, D)
        return tau_c, tau_d, K, D

    def gains(self, qp: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``Σ JᵀCJ`` and ``Σ JᵀDJ`` (as ``element_gains``)."""
        n = self.nv
        K, D = np.zeros((n, n)), np.zeros((n, n))
        self._run(qp, np.zeros(n), True, np.zeros(n), np.zeros(n), K, D)
        return K, D

    def potential(self, qp: np.ndarray) -> float:
        """``U_c = Σ ½ δᵀ C δ`` (as ``spring_potential``)."""
        n = self.nv
        return self._run(qp, np.zeros(n), False, np.zeros(n), np.zeros(n), self._none, self._none)


class RelativePoints:
    """Compiled positions of points in other bodies' frames and their Jacobians.

    For pairs of frames ``(joint, SE3)``: frame 2's origin in frame 1's axes,
    ``r12 = R1ᵀ (p2 − p1)``, and ``∂r12/∂v`` (3 × nv, Pinocchio's v), from the same
    joint walk as the elements (:func:`relative_points`). A gear sector's mesh point in
    its stator is one (:func:`rt70.reference.drives.drive_force_function`).
    Build with :meth:`of`, which gives None when a pair's path is not supported.
    """

    def __init__(self, model: ReferenceModel, found: dict[str, np.ndarray]) -> None:
        self.nv = model.pin_model.nv
        self.n = len(found["split"])
        self.v_index = found["v_index"]
        names = ("start", "split", "kind", "q_index", "axis", "place_R", "place_p")
        self._args = tuple(found[k] for k in names + ("frame_R", "frame_p"))
        self.start = found["start"]
        self._work = np.zeros(12 * len(found["kind"]) + WORK_SMALL)
        self._jac = np.zeros((len(found["kind"]), 6))

    @classmethod
    def of(cls, model: ReferenceModel, frames1, frames2) -> RelativePoints | None:
        """The kernels of these pairs, or None if :func:`paths` does not support them."""
        found = paths(model, frames1, frames2)
        return None if found is None else cls(model, found)

    def frames(self, qp: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(c12, r12, J)``: frame 2's rotation and origin in frame 1, and their Jacobian.

        Shapes (n, 3, 3), (n, 3) and (n, 6, nv): ``J = [∂r12/∂v; ∂ω12/∂v]``, the origin's
        velocity and frame 2's angular velocity relative to frame 1, in frame 1's axes.
        """
        c, r = np.zeros((self.n, 3, 3)), np.zeros((self.n, 3))
        qp = np.ascontiguousarray(qp, dtype=float)
        relative_points(qp, self._work, *self._args, c, r, self._jac)
        J = np.zeros((self.n, 6, self.nv))
        for b in range(self.n):
            lo, hi = self.start[b], self.start[b + 1]
            J[b][:, self.v_index[lo:hi]] = self._jac[lo:hi].T
        return c, r, J

    def __call__(self, qp: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(r12, ∂r12/∂v)`` of every pair: shapes (n, 3) and (n, 3, nv)."""
        _, r, J = self.frames(qp)
        return r, J[:, :3]
