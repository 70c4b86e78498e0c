"""Writing rt70 URDF text deterministically: the pieces every generated scene is made of.

:func:`fmt` and :func:`fmt_vec` write numbers as the shortest text that reads back as
the same float; :class:`Writer` writes elements with a fixed attribute order and
two-space indentation; :func:`begin`, :func:`joint`, :func:`massless_link`,
:func:`massive_link`, :func:`six_dof_body` (the book's 6-DOF elastic pair),
:func:`gravity`, :func:`bushing` and :func:`end` write a scene's elements, following
``docs/urdf-extensions.md``. The scenes themselves are in :mod:`rt70.scenes.rt70_scenes`,
:mod:`rt70.scenes.book_scenes` and :mod:`rt70.scenes.loop_scenes`, gathered by
:mod:`rt70.scenes.generate`.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from rt70.scenes.pairs import PAIR_JOINTS

#: Namespace of the rt70 URDF extension elements.
RT70_NS = "urn:rt70:urdf-extensions:1"

#: Name of the root (ground) link of every scene.
ROOT_LINK = "world"

# Wide joint limits: pinocchio's URDF parser requires <limit> on revolute and prismatic
# joints; these never bind.
_LIMIT = (("lower", -1.0e3), ("upper", 1.0e3), ("effort", 1.0e12), ("velocity", 1.0e6))

#: The zero vector, default origin of frames, offsets and centres of mass.
ZERO3 = (0.0, 0.0, 0.0)
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


# ---------------------------------------------------------------------------------------
# Formatting
# ---------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Cylinder:
    """A link's drawn shape: a cylinder along the link's z, centred at ``xyz`` (m)."""

    radius: float
    length: float
    xyz: Sequence[float] = ZERO3


def fmt(value: float) -> str:
    """Format a number exactly and deterministically.

    Parameters
    ----------
    value : float
        A finite number.

    Returns
    -------
    str
        The shortest decimal text that reads back as the same float: for
        ``1e-4 ≤ |x| < 1e6`` Python's ``repr`` without a trailing ``.0`` (``25``,
        ``13.45``), otherwise scientific notation with the fewest digits
        (``5e+10``, ``5.35e+11``, ``1e-06``); zero (also ``-0.0``) is written ``0``.

    Raises
    ------
    ValueError
        If the value is NaN or infinite.
    """
    x = float(value)
    if not math.isfinite(x):
        raise ValueError(f"non-finite number {x!r} in a scene")
    if x == 0.0:
        return "0"
    if 1e-4 <= abs(x) < 1e6:
        text = repr(x)
        return text[:-2] if text.endswith(".0") else text
    for digits in range(17):
        text = format(x, f".{digits}e")
        if float(text) == x:
            return text
    return repr(x)  # pragma: no cover - 17 significant digits always round-trip


def fmt_vec(values: Iterable[float]) -> str:
    """Format a sequence of numbers as a space-separated attribute value.

    Parameters
    ----------
    values : iterable of float
        The numbers.

    Returns
    -------
    str
        The numbers formatted by :func:`fmt`, separated by single spaces.
    """
    return " ".join(fmt(v) for v in values)


def check_name(name: str) -> str:
    """Return ``name`` if it is a valid scene name (letters, digits, ``_``), else ValueError."""
    if not _NAME.match(name):
        raise ValueError(f"invalid name {name!r} in a scene")
    return name


class Writer:
    """Line-oriented XML writer with fixed attribute order and 2-space indentation."""

    def __init__(self) -> None:
        self.lines: list[str] = []
        self.depth = 0

    @staticmethod
    def _attrs(attrs: Sequence[tuple[str, str]]) -> str:
        for _, value in attrs:
            if any(c in value for c in '<>&"'):
                raise ValueError(f"attribute value {value!r} needs escaping")
        return "".join(f' {key}="{value}"' for key, value in attrs)

    def empty(self, tag: str, *attrs: tuple[str, str]) -> None:
        """Write an empty element ``<tag a="v"/>``."""
        self.lines.append("  " * self.depth + f"<{tag}{self._attrs(attrs)}/>")

    def open(self, tag: str, *attrs: tuple[str, str]) -> None:
        """Open an element ``<tag a="v">`` and indent what follows."""
        self.lines.append("  " * self.depth + f"<{tag}{self._attrs(attrs)}>")
        self.depth += 1

    def close(self, tag: str) -> None:
        """Close the innermost element ``</tag>``."""
        self.depth -= 1
        self.lines.append("  " * self.depth + f"</{tag}>")

    def comment(self, text: str) -> None:
        """Write a comment ``<!-- text -->``."""
        if "--" in text:
            raise ValueError("'--' is not allowed in an XML comment")
        self.lines.append("  " * self.depth + f"<!-- {text} -->")

    def blank(self) -> None:
        """Write an empty line."""
        self.lines.append("")

    def text(self) -> str:
        """The document written so far, with a final newline (elements must be closed)."""
        if self.depth != 0:
            raise RuntimeError("unbalanced XML elements")
        return "\n".join(self.lines) + "\n"


# ---------------------------------------------------------------------------------------
# Building blocks
# ---------------------------------------------------------------------------------------


def _check_inertia(link: str, mass: float, moments: Sequence[float]) -> None:
    if not mass > 0.0:
        raise ValueError(f"link {link!r}: mass must be positive, got {mass!r}")
    if any(not m > 0.0 for m in moments):
        raise ValueError(f"link {link!r}: principal moments must be positive, got {moments}")
    if 2.0 * max(moments) > sum(moments):
        raise ValueError(
            f"link {link!r}: principal moments {moments} violate the triangle inequality"
        )


def begin(w: Writer, name: str, description: str) -> None:
    """Open a scene: XML declaration, description, ``<robot>`` and the ground link.

    Parameters
    ----------
    w : Writer
        An empty writer.
    name : str
        The robot's name, also the scene's.
    description : str
        One line for the comment at the top of the file.
    """
    w.lines.append('<?xml version="1.0"?>')
    w.comment(f"{description}")
    w.comment("Generated by rt70.scenes.generate; do not edit by hand.")
    w.open("robot", ("name", check_name(name)), ("xmlns:rt70", RT70_NS))
    w.empty("link", ("name", ROOT_LINK))


def end(w: Writer) -> str:
    """Close the ``<robot>`` element and return the scene's text."""
    w.close("robot")
    return w.text()


def joint(
    w: Writer,
    name: str,
    jtype: str,
    parent: str,
    child: str,
    xyz: Sequence[float] = ZERO3,
    rpy: Sequence[float] = ZERO3,
    axis: Sequence[int] = (0, 0, 1),
) -> None:
    """Write a revolute, prismatic or fixed joint (wide ``<limit>`` on the moving ones).

    Parameters
    ----------
    w : Writer
        The scene being written.
    name : str
        Name of the joint.
    jtype : {"revolute", "prismatic", "fixed"}
        Type of the joint.
    parent, child : str
        Links the joint joins.
    xyz : sequence of float, optional
        Origin of the joint frame in the parent link, m.
    rpy : sequence of float, optional
        Roll, pitch, yaw of the joint frame in the parent link, rad.
    axis : sequence of int, optional
        Joint axis in the joint frame, integer entries (written as such).

    Raises
    ------
    ValueError
        For another joint type.
    """
    if jtype not in ("revolute", "prismatic", "fixed"):
        raise ValueError(f"joint type {jtype!r} is not used in rt70 scenes")
    w.open("joint", ("name", check_name(name)), ("type", jtype))
    w.empty("parent", ("link", check_name(parent)))
    w.empty("child", ("link", check_name(child)))
    w.empty("origin", ("xyz", fmt_vec(xyz)), ("rpy", fmt_vec(rpy)))
    if jtype != "fixed":
        w.empty("axis", ("xyz", " ".join(str(int(a)) for a in axis)))
        w.empty("limit", *((key, fmt(value)) for key, value in _LIMIT))
    w.close("joint")


def massless_link(w: Writer, name: str) -> None:
    """Write a link without ``<inertial>``."""
    w.empty("link", ("name", check_name(name)))


def massive_link(
    w: Writer,
    name: str,
    mass: float,
    moments: Sequence[float],
    com: Sequence[float] = ZERO3,
    rpy: Sequence[float] = ZERO3,
    visual: Cylinder | None = None,
) -> None:
    """Write a link whose inertia has principal ``moments`` on axes rotated by ``rpy``.

    Parameters
    ----------
    w : Writer
        The scene being written.
    name : str
        Name of the link.
    mass : float
        Mass, kg (> 0).
    moments : sequence of float
        Principal moments of inertia about the centre of mass, kg·m² (> 0, triangle
        inequality).
    com : sequence of float, optional
        Centre of mass in the link frame, m.
    rpy : sequence of float, optional
        Roll, pitch, yaw of the principal axes in the link frame, rad.
    visual : Cylinder, optional
        The link's drawn shape (``<visual>``: for URDF viewers; neither side reads it).

    Raises
    ------
    ValueError
        If the mass or a moment is not positive or the moments violate the triangle
        inequality.
    """
    _check_inertia(name, mass, moments)
    ixx, iyy, izz = moments
    w.open("link", ("name", check_name(name)))
    w.open("inertial")
    w.empty("origin", ("xyz", fmt_vec(com)), ("rpy", fmt_vec(rpy)))
    w.empty("mass", ("value", fmt(mass)))
    w.empty(
        "inertia",
        ("ixx", fmt(ixx)),
        ("ixy", "0"),
        ("ixz", "0"),
        ("iyy", fmt(iyy)),
        ("iyz", "0"),
        ("izz", fmt(izz)),
    )
    w.close("inertial")
    if visual is not None:
        w.open("visual")
        w.empty("origin", ("xyz", fmt_vec(visual.xyz)), ("rpy", fmt_vec(ZERO3)))
        w.open("geometry")
        w.empty("cylinder", ("radius", fmt(visual.radius)), ("length", fmt(visual.length)))
        w.close("geometry")
        w.close("visual")
    w.close("link")


def six_dof_body(
    w: Writer,
    body: str,
    parent: str,
    offset: Sequence[float],
    mass: float,
    moments: Sequence[float],
    com: Sequence[float] = ZERO3,
    inertia_rpy: Sequence[float] = ZERO3,
    visual: Cylinder | None = None,
) -> None:
    """Write a body joined to ``parent`` by six 1-DOF joints in series (a 6-DOF pair).

    The first joint's origin is the construction offset; the other five have zero
    origin. Intermediate links are massless; the body's inertia sits on the last link,
    named after the body.

    Parameters
    ----------
    w : Writer
        The scene being written.
    body : str
        Name of the body; the joints are ``<body>_x`` … ``<body>_rz``
        (:data:`rt70.scenes.pairs.PAIR_JOINTS`).
    parent : str
        The link the pair hangs on.
    offset : sequence of float
        Construction offset ``E_jc``: the first joint's origin in ``parent``, m.
    mass : float
        Mass of the body, kg.
    moments : sequence of float
        Principal moments of inertia about its centre of mass, kg·m².
    com : sequence of float, optional
        Centre of mass in the body frame, m.
    inertia_rpy : sequence of float, optional
        Roll, pitch, yaw of the principal axes in the body frame, rad.
    visual : Cylinder, optional
        The body's drawn shape (:func:`massive_link`).
    """
    w.comment(f"{body}: 6-DOF pair on {parent}, construction offset [{fmt_vec(offset)}]")
    previous = parent
    for k, (axis, jtype, direction) in enumerate(PAIR_JOINTS):
        last = k == len(PAIR_JOINTS) - 1
        child = body if last else f"{body}_{axis}_link"
        joint(
            w,
            f"{body}_{axis}",
            jtype,
            previous,
            child,
            xyz=offset if k == 0 else ZERO3,
            axis=direction,
        )
        if last:
            massive_link(w, child, mass, moments, com, inertia_rpy, visual)
        else:
            massless_link(w, child)
        previous = child


def gravity(w: Writer, g: Sequence[float]) -> None:
    """Write the scene's ``<rt70:gravity>`` vector, m/s²."""
    w.empty("rt70:gravity", ("xyz", fmt_vec(g)))


def _flat(values) -> list[float]:
    """The numbers of a sequence, or of a sequence of rows (a 6 × 6 matrix), in order."""
    return [float(v) for row in values for v in (row if hasattr(row, "__len__") else [row])]


def bushing(
    w: Writer,
    name: str,
    stiffness: Sequence[float],
    damping: Sequence[float],
    link1: str,
    link2: str,
    xyz1: Sequence[float] = ZERO3,
    rpy1: Sequence[float] = ZERO3,
    xyz2: Sequence[float] = ZERO3,
    rpy2: Sequence[float] = ZERO3,
) -> None:
    """Write an ``<rt70:bushing>``: its stiffness and damping between two link frames.

    Parameters
    ----------
    w : Writer
        The scene being written.
    name : str
        Name of the bushing.
    stiffness : sequence of float, length 6 or 36
        Along x, y, z (N/m), then about x, y, z (N·m/rad) of the deformation: the
        diagonal, or the symmetric 6 × 6 matrix row by row.
    damping : sequence of float, length 6 or 36
        Likewise, N·s/m and N·m·s/rad.
    link1, link2 : str
        Links of frame 1 and frame 2.
    xyz1, rpy1 : sequence of float, optional
        Frame 1 in ``link1``: origin (m) and roll, pitch, yaw (rad).
    xyz2, rpy2 : sequence of float, optional
        Frame 2 in ``link2``: origin (m) and roll, pitch, yaw (rad).

    Raises
    ------
    ValueError
        Without 6 or 36 values of each.
    """
    stiffness, damping = _flat(stiffness), _flat(damping)
    if len(stiffness) not in (6, 36) or len(damping) not in (6, 36):
        raise ValueError(f"bushing {name!r} needs 6 or 36 stiffness and damping values")
    w.open(
        "rt70:bushing",
        ("name", check_name(name)),
        ("stiffness", fmt_vec(stiffness)),
        ("damping", fmt_vec(damping)),
    )
    w.empty(
        "rt70:frame1", ("link", check_name(link1)), ("xyz", fmt_vec(xyz1)), ("rpy", fmt_vec(rpy1))
    )
    w.empty(
        "rt70:frame2", ("link", check_name(link2)), ("xyz", fmt_vec(xyz2)), ("rpy", fmt_vec(rpy2))
    )
    w.close("rt70:bushing")
