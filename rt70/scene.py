"""Scenes: a URDF file read once and turned into both sides of the cross-check."""

from __future__ import annotations

import os
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

from rt70.errors import SceneError
from rt70.textbook.data import Data
from rt70.textbook.model import Model, build_model
from rt70.urdf import RobotDescription, coordinate_names, read_urdf_string
from rt70.urdf.reader import read_source


def _scene_dir() -> Path:
    """Where the project's scenes are: ``RT70_URDF_DIR``, the installed package, or urdf/.

    A normal install ships the files of the repository's ``urdf/`` as package data
    ``rt70/scene_files/`` (pyproject.toml); in a source tree or an editable install they
    are read from ``urdf/`` beside the package.
    """
    override = os.environ.get("RT70_URDF_DIR")
    if override:
        return Path(override)
    installed = Path(__file__).resolve().parent / "scene_files"
    return installed if installed.is_dir() else Path(__file__).resolve().parents[1] / "urdf"


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
    :func:`rt70.urdf.coordinate_names`): ``scene.reference.mass_matrix(q)`` and
    ``dynamics.mass_matrix(scene.textbook, scene.textbook_data, q)`` compare directly.
    """

    name: str
    path: Path
    text: str
    description: RobotDescription

    @cached_property
    def textbook(self) -> Model:
        """The textbook model (:mod:`rt70.textbook`)."""
        return build_model(self.description)

    @cached_property
    def textbook_data(self) -> Data:
        """Work buffers for :attr:`textbook`."""
        return Data(self.textbook)

    @cached_property
    def reference(self):  # -> rt70.reference.ReferenceModel (imported lazily: Pinocchio)
        """The Pinocchio reference model (:mod:`rt70.reference`)."""
        from rt70.reference import ReferenceModel

        return ReferenceModel(self.description, self.text)

    @cached_property
    def coordinate_names(self) -> list[str]:
        """Names of the generalised coordinates, in the order of every result."""
        return coordinate_names(self.description)


def load_scene(target: str | Path) -> Scene:
    """Read a scene by name or path (see :func:`scene_path`), validating the URDF."""
    path = scene_path(target)
    text = read_source(path)
    desc = read_urdf_string(text, source=str(path))
    return Scene(path.stem, path, text, desc)


def scene_from_text(text: str, name: str = "<string>") -> Scene:
    """Build a scene from URDF text (generated models, tests); ``name`` labels messages."""
    desc = read_urdf_string(text, source=name)
    return Scene(name, Path(name), text, desc)


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
