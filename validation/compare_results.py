"""Compare two sets of results file by file: equal where deterministic, timings set aside.

For checking that a change of code did not change a result: regenerate the results in
two checkouts (for example the commit before a restructuring and the one after) and
compare their ``validation/results`` folders, or their ``notebooks`` folders.

- ``.json``: every value compared exactly, keys that name a time (``wall``, ``seconds``,
  ``_ms``, ``time_s``, …) skipped;
- ``.csv``: every cell compared as text, columns that name a time skipped;
- ``.md``: line by line, the run header dropped, table cells under a timing heading
  (``µs``, ``ms``, ``wall s``, …) and run-time lines masked;
- ``.npz``: every array exactly; ``.png``: every pixel;
- ``.ipynb``: every output of every code cell — text line by line (a line that names a
  time reported as such), figures pixel by pixel.

Usage: ``python validation/compare_results.py DIR_A DIR_B [FILE ...]`` (default: the
files of DIR_A). Prints one line per file (``identical bytes``, ``same except timings``
or the number of differences, the first ones after it); exits 1 if any file differs
beyond its timings or is missing from DIR_B.
"""

from __future__ import annotations

import argparse
import base64
import csv
import difflib
import io
import json
import re
import sys
from pathlib import Path

import numpy as np

#: A key, column or heading that names a time or a speed measured on the machine.
TIMING = re.compile(
    r"(wall|seconds|elapsed|_ms\b|_us\b|_times\b|time_s|times_s|rhs_s|jacobian_s|integrator_s|"
    r"run time|per_call|duration_s|timing|"
    r"real.time|µs|\bms\b|case s|\bs\b$)",
    re.I,
)


def compare_json(a, b, path: str = "") -> list[str]:
    """Differences of two JSON values, keys naming a time skipped."""
    if isinstance(a, dict) and isinstance(b, dict):
        out = []
        for key in sorted(set(a) | set(b)):
            if TIMING.search(key):
                continue
            if key not in a or key not in b:
                out.append(f"{path}/{key}: only in one")
            else:
                out += compare_json(a[key], b[key], f"{path}/{key}")
        return out
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{path}: {len(a)} items against {len(b)}"]
        return [
            d
            for i, (x, y) in enumerate(zip(a, b, strict=True))
            for d in compare_json(x, y, f"{path}[{i}]")
        ]
    return [] if a == b else [f"{path}: {a!r} against {b!r}"]


def compare_csv(text_a: str, text_b: str) -> list[str]:
    """Differences of two CSV tables, cell by cell, timing columns skipped."""
    rows_a, rows_b = list(csv.reader(io.StringIO(text_a))), list(csv.reader(io.StringIO(text_b)))
    if len(rows_a) != len(rows_b) or not rows_a:
        return [f"{len(rows_a)} rows against {len(rows_b)}"]
    head = rows_a[0]
    skip = {i for i, name in enumerate(head) if TIMING.search(name)}
    return [
        f"row {r} column {head[c] if c < len(head) else c}: {u} against {v}"
        for r, (x, y) in enumerate(zip(rows_a, rows_b, strict=True))
        for c, (u, v) in enumerate(zip(x, y, strict=False))
        if c not in skip and u != v
    ]


#: A row of ``rt70 validate``'s text table: textbook µs, reference µs, ratio, verdict.
VALIDATE_ROW = re.compile(r"(\s+[0-9.]+){3}\s+(yes|NO|no)$")


def _markdown_lines(text: str) -> list[str]:
    """The page's lines, its run header dropped and timing cells and lines masked."""
    out: list[str] = []
    head: list[str] | None = None
    for line in text.splitlines():
        if line.startswith("> `") and " · commit " in line:
            continue
        if VALIDATE_ROW.search(line):  # rt70 validate's table: its three timing columns
            out.append(VALIDATE_ROW.sub(r" # # # \2", line))
        elif line.startswith("_Run time") or "Total run time" in line:
            out.append(re.sub(r"[0-9.]+ s\b", "# s", line))
        elif line.startswith("|"):
            cells = [c.strip() for c in line.strip("|").split("|")]
            if head is None:
                head = cells
            else:
                cells = [
                    "#" if i < len(head) and TIMING.search(head[i]) else c
                    for i, c in enumerate(cells)
                ]
            out.append("|".join(cells))
        else:
            head = None
            out.append(line)
    while out and not out[0].strip():
        out.pop(0)
    return out


def compare_markdown(text_a: str, text_b: str) -> list[str]:
    """Lines of one page that the other lacks, timings masked."""
    diff = difflib.unified_diff(_markdown_lines(text_a), _markdown_lines(text_b), lineterm="", n=0)
    return [line for line in diff if line[:1] in "+-" and not line.startswith(("+++", "---"))]


def _pixels(data: bytes) -> np.ndarray:
    import matplotlib.image as mpimg

    return mpimg.imread(io.BytesIO(data), format="png")


def compare_png(data_a: bytes, data_b: bytes) -> list[str]:
    """How many pixels of two images differ, and by how much at most."""
    a, b = _pixels(data_a), _pixels(data_b)
    if a.shape != b.shape:
        return [f"image {a.shape} against {b.shape}"]
    changed = np.abs(a - b)
    if not changed.any():
        return []
    count = int(changed.reshape(*a.shape[:2], -1).any(axis=-1).sum())
    return [f"{count} of {a.shape[0] * a.shape[1]} pixels differ (at most {changed.max():.3g})"]


def compare_npz(path_a: Path, path_b: Path) -> list[str]:
    """Arrays of two archives that are not equal, element by element."""
    with np.load(path_a, allow_pickle=False) as a, np.load(path_b, allow_pickle=False) as b:
        names = sorted(set(a.files) | set(b.files))
        return [
            f"{name}: differs"
            for name in names
            if name not in a.files or name not in b.files or not np.array_equal(a[name], b[name])
        ]


def _cell_outputs(path: Path) -> list[tuple[str, list[tuple[str, str]]]]:
    cells = []
    for cell in json.loads(path.read_text(encoding="utf-8"))["cells"]:
        if cell["cell_type"] != "code":
            continue
        outputs = []
        for out in cell.get("outputs", []):
            data = out.get("data", {})
            if out["output_type"] == "stream":
                outputs.append(("text", "".join(out["text"])))
            elif "image/png" in data:
                outputs.append(("png", data["image/png"]))
            elif "text/plain" in data:
                outputs.append(("text", "".join(data["text/plain"])))
        cells.append(("".join(cell["source"]).splitlines()[0][:50], outputs))
    return cells


def compare_notebook(path_a: Path, path_b: Path) -> list[str]:
    """Outputs of two executions of a notebook that differ (a timing line says so)."""
    a, b = _cell_outputs(path_a), _cell_outputs(path_b)
    if len(a) != len(b):
        return [f"{len(a)} code cells against {len(b)}"]
    out = []
    for (source, outs_a), (_, outs_b) in zip(a, b, strict=True):
        if [k for k, _ in outs_a] != [k for k, _ in outs_b]:
            out.append(f"cell {source!r}: other outputs")
            continue
        for (kind, x), (_, y) in zip(outs_a, outs_b, strict=True):
            if kind == "png" and x != y:
                out += [
                    f"cell {source!r}: {d}" for d in compare_png(*map(base64.b64decode, (x, y)))
                ]
            elif kind == "text" and x != y:
                lines_x, lines_y = x.splitlines(), y.splitlines()
                if len(lines_x) != len(lines_y):
                    out.append(f"cell {source!r}: {len(lines_x)} lines against {len(lines_y)}")
                for u, v in zip(lines_x, lines_y, strict=False):
                    if u != v:
                        what = "a time" if TIMING.search(u) or re.search(r"\d s\b", u) else "value"
                        out.append(f"cell {source!r} ({what}): {u!r} against {v!r}")
    return out


def compare(path_a: Path, path_b: Path) -> list[str] | None:
    """The differences of two files of one kind; None if they are the same bytes."""
    if path_a.read_bytes() == path_b.read_bytes():
        return None
    suffix = path_a.suffix
    if suffix == ".json":
        return compare_json(*(json.loads(p.read_text(encoding="utf-8")) for p in (path_a, path_b)))
    if suffix == ".csv":
        return compare_csv(*(p.read_text(encoding="utf-8") for p in (path_a, path_b)))
    if suffix == ".png":
        return compare_png(path_a.read_bytes(), path_b.read_bytes())
    if suffix == ".npz":
        return compare_npz(path_a, path_b)
    if suffix == ".ipynb":
        return compare_notebook(path_a, path_b)
    return compare_markdown(*(p.read_text(encoding="utf-8") for p in (path_a, path_b)))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("a", type=Path, metavar="DIR_A")
    parser.add_argument("b", type=Path, metavar="DIR_B")
    parser.add_argument("files", nargs="*", metavar="FILE")
    args = parser.parse_args(argv)
    for folder in (args.a, args.b):
        if not folder.is_dir():
            parser.error(f"{folder}: not a directory")
    names = args.files or sorted(p.name for p in args.a.iterdir() if p.is_file())
    failed = False
    for name in names:
        path_a, path_b = args.a / name, args.b / name
        if not path_a.is_file() or not path_b.is_file():
            print(f"{name}: missing in {args.a if not path_a.is_file() else args.b}")
            failed = True
            continue
        found = compare(path_a, path_b)
        timing_only = found is not None and all(" (a time): " in d for d in found)
        if found is None:
            print(f"{name}: identical bytes")
        elif not found or timing_only:
            print(
                f"{name}: same except timings" + (f" ({len(found)} timing lines)" if found else "")
            )
        else:
            failed = True
            print(f"{name}: {len(found)} differences")
            for line in found[:8]:
                print(f"    {line[:200]}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
