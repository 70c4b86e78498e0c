"""The pairs' coordinates from the independent ones: ``q_full = G q_p + H η + q_offset``.

One job: the constant map from the scene's coordinates ``q = [q_p; η]`` to the pairs'
coordinates ``q_full`` — URDF ``<mimic>`` joints follow their source (chapter 3's
holonomic constraints, built by :func:`rt70.physics.constraints.mimic_map`), and the
joints of a modal body's interface chains follow its modal coordinates
(:mod:`rt70.urdf.modal_interfaces`). :class:`rt70.textbook.model.Model` keeps G,
``q_offset`` and H (``node_map``) and applies them in ``expand`` and ``reduce``.
"""

from __future__ import annotations

import numpy as np

from rt70.physics.constraints import mimic_map
from rt70.urdf.description import RobotDescription


def pair_coordinate_map(
    full_names: list[str], desc: RobotDescription
) -> tuple[np.ndarray | None, np.ndarray | None, list[str], np.ndarray | None]:
    """G, q_offset, the independent pair coordinates and H of ``desc`` (module docstring).

    Parameters
    ----------
    full_names : list of str
        Every pair coordinate, in the pairs' order.
    desc : RobotDescription
        The scene (its mimic joints and modal bodies).
    """
    G, q_offset, independent = mimic_constraints(full_names, desc)
    return node_constraints(full_names, desc, G, q_offset, independent)


def mimic_constraints(
    full_names: list[str], desc: RobotDescription
) -> tuple[np.ndarray | None, np.ndarray | None, list[str]]:
    """``q_full = G q + q_offset`` from the URDF ``<mimic>`` elements (chapter 3).

    Built by :func:`rt70.physics.constraints.mimic_map`, where every eliminated constraint is
    defined. Returns G, q_offset (None, None without mimics) and the independent
    coordinates.

    Parameters
    ----------
    full_names : list of str
        Every pair coordinate, in the pairs' order.
    desc : RobotDescription
        The scene (its joints' ``<mimic>`` elements).
    """
    mimics = {
        j.name: (j.mimic.joint, j.mimic.multiplier, j.mimic.offset)
        for j in desc.joints
        if j.mimic is not None
    }
    if not mimics:
        return None, None, list(full_names)
    constraint = mimic_map(full_names, mimics)
    return constraint.T, constraint.offset, list(constraint.names)


def node_constraints(
    full_names: list[str],
    desc: RobotDescription,
    G: np.ndarray | None,
    q_offset: np.ndarray | None,
    independent: list[str],
) -> tuple[np.ndarray | None, np.ndarray | None, list[str], np.ndarray | None]:
    """Take the interface chains' coordinates out of q: ``q_full = G q_p + H η + q_offset``.

    A chain joint of a modal body's interface (:mod:`rt70.urdf.modal_interfaces`) has
    the coordinate ``row · η``: its row of G is zero and its row of H (``node_map``,
    n_full × n_modal) is ``row`` in the body's modal columns. Returns G, q_offset, the
    independent pair coordinates and H (None without interfaces).

    Parameters
    ----------
    full_names : list of str
        Every pair coordinate, in the pairs' order.
    desc : RobotDescription
        The scene (its modal bodies' interfaces).
    G, q_offset : numpy.ndarray or None
        The mimic map (:func:`mimic_constraints`).
    independent : list of str
        The pair coordinates it leaves independent.
    """
    following = desc.node_joints
    if not following:
        return G, q_offset, independent, None
    n_full = len(full_names)
    if G is None:
        G, q_offset = np.eye(n_full), np.zeros(n_full)
    keep = [c for c, name in enumerate(independent) if name not in following]
    G = G[:, keep]
    starts = np.cumsum([0] + [b.modes for b in desc.modal_bodies])
    H = np.zeros((n_full, int(starts[-1])))
    for row, name in enumerate(full_names):
        if name in following:
            body, coefficients = following[name]
            H[row, starts[body] : starts[body + 1]] = coefficients
    return G, q_offset, [independent[c] for c in keep], H
