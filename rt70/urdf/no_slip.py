"""Read and check ``<rt70:no_slip>`` (docs/urdf-extensions.md, docs/nonholonomic.md).

One job: turn the XML of a rolling or knife-edge contact into a
:class:`~rt70.urdf.description.NoSlip` — the material point of a link (or the contact
point of a wheel of given radius) has no velocity along a direction fixed in a link —
or refuse it with an :class:`~rt70.errors.ExtensionError` naming the file and the
element. Each side builds the constraint row ``A(q)`` from its own kinematics
(:mod:`rt70.textbook.no_slip`, :mod:`rt70.reference.no_slip`). Called by
:mod:`rt70.urdf.extensions`.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from rt70.errors import ExtensionError
from rt70.urdf.description import NoSlip, RobotDescription
from rt70.urdf.elements import ElementReader

#: Shortest direction or normal vector accepted (they are normalised).
MIN_NORM = 1e-9


def read_no_slip(
    reader: ElementReader, elem: ET.Element, desc: RobotDescription, seen: list[NoSlip]
) -> NoSlip:
    """The :class:`NoSlip` of one ``<rt70:no_slip>`` element.

    Attributes: ``name`` (unique), ``link``, ``xyz`` (link frame, default the origin),
    ``direction`` (3 numbers, in the axes of ``frame``, normalised), ``frame`` (a
    link, default ``link``), ``radius`` (≥ 0, default 0: a wheel's contact point lies
    ``radius`` below ``xyz`` along ``−normal``), ``normal`` (ground axes, default
    ``0 0 1``, normalised).

    Parameters
    ----------
    reader : ElementReader
        The reader of the file (its name for messages, the attribute readers).
    elem : xml.etree.ElementTree.Element
        The ``<rt70:no_slip>`` element.
    desc : RobotDescription
        The description read so far (its links).
    seen : list of NoSlip
        The no-slip constraints already read from the file (a name may not repeat).

    Raises
    ------
    ExtensionError
        If the name is missing or repeated, a link does not exist, a number list is
        malformed, the direction or normal is (near) zero, or the radius is negative.
    """
    name = reader.name_of(elem)
    where = f"<rt70:no_slip name='{name}'>"
    if any(n.name == name for n in seen):
        raise reader.fail(ExtensionError, f"{where}: a second <rt70:no_slip> of that name")
    link = reader.link_ref(elem, "link", desc, where)
    frame = reader.link_ref(elem, "frame", desc, where) if elem.get("frame") else link
    owner = f"no_slip '{name}'"
    xyz = reader.numbers(elem, "xyz", 3, np.zeros(3), owner=owner)
    direction = _unit(reader, reader.numbers(elem, "direction", 3, owner=owner), where, "direction")
    radius = reader.number(elem, "radius", 0.0, owner=owner)
    if radius < 0.0:
        raise reader.fail(ExtensionError, f"{where}: negative radius {radius:g}")
    normal = _unit(
        reader, reader.numbers(elem, "normal", 3, [0.0, 0.0, 1.0], owner=owner), where, "normal"
    )
    return NoSlip(name, link, xyz, direction, frame, radius, normal)


def _unit(reader: ElementReader, v: np.ndarray, where: str, attr: str) -> np.ndarray:
    norm = float(np.linalg.norm(v))
    if norm < MIN_NORM:
        raise reader.fail(ExtensionError, f"{where}: {attr} {v.tolist()} has no length")
    return v / norm
