"""Scenes: a URDF file read once and turned into both sides of the cross-check."""

from __future__ import annotations

import dataclasses
import os
import warnings
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

from rt70.errors import Rt70Warning, SceneError
from rt70.guards.resources import check_massless, check_textbook
from rt70.textbook.data import Data
from rt70.textbook.massless import check_moves_mass
from rt70.textbook.model import Model, build_model
from rt70.urdf import RobotDescription, coordinate_names, read_urdf_string
from rt70.urdf.generated import expand_generated
from rt70.urdf.inertia import balanced_text
from rt70.urdf.text import prepare_text, read_source


def _scene_dir() -> Path:
    """Where the project's scenes are: ``RT70_URDF_DIR``, the installed package, or urdf/.

    A normal install ships the files of the repository's ``urdf/`` as package data
    ``rt70/scene_files/`` (pyproject.toml); in a source tree or an editable install they
    are read from ``urdf/`` beside the package.
    """
    override = os.environ.get("RT70_URDF_DIR")
    if override:
        return Path(override)
    installed = Path(__file__).resolve().parents[1] / "scene_files"
    return installed if installed.is_dir() else Path(__file__).resolve().parents[2] / "urdf"


#: Directory of the project's scenes (see :func:`_scene_dir`).
URDF_DIR = _scene_dir()


def scene_names() -> list[str]:
    """Names of all scenes in :data:`URDF_DIR` (file stems, sorted)."""
    return sorted(p.stem for p in URDF_DIR.glob("*.urdf"))


def scene_path(target: str | Path) -> Path:
    """Resolve a scene name (``rt70``, a stem in :data:`URDF_DIR`) or a URDF file path.

    Raises
    ------
    SceneError
        If ``target`` is neither an existing path nor a known scene name.
    """
    candidate = URDF_DIR / f"{target}.urdf"
    if Path(target).suffix != ".urdf" and candidate.is_file():
        return candidate
    path = Path(target)
    if path.is_dir():
        raise SceneError(f"{target}: is a directory, not a URDF file or a scene name")
    if path.exists() and not path.is_file():
        raise SceneError(f"{target}: is not a regular file (a device or a pipe?)")
    if path.suffix == ".urdf" or path.is_file():
        return path
    known = scene_names()
    where = f"known: {', '.join(known)}" if known else f"no scene files in {URDF_DIR}"
    raise SceneError(f"{target}: no such scene ({where}) and no such file")


@dataclass
class Scene:
    """One URDF scene: its description, the textbook model and the Pinocchio reference.

    Both sides take and return every per-coordinate vector and matrix in the same
    order, :attr:`coordinate_names` (the file's depth-first order,
    :func:`rt70.urdf.coordinate_names`), in one convention (a constant model, its
    work buffers, ``algorithm(model, data, q)``):
    ``reference.mass_matrix(scene.reference, scene.reference_data, q)`` and
    ``dynamics.mass_matrix(scene.textbook, scene.textbook_data, q)`` compare directly.
    ``text`` is what both sides read: the file's text as normalised by
    :func:`rt70.urdf.text.prepare_text`, with the inertias repaired on request written
    in (:func:`load_scene`).
    """

    name: str
    path: Path
    text: str
    description: RobotDescription

    @cached_property
    def textbook(self) -> Model:
        """The textbook model (:mod:`rt70.textbook`).

        Raises
        ------
        MasslessCoordinateError
            If a coordinate, or a combination of coordinates, moves no mass
            (:mod:`rt70.textbook.massless`).
        ResourceError
            If that check would not fit in this machine's memory
            (:func:`rt70.guards.resources.check_massless`).
        """
        model = build_model(self.description)
        check_massless(model.nb, model.n_full, self.description.source)
        check_moves_mass(model, self.description.source)
        return model

    @cached_property
    def textbook_data(self) -> Data:
        """Work buffers for :attr:`textbook` (refused beyond this machine's memory)."""
        model = self.textbook
        check_textbook(model.nb, model.n_full, self.description.source)
        return Data(model)

    @cached_property
    def static_kernels(self):  # -> rt70.textbook.static_kernel.StaticData | None
        """The compiled static forces' arrays (:mod:`rt70.textbook.static_kernel`), or None.

        None for a model the kernel does not cover (modal bodies, mimic joints).
        """
        from rt70.textbook.static_kernel import StaticData

        return StaticData.of(self.textbook)

    @cached_property
    def reference(self):  # -> rt70.reference.ReferenceModel (imported lazily: Pinocchio)
        """The Pinocchio reference model (:mod:`rt70.reference`)."""
        from rt70.reference import ReferenceModel

        return ReferenceModel(self.description, self.text)

    @cached_property
    def reference_data(self):  # -> rt70.reference.ReferenceData
        """Work buffers of :attr:`reference` (:class:`rt70.reference.ReferenceData`)."""
        from rt70.reference import ReferenceData

        return ReferenceData(self.reference)

    @cached_property
    def coordinate_names(self) -> list[str]:
        """Names of the generalised coordinates, in the order of every result."""
        return coordinate_names(self.description)


def load_scene(target: str | Path, balance_inertia: bool = False) -> Scene:
    """Read a scene by name or path (see :func:`scene_path`), validating the URDF.

    With ``balance_inertia`` the impossible rotational inertias of moving links are
    repaired (:func:`rt70.urdf.inertia.balanced_moments`) instead of refused, the same on
    both sides: the repaired values are written into the text Pinocchio parses.
    """
    path = scene_path(target)
    return _scene(path.stem, path, read_source(path), str(path), balance_inertia)


def scene_from_text(
    text: str, name: str = "<string>", balance_inertia: bool = False, source: str | None = None
) -> Scene:
    """Build a scene from URDF text (generated models, tests, a sweep's workers).

    Parameters
    ----------
    text : str
        The URDF text.
    name : str
        The scene's name; labels messages when there is no ``source``.
    balance_inertia : bool
        Repair impossible rotational inertias of moving links instead of refusing them
        (as :func:`load_scene`).
    source : str, optional
        The file the text was read from: labels messages about its content.
    """
    return _scene(name, Path(source or name), text, source or name, balance_inertia)


def _scene(name: str, path: Path, text: str, source: str, balance_inertia: bool) -> Scene:
    text = expand_generated(prepare_text(text, source), source)
    desc = read_urdf_string(text, source=source, balance_inertia=balance_inertia)
    if desc.inertia_repairs:  # both sides read the repaired text, warned about once
        text = balanced_text(text, desc.inertia_repairs)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", Rt70Warning)
            repaired = read_urdf_string(text, source=source)
        desc = dataclasses.replace(repaired, inertia_repairs=desc.inertia_repairs)
    return Scene(name, path, text, desc)


def require_coordinates(scene: Scene) -> None:
    """Refuse a scene with no generalised coordinate: there would be nothing to check.

    Raises
    ------
    SceneError
        If every joint of the scene is fixed (or it has none).
    """
    if scene.textbook.nv == 0:
        raise SceneError(
            f"{scene.path}: the model has no degree of freedom (no moving joint): nothing to check"
        )
