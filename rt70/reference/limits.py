"""What Pinocchio's URDF parser and this machine can take, checked before the parser runs.

Pinocchio's parser recurses once per level of the kinematic tree, and its model and data
hold ``nv³``-sized tensors: :func:`check_reference` refuses a description deeper than
:data:`rt70.guards.resources.PARSER_MAX_DEPTH` or larger than the memory share
(:func:`rt70.guards.resources.check_memory`) before :mod:`rt70.reference.model` builds it.
"""

from __future__ import annotations

import rt70.guards.resources as resources
from rt70.errors import ResourceError
from rt70.reference.modal_nodes import NODE_DOFS, node_count
from rt70.urdf.description import RobotDescription

_DOFS = {"revolute": 1, "continuous": 1, "prismatic": 1, "planar": 3, "floating": 6}


def pinocchio_size(desc: RobotDescription) -> tuple[int, int]:
    """``(nv, njoints)`` of the model Pinocchio's URDF parser will build from ``desc``.

    Every non-fixed joint is a Pinocchio joint (mimic joints included), and so is every
    node with mass of a modal body (:mod:`rt70.reference.modal_nodes`); ``njoints``
    counts the universe.
    """
    moving = [j for j in desc.joints if j.type != "fixed"]
    nodes = sum(node_count(body) for body in desc.modal_bodies)
    nv = sum(_DOFS.get(j.type, 1) for j in moving) + NODE_DOFS * nodes
    return nv, len(moving) + nodes + 1


def tree_depth(desc: RobotDescription) -> int:
    """Number of links on the longest path from the root (the root counts 1)."""
    parent = {j.child: j.parent for j in desc.joints}
    depth = {desc.root: 1}
    for link in desc.links:
        path = []
        while link not in depth:  # the reader guarantees a tree: this ends at the root
            path.append(link)
            link = parent[link]
        d = depth[link]
        for up in reversed(path):
            d += 1
            depth[up] = d
    return max(depth.values())


def check_reference(desc: RobotDescription) -> None:
    """Refuse a model Pinocchio cannot parse (tree depth) or this machine cannot hold."""
    depth = tree_depth(desc)
    if depth > resources.PARSER_MAX_DEPTH:
        raise ResourceError(
            f"{desc.source}: kinematic tree {depth} links deep; Pinocchio's URDF parser "
            f"recurses once per level and is only run on trees up to {resources.PARSER_MAX_DEPTH}"
        )
    nv, njoints = pinocchio_size(desc)
    resources.check_memory(
        resources.reference_peak_bytes(nv, njoints),
        f"Pinocchio's model and data for {nv} coordinates (nv³-sized tensors)",
        desc.source,
    )
