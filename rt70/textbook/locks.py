"""Rows of sudden constraints (locks) on the textbook side: a brake, a stow pin.

The constraint ``B_c q̇ = 0`` that engages in an impact (companion source 004 (15),
:mod:`rt70.physics.impact`), from the book's own matrices:

- a **brake** holds a 1-DOF joint: its row is the joint's row of the mimic map
  ``q̇_full = G q̇`` (``Model.G``; the unit row of the coordinate without mimic joints);
- a **stow pin** fixes a point of a link to the ground: its three rows are the point's
  velocity Jacobian ``J_v`` in ground axes (4.63), :func:`rt70.textbook.points.point_jacobian`.

The reference side computes the same rows from Pinocchio (:mod:`rt70.reference.locks`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from rt70.errors import Rt70Error
from rt70.textbook.data import Data
from rt70.textbook.model import Model
from rt70.textbook.points import point_jacobian


def brake_row(model: Model, joint: str) -> np.ndarray:
    """Row (nv,) of a brake on the 1-DOF joint ``joint``: ``q̇_joint = row · q̇``.

    Raises
    ------
    Rt70Error
        If the joint is not one of the model's 1-DOF coordinates (a mimic joint counts).
    """
    names = model.full_coordinate_names or model.coordinate_names
    if joint not in names:
        raise Rt70Error(f"{model.name}: no 1-DOF joint '{joint}' to brake")
    unit = np.zeros(model.n_full)
    unit[names.index(joint)] = 1.0
    return model.reduce(unit)  # the joint's row of G (no modal coordinate in it)


def pin_rows(model: Model, data: Data, q: np.ndarray, link: str, xyz) -> np.ndarray:
    """Rows (3, nv) of a stow pin fixing the point ``xyz`` of ``link``: ``v_p = J_v q̇``.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    link : str
        Name of a URDF link of the scene.
    xyz : array_like, shape (3,)
        The point in the link's frame, m.
    """
    return point_jacobian(model, data, q, link, xyz)[0]


def book_rows(
    model: Model,
    data: Data,
    q: np.ndarray,
    brakes: Sequence[str] = (),
    pins: Sequence[tuple[str, np.ndarray]] = (),
) -> np.ndarray:
    """The locks' rows ``B_c`` in the book's coordinates, (m, nv): brakes, then pins.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    brakes : sequence of str
        The braked joints (1-DOF), one row each.
    pins : sequence of (str, array_like)
        The stow pins: a link and the point fixed to the ground in the link's frame (m),
        three rows each.
    """
    rows = [brake_row(model, joint)[None] for joint in brakes]
    rows += [pin_rows(model, data, q, link, xyz) for link, xyz in pins]
    return np.vstack(rows) if rows else np.zeros((0, model.nv))
