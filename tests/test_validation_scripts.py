"""Every script of validation/ checks its options with argparse before any work.

A real run of a validation script takes minutes and overwrites the committed results
(validation/results/), so ``--help`` must print the usage and stop, and a misspelt
option must stop with argparse's one-line error (exit 2), never be ignored. The fast
test reads each script's source; the slow ones run ``--help`` and a bad option in a
subprocess and check that no committed result changed.
"""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCRIPTS = sorted((ROOT / "validation").glob("*.py"))
#: What the scripts write (wind_tables.py writes the package's tables).
OUTPUTS = (ROOT / "validation" / "results", ROOT / "rt70" / "wind_tables")


def _calls(tree: ast.AST):
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            func = node.func
            yield func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", None)


def test_the_scripts_are_found():
    assert len(SCRIPTS) >= 29, [p.name for p in SCRIPTS]


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.name)
def test_every_script_parses_its_options_with_argparse(script):
    calls = set(_calls(ast.parse(script.read_text(encoding="utf-8"), filename=str(script))))
    missing = {"ArgumentParser", "parse_args"} - calls
    assert not missing, (
        f"validation/{script.name} never calls {' or '.join(sorted(missing))}: give it an "
        "argparse.ArgumentParser parsed at the start of main, so that --help prints the usage "
        "and a misspelt option exits 2 instead of starting a run"
    )


def _snapshot() -> dict[Path, tuple[int, int]]:
    """Each output file's modification time and size."""
    return {
        path: (path.stat().st_mtime_ns, path.stat().st_size)
        for folder in OUTPUTS
        for path in folder.rglob("*")
        if path.is_file()
    }


def _run(script: Path, *args: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "MPLBACKEND": "Agg"}  # PYTHONPATH as the tests have it
    return subprocess.run(
        [sys.executable, str(script.relative_to(ROOT)), *args],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,  # a hang guard: --help must not start the run
        check=False,
    )


@pytest.mark.slow
@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.name)
def test_help_prints_the_usage_and_writes_nothing(script):
    before = _snapshot()
    proc = _run(script, "--help")
    assert proc.returncode == 0, proc.stderr
    assert "usage:" in proc.stdout
    assert _snapshot() == before, f"validation/{script.name} --help changed committed results"


@pytest.mark.slow
@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.name)
def test_an_unknown_option_exits_2_and_writes_nothing(script):
    before = _snapshot()
    proc = _run(script, "--no-such-option")
    assert proc.returncode == 2, proc.stderr
    assert "unrecognized arguments" in proc.stderr or "error:" in proc.stderr
    assert "Traceback" not in proc.stderr, proc.stderr
    assert _snapshot() == before, f"validation/{script.name} --no-such-option changed results"
