"""Structure-exploiting, batched form of the book's ``A = S Θ Sᵀ`` and ``B q̇`` (§4.3).

The dense form (:mod:`rt70.textbook.dynamics`) assembles the configuration matrix L
block by block. Here the chain property ``L_k^j = (L_0^k)⁻¹ L_0^j`` factorises every
block of L through the ground frame E0, which turns ``S Θ Sᵀ`` into sums over the
ancestor relation of the tree:

- ``σ_k = (L_0^k)⁻ᵀ M_k f_k`` — pair k's mobility axes seen from E0 (6 × k_k);
- ``Θ⁰_j = L_0^j Θ_j (L_0^j)ᵀ`` — body j's inertia about E0;
- ``Θᶜ_k = Σ_{j ⪰ k} Θ⁰_j`` — the composite inertia of the subtree of k;
- ``A_kl = σ_kᵀ Θᶜ_{k} σ_l`` when l ⪯ k (and symmetric), 0 across branches.

Likewise ``V⁰_j = Σ_{k ⪯ j} σ_k q̇_k``, ``Ṡᵀ q̇`` becomes ``a⁰_j = Σ_{k ⪯ j} σ̇_k q̇_k``
with ``σ̇_k = V⁰_k × σ_k + (L_0^k)⁻ᵀ Ṁ_k f_k``, and
``B q̇ = S (Θ Ṡᵀ q̇ + Φ⁰ Θ Sᵀ q̇)`` is ``σ_kᵀ Σ_{j ⪰ k} (Θ⁰_j a⁰_j + Φ(V⁰_j) Θ⁰_j V⁰_j)``.
Sums over the ancestor relation are products with the 0/1 ancestor matrix, so each
algorithm is a short sequence of numpy operations, vectorised over the bodies and over
a batch of K configurations; only the forward pass of the absolute placements loops,
over the depth of the tree. Pairs are grouped by their number of coordinates (1, 3 or
6), so the 6×6 work is done once per pair, not once per coordinate.

Every algorithm is called as ``algorithm(model, data, q, …)``, Pinocchio's convention:
the Model is constant, the work buffers (and the tree's :class:`Topology`, built once)
live in :class:`BatchData` — reuse one for repeated calls: fresh multi-megabyte
temporaries cost more than the arithmetic. ``mass_matrix_batch`` returns ``data.A``,
overwritten by the next call with the same data (as ``pin.crba`` fills ``data.M``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rt70.errors import NonFiniteError, ShapeError
from rt70.guards.arrays import check_vector
from rt70.textbook.model import Model
from rt70.textbook.spatial import placement

_E3 = np.eye(3)


@dataclass(frozen=True)
class Group:
    """Pairs with the same number ``width`` of coordinates (1, 3 or 6)."""

    width: int
    bodies: np.ndarray | slice  # (n_g,) pair indices, a slice when they are contiguous
    dofs: np.ndarray | slice  # (n_g, width) coordinates, a slice when contiguous
    count: int  # n_g

    def rows_of(self, x: np.ndarray) -> np.ndarray:
        """Per-coordinate rows ``x[:, dofs]`` as (K, n_g, width, 6); a view when contiguous."""
        if isinstance(self.dofs, slice):
            return x[:, self.dofs].reshape(x.shape[0], self.count, self.width, x.shape[-1])
        return x[:, self.dofs]


@dataclass(frozen=True)
class Topology:
    """Index arrays derived once from a model's parent array (plain data)."""

    jumps: tuple[np.ndarray, ...]  # ancestor 2^k levels up (nb = the ground), k = 0, 1, ...
    revolute_k: np.ndarray  # <a> of each revolute pair's axis (Rodrigues' formula)
    revolute_basis: np.ndarray  # rows 1, <a>, <a>² flattened, (n_rev, 3, 9)
    revolute_bodies: np.ndarray | slice  # revolute pairs (a slice when contiguous)
    revolute_dofs: np.ndarray | slice  # their coordinates
    L_construction: np.ndarray  # T(r_c)[c_c] of every pair (nb, 6, 6)
    translates: bool  # whether any pair has a variable translation
    anc: np.ndarray  # anc[k, j] = 1.0 if k is j or an ancestor of j
    dof_body: np.ndarray  # body of each full coordinate
    weight: np.ndarray  # 1 where body(l) ⊀ body(a) strictly, ½ on a body's own block
    weight_t: np.ndarray  # its transpose (contiguous)
    incidence: np.ndarray  # incidence[k, a] = 1.0 if coordinate a belongs to pair k
    groups: tuple[Group, ...]
    kinds: dict[str, np.ndarray]  # bodies of each pair kind
    kind_dofs: dict[str, np.ndarray]  # their coordinates, shape (n_kind, ndof)
    rows_1dof: np.ndarray  # body-frame axis [a; 0] or [0; a] of each 1-DOF pair (n1, 1, 6)


def _build_topology(model: Model) -> Topology:
    nb, n = model.nb, model.n_full
    depth = np.zeros(nb, dtype=int)
    for j in range(nb):
        depth[j] = 0 if model.parent[j] < 0 else depth[model.parent[j]] + 1
    # pointer jumping: jumps[k][j] is the ancestor 2^k levels above j, or nb (the ground)
    jump = np.where(model.parent < 0, nb, model.parent).astype(int)
    jump = np.append(jump, nb)
    jumps = []
    for _ in range(int(np.ceil(np.log2(depth.max() + 1))) if nb else 0):
        jumps.append(jump[:nb].copy())
        jump = jump[jump]
    anc = np.zeros((nb, nb))
    for j in range(nb):
        anc[model.ancestors(j), j] = 1.0
    dof_body = np.repeat(np.arange(nb), model.ndof)
    same = (dof_body[:, None] == dof_body[None, :]).astype(float)
    weight = anc[np.ix_(dof_body, dof_body)] - 0.5 * same
    incidence = np.zeros((nb, n))
    incidence[dof_body, np.arange(n)] = 1.0
    groups = []
    for width in (1, 3, 6):
        bodies = np.flatnonzero(model.ndof == width)
        if bodies.size:
            dofs = (model.q_start[bodies][:, None] + np.arange(width)).astype(int)
            groups.append(Group(width, _as_slice(bodies), _as_slice(dofs), bodies.size))
    kinds, kind_dofs = {}, {}
    for kind, width in (("euler6", 6), ("revolute", 1), ("prismatic", 1), ("planar", 3)):
        bodies = np.array([j for j in range(nb) if model.kind[j] == kind], dtype=int)
        kinds[kind] = bodies
        kind_dofs[kind] = (model.q_start[bodies][:, None] + np.arange(width)).astype(int)
    one = np.flatnonzero(model.ndof == 1)
    rows_1dof = np.zeros((one.size, 1, 6))
    for i, j in enumerate(one):
        rows_1dof[i, 0, 3:] = model.axis[j] if model.kind[j] == "revolute" else 0.0
        rows_1dof[i, 0, :3] = model.axis[j] if model.kind[j] == "prismatic" else 0.0
    rev_k = _skew_batch(model.axis[kinds["revolute"]])
    return Topology(
        jumps=tuple(jumps),
        L_construction=np.array(
            [placement(r, c) for r, c in zip(model.r_c, model.c_c, strict=True)]
        ).reshape(-1, 6, 6),
        translates=any(k in ("prismatic", "euler6", "planar") for k in model.kind),
        revolute_k=rev_k,
        revolute_basis=np.stack(
            [np.broadcast_to(_E3, rev_k.shape), rev_k, rev_k @ rev_k], axis=-3
        ).reshape(-1, 3, 9),
        revolute_bodies=_as_slice(kinds["revolute"])
        if kinds["revolute"].size
        else kinds["revolute"],
        revolute_dofs=_as_slice(kind_dofs["revolute"][:, 0])
        if kinds["revolute"].size
        else kind_dofs["revolute"][:, 0],
        anc=anc,
        dof_body=dof_body,
        weight=weight,
        weight_t=np.ascontiguousarray(weight.T),
        incidence=incidence,
        groups=tuple(groups),
        kinds=kinds,
        kind_dofs=kind_dofs,
        rows_1dof=rows_1dof,
    )


def _as_slice(index: np.ndarray) -> np.ndarray | slice:
    """A slice equal to ``index`` (flattened) if it is a contiguous range, else ``index``."""
    flat = index.ravel()
    if np.array_equal(flat, np.arange(flat[0], flat[0] + flat.size)):
        return slice(int(flat[0]), int(flat[0] + flat.size))
    return index


def topology(model: Model) -> Topology:
    """The :class:`Topology` of ``model`` (kept by :class:`BatchData`, built once there)."""
    return _build_topology(model)


#: Work arrays of one chunk of the batched mass matrix stay below this many bytes, so
#: that the nv × nv passes run in cache and only the result goes to memory.
CHUNK_BYTES = 8 << 20

#: Up to this many entries the nv × nv work is cache-resident (transposed reads are cheap).
_SMALL = 1 << 16


class Work:
    """Work buffers of the structured algorithms for ``size`` configurations."""

    def __init__(self, model: Model, size: int, topo: Topology | None = None) -> None:
        nb, n = model.nb, model.n_full
        topo = topology(model) if topo is None else topo
        self.topo = topo
        self.size = size
        self.M_rel = np.zeros((size, nb, 6, 6))  # T(r_j)[c_j]: the pairs' own motion
        self.M_rel[..., :3, :3] = _E3
        self.c_rel = self.M_rel[..., :3, :3]
        self.r_rel = np.zeros((size, nb, 3))
        self.L0_buffers = (np.empty((size, nb + 1, 6, 6)), np.empty((size, nb + 1, 6, 6)))
        for buf in self.L0_buffers:
            buf[:, nb] = np.eye(6)  # the ground
        self.L0 = self.L0_buffers[0][:, :nb]  # L_0^j of every body (a view, set per call)
        self.X = np.zeros((size, nb, 6, 6))  # (L_0^j)⁻ᵀ
        self.rows = {g.width: np.zeros((size, g.count, g.width, 6)) for g in topo.groups}
        self.sigma = np.empty((size, n, 6))  # σ, one row per full coordinate
        self.F = np.empty((size, n, 6))
        self.theta0 = np.empty((size, nb, 6, 6))
        self.theta_c = np.empty((size, nb, 6, 6))
        self.Gm = np.empty((size, n, n))
        self.GmT = np.empty((size, n, n))


class BatchData:
    """Work buffers and results of the structured algorithms for K configurations.

    The mass matrix is computed in chunks of ``chunk`` configurations (sized by
    :data:`CHUNK_BYTES`); each chunk size has its own :class:`Work`.

    Attributes
    ----------
    A : numpy.ndarray
        The last mass matrices computed, (K, nv, nv).
    """

    def __init__(self, model: Model, K: int = 1, chunk: int | None = None) -> None:
        n = max(model.n_full, 1)
        self.topology = topology(model)
        self.K = K
        self.chunk = chunk or max(1, min(K, CHUNK_BYTES // (24 * n * n)))
        self.A = np.empty((K, model.nv, model.nv))
        self._model = model
        self._works: dict[int, Work] = {}

    def work(self, size: int) -> Work:
        """The work buffers for ``size`` configurations (made once, then reused)."""
        if size not in self._works:
            self._works[size] = Work(self._model, size, self.topology)
        return self._works[size]


def _data_for(model: Model, K: int, data, kind: type | None = None):
    """``data`` if it is a ``kind`` made for ``model`` and K configurations (else ShapeError).

    ``kind`` is :class:`BatchData` by default; the compiled form passes its own.
    """
    kind = BatchData if kind is None else kind
    name = kind.__name__
    if not isinstance(data, kind) or data._model is not model:
        raise ShapeError(f"data: expected the {name} of this model ({name}(model, K))")
    if data.K != K:
        raise ShapeError(f"data: made for K = {data.K} configurations, got {K}")
    return data


_SKEW_SRC = np.array([0, 2, 1, 2, 0, 0, 1, 0, 0])
_SKEW_SIGN = np.array([0.0, -1.0, 1.0, 1.0, 0.0, -1.0, -1.0, 1.0, 0.0])


def _skew_batch(x: np.ndarray) -> np.ndarray:
    """``<x>`` for an array of 3-vectors, shape (..., 3) → (..., 3, 3)."""
    return (x[..., _SKEW_SRC] * _SKEW_SIGN).reshape(x.shape + (3,))


_E123 = np.eye(3)


def _euler123_batch(phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``c = c1(β) c2(θ) c3(α)`` (1.23) and the transposed Euler matrix εᵀ (1.38), batched.

    The rows of ``εᵀ`` are ``(c2 c3)ᵀ e_x``, ``c3ᵀ e_y`` and ``e_z`` read as rows of
    ``c2 c3`` and ``c3``.
    """
    elementary = _rotations_about_axes(_E123, phi)  # c1(β), c2(θ), c3(α)
    c23 = elementary[..., 1, :, :] @ elementary[..., 2, :, :]
    c = elementary[..., 0, :, :] @ c23
    eps_t = np.empty_like(c)
    eps_t[..., 0, :] = c23[..., 0, :]
    eps_t[..., 1, :] = elementary[..., 2, 1, :]
    eps_t[..., 2, :] = _E123[2]
    return c, eps_t


def _rotations_about_axes(axes: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Rodrigues' formula for rotations about unit ``axes`` (n, 3) by ``angles`` (K, n)."""
    k = _skew_batch(axes)
    k2 = k @ k
    s, c = np.sin(angles)[..., None, None], np.cos(angles)[..., None, None]
    return _E3 + s * k + (1.0 - c) * k2


def forward_kinematics_batch(model: Model, data: Work, Qf: np.ndarray) -> None:
    """Fill ``data.L0`` (``L_0^j`` of every body) and ``data.sigma`` for K configurations.

    ``L_i^j = T(r_c + c_c r_j)[c_c c_j]`` (4.5)–(4.7); forward pass over the depth of
    the tree with the chain property ``L_0^j = L_0^i L_i^j`` (§4.2), one batched
    product per level; then ``σ = (L_0^j)⁻ᵀ M_j f_j`` per group of equal-width pairs.
    """
    topo = data.topo
    c_rel, r_rel = data.c_rel, data.r_rel  # views into data.M_rel
    bodies, dofs = topo.revolute_bodies, topo.revolute_dofs
    if topo.revolute_k.size:
        # Rodrigues: c = 1 + sin q <a> + (1 − cos q) <a>², as one product with the basis
        angles = Qf[:, dofs]
        coef = np.stack([np.ones_like(angles), np.sin(angles), 1.0 - np.cos(angles)], axis=-1)
        c_rel[:, bodies] = (coef[..., None, :] @ topo.revolute_basis).reshape(angles.shape + (3, 3))
    bodies, dofs = topo.kinds["prismatic"], topo.kind_dofs["prismatic"]
    if bodies.size:
        r_rel[:, bodies] = Qf[:, dofs[:, 0], None] * model.axis[bodies]
    bodies, dofs = topo.kinds["euler6"], topo.kind_dofs["euler6"]
    if bodies.size:
        q6 = Qf[:, dofs]  # (K, n6, 6)
        c, eps_t = _euler123_batch(q6[..., 3:])
        c_rel[:, bodies] = c
        r_rel[:, bodies] = q6[..., :3]
        rows = data.rows[6]  # row a = column a of M_j = diag(cᵀ, ε)
        rows[..., :3, :3] = c
        rows[..., 3:, 3:] = eps_t
    bodies, dofs = topo.kinds["planar"], topo.kind_dofs["planar"]
    if bodies.size:
        q3 = Qf[:, dofs]
        ca, sa = np.cos(q3[..., 2]), np.sin(q3[..., 2])
        c_rel[:, bodies, 0, 0], c_rel[:, bodies, 0, 1] = ca, -sa
        c_rel[:, bodies, 1, 0], c_rel[:, bodies, 1, 1] = sa, ca
        r_rel[:, bodies, :2] = q3[..., :2]
        rows = data.rows[3]
        rows[..., 0, 0], rows[..., 0, 1] = ca, -sa  # cᵀ e_x
        rows[..., 1, 0], rows[..., 1, 1] = sa, ca  # cᵀ e_y
        rows[..., 2, 5] = 1.0
    # L_i^j = T(r_c)[c_c] · T(r_j)[c_j] (4.5)–(4.7): the constant part times M_rel
    M_rel = data.M_rel
    M_rel[..., 3:, 3:] = c_rel
    if topo.translates:
        np.matmul(_skew_batch(r_rel), c_rel, out=M_rel[..., 3:, :3])
    # L_0^j = L_0^i L_i^j (chain property) for all bodies at once by pointer jumping:
    # after step k, row j holds the transform from the ancestor 2^(k+1) levels up to j
    # (row nb is the ground's identity).
    cur, other = data.L0_buffers
    np.matmul(topo.L_construction, M_rel, out=cur[:, :-1])
    for jump in topo.jumps:
        np.matmul(cur[:, jump], cur[:, :-1], out=other[:, :-1])
        cur, other = other, cur
    data.L0 = L0 = cur[:, :-1]
    K, nb = L0.shape[:2]
    # (L_0^j)⁻ᵀ = [[c, <p>c], [0, c]]: L_0^j = [[c, 0], [<p>c, c]] with its blocks permuted
    np.take(L0.reshape(K, nb, 36), _INV_T, axis=-1, out=data.X.reshape(K, nb, 36))
    Xt = np.swapaxes(data.X, -1, -2)
    for g in topo.groups:
        rows = topo.rows_1dof if g.width == 1 else data.rows[g.width]
        if isinstance(g.dofs, slice):
            np.matmul(rows, Xt[:, g.bodies], out=g.rows_of(data.sigma))
        else:
            data.sigma[:, g.dofs] = rows @ Xt[:, g.bodies]


#: Flat indices taking [[c, 0], [<p>c, c]] to [[c, <p>c], [0, c]] (36 = the zero entry 3).
_INV_T = np.array(
    [
        [0, 1, 2, 18, 19, 20],
        [6, 7, 8, 24, 25, 26],
        [12, 13, 14, 30, 31, 32],
        [3, 3, 3, 21, 22, 23],
        [3, 3, 3, 27, 28, 29],
        [3, 3, 3, 33, 34, 35],
    ]
).ravel()


def ground_inertias(model: Model, data: Work) -> np.ndarray:
    """``Θ⁰_j = L_0^j Θ_j (L_0^j)ᵀ`` for every body, into ``data.theta0`` (4.77)."""
    L0 = data.L0
    np.matmul(L0 @ model.Theta, np.swapaxes(L0, -1, -2), out=data.theta0)
    return data.theta0


def _expand_batch(model: Model, Q: np.ndarray, offset: bool = True) -> np.ndarray:
    if model.G is None:
        return Q
    out = Q @ model.G.T
    return out + model.q_offset if offset else out


def _check_batch(name: str, Q: np.ndarray, nv: int) -> np.ndarray:
    try:
        Q = np.asarray(Q, dtype=float)
    except (TypeError, ValueError):
        raise ShapeError(f"{name}: expected a (K, {nv}) array of numbers") from None
    if Q.ndim != 2 or Q.shape[1] != nv:
        raise ShapeError(f"{name}: expected shape (K, {nv}), got shape {Q.shape}")
    if np.isnan(Q.ravel() @ np.zeros(Q.size)):  # 0·x is NaN exactly for x = ±inf or NaN
        raise NonFiniteError(f"{name} contains NaN or infinite values")
    return Q


def mass_matrix_batch(model: Model, data: BatchData, Q: np.ndarray) -> np.ndarray:
    """``A = S Θ Sᵀ`` for K configurations ``Q`` (K, nv) at once; returns ``data.A``.

    ``A_la = σ_lᵀ Θᶜ_{body(a)} σ_a`` for ``body(l) ⪯ body(a)`` and its transpose (the
    composite form of (4.79), module docstring). The returned array is ``data.A`` and is
    overwritten by the next call with the same ``data``.
    """
    Q = _check_batch("Q", Q, model.nv)
    data = _data_for(model, Q.shape[0], data)
    Qf = _expand_batch(model, Q)
    for start in range(0, Q.shape[0], data.chunk):
        stop = min(start + data.chunk, Q.shape[0])
        work = data.work(stop - start)
        out = data.A[start:stop] if model.G is None else np.empty_like(work.Gm)
        _mass_matrix_chunk(model, work, Qf[start:stop], out)
        if model.G is not None:
            np.matmul(model.G.T @ out, model.G, out=data.A[start:stop])
    return data.A


def _mass_matrix_chunk(model: Model, work: Work, Qf: np.ndarray, out: np.ndarray) -> None:
    topo = work.topo
    forward_kinematics_batch(model, work, Qf)
    theta0 = ground_inertias(model, work)
    K, nb = theta0.shape[:2]
    np.matmul(topo.anc, theta0.reshape(K, nb, 36), out=work.theta_c.reshape(K, nb, 36))
    for g in topo.groups:  # F_a = Θᶜ_body(a) σ_a (Θᶜ symmetric)
        if isinstance(g.dofs, slice):
            np.matmul(g.rows_of(work.sigma), work.theta_c[:, g.bodies], out=g.rows_of(work.F))
        else:
            work.F[:, g.dofs] = work.sigma[:, g.dofs] @ work.theta_c[:, g.bodies]
    np.matmul(work.sigma, np.swapaxes(work.F, -1, -2), out=work.Gm)  # σ_lᵀ Θᶜ_body(a) σ_a
    if work.Gm.size <= _SMALL:  # in cache: add the transpose directly
        work.Gm *= topo.weight
        np.add(work.Gm, np.swapaxes(work.Gm, -1, -2), out=out)
        return
    np.matmul(work.F, np.swapaxes(work.sigma, -1, -2), out=work.GmT)  # its transpose
    np.multiply(work.Gm, topo.weight, out=out)
    work.GmT *= topo.weight_t
    out += work.GmT


def mass_matrix(model: Model, data: BatchData, q: np.ndarray) -> np.ndarray:
    """``A = S Θ Sᵀ`` at one configuration (structure-exploiting form), a new array.

    ``data`` is a ``BatchData(model, 1)``.
    """
    q = check_vector("q", q, model.nv)
    return mass_matrix_batch(model, data, q[None, :])[0].copy()


def _crm_batch(v: np.ndarray) -> np.ndarray:
    """Motion cross product matrices ``V×`` (linear-first), ``−Φ(V)ᵀ`` of (1.55); batched."""
    out = np.zeros(v.shape[:-1] + (6, 6))
    w = _skew_batch(v[..., 3:])
    out[..., :3, :3] = w
    out[..., 3:, 3:] = w
    out[..., :3, 3:] = _skew_batch(v[..., :3])
    return out


def _mobility_rate(model: Model, topo: Topology, Qf: np.ndarray, Vf: np.ndarray, data: Work):
    """``Ṁ_j f_j q̇_j`` in body frames, shape (K, nb, 6) (4.82).

    euler6: ``[ċᵀ ẋ; ε̇ φ̇]`` with ``ċᵀ = −<ω> cᵀ``, ``ω = ε φ̇``; planar likewise with
    ``ω = α̇ e_z``; zero for 1-DOF pairs (their axes are constant in the body frame).
    """
    K = Qf.shape[0]
    out = np.zeros((K, model.nb, 6))
    bodies, dofs = topo.kinds["euler6"], topo.kind_dofs["euler6"]
    if bodies.size:
        q6, v6 = Qf[:, dofs], Vf[:, dofs]
        rows = data.rows[6]  # row a = column a of M_j (from forward_kinematics_batch)
        omega = (v6[..., None, 3:] @ rows[..., 3:, 3:])[..., 0, :]  # ε φ̇
        ct_x = (v6[..., None, :3] @ rows[..., :3, :3])[..., 0, :]  # cᵀ ẋ
        out[:, bodies, :3] = -(_skew_batch(omega) @ ct_x[..., None])[..., 0]
        st, ct = np.sin(q6[..., 4]), np.cos(q6[..., 4])
        sa, ca = np.sin(q6[..., 5]), np.cos(q6[..., 5])
        db, dt, da = v6[..., 3], v6[..., 4], v6[..., 5]
        # ε̇ φ̇ with ε̇ = θ̇ ∂ε/∂θ + α̇ ∂ε/∂α
        out[:, bodies, 3] = db * (-st * ca * dt - ct * sa * da) + da * ca * dt
        out[:, bodies, 4] = db * (st * sa * dt - ct * ca * da) - da * sa * dt
        out[:, bodies, 5] = db * ct * dt
    bodies, dofs = topo.kinds["planar"], topo.kind_dofs["planar"]
    if bodies.size:
        v3 = Vf[:, dofs]
        ct_x = (v3[..., None, :2] @ data.rows[3][..., :2, :3])[..., 0, :]
        out[:, bodies, 0] = v3[..., 2] * ct_x[..., 1]  # −<α̇ e_z> cᵀ ẋ
        out[:, bodies, 1] = -v3[..., 2] * ct_x[..., 0]
    return out


def bias_force_batch(model: Model, data: BatchData, Q: np.ndarray, Qd: np.ndarray) -> np.ndarray:
    """``B(q, q̇) q̇`` (4.80) for K states, shape (K, nv) (composite form, module docstring)."""
    Q = _check_batch("Q", Q, model.nv)
    Qd = _check_batch("Qd", Qd, model.nv)
    Qf, Vf = _expand_batch(model, Q), _expand_batch(model, Qd, offset=False)
    data = _data_for(model, Q.shape[0], data).work(Q.shape[0])
    topo = data.topo
    forward_kinematics_batch(model, data, Qf)
    u = topo.incidence @ (data.sigma * Vf[..., None])  # Σ_a σ_a q̇_a per pair, (K, nb, 6)
    V = topo.anc.T @ u  # V⁰_j = Σ_{k ⪯ j} u_k
    rate = (data.X @ _mobility_rate(model, topo, Qf, Vf, data)[..., None])[..., 0]
    crm = _crm_batch(V)
    a = topo.anc.T @ ((crm @ u[..., None])[..., 0] + rate)  # a⁰ = Ṡᵀ q̇ seen from E0
    theta0 = ground_inertias(model, data)
    h = theta0 @ V[..., None]  # momenta Θ⁰ V⁰
    f = (theta0 @ a[..., None] - np.swapaxes(crm, -1, -2) @ h)[..., 0]  # Θa + Φ(V) Θ V
    f_c = topo.anc @ f  # Σ_{j ⪰ k} f_j
    tau = np.sum(data.sigma * f_c[:, topo.dof_body], axis=-1)
    return tau if model.G is None else tau @ model.G


def bias_force(model: Model, data: BatchData, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """``B(q, q̇) q̇`` at one state (structure-exploiting form); ``data = BatchData(model, 1)``."""
    q, qd = check_vector("q", q, model.nv), check_vector("qd", qd, model.nv)
    return bias_force_batch(model, data, q[None, :], qd[None, :])[0]


def gravity_force_batch(model: Model, data: BatchData, Q: np.ndarray) -> np.ndarray:
    """``Q_g = S G`` (4.113)–(4.128) for K configurations: ``σ_aᵀ Θᶜ_body(a) [g0; 0]``."""
    Q = _check_batch("Q", Q, model.nv)
    data = _data_for(model, Q.shape[0], data).work(Q.shape[0])
    topo = data.topo
    forward_kinematics_batch(model, data, _expand_batch(model, Q))
    theta0 = ground_inertias(model, data)
    w = topo.anc @ (theta0[..., :, :3] @ model.gravity)  # Σ_{j ⪰ k} Θ⁰_j [g0; 0]
    tau = np.sum(data.sigma * w[:, topo.dof_body], axis=-1)
    return tau if model.G is None else tau @ model.G
