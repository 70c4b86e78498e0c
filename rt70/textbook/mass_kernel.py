"""Compiled kernel of the book's ``A = S Θ Sᵀ`` (§4.3, (4.79)), per call and batched.

The same structured algorithm as :mod:`rt70.textbook.structured` (read its docstring
first; that numpy form is the readable reference this kernel is tested against), written
as plain loops over the bodies of the tree and compiled with numba, so that a call costs
arithmetic instead of Python and numpy call overhead:

1. forward pass, parents before children: the absolute placement
   ``L_0^j = L_0^i T(r_c)[c_c] T(r_j)[c_j]`` (4.5)–(4.7), kept as its rotation ``C_j``
   and origin ``p_j`` (``T(r1)[c1] T(r2)[c2] = T(r1 + c1 r2)[c1 c2]``);
2. ``σ_a = (L_0^j)⁻ᵀ M_j f_j e_a`` — pair j's mobility axes seen from E0: for a body-frame
   axis ``[v; w]``, ``σ = [C v + p × C w; C w]``;
3. ``Θ⁰_j = L_0^j Θ_j (L_0^j)ᵀ`` (4.77), and the composite inertia
   ``Θᶜ_k = Σ_{j ⪰ k} Θ⁰_j`` accumulated from the leaves to the root;
4. ``A_la = σ_lᵀ Θᶜ_{body(a)} σ_a`` for ``body(l) ⪯ body(a)`` (and symmetric), walking
   from each body up its ancestors; 0 across branches.

With mimic constraints the kernel reduces ``A = Gᵀ A_full G`` itself (G in compressed
rows, one entry per mimic row). Compiled on first use and cached on disk
(:mod:`rt70.guards.kernel_cache`); no threads of its own: a batch is a plain loop.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from rt70.errors import Rt70Error
from rt70.guards.arrays import check_vector
from rt70.guards.kernel_cache import stamp_kernel_caches
from rt70.textbook.model import Model
from rt70.textbook.structured import _check_batch, _data_for

stamp_kernel_caches()  # before the first numba.njit

#: Pair kinds as the kernel's integer codes (:data:`rt70.textbook.model.PAIR_KINDS`).
KIND_CODE = {"euler6": 0, "revolute": 1, "prismatic": 2, "planar": 3}


@numba.njit(cache=True)
def _matmul3(a: np.ndarray, b: np.ndarray, out: np.ndarray) -> None:
    """``out = a b`` for 3 × 3 arrays (loops: numba's ``@`` calls BLAS, slow at this size)."""
    for i in range(3):
        for m in range(3):
            out[i, m] = a[i, 0] * b[0, m] + a[i, 1] * b[1, m] + a[i, 2] * b[2, m]


@numba.njit(cache=True)
def _matvec3(a: np.ndarray, x: np.ndarray, out: np.ndarray) -> None:
    """``out = a x`` for a 3 × 3 array and a 3-vector."""
    for i in range(3):
        out[i] = a[i, 0] * x[0] + a[i, 1] * x[1] + a[i, 2] * x[2]


@numba.njit(cache=True)
def _pair_motion(
    kind: int, axis: np.ndarray, q: np.ndarray, c: np.ndarray, r: np.ndarray, rows: np.ndarray
) -> None:
    """One pair's own motion ``c_j``, ``r_j`` and its axes ``M_j f_j``, into the buffers.

    Row a of ``rows`` is the body-frame axis ``[v; w]`` of coordinate a (4.8), (1.38).
    """
    c[:] = 0.0
    r[:] = 0.0
    rows[:] = 0.0
    if kind == 0:  # euler6: c = c1(β) c2(θ) c3(α) (1.23); rows of diag(cᵀ, ε)
        sb, cb = np.sin(q[3]), np.cos(q[3])
        st, ct = np.sin(q[4]), np.cos(q[4])
        sa, ca = np.sin(q[5]), np.cos(q[5])
        # c23 = c2(θ) c3(α), row by row; c = c1(β) c23
        rows[3, 3], rows[3, 4], rows[3, 5] = ct * ca, -ct * sa, st  # (c2 c3)ᵀ e_x as a row
        rows[4, 3], rows[4, 4] = sa, ca  # c3ᵀ e_y
        rows[5, 5] = 1.0  # e_z
        c23_2 = (-st * ca, st * sa, ct)
        for m in range(3):
            c[0, m] = rows[3, 3 + m]
            c[1, m] = cb * rows[4, 3 + m] - sb * c23_2[m]
            c[2, m] = sb * rows[4, 3 + m] + cb * c23_2[m]
        for i in range(3):
            r[i] = q[i]
            for m in range(3):
                rows[i, m] = c[i, m]
    elif kind == 1:  # revolute: Rodrigues, c = 1 + sin q <a> + (1 − cos q) <a>²
        s, v = np.sin(q[0]), 1.0 - np.cos(q[0])
        x, y, z = axis[0], axis[1], axis[2]
        n2 = x * x + y * y + z * z
        # <a>² = a aᵀ − |a|² 1
        c[0, 0] = 1.0 + v * (x * x - n2)
        c[1, 1] = 1.0 + v * (y * y - n2)
        c[2, 2] = 1.0 + v * (z * z - n2)
        c[0, 1], c[1, 0] = -s * z + v * x * y, s * z + v * x * y
        c[0, 2], c[2, 0] = s * y + v * x * z, -s * y + v * x * z
        c[1, 2], c[2, 1] = -s * x + v * y * z, s * x + v * y * z
        for i in range(3):
            rows[0, 3 + i] = axis[i]
    elif kind == 2:  # prismatic
        for i in range(3):
            c[i, i] = 1.0
            r[i] = q[0] * axis[i]
            rows[0, i] = axis[i]
    else:  # planar: x, y in the construction frame, then α about its z axis
        sa, ca = np.sin(q[2]), np.cos(q[2])
        c[0, 0], c[0, 1], c[1, 0], c[1, 1], c[2, 2] = ca, -sa, sa, ca, 1.0
        r[0], r[1] = q[0], q[1]
        rows[0, 0], rows[0, 1], rows[1, 0], rows[1, 1] = ca, -sa, sa, ca
        rows[2, 5] = 1.0


@numba.njit(cache=True)
def _ground_inertia(
    Cj: np.ndarray, pj: np.ndarray, Theta_j: np.ndarray, L: np.ndarray, T: np.ndarray, out
) -> None:
    """Step 3 for one pair: ``Θ⁰_j = L Θ_j Lᵀ`` with ``L = L_0^j = [[C, 0], [<p> C, C]]`` (4.77).

    Into ``out`` (6, 6); ``L`` and ``T`` are 6 × 6 scratch.
    """
    L[:3, 3:] = 0.0
    for m in range(3):
        L[m, :3] = Cj[m]
        L[3 + m, 3:] = Cj[m]
        L[3, m] = pj[1] * Cj[2, m] - pj[2] * Cj[1, m]
        L[4, m] = pj[2] * Cj[0, m] - pj[0] * Cj[2, m]
        L[5, m] = pj[0] * Cj[1, m] - pj[1] * Cj[0, m]
    for a in range(6):  # T = L Θ_j (the upper right block of L is zero)
        for b in range(6):
            acc = 0.0
            for k in range(3 if a < 3 else 6):
                acc += L[a, k] * Theta_j[k, b]
            T[a, b] = acc
    for a in range(6):  # Θ⁰_j = T Lᵀ (symmetric: the upper triangle, mirrored)
        for b in range(a, 6):
            acc = 0.0
            for k in range(3 if b < 3 else 6):
                acc += T[a, k] * L[b, k]
            out[a, b] = acc
            out[b, a] = acc


@numba.njit(cache=True)
def place_pair(
    j: int,
    qf: np.ndarray,
    parent: np.ndarray,
    kind: np.ndarray,
    q_start: np.ndarray,
    ndof: np.ndarray,
    axis: np.ndarray,
    r_c: np.ndarray,
    c_c: np.ndarray,
    C: np.ndarray,
    p: np.ndarray,
    sigma: np.ndarray,
    rows: np.ndarray,
    m3: np.ndarray,
    v3: np.ndarray,
) -> None:
    """Steps 1–2 for pair ``j``, its parent already placed: ``C[j]``, ``p[j]`` and its ``σ``.

    Parameters
    ----------
    j : int
        The pair.
    qf, parent, kind, q_start, ndof, axis, r_c, c_c : numpy.ndarray
        The full coordinates and the model's arrays (:func:`forward_pass`).
    C, p, sigma : numpy.ndarray
        In: the parent's placement; out: pair j's (:func:`forward_pass`).
    rows, m3, v3 : numpy.ndarray, shapes (6, 6), (2, 3, 3), (6, 3)
        Scratch.
    """
    (c, cc), (r, rr, w, v), s0 = m3, v3[:4], q_start[j]
    _pair_motion(kind[j], axis[j], qf[s0 : s0 + ndof[j]], c, r, rows)
    _matmul3(c_c[j], c, cc)  # the construction frame's rotation, then the pair's
    _matvec3(c_c[j], r, rr)
    for m in range(3):
        rr[m] += r_c[j, m]
    i = parent[j]
    if i < 0:
        C[j] = cc
        p[j] = rr
    else:
        _matmul3(C[i], cc, C[j])
        _matvec3(C[i], rr, p[j])
        for m in range(3):
            p[j, m] += p[i, m]
    Cj, pj = C[j], p[j]
    for a in range(ndof[j]):  # σ = [C v + p × C w; C w]
        _matvec3(Cj, rows[a, 3:], w)
        _matvec3(Cj, rows[a, :3], v)
        sigma[s0 + a, 0] = v[0] + pj[1] * w[2] - pj[2] * w[1]
        sigma[s0 + a, 1] = v[1] + pj[2] * w[0] - pj[0] * w[2]
        sigma[s0 + a, 2] = v[2] + pj[0] * w[1] - pj[1] * w[0]
        sigma[s0 + a, 3:] = w


@numba.njit(cache=True)
def forward_pass(
    qf: np.ndarray,
    parent: np.ndarray,
    kind: np.ndarray,
    q_start: np.ndarray,
    ndof: np.ndarray,
    axis: np.ndarray,
    r_c: np.ndarray,
    c_c: np.ndarray,
    Theta: np.ndarray,
    C: np.ndarray,
    p: np.ndarray,
    theta_c: np.ndarray,
    sigma: np.ndarray,
    m6: np.ndarray,
    m3: np.ndarray,
    v3: np.ndarray,
    inertias: bool = True,
) -> None:
    """Steps 1–3 at one configuration: ``C``, ``p``, ``σ`` and the composite ``Θᶜ``.

    Nothing is allocated here; the scratch arrays are contiguous slices, so that the
    compiled loops stay simple.

    Parameters
    ----------
    qf : numpy.ndarray, shape (n,)
        The full coordinates (mimic joints included), rad or m.
    parent, kind, q_start, ndof, axis, r_c, c_c, Theta : numpy.ndarray
        The model's arrays (:class:`KernelModel`).
    C, p : numpy.ndarray, shapes (nb, 3, 3) and (nb, 3)
        Out: each pair's absolute rotation and origin ``L_0^j``.
    theta_c : numpy.ndarray, shape (nb, 6, 6)
        Out: the composite inertias ``Θᶜ_k`` in E0 (untouched without ``inertias``).
    sigma : numpy.ndarray, shape (n, 6)
        Out: the mobility axes ``σ_a`` seen from E0.
    m6, m3, v3 : numpy.ndarray, shapes (3, 6, 6), (2, 3, 3), (6, 3)
        Scratch.
    inertias : bool
        Step 3 too (False: steps 1–2 only).
    """
    rows, L, T = m6[0], m6[1], m6[2]
    for j in range(parent.shape[0]):  # steps 1 and 2, parents first
        place_pair(j, qf, parent, kind, q_start, ndof, axis, r_c, c_c, C, p, sigma, rows, m3, v3)
        if inertias:
            _ground_inertia(C[j], p[j], Theta[j], L, T, theta_c[j])
    if inertias:
        _composite_inertias(parent, theta_c)


@numba.njit(cache=True)
def _mass_matrix_one(
    qf: np.ndarray,
    parent: np.ndarray,
    kind: np.ndarray,
    q_start: np.ndarray,
    ndof: np.ndarray,
    axis: np.ndarray,
    r_c: np.ndarray,
    c_c: np.ndarray,
    Theta: np.ndarray,
    C: np.ndarray,
    p: np.ndarray,
    theta_c: np.ndarray,
    sigma: np.ndarray,
    m6: np.ndarray,
    m3: np.ndarray,
    v3: np.ndarray,
    out: np.ndarray,
) -> None:
    """``A_full`` at one configuration into ``out`` (module docstring, steps 1–4)."""
    forward_pass(
        qf, parent, kind, q_start, ndof, axis, r_c, c_c, Theta, C, p, theta_c, sigma, m6, m3, v3
    )
    _mass_entries(parent, q_start, ndof, theta_c, sigma, v3[4:].reshape(6), out)


@numba.njit(cache=True)
def _composite_inertias(parent: np.ndarray, theta_c: np.ndarray) -> None:
    """Step 3: ``Θᶜ_k = Σ_{j ⪰ k} Θ⁰_j`` in place, from the leaves to the root."""
    for j in range(parent.shape[0] - 1, -1, -1):  # children follow parents
        i = parent[j]
        if i >= 0:
            for a in range(6):
                for b in range(6):
                    theta_c[i, a, b] += theta_c[j, a, b]


@numba.njit(cache=True)
def _mass_entries(
    parent: np.ndarray,
    q_start: np.ndarray,
    ndof: np.ndarray,
    theta_c: np.ndarray,
    sigma: np.ndarray,
    F: np.ndarray,
    out: np.ndarray,
) -> None:
    """Step 4: ``A_la = σ_lᵀ Θᶜ_k σ_a`` for a of body k, l of k (l ≤ a) or of its ancestors.

    And its mirror ``A_al``; zero across branches. ``F`` is a scratch 6-vector.
    """
    out[:] = 0.0
    for k in range(parent.shape[0]):
        sk = q_start[k]
        for a in range(sk, sk + ndof[k]):
            for m in range(6):  # F = Θᶜ_k σ_a
                acc = 0.0
                for n in range(6):
                    acc += theta_c[k, m, n] * sigma[a, n]
                F[m] = acc
            i = k
            while i >= 0:  # A_la = σ_l · F for l of body k (l ≤ a) and of its ancestors
                stop = a + 1 if i == k else q_start[i] + ndof[i]
                for l in range(q_start[i], stop):  # noqa: E741  (the book's index l)
                    x = 0.0
                    for n in range(6):
                        x += sigma[l, n] * F[n]
                    out[l, a] = x
                    out[a, l] = x
                i = parent[i]


@numba.njit(cache=True)
def _reduce(
    full: np.ndarray, g_ptr: np.ndarray, g_col: np.ndarray, g_val: np.ndarray, out: np.ndarray
) -> None:
    """``out = Gᵀ A_full G`` with G in compressed rows (a mimic row has one entry)."""
    out[:] = 0.0
    n = full.shape[0]
    for a in range(n):
        for b in range(n):
            x = full[a, b]
            if x == 0.0:
                continue
            for ia in range(g_ptr[a], g_ptr[a + 1]):
                xa = g_val[ia] * x
                for ib in range(g_ptr[b], g_ptr[b + 1]):
                    out[g_col[ia], g_col[ib]] += xa * g_val[ib]
    m = out.shape[0]
    for i in range(m):  # exactly symmetric (the sums above run in different orders)
        for j in range(i + 1, m):
            x = 0.5 * (out[i, j] + out[j, i])
            out[i, j] = x
            out[j, i] = x


@numba.njit(cache=True)
def _mass_matrix_many(
    Qf: np.ndarray,
    parent: np.ndarray,
    kind: np.ndarray,
    q_start: np.ndarray,
    ndof: np.ndarray,
    axis: np.ndarray,
    r_c: np.ndarray,
    c_c: np.ndarray,
    Theta: np.ndarray,
    g_ptr: np.ndarray,
    g_col: np.ndarray,
    g_val: np.ndarray,
    out: np.ndarray,
) -> None:
    """A for every row of ``Qf`` (full coordinates) into ``out``; one thread, a plain loop.

    Without mimic constraints (``g_ptr`` empty) ``out`` is A_full, (K, n, n); with them
    ``Gᵀ A_full G`` (K, nv, nv), G given in compressed rows ``g_ptr``, ``g_col``, ``g_val``.
    """
    nb, n = parent.shape[0], Qf.shape[1]
    C = np.empty((nb, 3, 3))
    p = np.empty((nb, 3))
    theta_c = np.empty((nb, 6, 6))
    sigma = np.empty((n, 6))
    m6, m3, v3 = np.empty((3, 6, 6)), np.empty((2, 3, 3)), np.empty((6, 3))
    reduce = g_ptr.size > 0
    full = np.empty((n, n)) if reduce else np.empty((0, 0))
    for s in range(Qf.shape[0]):
        if not reduce:
            full = out[s]
        _mass_matrix_one(
            Qf[s], parent, kind, q_start, ndof, axis, r_c, c_c, Theta, C, p, theta_c, sigma,
            m6, m3, v3, full,
        )  # fmt: skip
        if reduce:
            _reduce(full, g_ptr, g_col, g_val, out[s])


@dataclass(frozen=True)
class KernelModel:
    """A :class:`Model`'s constant arrays in the kernel's types (made once per model)."""

    parent: np.ndarray
    kind: np.ndarray
    q_start: np.ndarray
    ndof: np.ndarray
    axis: np.ndarray
    r_c: np.ndarray
    c_c: np.ndarray
    Theta: np.ndarray
    g_ptr: np.ndarray  # G (mimic constraints) in compressed rows; empty without them
    g_col: np.ndarray
    g_val: np.ndarray

    @classmethod
    def of(cls, model: Model) -> KernelModel:
        """The arrays of ``model`` (contiguous, int64 / float64).

        Raises
        ------
        Rt70Error
            For a model with modal bodies (the kernel knows rigid pairs only; the
            structured form, :mod:`rt70.textbook.structured`, adds the bodies' terms).
        """
        if model.modal:
            raise Rt70Error(f"{model.name}: the compiled mass kernel has no modal bodies")
        G = model.G

        def f64(x: np.ndarray) -> np.ndarray:
            return np.ascontiguousarray(x, dtype=np.float64)

        def i64(x: object) -> np.ndarray:
            return np.ascontiguousarray(x, dtype=np.int64)

        return cls(
            parent=i64(model.parent),
            kind=i64([KIND_CODE[k] for k in model.kind]),
            q_start=i64(model.q_start),
            ndof=i64(model.ndof),
            axis=f64(np.reshape(model.axis, (model.nb, 3))),
            r_c=f64(np.reshape(model.r_c, (model.nb, 3))),
            c_c=f64(np.reshape(model.c_c, (model.nb, 3, 3))),
            Theta=f64(np.reshape(model.Theta, (model.nb, 6, 6))),
            g_ptr=i64(
                np.zeros(0) if G is None else np.r_[0, np.cumsum(np.count_nonzero(G, axis=1))]
            ),
            g_col=i64(np.zeros(0) if G is None else np.nonzero(G)[1]),
            g_val=f64(np.zeros(0) if G is None else G[np.nonzero(G)]),
        )


class KernelData:
    """The kernel's model arrays and result buffer for K configurations (reuse it).

    Attributes
    ----------
    A : numpy.ndarray
        The last mass matrices computed, (K, nv, nv); overwritten by the next call.
    """

    def __init__(self, model: Model, K: int = 1) -> None:
        self.arrays = KernelModel.of(model)
        self.K = K
        self.A = np.empty((K, model.nv, model.nv))
        self._model = model


def mass_matrix_batch(model: Model, data: KernelData, Q: np.ndarray) -> np.ndarray:
    """``A = S Θ Sᵀ`` for K configurations ``Q`` (K, nv) by the kernel; returns ``data.A``.

    Equal to :func:`rt70.textbook.structured.mass_matrix_batch` to round-off. The
    returned array is ``data.A``, overwritten by the next call with the same ``data``.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : KernelData
        ``KernelData(model, K)``: the kernel's arrays and ``data.A``.
    Q : numpy.ndarray, shape (K, nv)
        One configuration per row, in the model's coordinates (``Model.coordinate_names``),
        rad or m.
    """
    Q = _check_batch("Q", Q, model.nv)
    data = _data_for(model, Q.shape[0], data, KernelData)
    _compute(model, data, Q)
    return data.A


def _compute(model: Model, data: KernelData, Q: np.ndarray) -> None:
    k = data.arrays
    Qf = Q if model.G is None else Q @ model.G.T + model.q_offset
    _mass_matrix_many(
        np.ascontiguousarray(Qf), k.parent, k.kind, k.q_start, k.ndof, k.axis, k.r_c, k.c_c,
        k.Theta, k.g_ptr, k.g_col, k.g_val, data.A,
    )  # fmt: skip


def mass_matrix(model: Model, data: KernelData, q: np.ndarray) -> np.ndarray:
    """``A = S Θ Sᵀ`` at one configuration by the kernel, a new array (``KernelData(model, 1)``).

    Parameters
    ----------
    model : Model
        The textbook model.
    data : KernelData
        ``KernelData(model, 1)``.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    """
    q = check_vector("q", q, model.nv)
    data = _data_for(model, 1, data, KernelData)
    _compute(model, data, q[None, :])
    return data.A[0].copy()
