"""The book's spatial helpers on stacks: many vectors, angles or twists in one array.

The batched twins of :mod:`rt70.textbook.spatial`, for the structured algorithms
(:mod:`rt70.textbook.structured`) and the tree's index arrays
(:mod:`rt70.textbook.topology`), which work on every body and on K configurations at
once: the skew matrix ``<x>`` (formalism §0), Rodrigues' rotations, the 1–2–3 rotation
(1.23) with its Euler matrix (1.38), and the motion cross product (1.55). Spatial
vectors are ``[linear; angular]``; the leading axes of every argument are kept.
"""

from __future__ import annotations

import numpy as np

_E3 = np.eye(3)

_SKEW_SRC = np.array([0, 2, 1, 2, 0, 0, 1, 0, 0])
_SKEW_SIGN = np.array([0.0, -1.0, 1.0, 1.0, 0.0, -1.0, -1.0, 1.0, 0.0])


def skew_batch(x: np.ndarray) -> np.ndarray:
    """``<x>`` for an array of 3-vectors, shape (..., 3) → (..., 3, 3)."""
    return (x[..., _SKEW_SRC] * _SKEW_SIGN).reshape(x.shape + (3,))


def euler123_batch(phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``c = c1(β) c2(θ) c3(α)`` (1.23) and the transposed Euler matrix εᵀ (1.38), batched.

    The rows of ``εᵀ`` are ``(c2 c3)ᵀ e_x``, ``c3ᵀ e_y`` and ``e_z`` read as rows of
    ``c2 c3`` and ``c3``. ``phi`` is ``[β, θ, α]`` in its last axis, rad.
    """
    elementary = rotations_about_axes(_E3, phi)  # c1(β), c2(θ), c3(α)
    c23 = elementary[..., 1, :, :] @ elementary[..., 2, :, :]
    c = elementary[..., 0, :, :] @ c23
    eps_t = np.empty_like(c)
    eps_t[..., 0, :] = c23[..., 0, :]
    eps_t[..., 1, :] = elementary[..., 2, 1, :]
    eps_t[..., 2, :] = _E3[2]
    return c, eps_t


def rotations_about_axes(axes: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Rodrigues' formula for rotations about unit ``axes`` (n, 3) by ``angles`` (K, n)."""
    k = skew_batch(axes)
    k2 = k @ k
    s, c = np.sin(angles)[..., None, None], np.cos(angles)[..., None, None]
    return _E3 + s * k + (1.0 - c) * k2


def crm_batch(v: np.ndarray) -> np.ndarray:
    """Motion cross product matrices ``V×`` (linear-first), ``−Φ(V)ᵀ`` of (1.55); batched."""
    out = np.zeros(v.shape[:-1] + (6, 6))
    w = skew_batch(v[..., 3:])
    out[..., :3, :3] = w
    out[..., 3:, 3:] = w
    out[..., :3, 3:] = skew_batch(v[..., :3])
    return out
