"""Choosing a side (docs/architecture.md): one word, one accessor, twin modules of one name.

The choice between Pinocchio's algorithms and the book's is ``side`` everywhere, with
the values ``"reference"`` and ``"textbook"``; the old spellings (``backend=``,
``--backend``, ``"pinocchio"``) are refused with the new one. :func:`rt70.model.sides.side_of`
gives a scene's side its model, data and mirrored modules, which carry one name and the
same functions on both sides (:data:`rt70.model.sides.TWINS`).
"""

from __future__ import annotations

import ast
import importlib
import inspect
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from rt70.cli.main import main
from rt70.errors import Rt70Error
from rt70.model import sides
from rt70.model.scene import load_scene
from rt70.model.sides import SIDES, TWINS, Side, check_side, side_of

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "rt70"

#: Modules both sides have under one name that are not twins of the accessor: each
#: side's own model (its constructor takes different things) and the package.
NOT_TWINS = {"__init__", "model"}


@pytest.fixture(scope="module")
def pendulum():
    return load_scene("double_pendulum")


# --- the twin modules ---------------------------------------------------------------------


def _stems(side: str) -> set[str]:
    return {p.stem for p in (PACKAGE / side).glob("*.py")}


def test_the_sides_mirror_each_other_under_one_name():
    """Every module both sides have is a twin, and every twin is on both sides."""
    common = _stems("textbook") & _stems("reference")
    assert common - NOT_TWINS == set(TWINS)
    assert set(TWINS) <= _stems("textbook") and set(TWINS) <= _stems("reference")


@pytest.mark.parametrize("twin", sorted(TWINS))
def test_twins_have_the_same_functions(twin):
    """The shared functions exist on both sides with the same parameters."""
    textbook = importlib.import_module(f"rt70.textbook.{twin}")
    reference = importlib.import_module(f"rt70.reference.{twin}")
    assert TWINS[twin], twin
    for name in TWINS[twin]:
        f, g = getattr(textbook, name), getattr(reference, name)
        assert list(inspect.signature(f).parameters) == list(inspect.signature(g).parameters), (
            f"{twin}.{name}"
        )


@pytest.mark.parametrize("side", SIDES)
def test_the_accessor_gives_each_side_its_modules(pendulum, side):
    s = side_of(pendulum, side)
    assert isinstance(s, Side) and s.name == side
    assert s.model is getattr(pendulum, side)
    assert s.data is getattr(pendulum, f"{side}_data")
    for twin in TWINS:
        module = getattr(s, twin)
        assert module is s.module(twin)
        assert module.__name__ == f"rt70.{side}.{twin}"
    with pytest.raises(Rt70Error, match="no mirrored module 'spatial'"):
        s.module("spatial")


def test_the_accessor_exposes_every_twin():
    """A twin added to TWINS is a property of Side, and Side has no other module."""
    modules = {n for n, v in vars(Side).items() if isinstance(v, property)}
    assert modules == set(TWINS)


def test_one_call_gives_the_same_numbers_on_both_sides(pendulum):
    q = np.array([0.3, -0.2])
    A = [
        (lambda s: s.dynamics.mass_matrix(s.model, s.data, q))(side_of(pendulum, side))
        for side in SIDES
    ]
    np.testing.assert_allclose(A[0], A[1], rtol=1e-12)


#: Importing the accessor and using the textbook side through it loads no Pinocchio.
TEXTBOOK_ONLY = """
import sys
sys.modules["pinocchio"] = None  # any "import pinocchio" now raises ImportError

import numpy as np

from rt70.model.scene import load_scene
from rt70.model.sides import TWINS, side_of

scene = load_scene("double_pendulum")
s = side_of(scene, "textbook")
for twin in TWINS:
    getattr(s, twin)
print(s.dynamics.mass_matrix(s.model, s.data, np.zeros(2)).shape)
assert sys.modules["pinocchio"] is None
assert not any(m.startswith("rt70.reference") for m in sys.modules), "reference loaded"
"""


def test_the_textbook_side_through_the_accessor_loads_no_pinocchio():
    proc = subprocess.run(
        [sys.executable, "-c", TEXTBOOK_ONLY],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=ROOT,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "(2, 2)"


# --- no hand-written dispatch left ----------------------------------------------------------


def _side_of_import(node: ast.AST) -> str | None:
    """``"textbook"`` or ``"reference"`` if ``node`` imports from that side."""
    if isinstance(node, ast.ImportFrom) and node.module and not node.level:
        names = [f"{node.module}.{a.name}" for a in node.names]
    elif isinstance(node, ast.Import):
        names = [a.name for a in node.names]
    else:
        return None
    for side in SIDES:
        if any(n == f"rt70.{side}" or n.startswith(f"rt70.{side}.") for n in names):
            return side
    return None


def _imported_sides(nodes: list[ast.stmt]) -> set[str]:
    """The sides the statements import from, at any depth."""
    return {_side_of_import(n) for n in ast.walk(ast.Module(nodes, []))} - {None}


def _dispatches(tree: ast.AST) -> list[int]:
    """Lines of ``if …: from rt70.<one side> import …`` with the other side imported in
    its ``else`` or after it in the same block (``if side == "textbook": … return``)."""
    found = []
    for node in ast.walk(tree):
        for field in ("body", "orelse", "finalbody"):
            block = getattr(node, field, None)
            if not isinstance(block, list):
                continue
            for i, stmt in enumerate(block):
                if not isinstance(stmt, ast.If):
                    continue
                here = _imported_sides(stmt.body)
                there = _imported_sides(stmt.orelse + block[i + 1 :])
                if here and there - here:
                    found.append(stmt.lineno)
    return sorted(set(found))


def test_the_dispatch_detector_finds_one():
    tree = ast.parse(
        textwrap.dedent("""
        def f(side):
            if side == "textbook":
                from rt70.textbook import points
            else:
                from rt70.reference import points
            return points
        """)
    )
    assert _dispatches(tree) == [3]
    assert _dispatches(ast.parse("if x:\n    from rt70.textbook import points\n")) == []
    tree = ast.parse(
        textwrap.dedent("""
        def f(side):
            if side == "reference":
                from rt70.reference.points import point_positions
                return point_positions
            from rt70.textbook.points import point_positions
            return point_positions
        """)
    )
    assert _dispatches(tree) == [3]


@pytest.mark.parametrize(
    "path",
    sorted(p for p in PACKAGE.rglob("*.py") if p.parent.name not in SIDES),
    ids=lambda p: p.relative_to(ROOT).as_posix(),
)
def test_no_module_dispatches_by_hand(path):
    """Modules reach a side through rt70.model.sides, not by importing each side in turn."""
    assert _dispatches(ast.parse(path.read_text(encoding="utf-8"))) == []


# --- the old spellings are refused ----------------------------------------------------------


def test_the_side_names():
    assert SIDES == ("reference", "textbook")
    assert [check_side(s) for s in SIDES] == list(SIDES)
    with pytest.raises(Rt70Error, match="side 'pinocchio' is now 'reference'"):
        check_side("pinocchio")
    with pytest.raises(Rt70Error, match="unknown side 'dense'.*'reference' = Pinocchio"):
        check_side("dense")
    with pytest.raises(Rt70Error, match="unknown side None"):
        check_side(None)


def test_pinocchio_is_refused_wherever_a_side_is_taken(pendulum):
    from rt70.linear import linearize as lin
    from rt70.model import outputs
    from rt70.simulation.simulate import simulate

    q = np.zeros(2)
    for call in (
        lambda: side_of(pendulum, "pinocchio"),
        lambda: simulate(pendulum, (0.0, 0.01), None, "pinocchio"),
        lambda: lin.stiffness_matrix(pendulum, q, side="pinocchio"),
        lambda: outputs.evaluate(pendulum, q, [], "pinocchio"),
    ):
        with pytest.raises(Rt70Error, match="'pinocchio' is now 'reference'"):
            call()


def test_pinocchio_is_refused_by_the_couplings_and_the_wind():
    from rt70.model.couplings import SceneCoupling
    from rt70.physics.aerodynamics import WindCondition
    from rt70.wind.load import WindLoad

    servo = load_scene("rt70_servo")
    drive = servo.description.drives[0]
    with pytest.raises(Rt70Error, match=f"drive '{drive.name}': side 'pinocchio' is now"):
        SceneCoupling(servo, drive, "pinocchio")
    with pytest.raises(Rt70Error, match="wind load: side 'pinocchio' is now 'reference'"):
        WindLoad(servo, WindCondition(10.0, 0.0), side="pinocchio")


def test_backend_keyword_is_refused_naming_side(pendulum):
    from rt70.reports.stress.runs import run_capped
    from rt70.simulation.simulate import simulate
    from rt70.telescope.scenarios import run_scenario, scenario

    with pytest.raises(TypeError, match=r"simulate\(\): backend= is now side="):
        simulate(pendulum, (0.0, 0.01), backend="textbook")
    with pytest.raises(TypeError, match=r"run_scenario\(\): backend= is now side="):
        run_scenario(pendulum, scenario("hold"), backend="pinocchio")
    with pytest.raises(TypeError, match=r"run_capped\(\): backend= is now side="):
        run_capped(pendulum, (0.0, 0.01), backend="pinocchio")
    assert "side" in inspect.signature(simulate).parameters  # the wrapper keeps it


def test_refusal_decorator_passes_other_calls():
    @sides.refuses_backend
    def f(a, side="reference"):
        """Return its arguments."""
        return a, side

    assert f(1, side="textbook") == (1, "textbook") and f.__name__ == "f"
    with pytest.raises(TypeError, match=r"f\(\): backend= is now side="):
        f(1, backend="textbook")


@pytest.mark.parametrize(
    "argv, new",
    [
        (["simulate", "rt70", "--backend", "pinocchio"], "'--side reference'"),
        (["simulate", "rt70", "--backend=textbook"], "'--side textbook'"),
        (["simulate", "rt70", "--backend"], "'--side reference' or '--side textbook'"),
        (["cart", "--backend", "pinocchio"], "'--side reference'"),
    ],
)
def test_backend_option_is_one_line_naming_side(argv, new, capsys):
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert err.startswith(
        f"rt70: error: --backend is now --side (reference = Pinocchio, textbook): use {new}"
    )


@pytest.mark.parametrize("command", ["simulate rt70", "cart"])
def test_side_option_refuses_pinocchio_naming_reference(command, capsys):
    with pytest.raises(SystemExit) as stop:
        main([*command.split(), "--side", "pinocchio"])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "argument --side: side 'pinocchio' is now 'reference'" in err


def test_side_option_is_in_the_help(capsys):
    for command in ("simulate", "cart"):
        with pytest.raises(SystemExit):
            main([command, "--help"])
        out = capsys.readouterr().out
        assert "--side {reference,textbook}" in out and "--backend" not in out
