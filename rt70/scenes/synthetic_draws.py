"""Random draws of the synthetic scenes: rotations, axes, inertias and joint geometry.

:mod:`rt70.scenes.synthetic` builds its scenes from these draws on one
``numpy.random.Generator``, in a fixed order, so that a seed gives the same text byte for
byte. :class:`Body` is one generated link and the joint that carries it, as drawn;
:mod:`rt70.scenes.synthetic_xml` writes it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from rt70.physics.rotations import rpy_matrix

#: Joint types with one coordinate.
ONE_DOF_JOINT_TYPES = ("revolute", "prismatic", "continuous")


class Body:
    """One generated link and the joint that carries it.

    Attributes
    ----------
    name, joint, jtype, parent : str
        The link's name, its joint's name and type, and the parent link.
    xyz, rpy : ndarray, shape (3,)
        The joint's origin in the parent link: m and rad (roll, pitch, yaw).
    axis : ndarray, shape (3,)
        The joint axis in the joint frame (unit vector).
    inertial : tuple or None
        ``(mass kg, centre of mass xyz m, its frame's rpy rad, inertia tensor kg·m² in
        that frame)``; None for a massless link.
    """

    def __init__(self, name: str, joint: str, jtype: str, parent: str) -> None:
        self.name = name
        self.joint = joint
        self.jtype = jtype
        self.parent = parent
        self.xyz = np.zeros(3)
        self.rpy = np.zeros(3)
        self.axis = np.array([0.0, 0.0, 1.0])
        self.inertial: tuple[float, np.ndarray, np.ndarray, np.ndarray] | None = None

    def axis_in_link_frame(self) -> np.ndarray:
        """The joint axis in the parent link's frame."""
        return rpy_matrix(self.rpy) @ self.axis


def pose(xyz: Sequence[float], rpy: Sequence[float]) -> np.ndarray:
    """Homogeneous 4 × 4 transform of a URDF origin (xyz in m, rpy in rad)."""
    out = np.eye(4)
    out[:3, :3] = rpy_matrix(rpy)
    out[:3, 3] = xyz
    return out


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    """A rotation matrix uniform on SO(3) (normalised Gaussian quaternion)."""
    w, x, y, z = rng.normal(size=4)
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def random_rpy(rng: np.random.Generator) -> np.ndarray:
    """Roll, pitch, yaw each uniform in ±π, rad."""
    return rng.uniform(-math.pi, math.pi, 3)


def random_axis(rng: np.random.Generator, aligned: float = 0.3) -> np.ndarray:
    """A unit axis: with probability ``aligned`` exactly ±x, ±y or ±z, else any direction."""
    if rng.random() < aligned:
        axis = np.zeros(3)
        axis[rng.integers(3)] = rng.choice((-1.0, 1.0))
        return axis
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def log_uniform(rng: np.random.Generator, low: float, high: float, size=None):
    """Log-uniform draws in ``[low, high]``.

    Parameters
    ----------
    rng : numpy.random.Generator
        The scene's generator.
    low, high : float
        Bounds (> 0), in the unit of the quantity drawn.
    size : int or tuple of int, optional
        Shape of the draw; None: one float.

    Returns
    -------
    float or ndarray
        ``exp(uniform(log low, log high))``.
    """
    return np.exp(rng.uniform(math.log(low), math.log(high), size))


def random_inertial(rng: np.random.Generator) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    """Mass in [0.1, 10] kg (log-uniform), COM and its frame random, valid inertia tensor.

    Principal moments ``b + c, a + c, a + b`` with ``a, b, c > 0`` satisfy the triangle
    inequality strictly; a random rotation gives the tensor off-diagonal terms.
    """
    mass = float(log_uniform(rng, 0.1, 10.0))
    a, b, c = mass * rng.uniform(0.005, 0.2, 3)
    rot = random_rotation(rng)
    tensor = rot @ np.diag([b + c, a + c, a + b]) @ rot.T
    tensor = 0.5 * (tensor + tensor.T)
    return mass, rng.uniform(-0.3, 0.3, 3), random_rpy(rng), tensor


def random_joint_geometry(rng: np.random.Generator, body: Body, reach: float = 0.6) -> None:
    """Random origin (xyz, rpy) and, for the joint types that use one, a random axis.

    Parameters
    ----------
    rng : numpy.random.Generator
        The scene's generator.
    body : Body
        The body whose joint is drawn (its ``xyz``, ``rpy`` and ``axis`` are set).
    reach : float, optional
        The origin's coordinates are uniform in ±``reach``, m.
    """
    body.xyz = rng.uniform(-reach, reach, 3)
    body.rpy = random_rpy(rng)
    if body.jtype in ONE_DOF_JOINT_TYPES:
        body.axis = random_axis(rng)
    else:
        body.axis = np.array([0.0, 0.0, 1.0])  # planar: Pinocchio's plane; unused otherwise
