"""The modal body file, ``rt70-modal/1``: a flexible body as nodes, masses and mode shapes.

One job: the format's one reader and writer (docs/fe-models.md, "The modal body file").
A NumPy ``.npz`` archive with

=============== ========= ===========================================================
key             shape     meaning
=============== ========= ===========================================================
format          ()        the string ``rt70-modal/1``
nodes           (N, 3)    the nodes ``x_n`` in the body frame (the link's frame), m
masses          (N,)      their lumped translational masses ``m_n``, kg (≥ 0)
shapes          (N, 3, k) ``Φ_n``: each node's displacement per unit modal coordinate
stiffness       (k, k)    the modal stiffness ``K_η`` (symmetric, positive semidefinite)
damping         (k, k)    optional: the modal damping ``D_η`` (symmetric, psd)
rotations       (N, 3, k) optional: each node's small rotation per unit modal coordinate
                          (a rotation vector in the body frame; used only where a link is
                          attached to the node, ``<rt70:interface>``)
edges           (E, 2)    optional: node index pairs drawn as lines (the FE mesh's edges)
source          ()        optional: where the body came from (a free text)
surface_nodes   (S,)      optional, with the next two: the reflecting surface's nodes
surface_weights (S,)      their shares of the aperture (m², > 0): the best fit's weights
focal_length    ()        F of the surface's paraboloid ``z = (x² + y²)/(4F)``, m
=============== ========= ===========================================================

The body is ``r_n = x_n + Φ_n η`` (rt70.textbook.flexible): the nodes' masses are
lumped and translational, the modes are shapes in the body frame, clamped to it where
the body is attached (fixed-interface modes of a Craig–Bampton reduction, docs/fe-models.md).
The reader checks every array (shapes, finite numbers, symmetry, definiteness, a
positive modal mass) and raises :class:`~rt70.errors.ExtensionError` naming the file.
"""

from __future__ import annotations

import os
import tempfile
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rt70.errors import ExtensionError
from rt70.urdf.modal_record import Surface

#: The format's name, stored in the file.
FORMAT = "rt70-modal/1"

#: A matrix is symmetric when ``|X − Xᵀ| ≤ SYMMETRY_RTOL · max |X|`` (rounding of a
#: product ``Φᵀ K Φ`` written out, not a modelling choice).
SYMMETRY_RTOL = 1e-9

#: A symmetric matrix is positive semidefinite when its lowest eigenvalue is above
#: ``−DEFINITE_RTOL · max |λ|`` (rounding of the eigensolver on rigid modes).
DEFINITE_RTOL = 1e-9

#: A surface node lies on its paraboloid when ``|z − r²/(4F)| ≤ SURFACE_RTOL · r_max``
#: (a file written from a design, not a measured surface: rounding of its coordinates).
SURFACE_RTOL = 1e-9

#: The three keys of a reflecting surface, all or none.
SURFACE_KEYS = ("surface_nodes", "surface_weights", "focal_length")


@dataclass(frozen=True)
class ModalArrays:
    """The arrays of a modal body file (module docstring), checked.

    Attributes
    ----------
    nodes : numpy.ndarray, shape (N, 3)
    masses : numpy.ndarray, shape (N,)
    shapes : numpy.ndarray, shape (N, 3, k)
    stiffness : numpy.ndarray, shape (k, k)
    damping : numpy.ndarray, shape (k, k)
        Zero when the file has none.
    source : str
    edges : numpy.ndarray of int, shape (E, 2)
        Node index pairs drawn as lines (none when the file has none).
    rotations : numpy.ndarray or None, shape (N, 3, k)
        The nodes' small rotations per unit modal coordinate; None when the file has none
        (a link attached to a node then keeps the body frame's orientation).
    surface : rt70.urdf.modal_record.Surface or None
        The reflecting surface (its nodes, weights and F); None when the file has none.
    """

    nodes: np.ndarray
    masses: np.ndarray
    shapes: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    source: str = ""
    edges: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), dtype=np.int64))
    rotations: np.ndarray | None = None
    surface: Surface | None = None

    @property
    def modes(self) -> int:
        """k, the number of mode shapes."""
        return self.shapes.shape[2]

    @property
    def modal_mass(self) -> np.ndarray:
        """``M_ηη = Σ m_n Φ_nᵀ Φ_n``, (k, k)."""
        return modal_mass(self.masses, self.shapes)


def modal_mass(masses: np.ndarray, shapes: np.ndarray) -> np.ndarray:
    """``M_ηη = Σ m_n Φ_nᵀ Φ_n`` of lumped masses (N,) and shapes (N, 3, k), (k, k)."""
    return np.einsum("n,nai,naj->ij", masses, shapes, shapes)


def write_modal_file(path: str | Path, body: ModalArrays) -> Path:
    """Write ``body`` to ``path`` (an ``.npz``), atomically: a finished file or none.

    Parameters
    ----------
    path : str or pathlib.Path
        The file to write; its directory must exist.
    body : ModalArrays
        The body; checked as the reader checks it before anything is written.
    """
    path = Path(path)
    check_arrays(body, str(path))
    arrays = {
        "format": np.array(FORMAT),
        "nodes": body.nodes,
        "masses": body.masses,
        "shapes": body.shapes,
        "stiffness": body.stiffness,
        "damping": body.damping,
        "edges": body.edges,
        "source": np.array(body.source),
    }
    if body.rotations is not None:
        arrays["rotations"] = body.rotations
    if body.surface is not None:
        arrays["surface_nodes"] = np.asarray(body.surface.nodes, dtype=np.int64)
        arrays["surface_weights"] = body.surface.weights
        arrays["focal_length"] = np.array(float(body.surface.focal_length))
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".npz")
    try:
        with os.fdopen(fd, "wb") as handle, zipfile.ZipFile(handle, "w") as archive:
            for key, array in arrays.items():  # a fixed date: the same body, the same bytes
                info = zipfile.ZipInfo(f"{key}.npy", date_time=(1980, 1, 1, 0, 0, 0))
                with archive.open(info, "w") as member:
                    np.lib.format.write_array(member, np.asarray(array), allow_pickle=False)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def read_modal_file(path: str | Path, where: str) -> ModalArrays:
    """The checked arrays of the modal body file ``path``.

    Parameters
    ----------
    path : str or pathlib.Path
        The ``.npz`` file.
    where : str
        The start of every message (the URDF file and element that name the file).

    Raises
    ------
    ExtensionError
        If the file is missing or unreadable, of another format, or an array is missing,
        of the wrong shape, not finite, not symmetric or not semidefinite, or a mode
        moves no mass.
    """
    try:
        with np.load(path, allow_pickle=False) as archive:
            arrays = {key: archive[key] for key in archive.files}
    except FileNotFoundError:
        raise ExtensionError(f"{where}: modal body file '{path}' not found") from None
    except (OSError, ValueError, zipfile.BadZipFile) as exc:
        raise ExtensionError(f"{where}: '{path}' is not a readable .npz file ({exc})") from None
    found = str(arrays.get("format", ""))
    if found != FORMAT:
        raise ExtensionError(f"{where}: '{path}' has format '{found}', expected '{FORMAT}'")
    for key in ("nodes", "masses", "shapes", "stiffness"):
        if key not in arrays:
            raise ExtensionError(f"{where}: '{path}' has no array '{key}'")
    shapes = np.asarray(arrays["shapes"], dtype=float)
    k = shapes.shape[2] if shapes.ndim == 3 else 0
    body = ModalArrays(
        nodes=np.asarray(arrays["nodes"], dtype=float),
        masses=np.asarray(arrays["masses"], dtype=float),
        shapes=shapes,
        stiffness=np.asarray(arrays["stiffness"], dtype=float),
        damping=np.asarray(arrays.get("damping", np.zeros((k, k))), dtype=float),
        source=str(arrays.get("source", "")),
        edges=np.asarray(arrays.get("edges", np.zeros((0, 2))), dtype=np.int64),
        rotations=np.asarray(arrays["rotations"], dtype=float) if "rotations" in arrays else None,
        surface=_surface(arrays, f"{where}: '{path}'"),
    )
    check_arrays(body, f"{where}: '{path}'")
    return body


def _surface(arrays: dict, where: str) -> Surface | None:
    """The file's :class:`Surface` from its three keys (all or none), or None."""
    present = [key for key in SURFACE_KEYS if key in arrays]
    if not present:
        return None
    if len(present) < len(SURFACE_KEYS):
        missing = ", ".join(k for k in SURFACE_KEYS if k not in arrays)
        raise ExtensionError(
            f"{where}: a surface needs {', '.join(SURFACE_KEYS)}; {missing} missing"
        )
    nodes = np.asarray(arrays["surface_nodes"])
    if nodes.dtype.kind not in "iu":
        raise ExtensionError(f"{where}: surface_nodes must be integers, not {nodes.dtype}")
    F = np.asarray(arrays["focal_length"], dtype=float)
    focal_length = float(F) if F.shape == () else float("nan")  # refused by check_surface
    weights = np.asarray(arrays["surface_weights"], dtype=float)
    return Surface(nodes.astype(np.int64), weights, focal_length)


def check_surface(surface: Surface, nodes: np.ndarray, where: str) -> None:
    """Refuse a surface whose nodes, weights or F are wrong (names ``where`` first).

    Parameters
    ----------
    surface : rt70.urdf.modal_record.Surface
        The surface.
    nodes : numpy.ndarray, shape (N, 3)
        The body's nodes in its frame, m.
    where : str
        The start of every message.
    """
    n = nodes.shape[0]
    idx, weights, F = surface.nodes, surface.weights, surface.focal_length
    if idx.ndim != 1 or idx.size < 6:
        raise ExtensionError(f"{where}: surface_nodes has shape {idx.shape}, expected (S,), S ≥ 6")
    if idx.min() < 0 or idx.max() >= n or np.unique(idx).size != idx.size:
        raise ExtensionError(f"{where}: surface_nodes must be distinct nodes of the {n}")
    if weights.shape != idx.shape:
        raise ExtensionError(
            f"{where}: surface_weights has shape {weights.shape}, expected {idx.shape}"
        )
    if not (np.all(np.isfinite(weights)) and np.all(weights > 0.0)):
        raise ExtensionError(f"{where}: surface_weights must be finite and > 0")
    if not (np.isfinite(F) and F > 0.0):
        raise ExtensionError(f"{where}: focal_length must be one finite number > 0 (m)")
    x = nodes[idx]
    r2 = x[:, 0] ** 2 + x[:, 1] ** 2
    off = np.abs(x[:, 2] - r2 / (4.0 * F))
    worst = int(np.argmax(off))
    if off[worst] > SURFACE_RTOL * max(float(np.sqrt(r2.max())), F):
        raise ExtensionError(
            f"{where}: surface node {int(idx[worst])} is {off[worst]:.3g} m off the "
            f"paraboloid z = (x² + y²)/(4F), F = {F:g} m (vertex at the body frame's origin)"
        )


def check_arrays(body: ModalArrays, where: str) -> None:
    """Raise :class:`~rt70.errors.ExtensionError` (``where`` first) unless ``body`` is sound."""
    n = body.nodes.shape[0] if body.nodes.ndim == 2 else -1
    if body.nodes.shape != (n, 3) or n < 1:
        raise ExtensionError(f"{where}: nodes has shape {body.nodes.shape}, expected (N, 3)")
    k = body.shapes.shape[2] if body.shapes.ndim == 3 else 0
    expected = {
        "masses": (body.masses, (n,)),
        "shapes": (body.shapes, (n, 3, k)),
        "stiffness": (body.stiffness, (k, k)),
        "damping": (body.damping, (k, k)),
    }
    if body.rotations is not None:
        expected["rotations"] = (body.rotations, (n, 3, k))
    if k < 1:
        raise ExtensionError(f"{where}: shapes has shape {body.shapes.shape}, expected (N, 3, k)")
    for key, (array, shape) in expected.items():
        if array.shape != shape:
            raise ExtensionError(f"{where}: {key} has shape {array.shape}, expected {shape}")
    for key, array in (("nodes", body.nodes), *((key, a) for key, (a, _) in expected.items())):
        if not np.all(np.isfinite(array)):
            raise ExtensionError(f"{where}: {key} has NaN or infinite entries")
    edges = body.edges
    if edges.ndim != 2 or edges.shape[1] != 2:
        raise ExtensionError(f"{where}: edges has shape {edges.shape}, expected (E, 2)")
    if edges.size and (edges.min() < 0 or edges.max() >= n or np.any(edges[:, 0] == edges[:, 1])):
        raise ExtensionError(f"{where}: edges must join two different nodes of the {n}")
    if np.any(body.masses < 0.0) or not body.masses.sum() > 0.0:
        raise ExtensionError(f"{where}: masses must be ≥ 0 with a positive total")
    for key in ("stiffness", "damping"):
        _check_semidefinite(getattr(body, key), f"{where}: {key}")
    if body.surface is not None:
        check_surface(body.surface, body.nodes, where)
    eigenvalues = np.linalg.eigvalsh(body.modal_mass)
    if not eigenvalues[0] > DEFINITE_RTOL * eigenvalues[-1]:
        raise ExtensionError(
            f"{where}: the modal mass Σ m Φᵀ Φ is singular: a mode (or a combination of "
            "modes) moves no mass"
        )


def _check_semidefinite(matrix: np.ndarray, where: str) -> None:
    scale = float(np.max(np.abs(matrix), initial=0.0))
    if np.max(np.abs(matrix - matrix.T), initial=0.0) > SYMMETRY_RTOL * scale:
        raise ExtensionError(f"{where} is not symmetric")
    if scale > 0.0 and np.linalg.eigvalsh(matrix)[0] < -DEFINITE_RTOL * scale:
        raise ExtensionError(f"{where} is not positive semidefinite")
