"""The tree of a textbook model as index arrays, derived once for the structured algorithms.

:mod:`rt70.textbook.structured` writes the sums over the ancestor relation of the tree
(``Θᶜ_k = Σ_{j ⪰ k} Θ⁰_j``, ``V⁰_j = Σ_{k ⪯ j} σ_k q̇_k``, formalism §4.2–§4.3) as
products with 0/1 matrices, and works on pairs grouped by kind and by their number of
coordinates. Those matrices and groups depend on the model's parent array, pair kinds
and axes only: :func:`topology` builds them once per model (:class:`Topology`, plain
data), and :class:`~rt70.textbook.structured.BatchData` keeps it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rt70.textbook.model import Model
from rt70.textbook.spatial import placement
from rt70.textbook.spatial_batch import skew_batch

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
    rev_k = skew_batch(model.axis[kinds["revolute"]])
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
    """The :class:`Topology` of ``model`` (a BatchData builds it once and keeps it)."""
    return _build_topology(model)
