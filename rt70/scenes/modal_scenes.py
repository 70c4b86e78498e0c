"""Flexible members from finite-element models, as modal bodies in scenes (docs/fe-models.md).

The slewing truss: a steel space frame (:func:`rt70.fe.truss.space_frame`, an FE model
assembled from bar elements) cantilevered from a hub that turns about the vertical on a
torsion spring — a boom, an arm, a feed-support leg. The frame is clamped to the hub at
its four nodes of the face x = 0 and enters the scene as a modal body with its lowest
fixed-interface modes (:func:`rt70.fe.modal_body.clamped_modes`), written to
``slewing_truss.npz`` beside the scene's URDF file (``rt70-modal/1``).
"""

from __future__ import annotations

import numpy as np

from rt70.fe.modal_body import clamped_modes
from rt70.fe.truss import space_frame
from rt70.scenes import urdf_writer as uw
from rt70.urdf.modal_file import ModalArrays

#: The truss: nodes a layer along x and y, node spacing and layer depth (m), and every
#: bar's axial stiffness (N) and mass per length (kg/m): steel tubes of ≈ 10 cm².
TRUSS = {"nx": 6, "ny": 2, "spacing": 1.0, "depth": 1.0, "EA": 2e8, "rho_A": 20.0}

#: Modes of the truss kept in its modal body file.
TRUSS_MODES = 8

#: The hub (kg, kg·m² about x, y, z), the slew spring (N·m/rad, N·m·s/rad) and the
#: truss's modal damping ratio.
HUB_MASS, HUB_MOMENTS = 500.0, (100.0, 100.0, 150.0)
SLEW_STIFFNESS, SLEW_DAMPING = 5e6, 2e4
TRUSS_DAMPING_RATIO = 0.005

#: The modal body file of the slewing truss, beside its URDF file.
TRUSS_FILE = "slewing_truss.npz"


def truss_arm(modes: int = TRUSS_MODES, interface: tuple[int, ...] = ()) -> ModalArrays:
    """The truss clamped at its face x = 0: nodes in the hub's frame, masses, modes.

    The hub's frame has its origin at the centre of the clamped face, x along the truss.

    Parameters
    ----------
    modes : int
        Fixed-interface modes kept (the lowest).
    interface : tuple of int
        FE node numbers kept as boundary nodes: their constraint modes come first
        (:func:`rt70.fe.modal_body.clamped_modes`).
    """
    fe = space_frame(**TRUSS)
    clamped = [int(n) for n, x in zip(fe.node_ids, fe.node_xyz, strict=True) if x[0] == 0.0]
    body = clamped_modes(fe, clamped, modes, interface)
    centre = np.array([0.0, 0.5 * (TRUSS["ny"] - 1) * TRUSS["spacing"], 0.5 * TRUSS["depth"]])
    return ModalArrays(
        body.nodes - centre,
        body.masses,
        body.shapes,
        body.stiffness,
        np.zeros_like(body.stiffness),
        f"{fe.name} (rt70.fe.truss), clamped at x = 0, {modes} fixed-interface modes"
        + (f", constraint modes of nodes {list(interface)} first" if interface else ""),
        body.edges,
    )


def slewing_truss_scene() -> str:
    """The URDF text of the slewing truss (module docstring)."""
    w = uw.Writer()
    uw.begin(w, "slewing_truss", "A space-frame truss as a modal body on a slewing hub")
    uw.gravity(w, (0.0, 0.0, -9.81))
    uw.massive_link(w, "hub", HUB_MASS, HUB_MOMENTS)
    uw.joint(w, "slew", "revolute", uw.ROOT_LINK, "hub")
    w.empty(
        "rt70:joint_spring",
        ("name", "slew_spring"),
        ("joint", "slew"),
        ("stiffness", uw.fmt(SLEW_STIFFNESS)),
        ("damping", uw.fmt(SLEW_DAMPING)),
    )
    w.empty(
        "rt70:modal_body",
        ("name", "truss"),
        ("link", "hub"),
        ("file", TRUSS_FILE),
        ("damping_ratio", uw.fmt(TRUSS_DAMPING_RATIO)),
    )
    return uw.end(w)
