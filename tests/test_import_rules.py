"""Who may import whom (docs/architecture.md): the folders as floors, checked.

Each folder of the package stands on a floor (:data:`FLOORS`): a module imports its own
folder and the floors below, never a floor above nor a folder beside it on its own floor,
and the modules' import graph has no circle. Within the lower floors finer rules hold:

The two sides of the cross-check stay independent only if the import graph says so:
``rt70/urdf/`` (the reader) imports nothing of the textbook side nor of the reference
side; ``rt70/textbook/`` never imports the reference side (nor Pinocchio, see
tests/test_independence.py) and the reference side never imports the textbook; both
may use the shared math below them (``rt70.physics.rotations``; the textbook also
``rt70.physics.constraints``) and the small helpers every
layer uses (``rt70.errors``, ``rt70.guards.arrays``). The generic analyses and the simulation
load no RT-70 module (:data:`RT70_MODULES`), not even through another module. Every
import is found statically, at any depth (inside functions too).

Drawing is apart from the analyses: matplotlib is imported by ``rt70/plotting/`` (and
the reports, notebooks and tests that draw), never by the core — checked by importing
the core in a fresh interpreter.

The reports and benchmarks (``rt70/reports/``) are built on the core and apart from it:
no module outside ``rt70/reports/`` imports them, except the ``rt70 bench`` command
(``rt70/cli/bench.py``), which runs them.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "rt70"

#: Modules below both sides that any layer may import (``rt70.physics.loads``: the plain
#: Wrench value both sides turn into a generalised force; ``rt70.physics.aerodynamics``:
#: the wind's Wrench on a body at a pose each side computes, from the coefficient tables
#: of ``rt70.physics.coefficient_tables``; ``rt70.surface.pressure``:
#: that Wrench spread over surface nodes each side places; ``rt70.guards.kernel_cache``:
#: numba's cache of every compiled kernel, either side's).
SHARED = (
    "rt70.errors",
    "rt70.guards.arrays",
    "rt70.physics.rotations",
    "rt70.physics.loads",
    "rt70.physics.constraints",
    "rt70.physics.aerodynamics",
    "rt70.physics.coefficient_tables",
    "rt70.physics.cubic_pieces",
    "rt70.physics.kkt",
    "rt70.physics.baumgarte",
    "rt70.surface.pressure",
    "rt70.guards.kernel_cache",
)

#: layer (module prefix) → module prefixes it may import from rt70.
RULES = {
    "rt70.urdf": ("rt70.urdf", *SHARED),
    "rt70.textbook": ("rt70.textbook", "rt70.urdf", *SHARED),
    # not rt70.physics.constraints: the reference side maps mimic joints on its own, so the
    # cross-check also checks the textbook's constraint matrix G
    "rt70.reference": (
        "rt70.reference",
        "rt70.urdf",
        "rt70.guards.resources",
        *SHARED[:4],
        "rt70.physics.aerodynamics",
        "rt70.physics.coefficient_tables",
        "rt70.physics.cubic_pieces",
        "rt70.physics.baumgarte",
        "rt70.surface.pressure",
        "rt70.guards.kernel_cache",
    ),
    "rt70.guards.resources": ("rt70.errors",),
    "rt70.physics.rotations": (),
    "rt70.errors": (),
    "rt70.guards.arrays": ("rt70.errors",),
    "rt70.physics.constraints": ("rt70.errors",),
    # a second formulation of the drives, independent of both rigid-body sides
    "rt70.bondgraph": ("rt70.bondgraph", *SHARED),
    "rt70.physics.loads": ("rt70.guards.arrays", "rt70.errors"),
    "rt70.physics.aerodynamics": (
        "rt70.errors",
        "rt70.physics.loads",
        "rt70.physics.coefficient_tables",
    ),
    "rt70.physics.coefficient_tables": ("rt70.errors", "rt70.physics.cubic_pieces"),
    "rt70.physics.cubic_pieces": (),
    "rt70.physics.kkt": ("rt70.errors",),
    "rt70.physics.baumgarte": ("rt70.errors",),
    "rt70.surface.pressure": ("rt70.errors",),
    "rt70.physics.nonholonomic": ("rt70.errors", "rt70.physics.kkt"),
}


#: The folders of the package from the ground up (docs/architecture.md gives each one's
#: role). A module may import its own folder and any folder on a lower floor; folders on
#: one floor are independent of each other (the two sides of the cross-check above all).
FLOORS = (
    ("rt70._version", "rt70.errors", "rt70.testing", "rt70.units"),
    ("rt70.guards", "rt70.bondgraph"),
    ("rt70.physics", "rt70.fe", "rt70.surface"),
    ("rt70.urdf",),
    ("rt70.textbook", "rt70.reference"),
    ("rt70.model",),
    ("rt70.simulation", "rt70.linear"),
    ("rt70.mechanics", "rt70.control"),
    ("rt70.wind", "rt70.scenes"),
    ("rt70.telescope",),
    ("rt70.crosscheck", "rt70.sweep"),
    ("rt70.plotting",),
    ("rt70.reports",),
    ("rt70.cli",),
    ("rt70.__main__",),
)

#: The package's face (``rt70/__init__.py``) is not a folder: it stands on the floor of
#: the highest module it imports, and only modules above that may import it.
FACE = "rt70"


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path) -> set[str]:
    """Every rt70 module imported by ``path`` (absolute and relative, at any depth)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                own = _module_name(path).split(".")
                base = own if path.name == "__init__.py" else own[:-1]
                base = base[: len(base) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            found.add(module)
    return {m for m in found if m == "rt70" or m.startswith("rt70.")}


MODULES = {_module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def _layer(module: str) -> str | None:
    for layer in RULES:
        if module == layer or module.startswith(layer + "."):
            return layer
    return None


def _allowed(layer: str, imported: str) -> bool:
    return any(imported == a or imported.startswith(a + ".") for a in RULES[layer])


def test_graph_is_found():
    assert "rt70.urdf.reader" in MODULES and "rt70.textbook.dynamics" in MODULES
    assert "rt70.physics.rotations" in _imports(MODULES["rt70.urdf.reader"])


@pytest.mark.parametrize("module", [m for m in MODULES if _layer(m)])
def test_layer_imports_only_what_it_may(module):
    layer = _layer(module)
    bad = sorted(m for m in _imports(MODULES[module]) if not _allowed(layer, m))
    assert not bad, f"{module} ({layer}) imports {bad}; allowed: {RULES[layer]}"


def test_detector_sees_nested_imports(tmp_path):
    sample = tmp_path / "sample.py"
    sample.write_text(
        "import numpy\n"
        "def f():\n"
        "    from rt70.textbook.spatial import rpy_matrix\n"
        "    import rt70.reference as ref\n"
    )
    assert _imports(sample) == {"rt70.textbook.spatial", "rt70.reference"}
    assert not _allowed("rt70.urdf", "rt70.textbook.spatial")
    assert not _allowed("rt70.textbook", "rt70.reference")


def test_reader_knows_no_textbook():
    """The example the rules exist for: the reader once imported textbook.spatial."""
    for module, path in MODULES.items():
        if module.startswith("rt70.urdf"):
            assert not any(m.startswith("rt70.textbook") for m in _imports(path)), module


#: Core modules that must load without matplotlib (the figures are in rt70.plotting).
NO_MATPLOTLIB = (
    "rt70.linear.modal",
    "rt70.linear.responses",
    "rt70.simulation.simulate",
    "rt70.crosscheck.validate",
    "rt70.model.scene",
)


def test_core_does_not_import_matplotlib():
    """The analyses compute; rt70.plotting draws. Importing the core loads no matplotlib."""
    code = (
        "import sys\n"
        + "".join(f"import {m}\n" for m in NO_MATPLOTLIB)
        + "print(sorted(m for m in sys.modules if m.split('.')[0] == 'matplotlib'))\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=False
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]", f"{NO_MATPLOTLIB} imported {proc.stdout.strip()}"


def test_plotting_is_where_matplotlib_is():
    """The check above can fail: the plotting package does load matplotlib."""
    code = "import sys\nimport rt70.plotting.modal\nprint('matplotlib' in sys.modules)\n"
    proc = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=False
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "True"


#: Modules outside rt70/reports/ that may import the reports: ``rt70 bench`` runs them.
REPORT_USERS = ("rt70.cli.bench",)


def _is_report(module: str) -> bool:
    return module == "rt70.reports" or module.startswith("rt70.reports.")


def _report_imports(path: Path) -> set[str]:
    """:func:`_imports`, plus ``rt70.x`` for ``from rt70 import x`` (``x`` may be a module)."""
    found = _imports(path)
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), filename=str(path))):
        if isinstance(node, ast.ImportFrom) and not node.level and node.module == "rt70":
            found |= {f"rt70.{a.name}" for a in node.names}
    return found


@pytest.mark.parametrize(
    "module", [m for m in MODULES if not _is_report(m) and m not in REPORT_USERS]
)
def test_core_never_imports_the_reports(module):
    bad = sorted(m for m in _report_imports(MODULES[module]) if _is_report(m))
    assert not bad, f"{module} (core) imports the reports {bad}; only {REPORT_USERS} may"


def test_report_rule_sees_the_reports():
    """The rule has something to check: the reports exist and the command line uses them."""
    assert "rt70.reports.book" in MODULES and "rt70.reports.stress.report" in MODULES
    assert any(_is_report(m) for m in _imports(MODULES["rt70.cli.bench"]))
    assert not _is_report("rt70.reporting") and _is_report("rt70.reports.bench")


def test_report_rule_sees_every_spelling(tmp_path):
    sample = tmp_path / "sample.py"
    sample.write_text(
        "from rt70 import errors, reports\n"
        "def f():\n"
        "    from rt70.reports.stress import runs\n"
        "    import rt70.reports.bench\n"
    )
    assert {m for m in _report_imports(sample) if _is_report(m)} == {
        "rt70.reports",
        "rt70.reports.stress",
        "rt70.reports.bench",
    }


# --- generic analyses know no telescope (issue 9) ---------------------------------------

#: The RT-70's own modules: the book's tables and what is built from them.
RT70_MODULES = (
    "rt70.scenes.rt70_data",
    "rt70.scenes.rt70_chapter2",
    "rt70.scenes.rt70_state",
    "rt70.scenes.rt70_drives",
    "rt70.scenes.rt70_optics",
    "rt70.scenes.rt70_wind",
    "rt70.scenes.rt70_visuals",
    "rt70.scenes.rt70_scenes",
    "rt70.scenes.rt70_mirror",
)

#: Generic analyses and simulation: they take what they need of a scene as arguments.
GENERIC = (
    "rt70.linear",
    "rt70.simulation.simulate",
    "rt70.simulation.states",
    "rt70.model.outputs",
    "rt70.model.optics",
    "rt70.physics.loads",
    "rt70.physics.aerodynamics",
    "rt70.physics.coefficient_tables",
    "rt70.wind.load",
    "rt70.physics.constraints",
    "rt70.physics.kkt",
    "rt70.bondgraph",
    "rt70.control.drives",
    "rt70.control.servo",
    "rt70.model.couplings",
    "rt70.control.drive_energy",
    "rt70.control.friction",
    "rt70.control.geartrains",
    "rt70.crosscheck.validate",
    "rt70.model.scene",
    "rt70.reference",
    "rt70.textbook",
    "rt70.urdf",
)


def _imported_modules(path: Path) -> set[str]:
    """:func:`_imports`, plus ``a.b.c`` for ``from a.b import c`` when c is a module."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    found = set(_imports(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and not node.level:
            found |= {f"{node.module}.{a.name}" for a in node.names} & MODULES.keys()
    return found


def _loaded_with(module: str) -> set[str]:
    """Every rt70 module that importing ``module`` may load (packages' __init__ included)."""
    seen: set[str] = set()
    todo = [module]
    while todo:
        m = todo.pop()
        parts = m.split(".")
        for k in range(1, len(parts) + 1):
            name = ".".join(parts[:k])
            if name in MODULES and name not in seen:
                seen.add(name)
                todo.extend(_imported_modules(MODULES[name]))
    return seen


def _generic_modules() -> list[str]:
    return [m for m in MODULES if any(m == g or m.startswith(g + ".") for g in GENERIC)]


def test_rt70_modules_are_all_listed():
    """A new RT-70 module under rt70/scenes/ must join RT70_MODULES to be guarded."""
    assert set(RT70_MODULES) <= MODULES.keys()
    own = {m for m in MODULES if m.startswith("rt70.scenes.rt70_")}
    assert own == set(RT70_MODULES)
    assert len(_generic_modules()) > len(GENERIC)  # the packages' modules are found


@pytest.mark.slow
@pytest.mark.parametrize("module", _generic_modules())
def test_generic_analysis_knows_no_telescope(module):
    """No generic analysis loads the RT-70's tables, chapter-2 models or states, even
    through another module: the RT-70 comes in as arguments (a scene, held coordinates,
    a start state) chosen by the command line or the reports."""
    bad = sorted(_loaded_with(module) & set(RT70_MODULES))
    assert not bad, f"{module} loads {bad}"


def test_detector_follows_from_package_imports(tmp_path):
    """``from rt70.scenes import rt70_data`` (how topology.py once imported the tables)."""
    sample = tmp_path / "sample.py"
    sample.write_text("def f():\n    from rt70.scenes import rt70_data, synthetic\n")
    assert _imported_modules(sample) >= {"rt70.scenes.rt70_data", "rt70.scenes.synthetic"}
    assert "rt70.scenes.rt70_data" in _loaded_with("rt70.scenes.rt70_chapter2")


# --- the floors (issue 22) ----------------------------------------------------------------


def _folder(module: str) -> str | None:
    """The folder of :data:`FLOORS` that ``module`` lies in (None for the face or unknown)."""
    folders = [f for floor in FLOORS for f in floor]
    inside = [f for f in folders if module == f or module.startswith(f + ".")]
    return max(inside, key=len, default=None)


def _floor(module: str) -> int:
    """The floor of ``module``: its folder's, or for the face the highest it imports."""
    if module == FACE:
        return max(_floor(m) for m in _imported_modules(MODULES[FACE]) if m != FACE)
    folder = _folder(module)
    assert folder is not None, f"{module} lies in no folder of FLOORS: give it one"
    return next(i for i, floor in enumerate(FLOORS) if folder in floor)


def test_every_module_has_a_floor():
    """A new folder must take its place in FLOORS (and a line in docs/architecture.md)."""
    lost = [m for m in MODULES if m != FACE and _folder(m) is None]
    assert not lost, f"modules in no folder of FLOORS: {lost}"
    assert len(MODULES) > 150  # the package was found


@pytest.mark.parametrize("module", sorted(set(MODULES) - {FACE}))
def test_no_import_upward_or_sideways(module):
    """A module imports its own folder or lower floors, never up nor to a neighbour."""
    floor, folder = _floor(module), _folder(module)
    bad = sorted(
        m
        for m in _imported_modules(MODULES[module])
        if m in MODULES and _folder(m) != folder and _floor(m) >= floor
    )
    assert not bad, f"{module} (floor {floor}: {FLOORS[floor]}) imports upward or sideways: {bad}"


def _circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    for start in graph:
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in graph:
                    continue
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    top = stack.pop()
                    on_stack.discard(top)
                    component.append(top)
                    if top == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return found


def _module_graph() -> dict[str, set[str]]:
    """Every module and the modules it imports, at any depth, ``if TYPE_CHECKING`` too."""
    return {m: _imported_modules(p) & MODULES.keys() - {m} for m, p in MODULES.items()}


def test_the_import_graph_has_no_circle():
    assert _circles(_module_graph()) == []


def test_circle_detector_finds_a_circle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}, "e": set()}
    assert _circles(graph) == [["a", "b", "c"]]
    assert _circles({"a": {"b"}, "b": set()}) == []


def test_floor_rule_refuses_a_step_up():
    """The rule can fail: the reader importing the simulation would be a step up."""
    assert _floor("rt70.urdf.reader") < _floor("rt70.simulation.simulate")
    assert _floor("rt70.textbook.dynamics") == _floor("rt70.reference.dynamics")
    assert _folder("rt70.textbook.dynamics") != _folder("rt70.reference.dynamics")
