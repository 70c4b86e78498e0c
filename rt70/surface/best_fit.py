"""The best-fit paraboloid of a deformed reflector surface (book §4.1.8's approximating one).

One job: the paraboloid that minimises the weighted RMS of the half-path-length errors
``h`` (:mod:`rt70.surface.paraboloid`) over the aperture, its parameters and what is left.
The best-fit paraboloid (BFP) is the nominal one moved rigidly — vertex translation
``t = (u, v, w)``, axis tilt ``φ = (φ_x, φ_y)`` about the vertex — with its focal length
changed by ΔF. For small deformations its own ``h`` is linear in ``β = (u, v, w, φ_x, φ_y,
ΔF)`` (Levy 1996, ch. 4; spec flexible-and-reflector.md §5): a node moved by
``t + φ × p`` and, for ΔF, by ``−r²/(4F²) ΔF`` along z at fixed (x, y) has, with
``c = cos²(θ/2)`` and ``z = r²/(4F)``,

    h = c [ −x/(2F) u − y/(2F) v + w + y (1 + z/(2F)) φ_x − x (1 + z/(2F)) φ_y
            − r²/(4F²) ΔF ]  =  (A β)_n.

The fit is the weighted least-squares problem ``min Σ w_n (h_n − (A β)_n)²``: with
``W = diag(w)``, ``β = P h``, ``P = (Aᵀ W A)⁻¹ Aᵀ W`` (solved by an SVD of ``W^½ A``),
the residual ``r = (1 − A P) h`` and its RMS ``sqrt(Σ w r² / Σ w)``. A rotation about the
axis leaves a paraboloid of revolution in place (its ``h`` is zero), so it is not a
parameter. The weights are the area of the aperture each node stands for, times the
illumination taper where one is given.

From β: the BFP's vertex ``t``, its axis ``(φ_y, −φ_x, 1)`` (to first order), its focal
length ``F + ΔF`` and its focus, displaced from the nominal ``(0, 0, F)`` by
``(u + F φ_y, v − F φ_x, w + ΔF)``: the lateral and axial (linear) defocus of the book's
control errors, the tilt the angular one. Every output is linear in the nodes'
displacements, so :func:`fit_maps` gives the exact matrices the plant's outputs need.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from rt70.errors import Rt70Error
from rt70.surface.paraboloid import check_nodes, path_error_map

#: The BFP's parameters, in the order of β.
PARAMETERS = ("u", "v", "w", "phi_x", "phi_y", "dF")
#: Singular values of ``W^½ A`` below this fraction of the largest: parameters the
#: nodes cannot tell apart (too few nodes, all on one ring, …), refused.
RANK_RTOL = 1e-10


@dataclass(frozen=True)
class FitMaps:
    """The best fit as linear maps of the nodes' half-path-length errors h, (N,).

    Attributes
    ----------
    A : numpy.ndarray, shape (N, 6)
        h of a unit change of each BFP parameter (module docstring).
    P : numpy.ndarray, shape (6, N)
        ``β = P h``.
    R : numpy.ndarray, shape (N, N)
        The residual ``r = R h = (1 − A P) h``.
    weights : numpy.ndarray, shape (N,)
        The weights, normalised to sum 1.
    H : numpy.ndarray, shape (N, 3)
        ``h_n = H_n · Δ_n`` (:func:`rt70.surface.paraboloid.path_error_map`).
    """

    A: np.ndarray
    P: np.ndarray
    R: np.ndarray
    weights: np.ndarray
    H: np.ndarray


@dataclass(frozen=True)
class BestFit:
    """The best-fit paraboloid of one deformed surface.

    Attributes
    ----------
    parameters : numpy.ndarray, shape (6,)
        β = (u, v, w, φ_x, φ_y, ΔF): m, m, m, rad, rad, m.
    residual : numpy.ndarray, shape (N,)
        Each node's half-path-length error left after the fit, m.
    rms : float
        ``sqrt(Σ w r² / Σ w)``, the weighted RMS of the residual, m (the surface error).
    focal_length : float
        The nominal F, m.
    """

    parameters: np.ndarray
    residual: np.ndarray
    rms: float
    focal_length: float

    @property
    def vertex_shift(self) -> np.ndarray:
        """The BFP's vertex from the nominal one, (3,), m."""
        return self.parameters[:3].copy()

    @property
    def tilt(self) -> np.ndarray:
        """Its axis's tilt (φ_x, φ_y) about the reflector's x and y axes, rad."""
        return self.parameters[3:5].copy()

    @property
    def focal_change(self) -> float:
        """ΔF, m."""
        return float(self.parameters[5])

    @property
    def focus_shift(self) -> np.ndarray:
        """The BFP's focus from the nominal ``(0, 0, F)``, (3,), m (to first order)."""
        u, v, w, phi_x, phi_y, dF = self.parameters
        F = self.focal_length
        return np.array([u + F * phi_y, v - F * phi_x, w + dF])


def fit_maps(nodes: np.ndarray, focal_length: float, weights: np.ndarray) -> FitMaps:
    """The linear maps of the best fit for surface nodes with their weights.

    Parameters
    ----------
    nodes : array_like, shape (N, 3)
        The surface nodes in the reflector's frame (on ``z = r²/(4F)``), m.
    focal_length : float
        F, m.
    weights : array_like, shape (N,)
        Each node's share of the aperture (area, times the illumination taper), ≥ 0 with
        a positive sum; any scale.

    Raises
    ------
    Rt70Error
        Wrong shapes, non-finite or negative weights, a zero total, or nodes that do not
        fix the six parameters (fewer than six weighted nodes, all on one ring, …).
    """
    nodes = check_nodes(nodes, focal_length)
    w = np.asarray(weights, dtype=float)
    if w.shape != (nodes.shape[0],):
        raise Rt70Error(f"weights have shape {w.shape}, expected ({nodes.shape[0]},)")
    if not np.all(np.isfinite(w)) or np.any(w < 0.0) or not w.sum() > 0.0:
        raise Rt70Error("weights must be finite, ≥ 0 and not all zero")
    w = w / w.sum()
    F = focal_length
    x, y = nodes[:, 0], nodes[:, 1]
    r2 = x**2 + y**2
    lever = 1.0 + r2 / (8.0 * F**2)  # 1 + z/(2F) on the nominal surface
    H = path_error_map(nodes, F)
    c = H[:, 2]  # cos²(θ/2): h of a unit Δz
    A = c[:, None] * np.column_stack(
        [-x / (2.0 * F), -y / (2.0 * F), np.ones_like(x), y * lever, -x * lever, -r2 / (4 * F**2)]
    )
    root = np.sqrt(w)
    U, s, Vt = scipy.linalg.svd(root[:, None] * A, full_matrices=False)
    if s[-1] <= RANK_RTOL * s[0]:
        raise Rt70Error(
            f"the {int(np.count_nonzero(w))} weighted nodes do not fix the best-fit "
            "paraboloid's six parameters (singular values "
            f"{s[-1]:.1e} of {s[0]:.1e}): give nodes on at least two rings"
        )
    P = (Vt.T / s) @ (U.T * root)  # (Aᵀ W A)⁻¹ Aᵀ W
    R = np.eye(nodes.shape[0]) - A @ P
    return FitMaps(A, P, R, w, H)


def best_fit(
    nodes: np.ndarray, displacements: np.ndarray, focal_length: float, weights: np.ndarray
) -> BestFit:
    """The best-fit paraboloid of the surface whose nodes moved by ``displacements``.

    Parameters
    ----------
    nodes : array_like, shape (N, 3)
        The surface nodes in the reflector's frame, m.
    displacements : array_like, shape (N, 3)
        Their displacements in the same frame, m.
    focal_length : float
        F, m.
    weights : array_like, shape (N,)
        Each node's share of the aperture (:func:`fit_maps`).
    """
    maps = fit_maps(nodes, focal_length, weights)
    delta = np.asarray(displacements, dtype=float)
    if delta.shape != maps.H.shape or not np.all(np.isfinite(delta)):
        raise Rt70Error(
            f"displacements must be a finite ({maps.H.shape[0]}, 3) array, got {delta.shape}"
        )
    h = np.sum(maps.H * delta, axis=1)
    residual = maps.R @ h
    rms = float(np.sqrt(maps.weights @ residual**2))
    return BestFit(maps.P @ h, residual, rms, float(focal_length))
