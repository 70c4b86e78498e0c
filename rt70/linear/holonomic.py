"""Holonomic (rigid) links in linear models: elimination through a spanning tree (chapter 3).

The book's algorithm (§3.1, formalism §3), for a graph of bodies (vertex 0 = the ground)
with elastic links and some rigid links:

1. the equations of the elastic graph, ``I α̈ + Γᵀ D Γ α̇ + Γᵀ C Γ α = Q`` (3.6);
2. a spanning tree PD of the whole graph that contains the rigid subgraph PG, with its
   topology matrix Γ* (3.7): one row per body, the row of the tree's central vertex (the
   root) holding a single +1 — it moves relative to the ground;
3. relative coordinates ``α* = Γ* α`` (3.8) and the configuration matrix ``L = Γ*⁻ᵀ``
   (3.9);
4. the mobility matrix f (3.10): ``f_ii = 1`` when the relative motion ``α*_i`` is allowed,
   0 when a rigid link locks it;
5. the structure matrix ``S = fᵀ L`` (3.11) and ``S I Sᵀ α̈* + S Γᵀ D Γ Sᵀ α̇* +
   S Γᵀ C Γ Sᵀ α* = S Q`` (3.13);
6. without the zero rows and columns: ``A* α̈** + D* α̇** + C* α** = Q*`` (3.14)–(3.16)
   with ``S* = f*ᵀ L``, f* = f without its zero columns;
7. back to the bodies: ``α = S*ᵀ α**`` (3.17).

Decisions where the book is silent:

* The tree is built Kruskal-fashion and deterministically: rigid links first (in the given
  order), then the root's row, then the elastic links (in the model's order). A rigid link
  that closes a loop of rigid links is redundant — all relative motions in the loop are
  already zero — and is left out of the tree (:attr:`SpanningTree.dropped_rigid_edges`);
  this is how the conclusion's "a rigid loop does not prevent the method" is honoured.
* The ground is vertex 0 of the tree and the root's row is a free link ``(0, root)``:
  rigid and elastic links to the ground are handled like any other link (a rigid link to
  the ground clamps its body; then the root row is dropped if the root is clamped).
  Components of the graph that reach neither the root nor the ground get their own
  central vertex (their smallest body): PD is then a forest, as the book allows.
* A link that is both elastic and rigid: the rigid constraint wins. Its spring stays in C
  but its deformation is identically zero in the reduced coordinates, so it drops out of
  C* and D* — exactly as the internal link 2–4 drops out in the book's example.
* For 3-D point masses (``dim=3``) every entry of Γ*, L and f is a 3 × 3 block; a rigid
  link locks the whole relative displacement (f acts per coordinate).
"""

from __future__ import annotations

import operator
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from rt70.errors import TopologyError
from rt70.linear.topology import (
    Edge,
    LinearModel,
    LinearModelError,
    _positive_int,
    check_edges,
    edges_from_topology,
)
from rt70.physics.constraints import HolonomicMap, rigid_link_map

#: Kinds of tree rows: the book's central vertex (free relative to the ground), a tree
#: link that is elastic (free relative motion) or rigid (locked).
ROOT, ELASTIC, RIGID = "root", "elastic", "rigid"


def _node(value: object, n_nodes: int, what: str) -> int:
    try:
        k = operator.index(value)
    except TypeError:
        raise TopologyError(f"{what} must be a node number, got {value!r}") from None
    if not 1 <= k <= n_nodes:
        raise TopologyError(f"{what} {k} out of range 1..{n_nodes}")
    return k


def _n_nodes(value: object) -> int:
    return _positive_int(value, "n_nodes")


def _roots(root: int | Sequence[int] | None, n_nodes: int) -> list[int]:
    if root is None:
        return []
    if isinstance(root, Sequence):
        return [_node(r, n_nodes, "root") for r in root]
    return [_node(root, n_nodes, "root")]


class _UnionFind:
    """Disjoint sets of the vertices 0..n (0 = the ground)."""

    def __init__(self, n: int) -> None:
        self.up = list(range(n + 1))

    def find(self, v: int) -> int:
        while self.up[v] != v:
            self.up[v] = self.up[self.up[v]]
            v = self.up[v]
        return v

    def union(self, a: int, b: int) -> bool:
        ra, rb = self.find(a), self.find(b)
        if ra == rb:
            return False
        self.up[max(ra, rb)] = min(ra, rb)
        return True


def _orient(n_nodes: int, edges: Sequence[Edge]) -> list[int]:
    """Parent of each body in the tree of ``edges`` hung from the ground (0 = ground).

    Raises TopologyError unless ``edges`` is a spanning tree of the vertices 0..n_nodes.
    """
    if len(edges) != n_nodes:
        raise TopologyError(
            f"a spanning tree of {n_nodes} bodies and the ground has {n_nodes} links "
            f"(root rows included), got {len(edges)}"
        )
    adjacent: list[list[int]] = [[] for _ in range(n_nodes + 1)]
    for i, j in edges:
        adjacent[i].append(j)
        adjacent[j].append(i)
    parent = [-1] * (n_nodes + 1)
    parent[0] = 0
    stack = [0]
    while stack:
        v = stack.pop()
        for w in adjacent[v]:
            if parent[w] < 0:
                parent[w] = v
                stack.append(w)
    missing = [k for k in range(1, n_nodes + 1) if parent[k] < 0]
    if missing:
        raise TopologyError(
            f"the tree does not reach node(s) {missing} from the ground/root (it has a loop)"
        )
    return parent[1:]


@dataclass(frozen=True)
class SpanningTree:
    """A spanning tree PD of the graph, hung from the ground (vertex 0).

    Attributes
    ----------
    n_nodes : int
        Number of bodies.
    parent : tuple of int
        ``parent[k-1]`` is the parent of body k (0 = the ground).
    kind : tuple of str
        ``kind[k-1]`` is the kind of body k's row of Γ*: ``"root"`` (a central vertex,
        free relative to the ground), ``"elastic"`` (an elastic tree link, free relative
        motion) or ``"rigid"`` (a rigid tree link, locked).
    dropped_rigid_edges : tuple of (int, int)
        Rigid links left out of the tree because they close a loop of rigid links.
    """

    n_nodes: int
    parent: tuple[int, ...]
    kind: tuple[str, ...]
    dropped_rigid_edges: tuple[Edge, ...] = ()

    @property
    def roots(self) -> tuple[int, ...]:
        """The central vertices (one per tree of the forest not clamped to the ground)."""
        return tuple(k for k, kind in enumerate(self.kind, start=1) if kind == ROOT)

    @property
    def edges(self) -> tuple[Edge, ...]:
        """Tree links oriented away from the ground, ``(parent, child)``, in body order.

        The root rows are not links and are not listed (see :attr:`roots`).
        """
        return tuple(
            (p, k)
            for k, (p, kind) in enumerate(zip(self.parent, self.kind, strict=True), start=1)
            if kind != ROOT
        )

    @property
    def rigid_edges(self) -> tuple[Edge, ...]:
        """Rigid tree links ``(parent, child)`` (the rigid forest PG without its loops)."""
        return tuple(
            (p, k)
            for k, (p, kind) in enumerate(zip(self.parent, self.kind, strict=True), start=1)
            if kind == RIGID
        )

    @property
    def mobility(self) -> np.ndarray:
        """The diagonal of f (3.10): 1 for root rows and elastic tree links, 0 for rigid."""
        return np.array([0.0 if kind == RIGID else 1.0 for kind in self.kind])


def spanning_tree(
    n_nodes: int,
    elastic_edges: Sequence[Sequence[int]],
    rigid_edges: Sequence[Sequence[int]],
    root: int = 1,
) -> SpanningTree:
    """Choose the spanning tree PD of §3.1: it contains every rigid link and reaches every body.

    Kruskal's rule, deterministic: the rigid links in the given order (one that closes a
    loop of rigid links is redundant and dropped), then the root's row ``(0, root)``
    unless rigid links already clamp the root to the ground, then the elastic links in
    the given order, then a root row for the smallest body of every component still not
    connected (PD is then a forest).

    Parameters
    ----------
    n_nodes : int
        Number of bodies.
    elastic_edges, rigid_edges : sequence of pairs of int
        Links ``(i, j)``, 1-based, 0 = the ground.
    root : int
        The central vertex of the tree (the book's choice for Fig. 3.1 is body 1).

    Returns
    -------
    SpanningTree
        For Fig. 3.1 (elastic 1–2, 1–3, 1–4, 2–4; rigid 2–3, 3–4; root 1): the tree
        1–2, 2–3, 3–4 with kinds root, elastic, rigid, rigid.

    Raises
    ------
    TopologyError
        On a link out of range, a self-loop or a root out of range.
    """
    n_nodes = _n_nodes(n_nodes)
    rigid = check_edges(rigid_edges, n_nodes, "rigid link")
    elastic = check_edges(elastic_edges, n_nodes, "elastic link")
    roots = _roots(root, n_nodes)
    sets = _UnionFind(n_nodes)
    chosen: list[Edge] = []
    kind_of: dict[frozenset[int], str] = {}
    dropped: list[Edge] = []

    def take(edge: Edge, kind: str) -> bool:
        if sets.union(*edge):
            chosen.append(edge)
            kind_of[frozenset(edge)] = kind
            return True
        return False

    for edge in rigid:
        if not take(edge, RIGID):
            dropped.append(edge)
    for r in roots:
        take((0, r), ROOT)
    for edge in elastic:
        take(edge, ELASTIC)
    for k in range(1, n_nodes + 1):
        take((0, k), ROOT)
    parent = _orient(n_nodes, chosen)
    kind = tuple(kind_of[frozenset((p, k))] for k, p in enumerate(parent, start=1))
    return SpanningTree(n_nodes, tuple(parent), kind, tuple(dropped))


def gamma_star(
    tree_edges: Sequence[Sequence[int]],
    n_nodes: int,
    root: int | Sequence[int] | None = 1,
    dim: int = 1,
) -> np.ndarray:
    """Topology matrix Γ* of a spanning tree (3.7).

    Row k belongs to body k: the tree link into k from its parent p (oriented away from
    the ground and the root) puts −1 in column p and +1 in column k; the root's row (and
    the row of a body hung directly from the ground) holds a single +1 in its own column.
    Γ* is square and unimodular, and ``α* = Γ* α`` (3.8) are the relative coordinates.

    Parameters
    ----------
    tree_edges : sequence of pairs of int
        The tree links, in any order and orientation (1-based, 0 = the ground).
    n_nodes : int
        Number of bodies.
    root : int, sequence of int or None
        The central vertex (or one per tree of a forest); ``None`` when the tree links
        already hang every body from the ground.
    dim : int
        Coordinates per body; for 3 every entry is a ±1₃ block.

    Returns
    -------
    numpy.ndarray
        Γ*, shape ``(dim·n_nodes, dim·n_nodes)``. For Fig. 3.1 (tree 1–2, 2–3, 3–4,
        root 1): ``[[1,0,0,0], [−1,1,0,0], [0,−1,1,0], [0,0,−1,1]]``.

    Raises
    ------
    TopologyError
        If the links and root rows are not a spanning tree of the bodies and the ground.
    """
    n_nodes = _n_nodes(n_nodes)
    edges = check_edges(tree_edges, n_nodes, "tree link")
    parent = _orient(n_nodes, edges + [(0, r) for r in _roots(root, n_nodes)])
    return _gamma_star(parent, dim)


def _gamma_star(parent: Sequence[int], dim: int) -> np.ndarray:
    n = len(parent)
    g = np.eye(n)
    for k, p in enumerate(parent, start=1):
        if p:
            g[k - 1, p - 1] = -1.0
    return np.kron(g, np.eye(dim)) if dim > 1 else g


def _configuration(parent: Sequence[int], dim: int) -> np.ndarray:
    """``L = Γ*⁻ᵀ`` (3.9), exactly: ``L[k, j] = 1`` when body k is on j's path to the ground."""
    n = len(parent)
    L = np.zeros((n, n))
    for j in range(1, n + 1):
        k = j
        while k:
            L[k - 1, j - 1] = 1.0
            k = parent[k - 1]
    return np.kron(L, np.eye(dim)) if dim > 1 else L


@dataclass(frozen=True)
class Reduction:
    """The model with its rigid links eliminated: ``A* α̈** + D* α̇** + C* α** = Q*`` (3.16).

    Attributes
    ----------
    tree : SpanningTree
        The spanning tree PD.
    gamma_star : numpy.ndarray
        Γ* (3.7), ``α* = Γ* α``.
    L : numpy.ndarray
        Configuration matrix ``Γ*⁻ᵀ`` (3.9).
    f : numpy.ndarray
        Mobility matrix (3.10), diagonal 0/1.
    S : numpy.ndarray
        Structure matrix ``fᵀ L`` (3.11).
    f_star : numpy.ndarray
        f without its zero columns (3.18).
    S_star : numpy.ndarray
        ``f*ᵀ L`` (3.17): the non-zero rows of S.
    A_star, C_star, D_star : numpy.ndarray
        ``S* m S*ᵀ``, ``S* C S*ᵀ``, ``S* D S*ᵀ`` (3.14)–(3.16).
    names : tuple of str
        Names of the coordinates α**: a root's own coordinate, or ``child-parent``.
    dropped_rigid_edges : tuple of (int, int)
        Rigid links left out of the tree because they close a rigid loop.
    constraint : HolonomicMap
        The rigid links as a constraint map ``α = S*ᵀ α**`` (:mod:`rt70.physics.constraints`),
        which reduces A*, C*, D*.
    """

    tree: SpanningTree
    gamma_star: np.ndarray
    L: np.ndarray
    f: np.ndarray
    S: np.ndarray
    f_star: np.ndarray
    S_star: np.ndarray
    A_star: np.ndarray
    C_star: np.ndarray
    D_star: np.ndarray
    names: tuple[str, ...]
    dropped_rigid_edges: tuple[Edge, ...]
    constraint: HolonomicMap

    @property
    def n(self) -> int:
        """Number of remaining coordinates α**."""
        return self.S_star.shape[0]

    def back_substitute(self, alpha_star_star: np.ndarray) -> np.ndarray:
        """Physical coordinates from the reduced ones, ``α = S*ᵀ α**`` (3.17).

        Parameters
        ----------
        alpha_star_star : array_like
            α**, shape ``(n,)`` or ``(n, ...)`` (e.g. one column per time step).

        Returns
        -------
        numpy.ndarray
            α, shape ``(N,)`` or ``(N, ...)``; velocities and accelerations map the same.

        Raises
        ------
        LinearModelError
            If the first dimension is not the number of reduced coordinates.
        """
        x = np.asarray(alpha_star_star, dtype=float)
        if x.ndim == 0 or x.shape[0] != self.n:
            raise LinearModelError(f"α** must have {self.n} rows, got shape {x.shape}")
        return np.tensordot(self.S_star.T, x, axes=1)

    def reduce_force(self, Q: np.ndarray) -> np.ndarray:
        """Generalised force on the reduced coordinates, ``Q* = S* Q`` (3.13)–(3.16).

        Parameters
        ----------
        Q : array_like
            Forces on the physical coordinates, shape ``(N,)`` or ``(N, ...)``.

        Returns
        -------
        numpy.ndarray
            Q*, shape ``(n,)`` or ``(n, ...)``.

        Raises
        ------
        LinearModelError
            If the first dimension is not the number of physical coordinates.
        """
        x = np.asarray(Q, dtype=float)
        if x.ndim == 0 or x.shape[0] != self.S_star.shape[1]:
            raise LinearModelError(f"Q must have {self.S_star.shape[1]} rows, got shape {x.shape}")
        return np.tensordot(self.S_star, x, axes=1)


def _model_edges(model: LinearModel) -> list[Edge]:
    if model.edges is not None:
        return list(model.edges)
    if model.gamma is not None:
        return edges_from_topology(model.gamma, model.dim)
    raise LinearModelError("eliminate needs a model built from a graph (its edges or Γ)")


def eliminate(model: LinearModel, rigid_edges: Sequence[Sequence[int]], root: int = 1) -> Reduction:
    """Eliminate rigid (holonomic) links from a linear graph model (§3.1, (3.5)–(3.18)).

    Parameters
    ----------
    model : LinearModel
        The elastic model ``m α̈ + D α̇ + C α = Q`` (from :func:`rt70.linear.topology.from_graph`
        or a builder; scalar or ``dim=3``).
    rigid_edges : sequence of pairs of int
        The rigid links ``(i, j)``, 1-based, 0 = the ground. They may repeat elastic links
        (the rigid constraint wins: the spring's deformation is zero and it drops out of
        C*, D*) and may form loops (the redundant links are dropped from the tree).
    root : int
        The tree's central vertex (the book: 1).

    Returns
    -------
    Reduction
        Γ*, L, f, S, S*, A*, C*, D* and the back-substitution ``α = S*ᵀ α**``. For
        Fig. 3.1: ``A* = [[I1+I2+I3+I4, I2+I3+I4], [I2+I3+I4, I2+I3+I4]]``,
        ``C* = diag(0, C1+C2+C3)``, ``D* = diag(0, D1+D2+D3)``.

    Raises
    ------
    TopologyError
        On a link or root out of range, or a self-loop.
    LinearModelError
        If the model carries no graph or its matrices do not match its bodies.
    """
    edges = _model_edges(model)
    dim = model.dim
    n_nodes = model.n_nodes
    for name, mat in (("m", model.m), ("C", model.C), ("D", model.D)):
        if np.shape(mat) != (n_nodes * dim, n_nodes * dim) or n_nodes * dim != model.n:
            raise LinearModelError(
                f"model matrix {name} has shape {np.shape(mat)}, expected "
                f"({n_nodes * dim}, {n_nodes * dim})"
            )
    tree = spanning_tree(n_nodes, edges, rigid_edges, root)
    gs = _gamma_star(tree.parent, dim)
    L = _configuration(tree.parent, dim)
    mobility = np.repeat(tree.mobility, dim)
    f = np.diag(mobility)
    S = f.T @ L
    keep = np.flatnonzero(mobility)
    f_star = f[:, keep]
    S_star = f_star.T @ L
    names = []
    for k in np.flatnonzero(tree.mobility) + 1:
        p = tree.parent[k - 1]
        for a in range(dim):
            own = model.names[(k - 1) * dim + a]
            names.append(own if p == 0 else f"{own}-{model.names[(p - 1) * dim + a]}")
    rigid = rigid_link_map(S_star, model.names, names)  # α = S*ᵀ α** (3.17)
    return Reduction(
        tree=tree,
        gamma_star=gs,
        L=L,
        f=f,
        S=S,
        f_star=f_star,
        S_star=S_star,
        A_star=rigid.reduce_matrix(model.m),
        C_star=rigid.reduce_matrix(model.C),
        D_star=rigid.reduce_matrix(model.D),
        names=tuple(names),
        dropped_rigid_edges=tree.dropped_rigid_edges,
        constraint=rigid,
    )
