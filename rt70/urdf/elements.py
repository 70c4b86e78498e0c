"""What every element reader of a URDF file needs: numbers, names, links, joints, errors.

:class:`ElementReader` is the part of the reader (:mod:`rt70.urdf.reader`) that the readers
of the extension elements (:mod:`rt70.urdf.extensions`, :mod:`rt70.urdf.drives`,
:mod:`rt70.urdf.no_slip`, :mod:`rt70.urdf.wind`) use: each error it raises names the
file, the element and the attribute (docs/urdf-reader.md).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np

from rt70.errors import ExtensionError, MagnitudeError, NonFiniteError, UrdfError
from rt70.urdf.description import Joint, RobotDescription
from rt70.urdf.text import RT70_NS

#: Relative tolerance of a six-axis element's 6 × 6 matrices: asymmetry against the
#: largest entry, a negative eigenvalue against the largest eigenvalue
#: (:meth:`ElementReader.gain_matrices`).
GAIN_MATRIX_RTOL = 1e-9
#: The attributes of an element's gains, in the order they are returned.
GAINS = ("stiffness", "damping")

#: Largest magnitude of any number rt70 reads from a URDF (docs/urdf-reader.md): a product
#: of ten such numbers stays below the largest double (1.8e308), far more factors than
#: any term of the equations of motion multiplies, so no evaluation can overflow.
MAX_MAGNITUDE = 1e30

#: Joint types with one coordinate (the only ones a ``<mimic>`` or a joint spring may use).
ONE_DOF_JOINT_TYPES = ("revolute", "continuous", "prismatic")

#: The zero vector an absent ``<origin>`` stands for.
ZERO3 = np.zeros(3)


class ElementReader:
    """Reads the attributes of the elements of one file, with the file's name for messages.

    Parameters
    ----------
    source : str
        The file (or the text's label) that every error names.
    """

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, cls: type[UrdfError], what: str) -> UrdfError:
        """The error ``cls`` with the file's name in front of ``what`` (to be raised)."""
        return cls(f"{self.source}: {what}")

    def numbers(
        self, elem: ET.Element, attr: str, count: int, default=None, owner: str = ""
    ) -> np.ndarray:
        """The ``count`` numbers of attribute ``attr`` of ``elem``.

        Parameters
        ----------
        elem : xml.etree.ElementTree.Element
            The element that carries the attribute.
        attr : str
            The attribute's name.
        count : int
            How many numbers the attribute must hold.
        default : array_like, optional
            The value of an absent attribute; None: the attribute is required.
        owner : str, optional
            The element that holds ``elem``, for messages (``<joint name='j'>``).

        Raises
        ------
        UrdfError
            (ExtensionError for an rt70 element) if the attribute is missing and required,
            is not a list of ``count`` numbers; NonFiniteError for a NaN or infinity;
            MagnitudeError beyond :data:`MAX_MAGNITUDE`.
        """
        raw = elem.get(attr)
        if raw is not None:
            try:
                values = [float(tok) for tok in raw.split()]
            except ValueError:
                values = []
            if len(values) == count and all(abs(v) <= MAX_MAGNITUDE for v in values):
                return np.array(values, dtype=float)  # NaN fails the comparison too
        elif default is not None:
            return np.array(default, dtype=float)
        raise self._bad_numbers(elem, attr, count, owner)

    def _bad_numbers(self, elem: ET.Element, attr: str, count: int, owner: str) -> UrdfError:
        """The error of an attribute that :meth:`numbers` refused (to be raised)."""
        raw = elem.get(attr)
        tag = f"{owner} <{tag_of(elem)}" if owner else f"<{tag_of(elem)}"
        bad = ExtensionError if tag_of(elem).startswith("rt70:") else UrdfError
        if raw is None:
            return self.fail(bad, f"{tag}> lacks attribute '{attr}'")
        try:
            values = [float(tok) for tok in raw.split()]
        except ValueError:
            return self.fail(bad, f'{tag} {attr}="{raw}">: not a list of numbers')
        if len(values) != count:
            return self.fail(
                bad, f'{tag} {attr}="{raw}">: expected {count} numbers, got {len(values)}'
            )
        if not all(math.isfinite(v) for v in values):
            return self.fail(NonFiniteError, f'{tag} {attr}="{raw}">: NaN or infinite value')
        return self.fail(
            MagnitudeError,
            f'{tag} {attr}="{raw}">: magnitude above {MAX_MAGNITUDE:g}, the largest number '
            "rt70 reads (docs/urdf-reader.md)",
        )

    def number(
        self, elem: ET.Element, attr: str, default: float | None = None, owner: str = ""
    ) -> float:
        """The one number of attribute ``attr`` (:meth:`numbers` with ``count`` = 1).

        Parameters
        ----------
        elem : xml.etree.ElementTree.Element
            The element that carries the attribute.
        attr : str
            The attribute's name.
        default : float, optional
            The value of an absent attribute; None: the attribute is required.
        owner : str, optional
            The element that holds ``elem``, for messages.
        """
        value = self.numbers(elem, attr, 1, None if default is None else [default], owner)
        return float(value[0])

    def name_of(self, elem: ET.Element) -> str:
        """The element's ``name`` attribute; an element without one is an error."""
        name = elem.get("name")
        if not name:
            bad = ExtensionError if tag_of(elem).startswith("rt70:") else UrdfError
            raise self.fail(bad, f"<{tag_of(elem)}> without a name")
        return name

    def origin(self, elem: ET.Element, owner: str) -> tuple[np.ndarray, np.ndarray]:
        """``(xyz, rpy)`` of the element's ``<origin>``, zeros where it is absent."""
        o = elem.find("origin")
        if o is None:
            return ZERO3.copy(), ZERO3.copy()
        return self.numbers(o, "xyz", 3, ZERO3, owner), self.numbers(o, "rpy", 3, ZERO3, owner)

    def link_ref(self, elem: ET.Element, attr: str, desc: RobotDescription, where: str) -> str:
        """The link that attribute ``attr`` names; a missing or unknown link is an error.

        Parameters
        ----------
        elem : xml.etree.ElementTree.Element
            The element that names the link.
        attr : str
            The attribute that holds the link's name (``link``, ``parent``, ``stator``).
        desc : RobotDescription
            The description whose links the name must be one of.
        where : str
            The element as messages name it (``<rt70:bushing name='b'>``).
        """
        link = elem.get(attr)
        if not link:
            raise self.fail(ExtensionError, f"{where} lacks attribute '{attr}'")
        if link not in desc.links:
            raise self.fail(ExtensionError, f"{where}: link '{link}' does not exist")
        return link

    def gains(self, elem: ET.Element, count: int, where: str) -> tuple[np.ndarray, np.ndarray]:
        """``(stiffness, damping)``, ``count`` numbers each (zero when absent, never negative).

        Parameters
        ----------
        elem : xml.etree.ElementTree.Element
            The element with the ``stiffness`` and ``damping`` attributes.
        count : int
            How many numbers each holds (1 for a joint spring; a six-axis element's are
            read by :meth:`gain_matrices`).
        where : str
            The element as messages name it.
        """
        stiffness, damping = (self._nonnegative(elem, a, count, where) for a in GAINS)
        return stiffness, damping

    def _nonnegative(self, elem: ET.Element, attr: str, count: int, where: str) -> np.ndarray:
        """The ``count`` numbers of gain ``attr`` (zero when absent), none negative."""
        values = self.numbers(elem, attr, count, np.zeros(count))
        if np.any(values < 0.0):
            raise self.fail(ExtensionError, f"{where}: negative {attr}")
        return values

    def gain_matrices(self, elem: ET.Element, where: str) -> tuple[np.ndarray, np.ndarray]:
        """``(C, D)`` of a six-axis element: 6 numbers (the diagonal) or 36 (the matrix).

        The 36 numbers are the symmetric positive semi-definite 6 × 6 matrix row by row,
        in the order x, y, z, rx, ry, rz of the element's deformation. Symmetry is
        checked to :data:`GAIN_MATRIX_RTOL` of the largest entry (then the mean of the
        two triangles is kept) and semi-definiteness to the same fraction of the largest
        eigenvalue: a file printed with ten digits passes, a sign slip does not.

        Parameters
        ----------
        elem : xml.etree.ElementTree.Element
            The element with the ``stiffness`` and ``damping`` attributes.
        where : str
            The element as messages name it.

        Returns
        -------
        (numpy.ndarray, numpy.ndarray)
            C (N/m, N·m/rad and N/rad off the diagonal blocks) and D (the same per
            second), shape (6, 6) each; zero where the attribute is absent.
        """
        out = []
        for attr in GAINS:
            raw = elem.get(attr)
            count = len(raw.split()) if raw is not None else 6
            if count == 6:
                out.append(np.diag(self._nonnegative(elem, attr, 6, where)))
            elif count == 36:
                matrix = self.numbers(elem, attr, 36).reshape(6, 6)
                out.append(self._semidefinite(matrix, attr, where))
            else:
                raise self.fail(
                    ExtensionError,
                    f'{where} {attr}="{raw}": expected 6 numbers (the diagonal) or 36 (the '
                    f"symmetric 6×6 matrix, row by row), got {count}",
                )
        return out[0], out[1]

    def _semidefinite(self, matrix: np.ndarray, attr: str, where: str) -> np.ndarray:
        """``matrix`` checked symmetric and positive semi-definite, symmetrised."""
        scale = float(np.max(np.abs(matrix)))
        asym = np.abs(matrix - matrix.T)
        if np.max(asym) > GAIN_MATRIX_RTOL * scale:
            i, j = np.unravel_index(int(np.argmax(asym)), asym.shape)
            raise self.fail(
                ExtensionError,
                f"{where}: {attr} is not symmetric: entry ({i + 1}, {j + 1}) is "
                f"{matrix[i, j]:g}, entry ({j + 1}, {i + 1}) is {matrix[j, i]:g}",
            )
        symmetric = 0.5 * (matrix + matrix.T)
        eigenvalues = np.linalg.eigvalsh(symmetric)
        if eigenvalues[0] < -GAIN_MATRIX_RTOL * max(float(eigenvalues[-1]), 0.0):
            raise self.fail(
                ExtensionError,
                f"{where}: {attr} is not positive semi-definite: its smallest eigenvalue is "
                f"{eigenvalues[0]:g} (the largest {eigenvalues[-1]:g}): the element would "
                "give energy instead of storing it",
            )
        return symmetric

    def one_dof_joint(self, elem: ET.Element, joints: dict[str, Joint], where: str) -> Joint:
        """The 1-DOF joint an extension element names in its ``joint`` attribute.

        Parameters
        ----------
        elem : xml.etree.ElementTree.Element
            The extension element.
        joints : dict of str to Joint
            The file's joints by name.
        where : str
            The element as messages name it.

        Raises
        ------
        ExtensionError
            If the attribute is missing, names no joint, or a joint that is not 1-DOF.
        """
        jname = elem.get("joint")
        if not jname:
            raise self.fail(ExtensionError, f"{where} lacks attribute 'joint'")
        joint = joints.get(jname)
        if joint is None:
            raise self.fail(ExtensionError, f"{where}: joint '{jname}' does not exist")
        if joint.type not in ONE_DOF_JOINT_TYPES:
            raise self.fail(
                ExtensionError, f"{where}: joint '{jname}' is {joint.type}, not a 1-DOF joint"
            )
        return joint


def tag_of(elem: ET.Element) -> str:
    """The element's tag as written in a file: ``rt70:name`` for rt70's namespace."""
    tag = elem.tag
    if tag.startswith("{" + RT70_NS + "}"):
        return "rt70:" + tag[len(RT70_NS) + 2 :]
    return tag
