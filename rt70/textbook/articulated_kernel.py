"""The iteration matrix ``A + X`` of an implicit step, factored and solved in O(nv).

The articulated-body algorithm (Featherstone, *Rigid Body Dynamics Algorithms*, 2008,
§7.3, at zero velocity) on the placements of :mod:`rt70.textbook.motion_kernel`, with
its spatial vectors about each pair's own origin: from the leaves, ``U = Iᴬ σ``,
``D_j = σᵀ U + X_j``, ``Iᴬ_parent += Mᵀ (Iᴬ_j − U D_j⁻¹ Uᵀ) M`` with M the move from the
parent's origin to the child's; a solve passes the bias ``pᴬ`` up and the accelerations
down. ``X_j`` is pair j's own block (``γ′h D + β′h² K`` of the generalized-α method,
:mod:`rt70.simulation.generalized_alpha`), so the matrix never exists as nv × nv.
"""

from __future__ import annotations

import numba
import numpy as np

from rt70.errors import Rt70Error
from rt70.guards.kernel_cache import stamp_kernel_caches
from rt70.textbook.model import Model
from rt70.textbook.motion_kernel import MotionData, _add_shifted_force, _placed, _shift_motion

stamp_kernel_caches()  # before the first numba.njit


@numba.njit(cache=True)
def _spd_inverse(D: np.ndarray, out: np.ndarray, L: np.ndarray, y: np.ndarray) -> bool:
    """``out = D⁻¹`` by Cholesky (D = L Lᵀ); False unless D is symmetric positive definite.

    ``L`` (n × n or larger) and ``y`` (n or longer) are work buffers.
    """
    n = D.shape[0]
    for i in range(n):
        for k in range(i + 1):
            x = D[i, k]
            for m in range(k):
                x -= L[i, m] * L[k, m]
            if i == k:
                if not x > 0.0:  # also False for NaN
                    return False
                L[i, i] = np.sqrt(x)
            else:
                L[i, k] = x / L[k, k]
    for c in range(n):  # columns of D⁻¹: L y = e_c, then Lᵀ x = y
        for i in range(n):
            x = 1.0 if i == c else 0.0
            for m in range(i):
                x -= L[i, m] * y[m]
            y[i] = x / L[i, i]
        for i in range(n - 1, -1, -1):
            x = y[i]
            for m in range(i + 1, n):
                x -= L[m, i] * out[m, c]
            out[i, c] = x / L[i, i]
    return True


@numba.njit(cache=True)
def _zero(X: np.ndarray) -> bool:
    """True if every entry of ``X`` is zero."""
    for i in range(X.shape[0]):
        for k in range(X.shape[1]):
            if X[i, k] != 0.0:
                return False
    return True


@numba.njit(cache=True)
def _articulated_factor(parent, q_start, ndof, p, sl, I0, X, IA, U, Dinv) -> bool:
    """``Iᴬ``, ``U = Iᴬ σ`` and ``D_j⁻¹ = (σᵀ U + X_j)⁻¹`` from the leaves; False if singular.

    About each pair's origin, as :func:`_newton_euler`: a child's ``Iᴬ − U D⁻¹ Uᵀ`` is
    moved to its parent's origin by ``Mᵀ I M``, ``M = [[1, −<d>], [0, 1]]``.
    """
    IA[:] = I0
    Y, Ia, D, L = np.empty((6, 6)), np.empty((6, 6)), np.empty((6, 6)), np.empty((6, 6))
    d, y = np.empty(3), np.empty(6)
    for j in range(parent.shape[0] - 1, -1, -1):
        s0, nd = q_start[j], ndof[j]
        for a in range(s0, s0 + nd):
            for m in range(6):
                x = 0.0
                for n in range(6):
                    x += IA[j, m, n] * sl[a, n]
                U[a, m] = x
        for a in range(nd):
            for b in range(nd):
                x = X[j, a, b]
                for m in range(6):
                    x += sl[s0 + a, m] * U[s0 + b, m]
                D[a, b] = x
        Di = Dinv[j, :nd, :nd]
        if not _spd_inverse(D[:nd, :nd], Di, L, y):
            return False
        i = parent[j]
        if i < 0 or (nd == 6 and _zero(X[j])):
            continue  # a six-coordinate pair without X passes its parent Iᴬ − U D⁻¹ Uᵀ = 0
        for m in range(6):  # Y = U D⁻¹ (6 × nd), then Ia = Iᴬ_j − Y Uᵀ
            for b in range(nd):
                x = 0.0
                for a in range(nd):
                    x += U[s0 + a, m] * Di[a, b]
                Y[m, b] = x
        for m in range(6):
            for n in range(6):
                x = IA[j, m, n]
                for b in range(nd):
                    x -= Y[m, b] * U[s0 + b, n]
                Ia[m, n] = x
        for m in range(3):
            d[m] = p[j, m] - p[i, m]
        for m in range(6):  # Ia M: columns 3–5 gain −(row m's first three) × d
            a0, a1, a2 = Ia[m, 0], Ia[m, 1], Ia[m, 2]
            Ia[m, 3] -= a1 * d[2] - a2 * d[1]
            Ia[m, 4] -= a2 * d[0] - a0 * d[2]
            Ia[m, 5] -= a0 * d[1] - a1 * d[0]
        for n in range(6):  # Mᵀ (Ia M): rows 3–5 gain d × (column n's first three)
            b0, b1, b2 = Ia[0, n], Ia[1, n], Ia[2, n]
            IA[i, 0, n] += b0
            IA[i, 1, n] += b1
            IA[i, 2, n] += b2
            IA[i, 3, n] += Ia[3, n] + d[1] * b2 - d[2] * b1
            IA[i, 4, n] += Ia[4, n] + d[2] * b0 - d[0] * b2
            IA[i, 5, n] += Ia[5, n] + d[0] * b1 - d[1] * b0
    return True


@numba.njit(cache=True)
def _articulated_solve(parent, q_start, ndof, p, sl, U, Dinv, r, pA, acc6, u, out) -> None:
    """``x = (A + X)⁻¹ r`` after :func:`_articulated_factor` (module docstring)."""
    pA[:] = 0.0
    nb = parent.shape[0]
    f, d = np.empty(6), np.empty(3)
    for j in range(nb - 1, -1, -1):
        s0, nd = q_start[j], ndof[j]
        for a in range(s0, s0 + nd):
            x = r[a]
            for m in range(6):
                x -= sl[a, m] * pA[j, m]
            u[a] = x
        i = parent[j]
        if i < 0:
            continue
        for m in range(6):
            f[m] = pA[j, m]
        for a in range(nd):  # pᴬ_parent += pᴬ_j + U D⁻¹ u, moved to the parent's origin
            x = 0.0
            for b in range(nd):
                x += Dinv[j, a, b] * u[s0 + b]
            for m in range(6):
                f[m] += U[s0 + a, m] * x
        for m in range(3):
            d[m] = p[j, m] - p[i, m]
        _add_shifted_force(f, d, pA[i])
    for j in range(nb):
        i = parent[j]
        s0, nd = q_start[j], ndof[j]
        if i >= 0:
            for m in range(3):
                d[m] = p[j, m] - p[i, m]
            _shift_motion(acc6[i], d, acc6[j])
        else:
            for m in range(6):
                acc6[j, m] = 0.0
        for a in range(nd):  # y = u − Uᵀ a_parent
            x = u[s0 + a]
            for m in range(6):
                x -= U[s0 + a, m] * acc6[j, m]
            out[s0 + a] = x
        for a in range(nd):
            x = 0.0
            for b in range(nd):
                x += Dinv[j, a, b] * out[s0 + b]
            f[a] = x
        for a in range(nd):
            out[s0 + a] = f[a]
            for m in range(6):
                acc6[j, m] += sl[s0 + a, m] * f[a]


def articulated_factor(model: Model, data: MotionData, q: np.ndarray, X: np.ndarray) -> None:
    """Factor ``A(q) + X`` (X: pair-local blocks, (nb, 6, 6)) for :func:`articulated_solve`.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : MotionData
        ``MotionData.of(model)``; holds the factor.
    q : numpy.ndarray, shape (nv,)
        Coordinates in the model's order, rad or m.
    X : numpy.ndarray, shape (nb, 6, 6)
        Each pair's own block (upper left ``ndof × ndof`` used), in A's units.

    Raises
    ------
    Rt70Error
        If a pair's articulated inertia is not positive definite.
    """
    st = data.static
    _placed(model, data, q)
    parent, q_start, ndof = st.arrays[0], st.arrays[2], st.arrays[3]
    ok = _articulated_factor(parent, q_start, ndof, st.work[1], data.sl, data.I0,
                             np.ascontiguousarray(X, dtype=float), data.IA, data.U,
                             data.Dinv)  # fmt: skip
    if not ok:
        raise Rt70Error(
            f"{model.name}: the articulated inertia of a pair is singular or not positive definite"
        )


def articulated_solve(model: Model, data: MotionData, r: np.ndarray) -> np.ndarray:
    """``x = (A + X)⁻¹ r`` with the factor of :func:`articulated_factor`, a new array.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : MotionData
        The data :func:`articulated_factor` filled.
    r : numpy.ndarray, shape (nv,)
        The right-hand side, in A's force units (N or N·m).
    """
    st = data.static
    parent, q_start, ndof = st.arrays[0], st.arrays[2], st.arrays[3]
    out = np.empty(model.nv)
    _articulated_solve(parent, q_start, ndof, st.work[1], data.sl, data.U, data.Dinv,
                       np.ascontiguousarray(r, dtype=float), data.pA, data.acc6, data.u,
                       out)  # fmt: skip
    return out
