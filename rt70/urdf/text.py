"""The URDF text before it is parsed: reading, normalising, refusing what would be misread.

Both sides of the cross-check read the same text: rt70's reader parses it, and the
Pinocchio side hands it to Pinocchio's parser. What would make the two read different
models — DTD entities (Python's parser expands them, Pinocchio's does not), xacro
templates (not URDF at all) — is refused here with a message naming the file, the
element and how to fix it (docs/urdf-reader.md).
"""

from __future__ import annotations

import re
import warnings
import xml.etree.ElementTree as ET
import xml.parsers.expat
from pathlib import Path

from rt70.errors import DtdError, ExtensionError, Rt70Warning, UrdfError, XacroError

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


#: An element or attribute name with the prefix ``rt70:`` in a start tag.
_RT70_PREFIXED = re.compile(r"(^<|\s)rt70:[\w.-]+")

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


def parse(text: str, source: str) -> tuple[ET.Element, dict[str, set[str]]]:
    """The XML tree of a URDF text, and the prefixes its namespace declarations bind.

    Returns
    -------
    root : xml.etree.ElementTree.Element
        The document element.
    prefixes : dict of str to set of str
        For each namespace URI the document declares, the prefixes bound to it (``""``
        for a default namespace).

    Raises
    ------
    ExtensionError
        If the prefix ``rt70:`` is used without its namespace declaration.
    XacroError
        If the prefix ``xacro:`` is used without its namespace declaration.
    UrdfError
        If the text is not well-formed XML.
    """
    builder = _NamespaceRecorder()
    parser = ET.XMLParser(target=builder)
    try:
        parser.feed(text)
        root = parser.close()
    except ET.ParseError as exc:
        if "unbound prefix" in str(exc):
            tag = _start_tag(text, *exc.position)
            if _RT70_PREFIXED.search(tag):
                raise ExtensionError(
                    f"{source}: line {exc.position[0]}: {tag}: the prefix 'rt70:' is not "
                    f'declared: add xmlns:rt70="{RT70_NS}" to <robot>'
                ) from None
            if "xacro:" in text:
                raise XacroError(
                    f"{source}: xacro elements without the xacro namespace ({exc}): {EXPAND_XACRO}"
                ) from None
        raise UrdfError(f"{source}: malformed XML: {exc}") from None
    return root, builder.prefixes


class _NamespaceRecorder(ET.TreeBuilder):
    """A tree builder that also records each namespace declaration's prefix."""

    def __init__(self) -> None:
        super().__init__()
        self.prefixes: dict[str, set[str]] = {}

    def start_ns(self, prefix: str, uri: str) -> None:
        self.prefixes.setdefault(uri, set()).add(prefix)


def _start_tag(text: str, line: int, column: int) -> str:
    """The start tag at ``line`` (1-based) and ``column`` (0-based) of ``text``, shortened."""
    lines = text.splitlines()
    if not 1 <= line <= len(lines):
        return ""
    rest = lines[line - 1][column:] + " " + " ".join(lines[line : line + 5])
    end = rest.find(">")
    tag = rest[: end + 1] if end >= 0 else rest
    return tag if len(tag) <= 80 else tag[:76] + " ..."


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


#: Wide limits written on the revolute and prismatic joints rt70 generates into a text
#: (Pinocchio's parser requires them; they never bind).
GENERATED_LIMIT = '<limit lower="-1000" upper="1000" effort="1e12" velocity="1e6"/>'


def link_and_joint_names(root: ET.Element) -> set[str]:
    """Every link and joint name of a parsed URDF (what a generated element may not take)."""
    return {e.get("name") for e in root.findall("link")} | {
        e.get("name") for e in root.findall("joint")
    }


def insert_before_robot_end(text: str, blocks: list[str]) -> str:
    """``text`` with the generated ``blocks`` inserted just before its last ``</robot>``."""
    end = [m.end() for m in re.finditer(r"</\s*robot\s*>", text)][-1]
    start = text.rindex("<", 0, end)
    return text[:start] + "".join(blocks) + text[start:]
