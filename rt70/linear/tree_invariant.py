"""The product of the non-zero ω² of a free torsional tree: ``ΠC · ΣI / ΠI``, whatever the wiring.

A chapter-2 model (2.9) of n bodies with inertias ``I_1 … I_n > 0`` on one axis,
``M = diag(I)``, and n − 1 torsion springs ``C_1 … C_{n−1} > 0`` whose links form a
spanning tree of the bodies with no link to the ground (Γ the (n−1) × n topology
matrix, one −1 and one +1 per row), has ``K = Γᵀ diag(C) Γ`` and the spectrum
``K v = ω² M v``. Then ω = 0 is a simple eigenvalue (the free rotation of the whole)
and the product of the other n − 1 eigenvalues is

    ``Π_k ω_k² = ΠC · ΣI / ΠI``                                              (*)

— independent of which bodies the springs join and of which spring or body carries
which value.

Derivation (the full proof, with the case of non-unit entries of Γ, is in
``docs/tree-invariant.md``). With ``A = C^{1/2} Γ M^{−1/2}`` ((n−1) × n), the
eigenvalues of the pencil are those of ``AᵀA = M^{−1/2} K M^{−1/2}``, whose non-zero
eigenvalues are those of ``AAᵀ = C^{1/2} Γ M⁻¹ Γᵀ C^{1/2}``. By the Cauchy–Binet formula

    ``det(AAᵀ) = ΠC · det(Γ M⁻¹ Γᵀ) = ΠC · Σ_k det(Γ_(k))² · I_k / ΠI``,

``Γ_(k)`` being Γ without column k. For a tree every ``Γ_(k)`` has determinant ±1
(root the tree at k and order the links by their far end: the matrix is triangular
with ±1 on the diagonal) — this is the weighted matrix-tree theorem (Kirchhoff): every
cofactor of the weighted Laplacian ``K`` equals the sum over spanning trees of the
product of their weights, here the single tree's ``ΠC``. So ``det(AAᵀ) = ΠC ΣI / ΠI
> 0``: ``AAᵀ`` is non-singular, all its n − 1 eigenvalues are the non-zero ones of the
pencil, and their product is (*).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from rt70.errors import NonFiniteError
from rt70.linear.topology import LinearModel, LinearModelError


def _positive(values: Sequence[float] | np.ndarray, what: str) -> np.ndarray:
    v = np.asarray(values, dtype=float)
    if v.ndim != 1 or v.size == 0:
        raise LinearModelError(f"{what} must be a non-empty vector, got shape {v.shape}")
    if not np.all(np.isfinite(v)):
        raise NonFiniteError(f"{what} contain NaN or infinite values")
    if np.any(v <= 0):
        raise LinearModelError(f"{what} must be positive, got {v.min():g}")
    return v


def free_tree_omega2_product(
    inertias: Sequence[float] | np.ndarray, stiffness: Sequence[float] | np.ndarray
) -> float:
    """``ΠC · ΣI / ΠI``: the product of the non-zero ω² of any free tree of these values.

    Parameters
    ----------
    inertias : array_like
        ``I_1 … I_n`` of the bodies, positive.
    stiffness : array_like
        ``C_1 … C_{n−1}`` of the springs, positive; any wiring of them into a spanning
        tree without a link to the ground has this product (module docstring).

    Returns
    -------
    float
        ``Π_k ω_k²`` over the n − 1 non-zero eigenvalues, in (1/s)^(2(n−1)) when I and C
        are in consistent units (the unit cancels: I and C scale alike).

    Raises
    ------
    LinearModelError
        If there are not n − 1 stiffnesses for n inertias, a value is not positive, or
        the product overflows a float.
    NonFiniteError
        On NaN or infinite values.
    """
    inertia = _positive(inertias, "inertias")
    c = _positive(stiffness, "stiffnesses")
    if c.size != inertia.size - 1:
        raise LinearModelError(
            f"a tree of {inertia.size} bodies has {inertia.size - 1} springs, got {c.size}"
        )
    log = (
        math.fsum(np.log(c)) + math.log(math.fsum(inertia)) - math.fsum(np.log(inertia))
    )  # in logarithms: ΠC alone overflows for a few dozen stiff springs
    try:
        return math.exp(log)
    except OverflowError:
        raise LinearModelError(f"ΠC·ΣI/ΠI = exp({log:.6g}) overflows a float") from None


def free_tree_check(model: LinearModel) -> None:
    """Raise unless ``model`` is a free tree of torsion springs with unit topology matrix.

    That is: one coordinate per body (dim 1), ``m`` diagonal, n − 1 links built from a
    graph (:func:`rt70.linear.topology.from_graph`), none to the ground, joining all
    bodies (a spanning tree) — the hypotheses of :func:`free_tree_omega2_product`.

    Raises
    ------
    LinearModelError
        Naming the hypothesis that fails.
    """
    if model.edges is None or model.c_links is None:
        raise LinearModelError("not built from a graph: no links (Γ, C_s) to check")
    if model.dim != 1:
        raise LinearModelError(f"{model.dim} coordinates per body: the invariant is for dim 1")
    if not np.array_equal(model.m, np.diag(np.diag(model.m))):
        raise LinearModelError("inertia matrix is not diagonal")
    n = model.n_nodes
    if len(model.edges) != n - 1:
        raise LinearModelError(f"{len(model.edges)} links for {n} bodies: a tree has {n - 1}")
    root = list(range(n + 1))  # union–find over the vertices, 0 = the ground

    def find(v: int) -> int:
        while root[v] != v:
            root[v] = root[root[v]]
            v = root[v]
        return v

    for s, (i, j) in enumerate(model.edges):
        if i == 0 or j == 0:
            raise LinearModelError(f"link {s + 1} ({i}, {j}) is tied to the ground: not free")
        a, b = find(i), find(j)
        if a == b:
            raise LinearModelError(f"link {s + 1} ({i}, {j}) closes a loop: not a tree")
        root[a] = b


def model_omega2_product(model: LinearModel) -> float:
    """``ΠC · ΣI / ΠI`` of a chapter-2 model, after checking it is a free tree.

    Parameters
    ----------
    model : LinearModel
        E.g. :func:`rt70.scenes.rt70_chapter2.azimuth_model`.

    Returns
    -------
    float
        The product of its n − 1 non-zero ω² (see :func:`free_tree_omega2_product`).

    Raises
    ------
    LinearModelError
        If the model is not a free unit-incidence tree (:func:`free_tree_check`).
    """
    free_tree_check(model)
    return free_tree_omega2_product(np.diag(model.m), model.c_links)


def printed_omega2_product(freq_hz: Sequence[float] | np.ndarray) -> float:
    """``Π (2π f)²`` over the non-zero frequencies of a spectrum (zeros left out).

    Parameters
    ----------
    freq_hz : array_like
        Frequencies in Hz, e.g. a printed spectrum; exact zeros are the rigid modes.

    Returns
    -------
    float
        The product of the non-zero ω², (1/s)^(2m) for m non-zero frequencies.

    Raises
    ------
    LinearModelError
        If a frequency is negative or none is non-zero.
    NonFiniteError
        On NaN or infinite values.
    """
    f = np.asarray(freq_hz, dtype=float)
    if not np.all(np.isfinite(f)):
        raise NonFiniteError("frequencies contain NaN or infinite values")
    if np.any(f < 0):
        raise LinearModelError(f"frequencies must be non-negative, got {f.min():g}")
    nonzero = f[f > 0]
    if nonzero.size == 0:
        raise LinearModelError("no non-zero frequency")
    return math.exp(2.0 * math.fsum(np.log(2.0 * math.pi * nonzero)))
