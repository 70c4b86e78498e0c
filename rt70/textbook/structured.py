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
the Model is constant, the work buffers (and the tree's index arrays,
:class:`~rt70.textbook.topology.Topology`, built once) live in :class:`BatchData` —
reuse one for repeated calls: fresh multi-megabyte temporaries cost more than the
arithmetic. ``mass_matrix_batch`` returns ``data.A``, overwritten by the next call with
the same data (as ``pin.crba`` fills ``data.M``). The batched spatial helpers are in
:mod:`rt70.textbook.spatial_batch`.
"""

from __future__ import annotations

import numpy as np

from rt70.errors import NonFiniteError, ShapeError
from rt70.guards.arrays import check_vector
from rt70.textbook import modal_bodies
from rt70.textbook.model import Model
from rt70.textbook.spatial_batch import crm_batch, euler123_batch, skew_batch
from rt70.textbook.topology import Topology, topology

_E3 = np.eye(3)


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


def forward_kinematics_batch(model: Model, data: Work, Qf: np.ndarray) -> None:
    """Fill ``data.L0`` (``L_0^j`` of every body) and ``data.sigma`` for K configurations.

    ``L_i^j = T(r_c + c_c r_j)[c_c c_j]`` (4.5)–(4.7); forward pass over the depth of
    the tree with the chain property ``L_0^j = L_0^i L_i^j`` (§4.2), one batched
    product per level; then ``σ = (L_0^j)⁻ᵀ M_j f_j`` per group of equal-width pairs.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Work
        Work buffers for the K configurations (:meth:`BatchData.work`), filled here.
    Qf : numpy.ndarray, shape (K, n_full)
        Pair coordinates of each configuration, ``q_full = G q + q_offset`` (mimic
        joints included), rad or m.
    """
    _pair_motions(model, data, Qf)
    _ground_placements(data)
    _mobility_axes(data)


def _pair_motions(model: Model, data: Work, Qf: np.ndarray) -> None:
    """Each pair's own motion ``T(r_j)[c_j]`` into ``data.M_rel`` and its axes ``M_j f_j``.

    Kind by kind (4.8), (1.23), (1.38): ``c_j``, ``r_j`` into the views ``data.c_rel``,
    ``data.r_rel``, the rows of ``M_j f_j`` of the euler6 and planar pairs into
    ``data.rows`` (those of 1-DOF pairs are constant, ``Topology.rows_1dof``).
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
        c, eps_t = euler123_batch(q6[..., 3:])
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
    M_rel = data.M_rel
    M_rel[..., 3:, 3:] = c_rel
    if topo.translates:
        np.matmul(skew_batch(r_rel), c_rel, out=M_rel[..., 3:, :3])


def _ground_placements(data: Work) -> None:
    """``L_0^j`` of every body into ``data.L0``, from the pairs' motions in ``data.M_rel``.

    ``L_i^j = T(r_c)[c_c] · T(r_j)[c_j]`` (4.5)–(4.7), the constant part times M_rel;
    then ``L_0^j = L_0^i L_i^j`` (chain property) for all bodies at once by pointer
    jumping: after step k, row j holds the transform from the ancestor 2^(k+1) levels
    up to j (row nb is the ground's identity).
    """
    topo = data.topo
    cur, other = data.L0_buffers
    np.matmul(topo.L_construction, data.M_rel, out=cur[:, :-1])
    for jump in topo.jumps:
        np.matmul(cur[:, jump], cur[:, :-1], out=other[:, :-1])
        cur, other = other, cur
    data.L0 = cur[:, :-1]


def _mobility_axes(data: Work) -> None:
    """``σ = (L_0^j)⁻ᵀ M_j f_j`` of every coordinate into ``data.sigma``, group by group."""
    topo, L0 = data.topo, data.L0
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
    """:meth:`Model.expand` of K rows, (K, nv) → (K, n_full)."""
    eta = Q[:, model.n_pairs :]
    if model.modal:
        Q = Q[:, : model.n_pairs]
    if model.G is None:
        return Q
    out = Q @ model.G.T
    if model.node_map is not None:
        out += eta @ model.node_map.T
    return out + model.q_offset if offset else out


def _reduce_batch(model: Model, tau: np.ndarray) -> np.ndarray:
    """:meth:`Model.reduce` of K rows, (K, n_full) → (K, nv)."""
    return model.reduce(tau.T).T


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

    Parameters
    ----------
    model : Model
        The textbook model.
    data : BatchData
        ``BatchData(model, K)``: the work buffers and ``data.A``.
    Q : numpy.ndarray, shape (K, nv)
        One configuration per row, in the model's coordinates
        (``Model.coordinate_names``), rad or m.
    """
    Q = _check_batch("Q", Q, model.nv)
    data = _data_for(model, Q.shape[0], data)
    Qf = _expand_batch(model, Q)
    direct = model.G is None and not model.modal
    n = model.n_pairs
    # q̇_full = [G H] q̇ when interface chains move with η (made once, not per chunk)
    full_map = None if model.node_map is None else model.reduce(np.eye(model.n_full)).T
    for start in range(0, Q.shape[0], data.chunk):
        stop = min(start + data.chunk, Q.shape[0])
        work = data.work(stop - start)
        out = data.A[start:stop] if direct else np.empty_like(work.Gm)
        _mass_matrix_chunk(model, work, Qf[start:stop], out)
        if direct:
            continue
        A = data.A[start:stop]
        if full_map is not None:
            A[:] = full_map.T @ out @ full_map
        else:
            A[:, :n, :n] = out if model.G is None else model.G.T @ out @ model.G
        if model.modal:
            if model.node_map is None:
                A[:, n:, :], A[:, :n, n:] = 0.0, 0.0
            for c in range(stop - start):
                frames = _modal_frames(model, work, c)
                A[c] += modal_bodies.mass_matrix_terms(model, frames, Q[start + c])
    return data.A


def _modal_frames(
    model: Model, work: Work, c: int, a0: np.ndarray | None = None
) -> list[modal_bodies.Frame]:
    """The modal bodies' frames at configuration ``c`` of ``work``'s forward pass.

    Body h's velocity in its own axes is ``(L_0^h)ᵀ V⁰_h``, so its columns of S are
    ``S_b = σ (L_0^h)`` on the coordinates of its ancestors (and zero elsewhere), and
    ``Ṡ_bᵀ q̇ = (L_0^h)ᵀ a⁰_h`` (``L̇_0^h = L_0^h Φ(V_h)`` adds ``Φ(V)ᵀ V = 0``).
    ``a0``: the bias accelerations ``a⁰`` of the state, (nb, 6); None leaves ``bias`` zero.
    """
    topo = work.topo
    frames = []
    for mb in model.modal:
        h = mb.body
        if h < 0:
            frames.append(
                modal_bodies.Frame(_E3, np.zeros(3), np.zeros((6, model.nv)), np.zeros(6))
            )
            continue
        L0 = work.L0[c, h]  # [[c, 0], [<p> c, c]]
        R = L0[:3, :3]
        p_skew = L0[3:, :3] @ R.T
        p = np.array([p_skew[2, 1], p_skew[0, 2], p_skew[1, 0]])
        rows = (work.sigma[c] @ L0) * topo.anc[topo.dof_body, h][:, None]
        bias = np.zeros(6) if a0 is None else L0.T @ a0[h]
        frames.append(modal_bodies.Frame(R, p, model.reduce(rows).T, bias))
    return frames


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

    Parameters
    ----------
    model : Model
        The textbook model.
    data : BatchData
        ``BatchData(model, 1)``.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates in the model's order (``Model.coordinate_names``), rad
        or m.
    """
    q = check_vector("q", q, model.nv)
    return mass_matrix_batch(model, data, q[None, :])[0].copy()


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
        out[:, bodies, :3] = -(skew_batch(omega) @ ct_x[..., None])[..., 0]
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
    """``B(q, q̇) q̇`` (4.80) for K states, shape (K, nv) (composite form, module docstring).

    Parameters
    ----------
    model : Model
        The textbook model.
    data : BatchData
        ``BatchData(model, K)``.
    Q, Qd : numpy.ndarray, shape (K, nv)
        Configurations (rad or m) and velocities (rad/s or m/s), one state per row.
    """
    Q = _check_batch("Q", Q, model.nv)
    Qd = _check_batch("Qd", Qd, model.nv)
    Qf, Vf = _expand_batch(model, Q), _expand_batch(model, Qd, offset=False)
    data = _data_for(model, Q.shape[0], data).work(Q.shape[0])
    topo = data.topo
    forward_kinematics_batch(model, data, Qf)
    u = topo.incidence @ (data.sigma * Vf[..., None])  # Σ_a σ_a q̇_a per pair, (K, nb, 6)
    V = topo.anc.T @ u  # V⁰_j = Σ_{k ⪯ j} u_k
    rate = (data.X @ _mobility_rate(model, topo, Qf, Vf, data)[..., None])[..., 0]
    crm = crm_batch(V)
    a = topo.anc.T @ ((crm @ u[..., None])[..., 0] + rate)  # a⁰ = Ṡᵀ q̇ seen from E0
    theta0 = ground_inertias(model, data)
    h = theta0 @ V[..., None]  # momenta Θ⁰ V⁰
    f = (theta0 @ a[..., None] - np.swapaxes(crm, -1, -2) @ h)[..., 0]  # Θa + Φ(V) Θ V
    f_c = topo.anc @ f  # Σ_{j ⪰ k} f_j
    out = _reduce_batch(model, np.sum(data.sigma * f_c[:, topo.dof_body], axis=-1))
    if not model.modal:
        return out
    for c in range(Q.shape[0]):
        frames = _modal_frames(model, data, c, a[c])
        out[c] += modal_bodies.bias_terms(model, frames, Q[c], Qd[c])
    return out


def bias_force(model: Model, data: BatchData, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """``B(q, q̇) q̇`` at one state (structure-exploiting form), shape (nv,).

    Parameters
    ----------
    model : Model
        The textbook model.
    data : BatchData
        ``BatchData(model, 1)``.
    q, qd : numpy.ndarray, shape (nv,)
        Generalised coordinates (rad or m) and velocities (rad/s or m/s) in the model's
        order.
    """
    q, qd = check_vector("q", q, model.nv), check_vector("qd", qd, model.nv)
    return bias_force_batch(model, data, q[None, :], qd[None, :])[0]


def gravity_force_batch(model: Model, data: BatchData, Q: np.ndarray) -> np.ndarray:
    """``Q_g = S G`` (4.113)–(4.128) for K configurations: ``σ_aᵀ Θᶜ_body(a) [g0; 0]``.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : BatchData
        ``BatchData(model, K)``.
    Q : numpy.ndarray, shape (K, nv)
        One configuration per row, rad or m.

    Returns
    -------
    numpy.ndarray, shape (K, nv)
        The generalised gravity force of each configuration, N or N·m.
    """
    Q = _check_batch("Q", Q, model.nv)
    data = _data_for(model, Q.shape[0], data).work(Q.shape[0])
    topo = data.topo
    forward_kinematics_batch(model, data, _expand_batch(model, Q))
    theta0 = ground_inertias(model, data)
    w = topo.anc @ (theta0[..., :, :3] @ model.gravity)  # Σ_{j ⪰ k} Θ⁰_j [g0; 0]
    out = _reduce_batch(model, np.sum(data.sigma * w[:, topo.dof_body], axis=-1))
    if not model.modal:
        return out
    for c in range(Q.shape[0]):
        out[c] += modal_bodies.gravity_terms(model, _modal_frames(model, data, c), Q[c])
    return out
