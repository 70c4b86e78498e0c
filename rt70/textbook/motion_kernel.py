"""Compiled equations of motion of the book's model in O(nv): residual and iteration matrix.

An implicit integrator of a model of thousands of coordinates
(:mod:`rt70.simulation.generalized_alpha`) needs, at every Newton iterate, the residual
of the equations of motion (1.73), (4.79)

    r = A(q) q̈ + B(q, q̇) q̇ − Q_g(q) − Q_c(q) − Q_d(q, q̇)

and, at every step, solutions of ``(A + X) x = r`` with X a pair-local stiffness and
damping. Forming A costs O(nv²) memory and its factorisation O(nv³); this kernel does
neither. It works on the mass kernel's placements (:mod:`rt70.textbook.mass_kernel`:
each pair's ``C_j`` and ``p_j``), with spatial vectors in E0's axes (``[v; w]`` for
motions, ``[f; n]`` for forces) taken about each pair's own origin ``p_j``: the axes
``σ_a = [C v_a; C w_a]`` and the inertia ``R Θ_j Rᵀ`` ((4.77) about ``p_j``), moved from
a parent's origin to a child's by ``d = p_j − p_i`` (motions ``v + w × d``, forces
``n + d × f``). About E0's origin instead (as the mass kernel's ``σ`` and ``Θ⁰``) a
structure 2 km from it loses 2.7e-10 of its residual to the cancellation of lever-arm
terms ``m |p|²``; about its own origin each term is the size of the body's own motion.

- **The residual** by the recursive Newton–Euler algorithm (Featherstone, *Rigid Body
  Dynamics Algorithms*, 2008, §5.3). A pair is a
  series of elementary motions in the order of its coordinates (euler6: x, y, z in the
  construction frame, then β, θ, α; planar: x, y, then α), so axis a is fixed in the
  frame moved by its pair's earlier coordinates, whose velocity is
  ``W_a = V_parent + Σ_{b<a} σ_b q̇_b``, and ``σ̇_a = W_a ×ₘ σ_a``. Forward:
  ``V_j = V_parent + Σ σ_a q̇_a``, ``Ȧ_j = Ȧ_parent + Σ (σ̇_a q̇_a + σ_a q̈_a)`` from the
  ground's ``[−g; 0]`` (gravity as a ground acceleration), each moved to the child's
  origin; ``F_j = Θ_j Ȧ_j + V_j ×* Θ_j V_j``. Backward: ``τ_a = σ_aᵀ F_j``,
  ``F_parent += F_j`` moved to the parent's origin. Then ``r = τ − Q_c − Q_d`` with the
  bushings' ``Q = −Jᵀ (C δ + D J q̇)`` over their paths (as
  :mod:`rt70.textbook.static_kernel`) and the joint springs' ``−k q − d q̇``.
- **The pairs' own blocks** of ``Σ JᵀCJ`` and ``Σ JᵀDJ`` (:func:`pair_gains`), the X of
  the iteration matrix ``A + X`` that :mod:`rt70.textbook.articulated_kernel` factors.

Compiled on first use and cached on disk, like the other kernels. Models with modal
bodies or mimic joints have no kernel (:meth:`MotionData.of` gives None).
"""

from __future__ import annotations

import numba
import numpy as np

from rt70.guards.kernel_cache import stamp_kernel_caches
from rt70.textbook.mass_kernel import place_pair
from rt70.textbook.model import Model
from rt70.textbook.static_kernel import (
    StaticData,
    _bushing_rows,
    _check,
    _path_gain,
    _twist_rows,
)

stamp_kernel_caches()  # before the first numba.njit


@numba.njit(cache=True)
def _cross_motion(m: np.ndarray, s: np.ndarray, out: np.ndarray) -> None:
    """``out = m ×ₘ s = [w × s_v + v × s_w; w × s_w]`` for ``m = [v; w]``."""
    out[0] = m[4] * s[2] - m[5] * s[1] + m[1] * s[5] - m[2] * s[4]
    out[1] = m[5] * s[0] - m[3] * s[2] + m[2] * s[3] - m[0] * s[5]
    out[2] = m[3] * s[1] - m[4] * s[0] + m[0] * s[4] - m[1] * s[3]
    out[3] = m[4] * s[5] - m[5] * s[4]
    out[4] = m[5] * s[3] - m[3] * s[5]
    out[5] = m[3] * s[4] - m[4] * s[3]


@numba.njit(cache=True)
def _add_cross_force(m: np.ndarray, f: np.ndarray, out: np.ndarray) -> None:
    """``out += m ×* f = [w × f_f; w × f_n + v × f_f]`` for ``m = [v; w]``, ``f = [f_f; f_n]``."""
    out[0] += m[4] * f[2] - m[5] * f[1]
    out[1] += m[5] * f[0] - m[3] * f[2]
    out[2] += m[3] * f[1] - m[4] * f[0]
    out[3] += m[4] * f[5] - m[5] * f[4] + m[1] * f[2] - m[2] * f[1]
    out[4] += m[5] * f[3] - m[3] * f[5] + m[2] * f[0] - m[0] * f[2]
    out[5] += m[3] * f[4] - m[4] * f[3] + m[0] * f[1] - m[1] * f[0]


@numba.njit(cache=True)
def _place(qf, arrays, work, I0, sl) -> None:
    """Every pair's placement (into ``work``), its axes and inertia at its own origin.

    ``sl[a] = [C v_a; C w_a]``: axis a at the origin ``p_j`` of its pair, in E0's axes;
    ``I0[j] = R Θ_j Rᵀ`` with ``R = diag(C_j, C_j)``: (4.77) about ``p_j`` instead of O.
    """
    _place_from(qf, 0, arrays, work, I0, sl)


@numba.njit(cache=True)
def _place_from(qf, first, arrays, work, I0, sl) -> None:
    """:func:`_place` of the pairs from index ``first`` on, the others placed already.

    A pair's parent has a smaller index.
    """
    parent, kind, q_start, ndof, axis, r_c, c_c, Theta = arrays[:8]
    C, p, _, sigma, m6, m3, v3 = work[:7]
    for j in range(first, parent.shape[0]):
        place_pair(j, qf, parent, kind, q_start, ndof, axis, r_c, c_c, C, p, sigma, m6[0], m3, v3)
        rows = m6[0]  # the pair's body-frame axes, as place_pair left them
        for a in range(ndof[j]):
            for i in range(3):
                x, y = 0.0, 0.0
                for m in range(3):
                    x += C[j, i, m] * rows[a, m]
                    y += C[j, i, m] * rows[a, 3 + m]
                sl[q_start[j] + a, i] = x
                sl[q_start[j] + a, 3 + i] = y
        _rotated_inertia(C[j], Theta[j], m6[1], I0[j])


@numba.njit(cache=True)
def _rotated_inertia(Cj: np.ndarray, Theta_j: np.ndarray, T: np.ndarray, out: np.ndarray) -> None:
    """``out = R Θ_j Rᵀ``, ``R = diag(C_j, C_j)``: (4.77) turned into E0's axes, block by block.

    Each 3 × 3 block ``Θ_ab`` becomes ``C Θ_ab Cᵀ``; ``T`` (6 × 6) is scratch.
    """
    for a in range(6):  # T = R Θ: rows of each block row turned by C
        r = 3 * (a // 3)
        i = a - r
        for b in range(6):
            T[a, b] = (Cj[i, 0] * Theta_j[r, b] + Cj[i, 1] * Theta_j[r + 1, b]
                       + Cj[i, 2] * Theta_j[r + 2, b])  # fmt: skip
    for a in range(6):  # out = T Rᵀ (symmetric: the upper triangle, mirrored)
        for b in range(a, 6):
            c = 3 * (b // 3)
            k = b - c
            x = T[a, c] * Cj[k, 0] + T[a, c + 1] * Cj[k, 1] + T[a, c + 2] * Cj[k, 2]
            out[a, b] = x
            out[b, a] = x


@numba.njit(cache=True)
def _shift_motion(m: np.ndarray, d: np.ndarray, out: np.ndarray) -> None:
    """``out = [v + w × d; w]``: motion ``m = [v; w]`` from a point to the point ``+ d``."""
    out[0] = m[0] + m[4] * d[2] - m[5] * d[1]
    out[1] = m[1] + m[5] * d[0] - m[3] * d[2]
    out[2] = m[2] + m[3] * d[1] - m[4] * d[0]
    out[3], out[4], out[5] = m[3], m[4], m[5]


@numba.njit(cache=True)
def _add_shifted_force(f: np.ndarray, d: np.ndarray, out: np.ndarray) -> None:
    """``out += [f_f; f_n + d × f_f]``: force ``f`` at the point ``+ d`` moved to the point."""
    out[0] += f[0]
    out[1] += f[1]
    out[2] += f[2]
    out[3] += f[3] + d[1] * f[2] - d[2] * f[1]
    out[4] += f[4] + d[2] * f[0] - d[0] * f[2]
    out[5] += f[5] + d[0] * f[1] - d[1] * f[0]


@numba.njit(cache=True)
def _newton_euler(v, acc, gravity, arrays, p, sl, I0, V, Ad, F, tmp, out, sums) -> None:
    """``τ = A q̈ + B q̇ − Q_g`` into ``out`` after :func:`_place` (module docstring).

    Each body's V, Ȧ, F in E0's axes about its own origin ``p_j`` (moved between a
    parent's origin and a child's by ``d = p_j − p_i``), so that no term carries the
    lever arm of E0's origin. ``sums[0]`` = T, ``sums[1] = U_g = −Σ g · m x_cm``.
    """
    parent, q_start, ndof, mass = arrays[0], arrays[2], arrays[3], arrays[8]
    T, U = 0.0, 0.0
    d = np.empty(3)
    for j in range(parent.shape[0]):
        # the first moment about p_j is Θ's lower left block m <C c>
        U -= gravity[0] * (mass[j] * p[j, 0] + I0[j, 5, 1])
        U -= gravity[1] * (mass[j] * p[j, 1] + I0[j, 3, 2])
        U -= gravity[2] * (mass[j] * p[j, 2] + I0[j, 4, 0])
        i = parent[j]
        if i >= 0:
            for m in range(3):
                d[m] = p[j, m] - p[i, m]
            _shift_motion(V[i], d, V[j])
            _shift_motion(Ad[i], d, Ad[j])
        else:  # the ground: at rest, accelerating by −g (gravity), at any point
            for m in range(6):
                V[j, m] = 0.0
                Ad[j, m] = -gravity[m] if m < 3 else 0.0
        for a in range(q_start[j], q_start[j] + ndof[j]):
            s = sl[a]
            _cross_motion(V[j], s, tmp[0])  # σ̇_a = W_a ×ₘ σ_a; V[j] holds W_a here
            for m in range(6):
                Ad[j, m] += tmp[0, m] * v[a] + s[m] * acc[a]
                V[j, m] += s[m] * v[a]
        h = tmp[1]
        for m in range(6):  # h = Θ V (momentum), F = Θ Ȧ + V ×* h
            x, y = 0.0, 0.0
            for n in range(6):
                x += I0[j, m, n] * V[j, n]
                y += I0[j, m, n] * Ad[j, n]
            h[m] = x
            F[j, m] = y
        for m in range(6):
            T += 0.5 * V[j, m] * h[m]
        _add_cross_force(V[j], h, F[j])
    for j in range(parent.shape[0] - 1, -1, -1):
        for a in range(q_start[j], q_start[j] + ndof[j]):
            x = 0.0
            for m in range(6):
                x += sl[a, m] * F[j, m]
            out[a] = x
        i = parent[j]
        if i >= 0:
            for m in range(3):
                d[m] = p[j, m] - p[i, m]
            _add_shifted_force(F[j], d, F[i])
    sums[0], sums[1] = T, U


@numba.njit(cache=True)
def _bushing_force(k, v, bushes, damping, paths, work, jac, out, sums) -> bool:
    """``out −= Q_c + Q_d`` of bushing ``k`` alone, on its path; False at gimbal lock.

    ``sums[0] += ½ δᵀ C δ``, ``sums[1] += δ̇ᵀ D δ̇``.
    """
    C, p, sigma, W, rows = work[0], work[1], work[3], work[7], work[8]
    body1, body2, r1, c1, r2, c2, Cb = bushes
    cptr, ccol, csign = paths[2], paths[3], paths[4]
    if not _bushing_rows(k, body1, body2, r1, c1, r2, c2, C, p, W):
        return False
    rate, f = rows[0], rows[1]
    rate[:] = 0.0
    for u in range(cptr[k], cptr[k + 1]):
        _twist_rows(W, sigma[ccol[u]], csign[u], jac[u - cptr[k]])
        for i in range(6):
            rate[i] += jac[u - cptr[k], i] * v[ccol[u]]
    for i in range(6):
        x, y = 0.0, 0.0
        for m in range(6):
            x += Cb[k, i, m] * W[0, m]
            y += damping[k, i, m] * rate[m]
        sums[0] += 0.5 * W[0, i] * x
        sums[1] += rate[i] * y
        f[i] = x + y
    for u in range(cptr[k], cptr[k + 1]):
        x = 0.0
        for i in range(6):
            x += jac[u - cptr[k], i] * f[i]
        out[ccol[u]] += x
    return True


@numba.njit(cache=True)
def _elements(qf, v, bushes, damping, paths, scoord, sk, sd, work, jac, out, sums) -> int:
    """``out −= Q_c + Q_d`` of the bushings and joint springs; U_c and P_d into ``sums``.

    ``sums[0] = Σ ½ δᵀ C δ`` (J), ``sums[1] = Σ δ̇ᵀ D δ̇`` (W, the dampers' power).
    Returns −1, or the bushing at gimbal lock.
    """
    sums[0], sums[1] = 0.0, 0.0
    for k in range(bushes[0].shape[0]):
        if not _bushing_force(k, v, bushes, damping, paths, work, jac, out, sums):
            return k
    for i in range(scoord.shape[0]):
        a = scoord[i]
        out[a] += sk[i] * qf[a] + sd[i] * v[a]
        sums[0] += 0.5 * sk[i] * qf[a] * qf[a]
        sums[1] += sd[i] * v[a] * v[a]
    return -1


@numba.njit(cache=True)
def _pair_gains(bushes, X, paths, scoord, sk, pair_of, q_start, work, jac, block, out) -> None:
    """Each pair's own block of ``Σ Jᵀ X J`` (bushings on one pair) and its joint springs' k.

    Into ``out`` (nb, 6, 6), after :func:`_place`; a bushing whose path is more than one
    pair is left out (:func:`pair_gains` reports those).
    """
    C, p, sigma, W, rows = work[0], work[1], work[3], work[7], work[8]
    body1, body2, r1, c1, r2, c2, _ = bushes
    ptr, pbody, cptr, ccol = paths[0], paths[1], paths[2], paths[3]
    out[:] = 0.0
    for k in range(body1.shape[0]):
        if ptr[k + 1] - ptr[k] != 1:
            continue
        j = pbody[ptr[k]]
        _bushing_rows(k, body1, body2, r1, c1, r2, c2, C, p, W)  # lock: caught by the residual
        cols = ccol[cptr[k] : cptr[k + 1]]
        for u in range(_path_gain(k, X, paths, sigma, W, jac, rows, block)):
            for v in range(cols.shape[0]):
                out[j, cols[v] - q_start[j], cols[u] - q_start[j]] += block[v, u]
    for i in range(scoord.shape[0]):
        a = scoord[i]
        j = pair_of[a]
        out[j, a - q_start[j], a - q_start[j]] += sk[i]


class MotionData:
    """The static kernel's arrays and the work buffers of this kernel, for one model.

    Build with :meth:`of`, which gives None for a model the kernels do not cover.

    Attributes
    ----------
    static : StaticData
        The model's arrays, bushing paths and placement buffers
        (:class:`rt70.textbook.static_kernel.StaticData`).
    local : bool
        Every bushing's path is one pair: :func:`pair_gains` holds all of Σ JᵀCJ and Σ JᵀDJ.
    """

    def __init__(self, static: StaticData) -> None:
        self.static = static
        parent, q_start, ndof = static.arrays[0], static.arrays[2], static.arrays[3]
        nb, n = parent.shape[0], int(q_start[-1] + ndof[-1]) if parent.size else 0
        self.pair_of = np.repeat(np.arange(nb, dtype=np.int64), ndof)
        self.I0, self.IA, self.X = (np.zeros((nb, 6, 6)) for _ in range(3))
        self.Dinv = np.zeros((nb, 6, 6))
        self.V, self.Ad, self.F, self.pA, self.acc6 = (np.zeros((nb, 6)) for _ in range(5))
        self.U, self.u, self.sl = np.zeros((n, 6)), np.zeros(n), np.zeros((n, 6))
        self.tmp = np.zeros((2, 6))
        ptr = static.paths[0]
        self.local = bool(np.all(np.diff(ptr) == 1))
        self.placed = np.full(n, np.nan)

    @classmethod
    def of(cls, model: Model) -> MotionData | None:
        """The kernel's data for ``model``, or None with modal bodies or mimic joints."""
        static = StaticData.of(model)
        return None if static is None else cls(static)


def _placed(model: Model, data: MotionData, q: np.ndarray) -> np.ndarray:
    """Place the pairs at ``q`` unless they are placed there already; q as floats."""
    q = np.asarray(q, dtype=float)
    if not np.array_equal(q, data.placed):
        _place(q, data.static.arrays, data.static.work, data.I0, data.sl)
        data.placed[:] = q
    return q


def residual(
    model: Model, data: MotionData, q: np.ndarray, v: np.ndarray, acc: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``r = A q̈ + B q̇ − Q_g − Q_c − Q_d`` and the energies ``[T, U_g, U_c, P_d]``.

    T is the kinetic energy, U_g gravity's (as the textbook side's), U_c the springs'
    ``Σ ½ δᵀ C δ`` (J), P_d the dampers' power ``−q̇ᵀ Q_d`` (W).

    Parameters
    ----------
    model : Model
        The textbook model.
    data : MotionData
        ``MotionData.of(model)``.
    q, v, acc : numpy.ndarray, shape (nv,)
        Coordinates (rad or m), velocities (rad/s or m/s) and accelerations
        (rad/s² or m/s²) in the model's order.

    Raises
    ------
    SingularConfigurationError
        A bushing's Euler angles at gimbal lock.
    """
    st = data.static
    q = _placed(model, data, q)
    out, energies = np.empty(model.nv), np.empty(4)
    v = np.asarray(v, dtype=float)
    _newton_euler(v, np.asarray(acc, dtype=float), st.gravity, st.arrays, st.work[1], data.sl,
                  data.I0, data.V, data.Ad, data.F, data.tmp, out, energies)  # fmt: skip
    bad = _elements(q, v, st.bushes, st.damping, st.paths, st.scoord, st.sk, st.sd, st.work,
                    st.jac, out, energies[2:])  # fmt: skip
    _check(st, bad)
    return out, energies


def pair_gains(model: Model, data: MotionData, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each pair's own blocks of ``Σ Jᵀ C J`` and ``Σ Jᵀ D J``, shape (nb, 6, 6) each.

    Exact for a model whose bushings each act on one pair (``data.local``); otherwise the
    bushings across pairs are left out.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : MotionData
        ``MotionData.of(model)``.
    q : numpy.ndarray, shape (nv,)
        Coordinates in the model's order, rad or m.
    """
    st = data.static
    q = _placed(model, data, q)
    out = []
    for X, k in ((st.bushes[6], st.sk), (st.damping, st.sd)):
        G = np.empty((model.nb, 6, 6))
        _pair_gains(st.bushes, X, st.paths, st.scoord, k, data.pair_of, st.arrays[2], st.work,
                    st.jac, st.block, G)  # fmt: skip
        out.append(G)
    return out[0], out[1]
