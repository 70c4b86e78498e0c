"""The textbook side and the URDF reader never import Pinocchio.

The cross-check is only worth something if the two implementations are independent:
``rt70/textbook/`` and ``rt70/urdf/`` must work with Pinocchio absent.
"""

from __future__ import annotations

import ast
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("rt70/textbook", "rt70/urdf")
FORBIDDEN = {"pinocchio", "pin"}


def _sources() -> list[Path]:
    return sorted(p for pkg in PACKAGES for p in (ROOT / pkg).rglob("*.py"))


def _forbidden(module: str | None) -> bool:
    return module is not None and module.split(".")[0] in FORBIDDEN


def _pinocchio_imports(path: Path) -> list[str]:
    """Every import of pinocchio in ``path``, anywhere (module level, functions, ...)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [f"import {a.name}" for a in node.names if _forbidden(a.name)]
        elif isinstance(node, ast.ImportFrom):
            if node.level == 0 and _forbidden(node.module):
                found.append(f"from {node.module} import ...")
        elif isinstance(node, ast.Call):  # importlib.import_module("pinocchio"), __import__
            func = node.func
            name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
            if name in ("import_module", "__import__") and node.args:
                arg = node.args[0]
                if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
                    if _forbidden(arg.value):
                        found.append(f"{name}({arg.value!r})")
    return found


def test_sources_are_found():
    names = {p.relative_to(ROOT).as_posix() for p in _sources()}
    for expected in (
        "rt70/textbook/dynamics.py",
        "rt70/textbook/forces.py",
        "rt70/textbook/model.py",
        "rt70/urdf/reader.py",
    ):
        assert expected in names


@pytest.mark.parametrize("path", _sources(), ids=lambda p: p.relative_to(ROOT).as_posix())
def test_no_static_pinocchio_import(path):
    assert _pinocchio_imports(path) == [], path.relative_to(ROOT)


def test_detector_catches_nested_imports(tmp_path):
    """The static check sees imports inside functions and via importlib."""
    sample = tmp_path / "sample.py"
    sample.write_text(
        textwrap.dedent("""
        def f():
            import pinocchio as pin
            from pinocchio.utils import zero
            import importlib
            return importlib.import_module("pinocchio")
    """)
    )
    assert _pinocchio_imports(sample) == [
        "import pinocchio",
        "from pinocchio.utils import ...",
        "import_module('pinocchio')",
    ]


DYNAMIC = """
import sys
sys.modules["pinocchio"] = None  # any "import pinocchio" now raises ImportError
try:
    import pinocchio  # noqa: F401
except ImportError:
    pass
else:
    raise SystemExit("the pinocchio blocker does not work")

import numpy as np

import rt70.textbook.dynamics
import rt70.textbook.forces
import rt70.textbook.model
import rt70.urdf
from rt70.testing import assert_close
from rt70.textbook.data import Data

desc = rt70.urdf.read_urdf(sys.argv[1])
model = rt70.textbook.model.build_model(desc)
data = Data(model)
rng = np.random.default_rng(0)
q = 0.01 * rng.standard_normal(model.nv)
A = rt70.textbook.dynamics.mass_matrix(model, data, q)
assert A.shape == (model.nv, model.nv)
assert_close(A, A.T, rel=1e-12)  # symmetric to the rounding of S Θ Sᵀ (< 1 ulp measured)
assert np.all(np.linalg.eigvalsh(A) > 0)
Qc, Qd = rt70.textbook.forces.spring_damper_force(model, data, q, np.zeros(model.nv))
assert np.all(np.isfinite(Qc))
assert sys.modules["pinocchio"] is None
print("nv", model.nv)
"""


def test_textbook_runs_without_pinocchio():
    proc = subprocess.run(
        [sys.executable, "-c", DYNAMIC, str(ROOT / "urdf" / "rt70.urdf")],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=ROOT,
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith("nv "), proc.stdout
    assert int(proc.stdout.split()[1]) > 0
