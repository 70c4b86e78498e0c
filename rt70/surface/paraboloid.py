"""The paraboloid ``z = (x² + y²) / (4F)`` and the half-path-length error of its nodes.

One job: the first-order path error of a node of a paraboloidal reflector displaced by
``Δ = (Δx, Δy, Δz)`` in the reflector's frame (vertex at the origin, axis +z towards the
focus at ``(0, 0, F)``). A plane wave along the axis reflected to the focus travels the
same path from every point of the nominal surface; a displaced node changes the path
of its ray by ``2 h``, with the **half-path-length error** (Levy, *Structural Engineering
of Microwave Antennas*, IEEE Press 1996, ch. 4; spec flexible-and-reflector.md §5)

    h = (Δz − (x Δx + y Δy) / (2F)) · cos²(θ/2),    cos²(θ/2) = 1 / (1 + r² / (4F²)),

θ the angle at the focus between the axis and the node. ``(−x/2F, −y/2F, 1)`` is the
surface's gradient, of length ``1 / cos(θ/2)``, so ``h = (n · Δ) cos(θ/2)`` with n the
unit normal: a displacement along the surface costs nothing, one along the normal
``cos(θ/2)`` of itself, and the normal error is ``ε_n = h / cos(θ/2)``. ``h > 0``: the
node moved towards the focus side, its ray's path is shorter by ``2h`` (the surface is
high there).
"""

from __future__ import annotations

import numpy as np

from rt70.errors import Rt70Error


def check_nodes(nodes: np.ndarray, focal_length: float) -> np.ndarray:
    """``nodes`` as an (N, 3) float array, or an :class:`~rt70.errors.Rt70Error`.

    Parameters
    ----------
    nodes : array_like, shape (N, 3)
        Surface nodes in the reflector's frame, m.
    focal_length : float
        F, m (> 0).
    """
    if not (np.isfinite(focal_length) and focal_length > 0.0):
        raise Rt70Error(f"the focal length must be a positive number of metres, got {focal_length}")
    array = np.asarray(nodes, dtype=float)
    if array.ndim != 2 or array.shape[1] != 3 or array.shape[0] < 1:
        raise Rt70Error(f"surface nodes must be an (N, 3) array, got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise Rt70Error("surface nodes contain NaN or infinite values")
    return array


def surface_height(x: np.ndarray, y: np.ndarray, focal_length: float) -> np.ndarray:
    """``z = (x² + y²) / (4F)`` of the nominal paraboloid, m.

    Parameters
    ----------
    x, y : array_like
        Coordinates in the reflector's frame, m.
    focal_length : float
        F, m.
    """
    return (np.asarray(x) ** 2 + np.asarray(y) ** 2) / (4.0 * focal_length)


def obliquity(nodes: np.ndarray, focal_length: float) -> np.ndarray:
    """``cos²(θ/2) = 1 / (1 + r² / (4F²))`` at each node, (N,)."""
    r2 = nodes[:, 0] ** 2 + nodes[:, 1] ** 2
    return 1.0 / (1.0 + r2 / (4.0 * focal_length**2))


def path_error_map(nodes: np.ndarray, focal_length: float) -> np.ndarray:
    """The linear map from the nodes' displacements to their half-path-length errors.

    Parameters
    ----------
    nodes : array_like, shape (N, 3)
        Surface nodes in the reflector's frame, m (on the paraboloid of ``focal_length``).
    focal_length : float
        F, m.

    Returns
    -------
    numpy.ndarray, shape (N, 3)
        Row n is ``(−x/(2F), −y/(2F), 1) cos²(θ/2)``: ``h_n = row_n · Δ_n``.
    """
    nodes = check_nodes(nodes, focal_length)
    c = obliquity(nodes, focal_length)
    return np.column_stack(
        [-nodes[:, 0] / (2.0 * focal_length) * c, -nodes[:, 1] / (2.0 * focal_length) * c, c]
    )


def half_path_errors(
    nodes: np.ndarray, displacements: np.ndarray, focal_length: float
) -> np.ndarray:
    """``h`` of each node displaced by ``displacements`` (N, 3), m (module docstring).

    Parameters
    ----------
    nodes : array_like, shape (N, 3)
        Surface nodes in the reflector's frame, m.
    displacements : array_like, shape (N, 3)
        Their displacements, m.
    focal_length : float
        F, m.
    """
    rows = path_error_map(nodes, focal_length)
    delta = np.asarray(displacements, dtype=float)
    if delta.shape != rows.shape:
        raise Rt70Error(f"displacements have shape {delta.shape}, the nodes {rows.shape}")
    if not np.all(np.isfinite(delta)):
        raise Rt70Error("displacements contain NaN or infinite values")
    return np.sum(rows * delta, axis=1)
