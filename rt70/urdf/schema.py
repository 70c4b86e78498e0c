"""The one check that a URDF scene carries only what rt70's vocabulary declares.

Every element kind rt70 reads declares, in one table per family
(:mod:`rt70.urdf.vocabulary`), the attributes it knows (the required ones apart) and the
children it checks; this module enforces them:

- **rt70's extension elements** (:data:`RT70`, namespace :data:`~rt70.urdf.text.RT70_NS`)
  are rt70's own vocabulary, so nothing in them may pass unread: an unknown or misspelt
  attribute, a missing required one, an unknown child, a child too many or too few, text
  content, an rt70 element anywhere but where the table puts it, are each an
  :class:`~rt70.errors.ExtensionError` naming the file, the element and the attribute,
  with the nearest known name (``did you mean 'stiffness'?``).
- **standard URDF elements** (:data:`URDF`) keep the tolerance of Pinocchio, MuJoCo and
  Drake: an attribute the URDF specification (and the widely used readers' documented
  extensions) does not have is read past with one :class:`~rt70.errors.Rt70Warning` per
  element kind and attribute; elements the table does not list (``<gazebo>``,
  ``<transmission>`` contents, ...) are not looked into.
- **namespaces**: an element or attribute whose namespace looks like rt70's but is not it
  (:func:`looks_like_rt70`) would be dropped without a word, so it is an
  :class:`~rt70.errors.ExtensionError`; so is an rt70 attribute on a standard element.
  Other namespaces (xacro is refused before, :func:`rt70.urdf.text.refuse_xacro`) are
  accepted.

:func:`check_scene` runs the whole check once, before anything is read
(docs/urdf-extensions.md, "Errors"; docs/urdf-reader.md).
"""

from __future__ import annotations

import difflib
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Mapping

from rt70.errors import ExtensionError
from rt70.urdf.text import RT70_NS, warn
from rt70.urdf.vocabulary import RT70, URDF, Spec

#: Smallest difflib similarity ratio for a "did you mean" suggestion.
SUGGESTION_CUTOFF = 0.6


# --- namespaces ------------------------------------------------------------------------


def split(name: str) -> tuple[str | None, str]:
    """``{uri}local`` as ``(uri, local)``; a name in no namespace as ``(None, name)``."""
    if name[:1] != "{":
        return None, name
    uri, local = name[1:].split("}", 1)
    return uri, local


def looks_like_rt70(uri: str, prefixes: Iterable[str] = ()) -> bool:
    """Whether a namespace URI other than rt70's was meant to be rt70's.

    It was when its URI contains ``rt70`` in any case (another version
    ``urn:rt70:urdf-extensions:2``, a misspelling ``urn:rt70:urdf-extension:1``, a case
    or trailing-slash variant, another scheme ``http://rt70.org/urdf``) or when the
    document binds it to the prefix ``rt70`` (``prefixes``: the prefixes it is bound
    to, in any case). rt70's own URI, :data:`~rt70.urdf.text.RT70_NS`, does not.
    """
    if uri == RT70_NS:
        return False
    return "rt70" in uri.casefold() or any(p.casefold() == "rt70" for p in prefixes)


#: ``{RT70_NS}``: how an rt70 element's or attribute's name starts once parsed.
_RT70 = "{" + RT70_NS + "}"


# --- the check -------------------------------------------------------------------------


def check_scene(root: ET.Element, source: str, prefixes: Mapping[str, set[str]]) -> None:
    """Check a parsed scene against :data:`RT70` and :data:`URDF`, and its namespaces.

    Parameters
    ----------
    root : xml.etree.ElementTree.Element
        The ``<robot>`` element.
    source : str
        The file name, for messages.
    prefixes : mapping of str to set of str
        For each namespace URI the document declares, the prefixes bound to it.

    Raises
    ------
    ExtensionError
        At the first element or attribute in a namespace that looks like rt70's
        (:func:`looks_like_rt70`), rt70 attribute on a standard element, rt70 element
        out of its place, or rt70 element that breaks :data:`RT70`.

    Warns
    -----
    Rt70Warning
        Once for each standard element kind and attribute :data:`URDF` does not know.
    """
    _check_namespaces_and_places(root, source, prefixes)
    _check_rt70(RT70, root, (), source)
    unknown: dict[tuple[str, str], list] = {}
    _check_urdf(URDF, root, "", (), unknown)
    for (path, attr), (trail, known, count) in unknown.items():
        also = f" (also on {count - 1} more <{path.rsplit('/', 1)[-1]}>)" if count > 1 else ""
        warn(
            f"{source}: {_where(trail)}: attribute '{attr}' is not URDF, ignored"
            f"{_suggestion(attr, known)}{also}"
        )


def _check_namespaces_and_places(
    root: ET.Element, source: str, prefixes: Mapping[str, set[str]]
) -> None:
    """Refuse what rt70 would ignore: namespaces that look like rt70's, misplaced rt70 names.

    That is an element or attribute in a look-alike namespace (:func:`looks_like_rt70`),
    an rt70 attribute on a standard element, and an rt70 element inside a standard
    element other than ``<robot>``.
    """
    judged: set[str] = {RT70_NS}  # URIs found not to look like rt70's

    def look_alike(uri: str) -> bool:
        if uri in judged:
            return False
        if looks_like_rt70(uri, prefixes.get(uri, ())):
            return True
        judged.add(uri)
        return False

    for elem in root.iter():
        uri, local = split(elem.tag)
        if uri is not None and look_alike(uri):
            raise ExtensionError(
                f"{source}: <{local}> is in the namespace '{uri}', not rt70's '{RT70_NS}': "
                f'it would be ignored; declare xmlns:rt70="{RT70_NS}"'
            )
        for key in elem.attrib:
            if not key.startswith("{"):
                continue
            kuri, klocal = split(key)
            if look_alike(kuri):
                raise ExtensionError(
                    f"{source}: {_label(elem)} attribute '{klocal}' is in the namespace "
                    f"'{kuri}', not rt70's '{RT70_NS}': it would be ignored"
                )
            if kuri == RT70_NS and uri != RT70_NS:
                raise ExtensionError(
                    f"{source}: {_label(elem)} attribute 'rt70:{klocal}': rt70 has no "
                    "attributes on standard elements; its elements are children of <robot> "
                    "(docs/urdf-extensions.md)"
                )
        if elem is root or uri == RT70_NS:
            continue
        for child in elem:
            if child.tag.startswith(_RT70):
                raise ExtensionError(
                    f"{source}: {_label(child)} inside {_label(elem)}: rt70 elements are "
                    "read only as children of <robot> (and their own children, "
                    "docs/urdf-extensions.md)"
                )


def _check_rt70(spec: Spec, elem: ET.Element, trail: tuple, source: str) -> None:
    """Enforce ``spec`` on the rt70 children of ``elem`` and, recursively, theirs.

    ``elem`` is ``<robot>`` (whose other children are standard, ``trail`` empty) or an
    rt70 element already checked itself (``trail``: it and its rt70 ancestors).
    """
    counts: dict[str, int] = {}
    for child in elem:
        found = spec.rt70_children.get(child.tag)
        if found is None:
            if trail or child.tag.startswith(_RT70):
                _refuse_child(spec, child, trail, source)
            continue
        local, kind = found
        inner = (*trail, child)
        _check_attributes(kind.spec, child, inner, source)
        _check_rt70(kind.spec, child, inner, source)
        counts[local] = counts.get(local, 0) + 1
    for local, kind in spec.children.items():
        count = counts.get(local, 0)
        if count < kind.least:
            raise ExtensionError(f"{source}: {_where(trail)} lacks <rt70:{local}>")
        if kind.most is not None and count > kind.most:
            many = "more than one" if kind.most == 1 else f"more than {kind.most}"
            raise ExtensionError(f"{source}: {_where(trail)} has {many} <rt70:{local}>")


def _check_attributes(spec: Spec, elem: ET.Element, trail: tuple, source: str) -> None:
    """Refuse an unknown attribute, text content, or a missing required attribute."""
    for key in elem.attrib:
        if key not in spec.known:
            raise ExtensionError(
                f"{source}: {_where(trail)}: unknown attribute '{_tag(key)}'"
                f"{_suggestion(split(key)[1], spec.attributes)}; known: "
                + ", ".join(spec.attributes)
            )
    if elem.text and not elem.text.isspace():
        raise ExtensionError(
            f"{source}: {_where(trail)}: text '{elem.text.strip()[:40]}' is not read: rt70 "
            "elements carry their values in attributes"
        )
    for key in spec.required:
        if key not in elem.attrib:
            what = "without a name" if key == "name" else f"lacks attribute '{key}'"
            raise ExtensionError(f"{source}: {_where(trail)} {what}")


def _refuse_child(spec: Spec, child: ET.Element, trail: tuple, source: str) -> None:
    """Refuse an unknown rt70 element kind (at the top) or child (inside an rt70 element)."""
    known = [f"rt70:{k}" for k in spec.children]
    listed = ", ".join(f"<{k}>" for k in known) or "none"
    hint = _suggestion("rt70:" + split(child.tag)[1], known, "<", ">")
    what = f"{_where(trail)}: unknown child" if trail else "unknown rt70 element"
    raise ExtensionError(f"{source}: {what} <{_tag(child.tag)}>{hint}; known: {listed}")


def _check_urdf(spec: Spec, elem: ET.Element, path: str, trail: tuple, unknown: dict) -> None:
    """Record the attributes of standard elements that ``spec`` does not know.

    ``unknown`` maps ``(element path, attribute)`` to ``[trail, known attributes,
    number of elements]``, ``trail`` leading to the first of them; attributes in a
    namespace are other tools' (rt70's were checked before).
    """
    for key in elem.attrib:
        if key not in spec.known and not key.startswith("{"):
            entry = unknown.setdefault((path or "robot", key), [trail, spec.attributes, 0])
            entry[2] += 1
    for child in elem:
        kind = spec.children.get(child.tag)
        if kind is not None:
            _check_urdf(kind.spec, child, f"{path}/{child.tag}", (*trail, child), unknown)


# --- messages --------------------------------------------------------------------------


def _suggestion(name: str, known: Iterable[str], before: str = "'", after: str = "'") -> str:
    """`` (did you mean 'x'?)`` for the known name closest to ``name``, or nothing."""
    close = difflib.get_close_matches(name, list(known), n=1, cutoff=SUGGESTION_CUTOFF)
    return f" (did you mean {before}{close[0]}{after}?)" if close else ""


def _tag(name: str) -> str:
    """An element or attribute name as written with rt70's prefix (others as parsed)."""
    uri, local = split(name)
    return f"rt70:{local}" if uri == RT70_NS else name


def _where(trail: tuple) -> str:
    """An element described by its path: ``<link name='l1'> <inertial> <mass>``."""
    return " ".join(_label(e) for e in trail) or "<robot>"


def _label(elem: ET.Element) -> str:
    """``<tag name='…'>`` (or ``<tag>``) of an element, for messages."""
    name = elem.get("name")
    return f"<{_tag(elem.tag)} name='{name}'>" if name is not None else f"<{_tag(elem.tag)}>"
