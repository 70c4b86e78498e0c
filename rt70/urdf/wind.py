"""Read and check ``<rt70:wind>`` and ``<rt70:air>`` (docs/urdf-extensions.md, docs/wind.md).

One job: turn the XML of an exposed body — its link, reference point, symmetry axis,
reference area and length, and coefficient table — into a
:class:`~rt70.urdf.description.Wind`, or the scene's air density, or refuse it with an
:class:`~rt70.errors.ExtensionError` naming the file and the element. The coefficient
table is read and checked here
(:class:`rt70.physics.coefficient_tables.CoefficientTable`): a built-in ``shape`` or a
``coefficients`` CSV file, relative to the URDF file's directory.
Called by :mod:`rt70.urdf.extensions`.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from rt70.errors import ExtensionError
from rt70.physics.coefficient_tables import (
    BUILTIN_TABLES,
    CoefficientTable,
    WindError,
    builtin_table,
)
from rt70.urdf.description import RobotDescription, Wind
from rt70.urdf.elements import ElementReader


def read_wind(
    reader: ElementReader, elem: ET.Element, desc: RobotDescription, seen: list[Wind]
) -> Wind:
    """The :class:`Wind` of one ``<rt70:wind>`` element.

    Parameters
    ----------
    reader : ElementReader
        The reader of the file (its name for messages and the directory a relative
        ``coefficients`` file is found in; the attribute readers).
    elem : xml.etree.ElementTree.Element
        The ``<rt70:wind>`` element.
    desc : RobotDescription
        The description read so far (its links).
    seen : list of Wind
        The winds already read from the file (a name may not repeat).

    Raises
    ------
    ExtensionError
        If the name is missing or repeated, the link does not exist, the axis is zero,
        the area or length is not positive, not exactly one of ``shape`` and
        ``coefficients`` is given, the shape is not built in, or the coefficient file
        is missing or malformed
        (:meth:`rt70.physics.coefficient_tables.CoefficientTable.from_text`).
    NonFiniteError, MagnitudeError
        If a number is NaN, infinite or too large (as anywhere in the file).
    """
    name = reader.name_of(elem)
    where = f"<rt70:wind name='{name}'>"
    if any(w.name == name for w in seen):
        raise reader.fail(ExtensionError, f"two <rt70:wind> elements named '{name}'")
    link = reader.link_ref(elem, "link", desc, where)
    owner = f"wind '{name}'"
    xyz = reader.numbers(elem, "xyz", 3, np.zeros(3), owner)
    axis = reader.numbers(elem, "axis", 3, owner=owner)
    norm = float(np.linalg.norm(axis))
    if norm < 1e-12:
        raise reader.fail(ExtensionError, f"{where}: zero-length axis")
    values = {}
    for key in ("area", "length"):
        value = reader.number(elem, key, owner=owner)
        if value <= 0.0:
            raise reader.fail(ExtensionError, f"{where}: {key}={value:g} must be positive")
        values[key] = value
    shape, table = _table(reader, elem, where)
    surface = elem.get("surface")
    return Wind(
        name, link, xyz, axis / norm, values["area"], values["length"], shape, table, surface
    )


def check_wind_surfaces(reader: ElementReader, winds: list[Wind], bodies: tuple) -> None:
    """Refuse a ``surface=`` that names no modal body with a reflecting surface.

    Parameters
    ----------
    reader : ElementReader
        The reader of the file (its name for messages).
    winds : list of Wind
        The file's winds.
    bodies : tuple of rt70.urdf.modal_record.ModalBody
        The file's modal bodies.
    """
    with_surface = {b.name for b in bodies if b.surface is not None}
    for w in winds:
        if w.surface is not None and w.surface not in with_surface:
            known = ", ".join(sorted(with_surface)) or "none"
            raise reader.fail(
                ExtensionError,
                f"<rt70:wind name='{w.name}'>: surface=\"{w.surface}\" is no modal body with a "
                f"reflecting surface (those with one: {known})",
            )


def _table(reader: ElementReader, elem: ET.Element, where: str) -> tuple[str, CoefficientTable]:
    """The element's coefficient table: a built-in ``shape`` or a ``coefficients`` file."""
    shape, file = elem.get("shape"), elem.get("coefficients")
    if (shape is None) == (file is None):
        raise reader.fail(
            ExtensionError,
            f"{where}: give exactly one of shape= (built in: {', '.join(BUILTIN_TABLES)}) "
            "and coefficients=FILE.csv",
        )
    try:
        if shape is not None:
            if shape not in BUILTIN_TABLES:
                raise WindError(
                    f"unknown shape '{shape}' (built in: {', '.join(BUILTIN_TABLES)}; "
                    "or coefficients=FILE.csv)"
                )
            return shape, builtin_table(shape)
        path = Path(file)
        if not path.is_absolute():
            path = Path(reader.source).parent / path
        return file, CoefficientTable.from_csv(path)
    except WindError as exc:
        raise reader.fail(ExtensionError, f"{where}: {exc}") from None


def read_air(reader: ElementReader, elem: ET.Element) -> float:
    """The air density of ``<rt70:air density="...">``, kg/m³ (positive).

    Raises
    ------
    ExtensionError
        If the density is missing or not positive.
    """
    density = reader.number(elem, "density", owner="air")
    if density <= 0.0:
        raise reader.fail(ExtensionError, f"<rt70:air density='{density:g}'>: must be positive")
    return density
