"""The compiled joint walk between two frames, and the elements' forces evaluated on it.

The kernels of :mod:`rt70.reference.element_kernels` (read its docstring first), on
the tables of :mod:`rt70.reference.element_tables`: for each pair of frames, the
joints from their common ancestor down to each frame are composed,
``frame i = Π_k (placement_k · X_k(q_k)) · P_i`` (``_pair_pose``), recording each
joint's origin ``o_k`` and axis ``a_k``; frame 2 in frame 1 and the columns of its
Jacobian follow (:func:`relative_points`), and for the bushings the deformation
``δ = [r12; −rpy(c12ᵀ)]``, its Jacobian, and the forces, gains and potential of
every element (:func:`evaluate`, and :func:`evaluate_packed` on the two arrays of
:func:`rt70.reference.element_tables.pack`). Explicit 3×3 loops, no BLAS, no
allocation per call (the scratch is one buffer, ``_walk_scratch``); compiled on
first use and cached on disk.
"""

from __future__ import annotations

import math

import numba

from rt70.guards.kernel_cache import stamp_kernel_caches
from rt70.reference.element_tables import CONTINUOUS, PRISMATIC
from rt70.reference.forces import GIMBAL_LOCK_COS

stamp_kernel_caches()  # before the first numba.njit

#: Size of the kernels' fixed scratch (3×3 and 3-, 6-vectors) after the per-entry part.
WORK_SMALL = 117


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
    J_W⁻¹ at 54, 60, 66; T, X at 75, 84; its bushing scratch ``C δ``, ``D δ̇``, ``C Jₖ``,
    ``D Jₖ`` at 93.
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

    Parameters
    ----------
    qp : numpy.ndarray, shape (nq,)
        Pinocchio's configuration (contiguous float64).
    work : numpy.ndarray
        Scratch of ``12 n +`` :data:`WORK_SMALL` numbers, n the number of joint entries.
    start, split : numpy.ndarray
        int64, shapes (n_p + 1,) and (n_p,): pair b's joint entries are
        ``start[b]:start[b + 1]``, frame 2's branch from ``split[b]``
        (:class:`~rt70.reference.element_tables.Tables`).
    kind, q_index : numpy.ndarray
        int64 per joint entry: the joint's kind (``REVOLUTE``, ``PRISMATIC`` or
        ``CONTINUOUS`` of :mod:`rt70.reference.element_tables`) and its first index in
        ``qp``.
    axis, place_R, place_p : numpy.ndarray
        Per joint entry: unit axis in the joint's frame (n, 3), and the joint's
        placement in its parent joint, (n, 3, 3) and (n, 3) m.
    frame_R, frame_p : numpy.ndarray
        Each pair's two frames in their joints, (n_p, 2, 3, 3) and (n_p, 2, 3) m.
    c, r : numpy.ndarray
        Out: ``c12`` (n_p, 3, 3) and ``r12`` (n_p, 3) m.
    jac : numpy.ndarray, shape (n, 6)
        Out: per joint entry, ``[∂r12/∂q̇_k; ∂ω12/∂q̇_k]`` (m or m/rad; rad/rad).
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
def sector_angle(
    qp, work, start, split, kind, q_index, axis, place_R, place_p, frame_R, frame_p,
    c, r, jac, v_index, centre, u, v, gradient,
):  # fmt: skip
    """A gear sector's angle θ_d and ``∂θ_d/∂q̇`` from its mesh point in the stator.

    Pair 0 of :func:`relative_points` is the stator's frame and the mesh point; with
    ``d = r12 − centre``, ``x = u·d``, ``y = v·d`` the angle is ``atan2(y, x)`` and its
    gradient ``((x v − y u)/(x² + y²))ᵀ ∂r12/∂q̇`` on the pair's joints
    (:func:`rt70.reference.drives.drive_force_function`; the same numbers as its Python
    form).

    Parameters
    ----------
    qp, work, start, split, kind, q_index, axis, place_R, place_p, frame_R, frame_p, c, r, jac
        As :func:`relative_points` (pair 0: the stator's frame and the mesh point).
    v_index : numpy.ndarray
        int64 per joint entry: its column in Pinocchio's velocity.
    centre, u, v : numpy.ndarray, shape (3,)
        The pitch circle's centre (m) and its in-plane unit axes, in the stator's frame.
    gradient : numpy.ndarray, shape (nv,)
        Out: ``∂θ_d/∂q̇``, overwritten (zero but on the pair's joints' columns).
    """
    relative_points(qp, work, start, split, kind, q_index, axis, place_R, place_p, frame_R,
                    frame_p, c, r, jac)  # fmt: skip
    d0, d1, d2 = r[0, 0] - centre[0], r[0, 1] - centre[1], r[0, 2] - centre[2]
    x = u[0] * d0 + u[1] * d1 + u[2] * d2
    y = v[0] * d0 + v[1] * d1 + v[2] * d2
    h = x * x + y * y
    g0, g1, g2 = (x * v[0] - y * u[0]) / h, (x * v[1] - y * u[1]) / h, (x * v[2] - y * u[2]) / h
    gradient[:] = 0.0
    for k in range(start[0], start[1]):
        gradient[v_index[k]] = g0 * jac[k, 0] + g1 * jac[k, 1] + g2 * jac[k, 2]
    return math.atan2(y, x)


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

    Parameters
    ----------
    qp, vp : numpy.ndarray
        Pinocchio's configuration (nq,) and velocity (nv,), contiguous float64.
    gains : bool
        Whether to add the gains to K and D.
    tau_c, tau_d : numpy.ndarray, shape (nv,)
        Spring and damper forces in Pinocchio's velocity space (N, N·m), added to.
    K, D : numpy.ndarray, shape (nv, nv)
        Stiffness and damping gains, added to with ``gains`` (not read without).
    work : numpy.ndarray
        Scratch of ``12 n +`` :data:`WORK_SMALL` numbers, n the number of joint entries.
    start, split, kind, q_index, v_index : numpy.ndarray
        int64: each bushing's joint entries ``start[b]:start[b + 1]`` (frame 2's branch
        from ``split[b]``), and per entry the joint's kind (``REVOLUTE``, ``PRISMATIC``
        or ``CONTINUOUS``), q index and v index
        (:class:`~rt70.reference.element_tables.Tables`).
    axis, place_R, place_p : numpy.ndarray
        Per joint entry: unit axis in the joint's frame (n, 3), and the joint's
        placement in its parent joint, (n, 3, 3) and (n, 3) m.
    frame_R, frame_p : numpy.ndarray
        Each bushing's two frames in their joints, (n_b, 2, 3, 3) and (n_b, 2, 3) m.
    stiffness, damping : numpy.ndarray, shape (n_b, 6, 6)
        Each bushing's C (N/m, N·m/rad) and D (N·s/m, N·m·s/rad).
    spring_q, spring_v, spring_kind : numpy.ndarray
        int64 per joint spring: q index, v index, and
        :data:`~rt70.reference.element_tables.CONTINUOUS` for a continuous joint.
    spring_k, spring_d : numpy.ndarray
        Each joint spring's stiffness and damping.
    """
    n = kind.shape[0]
    origin, axis_w, R, R1, R2, p, p1, p2, w, lin, T, X = _walk_scratch(work, n)
    jac = work[6 * n : 12 * n].reshape((n, 6))
    small = work[12 * n :]
    c12, d = small[27:36].reshape((3, 3)), small[45:48]
    delta, rate = small[54:60], small[60:66]
    inv = small[66:75].reshape((3, 3))
    f = small[93:117].reshape((4, 6))
    inv[0, 2] = inv[1, 2] = 0.0
    U = 0.0
    for b in range(start.shape[0] - 1):
        lo, mid, hi = start[b], split[b], start[b + 1]
        _pair_pose(qp, b, lo, mid, hi, kind, q_index, axis, place_R, place_p, frame_R, frame_p,
                   R, p, R1, p1, R2, p2, origin, axis_w, T, X)  # fmt: skip
        if not _deformation(R1, R2, p1, p2, c12, d, delta, inv):
            return math.nan, b
        rate[:] = 0.0  # ∂δ/∂q̇_k of each joint entry, rotation rows J_W(ρ)⁻¹ R2ᵀ ω; δ̇
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
        _add_bushing(b, lo, hi, gains, jac, delta, rate, stiffness, damping, v_index,
                     tau_c, tau_d, K, D, f)  # fmt: skip
        for i in range(6):
            U += 0.5 * delta[i] * f[0, i]
    U = _add_joint_springs(U, qp, vp, gains, tau_c, tau_d, K, D,
                           spring_q, spring_v, spring_kind, spring_k, spring_d)  # fmt: skip
    return U, -1


@numba.njit(cache=True, inline="always")
def _deformation(R1, R2, p1, p2, c12, d, delta, inv):
    """δ of one bushing and ``J_W(ρ)⁻¹`` from its frames' poses; False at gimbal lock.

    ``c12 = R1ᵀ R2``, ``δ[:3] = r12 = R1ᵀ (p2 − p1)`` and ``δ[3:] = −ρ``, ρ the rpy of
    ``c12ᵀ`` (Pinocchio's ``matrixToRpy``); the inverse world rpy Jacobian of ρ into
    the first two columns of ``inv``. ``d`` is scratch.
    """
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
        return False
    delta[3], delta[4], delta[5] = -roll, -pitch, -yaw
    cy, sy, tp = math.cos(yaw), math.sin(yaw), math.tan(pitch)
    inv[0, 0], inv[0, 1] = cy / cp, sy / cp
    inv[1, 0], inv[1, 1] = -sy, cy
    inv[2, 0], inv[2, 1], inv[2, 2] = cy * tp, sy * tp, 1.0
    return True


@numba.njit(cache=True, inline="always")
def _add_bushing(b, lo, hi, gains, jac, delta, rate, stiffness, damping, v_index,
                 tau_c, tau_d, K, D, f):  # fmt: skip
    """Bushing b's ``−Jᵀ C δ``, ``−Jᵀ D δ̇`` (and ``JᵀCJ``, ``JᵀDJ``) on its own joints.

    Leaves ``C δ`` in ``f[0]`` (for the potential) and ``D δ̇`` in ``f[1]``; with
    ``gains``, ``f[2]`` and ``f[3]`` hold ``C Jₖ`` and ``D Jₖ`` of one joint entry at a
    time.
    """
    C, Dm = stiffness[b], damping[b]
    for i in range(6):
        fc = 0.0
        fd = 0.0
        for j in range(6):
            fc += C[i, j] * delta[j]
            fd += Dm[i, j] * rate[j]
        f[0, i], f[1, i] = fc, fd
    for k in range(lo, hi):
        fc = 0.0
        fd = 0.0
        for i in range(6):
            fc += jac[k, i] * f[0, i]
            fd += jac[k, i] * f[1, i]
        tau_c[v_index[k]] -= fc
        tau_d[v_index[k]] -= fd
    if not gains:
        return
    for k in range(lo, hi):
        for i in range(6):  # (C Jₖ)ᵢ, (D Jₖ)ᵢ, C and D symmetric
            kc = 0.0
            kd = 0.0
            for j in range(6):
                kc += C[i, j] * jac[k, j]
                kd += Dm[i, j] * jac[k, j]
            f[2, i], f[3, i] = kc, kd
        for m in range(lo, hi):
            kc = 0.0
            kd = 0.0
            for i in range(6):
                kc += jac[m, i] * f[2, i]
                kd += jac[m, i] * f[3, i]
            K[v_index[m], v_index[k]] += kc
            D[v_index[m], v_index[k]] += kd


@numba.njit(cache=True, inline="always")
def _add_joint_springs(U, qp, vp, gains, tau_c, tau_d, K, D, spring_q, spring_v, spring_kind,
                       spring_k, spring_d):  # fmt: skip
    """The joint springs (δ = the joint's coordinate) added in place; returns U + Σ ½ k δ²."""
    for e in range(spring_v.shape[0]):
        qi, vi = spring_q[e], spring_v[e]
        x = math.atan2(qp[qi + 1], qp[qi]) if spring_kind[e] == CONTINUOUS else qp[qi]
        tau_c[vi] -= spring_k[e] * x
        tau_d[vi] -= spring_d[e] * vp[vi]
        if gains:
            K[vi, vi] += spring_k[e]
            D[vi, vi] += spring_d[e]
        U += 0.5 * spring_k[e] * x * x
    return U


@numba.njit(cache=True)
def evaluate_packed(qp, vp, gains, tau_c, tau_d, K, D, work, ints, floats, theta_cos):
    """:func:`evaluate` on the packed tables; first the Euler pairs' guard.

    Returns ``(nan, -2)`` if a listed angle has ``|cos θ| < theta_cos``, else what
    :func:`evaluate` returns.

    Parameters
    ----------
    qp, vp, gains, tau_c, tau_d, K, D, work
        As :func:`evaluate`.
    ints, floats : numpy.ndarray
        The tables and the guarded angles' q indices, packed by
        :func:`rt70.reference.element_tables.pack` (int64, float64).
    theta_cos : float
        The guard: smallest ``|cos θ|`` allowed for the listed angles (0: no guard).
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
    stiffness = floats[j : j + 36 * n_b].reshape((n_b, 6, 6))
    j += 36 * n_b
    damping = floats[j : j + 36 * n_b].reshape((n_b, 6, 6))
    j += 36 * n_b
    spring_k, spring_d = floats[j : j + ns], floats[j + ns : j + 2 * ns]
    return evaluate(
        qp, vp, gains, tau_c, tau_d, K, D, work,
        start, split, kind, q_index, v_index, axis, place_R, place_p, frame_R, frame_p,
        stiffness, damping, spring_q, spring_v, spring_kind, spring_k, spring_d,
    )  # fmt: skip
