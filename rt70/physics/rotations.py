"""Rotation matrices shared below both sides of the cross-check.

The URDF reader needs the rotation of an ``<origin rpy>`` (and its inverse, to write
frames back); the textbook side needs the same elementary rotations (1.23) for its
Euler angles. Both import them from here, so ``rt70.urdf`` depends on nothing of
``rt70.textbook`` and the independence of the two sides stays visible in the import
graph (docs/architecture.md). Plain numpy, no state.
"""

from __future__ import annotations

import numpy as np


def c1(beta: float) -> np.ndarray:
    """Elementary rotation about x, (1.23)."""
    c, s = np.cos(beta), np.sin(beta)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def c2(theta: float) -> np.ndarray:
    """Elementary rotation about y, (1.23)."""
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def c3(alpha: float) -> np.ndarray:
    """Elementary rotation about z, (1.23)."""
    c, s = np.cos(alpha), np.sin(alpha)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rpy_matrix(rpy: np.ndarray) -> np.ndarray:
    """Rotation of a URDF ``rpy`` origin: ``Rz(yaw) Ry(pitch) Rx(roll)``."""
    return c3(rpy[2]) @ c2(rpy[1]) @ c1(rpy[0])


def rpy_of_matrix(rot: np.ndarray) -> np.ndarray:
    """URDF ``rpy`` of a rotation matrix (the inverse of :func:`rpy_matrix`)."""
    pitch = np.arctan2(-rot[2, 0], np.hypot(rot[0, 0], rot[1, 0]))
    roll = np.arctan2(rot[2, 1], rot[2, 2])
    yaw = np.arctan2(rot[1, 0], rot[0, 0])
    return np.array([roll, pitch, yaw])
