"""Newton's matrix of the compiled BDF (:mod:`rt70.simulation.bdf_kernel`): taken, factored, solved.

The step's Newton system, reduced to the velocities (the kernel's docstring), has the
matrix ``M = A + c R_q̇ + c² R_q``: the mass matrix and the springs' and dampers'
material gains ``R_q = Σ JᵀCJ``, ``R_q̇ = Σ JᵀDJ`` (with the joint springs' k and d), all
at the state where the Jacobian was last taken (:func:`jacobian_at`). Two forms:

- **pair-local** (every bushing acts across one pair, ``MotionData.local``): the gains
  are blocks of each pair's own coordinates, so M is the mass matrix plus a pair-local
  X, which the articulated-body algorithm factors and solves in O(nv) without forming M
  (:mod:`rt70.textbook.articulated_kernel`, as the generalized-α method does), with the
  pairs' placement and inertias of the Jacobian's state kept beside the factor;
- **dense** (a bushing across pairs): A and R as nv × nv arrays
  (:func:`rt70.textbook.forward_kernel._material_jacobian`), M factored by LU with partial
  pivoting.

The flag ``s[LOCAL]`` of the run chooses. ``newton = (dense, local)`` holds both
buffers; the unused one is of size 1.
"""

from __future__ import annotations

import numba
import numpy as np

from rt70.guards.kernel_cache import stamp_kernel_caches
from rt70.textbook.articulated_kernel import _articulated_factor, _articulated_solve
from rt70.textbook.forward_kernel import (
    DONE,
    K_ARRAYS,
    K_BUSHES,
    K_DAMPING,
    K_I0,
    K_JAC,
    K_PAIR_OF,
    K_PATHS,
    K_SCOORD,
    K_SD,
    K_SK,
    K_SL,
    K_WORK,
    SINGULAR,
    _material_jacobian,
)
from rt70.textbook.motion_kernel import _pair_gains, _place

stamp_kernel_caches()  # before the first numba.njit


def buffers(nv: int, nb: int, local: bool) -> tuple[tuple, tuple]:
    """``(dense, local)``: the buffers of Newton's matrix in the form asked, the other of size 1.

    Parameters
    ----------
    nv, nb : int
        Coordinates and pairs of the model.
    local : bool
        The pair-local form.
    """
    m, k = (1, nb) if local else (nv, 1)
    dense = (np.empty((m, m)), np.zeros(m, dtype=np.int64), *(np.empty((m, m)) for _ in range(3)))
    local_buffers = (
        *(np.zeros((k, 6, 6)) for _ in range(5)),  # K, D, X, I0 at the Jacobian, Iᴬ
        np.empty((nv if local else 1, 6)),  # σ of the pairs at the Jacobian
        np.empty((k, 3)),  # their origins
        np.empty((nv if local else 1, 6)),  # U
        np.zeros((k, 6, 6)),  # D⁻¹
        np.empty((k, 6)),  # pᴬ
        np.empty((k, 6)),  # the pairs' accelerations
        np.empty(nv),  # u
        np.empty(nv),  # the right-hand side
    )
    return dense, local_buffers


@numba.njit(cache=True)
def _pair_jacobian(q, K, local) -> int:
    """Each pair's blocks of the gains and the placement at q, into the local buffers."""
    Kp, Dp, _, I0J, _, slJ, pJ = local[:7]
    arrays, work, bushes, damping = K[K_ARRAYS], K[K_WORK], K[K_BUSHES], K[K_DAMPING]
    paths, scoord, sk, sd, jac = K[K_PATHS], K[K_SCOORD], K[K_SK], K[K_SD], K[K_JAC]
    I0, sl, pair_of = K[K_I0], K[K_SL], K[K_PAIR_OF]
    _place(q, arrays, work, I0, sl)
    block = np.empty((jac.shape[0], jac.shape[0]))
    q_start = arrays[2]
    _pair_gains(bushes, bushes[6], paths, scoord, sk, pair_of, q_start, work, jac, block, Kp)
    _pair_gains(bushes, damping, paths, scoord, sd, pair_of, q_start, work, jac, block, Dp)
    I0J[:] = I0
    slJ[:] = sl
    pJ[:] = work[1]
    return DONE


@numba.njit(cache=True)
def jacobian_at(K, n, y, newton, s, local) -> int:
    """Take the Jacobian's parts at ``y`` (the module docstring's form); the kernel's status.

    Parameters
    ----------
    K : tuple
        The forward kernel's arrays.
    n : int
        Coordinates, nv.
    y : numpy.ndarray, shape (2 nv + 1,)
        The state.
    newton : tuple
        ``(dense, local)`` (:func:`buffers`).
    s : numpy.ndarray
        The run's scalars (``s[njev]`` counted by the caller).
    local : bool
        The pair-local form.
    """
    if local:
        return _pair_jacobian(y[:n].copy(), K, newton[1])
    dense = newton[0]
    return _material_jacobian(y[:n].copy(), K, dense[2], dense[3], dense[4])


@numba.njit(cache=True)
def factor(K, newton, c, local) -> int:
    """Factor ``M = A + c R_q̇ + c² R_q``; :data:`DONE` or :data:`SINGULAR`.

    Parameters
    ----------
    K : tuple
        The forward kernel's arrays.
    newton : tuple
        ``(dense, local)`` with the Jacobian's parts.
    c : float
        The step's ``h / α_k``, s.
    local : bool
        The pair-local form.
    """
    if not local:
        LU, piv, A, Rq, Rv = newton[0]
        _lu_factor(A, Rq, Rv, c, LU, piv)
        return DONE
    Kp, Dp, X, I0J, IA, slJ, pJ, U, Dinv = newton[1][:9]
    arrays = K[K_ARRAYS]
    for j in range(X.shape[0]):
        for a in range(6):
            for b in range(6):
                X[j, a, b] = c * Dp[j, a, b] + c * c * Kp[j, a, b]
    ok = _articulated_factor(arrays[0], arrays[2], arrays[3], pJ, slJ, I0J, X, IA, U, Dinv)
    return DONE if ok else SINGULAR


@numba.njit(cache=True)
def _lu_factor(A, Rq, Rv, c, LU, piv) -> None:
    """``LU = A + c R_q̇ + c² R_q`` factored in place with partial pivoting (rows in ``piv``)."""
    n = LU.shape[0]
    for i in range(n):
        for j in range(n):
            LU[i, j] = A[i, j] + c * Rv[i, j] + c * c * Rq[i, j]
    for k in range(n):
        p = k
        for i in range(k + 1, n):
            if abs(LU[i, k]) > abs(LU[p, k]):
                p = i
        piv[k] = p
        if p != k:
            for j in range(n):
                LU[k, j], LU[p, j] = LU[p, j], LU[k, j]
        if LU[k, k] == 0.0:
            continue
        for i in range(k + 1, n):
            LU[i, k] /= LU[k, k]
            m = LU[i, k]
            for j in range(k + 1, n):
                LU[i, j] -= m * LU[k, j]


@numba.njit(cache=True)
def solve(K, newton, c, b, n, out, local) -> None:
    """``out = (1 − c J)⁻¹ G`` by the kernel's reduction, ``b = [G_q; A G_q̇; G_E]``.

    Parameters
    ----------
    K : tuple
        The forward kernel's arrays.
    newton : tuple
        ``(dense, local)``, factored (:func:`factor`).
    c : float
        The step's ``h / α_k``, s.
    b : numpy.ndarray, shape (2 nv + 1,)
        The Newton residual as :func:`rt70.simulation.bdf_kernel._newton_residual` gives it.
    n : int
        Coordinates, nv.
    out : numpy.ndarray, shape (2 nv + 1,)
        The correction ``[Δq; Δq̇; ΔE]``.
    local : bool
        The pair-local form.
    """
    x = out[n : 2 * n]
    if local:
        _local_solve(K, newton[1], c, b, n, x)
    else:
        _dense_solve(newton[0], c, b, n, x)
    for i in range(n):
        out[i] = b[i] + c * x[i]
    for i in range(2 * n, b.shape[0]):
        out[i] = b[i]


@numba.njit(cache=True)
def _dense_solve(dense, c, b, n, x) -> None:
    """``x = M⁻¹ (A G_q̇ − c R_q G_q)`` with the LU of :func:`_lu_factor`."""
    LU, piv, _, Rq, _ = dense
    for i in range(n):
        s = b[n + i]
        for j in range(n):
            s -= c * Rq[i, j] * b[j]
        x[i] = s
    for k in range(n):
        p = piv[k]
        if p != k:
            x[k], x[p] = x[p], x[k]
    for i in range(n):
        for j in range(i):
            x[i] -= LU[i, j] * x[j]
    for i in range(n - 1, -1, -1):
        for j in range(i + 1, n):
            x[i] -= LU[i, j] * x[j]
        x[i] /= LU[i, i]


@numba.njit(cache=True)
def _local_solve(K, local, c, b, n, x) -> None:
    """``x = M⁻¹ (A G_q̇ − c R_q G_q)`` by the articulated-body solve, R_q by its pair blocks."""
    Kp, _, _, _, _, slJ, pJ, U, Dinv, pA, acc6, u, rhs = local
    arrays = K[K_ARRAYS]
    q_start, ndof = arrays[2], arrays[3]
    for j in range(q_start.shape[0]):
        s0, nd = q_start[j], ndof[j]
        for a in range(nd):
            s = b[n + s0 + a]
            for m in range(nd):
                s -= c * Kp[j, a, m] * b[s0 + m]
            rhs[s0 + a] = s
    _articulated_solve(arrays[0], q_start, ndof, pJ, slJ, U, Dinv, rhs, pA, acc6, u, x)
