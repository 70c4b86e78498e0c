"""Nastran matrices in: OUTPUT4 (``.op4``) files and the bulk data that maps their rows.

One job: bring a model that MSC or NX Nastran exported — above all an external
superelement (``EXTSEOUT``: the Craig–Bampton matrices ``KAA``, ``MAA`` in an ``.op4``
file, its boundary grids, coordinate systems and modal scalar points in the ``.pch`` or
``.asm`` bulk data) — into rt70's FE model (:class:`rt70.fe.neutral.FEModel`), in the
basic coordinate system, SI as written. docs/fe-models.md, "Nastran".

- :func:`read_op4`: the matrices of a formatted (ASCII) OUTPUT4 file, dense columns and
  sparse strings (the non-BIGMAT string header ``IS = IROW + 65536 (L + 1)`` and the
  BIGMAT pair ``L + 1, IROW``), real or complex, single or double precision.
- :func:`read_bulk`: the ``GRID``, ``CORD2R``, ``SPOINT``, ``ASET``/``ASET1``/``QSET1``
  cards of a bulk data file in small, large (``*``) or free (``,``) field, with
  Nastran's reals (``1.5-3`` is 1.5e-3).
- :func:`read_superelement`: both, the a-set's rows in Nastran's internal order
  (ascending id; a grid's components ascending), in the superelement's own frame: the
  system its boundary grids are located in (their common ``CP``), which is the basic
  system of the component run that wrote the matrices — the grids' positions in it, and
  each grid's displacement system ``CD`` (blank: that frame) turned to it
  (``K = T K_cd Tᵀ``, ``T`` the block diagonal of the CD rotations); scalar points (the
  modal coordinates) with component 0 and no position. The convention is the one the
  MSC-written test superelement satisfies: its stiffness holds the six rigid-body
  motions to 1e-11 in this frame, and to 1e-2 only with the grids placed in the
  assembly's basic (tests/test_nastran.py).

What is not read is refused by name (binary OUTPUT4, cylindrical and spherical
systems), never skipped.
"""

from __future__ import annotations

import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from rt70.errors import Rt70Warning
from rt70.fe.neutral import FEModel, FEModelError

#: 65536: the packing base of a non-BIGMAT string header.
_PACK = 1 << 16
#: Words per number of each OUTPUT4 precision type (1 RSP, 2 RDP, 3 CSP, 4 CDP) and
#: whether its values are complex (two numbers, real and imaginary).
_WORDS = {1: 1, 2: 2, 3: 1, 4: 2}
_COMPLEX = {3, 4}
_NASTRAN_REAL = re.compile(r"^([+-]?(?:\d+\.?\d*|\.\d+))([+-]\d+)$")


def read_op4(path: str | Path) -> dict[str, sp.csc_array]:
    """The matrices of a formatted OUTPUT4 file, by name, as sparse arrays.

    Raises
    ------
    FEModelError
        A missing or binary file, or a record that does not parse (naming the file, the
        matrix and the line).
    """
    path = Path(path)
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise FEModelError(f"{path}: no such file") from None
    if b"\0" in raw[:256]:
        raise FEModelError(f"{path}: a binary OUTPUT4 file; write it formatted (FORMATTED)")
    lines = raw.decode("ascii", errors="replace").splitlines()
    matrices: dict[str, sp.csc_array] = {}
    i = 0
    while i < len(lines):
        if not lines[i].strip():
            i += 1
            continue
        name, matrix, i = _op4_matrix(path, lines, i)
        matrices[name] = matrix
    return matrices


def _op4_matrix(path: Path, lines: list[str], i: int) -> tuple[str, sp.csc_array, int]:
    """One matrix from its header at line ``i``: its name, its values, the next line."""
    head = lines[i]
    try:
        ncol, nrow, _form, ntype = (int(head[k : k + 8]) for k in range(0, 32, 8))
    except ValueError:
        raise FEModelError(f"{path}: line {i + 1}: not an OUTPUT4 matrix header") from None
    name = head[32:40].strip()
    where = f"{path}: matrix {name}"
    if ntype not in _WORDS:
        raise FEModelError(f"{where}: precision type {ntype} is not one of 1–4")
    fmt = re.search(r"(\d+)E(\d+)\.(\d+)", head[40:].upper())
    if fmt is None:
        raise FEModelError(f"{where}: no E-format in the header '{head[40:].strip()}'")
    per_line, width = int(fmt.group(1)), int(fmt.group(2))
    bigmat, nrow = nrow < 0, abs(nrow)
    words = _WORDS[ntype]
    rows, cols, vals = [], [], []
    pair = 2 if ntype in _COMPLEX else 1  # numbers per value
    i += 1
    while True:
        icol, irow, nw = _ints(path, lines, i, 3)
        i += 1
        if icol > ncol:  # the closing record and its dummy value
            _, i = _reals(path, lines, i, nw, per_line, width)
            break
        if irow:  # one dense run of nw numbers from irow (a formatted file counts numbers)
            numbers, i = _reals(path, lines, i, nw, per_line, width)
            run = list(enumerate(_values(numbers, pair), start=irow - 1))
        else:  # sparse strings
            run, i = _strings(path, lines, i, nw, words, bigmat, per_line, width, pair)
        rows.extend(r for r, _ in run)
        cols.extend([icol - 1] * len(run))
        vals.extend(v for _, v in run)
    if rows and (min(rows) < 0 or max(rows) >= nrow):
        raise FEModelError(f"{where}: a row outside 1…{nrow}")
    dtype = complex if pair == 2 else float
    matrix = sp.csc_array(
        sp.coo_array((np.array(vals, dtype=dtype), (rows, cols)), shape=(nrow, ncol))
    )
    return name, matrix, i


def _ints(path: Path, lines: list[str], i: int, count: int) -> list[int]:
    try:
        values = [int(x) for x in lines[i].split()]
    except (IndexError, ValueError):
        raise FEModelError(f"{path}: line {i + 1}: expected {count} integers") from None
    if len(values) != count:
        raise FEModelError(f"{path}: line {i + 1}: expected {count} integers")
    return values


def _reals(
    path: Path, lines: list[str], i: int, count: int, per_line: int, width: int
) -> tuple[list[float], int]:
    """``count`` reals in fixed fields of ``width``, ``per_line`` a line, from line i."""
    out: list[float] = []
    while len(out) < count:
        if i >= len(lines):
            raise FEModelError(f"{path}: the file ends inside a column")
        text = lines[i]
        try:
            out.extend(
                float(text[k : k + width])
                for k in range(0, min(len(text), per_line * width), width)
                if text[k : k + width].strip()
            )
        except ValueError:
            raise FEModelError(f"{path}: line {i + 1}: not a line of reals") from None
        i += 1
    return out[:count], i


def _strings(
    path: Path,
    lines: list[str],
    i: int,
    nw: int,
    words: int,
    bigmat: bool,
    per_line: int,
    width: int,
    pair: int,
) -> tuple[list[tuple[int, float]], int]:
    """The (row, value) pairs of a sparse column of ``nw`` words from line ``i``.

    Each string: its header — one integer ``IS = IROW + 65536 (L + 1)``, or two, ``L + 1``
    and ``IROW``, in a BIGMAT matrix — on a line of its own, then its ``L`` words
    (``words`` a number, ``pair`` numbers a value).
    """
    out: list[tuple[int, float]] = []
    used = 0
    while used < nw:
        head = _ints(path, lines, i, 2 if bigmat else 1)
        i += 1
        if bigmat:
            length, irow = head[0] - 1, head[1]
            used += 2
        else:
            length = head[0] // _PACK - 1
            irow = head[0] - _PACK * (length + 1)
            used += 1
        numbers, i = _reals(path, lines, i, length // words, per_line, width)
        out.extend(enumerate(_values(numbers, pair), start=irow - 1))
        used += length
    return out, i


def _values(numbers: list[float], pair: int) -> list:
    """The numbers as values: themselves, or (real, imaginary) pairs as complex."""
    if pair == 1:
        return numbers
    return [complex(a, b) for a, b in zip(numbers[::2], numbers[1::2], strict=True)]


@dataclass
class Bulk:
    """The cards of a bulk data file that place a superelement's rows.

    Attributes
    ----------
    grids : dict of int to (int, numpy.ndarray, int)
        Each grid's position system CP, position (in CP) and displacement system CD.
    systems : dict of int to (int, numpy.ndarray)
        Each ``CORD2R``'s reference system RID and its points A, B, C (3, 3) in RID.
    spoints : set of int
        The scalar points.
    aset : dict of int to set of int
        The a-set's grid components (1–6) and scalar points (component 0).
    """

    grids: dict[int, tuple[int, np.ndarray, int]] = field(default_factory=dict)
    systems: dict[int, tuple[int, np.ndarray]] = field(default_factory=dict)
    spoints: set[int] = field(default_factory=set)
    aset: dict[int, set[int]] = field(default_factory=dict)


def read_bulk(path: str | Path) -> Bulk:
    """The GRID, CORD2R, SPOINT and a-set cards of a bulk data file (module docstring).

    Raises
    ------
    FEModelError
        A missing file, a field that is not a number where one is needed, or a
        coordinate system other than CORD2R (naming the file and the card).
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="latin-1")
    except FileNotFoundError:
        raise FEModelError(f"{path}: no such file") from None
    bulk = Bulk()
    for name, fields in _cards(text):
        where = f"{path}: {name} {' '.join(f for f in fields[:1])}"
        if name == "GRID":
            gid = _int(fields, 0, where)
            xyz = np.array([_real(fields, k, where) for k in (2, 3, 4)])
            bulk.grids[gid] = (_int(fields, 1, where, 0), xyz, _int(fields, 5, where, 0))
        elif name == "CORD2R":
            cid = _int(fields, 0, where)
            points = np.array([_real(fields, k, where) for k in range(2, 11)]).reshape(3, 3)
            bulk.systems[cid] = (_int(fields, 1, where, 0), points)
        elif name in ("CORD1R", "CORD1C", "CORD1S", "CORD2C", "CORD2S"):
            raise FEModelError(f"{where}: only CORD2R systems are read")
        elif name == "SPOINT":
            bulk.spoints.update(_id_list(fields, where))
        elif name in ("ASET", "ASET1", "QSET1"):
            _add_set(bulk, name, fields, where)
    return bulk


def _cards(text: str) -> list[tuple[str, list[str]]]:
    """Each card's name and its data fields (continuations joined), in file order."""
    cards: list[tuple[str, list[str]]] = []
    for line in text.splitlines():
        line = line.split("$", 1)[0].rstrip().expandtabs(8)
        if not line.strip() or line.upper().startswith(("BEGIN", "ENDDATA")):
            continue
        if "," in line[:10]:  # free field
            parts = [p.strip() for p in line.split(",")]
            first, data = parts[0], parts[1:]
        else:
            first = line[:8].strip()
            wide = first.endswith("*") or (not first and line.startswith("*"))
            size = 16 if wide else 8
            data = [line[k : k + size].strip() for k in range(8, 72, size)]
        head = first.rstrip("*").strip().upper()
        if head and not head.startswith("+"):
            cards.append((head, data))
        elif cards:
            cards[-1][1].extend(data)
    return [(name, _trim(fields)) for name, fields in cards]


def _trim(fields: list[str]) -> list[str]:
    while fields and not fields[-1]:
        fields.pop()
    return fields


def _real(fields: list[str], k: int, where: str, default: float = 0.0) -> float:
    text = fields[k].upper().replace("D", "E") if k < len(fields) else ""
    if not text:
        return default
    m = _NASTRAN_REAL.match(text)
    try:
        return float(f"{m.group(1)}E{m.group(2)}") if m else float(text)
    except ValueError:
        raise FEModelError(f"{where}: field {k + 2} '{fields[k]}' is not a number") from None


def _int(fields: list[str], k: int, where: str, default: int | None = None) -> int:
    text = fields[k] if k < len(fields) else ""
    if not text and default is not None:
        return default
    try:
        return int(text)
    except ValueError:
        raise FEModelError(f"{where}: field {k + 2} '{text}' is not an integer") from None


def _id_list(fields: list[str], where: str) -> list[int]:
    """Ids written one by one or as ``a THRU b``."""
    ids: list[int] = []
    k = 0
    while k < len(fields):
        if not fields[k]:
            k += 1
            continue
        if k + 2 < len(fields) and fields[k + 1].upper() == "THRU":
            first, last = _int(fields, k, where), _int(fields, k + 2, where)
            ids.extend(range(first, last + 1))
            k += 3
        else:
            ids.append(_int(fields, k, where))
            k += 1
    return ids


def _add_set(bulk: Bulk, name: str, fields: list[str], where: str) -> None:
    """ASET (id, components pairs) or ASET1/QSET1 (components, then ids)."""
    if name == "ASET":
        pairs = [
            (fields[k], fields[k + 1] if k + 1 < len(fields) else "")
            for k in range(0, len(fields), 2)
        ]
        for gid, comps in pairs:
            if gid:
                bulk.aset.setdefault(int(gid), set()).update(_components(comps))
        return
    comps = _components(fields[0] if fields else "")
    for gid in _id_list(fields[1:], where):
        bulk.aset.setdefault(gid, set()).update(comps)


def _components(text: str) -> set[int]:
    return {int(c) for c in text if c.isdigit()} if text.strip() not in ("", "0") else {0}


def basic_frame(bulk: Bulk, cid: int, where: str, depth: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """``(R, o)`` of system ``cid`` in basic: ``x_basic = R x + o`` (0 is basic).

    A CORD2R's origin is A, its z axis towards B, its x–z plane through C, all three
    given in its reference system RID.

    Parameters
    ----------
    bulk : Bulk
        The cards read (:func:`read_bulk`).
    cid : int
        The system.
    where : str
        The start of a message (the file).
    depth : int
        Systems followed so far (a cycle of references stops at 64).
    """
    if cid == 0:
        return np.eye(3), np.zeros(3)
    if cid not in bulk.systems or depth > 64:
        raise FEModelError(f"{where}: coordinate system {cid} is not defined (as CORD2R)")
    rid, (a, b, c) = bulk.systems[cid]
    R_ref, o_ref = basic_frame(bulk, rid, where, depth + 1)
    a, b, c = (R_ref @ p + o_ref for p in (a, b, c))
    z = (b - a) / np.linalg.norm(b - a)
    y = np.cross(z, c - a)
    y /= np.linalg.norm(y)
    return np.column_stack([np.cross(y, z), y, z]), a


def read_superelement(
    op4: str | Path, bulk: str | Path, stiffness: str = "KAA", mass: str = "MAA"
) -> FEModel:
    """An external superelement as an FE model in its own frame (module docstring).

    Parameters
    ----------
    op4 : str or pathlib.Path
        The formatted OUTPUT4 file with the superelement's matrices.
    bulk : str or pathlib.Path
        Its bulk data (the ``.pch`` or ``.asm`` Nastran wrote beside it).
    stiffness, mass : str
        The matrices' names in the OUTPUT4 file.

    Raises
    ------
    FEModelError
        As the readers, a matrix that is missing, or an a-set whose size is not the
        matrices'.
    """
    matrices = read_op4(op4)
    for label in (stiffness, mass):
        if label not in matrices:
            raise FEModelError(f"{op4}: no matrix {label} (it has {', '.join(matrices)})")
    cards = read_bulk(bulk)
    where = str(bulk)
    dof_node = [p for p in sorted(cards.aset) for _ in sorted(cards.aset[p])]
    dof_comp = [c for p in sorted(cards.aset) for c in sorted(cards.aset[p])]
    K, M = matrices[stiffness], matrices[mass]
    if K.shape != (len(dof_node), len(dof_node)):
        raise FEModelError(
            f"{where}: the a-set has {len(dof_node)} DOFs, {stiffness} is {K.shape[0]}"
        )
    grids = [p for p in cards.aset if p in cards.grids]
    frames = {cards.grids[p][0] for p in grids}
    if len(frames) > 1:
        raise FEModelError(
            f"{where}: the boundary grids are located in systems {sorted(frames)}, not one"
        )
    own = frames.pop() if frames else 0
    T = _frame_rotation(cards, own, dof_node, dof_comp, where)
    nodes = sorted(set(dof_node))
    xyz = np.full((len(nodes), 3), np.nan)
    for n, point in enumerate(nodes):
        if point in cards.grids:
            xyz[n] = cards.grids[point][1]
    M, K = sp.csr_array(T @ M @ T.T), sp.csr_array(T @ K @ T.T)
    keep = _drop_void(M, K, dof_node, dof_comp, where)
    nodes_kept = np.isin(nodes, np.asarray(dof_node)[keep])
    return FEModel(
        M[keep][:, keep],
        K[keep][:, keep],
        np.array(nodes, dtype=np.int64)[nodes_kept],
        xyz[nodes_kept],
        np.array(dof_node, dtype=np.int64)[keep],
        np.array(dof_comp, dtype=np.int64)[keep],
        name=f"{op4} ({stiffness}, {mass}) with {bulk}",
    )


def _drop_void(
    M: sp.csr_array, K: sp.csr_array, dof_node: list[int], dof_comp: list[int], where: str
) -> np.ndarray:
    """The rows to keep: all but those with neither mass nor stiffness, with a warning.

    A boundary grid of solid elements lists rotations that nothing in the model touches
    (Nastran's AUTOSPC would hold them); they carry no dynamics, and left in they make
    every ``K − σ M`` singular.
    """
    void = (abs(M).sum(axis=1) == 0.0) & (abs(K).sum(axis=1) == 0.0)
    if np.any(void):
        named = [f"{dof_node[r]}:{dof_comp[r]}" for r in np.flatnonzero(void)[:6]]
        warnings.warn(
            f"{where}: {int(void.sum())} DOFs have neither mass nor stiffness and are left "
            f"out ({', '.join(named)}{', …' if void.sum() > 6 else ''})",
            Rt70Warning,
            stacklevel=3,
        )
    return np.flatnonzero(~void)


def _frame_rotation(
    cards: Bulk, own: int, dof_node: list[int], dof_comp: list[int], where: str
) -> sp.csr_array:
    """T with ``u = T u_cd``: each grid's translations and rotations turned from its CD.

    ``own`` is the superelement's frame (a grid with a blank CD is in it). A grid whose
    CD is not parallel to it must have the whole triad (1–3, 4–6) it has any of in the
    a-set, else its components in the frame are not known.
    """
    R_own = basic_frame(cards, own, where)[0]
    n = len(dof_node)
    T = sp.lil_array((n, n))
    rows_of: dict[tuple[int, int], list[int]] = {}
    for r, (point, comp) in enumerate(zip(dof_node, dof_comp, strict=True)):
        triad = 0 if comp == 0 else (1 if comp <= 3 else 4)
        rows_of.setdefault((point, triad), []).append(r)
    for (point, triad), rows in rows_of.items():
        R = np.eye(3)
        cd = cards.grids[point][2] if triad and point in cards.grids else 0
        if cd:
            R = R_own.T @ basic_frame(cards, cd, where)[0]
        if triad == 0 or np.allclose(R, np.eye(3), rtol=0.0, atol=1e-12):
            for r in rows:
                T[r, r] = 1.0
            continue
        if len(rows) != 3:
            raise FEModelError(
                f"{where}: grid {point} has {len(rows)} of a triad in the a-set and a "
                "displacement system that is not basic"
            )
        for a, r in enumerate(rows):
            for b, c in enumerate(rows):
                T[r, c] = R[a, b]
    return sp.csr_array(T)
