"""Read and check a ``<rt70:mount>`` element: the pointing axes of a structure.

One job: turn the XML of a mount — its type and, for each of its axes, the joint that
turns it, where its angle counts from and which way, and the range it points over —
into a :class:`~rt70.urdf.description.Mount`, or refuse it with an
:class:`~rt70.errors.ExtensionError` naming the file and the element
(docs/urdf-extensions.md, ``<rt70:mount>``). Called by :mod:`rt70.urdf.extensions` once
the joints are known. The mount carries no dynamics: the analyses that point a structure
(a pointing's held coordinates, the servo axes) read it.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

from rt70.errors import ExtensionError
from rt70.urdf.description import MOUNT_AXES, Joint, Mount, MountAxis
from rt70.urdf.elements import ElementReader
from rt70.urdf.text import RT70_NS

#: Joint types that can turn a pointing axis.
ROTARY = ("revolute", "continuous")


def read_mount(reader: ElementReader, elem: ET.Element, joints: dict[str, Joint]) -> Mount:
    """The :class:`Mount` of one ``<rt70:mount>`` element.

    Parameters
    ----------
    reader : ElementReader
        The reader of the file (its name for messages, the attribute readers).
    elem : xml.etree.ElementTree.Element
        The ``<rt70:mount>`` element, checked against :data:`rt70.urdf.vocabulary.RT70`.
    joints : dict of str to Joint
        The file's joints by name.

    Raises
    ------
    ExtensionError
        If the type is not one of :data:`~rt70.urdf.description.MOUNT_AXES`, its axes are
        not exactly that type's, an axis's joint does not exist, is not a revolute or
        continuous joint, is a mimic joint or turns two axes, ``sign`` is not 1 or −1,
        or the range is empty.
    NonFiniteError, MagnitudeError
        If a number is NaN, infinite or too large (as anywhere in the file).
    """
    kind = elem.get("type", "")
    if kind not in MOUNT_AXES:
        known = ", ".join(f"'{k}'" for k in MOUNT_AXES)
        raise reader.fail(ExtensionError, f"<rt70:mount type='{kind}'>: the type is one of {known}")
    axes = [_axis(reader, child, joints) for child in elem.iter(f"{{{RT70_NS}}}axis")]
    names = [a.name for a in axes]
    if sorted(names) != sorted(MOUNT_AXES[kind]):
        raise reader.fail(
            ExtensionError,
            f"<rt70:mount type='{kind}'> has the axes {names}: it needs exactly "
            f"{list(MOUNT_AXES[kind])}, each once",
        )
    used = [a.joint for a in axes]
    if len(set(used)) != len(used):
        raise reader.fail(ExtensionError, f"<rt70:mount>: one joint turns two axes ({used})")
    order = MOUNT_AXES[kind]
    return Mount(kind, tuple(sorted(axes, key=lambda a: order.index(a.name))))


def _axis(reader: ElementReader, elem: ET.Element, joints: dict[str, Joint]) -> MountAxis:
    """One ``<rt70:axis>``: its joint, zero, sign and range (degrees in, radians out)."""
    name = reader.name_of(elem)
    where = f"<rt70:axis name='{name}'>"
    joint = reader.one_dof_joint(elem, joints, where)
    if joint.type not in ROTARY:
        raise reader.fail(
            ExtensionError, f"{where}: joint '{joint.name}' is {joint.type}, not rotary"
        )
    if joint.mimic is not None:
        raise reader.fail(ExtensionError, f"{where}: joint '{joint.name}' is a mimic joint")
    sign = reader.number(elem, "sign", 1.0, owner=where)
    if sign not in (1.0, -1.0):
        raise reader.fail(ExtensionError, f"{where}: sign is 1 or -1, got {sign:g}")
    zero = reader.number(elem, "zero_deg", 0.0, owner=where)
    lower = reader.number(elem, "min_deg", -360.0, owner=where)
    upper = reader.number(elem, "max_deg", 360.0, owner=where)
    if not lower < upper:
        raise reader.fail(
            ExtensionError, f"{where}: min_deg {lower:g} is not below max_deg {upper:g}"
        )
    return MountAxis(
        name, joint.name, math.radians(zero), int(sign), math.radians(lower), math.radians(upper)
    )
