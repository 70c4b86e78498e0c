"""rt70's neutral finite-element format: sparse M and K with their nodes, DOF map and interfaces.

One ``.npz`` file (numpy's zip of arrays, read without pickle) holds what a structural
model needs to become a flexible body (docs/fe-models.md):

- ``format``: ``"rt70-fe/1"``;
- ``M_*``, ``K_*``: the mass (kg, kg·m, kg·m²) and stiffness (N/m, N/rad, N·m/rad)
  matrices;
- ``node_ids`` (n,) and ``node_xyz`` (n, 3): the FE program's node numbers and the
  nodes' positions, m;
- ``dof_node``, ``dof_comp`` (N,): the node and the component of each matrix row —
  1–3 translations x, y, z (m), 4–6 rotations about x, y, z (rad), 0 for a scalar point
  (a modal coordinate of a reduced model: its node has no position, ``node_xyz`` NaN);
- ``interface_names``, ``interface_nodes`` (k,): the named interface nodes.

``M_*`` and ``K_*`` are the ``data``, ``indices``, ``indptr`` and ``shape`` of a
:class:`scipy.sparse.csr_array` each. SI units throughout. :func:`read` checks what it
reads (shapes, symmetry, the DOF map, the interface nodes) and names the file and the
fault; :func:`write` writes atomically.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from rt70.errors import Rt70Error
from rt70.guards.atomic import atomic_write

#: The ``format`` entry of a file this module writes and reads.
FORMAT = "rt70-fe/1"
#: Asymmetry of M or K tolerated, against the matrix's largest entry (rounding of an
#: exported file); beyond it the file is refused.
SYMMETRY_RTOL = 1e-9
#: Names of the components of a node's six degrees of freedom, 1 to 6.
COMPONENTS = ("x", "y", "z", "rx", "ry", "rz")


class FEModelError(Rt70Error):
    """A finite-element model file that cannot be read as it is (its path and the fault)."""


@dataclass(frozen=True, eq=False)
class FEModel:
    """A linear finite-element model: ``M ü + K u = f`` on its degrees of freedom.

    Attributes
    ----------
    M, K : scipy.sparse.csr_array, shape (N, N)
        Mass (kg, kg·m, kg·m²) and stiffness (N/m, N/rad, N·m/rad), symmetric.
    node_ids : numpy.ndarray, shape (n,)
        The FE program's node numbers.
    node_xyz : numpy.ndarray, shape (n, 3)
        Node positions, m.
    dof_node, dof_comp : numpy.ndarray, shape (N,)
        Node number and component (1–6: x, y, z, rx, ry, rz; 0: a scalar point) of each row.
    interfaces : dict of str to int
        Named interface nodes (where the body attaches to others), node numbers.
    name : str
        Where the model came from, for messages.
    """

    M: sp.csr_array
    K: sp.csr_array
    node_ids: np.ndarray
    node_xyz: np.ndarray
    dof_node: np.ndarray
    dof_comp: np.ndarray
    interfaces: dict[str, int] = field(default_factory=dict)
    name: str = "fe model"

    def __post_init__(self) -> None:
        check(self)

    @property
    def n_dofs(self) -> int:
        """Number of degrees of freedom N."""
        return int(self.M.shape[0])

    def dofs_of(self, node: int) -> np.ndarray:
        """Row indices of a node's degrees of freedom, in component order."""
        rows = np.flatnonzero(self.dof_node == node)
        return rows[np.argsort(self.dof_comp[rows])]

    def dof_labels(self) -> list[str]:
        """``"node 12 x"``, … for every row."""
        return [
            f"node {n} {COMPONENTS[c - 1] if c else 'scalar'}"
            for n, c in zip(self.dof_node.tolist(), self.dof_comp.tolist(), strict=True)
        ]


def check(model: FEModel) -> None:
    """Refuse an inconsistent model, naming it and the fault.

    Raises
    ------
    FEModelError
        Shapes that do not agree, non-finite entries, M or K not symmetric (to
        :data:`SYMMETRY_RTOL`), a negative diagonal of M, a DOF on a node that is not in
        the node table, a component outside 0–6, a node's component listed twice, an
        interface node that is not in the table.
    """
    where = model.name
    n_dofs = model.M.shape[0]
    for label, matrix in (("M", model.M), ("K", model.K)):
        if matrix.shape != (n_dofs, n_dofs):
            raise FEModelError(f"{where}: {label} is {matrix.shape}, M is {model.M.shape}")
        if not np.all(np.isfinite(matrix.data)):
            raise FEModelError(f"{where}: {label} has NaN or infinite entries")
        scale = float(np.max(np.abs(matrix.data), initial=0.0))
        asym = sp.coo_array(abs(matrix - matrix.T))
        if asym.nnz and float(asym.data.max()) > SYMMETRY_RTOL * scale:
            k = int(np.argmax(asym.data))
            raise FEModelError(
                f"{where}: {label} is not symmetric: entries ({asym.row[k]}, {asym.col[k]}) "
                f"and ({asym.col[k]}, {asym.row[k]}) are {asym.data[k]:g} apart, against "
                f"its largest entry {scale:g}"
            )
    if np.any(model.M.diagonal() < 0.0):
        row = int(np.argmin(model.M.diagonal()))
        raise FEModelError(f"{where}: M has a negative diagonal entry (row {row})")
    ids = np.asarray(model.node_ids)
    if model.node_xyz.shape != (ids.size, 3):
        raise FEModelError(f"{where}: node_xyz is {model.node_xyz.shape}, expected ({ids.size}, 3)")
    if np.unique(ids).size != ids.size:
        raise FEModelError(f"{where}: a node number is listed twice in the node table")
    if model.dof_node.shape != (n_dofs,) or model.dof_comp.shape != (n_dofs,):
        raise FEModelError(f"{where}: the DOF map must have one entry per row ({n_dofs})")
    unknown = np.setdiff1d(model.dof_node, ids)
    if unknown.size:
        raise FEModelError(f"{where}: DOFs on node {int(unknown[0])}, which is not in the table")
    bad = (model.dof_comp < 0) | (model.dof_comp > 6)
    if np.any(bad):
        comp = int(model.dof_comp[np.argmax(bad)])
        raise FEModelError(f"{where}: component {comp} (components are 0 to 6)")
    pairs = model.dof_node.astype(np.int64) * 8 + model.dof_comp
    if np.unique(pairs).size != pairs.size:
        raise FEModelError(f"{where}: a node's component is listed twice in the DOF map")
    for name, node in model.interfaces.items():
        if node not in set(ids.tolist()):
            raise FEModelError(f"{where}: interface '{name}' is node {node}, not in the table")


def _csr_arrays(prefix: str, matrix: sp.csr_array) -> dict[str, np.ndarray]:
    m = sp.csr_array(matrix)
    return {
        f"{prefix}_data": m.data,
        f"{prefix}_indices": m.indices,
        f"{prefix}_indptr": m.indptr,
        f"{prefix}_shape": np.array(m.shape),
    }


def write(model: FEModel, path: str | Path) -> Path:
    """Write ``model`` to ``path`` (``.npz``) in the neutral format, atomically."""
    arrays = {
        "format": np.array(FORMAT),
        **_csr_arrays("M", model.M),
        **_csr_arrays("K", model.K),
        "node_ids": np.asarray(model.node_ids, dtype=np.int64),
        "node_xyz": np.asarray(model.node_xyz, dtype=float),
        "dof_node": np.asarray(model.dof_node, dtype=np.int64),
        "dof_comp": np.asarray(model.dof_comp, dtype=np.int64),
        "interface_names": np.array(list(model.interfaces), dtype=str),
        "interface_nodes": np.array(list(model.interfaces.values()), dtype=np.int64),
    }

    def save(tmp: Path) -> None:
        with open(tmp, "wb") as f:
            np.savez_compressed(f, **arrays)

    return atomic_write(Path(path), save)


def read(path: str | Path) -> FEModel:
    """Read a neutral ``.npz`` file (see the module docstring), checked.

    Raises
    ------
    FEModelError
        A missing file, another format, a missing or malformed entry, or an inconsistent
        model (:func:`check`), naming the file.
    """
    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except FileNotFoundError:
        raise FEModelError(f"{path}: no such file") from None
    except (OSError, ValueError) as exc:
        raise FEModelError(f"{path}: not an .npz file ({exc})") from None
    if str(arrays.get("format", "")) != FORMAT:
        raise FEModelError(f"{path}: format '{arrays.get('format', '')}', expected '{FORMAT}'")
    try:
        M, K = (
            sp.csr_array(
                (arrays[f"{p}_data"], arrays[f"{p}_indices"], arrays[f"{p}_indptr"]),
                shape=tuple(int(x) for x in arrays[f"{p}_shape"]),
            )
            for p in ("M", "K")
        )
        interfaces = dict(
            zip(
                [str(x) for x in arrays["interface_names"]],
                [int(x) for x in arrays["interface_nodes"]],
                strict=True,
            )
        )
        return FEModel(
            M,
            K,
            arrays["node_ids"].astype(np.int64),
            arrays["node_xyz"].astype(float),
            arrays["dof_node"].astype(np.int64),
            arrays["dof_comp"].astype(np.int64),
            interfaces,
            name=str(path),
        )
    except KeyError as exc:
        raise FEModelError(f"{path}: missing entry {exc}") from None
    except ValueError as exc:
        raise FEModelError(f"{path}: {exc}") from None
