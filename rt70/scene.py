"""Scenes: a URDF file read once and turned into both sides of the cross-check."""

from __future__ import annotations

import os
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from rt70.errors import SceneError
from rt70.resources import check_textbook
from rt70.textbook.data import Data
from rt70.textbook.model import Model, build_model
from rt70.urdf import RobotDescription, read_urdf_string
from rt70.urdf.reader import read_source

#: Directory of the project's scenes (``urdf/`` beside the package; ``RT70_URDF_DIR`` overrides).
URDF_DIR = Path(os.environ.get("RT70_URDF_DIR", Path(__file__).resolve().parents[1] / "urdf"))


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
    raise SceneError(
        f"{target}: no such scene (known: {', '.join(scene_names())}) and no such file"
    )


@dataclass
class Scene:
    """One URDF scene: its description, the textbook model and the Pinocchio reference.

    ``perm[i]`` is Pinocchio's velocity index of the textbook's coordinate i, so
    ``x_pin[perm] = x_textbook`` for any per-coordinate vector.
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
        """Work buffers for :attr:`textbook` (refused beyond this machine's memory)."""
        model = self.textbook
        check_textbook(model.nb, model.n_full, self.description.source)
        return Data(model)

    @cached_property
    def reference(self):  # -> rt70.reference.ReferenceModel (imported lazily: Pinocchio)
        """The Pinocchio reference model (:mod:`rt70.reference`)."""
        from rt70.reference import ReferenceModel

        return ReferenceModel(self.description, self.text)

    @cached_property
    def perm(self) -> np.ndarray:
        """Pinocchio velocity index of each textbook coordinate."""
        return self.reference.coordinate_index(self.textbook.coordinate_names)

    def to_reference(self, x: np.ndarray) -> np.ndarray:
        """Map a textbook-ordered coordinate vector to Pinocchio's order."""
        out = np.zeros(self.reference.nv)
        out[self.perm] = x
        return out


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
