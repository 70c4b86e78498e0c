"""Compiled forward dynamics ``q̈ = A⁻¹ (Q_g + Q_c + Q_d − B q̇)`` and its Jacobian, in O(nv).

The right-hand side of an explicit first-order form ``ẋ = [q̇; q̈]`` of (1.73), (4.79),
for an integrator whose loop is compiled as well
(:mod:`rt70.simulation.bdf_kernel`): nothing here returns to Python.

- **Accelerations** (:func:`_forward`). The residual ``r = A q̈ + B q̇ − Q_g − Q_c − Q_d``
  at ``q̈ = 0`` by the recursive Newton–Euler algorithm with the bushings and joint
  springs (:mod:`rt70.textbook.motion_kernel`), then ``q̈ = −A⁻¹ r`` by the articulated-body
  algorithm at ``X = 0`` (:mod:`rt70.textbook.articulated_kernel`; Featherstone, *Rigid
  Body Dynamics Algorithms*, 2008, §7.3). The same passes give T, U_g, U_c and the
  dampers' power.
- **Jacobian** (:func:`_jacobian`) as its parts ``A``, ``R_q = ∂r/∂q`` and
  ``R_q̇ = ∂r/∂q̇`` at the accelerations held: ``∂q̈/∂x = −A⁻¹ R_x``. A by the mass
  kernel's composite inertias (:mod:`rt70.textbook.mass_kernel`). R two ways:

  - *exact*: columns by forward differences of the residual, of step
    ``√ε · max(|x_j|, 1)`` (a relative error of about 1e-8); a q column places the pairs
    from the coordinate's pair on again, and a bushing is differenced only in the
    coordinates of its path (its force depends on no other and acts on no other);
  - *material*: the springs' and dampers' ``Σ JᵀCJ``, ``Σ JᵀDJ`` and joint springs'
    ``k``, ``d`` (as the reference side's Jacobian): no geometric stiffness, gravity's or
    the inertial terms' derivatives. For an implicit integrator's Newton matrix
    ``A + c R_q̇ + c² R_q`` what it leaves out is of relative size ``c² g/ℓ`` and
    ``c ω``, far below the springs' ``c² k/m``. On the RT-70's 10 s transient at rtol
    1e-7 the compiled BDF took 4 830 evaluations and 154 Jacobians with it, 4 657 and
    156 with the exact one, a Jacobian costing 45 µs against 433 µs (measured by hand,
    2026-11-28).

Both refuse what the motion kernel refuses (modal bodies, mimic joints): build the data
with :meth:`ForwardData.of`, which gives None for such a model.
"""

from __future__ import annotations

import numba
import numpy as np

from rt70.errors import Rt70Error, SimulationError
from rt70.guards.arrays import check_vector
from rt70.guards.kernel_cache import stamp_kernel_caches
from rt70.textbook.articulated_kernel import _articulated_factor, _articulated_solve
from rt70.textbook.mass_kernel import _composite_inertias, _ground_inertia, _mass_entries
from rt70.textbook.model import Model
from rt70.textbook.motion_kernel import (
    MotionData,
    _bushing_force,
    _elements,
    _newton_euler,
    _place,
    _place_from,
)
from rt70.textbook.static_kernel import _check, placed_gains

stamp_kernel_caches()  # before the first numba.njit

#: Status of a kernel call: done.
DONE = -1
#: Status: an articulated inertia is not positive definite (the mass matrix is singular).
SINGULAR = -2
#: Status: the accelerations or a Jacobian column are not finite.
NOT_FINITE = -3

#: Positions in :attr:`ForwardData.arrays` (``K``), constants to numba: the static
#: kernel's gravity, model arrays, work buffers, bushings, dampings, paths, springs'
#: coordinates, stiffnesses and dampings, Jacobian buffer; the motion kernel's ground
#: inertias, pair transforms, spatial velocities, accelerations, forces and scratch; the
#: articulated factor's inertias, U, D⁻¹, bias forces, accelerations and joint forces u,
#: its zero added inertia X₀; zero accelerations; the residual; each coordinate's
#: bushings (pointers, indices); the held accelerations; each coordinate's pair.
(
    K_GRAVITY, K_ARRAYS, K_WORK, K_BUSHES, K_DAMPING, K_PATHS, K_SCOORD, K_SK, K_SD, K_JAC,
    K_I0, K_SL, K_V, K_AD, K_F, K_TMP,
    K_IA, K_U, K_DINV, K_PA, K_ACC6, K_U_FORCE, K_X0,
    K_ZERO, K_R, K_BPTR, K_BUSH, K_HELD, K_PAIR_OF,
) = range(29)  # fmt: skip


@numba.njit(cache=True)
def _residual(q, v, acc, K, out, sums) -> int:
    """``out = r(q, q̇, q̈)`` and ``sums = [T, U_g, U_c, P_d]``, the pairs placed at q.

    Returns :data:`DONE` or the bushing at gimbal lock.
    """
    _place(q, K[K_ARRAYS], K[K_WORK], K[K_I0], K[K_SL])
    _inverse_dynamics(v, acc, K, out, sums)
    return _elements(q, v, K[K_BUSHES], K[K_DAMPING], K[K_PATHS], K[K_SCOORD], K[K_SK],
                     K[K_SD], K[K_WORK], K[K_JAC], out, sums[2:])  # fmt: skip


@numba.njit(cache=True)
def _inverse_dynamics(v, acc, K, out, sums) -> None:
    """``out = A q̈ + B q̇ − Q_g`` of the placed pairs, ``sums[:2] = [T, U_g]`` (Newton–Euler)."""
    _newton_euler(v, acc, K[K_GRAVITY], K[K_ARRAYS], K[K_WORK][1], K[K_SL], K[K_I0], K[K_V],
                  K[K_AD], K[K_F], K[K_TMP], out, sums)  # fmt: skip


@numba.njit(cache=True)
def _solve(K, r, out) -> None:
    """``out = A⁻¹ r`` with the articulated factor of :func:`_forward` (pairs placed there)."""
    arrays = K[K_ARRAYS]
    _articulated_solve(arrays[0], arrays[2], arrays[3], K[K_WORK][1], K[K_SL], K[K_U],
                       K[K_DINV], r, K[K_PA], K[K_ACC6], K[K_U_FORCE], out)  # fmt: skip


@numba.njit(cache=True)
def _forward(q, v, K, acc, sums) -> int:
    """``acc = q̈(q, q̇)`` and ``sums = [T, U_g, U_c, P_d]`` (module docstring).

    Leaves the pairs placed at q and the articulated factor of ``A(q)``. Returns
    :data:`DONE`, :data:`SINGULAR`, :data:`NOT_FINITE` or the bushing at gimbal lock.
    """
    arrays, r = K[K_ARRAYS], K[K_R]
    bad = _residual(q, v, K[K_ZERO], K, r, sums)
    if bad >= 0:
        return bad
    if not _articulated_factor(arrays[0], arrays[2], arrays[3], K[K_WORK][1], K[K_SL],
                               K[K_I0], K[K_X0], K[K_IA], K[K_U], K[K_DINV]):  # fmt: skip
        return SINGULAR
    for i in range(r.shape[0]):
        r[i] = -r[i]
    _solve(K, r, acc)
    for i in range(acc.shape[0]):
        if not np.isfinite(acc[i]):
            return NOT_FINITE
    return DONE


@numba.njit(cache=True)
def _difference_column(j, h, v, K, ne0, base, buf, out) -> int:
    """Column j of ``∂r/∂x`` into ``out`` by a forward difference of step h.

    The pairs are placed at the perturbed q, ``v`` is the perturbed q̇. Returns
    :data:`DONE` or the bushing at gimbal lock.
    """
    bushes, damping, paths, work, jac = K[K_BUSHES], K[K_DAMPING], K[K_PATHS], K[K_WORK], K[K_JAC]
    cptr, ccol = paths[2], paths[3]
    bptr, bush = K[K_BPTR], K[K_BUSH]
    sums = np.empty(2)
    _inverse_dynamics(v, K[K_HELD], K, buf, sums)
    for i in range(buf.shape[0]):
        out[i] = (buf[i] - ne0[i]) / h
        buf[i] = 0.0
    for m in range(bptr[j], bptr[j + 1]):  # the bushings whose path holds coordinate j
        k = bush[m]
        if not _bushing_force(k, v, bushes, damping, paths, work, jac, buf, sums):
            return k
        for u in range(cptr[k], cptr[k + 1]):
            out[ccol[u]] += (buf[ccol[u]] - base[k, u - cptr[k]]) / h
            buf[ccol[u]] = 0.0
    return DONE


@numba.njit(cache=True)
def _bushing_baselines(v, K, base, buf) -> None:
    """Each bushing's ``−(Q_c + Q_d)`` on its path's coordinates at the placed q, into ``base``."""
    work, bushes, damping, paths, jac = K[K_WORK], K[K_BUSHES], K[K_DAMPING], K[K_PATHS], K[K_JAC]
    cptr, ccol = paths[2], paths[3]
    sums = np.empty(2)
    buf[:] = 0.0
    for k in range(bushes[0].shape[0]):
        _bushing_force(k, v, bushes, damping, paths, work, jac, buf, sums)
        for u in range(cptr[k], cptr[k + 1]):
            base[k, u - cptr[k]] = buf[ccol[u]]
            buf[ccol[u]] = 0.0


@numba.njit(cache=True)
def _mass(arrays, work, A) -> None:
    """``A(q)`` of the placed pairs by the mass kernel's composite inertias (§4.3, (4.79))."""
    parent, q_start, ndof, Theta = arrays[0], arrays[2], arrays[3], arrays[7]
    C, p, sigma = work[0], work[1], work[3]
    theta_c = np.empty((parent.shape[0], 6, 6))
    L, T, F = np.empty((6, 6)), np.empty((6, 6)), np.empty(6)
    for j in range(parent.shape[0]):
        _ground_inertia(C[j], p[j], Theta[j], L, T, theta_c[j])
    _composite_inertias(parent, theta_c)
    _mass_entries(parent, q_start, ndof, theta_c, sigma, F, A)


@numba.njit(cache=True)
def _material_stiffness(K, Rq, X, sk) -> int:
    """``R = Σ Jᵀ X J`` of the bushings and the joint springs' ``sk``, at the placed pairs.

    With X the bushings' stiffness and sk the springs', the material stiffness alone: no
    geometric stiffness, gravity's or the inertial terms' derivatives (module docstring);
    with their dampings, the dampers' ``∂r/∂q̇``. Returns :data:`DONE` or the bushing at
    gimbal lock (:func:`rt70.textbook.static_kernel.placed_gains`).
    """
    jac = K[K_JAC]
    block = np.empty((jac.shape[0], jac.shape[0]))
    return placed_gains(K[K_BUSHES], X, K[K_PATHS], K[K_SCOORD], sk, K[K_WORK], jac, block, Rq)


@numba.njit(cache=True)
def _jacobian(q, v, K, acc, A, Rq, Rv) -> int:
    """``A(q)``, ``R_q = ∂r/∂q`` and ``R_q̇ = ∂r/∂q̇`` by differences at (q, q̇, q̈(q, q̇)).

    ``∂q̈/∂x = −A⁻¹ R_x`` (module docstring); ``acc = q̈``. A by the mass kernel's
    composite inertias; R's columns by forward differences, a bushing differenced only in
    the coordinates of its path (its force depends on no other and acts on no other).
    Returns the status of :func:`_forward`.
    """
    sums = np.empty(4)
    status = _forward(q, v, K, acc, sums)
    if status != DONE:
        return status
    _mass(K[K_ARRAYS], K[K_WORK], A)
    status = _differences(q, v, K, acc, Rq, Rv)
    return status if status != DONE else _finite(Rq, Rv)


@numba.njit(cache=True)
def _material_jacobian(q, K, A, Rq, Rv) -> int:
    """``A(q)`` and the springs' and dampers' material gains ``Σ JᵀCJ``, ``Σ JᵀDJ`` at q.

    The R of Newton's matrix (module docstring, :func:`_material_stiffness`); the pairs
    are placed at q. Returns :data:`DONE`, :data:`NOT_FINITE` or the bushing at gimbal
    lock.
    """
    _place(q, K[K_ARRAYS], K[K_WORK], K[K_I0], K[K_SL])
    _mass(K[K_ARRAYS], K[K_WORK], A)
    status = _material_stiffness(K, Rv, K[K_DAMPING], K[K_SD])
    if status == DONE:
        status = _material_stiffness(K, Rq, K[K_BUSHES][6], K[K_SK])
    return status if status != DONE else _finite(Rq, Rv)


@numba.njit(cache=True)
def _finite(Rq, Rv) -> int:
    """:data:`DONE` if every entry of both is finite, else :data:`NOT_FINITE`."""
    for i in range(Rq.shape[0]):
        for j in range(Rq.shape[1]):
            if not (np.isfinite(Rq[i, j]) and np.isfinite(Rv[i, j])):
                return NOT_FINITE
    return DONE


@numba.njit(cache=True)
def _differences(q, v, K, acc, Rq, Rv) -> int:
    """``R_q``, ``R_q̇`` by forward differences at ``acc`` held (:func:`_jacobian`)."""
    n = q.shape[0]
    held, scoord, sd = K[K_HELD], K[K_SCOORD], K[K_SD]
    held[:] = acc
    sums, ne0, buf, col = np.empty(4), np.empty(n), np.zeros(n), np.empty(n)
    base = np.empty((K[K_BUSHES][0].shape[0], max(K[K_JAC].shape[0], 1)))
    _inverse_dynamics(v, held, K, ne0, sums)
    _bushing_baselines(v, K, base, buf)
    y = v.copy()
    for j in range(n):
        h = 1.4901161193847656e-08 * max(abs(v[j]), 1.0)
        y[j] = v[j] + h
        h = y[j] - v[j]
        _difference_column(j, h, y, K, ne0, base, buf, col)
        y[j] = v[j]
        Rv[:, j] = col
    for i in range(scoord.shape[0]):
        Rv[scoord[i], scoord[i]] += sd[i]
    return _q_columns(q, v, K, ne0, base, Rq)


@numba.njit(cache=True)
def _q_columns(q, v, K, ne0, base, Rq) -> int:
    """``R_q`` by forward differences (:func:`_jacobian`), the pairs placed at q after."""
    n = q.shape[0]
    arrays, work, I0, sl = K[K_ARRAYS], K[K_WORK], K[K_I0], K[K_SL]
    scoord, sk = K[K_SCOORD], K[K_SK]
    buf, col = np.zeros(n), np.empty(n)
    x, pair_of = q.copy(), K[K_PAIR_OF]
    for j in range(n - 1, -1, -1):  # the pairs from j's on placed again: all moved before
        h = 1.4901161193847656e-08 * max(abs(q[j]), 1.0)
        x[j] = q[j] + h
        h = x[j] - q[j]
        _place_from(x, pair_of[j], arrays, work, I0, sl)
        status = _difference_column(j, h, v, K, ne0, base, buf, col)
        x[j] = q[j]
        if status != DONE:
            return status
        Rq[:, j] = col
    _place_from(q, pair_of[0] if n else 0, arrays, work, I0, sl)
    for i in range(scoord.shape[0]):
        Rq[scoord[i], scoord[i]] += sk[i]
    return DONE


class ForwardData:
    """The motion kernel's data and this kernel's buffers, as one tuple the kernels take.

    Build with :meth:`of`, which gives None for a model the kernels do not cover.

    Attributes
    ----------
    motion : MotionData
        The motion kernel's arrays and buffers.
    arrays : tuple
        What :func:`_forward` and :func:`_jacobian` take (``K``).
    """

    def __init__(self, motion: MotionData, nv: int) -> None:
        self.motion = motion
        st, m = motion.static, motion
        X0 = np.zeros_like(m.X)
        self.arrays = (
            st.gravity, st.arrays, st.work, st.bushes, st.damping, st.paths, st.scoord, st.sk,
            st.sd, st.jac, m.I0, m.sl, m.V, m.Ad, m.F, m.tmp, m.IA, m.U, m.Dinv, m.pA, m.acc6,
            m.u, X0, np.zeros(nv), np.zeros(nv), *_bushings_of_coordinates(st.paths, nv),
            np.zeros(nv), m.pair_of,
        )  # fmt: skip

    @classmethod
    def of(cls, model: Model) -> ForwardData | None:
        """The kernel's data for ``model``, or None with modal bodies or mimic joints."""
        motion = MotionData.of(model)
        return None if motion is None else cls(motion, model.nv)


def _bushings_of_coordinates(paths, nv: int) -> tuple[np.ndarray, np.ndarray]:
    """``(bptr, bush)``: coordinate j's bushings are ``bush[bptr[j]:bptr[j + 1]]``.

    The transpose of the paths' compressed rows: the bushings whose path holds j.
    """
    cptr, ccol = paths[2], paths[3]
    owners = np.repeat(np.arange(cptr.size - 1, dtype=np.int64), np.diff(cptr))
    order = np.argsort(ccol, kind="stable")
    bptr = np.zeros(nv + 1, dtype=np.int64)
    np.add.at(bptr, ccol + 1, 1)
    return np.cumsum(bptr), np.ascontiguousarray(owners[order], dtype=np.int64)


def raise_status(model: Model, data: ForwardData, status: int) -> None:
    """Raise the error a kernel's ``status`` stands for (nothing for :data:`DONE`).

    Parameters
    ----------
    model : Model
        The textbook model.
    data : ForwardData
        Its kernel data.
    status : int
        What :func:`_forward` or :func:`_jacobian` returned.
    """
    if status == SINGULAR:
        raise Rt70Error(
            f"{model.name}: the articulated inertia of a pair is singular or not positive definite"
        )
    if status == NOT_FINITE:
        raise SimulationError("the accelerations are not finite")
    _check(data.motion.static, status)


def _state(model: Model, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(q, q̇)`` checked against nv and copied as floats."""
    return tuple(
        np.array(check_vector(s, x, model.nv), dtype=float) for s, x in (("q", q), ("v", v))
    )


def accelerations(
    model: Model, data: ForwardData, q: np.ndarray, v: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``(q̈, [T, U_g, U_c, P_d])`` at (q, q̇), new arrays.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : ForwardData
        ``ForwardData.of(model)``.
    q, v : numpy.ndarray, shape (nv,)
        Coordinates (rad or m) and velocities (rad/s or m/s) in the model's order.
    """
    q, v = _state(model, q, v)
    acc, sums = np.empty(model.nv), np.empty(4)
    raise_status(model, data, _forward(q, v, data.arrays, acc, sums))
    data.motion.placed[:] = np.nan  # the motion kernel's placement cache no longer holds
    return acc, sums


def jacobian(
    model: Model, data: ForwardData, q: np.ndarray, v: np.ndarray, exact: bool = True
) -> tuple[np.ndarray, np.ndarray]:
    """``(∂q̈/∂q, ∂q̈/∂q̇)`` at (q, q̇) by the kernel's ``−A⁻¹ R``, new arrays (nv, nv).

    Parameters
    ----------
    model : Model
        The textbook model.
    data : ForwardData
        ``ForwardData.of(model)``.
    q, v : numpy.ndarray, shape (nv,)
        Coordinates and velocities in the model's order.
    exact : bool
        ∂q̈/∂q by differences (else from the springs' material stiffness alone, what
        Newton's matrix of :mod:`rt70.simulation.bdf_kernel` uses).
    """
    q, v = _state(model, q, v)
    n = model.nv
    A, Rq, Rv, acc = np.empty((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty(n)
    K = data.arrays
    status = _jacobian(q, v, K, acc, A, Rq, Rv) if exact else _material_jacobian(q, K, A, Rq, Rv)
    raise_status(model, data, status)
    data.motion.placed[:] = np.nan
    return -np.linalg.solve(A, Rq), -np.linalg.solve(A, Rv)
