"""``<rt70:modal_body>``: a flexible body on a link, read from its modal body file.

One job: read the element (docs/urdf-extensions.md) into a :class:`ModalBody` — the
link it deforms with, the file (:mod:`rt70.urdf.modal_file`, found beside the URDF file
when relative), how many of its modes to keep and their damping — refusing what is
wrong with an :class:`~rt70.errors.ExtensionError` naming the file and the element.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import numpy as np
import scipy.linalg

from rt70.errors import ExtensionError
from rt70.urdf.description import ModalBody, RobotDescription
from rt70.urdf.elements import ElementReader
from rt70.urdf.modal_file import modal_mass, read_modal_file
from rt70.urdf.modal_interfaces import body_file, read_interfaces


def read_modal_body(reader: ElementReader, elem: ET.Element, desc: RobotDescription) -> ModalBody:
    """The :class:`ModalBody` of one ``<rt70:modal_body>`` element.

    ``modes="k"`` keeps the file's first k modes (default all of them);
    ``damping_ratio="ζ"`` gives every mode the ratio ζ of critical damping,
    ``D = M V diag(2 ζ ω) Vᵀ M`` with ``K V = M V diag(ω²)``, ``Vᵀ M V = 1`` (instead of
    the file's damping, which must then be absent or zero).

    Parameters
    ----------
    reader : ElementReader
        The reader of the file (its name, the attribute readers).
    elem : xml.etree.ElementTree.Element
        The ``<rt70:modal_body>`` element.
    desc : RobotDescription
        The links and joints already read.

    Raises
    ------
    ExtensionError
        For an unknown link, a file that is missing or wrong, ``modes`` that is not a
        whole number between 1 and the file's count, a negative ``damping_ratio`` or one
        given beside the file's damping.
    """
    name = reader.name_of(elem)
    where = f"{reader.source}: <rt70:modal_body name='{name}'>"
    link = reader.link_ref(elem, "link", desc, where)
    path = body_file(reader, elem)
    body = read_modal_file(path, where)
    k = body.modes
    raw = elem.get("modes", str(k))
    if not re.fullmatch(r"\s*[0-9]+\s*", raw) or not 1 <= int(raw) <= k:
        raise ExtensionError(f'{where}: modes="{raw}" is not a whole number from 1 to {k}')
    keep = int(raw)
    stiffness = body.stiffness[:keep, :keep]
    damping = body.damping[:keep, :keep]
    shapes = body.shapes[:, :, :keep]
    if "damping_ratio" in elem.attrib:
        zeta = reader.number(elem, "damping_ratio")
        if not zeta >= 0.0:
            raise ExtensionError(f'{where}: damping_ratio="{elem.get("damping_ratio")}" is < 0')
        if np.any(body.damping != 0.0):
            raise ExtensionError(
                f"{where}: the file has a damping matrix; give damping_ratio or the file's "
                "damping, not both"
            )
        damping = proportional_damping(modal_mass(body.masses, shapes), stiffness, zeta)
    interfaces = read_interfaces(reader, elem, body, keep, where)
    return ModalBody(
        name, link, str(path), body.nodes, body.masses, shapes, stiffness, damping, body.edges,
        interfaces, body.surface,
    )  # fmt: skip


def proportional_damping(mass: np.ndarray, stiffness: np.ndarray, zeta: float) -> np.ndarray:
    """``D = M V diag(2 ζ ω) Vᵀ M``: every mode of (M, K) damped at the ratio ζ.

    Parameters
    ----------
    mass, stiffness : numpy.ndarray, shape (k, k)
        The modal mass (positive definite) and stiffness (semidefinite).
    zeta : float
        The ratio of critical damping.
    """
    omega2, vectors = scipy.linalg.eigh(stiffness, mass)
    omega = np.sqrt(np.clip(omega2, 0.0, None))
    mv = mass @ vectors
    damping = mv @ np.diag(2.0 * zeta * omega) @ mv.T
    return 0.5 * (damping + damping.T)
