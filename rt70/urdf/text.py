"""The URDF text before it is parsed: reading, normalising, refusing what would be misread.

Both sides of the cross-check read the same text: rt70's reader parses it, and the
Pinocchio side hands it to Pinocchio's parser. What would make the two read different
models — DTD entities (Python's parser expands them, Pinocchio's does not), xacro
templates (not URDF at all) — is refused here with a message naming the file, the
element and how to fix it (docs/urdf-reader.md).
"""

from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET
import xml.parsers.expat
from pathlib import Path

from rt70.errors import DtdError, Rt70Warning, UrdfError, XacroError

#: XML namespace of the rt70 extension elements (docs/urdf-extensions.md).
RT70_NS = "urn:rt70:urdf-extensions:1"


def read_source(path: str | Path) -> str:
    """The text of a URDF file, or a :class:`~rt70.errors.UrdfError` naming the file."""
    path = Path(path)
    try:
        return path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise UrdfError(f"{path}: file not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise UrdfError(f"{path}: cannot read file ({exc})") from None


def warn(message: str) -> None:
    """Issue ``message`` as an :class:`~rt70.errors.Rt70Warning` (one line)."""
    warnings.warn(Rt70Warning(message), stacklevel=2)


def prepare_text(text: str, source: str = "<string>") -> str:
    """The URDF text as both sides read it (Pinocchio is handed this text too).

    A byte-order mark is dropped. Whitespace before the ``<?xml`` declaration (which XML
    forbids, Pinocchio's TinyXML-based parser skips) and NUL characters after the
    document (where a C parser stops reading) are removed with an
    :class:`~rt70.errors.Rt70Warning`. Idempotent.

    Raises
    ------
    UrdfError
        If a NUL character is followed by anything but NULs and whitespace.
    """
    text = text.removeprefix("\ufeff")
    nul = text.find("\x00")
    if nul >= 0:
        if text[nul:].strip("\x00 \t\r\n"):
            line = text.count("\n", 0, nul) + 1
            raise UrdfError(f"{source}: malformed XML: NUL character in the document, line {line}")
        text = text[:nul]
        warn(f"{source}: NUL characters after the document ignored")
    stripped = text.lstrip()
    if len(stripped) < len(text) and stripped.startswith("<?xml"):
        warn(f"{source}: whitespace before the XML declaration '<?xml' ignored")
        text = stripped
    return text


#: How to turn a xacro template into a URDF.
EXPAND_XACRO = (
    "this is a xacro template, not a URDF: expand it with xacro first (xacro FILE > FILE.urdf)"
)


def refuse_entities(text: str, source: str) -> None:
    """Raise :class:`~rt70.errors.DtdError` if the document declares DTD entities.

    Python's XML parser expands internal entities; Pinocchio's (TinyXML) does not, so
    the two sides of the cross-check would read different numbers.
    """
    if "<!DOCTYPE" not in text:
        return
    parser = xml.parsers.expat.ParserCreate()
    declared: list[str] = []

    def entity(name, is_parameter, *_) -> None:
        declared.append(("%" if is_parameter else "") + name)
        raise _EntityFound

    parser.EntityDeclHandler = entity
    try:
        parser.Parse(text, True)
    except (_EntityFound, xml.parsers.expat.ExpatError):
        pass  # malformed XML is reported by the main parse
    if declared:
        raise DtdError(
            f"{source}: <!ENTITY {declared[0]}> in <!DOCTYPE>: DTD entities are not supported "
            "(rt70's reader would expand them, Pinocchio's parser does not, so the two sides "
            "would read different models): expand them first (xmllint --noent --dropdtd FILE)"
        )


class _EntityFound(Exception):
    """Stops the entity scan at the first declaration."""


def refuse_xacro(root: ET.Element, source: str) -> None:
    """Raise :class:`~rt70.errors.XacroError` at the first xacro element or substitution.

    A xacro namespace declaration alone is no xacro: expanded files keep it.
    """
    for elem in root.iter():
        if is_xacro(elem.tag):
            raise XacroError(f"{source}: <{qualified(elem.tag)}>: xacro element: {EXPAND_XACRO}")
        for key, value in elem.attrib.items():
            if is_xacro(key) or "${" in value or "$(" in value:
                raise XacroError(
                    f'{source}: <{qualified(elem.tag)} {qualified(key)}="{value}">: xacro '
                    f"substitution: {EXPAND_XACRO}"
                )


def is_xacro(name: str) -> bool:
    """Whether an element or attribute name is in a xacro namespace (``…/xacro``)."""
    return name.startswith("{") and name[1 : name.find("}")].rstrip("/").endswith("xacro")


def qualified(name: str) -> str:
    """``{uri}local`` as ``xacro:local``/``rt70:local`` (other URIs kept), else ``name``."""
    if not name.startswith("{"):
        return name
    uri, local = name[1:].split("}", 1)
    if is_xacro(name):
        return f"xacro:{local}"
    return f"rt70:{local}" if uri == RT70_NS else name
