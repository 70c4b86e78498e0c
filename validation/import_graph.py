"""The package's house counted from its code: folders, floors, modules, sizes and imports.

Reads every module of ``rt70/`` with the import finder and the floors of
``tests/test_import_rules.py`` (the test that refuses an import upward or a circle), and
prints one line per folder (its floor, modules, lines, largest module), the import
graph's circles, and its depth: the longest chain of imports between modules and
between folders. ``--out FILE`` also writes the table as a Markdown page.

Run: ``python validation/import_graph.py [--out validation/results/import_graph.md]``.
"""

from __future__ import annotations

import argparse
import functools
import importlib.util
import sys
from pathlib import Path

from rt70.guards.atomic import atomic_write_text
from rt70.reports.provenance import headed, run_header

ROOT = Path(__file__).resolve().parents[1]


def _rules():
    """``tests/test_import_rules.py`` as a module: the floors and the import finder."""
    path = ROOT / "tests" / "test_import_rules.py"
    spec = importlib.util.spec_from_file_location("import_rules", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _longest_chain(graph: dict[str, set[str]]) -> list[str]:
    """The longest chain ``a → b → …`` of imports in an acyclic graph."""

    @functools.cache
    def chain(node: str) -> tuple[str, ...]:
        below = [chain(child) for child in graph[node] if child in graph]
        return (node, *max(below, key=len, default=()))

    return list(max((chain(n) for n in graph), key=len))


def _folder_of(rules, module: str) -> str:
    folder = rules._folder(module)
    return folder if folder is not None else module


def survey() -> dict:
    """Folders with their floor, modules and lines; circles; the longest chains."""
    rules = _rules()
    graph = rules._module_graph()
    folders: dict[str, dict] = {}
    for module, path in rules.MODULES.items():
        folder = _folder_of(rules, module)
        lines = len(path.read_text(encoding="utf-8").splitlines())
        row = folders.setdefault(
            folder, {"floor": None, "modules": 0, "lines": 0, "largest": ("", 0)}
        )
        if folder != rules.FACE:
            row["floor"] = rules._floor(module) + 1
        row["modules"] += 1
        row["lines"] += lines
        if lines > row["largest"][1]:
            row["largest"] = (path.relative_to(ROOT).as_posix(), lines)
    folder_graph: dict[str, set[str]] = {f: set() for f in folders}
    for module, imported in graph.items():
        here = _folder_of(rules, module)
        folder_graph[here] |= {_folder_of(rules, m) for m in imported} - {here}
    return {
        "folders": folders,
        "modules": len(graph),
        "circles": rules._circles(graph),
        "folder_circles": rules._circles(folder_graph),
        "module_chain": _longest_chain(graph),
        "folder_chain": _longest_chain(folder_graph),
        "floors": len(rules.FLOORS),
    }


def _path(rules_name: str) -> str:
    """``rt70.cli`` as ``rt70/cli/``, ``rt70.errors`` as ``rt70/errors.py``."""
    path = ROOT / Path(*rules_name.split("."))
    return (
        f"{rules_name.replace('.', '/')}/"
        if path.is_dir()
        else f"{rules_name.replace('.', '/')}.py"
    )


def format_report(result: dict) -> str:
    """The survey as a Markdown table and a few lines of totals."""
    lines = [
        "| floor | folder | modules | lines | largest module (lines) |",
        "|---:|---|---:|---:|---|",
    ]
    rows = sorted(result["folders"].items(), key=lambda kv: (kv[1]["floor"] or 99, kv[0]))
    for folder, row in rows:
        floor = row["floor"] if row["floor"] is not None else "face"
        largest, size = row["largest"]
        cells = (floor, f"`{_path(folder)}`", row["modules"], row["lines"], f"{largest} ({size})")
        lines.append("| " + " | ".join(str(c) for c in cells) + " |")
    total = sum(r["lines"] for r in result["folders"].values())
    chain, fchain = result["module_chain"], result["folder_chain"]
    lines += [
        "",
        f"- {result['modules']} modules, {total} lines, {result['floors']} floors",
        f"- circles between modules: {len(result['circles'])}; "
        f"between folders: {len(result['folder_circles'])}",
        f"- longest chain of imports between modules: {len(chain)} modules "
        f"({chain[0]} → … → {chain[-1]})",
        f"- longest chain of imports between folders: {len(fchain)} folders ({' → '.join(fchain)})",
    ]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, help="also write the report to this Markdown file")
    args = parser.parse_args(argv)
    report = format_report(survey())
    print(report)
    if args.out:
        command = f"python validation/import_graph.py --out {args.out.as_posix()}"
        page = (
            "# The package's folders and imports\n\n"
            "Counted from the code by the import finder and the floors of "
            "`tests/test_import_rules.py`; the roles of the folders: "
            "[architecture](../../docs/architecture.md).\n\n" + report + "\n"
        )
        atomic_write_text(args.out, headed(page, run_header(command)))
        print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
