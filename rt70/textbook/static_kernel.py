"""Compiled static forces of the book's model: gravity ``S G``, springs, and their K.

For models of thousands of coordinates, where the dense textbook form and Pinocchio's
``Data`` (four ``nv³`` tensors) are out of reach, the static force and its derivatives
are needed at every Newton step of an equilibrium and for the stiffness matrix of the
linear model. This kernel computes them on the mass kernel's placements
(:func:`rt70.textbook.mass_kernel.forward_pass`, steps 1–2: the absolute placements
``C_j``, ``p_j`` and the mobility axes ``σ_a = [v_a; w_a]`` seen from E0):

- gravity (4.113)–(4.128): ``Q_g,a = σ_aᵀ [m_k g; h_k × g]`` for coordinate a of pair k,
  with ``m_k`` and ``h_k = Σ m x`` the mass and first moment about E0 of k's subtree —
  ``S G`` summed over the subtree at once (``Θᶜ_k [g; 0]`` needs only these);
- a bushing (the book's elastic pair (4.83) and strut package (4.85)): frame i at
  ``R_i = C_b c_i``, ``p_i = p_b + C_b r_i``; ``δ = [R1ᵀ (p2 − p1); φ(R1ᵀ R2)]`` with φ the
  1–2–3 angles (as :func:`rt70.textbook.forces.bushing_deformation`). A coordinate a on
  the path from the two bodies' lowest common ancestor to body 2 (sign s = +1) or to
  body 1 (s = −1) moves frame 2 relative to frame 1 by the twist ``s σ_a``:
  ``∂δ/∂q_a = s [R1ᵀ (v_a + w_a × p2); ε⁻¹(φ) R2ᵀ w_a]`` (1.38), and the force on it is
  ``Q_a = −(∂δ/∂q_a) · C δ``;
- a joint spring: ``Q_a −= k q_a`` (4.83).

``stiffness_matrices`` gives ``K = −∂(Q_g + Q_c)/∂q`` and its gravity part ``K_g`` in
O(nv · depth) work:

- ``K_g`` exactly: coordinate b moves its pair's subtree S by the twist ``σ_b``, which
  turns the weight's moment by ``D_b = (m_S v_b + w_b × h_S) × g`` (h the first moment
  about E0); for a coordinate a at or above b, ``K_g[a, b] = −w_a · D_b``, and K_g is
  symmetric;
- each bushing's part by central differences over its own path's coordinates, re-placing
  only the path's pairs (its δ depends on nothing else), so the springs' preload terms
  ``(∂Jᵀ/∂q) C δ`` are in K as well as ``Jᵀ C J``;
- the joint springs' k on the diagonal.

``element_gains`` gives the exact ``Σ Jᵀ C J`` and ``Σ Jᵀ D J``. Models with modal bodies
or mimic joints have no kernel (:meth:`StaticData.of` gives None).
"""

from __future__ import annotations

import numba
import numpy as np

from rt70.errors import SingularConfigurationError
from rt70.guards.arrays import check_vector
from rt70.guards.kernel_cache import stamp_kernel_caches
from rt70.textbook.mass_kernel import KernelModel, forward_pass, place_pair
from rt70.textbook.model import Model
from rt70.textbook.spatial import GIMBAL_LOCK_COS

stamp_kernel_caches()  # before the first numba.njit


@numba.njit(cache=True)
def _frame(b: int, r: np.ndarray, c: np.ndarray, C: np.ndarray, p: np.ndarray, R, x) -> None:
    """Frame (``c``, ``r``) of body ``b`` (−1 = ground) in E0: rotation ``R``, origin ``x``."""
    for i in range(3):
        for m in range(3):
            if b < 0:
                R[i, m] = c[i, m]
            else:
                R[i, m] = C[b, i, 0] * c[0, m] + C[b, i, 1] * c[1, m] + C[b, i, 2] * c[2, m]
        x[i] = (
            r[i] if b < 0 else p[b, i] + C[b, i, 0] * r[0] + C[b, i, 1] * r[1] + C[b, i, 2] * r[2]
        )


@numba.njit(cache=True)
def _bushing_rows(k, body1, body2, r1, c1, r2, c2, C, p, W) -> bool:
    """δ and the 6 × 6 map of a twist to ``∂δ`` of bushing ``k``; False at gimbal lock.

    Into ``W``: row 0 δ; rows 1–3 ``R1`` (translation rows: ``∂δ_t = R1ᵀ (v + w × p2)``);
    rows 4–6 ``R2 ε⁻ᵀ`` as its transpose acts (``∂δ_r = ε⁻¹ R2ᵀ w``); row 7 ``p2``.
    """
    R1, R2, x1 = W[1:4, :3], W[4:7, :3], W[8, :3]
    _frame(body1[k], r1[k], c1[k], C, p, R1, x1)
    _frame(body2[k], r2[k], c2[k], C, p, R2, W[7, :3])
    d = W[0]
    for i in range(3):
        d[i] = 0.0
        for m in range(3):
            d[i] += R1[m, i] * (W[7, m] - x1[m])
    c12 = W[9:12, :3]
    for i in range(3):
        for m in range(3):
            c12[i, m] = R1[0, i] * R2[0, m] + R1[1, i] * R2[1, m] + R1[2, i] * R2[2, m]
    ct = np.hypot(c12[0, 0], c12[0, 1])
    if ct < GIMBAL_LOCK_COS:
        return False
    st = min(1.0, max(-1.0, c12[0, 2]))
    d[3] = np.arctan2(-c12[1, 2], c12[2, 2])
    d[4] = np.arctan2(st, ct)
    d[5] = np.arctan2(-c12[0, 1], c12[0, 0])
    ca, sa = np.cos(d[5]), np.sin(d[5])
    ct, st = np.cos(d[4]), np.sin(d[4])
    Einv = W[12:15, :3]  # ε⁻¹ of (1.38)
    Einv[0, 0], Einv[0, 1], Einv[0, 2] = ca / ct, -sa / ct, 0.0
    Einv[1, 0], Einv[1, 1], Einv[1, 2] = sa, ca, 0.0
    Einv[2, 0], Einv[2, 1], Einv[2, 2] = -st * ca / ct, st * sa / ct, 1.0
    G = W[4:7, 3:6]  # R2 ε⁻ᵀ: rotation rows of ∂δ are (G ᵀ w)
    for i in range(3):
        for m in range(3):
            G[i, m] = R2[i, 0] * Einv[m, 0] + R2[i, 1] * Einv[m, 1] + R2[i, 2] * Einv[m, 2]
    return True


@numba.njit(cache=True)
def _twist_rows(W: np.ndarray, sig: np.ndarray, s: float, out: np.ndarray) -> None:
    """``∂δ/∂q_a`` (6) of the bushing in ``W`` for the axis ``sig`` = σ_a with sign s."""
    p2 = W[7, :3]
    t0 = sig[0] + sig[4] * p2[2] - sig[5] * p2[1]
    t1 = sig[1] + sig[5] * p2[0] - sig[3] * p2[2]
    t2 = sig[2] + sig[3] * p2[1] - sig[4] * p2[0]
    for i in range(3):
        out[i] = s * (W[1, i] * t0 + W[2, i] * t1 + W[3, i] * t2)
        out[3 + i] = s * (W[4, 3 + i] * sig[3] + W[5, 3 + i] * sig[4] + W[6, 3 + i] * sig[5])


@numba.njit(cache=True)
def _static_force(qf, gravity, springs, arrays, bushes, paths, scoord, sk, work, fbuf, out) -> int:
    """``Q_g + Q_c`` at ``qf`` into ``out`` (``fbuf``: scratch as long as the widest path).

    Returns −1, or the bushing at gimbal lock.
    """
    parent, q_start, ndof = arrays[0], arrays[2], arrays[3]
    cptr, ccol = paths[2], paths[3]
    C, p, _, sigma, _, _, _, W, rows, weights = work
    _subtree_weights(qf, arrays, work)
    out[:] = 0.0
    for k in range(parent.shape[0]):  # the subtree's weight m g and its moment h × g about E0
        m, h = weights[k, 0], weights[k, 1:]
        f0, f1, f2 = m * gravity[0], m * gravity[1], m * gravity[2]
        n0 = h[1] * gravity[2] - h[2] * gravity[1]
        n1 = h[2] * gravity[0] - h[0] * gravity[2]
        n2 = h[0] * gravity[1] - h[1] * gravity[0]
        for a in range(q_start[k], q_start[k] + ndof[k]):
            s = sigma[a]
            out[a] = s[0] * f0 + s[1] * f1 + s[2] * f2 + s[3] * n0 + s[4] * n1 + s[5] * n2
    if not springs:
        return -1
    for k in range(cptr.shape[0] - 1):
        if not _bushing_force(k, bushes, paths, C, p, sigma, W, rows, fbuf):
            return k
        for u in range(cptr[k], cptr[k + 1]):
            out[ccol[u]] += fbuf[u - cptr[k]]
    for i in range(scoord.shape[0]):
        out[scoord[i]] -= sk[i] * qf[scoord[i]]
    return -1


@numba.njit(cache=True)
def _subtree_weights(qf, arrays, work) -> None:
    """Steps 1–2 of the forward pass, then each subtree's mass and first moment in E0.

    Into ``work``'s ``weights`` (nb, 4): per pair, its subtree's mass m and first moment
    ``h = Σ m x`` about E0.
    """
    parent, kind, q_start, ndof, axis, r_c, c_c, Theta, mass, moment = arrays
    C, p, theta_c, sigma, m6, m3, v3, _, _, weights = work
    forward_pass(qf, parent, kind, q_start, ndof, axis, r_c, c_c, Theta, C, p, theta_c,
                 sigma, m6, m3, v3, False)  # fmt: skip
    nb = parent.shape[0]
    for j in range(nb):  # the body's own: m and m (p + C c)
        weights[j, 0] = mass[j]
        for i in range(3):
            weights[j, 1 + i] = mass[j] * p[j, i]
            for m in range(3):
                weights[j, 1 + i] += C[j, i, m] * moment[j, m]
    for j in range(nb - 1, -1, -1):  # children follow parents
        if parent[j] >= 0:
            for i in range(4):
                weights[parent[j], i] += weights[j, i]


@numba.njit(cache=True)
def _gravity_stiffness(gravity, arrays, work, Dv, K) -> None:
    """``K_g = −∂Q_g/∂q`` exactly, after :func:`_subtree_weights`, into ``K`` (overwritten).

    Coordinate b moves the subtree S of its pair by the twist σ_b, so the first moment
    changes by ``dh = m_S v_b + w_b × h_S`` and the weight's moment by ``D_b = dh × g``;
    a coordinate a at or above b (of an ancestor pair, or before b in b's own pair) has
    ``Q_a = σ_a · [m g; h × g]`` over its subtree, which contains S, and b does not move
    σ_a: ``K_g[a, b] = −w_a · D_b``. K_g is symmetric (gravity is conservative), so this
    gives the other half too.
    """
    parent, q_start, ndof = arrays[0], arrays[2], arrays[3]
    sigma, weights = work[3], work[9]
    g0, g1, g2 = gravity[0], gravity[1], gravity[2]
    for j in range(parent.shape[0]):
        m, h = weights[j, 0], weights[j, 1:]
        for b in range(q_start[j], q_start[j] + ndof[j]):
            s = sigma[b]
            x0 = m * s[0] + s[4] * h[2] - s[5] * h[1]
            x1 = m * s[1] + s[5] * h[0] - s[3] * h[2]
            x2 = m * s[2] + s[3] * h[1] - s[4] * h[0]
            Dv[b, 0], Dv[b, 1], Dv[b, 2] = x1 * g2 - x2 * g1, x2 * g0 - x0 * g2, x0 * g1 - x1 * g0
    K[:] = 0.0
    for j in range(parent.shape[0]):
        k = j
        while k >= 0:  # the pair itself, then its ancestors
            for a in range(q_start[k], q_start[k] + ndof[k]):
                for b in range(max(a, q_start[j]) if k == j else q_start[j], q_start[j] + ndof[j]):
                    x = -(sigma[a, 3] * Dv[b, 0] + sigma[a, 4] * Dv[b, 1] + sigma[a, 5] * Dv[b, 2])
                    K[a, b] = x
                    K[b, a] = x
            k = parent[k]


@numba.njit(cache=True)
def _bushing_force(k, bushes, paths, C, p, sigma, W, rows, out) -> bool:
    """Bushing k's generalised force ``−Jᵀ C δ`` on its path's coordinates, in path order.

    Into ``out`` (as many as the path has coordinates); False at gimbal lock.
    """
    body1, body2, r1, c1, r2, c2, Cb = bushes
    cptr, ccol, csign = paths[2], paths[3], paths[4]
    if not _bushing_rows(k, body1, body2, r1, c1, r2, c2, C, p, W):
        return False
    f = rows[0]
    for i in range(6):
        f[i] = 0.0
        for m in range(6):
            f[i] += Cb[k, i, m] * W[0, m]
    for u in range(cptr[k], cptr[k + 1]):
        _twist_rows(W, sigma[ccol[u]], csign[u], rows[1])
        acc = 0.0
        for i in range(6):
            acc += rows[1, i] * f[i]
        out[u - cptr[k]] = -acc
    return True


@numba.njit(cache=True)
def _spring_stiffness(qf, h, arrays, bushes, paths, work, fp, fm, K) -> int:
    """``−∂Q_c/∂q`` of the bushings added into ``K``, after a forward pass at ``qf``.

    A bushing's force on its path depends on its path's coordinates only (its δ is the
    pose of frame 2 in frame 1), so each is differenced centrally (step h) over those
    alone, re-placing only the path's pairs (parents first: pair indices ascending).
    Returns −1, or a bushing at gimbal lock.
    """
    parent, kind, q_start, ndof, axis, r_c, c_c = arrays[:7]
    ptr, pbody, cptr, ccol = paths[0], paths[1], paths[2], paths[3]
    C, p, _, sigma, m6, m3, v3, W, rows, _ = work
    for k in range(cptr.shape[0] - 1):
        cols = ccol[cptr[k] : cptr[k + 1]]
        for b in cols:
            x = qf[b]
            for side in range(3):
                qf[b] = x + h if side == 0 else x - h if side == 1 else x
                for j in pbody[ptr[k] : ptr[k + 1]]:
                    place_pair(j, qf, parent, kind, q_start, ndof, axis, r_c, c_c, C, p, sigma,
                               m6[0], m3, v3)  # fmt: skip
                if side == 2:
                    continue
                out = fp if side == 0 else fm
                if not _bushing_force(k, bushes, paths, C, p, sigma, W, rows, out):
                    qf[b] = x
                    return k
            for v in range(cols.shape[0]):
                K[cols[v], b] -= (fp[v] - fm[v]) / (2.0 * h)
    return -1


@numba.njit(cache=True)
def _path_gain(k, X, paths, sigma, W, jac, rows, block) -> int:
    """Bushing k's ``Jᵀ X_k J`` over its path's coordinates, after :func:`_bushing_rows`.

    Into ``block[:n, :n]`` in path order (``block[v, u] = J_vᵀ X_k J_u``); returns n.
    """
    cptr, ccol, csign = paths[2], paths[3], paths[4]
    n = cptr[k + 1] - cptr[k]
    for u in range(n):
        _twist_rows(W, sigma[ccol[cptr[k] + u]], csign[cptr[k] + u], jac[u])
    for u in range(n):
        for i in range(6):  # rows[0] = X J_u
            acc = 0.0
            for m in range(6):
                acc += X[k, i, m] * jac[u, m]
            rows[0, i] = acc
        for v in range(n):
            acc = 0.0
            for i in range(6):
                acc += jac[v, i] * rows[0, i]
            block[v, u] = acc
    return n


@numba.njit(cache=True)
def _gains(qf, arrays, bushes, X, paths, scoord, sk, work, jac, block, out) -> int:
    """``Σ Jᵀ X J`` over the bushings (X = C or D per bushing) and ``Σ k`` of the joint springs.

    Into ``out`` (n, n); returns −1, or the bushing at gimbal lock.
    """
    parent, kind, q_start, ndof, axis, r_c, c_c, Theta, _, _ = arrays
    C, p, theta_c, sigma, m6, m3, v3 = work[:7]
    forward_pass(qf, parent, kind, q_start, ndof, axis, r_c, c_c, Theta, C, p, theta_c,
                 sigma, m6, m3, v3, False)  # fmt: skip
    return placed_gains(bushes, X, paths, scoord, sk, work, jac, block, out)


@numba.njit(cache=True)
def placed_gains(bushes, X, paths, scoord, sk, work, jac, block, out) -> int:
    """:func:`_gains` at the placement ``work`` holds (C, p and σ of every pair).

    Into ``out`` (n, n); returns −1, or the bushing at gimbal lock.

    Parameters
    ----------
    bushes, paths, scoord, work : tuple or numpy.ndarray
        The kernel's arrays (:class:`StaticData`), ``work`` placed.
    X : numpy.ndarray, shape (n_bushings, 6, 6)
        Each bushing's gain: its stiffness (N/m, N·m/rad) or its damping.
    sk : numpy.ndarray
        The joint springs' gains of the same kind.
    jac, block : numpy.ndarray
        Scratch as long as the widest bushing path.
    out : numpy.ndarray, shape (n, n)
        ``Σ Jᵀ X J + diag(sk)``.
    """
    C, p, sigma, W, rows = work[0], work[1], work[3], work[7], work[8]
    body1, body2, r1, c1, r2, c2, _ = bushes
    cptr, ccol = paths[2], paths[3]
    out[:] = 0.0
    for k in range(body1.shape[0]):
        if not _bushing_rows(k, body1, body2, r1, c1, r2, c2, C, p, W):
            return k
        cols = ccol[cptr[k] : cptr[k + 1]]
        for u in range(_path_gain(k, X, paths, sigma, W, jac, rows, block)):
            for v in range(cols.shape[0]):
                out[cols[v], cols[u]] += block[v, u]
    for i in range(scoord.shape[0]):
        out[scoord[i], scoord[i]] += sk[i]
    return -1


class StaticData:
    """The kernel's model arrays (bushing paths included) and work buffers for one model.

    Build with :meth:`of`, which gives None for a model the kernel does not cover.
    """

    def __init__(self, model: Model) -> None:
        k = KernelModel.of(model)
        # Θ = [[m 1, −m<c>], [m<c>, J]] (4.77): m and the first moment m c from its block
        moment = np.ascontiguousarray(k.Theta[:, [5, 3, 4], [1, 2, 0]])
        self.arrays = (k.parent, k.kind, k.q_start, k.ndof, k.axis, k.r_c, k.c_c, k.Theta,
                       np.ascontiguousarray(k.Theta[:, 0, 0]), moment)  # fmt: skip
        bs = model.bushings
        stack = [np.ascontiguousarray([getattr(b, a) for b in bs], dtype=float).reshape(shape)
                 for a, shape in (("r1", (-1, 3)), ("c1", (-1, 3, 3)), ("r2", (-1, 3)),
                                  ("c2", (-1, 3, 3)), ("stiffness", (-1, 6, 6)))]  # fmt: skip
        body = [np.array([getattr(b, a) for b in bs], dtype=np.int64) for a in ("body1", "body2")]
        self.bushes = (body[0], body[1], stack[0], stack[1], stack[2], stack[3], stack[4])
        self.damping = np.ascontiguousarray([b.damping for b in bs], dtype=float).reshape(-1, 6, 6)
        self.paths = _paths(model)
        self.scoord = np.ascontiguousarray(model.spring_coords, dtype=np.int64)
        self.sk = np.ascontiguousarray(model.spring_stiffness, dtype=float)
        self.sd = np.ascontiguousarray(model.spring_damping, dtype=float)
        self.gravity = np.ascontiguousarray(model.gravity, dtype=float)
        nb, n = model.nb, model.n_full
        self.work = (
            np.empty((nb, 3, 3)), np.empty((nb, 3)), np.empty((nb, 6, 6)), np.empty((n, 6)),
            np.empty((3, 6, 6)), np.empty((2, 3, 3)), np.empty((6, 3)), np.empty((15, 6)),
            np.empty((2, 6)), np.empty((nb, 4)),
        )  # fmt: skip
        cptr = self.paths[2]
        #: Coordinates on the longest bushing path (the size of the path buffers).
        self.widest = int(np.max(np.diff(cptr), initial=0))
        self.jac = np.empty((self.widest, 6))
        self.block = np.empty((self.widest, self.widest))
        self.names = [b.name for b in bs]

    @classmethod
    def of(cls, model: Model) -> StaticData | None:
        """The kernel's data for ``model``, or None with modal bodies or mimic joints."""
        if model.modal or model.G is not None:
            return None
        return cls(model)


def _paths(model: Model) -> tuple[np.ndarray, ...]:
    """Each bushing's path: its pairs below the lowest common ancestor of its bodies.

    Compressed rows ``(ptr, pbody, cptr, ccol, csign)``: bushing k's pairs are
    ``pbody[ptr[k]:ptr[k + 1]]``, parents first (indices ascending: children follow
    parents); its coordinates are ``ccol[cptr[k]:cptr[k + 1]]``, each with the sign
    ``csign`` of its branch, +1 on body 2's and −1 on body 1's.
    """
    parent = np.asarray(model.parent)

    def up(b: int) -> list[int]:
        chain = []
        while b >= 0:
            chain.append(b)
            b = int(parent[b])
        return chain

    ptr, pbody, cptr, ccol, csign = [0], [], [0], [], []
    for b in model.bushings:
        one, two = up(b.body1), up(b.body2)
        common = set(one) & set(two)
        for chain, sign in ((two, 1.0), (one, -1.0)):
            for j in chain:
                if j not in common:
                    start = int(model.q_start[j])
                    ccol += range(start, start + int(model.ndof[j]))
                    csign += [sign] * int(model.ndof[j])
        pbody += sorted(j for j in {*one, *two} if j not in common)
        ptr.append(len(pbody))
        cptr.append(len(ccol))
    ints = [np.array(x, dtype=np.int64) for x in (ptr, pbody, cptr, ccol)]
    return (*ints, np.array(csign, dtype=float))


def _check(data: StaticData, bad: int) -> None:
    if bad >= 0:
        raise SingularConfigurationError(
            f"bushing '{data.names[bad]}': Euler angles 1-2-3 at gimbal lock "
            f"(|cos θ| < {GIMBAL_LOCK_COS:g})"
        )


def static_force(model: Model, data: StaticData, q: np.ndarray, springs: bool = True) -> np.ndarray:
    """``Q_g + Q_c`` at rest (4.113), (4.83): gravity and the springs' force, a new array.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : StaticData
        ``StaticData.of(model)``.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order.
    springs : bool
        Include the springs (False: gravity alone).
    """
    qf = np.array(check_vector("q", q, model.nv), dtype=float)
    out = np.empty(model.nv)
    bad = _static_force(qf, data.gravity, springs, data.arrays, data.bushes, data.paths,
                        data.scoord, data.sk, data.work, np.empty(data.widest), out)  # fmt: skip
    _check(data, bad)
    return out


def stiffness_matrices(
    model: Model, data: StaticData, q: np.ndarray, h: float = 1e-6
) -> tuple[np.ndarray, np.ndarray]:
    """``K = −∂(Q_g + Q_c)/∂q`` and gravity's ``K_g = −∂Q_g/∂q``, symmetrised.

    ``K_g`` exact (:func:`_gravity_stiffness`); the bushings' part by central differences
    over each one's path (:func:`_spring_stiffness`); the joint springs' k on the diagonal.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : StaticData
        ``StaticData.of(model)``.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order.
    h : float
        The difference step per coordinate, m or rad.
    """
    qf = np.array(check_vector("q", q, model.nv), dtype=float)
    n, widest = model.nv, data.widest
    Kg = np.empty((n, n))
    _subtree_weights(qf, data.arrays, data.work)
    _gravity_stiffness(data.gravity, data.arrays, data.work, np.empty((n, 3)), Kg)
    K = Kg.copy()
    np.add.at(K, (data.scoord, data.scoord), data.sk)
    _check(data, _spring_stiffness(qf, h, data.arrays, data.bushes, data.paths, data.work,
                                   np.empty(widest), np.empty(widest), K))  # fmt: skip
    for X in (K, Kg):
        X += X.T
        X *= 0.5
    return K, Kg


def element_gains(model: Model, data: StaticData, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(Σ Jᵀ C J, Σ Jᵀ D J)`` of the bushings and joint springs at ``q``, exact.

    Both symmetric: each is symmetrised, since its products round unevenly.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : StaticData
        ``StaticData.of(model)``.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order.
    """
    qf = np.array(check_vector("q", q, model.nv), dtype=float)
    out = []
    for X, k in ((data.bushes[6], data.sk), (data.damping, data.sd)):
        G = np.empty((model.nv, model.nv))
        _check(data, _gains(qf, data.arrays, data.bushes, X, data.paths, data.scoord, k,
                            data.work, data.jac, data.block, G))  # fmt: skip
        out.append(0.5 * (G + G.T))
    return out[0], out[1]
