"""Read and check an ``<rt70:optics>`` element: the reflector system of a structure.

One job: turn the XML of an optics — its type (prime focus, Cassegrain, Gregorian, beam
waveguide), the link of its reference frame and, for each reflector, the optical points
that are its focus and vertex — into an :class:`~rt70.urdf.mount_record.Optics`, or refuse
it with an :class:`~rt70.errors.ExtensionError` naming the file and the element
(docs/urdf-extensions.md, ``<rt70:optics>``). Called by :mod:`rt70.urdf.extensions` once
the optical points are known. The optics carries no dynamics: the pointing outputs
(:mod:`rt70.model.antenna`) read it.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from rt70.errors import ExtensionError
from rt70.urdf.description import OpticalPoint, RobotDescription
from rt70.urdf.elements import ElementReader
from rt70.urdf.mount_record import OPTICS_TYPES, Optics, Reflector
from rt70.urdf.text import RT70_NS

#: The roles a reflector takes in an optics.
ROLES = ("primary", "secondary")


def read_optics(reader: ElementReader, elem: ET.Element, desc: RobotDescription) -> Optics:
    """The :class:`Optics` of one ``<rt70:optics>`` element.

    Parameters
    ----------
    reader : ElementReader
        The reader of the file (its name for messages, the attribute readers).
    elem : xml.etree.ElementTree.Element
        The ``<rt70:optics>`` element, checked against :data:`rt70.urdf.vocabulary.RT70`.
    desc : RobotDescription
        The description with its links and every optical point of the file read.

    Raises
    ------
    ExtensionError
        If the type is not one of :data:`~rt70.urdf.mount_record.OPTICS_TYPES`, the
        reflectors are not the type's (a primary, and a secondary exactly when the type has
        one), a role is unknown or repeated, a focus or vertex names no optical point, a
        reflector's focus and vertex lie on different links or on the same point, a
        secondary has no ``support`` link or is supported by its own link, or a link is
        unknown.
    """
    kind = elem.get("type", "")
    if kind not in OPTICS_TYPES:
        known = ", ".join(f"'{k}'" for k in OPTICS_TYPES)
        raise reader.fail(
            ExtensionError, f"<rt70:optics type='{kind}'>: the type is one of {known}"
        )
    where = f"<rt70:optics type='{kind}'>"
    reference = reader.link_ref(elem, "reference_link", desc, where)
    points = {p.name: p for p in desc.optical_points}
    reflectors: dict[str, Reflector] = {}
    for child in elem.iter(f"{{{RT70_NS}}}reflector"):
        role = child.get("role", "")
        if role not in ROLES or role in reflectors:
            why = "is repeated" if role in reflectors else f"is one of {', '.join(ROLES)}"
            raise reader.fail(
                ExtensionError, f"{where}: <rt70:reflector role='{role}'>: the role {why}"
            )
        reflectors[role] = _reflector(
            reader, child, desc, points, f"<rt70:reflector role='{role}'>"
        )
    wanted = ["primary", "secondary"] if OPTICS_TYPES[kind] else ["primary"]
    if sorted(reflectors) != wanted:
        raise reader.fail(
            ExtensionError,
            f"{where} has the reflectors {sorted(reflectors)}: it needs exactly {wanted}",
        )
    primary = reflectors["primary"]
    if primary.support is not None:
        raise reader.fail(
            ExtensionError, f"{where}: the primary reflector has no 'support' (a secondary has)"
        )
    secondary = reflectors.get("secondary")
    if secondary is not None and secondary.support is None:
        raise reader.fail(
            ExtensionError,
            f"{where}: the secondary reflector needs 'support', the link its drive is on",
        )
    return Optics(kind, reference, primary, secondary)


def _reflector(
    reader: ElementReader,
    elem: ET.Element,
    desc: RobotDescription,
    points: dict[str, OpticalPoint],
    where: str,
) -> Reflector:
    """One ``<rt70:reflector>``: its focus and vertex points (and a secondary's support)."""
    named = []
    for attr in ("focus", "vertex"):
        name = elem.get(attr, "")
        if name not in points:
            raise reader.fail(
                ExtensionError, f"{where}: {attr} '{name}' is no <rt70:optical_point> of the file"
            )
        named.append(points[name])
    focus, vertex = named
    if focus.name == vertex.name:
        raise reader.fail(ExtensionError, f"{where}: focus and vertex are one point '{focus.name}'")
    if focus.link != vertex.link:
        raise reader.fail(
            ExtensionError,
            f"{where}: focus '{focus.name}' is on link '{focus.link}', vertex '{vertex.name}' "
            f"on '{vertex.link}': a reflector's points are on its own link",
        )
    support = None
    if elem.get("support") is not None:
        support = reader.link_ref(elem, "support", desc, where)
        if support == focus.link:
            raise reader.fail(
                ExtensionError, f"{where}: support '{support}' is the reflector's own link"
            )
    return Reflector(focus.name, vertex.name, support)
