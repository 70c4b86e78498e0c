"""Read and check a ``<rt70:drive>`` element (docs/urdf-extensions.md).

One job: turn the XML of a drive — a DC motor with a compliant reducer on one axis
(formalism §4.5, (4.137)–(4.150)) — into a :class:`~rt70.urdf.description.Drive`, or
refuse it with an :class:`~rt70.errors.ExtensionError` naming the file and the element.
Called by :mod:`rt70.urdf.extensions` once the joints and links are known.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from rt70.errors import ExtensionError
from rt70.urdf.description import DRIVE_PARAMETERS, Drive, DriveSector, Joint, RobotDescription
from rt70.urdf.elements import ElementReader
from rt70.urdf.text import RT70_NS

#: Parameters that must be positive (the others, D_m and D_r, may be zero).
POSITIVE = ("L_a", "R_a", "c_m", "c_e", "J_m", "i_r", "C_r")

#: Largest ``|axis · direction|`` of a sector: the tangent must be normal to the axis.
ORTHOGONALITY = 1e-9


def read_drive(
    reader: ElementReader, elem: ET.Element, desc: RobotDescription, joints: dict[str, Joint]
) -> Drive:
    """The :class:`Drive` of one ``<rt70:drive>`` element.

    Parameters
    ----------
    reader : ElementReader
        The reader of the file (its name for messages, the attribute readers).
    elem : xml.etree.ElementTree.Element
        The ``<rt70:drive>`` element.
    desc : RobotDescription
        The description read so far: its links, and the drives already read (a name
        may not repeat).
    joints : dict of str to Joint
        The file's joints by name.

    Raises
    ------
    ExtensionError
        If the name, the joint or a parameter is missing or wrong: the joint does not
        exist, is not 1-DOF or is a mimic joint; a parameter is negative (or zero where
        it must be positive); the sector's links do not exist, coincide, or its
        direction or axis is zero or not orthogonal; two sectors, or a sector on a
        prismatic joint.
    NonFiniteError, MagnitudeError
        If a number is NaN, infinite or too large (as anywhere in the file).
    """
    name = reader.name_of(elem)
    where = f"<rt70:drive name='{name}'>"
    if any(d.name == name for d in desc.drives):
        raise reader.fail(ExtensionError, f"two drives named '{name}'")
    joint = reader.one_dof_joint(elem, joints, where)
    jname = joint.name
    if joint.mimic is not None:
        raise reader.fail(
            ExtensionError,
            f"{where}: joint '{jname}' mimics '{joint.mimic.joint}': drive the independent "
            "joint instead",
        )
    values = {}
    for key in DRIVE_PARAMETERS:
        value = reader.number(elem, key, owner=f"drive '{name}'")
        if value < 0.0 or (key in POSITIVE and value == 0.0):
            need = "positive" if key in POSITIVE else "non-negative"
            raise reader.fail(ExtensionError, f"{where}: {key}={value:g} must be {need}")
        values[key] = value
    sub = elem.find(f"{{{RT70_NS}}}sector")  # at most one (rt70.urdf.vocabulary.RT70)
    sector = _sector(reader, sub, desc, name) if sub is not None else None
    if sector is not None and joint.type == "prismatic":
        raise reader.fail(
            ExtensionError, f"{where}: a gear sector turns an angle, joint '{jname}' is prismatic"
        )
    return Drive(name, jname, **values, sector=sector)


def _sector(
    reader: ElementReader, sub: ET.Element, desc: RobotDescription, name: str
) -> DriveSector:
    """The sector of drive ``name``: link, mesh point, tangent, axis, radius, stator."""
    where = f"<rt70:drive name='{name}'> <rt70:sector>"
    owner = f"drive '{name}'"
    link = reader.link_ref(sub, "link", desc, where)
    stator = reader.link_ref(sub, "stator", desc, where)
    if stator == link:
        raise reader.fail(ExtensionError, f"{where}: link and stator are both '{link}'")
    xyz = reader.numbers(sub, "xyz", 3, np.zeros(3), owner)
    unit = {}
    for attr in ("direction", "axis"):
        v = reader.numbers(sub, attr, 3, owner=owner)
        norm = float(np.linalg.norm(v))
        if norm < 1e-12:
            raise reader.fail(ExtensionError, f"{where}: zero-length {attr}")
        unit[attr] = v / norm
    if abs(float(unit["direction"] @ unit["axis"])) > ORTHOGONALITY:
        raise reader.fail(
            ExtensionError, f"{where}: direction is not orthogonal to axis (a pitch-circle tangent)"
        )
    radius = reader.number(sub, "radius", owner=owner)
    if radius <= 0.0:
        raise reader.fail(ExtensionError, f"{where}: radius={radius:g} must be positive")
    return DriveSector(link, xyz, unit["direction"], unit["axis"], radius, stator)
