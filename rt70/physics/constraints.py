"""Holonomic constraints solved explicitly: ``q_full = T q + q₀`` (book chapter 3).

The one place where the constraints the library eliminates meet. Each of them ties a set
of *full* coordinates to fewer *independent* ones by a constant linear map; the book's
elimination is the same every time — generalised forces reduce by ``Tᵀ``
(``S = fᵀ L``, ``Q* = S* Q``), matrices by ``Tᵀ M T`` ((3.13)–(3.16), (4.66)), and the
full coordinates come back as ``T q + q₀`` ((3.17)):

- URDF ``<mimic>`` joints, ``q_m = k q_s + o``: T = G, q₀ = the offsets
  (:func:`mimic_map`), eliminated by :func:`rt70.textbook.model.build_model`;
- coordinates locked or held by the drives: T = the identity without their columns (the
  mobility f, §4.1), q₀ = their values (:func:`locking`), eliminated by
  :func:`rt70.linear.linearize.linearize` and :func:`~rt70.linear.linearize.equilibrium`;
- rigid links of a linear graph model: T = ``S*ᵀ`` of the spanning tree (3.17)
  (:func:`rigid_link_map`), eliminated by :func:`rt70.linear.holonomic.eliminate`.

A new holonomic constraint that can be solved for its dependent coordinates builds a
:class:`HolonomicMap` here and hands it to the layer that eliminates it; maps compose
(:meth:`HolonomicMap.then`): e.g. coordinates locked in a model that already has mimic
joints. The reference side does not use this module: Pinocchio's mimic joints are mapped
independently (:mod:`rt70.reference.coordinates`), so the cross-check also checks G.
Constraints that cannot be solved explicitly (closed loops, nonholonomic ``Φ q̇ = 0``)
will be added here as implicit constraints.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from rt70.errors import Rt70Error


@dataclass(frozen=True)
class HolonomicMap:
    """``q_full = T q + q₀``: full coordinates from the independent ones.

    Attributes
    ----------
    T : numpy.ndarray
        Constraint matrix, shape (n_full, n) — G of the mimic joints, the mobility f of
        locked coordinates, ``S*ᵀ`` of rigid links.
    offset : numpy.ndarray
        q₀, shape (n_full,): the mimic offsets, the locked values.
    full_names, names : tuple of str
        Names of the full and of the independent coordinates.
    columns : numpy.ndarray or None
        When T is the identity without some columns (locked coordinates): the full
        coordinates kept, so that the products below are the exact selections they are
        (O(n²) instead of O(n³) for a model of thousands of coordinates).
    """

    T: np.ndarray
    offset: np.ndarray
    full_names: tuple[str, ...]
    names: tuple[str, ...]
    columns: np.ndarray | None = None

    def expand(self, q: np.ndarray, offset: bool = True) -> np.ndarray:
        """``T q + q₀`` (without q₀ for velocities and accelerations)."""
        if self.columns is not None:
            full = self.offset.copy() if offset else np.zeros(self.offset.shape)
            full[self.columns] = q
            return full
        return self.T @ q + self.offset if offset else self.T @ q

    def reduce_force(self, Q_full: np.ndarray) -> np.ndarray:
        """Generalised force on the independent coordinates, ``Tᵀ Q_full``."""
        if self.columns is not None:
            return np.asarray(Q_full)[self.columns]
        return self.T.T @ Q_full

    def reduce_matrix(self, M_full: np.ndarray) -> np.ndarray:
        """``Tᵀ M T``: a mass, stiffness or damping matrix on the independent coordinates.

        When nothing is locked (T = 1) that is a copy of ``M_full`` (it may be a work
        buffer, e.g. the textbook's ``data.A``).
        """
        if self.columns is not None:
            if self.columns.size == len(self.full_names):  # nothing locked: T = 1
                return np.array(M_full, dtype=float)
            return np.asarray(M_full)[np.ix_(self.columns, self.columns)]
        return self.T.T @ M_full @ self.T

    def then(self, inner: HolonomicMap) -> HolonomicMap:
        """The map of ``inner``'s independent coordinates into this map's full ones.

        ``self`` maps ``q_mid → q_full`` and ``inner`` maps ``q → q_mid``; the result is
        ``q_full = T (T_i q + q₀ᵢ) + q₀``.
        """
        if tuple(inner.full_names) != tuple(self.names):
            raise Rt70Error("constraint maps do not chain: inner's full coordinates differ")
        return HolonomicMap(
            self.T @ inner.T, self.T @ inner.offset + self.offset, self.full_names, inner.names
        )


def mimic_map(
    full_names: Sequence[str], mimics: Mapping[str, tuple[str, float, float]]
) -> HolonomicMap:
    """URDF ``<mimic>`` joints, ``q_m = k q_s + o``, as a map (chapter 3).

    Parameters
    ----------
    full_names : sequence of str
        Every coordinate of the pairs, mimic joints included.
    mimics : mapping
        ``{mimic joint: (source joint, multiplier k, offset o)}``.
    """
    independent = [n for n in full_names if n not in mimics]
    column = {name: c for c, name in enumerate(independent)}
    T = np.zeros((len(full_names), len(independent)))
    offset = np.zeros(len(full_names))
    for row, name in enumerate(full_names):
        if name in mimics:
            source, multiplier, shift = mimics[name]
            T[row, column[source]] = multiplier
            offset[row] = shift
        else:
            T[row, column[name]] = 1.0
    return HolonomicMap(T, offset, tuple(full_names), tuple(independent))


def locking(names: Sequence[str], locked: Mapping[str, float] | Sequence[str]) -> HolonomicMap:
    """Coordinates held at given values (a drive holding an axis), the rest free.

    ``T`` is the identity without the locked columns (the book's mobility f with
    ``f_ii = 0``, §4.1), ``q₀`` holds the locked values (0 for a bare list of names).

    Raises
    ------
    Rt70Error
        If a locked name is not a coordinate.
    """
    values = dict(locked) if isinstance(locked, Mapping) else dict.fromkeys(locked, 0.0)
    missing = [n for n in values if n not in names]
    if missing:
        raise Rt70Error(f"no coordinate(s) {', '.join(missing)}")
    free = [i for i, n in enumerate(names) if n not in values]
    T = np.eye(len(names))[:, free]
    offset = np.array([values.get(n, 0.0) for n in names], dtype=float)
    kept = np.array(free, dtype=int)
    return HolonomicMap(T, offset, tuple(names), tuple(names[i] for i in free), kept)


def rigid_link_map(
    S_star: np.ndarray, full_names: Sequence[str], names: Sequence[str]
) -> HolonomicMap:
    """Rigid links of a linear graph model: ``α = S*ᵀ α**`` (3.17), no offset.

    Parameters
    ----------
    S_star : numpy.ndarray, shape (k, n)
        ``S* = f*ᵀ L`` (3.17): the non-zero rows of the structure matrix, k reduced
        coordinates α** by n body coordinates α.
    full_names : sequence of str
        The n body coordinates' names (the graph model's).
    names : sequence of str
        The k reduced coordinates' names (relative motions the rigid links allow).
    """
    return HolonomicMap(S_star.T, np.zeros(S_star.shape[1]), tuple(full_names), tuple(names))
