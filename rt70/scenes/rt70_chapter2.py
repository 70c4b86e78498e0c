"""The book's RT-70 chapter-2 torsional models, typed from the tables as linear models.

:func:`azimuth_model` (§2.3, 7 masses) and :func:`elevation_model` (§2.4, 6 masses)
build :class:`rt70.linear.topology.LinearModel` objects from the tables in
:mod:`rt70.scenes.rt70_data` (technical units: inertia kgf·s²·m, stiffness kgf·m/rad;
the frequencies do not depend on the unit). :func:`rt70.linear.torsion_scene.from_scene`
reads the same models back from their URDF scenes (SI), so that the tables and the
files can be compared.
"""

from __future__ import annotations

import numpy as np

from rt70.linear.topology import LinearModel, LinearModelError, edges_from_topology, from_graph
from rt70.scenes import rt70_data

#: Elevations (degrees, as strings) of the azimuth model's two table columns.
AZIMUTH_ELEVATIONS = ("0", "90")


def azimuth_model(elevation: str | int = "0") -> LinearModel:
    """The 7-mass azimuth model of the RT-70 (§2.3, Tables 2.1–2.2, Γα (2.14)).

    Parameters
    ----------
    elevation : {"0", "90"}
        Which columns of the tables to use: the antenna at elevation 0° or 90°.

    Returns
    -------
    LinearModel
        Technical units: inertia kgf·s²·m, stiffness kgf·m/rad; no damping (see
        :func:`rt70.linear.topology.proportional_damping`). No link to the ground: one
        zero frequency.

    Raises
    ------
    LinearModelError
        If ``elevation`` is not 0 or 90.
    """
    key = str(elevation)
    if key not in AZIMUTH_ELEVATIONS:
        raise LinearModelError(f"azimuth model elevation must be '0' or '90', got {elevation!r}")
    d = rt70_data
    return from_graph(
        [node[f"I_el{key}"] for node in d.AZIMUTH_NODES],
        edges_from_topology(np.array(d.GAMMA_ALPHA)),
        [link[f"C_el{key}"] for link in d.AZIMUTH_LINKS],
        names=[node["name"] for node in d.AZIMUTH_NODES],
    )


def elevation_model() -> LinearModel:
    """The 6-mass elevation model of the RT-70 (§2.4, Tables 2.3–2.4, Γβ (2.26)).

    Returns
    -------
    LinearModel
        Technical units: inertia kgf·s²·m, stiffness kgf·m/rad; no damping. Its
        spectrum is the printed one, 0, 3.2700, 4.2424, 6.3041, 7.2579, 19.6420 Hz.
    """
    d = rt70_data
    return from_graph(
        [node["I"] for node in d.ELEVATION_NODES],
        edges_from_topology(np.array(d.GAMMA_BETA)),
        [link["C"] for link in d.ELEVATION_LINKS],
        names=[node["name"] for node in d.ELEVATION_NODES],
    )
