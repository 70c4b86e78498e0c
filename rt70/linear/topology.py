"""Linear models from the topology of an elastic graph (book chapter 2, formalism §2).

The bodies are the vertices of a graph (vertex 0 is the ground), the elastic links its
edges. A link s between vertices i and j deforms by ``α_j − α_i`` (by ``α_j`` when i is
the ground), so the deformations are ``Γ α`` with the topology matrix Γ, and (2.9)

    ``m q̈ + Γᵀ D Γ q̇ + Γᵀ C Γ q = Q + Γᵀ C Γ R``,   ``C = diag(C_s)``, ``D = diag(D_s)``.

For 3-D point masses every entry of Γ is a 3 × 3 block (``dim=3``): the coordinates are
ordered node by node, x, y, z within a node, and a link's stiffness acts per axis.

:func:`from_graph` builds a model from inertias, links and stiffnesses (the book's
RT-70 tables are typed this way in :mod:`rt70.scenes.rt70_chapter2`), and
:func:`rt70.linear.torsion_scene.from_scene` reads such a model back from a torsional
URDF scene (SI), so that tables and files can be compared.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from rt70.errors import NonFiniteError, Rt70Error, TopologyError

#: An elastic (or rigid) link: ``(i, j)``, 1-based node numbers, 0 = the ground.
Edge = tuple[int, int]


class LinearModelError(Rt70Error):
    """The data of a linear model are inconsistent (shapes, signs, not a chapter-2 scene)."""


# ---------------------------------------------------------------------------------------
# Topology matrix
# ---------------------------------------------------------------------------------------


def _positive_int(value: object, what: str) -> int:
    try:
        n = operator.index(value)
    except TypeError:
        raise LinearModelError(f"{what} must be an integer, got {value!r}") from None
    if n < 1:
        raise LinearModelError(f"{what} must be at least 1, got {n}")
    return n


def check_edges(edges: Sequence[Sequence[int]], n_nodes: int, what: str = "edge") -> list[Edge]:
    """Validate links ``(i, j)`` of a graph with ``n_nodes`` bodies and the ground 0.

    Parameters
    ----------
    edges : sequence of pairs of int
        Links between vertices, 1-based body numbers, 0 = the ground.
    n_nodes : int
        Number of bodies (vertices other than the ground).
    what : str
        Word naming the links in error messages ("elastic link", "rigid link").

    Returns
    -------
    list of tuple of int
        The links as plain ``(i, j)`` tuples.

    Raises
    ------
    TopologyError
        If a link is not a pair of integers, names a vertex outside ``0..n_nodes`` or
        joins a vertex to itself.
    """
    out: list[Edge] = []
    for k, edge in enumerate(edges):
        try:
            i, j = (operator.index(v) for v in edge)
        except (TypeError, ValueError):
            raise TopologyError(
                f"{what} {k}: {edge!r} is not a pair of node numbers (i, j)"
            ) from None
        for v in (i, j):
            if not 0 <= v <= n_nodes:
                raise TopologyError(
                    f"{what} {k} ({i}, {j}): node {v} out of range 0..{n_nodes} (0 = ground)"
                )
        if i == j:
            raise TopologyError(f"{what} {k} ({i}, {j}) joins node {i} to itself")
        out.append((i, j))
    return out


def topology_matrix(edges: Sequence[Sequence[int]], n_nodes: int, dim: int = 1) -> np.ndarray:
    """Topology matrix Γ of a graph (formalism §2; (2.14), (2.26), (3.5)).

    One row per link, one column per body. A link ``(i, j)`` between bodies i and j puts
    −1 in column i and +1 in column j, so its row of ``Γ α`` is the deformation
    ``α_j − α_i``; a link ``(0, j)`` to the ground puts only +1 in column j (and
    ``(i, 0)`` only −1 in column i).

    Parameters
    ----------
    edges : sequence of pairs of int
        Links ``(i, j)``, 1-based body numbers, 0 = the ground.
    n_nodes : int
        Number of bodies.
    dim : int
        Coordinates per body: 1 for rotation about one axis or motion along one line,
        3 for point masses in space (each entry becomes a ±1₃ block).

    Returns
    -------
    numpy.ndarray
        Γ, shape ``(dim·len(edges), dim·n_nodes)``.

    Raises
    ------
    TopologyError
        If a link names a node out of range or is a self-loop.
    LinearModelError
        If ``n_nodes`` or ``dim`` is not a positive integer.
    """
    n_nodes = _positive_int(n_nodes, "n_nodes")
    dim = _positive_int(dim, "dim")
    checked = check_edges(edges, n_nodes)
    gamma = np.zeros((len(checked), n_nodes))
    for s, (i, j) in enumerate(checked):
        if i:
            gamma[s, i - 1] = -1.0
        if j:
            gamma[s, j - 1] = 1.0
    return np.kron(gamma, np.eye(dim)) if dim > 1 else gamma


def edges_from_topology(gamma: np.ndarray, dim: int = 1) -> list[Edge]:
    """Read the links ``(i, j)`` back from a topology matrix Γ (inverse of :func:`topology_matrix`).

    Parameters
    ----------
    gamma : array_like
        Γ, shape ``(dim·n_links, dim·n_nodes)``, entries −1, 0, +1 (±1₃ blocks for dim 3).
    dim : int
        Coordinates per body.

    Returns
    -------
    list of tuple of int
        One link per (block) row: ``i`` is the column of −1 (0 when there is none, the
        ground), ``j`` the column of +1 (0 when there is none), 1-based.

    Raises
    ------
    TopologyError
        If a row is not one link (no entry, two entries of one sign, other values).
    """
    dim = _positive_int(dim, "dim")
    g = np.asarray(gamma, dtype=float)
    if g.ndim != 2 or g.shape[0] % dim or g.shape[1] % dim:
        raise TopologyError(f"topology matrix of shape {g.shape} has no {dim} × {dim} blocks")
    n_nodes = g.shape[1] // dim
    scalar = g[::dim, ::dim]
    if dim > 1 and not np.array_equal(g, np.kron(scalar, np.eye(dim))):
        raise TopologyError("topology matrix is not made of ±1 blocks times the identity")
    edges: list[Edge] = []
    for s, row in enumerate(scalar):
        minus = np.flatnonzero(row == -1.0)
        plus = np.flatnonzero(row == 1.0)
        if len(minus) > 1 or len(plus) > 1 or len(minus) + len(plus) != np.count_nonzero(row):
            raise TopologyError(f"topology row {s} {row.tolist()} is not one link")
        if len(minus) + len(plus) == 0:
            raise TopologyError(f"topology row {s} is empty")
        i = int(minus[0]) + 1 if len(minus) else 0
        j = int(plus[0]) + 1 if len(plus) else 0
        edges.append((i, j))
    check_edges(edges, n_nodes)
    return edges


# ---------------------------------------------------------------------------------------
# The linear model
# ---------------------------------------------------------------------------------------


@dataclass
class LinearModel:
    """A linear mechanical model ``m q̈ + D q̇ + C q = Q`` (2.9).

    Attributes
    ----------
    m : numpy.ndarray
        Mass / inertia matrix (n × n), ``diag(I)`` for a chapter-2 graph.
    C : numpy.ndarray
        Stiffness matrix ``Γᵀ diag(C_s) Γ``.
    D : numpy.ndarray
        Damping matrix ``Γᵀ diag(D_s) Γ``.
    names : tuple of str
        Coordinate names (for dim 3: ``<node>_x``, ``<node>_y``, ``<node>_z``).
    gamma : numpy.ndarray or None
        The topology matrix Γ, when the model was built from a graph.
    c_links, d_links : numpy.ndarray or None
        Stiffness and damping of each row of Γ (``C = diag(c_links)``).
    edges : tuple of (int, int) or None
        The elastic links ``(i, j)`` (1-based, 0 = ground), one per (block) row of Γ.
    dim : int
        Coordinates per body (1, or 3 for point masses in space).
    """

    m: np.ndarray
    C: np.ndarray
    D: np.ndarray
    names: tuple[str, ...]
    gamma: np.ndarray | None = None
    c_links: np.ndarray | None = None
    d_links: np.ndarray | None = None
    edges: tuple[Edge, ...] | None = None
    dim: int = 1

    @property
    def n(self) -> int:
        """Number of coordinates."""
        return self.m.shape[0]

    @property
    def n_nodes(self) -> int:
        """Number of bodies (coordinates / dim)."""
        return self.m.shape[0] // self.dim


def _link_values(
    values: Sequence[float] | np.ndarray | None, n_links: int, dim: int, what: str
) -> np.ndarray:
    """Per-row values of a link property: scalars per link, or (n_links, dim) per axis."""
    if values is None:
        return np.zeros(n_links * dim)
    v = np.asarray(values, dtype=float)
    if v.shape == (n_links,):
        v = np.repeat(v, dim)
    elif dim > 1 and v.shape == (n_links, dim):
        v = v.reshape(-1)
    else:
        shapes = f"({n_links},)" + (f" or ({n_links}, {dim})" if dim > 1 else "")
        raise LinearModelError(f"{what} has shape {v.shape}, expected {shapes}")
    if not np.all(np.isfinite(v)):
        raise NonFiniteError(f"{what} contains NaN or infinite values")
    if np.any(v < 0):
        raise LinearModelError(f"{what} must be non-negative, got {v.min():g}")
    return v


def from_graph(
    inertias: Sequence[float] | np.ndarray,
    edges: Sequence[Sequence[int]],
    stiffness: Sequence[float] | np.ndarray,
    damping: Sequence[float] | np.ndarray | None = None,
    names: Sequence[str] | None = None,
    dim: int = 1,
) -> LinearModel:
    """Build ``m``, ``Γᵀ C Γ`` and ``Γᵀ D Γ`` of a graph of bodies and links (2.9).

    Parameters
    ----------
    inertias : array_like
        Moment of inertia (or mass) of each body, length ``n_nodes``; for ``dim=3`` each
        is repeated on the three axes.
    edges : sequence of pairs of int
        Elastic links ``(i, j)``, 1-based, 0 = the ground (see :func:`topology_matrix`).
    stiffness : array_like
        ``C_s`` of each link, shape ``(n_links,)``, or ``(n_links, dim)`` per axis.
    damping : array_like, optional
        ``D_s`` of each link, same shapes; zero when omitted.
    names : sequence of str, optional
        Body names (default ``q1 … qn``); for ``dim=3`` the coordinates are named
        ``<name>_x``, ``<name>_y``, ``<name>_z``.
    dim : int
        Coordinates per body (1, or 3 for point masses in space).

    Returns
    -------
    LinearModel
        ``m = diag(inertias)``, ``C = Γᵀ diag(c) Γ``, ``D = Γᵀ diag(d) Γ``.

    Raises
    ------
    TopologyError
        On a link out of range or a self-loop.
    NonFiniteError
        On NaN or infinite inertias, stiffnesses or dampings.
    LinearModelError
        On wrong lengths, negative values or a name count that does not match.
    """
    dim = _positive_int(dim, "dim")
    inertia = np.asarray(inertias, dtype=float)
    if inertia.ndim != 1 or inertia.size == 0:
        raise LinearModelError(f"inertias must be a non-empty vector, got shape {inertia.shape}")
    if not np.all(np.isfinite(inertia)):
        raise NonFiniteError("inertias contain NaN or infinite values")
    if np.any(inertia < 0):
        raise LinearModelError(f"inertias must be non-negative, got {inertia.min():g}")
    n_nodes = inertia.size
    checked = check_edges(edges, n_nodes, "elastic link")
    gamma = topology_matrix(checked, n_nodes, dim)
    c = _link_values(stiffness, len(checked), dim, "stiffness")
    d = _link_values(damping, len(checked), dim, "damping")
    if names is None:
        names = [f"q{k}" for k in range(1, n_nodes + 1)]
    names = [str(x) for x in names]
    if len(names) != n_nodes:
        raise LinearModelError(f"{len(names)} names given for {n_nodes} bodies")
    if dim == 3:
        names = [f"{x}_{a}" for x in names for a in "xyz"]
    elif dim > 1:
        names = [f"{x}_{a}" for x in names for a in range(dim)]
    return LinearModel(
        m=np.diag(np.repeat(inertia, dim)),
        C=gamma.T @ (c[:, None] * gamma),
        D=gamma.T @ (d[:, None] * gamma),
        names=tuple(names),
        gamma=gamma,
        c_links=c,
        d_links=d,
        edges=tuple(checked),
        dim=dim,
    )


def proportional_damping(model: LinearModel, delta: float) -> LinearModel:
    """Return a copy of ``model`` with the book's proportional damping ``D_s = δ C_s`` (2.16).

    Parameters
    ----------
    model : LinearModel
        A model built from a graph (it must carry ``gamma`` and ``c_links``).
    delta : float
        The proportionality factor δ, s (non-negative); see :func:`book_delta`.

    Returns
    -------
    LinearModel
        The same model with ``d_links = δ c_links`` and ``D = Γᵀ diag(d_links) Γ = δ C``.

    Raises
    ------
    LinearModelError
        If the model has no topology (``gamma``/``c_links``) or δ is negative.
    NonFiniteError
        If δ is NaN or infinite.
    """
    if model.gamma is None or model.c_links is None:
        raise LinearModelError("proportional damping needs a model built from a graph (Γ, C_s)")
    delta = float(delta)
    if not math.isfinite(delta):
        raise NonFiniteError(f"damping factor δ must be finite, got {delta}")
    if delta < 0:
        raise LinearModelError(f"damping factor δ must be non-negative, got {delta:g}")
    d = delta * model.c_links
    return replace(model, D=model.gamma.T @ (d[:, None] * model.gamma), d_links=d)


def book_delta(omega1: float) -> float:
    """The book's damping factor ``δ = 0.1 / Ω1`` (§2.3, (2.16)).

    The full-scale experiment shows a 20 dB peak at the first resonance, i.e. ξ = 0.05
    there; with ``D = δ C`` the i-th mode has ``ξ_i = δ Ω_i / 2``, so ``δ = 2ξ/Ω1``.

    Parameters
    ----------
    omega1 : float
        First non-zero circular eigenfrequency Ω1, rad/s.

    Returns
    -------
    float
        δ, s.

    Raises
    ------
    LinearModelError
        If Ω1 is not a positive finite number.
    """
    omega1 = float(omega1)
    if not (math.isfinite(omega1) and omega1 > 0):
        raise LinearModelError(f"first resonance Ω1 must be positive and finite, got {omega1}")
    return 0.1 / omega1
