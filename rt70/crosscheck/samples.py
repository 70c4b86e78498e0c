"""Where the cross-check compares: random states and, seeded from each, a load, a drive, a wind.

:func:`random_state` draws the states (q, q̇) of :func:`rt70.crosscheck.validate.cross_check`;
at each state the probes compared are drawn from a generator seeded with the bits of q
(each in its own order of the bits): reproducible, new at every state, and apart from
the stream the states come from — a random load (:func:`state_wrench`, row
``load_force``), a random gear-sector drive (:func:`state_drive`, row ``drives``) and a
random steady wind (:func:`state_wind`, row :data:`WIND`). :func:`compared_points` lists
the positions of row ``points``.
"""

from __future__ import annotations

import numpy as np

from rt70.model.outputs import Output, optical_point_outputs, position_output
from rt70.model.scene import Scene
from rt70.physics.aerodynamics import WindCondition
from rt70.physics.loads import Wrench
from rt70.urdf.description import DRIVE_PARAMETERS, Drive, DriveSector

#: The row of the wind's generalised force, compared for a scene with ``<rt70:wind>``
#: elements only (after :data:`rt70.crosscheck.validate.QUANTITIES`).
WIND = "wind"


def random_state(nv: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A random state: ``q`` uniform in ±0.5 (rad or m), ``q̇`` uniform in ±1."""
    return rng.uniform(-0.5, 0.5, nv), rng.uniform(-1.0, 1.0, nv)


def random_wrench(scene: Scene, rng: np.random.Generator) -> Wrench:
    """A random load for the cross-check (:class:`rt70.physics.loads.Wrench`).

    On a moving link drawn uniformly, at a point within ±1 m of its origin, with force
    and torque uniform in ±1 N and ±1 N·m per ground axis.
    """
    links = [name for name, (body, _, _) in scene.textbook.link_frames.items() if body >= 0]
    link = links[int(rng.integers(len(links)))]
    xyz, force, torque = rng.uniform(-1.0, 1.0, (3, 3))
    return Wrench(link, xyz, force, torque)


def state_wrench(scene: Scene, q: np.ndarray) -> Wrench:
    """The random load compared at the state q (row ``load_force``).

    :func:`random_wrench` drawn from a generator seeded with the bits of q: reproducible,
    new at every sampled state, and apart from the stream the states are drawn from.
    """
    bits = np.frombuffer(np.ascontiguousarray(q, dtype=float).tobytes(), dtype=np.uint32)
    return random_wrench(scene, np.random.default_rng(bits))


def state_drive(scene: Scene, q: np.ndarray) -> Drive:
    """A random gear-sector drive compared at the state q (row ``drives``).

    Seeded from q as :func:`state_wrench`: the sector on a moving link drawn uniformly,
    its stator another link with a frame (the ground too), mesh point within ±1 m,
    random unit tangent and an axis normal to it, radius in [0.5, 2] m. Only its
    geometry is used (the motor's parameters are ones), so every scene has a drive to
    compare.
    """
    bits = np.frombuffer(np.ascontiguousarray(q, dtype=float).tobytes(), dtype=np.uint32)
    rng = np.random.default_rng(bits[::-1].copy())
    frames = scene.textbook.link_frames
    moving = [name for name, (body, _, _) in frames.items() if body >= 0]
    link = moving[int(rng.integers(len(moving)))]
    others = [name for name, (body, _, _) in frames.items() if body != frames[link][0]]
    stator = others[int(rng.integers(len(others)))] if others else scene.description.root
    xyz, direction, axis = rng.uniform(-1.0, 1.0, (3, 3))
    direction /= np.linalg.norm(direction)
    axis -= (axis @ direction) * direction
    axis /= np.linalg.norm(axis)
    sector = DriveSector(link, xyz, direction, axis, float(rng.uniform(0.5, 2.0)), stator)
    return Drive("probe", "", *np.ones(len(DRIVE_PARAMETERS)), sector=sector)


def state_wind(q: np.ndarray) -> WindCondition:
    """The steady wind compared at the state q (row ``wind``).

    Seeded from q as :func:`state_wrench` (the bits in another order): speed uniform in
    [1, 40] m/s, direction uniform in [0°, 360°), the scene's air density.
    """
    bits = np.frombuffer(np.ascontiguousarray(q, dtype=float).tobytes(), dtype=np.uint32)
    rng = np.random.default_rng(np.roll(bits, 1))
    return WindCondition(float(rng.uniform(1.0, 40.0)), float(rng.uniform(0.0, 360.0)))


def compared_points(scene: Scene) -> list[Output]:
    """The positions compared in row ``points``.

    The scene's optical points (its outputs, :func:`rt70.model.outputs.optical_point_outputs`)
    and the origin of every link with a frame on both sides (``link:<name>``), so that
    every scene has points to compare.
    """
    links = scene.textbook.link_frames
    origins = [position_output(f"link:{link}", link, np.zeros(3)) for link in links]
    return optical_point_outputs(scene) + origins
