"""The static sag of every body under gravity: its deflection from the rigid pose.

One job: compare each body's frame at a static equilibrium
(:func:`rt70.linear.linearize.equilibrium`) with its pose when every elastic coordinate
is zero — the book's deflections under the structure's own weight (chapter 2), in
millimetres and arc seconds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rt70.linear.linearize import coordinate_indices
from rt70.model.scene import Scene
from rt70.textbook import dynamics
from rt70.units import ARCSEC_PER_RAD


@dataclass(frozen=True)
class Sag:
    """Static deflection of one body under gravity, against its rigid (q_elastic = 0) pose."""

    body: str
    displacement_mm: np.ndarray  # of the body frame origin, ground axes
    rotation_arcsec: float  # angle of the relative rotation


def sag(scene: Scene, q_eq: np.ndarray, held: dict[str, float]) -> list[Sag]:
    """Deflection of every body at the equilibrium ``q_eq`` relative to the rigid pose.

    The rigid pose has the held coordinates at their values and every other coordinate
    at 0; displacements are in mm, rotations in arc seconds.

    Parameters
    ----------
    scene : Scene
        The scene (both sides built).
    q_eq : numpy.ndarray, shape (nv,)
        The equilibrium under gravity (:func:`rt70.linear.linearize.equilibrium`), m or rad.
    held : dict of str to float
        The held coordinates and their values, m or rad (as given to
        :func:`rt70.linear.linearize.equilibrium`).
    """
    model, data = scene.textbook, scene.textbook_data
    q_rigid = np.zeros(model.nv)
    q_rigid[coordinate_indices(scene, list(held))] = list(held.values())
    dynamics.mass_matrix(model, data, q_rigid)
    R0, p0 = data.R.copy(), data.p.copy()
    dynamics.mass_matrix(model, data, q_eq)
    out = []
    for j, name in enumerate(model.body_names):
        rel = R0[j].T @ data.R[j]
        angle = float(np.arccos(np.clip((np.trace(rel) - 1.0) / 2.0, -1.0, 1.0)))
        out.append(Sag(name, (data.p[j] - p0[j]) * 1e3, angle * ARCSEC_PER_RAD))
    return out
