"""Generic code names no RT-70 link, joint or optical point: it reads the scene's declarations.

The analyses that point a structure (pointing, plant, scenarios, sweeps, bearing loads)
take the axes from ``<rt70:mount>`` and the reflectors from ``<rt70:optics>``
(:mod:`rt70.model.antenna`), so they work on any antenna that declares them. This test
reads every module's string literals (docstrings apart: they may use the RT-70 as their
example) and fails on one equal to a name of the RT-70 scenes, outside the modules whose
subject is the RT-70 itself (:data:`RT70_OWN`).
"""

from __future__ import annotations

import ast
from functools import cache
from pathlib import Path

from rt70.model.scene import load_scene

PACKAGE = Path(__file__).resolve().parents[1] / "rt70"

#: Modules whose subject is the RT-70, with why they may name its parts.
RT70_OWN = {
    "reports/book.py": "the book's RT-70 tables, body by body",
    "reports/reduction_plants.py": "the RT-70 reduction study's wind inputs on its main mirror",
    "reports/servo_loops.py": "the RT-70 servo-loop page's wind torque on its main mirror",
    "reports/stress/rt70_cases.py": "stress cases that edit the RT-70's counterreflector",
    "reports/stress/gimbal_cases.py": "the RT-70 counterreflector's gimbal-lock case",
}


@cache
def _rt70_names() -> frozenset[str]:
    """Links, joints and optical points of the RT-70 scenes (``world`` is anyone's)."""
    names: set[str] = set()
    for scene in ("rt70", "rt70_servo", "rt70_jack"):
        d = load_scene(scene).description
        names |= set(d.links) | {j.name for j in d.joints} | {p.name for p in d.optical_points}
        names |= {b.name for b in d.bushings} | {s.name for s in d.joint_springs}
    return frozenset(names - {"world"})


def _docstrings(tree: ast.AST) -> set[int]:
    kinds = (ast.Module, ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)
    return {
        id(node.body[0].value)
        for node in ast.walk(tree)
        if isinstance(node, kinds)
        and node.body
        and isinstance(node.body[0], ast.Expr)
        and isinstance(node.body[0].value, ast.Constant)
    }


def _named(path: Path, names: set[str]) -> set[str]:
    """The RT-70 names among the string literals of one module (docstrings apart)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docs = _docstrings(tree)
    return {
        node.value
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant)
        and isinstance(node.value, str)
        and id(node) not in docs
        and node.value in names
    }


def _generic_modules() -> list[Path]:
    out = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        if rel.startswith("scenes/rt70_") or rel in RT70_OWN:
            continue
        out.append(path)
    return out


def test_generic_code_names_no_rt70_part():
    names = _rt70_names()
    found = {}
    for path in _generic_modules():
        hits = _named(path, names)
        if hits:
            found[path.relative_to(PACKAGE).as_posix()] = sorted(hits)
    assert not found, f"generic modules name RT-70 parts (read the declarations): {found}"


def test_the_search_sees_a_name_and_skips_docstrings(tmp_path):
    module = tmp_path / "m.py"
    module.write_text('"""platform_rz in a docstring."""\nAXIS = "base_rx"\n', encoding="utf-8")
    assert _named(module, {"platform_rz", "base_rx"}) == {"base_rx"}
    assert len(_rt70_names()) > 50 and "main_mirror_focus" in _rt70_names()


def test_every_exempt_module_exists_and_names_the_rt70():
    names = _rt70_names()
    for rel in RT70_OWN:
        assert _named(PACKAGE / rel, names), f"{rel} names no RT-70 part: drop its exemption"
