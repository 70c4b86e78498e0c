"""A chapter-2 torsional URDF scene read back into a linear model (book chapter 2).

One job: :func:`from_scene` turns a scene of coaxial bodies turning about z, joined by
``<rt70:bushing>`` torsion springs, into the :class:`~rt70.linear.topology.LinearModel`
``m q̈ + Γᵀ D Γ q̇ + Γᵀ C Γ q = Q`` (2.9) that :func:`rt70.linear.topology.from_graph`
builds from the book's tables (:mod:`rt70.scenes.rt70_chapter2`), so that the tables
and the files can be compared (SI units).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from rt70.errors import TopologyError
from rt70.linear.topology import Edge, LinearModel, LinearModelError, from_graph

if TYPE_CHECKING:
    from rt70.model.scene import Scene
    from rt70.urdf.description import RobotDescription


def _rpy_z_only(rpy: np.ndarray) -> bool:
    return bool(np.allclose(np.asarray(rpy, dtype=float)[:2], 0.0, atol=1e-12))


def from_scene(scene: Scene) -> LinearModel:
    """Read a chapter-2 URDF scene back into a :class:`LinearModel` (SI units).

    The scene must be coaxial bodies rotating about z: every joint revolute (or
    continuous) from the ground link to a body, about the z axis through the origin;
    every ``<rt70:bushing>`` a torsion spring about z (only the rz stiffness and damping
    non-zero, frames rotated about z at most) between two bodies or a body and the
    ground. Body k is the child of the k-th joint; its inertia is the moment about the
    axis, ``izz + m (x_c² + y_c²)``; each bushing is one link ``(i, j)`` with i its frame-1
    link (0 for the ground) and j its frame-2 link.

    Parameters
    ----------
    scene : rt70.model.scene.Scene
        A loaded scene (``rt70.model.scene.load_scene("rt70_elevation")``); only its
        ``description`` is used.

    Returns
    -------
    LinearModel
        Coordinates named after the body links; N·m·s², N·m/rad, N·m·s/rad.

    Raises
    ------
    LinearModelError
        If the scene is not such a torsional model.
    """
    desc = scene.description
    nodes, inertias = _torsion_bodies(desc)
    number = {name: k for k, name in enumerate(nodes, start=1)}
    number[desc.root] = 0
    edges, stiffness, damping = _torsion_links(desc, number)
    try:
        return from_graph(inertias, edges, stiffness, damping, names=nodes)
    except TopologyError as exc:
        raise LinearModelError(f"{desc.source}: {exc}") from None


def _torsion_bodies(desc: RobotDescription) -> tuple[list[str], list[float]]:
    """The bodies (children of the joints) and their moments about the common z axis.

    Each joint must be revolute (or continuous) from the ground about z through the
    origin; the moment is ``izz + m (x_c² + y_c²)``.
    """
    where = desc.source
    nodes: list[str] = []
    inertias: list[float] = []
    for joint in desc.joints:
        if joint.type not in ("revolute", "continuous") or joint.parent != desc.root:
            raise LinearModelError(
                f"{where}: joint '{joint.name}' ({joint.type}, parent '{joint.parent}') is not "
                f"a revolute joint from '{desc.root}': not a chapter-2 torsional scene"
            )
        axis = np.asarray(joint.axis, dtype=float)
        if (
            not _rpy_z_only(joint.rpy)
            or not np.allclose(axis, [0.0, 0.0, 1.0], atol=1e-12)
            or not np.allclose(np.asarray(joint.xyz)[:2], 0.0, atol=1e-12)
        ):
            raise LinearModelError(
                f"{where}: joint '{joint.name}' does not rotate about the common z axis"
            )
        link = desc.links[joint.child]
        if link.inertial is None:
            raise LinearModelError(f"{where}: body '{link.name}' has no inertia")
        inertial = link.inertial
        com = np.asarray(inertial.com, dtype=float)
        nodes.append(link.name)
        inertias.append(
            float(inertial.inertia[2, 2]) + inertial.mass * float(com[0] ** 2 + com[1] ** 2)
        )
    if not nodes:
        raise LinearModelError(f"{where}: no bodies")
    return nodes, inertias


def _torsion_links(
    desc: RobotDescription, number: dict[str, int]
) -> tuple[list[Edge], list[float], list[float]]:
    """``(edges, C_s, D_s)`` of the bushings: torsion springs about z between numbered links.

    ``number`` gives each body's node (1-based) and the ground's 0.
    """
    where = desc.source
    edges: list[Edge] = []
    stiffness: list[float] = []
    damping: list[float] = []
    for b in desc.bushings:
        c = np.asarray(b.stiffness, dtype=float).copy()
        d = np.asarray(b.damping, dtype=float).copy()
        rz = (c[5, 5], d[5, 5])
        c[5, 5] = d[5, 5] = 0.0
        if np.any(c != 0) or np.any(d != 0):
            raise LinearModelError(
                f"{where}: bushing '{b.name}' is not a torsion spring about z "
                "(only the rz stiffness and damping may be non-zero)"
            )
        if not (_rpy_z_only(b.frame1.rpy) and _rpy_z_only(b.frame2.rpy)):
            raise LinearModelError(f"{where}: bushing '{b.name}' frames are tilted off the z axis")
        for frame in (b.frame1, b.frame2):
            if frame.link not in number:
                raise LinearModelError(
                    f"{where}: bushing '{b.name}' is attached to '{frame.link}', "
                    "which is neither a body nor the ground"
                )
        edges.append((number[b.frame1.link], number[b.frame2.link]))
        stiffness.append(float(rz[0]))
        damping.append(float(rz[1]))
    return edges, stiffness, damping
