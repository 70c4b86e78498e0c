"""The slewing truss as a modal body against its FE model with the hub: frequencies.

The scene ``slewing_truss`` (:mod:`rt70.scenes.modal_scenes`) with k of the truss's
fixed-interface modes, against the same structure assembled directly from the FE model:
the hub's rotation θ and every interior DOF of the truss, gravity off (the modes about
the unloaded state). A node at x moves by ``θ e_z × x + u``, so the direct model has
``T = ½ [θ̇; u̇]ᵀ M [θ̇; u̇]`` with the hub's and the nodes' inertia about the axis, the
coupling ``Σ m (e_z × x)ᵀ u̇`` and the lumped ``M_ii``, and ``K = diag(k_slew, K_ii)``.
Shares nothing with the modal body's code but the FE model: with every mode the two are
one structure in two sets of coordinates. With ``tip_mass`` a point mass hangs on the
truss's far top corner — in the scene a link on the node (``<rt70:interface>``), in the
direct model a mass added to the node's.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from rt70.fe.truss import space_frame
from rt70.linear import linearize as lin
from rt70.linear import modal
from rt70.model.scene import scene_from_text
from rt70.scenes import modal_scenes
from rt70.urdf.modal_file import write_modal_file


def interior_dofs() -> int:
    """The truss's DOFs that are not clamped to the hub (every mode there is)."""
    return 3 * int(np.sum(space_frame(**modal_scenes.TRUSS).node_xyz[:, 0] > 0.0))


def tip_node() -> int:
    """The truss's far top corner: its index among the FE model's nodes."""
    return int(np.argmax(space_frame(**modal_scenes.TRUSS).node_xyz.sum(axis=1)))


def direct_frequencies(count: int, tip_mass: float = 0.0) -> np.ndarray:
    """The ``count`` lowest frequencies of the direct FE model with the hub, Hz.

    ``tip_mass`` (kg) is added to the mass of the far top corner (:func:`tip_node`).
    """
    fe = space_frame(**modal_scenes.TRUSS)
    centre = [0.0, 0.5 * (modal_scenes.TRUSS["ny"] - 1) * modal_scenes.TRUSS["spacing"]]
    x = fe.node_xyz - [*centre, 0.5 * modal_scenes.TRUSS["depth"]]
    interior = np.flatnonzero(fe.node_xyz[:, 0] > 0.0)
    rows = np.concatenate([fe.dofs_of(int(fe.node_ids[n])) for n in interior])
    masses = fe.M.diagonal()[::3].copy()
    masses[tip_node()] += tip_mass
    lever = np.cross([0.0, 0.0, 1.0], x)  # e_z × x
    n = rows.size + 1
    M, K = np.zeros((n, n)), np.zeros((n, n))
    M[0, 0] = modal_scenes.HUB_MOMENTS[2] + np.sum(masses * np.sum(lever**2, axis=1))
    M[0, 1:] = M[1:, 0] = (masses[interior, None] * lever[interior]).ravel()
    M[1:, 1:] = np.diag(np.repeat(masses[interior], 3))  # lumped: fe.M with the tip mass
    K[0, 0] = modal_scenes.SLEW_STIFFNESS
    K[1:, 1:] = fe.K.toarray()[np.ix_(rows, rows)]
    omega2 = scipy.linalg.eigh(K, M, eigvals_only=True)[:count]
    return np.sqrt(omega2) / (2.0 * np.pi)


def modal_frequencies(
    modes: int, directory, count: int, tip_mass: float = 0.0, corner_modes: bool = False
) -> np.ndarray:
    """The ``count`` lowest frequencies of the scene with ``modes`` modes, gravity off, Hz.

    Parameters
    ----------
    modes : int
        The truss's modes kept (1 to :func:`interior_dofs`).
    directory : pathlib.Path
        Where the modal body file is written.
    count : int
        Frequencies returned (at most ``modes + 1``).
    tip_mass : float
        A point mass (kg) on a link attached to the far top corner; 0: none.
    corner_modes : bool
        Make the corner a boundary node of the reduction: its three constraint modes
        first, then ``modes`` fixed-interface modes with it held.
    """
    corner = (tip_node() + 1,) if corner_modes else ()  # the FE model numbers nodes from 1
    arm = modal_scenes.truss_arm(modes, corner)
    path = write_modal_file(directory / f"truss_{modes}.npz", arm)
    text = (
        modal_scenes.slewing_truss_scene()
        .replace(modal_scenes.TRUSS_FILE, str(path))
        .replace('<rt70:gravity xyz="0 0 -9.81"/>', '<rt70:gravity xyz="0 0 0"/>')
    )
    if tip_mass > 0.0:
        node = int(np.argmax(arm.nodes.sum(axis=1)))  # the far top corner, in the hub frame
        text = text.replace(
            "/>\n</robot>",
            f'><rt70:interface link="corner" node="{node}"/></rt70:modal_body>\n'
            f'<link name="weight"><inertial><mass value="{tip_mass!r}"/>'
            '<inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial></link>\n'
            '<joint name="weight_mount" type="fixed"><parent link="corner"/>'
            '<child link="weight"/></joint>\n</robot>',
        )
    scene = scene_from_text(text, f"slewing_truss_{modes}")
    lm = lin.linearize(scene, np.zeros(scene.textbook.nv))
    return modal.modes(lm.M, lm.K).freq_hz[:count]
