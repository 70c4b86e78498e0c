"""Read and check a ``<rt70:mount>`` element: the pointing axes of a structure.

One job: turn the XML of a mount — its type and, for each of its axes, the joint that
turns it, where its angle counts from and which way, the range it points over and its
servo (the drive it closes around, limits, design) — into a
:class:`~rt70.urdf.mount_record.Mount`, or refuse it with an
:class:`~rt70.errors.ExtensionError` naming the file and the element
(docs/urdf-extensions.md, ``<rt70:mount>``). Called by :mod:`rt70.urdf.extensions` once
the joints and drives are known. The mount carries no dynamics: the analyses that point a structure
(a pointing's held coordinates, the servo axes) read it.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

from rt70.errors import ExtensionError
from rt70.urdf.description import MOUNT_AXES, Drive, Joint
from rt70.urdf.elements import ElementReader
from rt70.urdf.mount_record import AxisServo, Mount, MountAxis
from rt70.urdf.text import RT70_NS

#: Joint types that can turn a pointing axis.
ROTARY = ("revolute", "continuous")

#: Bandwidth ratio between nested loops when a servo gives none (antenna practice:
#: each loop some five times faster than the one around it; docs/antenna-servo).
DEFAULT_LOOP_RATIO = 5.0


def read_mount(
    reader: ElementReader,
    elem: ET.Element,
    joints: dict[str, Joint],
    drives: list[Drive] | None = None,
) -> Mount:
    """The :class:`Mount` of one ``<rt70:mount>`` element.

    Parameters
    ----------
    reader : ElementReader
        The reader of the file (its name for messages, the attribute readers).
    elem : xml.etree.ElementTree.Element
        The ``<rt70:mount>`` element, checked against :data:`rt70.urdf.vocabulary.RT70`.
    joints : dict of str to Joint
        The file's joints by name.
    drives : list of Drive, optional
        The file's ``<rt70:drive>`` elements (an axis's servo names one).

    Raises
    ------
    ExtensionError
        If the type is not one of :data:`~rt70.urdf.description.MOUNT_AXES`, its axes are
        not exactly that type's, an axis's joint does not exist, is not a revolute or
        continuous joint, is a mimic joint or turns two axes, ``sign`` is not 1 or −1,
        or the range is empty; a servo names no drive of the file or one on another
        joint, or a limit, bandwidth, ratio, inertia or friction is not positive.
    NonFiniteError, MagnitudeError
        If a number is NaN, infinite or too large (as anywhere in the file).
    """
    kind = elem.get("type", "")
    if kind not in MOUNT_AXES:
        known = ", ".join(f"'{k}'" for k in MOUNT_AXES)
        raise reader.fail(ExtensionError, f"<rt70:mount type='{kind}'>: the type is one of {known}")
    by_name = {d.name: d for d in drives or []}
    axes = [_axis(reader, child, joints, by_name) for child in elem.iter(f"{{{RT70_NS}}}axis")]
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


def _axis(
    reader: ElementReader, elem: ET.Element, joints: dict[str, Joint], drives: dict[str, Drive]
) -> MountAxis:
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
    servo = elem.find(f"{{{RT70_NS}}}servo")  # at most one (rt70.urdf.vocabulary.RT70)
    return MountAxis(
        name,
        joint.name,
        math.radians(zero),
        int(sign),
        math.radians(lower),
        math.radians(upper),
        None if servo is None else _servo(reader, servo, joint, drives, name),
    )


def _servo(
    reader: ElementReader, elem: ET.Element, joint: Joint, drives: dict[str, Drive], axis: str
) -> AxisServo:
    """One ``<rt70:servo>``: its drive, limits and design (degrees in, radians out)."""
    where = f"<rt70:axis name='{axis}'> <rt70:servo>"
    drive = elem.get("drive", "")
    if drive not in drives:
        known = ", ".join(drives) or "none"
        raise reader.fail(
            ExtensionError, f"{where}: drive '{drive}' is no <rt70:drive> of the file ({known})"
        )
    if drives[drive].joint != joint.name:
        raise reader.fail(
            ExtensionError,
            f"{where}: drive '{drive}' turns joint '{drives[drive].joint}', the axis turns "
            f"'{joint.name}'",
        )

    def positive(attr: str, default: float | None = None) -> float | None:
        if elem.get(attr) is None:
            return default
        value = reader.number(elem, attr, owner=where)
        if not value > 0.0:
            raise reader.fail(ExtensionError, f"{where}: {attr}={value:g} must be positive")
        return value

    ratio = positive("loop_ratio", DEFAULT_LOOP_RATIO)
    if not ratio > 1.0:
        raise reader.fail(ExtensionError, f"{where}: loop_ratio={ratio:g} must be above 1")
    torque = positive("torque_limit")
    static, top = positive("static_friction"), positive("top_speed_friction")
    if (static is None) != (top is None) or (static is not None and top < static):
        raise reader.fail(
            ExtensionError,
            f"{where}: give static_friction and top_speed_friction together, the second not "
            "below the first",
        )
    return AxisServo(
        drive=drive,
        rate_limit=math.radians(positive("rate_limit_deg_s")),
        torque_limit=torque,
        voltage_limit=positive("voltage_limit"),
        position_bandwidth_hz=positive("position_bandwidth_hz"),
        loop_ratio=ratio,
        nominal_torque=positive("nominal_torque", torque),
        reference_inertia=positive("reference_inertia"),
        static_friction=static,
        top_speed_friction=top,
    )
