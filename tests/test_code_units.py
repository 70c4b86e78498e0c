"""Small units (docs/architecture.md): module and function sizes, documented parameters.

A module holds one job and stays under :data:`MAX_MODULE_LINES`; a function reads as one
step of its algorithm and stays under :data:`MAX_FUNCTION_LINES` (``def`` to its last
line, docstring included). Every public function or method with
:data:`MIN_DOCUMENTED_PARAMETERS` or more parameters documents each of them in a numpydoc
``Parameters`` section, as python-control's docstring test requires of its API.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "rt70"
MODULES = sorted(PACKAGE.rglob("*.py"))

MAX_MODULE_LINES = 500
MAX_FUNCTION_LINES = 80
MIN_DOCUMENTED_PARAMETERS = 3

_SECTION = re.compile(
    r"^\s*Parameters\n\s*-{3,}\n(.*?)(?:\n\s*\n\s*[A-Z][A-Za-z ]+\n\s*-{3,}\n|\Z)", re.S | re.M
)
_ENTRY = re.compile(r"^(\s*)(\*{0,2}[A-Za-z_]\w*(?:\s*,\s*\*{0,2}[A-Za-z_]\w*)*)\s*(:|$)")


def documented_parameters(doc: str) -> set[str]:
    """The parameter names a numpydoc ``Parameters`` section lists (``a, b : float`` too)."""
    section = _SECTION.search(doc)
    if section is None:
        return set()
    lines = section.group(1).splitlines()
    indents = [len(x) - len(x.lstrip()) for x in lines if x.strip()]
    if not indents:
        return set()
    names: set[str] = set()
    for line in lines:
        entry = _ENTRY.match(line)
        if entry and len(entry.group(1)) == min(indents):
            names |= {n.strip().lstrip("*") for n in entry.group(2).split(",")}
    return names


def _rel(path: Path) -> str:
    return path.relative_to(ROOT).as_posix()


def _functions(tree: ast.AST):
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            yield node


def _public_functions(body: list[ast.stmt], prefix: str = ""):
    """Module-level functions and methods of public classes whose names are public."""
    for node in body:
        if isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
            yield from _public_functions(node.body, f"{prefix}{node.name}.")
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            if not node.name.startswith("_"):
                yield f"{prefix}{node.name}", node


def _parameters(node: ast.FunctionDef | ast.AsyncFunctionDef) -> list[str]:
    a = node.args
    names = [x.arg for x in a.posonlyargs + a.args + a.kwonlyargs]
    names += [x.arg for x in (a.vararg, a.kwarg) if x is not None]
    return [n for n in names if n not in ("self", "cls")]


def test_the_modules_are_found():
    assert len(MODULES) > 150


@pytest.mark.parametrize("path", MODULES, ids=_rel)
def test_module_is_small(path):
    lines = len(path.read_text(encoding="utf-8").splitlines())
    assert lines <= MAX_MODULE_LINES, f"{_rel(path)}: {lines} lines; split it by its jobs"


@pytest.mark.parametrize("path", MODULES, ids=_rel)
def test_functions_are_short(path):
    tree = ast.parse(path.read_text(encoding="utf-8"))
    long = {
        f"{n.name} (line {n.lineno})": n.end_lineno - n.lineno + 1
        for n in _functions(tree)
        if n.end_lineno - n.lineno + 1 > MAX_FUNCTION_LINES
    }
    assert not long, f"{_rel(path)}: functions over {MAX_FUNCTION_LINES} lines: {long}"


@pytest.mark.parametrize(
    "path", [p for p in MODULES if not p.name.startswith("_") or p.name == "__init__.py"], ids=_rel
)
def test_parameters_are_documented(path):
    tree = ast.parse(path.read_text(encoding="utf-8"))
    missing = {}
    for name, node in _public_functions(tree.body):
        params = _parameters(node)
        if len(params) >= MIN_DOCUMENTED_PARAMETERS:
            lacking = [
                p for p in params if p not in documented_parameters(ast.get_docstring(node) or "")
            ]
            if lacking:
                missing[name] = lacking
    assert not missing, f"{_rel(path)}: undocumented parameters {missing}"


def test_the_docstring_reader_can_fail():
    doc = """Do it.

    Parameters
    ----------
    a, b : float
        Two numbers.
    *args : tuple
        More.
    c : int
        Nested mention ``d : str`` is no entry.

    Returns
    -------
    e : float
        Not a parameter.
    """
    assert documented_parameters(doc) == {"a", "b", "args", "c"}
    assert documented_parameters("No sections.") == set()
