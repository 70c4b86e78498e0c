"""Scenes: a URDF file read once and turned into both sides of the cross-check."""

from __future__ import annotations

import dataclasses
import os
import warnings
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from rt70.errors import Rt70Warning, SceneError
from rt70.textbook.data import Data
from rt70.textbook.massless import check_moves_mass
from rt70.textbook.model import Model, build_model
from rt70.urdf import RobotDescription, read_urdf_string
from rt70.urdf.reader import balanced_text, prepare_text, read_source

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
    ``x_pin[perm] = x_textbook`` for any per-coordinate vector. ``text`` is what both
    sides read: the file's text as normalised by :func:`rt70.urdf.reader.prepare_text`,
    with the inertias repaired on request written in (:func:`load_scene`).
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
        """
        model = build_model(self.description)
        check_moves_mass(model, self.description.source)
        return model

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
    def perm(self) -> np.ndarray:
        """Pinocchio velocity index of each textbook coordinate."""
        return self.reference.coordinate_index(self.textbook.coordinate_names)

    def to_reference(self, x: np.ndarray) -> np.ndarray:
        """Map a textbook-ordered coordinate vector to Pinocchio's order."""
        out = np.zeros(self.reference.nv)
        out[self.perm] = x
        return out


def load_scene(target: str | Path, balance_inertia: bool = False) -> Scene:
    """Read a scene by name or path (see :func:`scene_path`), validating the URDF.

    With ``balance_inertia`` the impossible rotational inertias of moving links are
    repaired (:func:`rt70.urdf.reader.balanced_moments`) instead of refused, the same on
    both sides: the repaired values are written into the text Pinocchio parses.
    """
    path = scene_path(target)
    return _scene(path.stem, path, read_source(path), str(path), balance_inertia)


def scene_from_text(text: str, name: str = "<string>", balance_inertia: bool = False) -> Scene:
    """Build a scene from URDF text (generated models, tests); ``name`` labels messages."""
    return _scene(name, Path(name), text, name, balance_inertia)


def _scene(name: str, path: Path, text: str, source: str, balance_inertia: bool) -> Scene:
    text = prepare_text(text, source)
    desc = read_urdf_string(text, source=source, balance_inertia=balance_inertia)
    if desc.inertia_repairs:  # both sides read the repaired text, warned about once
        text = balanced_text(text, desc.inertia_repairs)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", Rt70Warning)
            repaired = read_urdf_string(text, source=source)
        desc = dataclasses.replace(repaired, inertia_repairs=desc.inertia_repairs)
    return Scene(name, path, text, desc)
