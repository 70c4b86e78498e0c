"""Every notebook in notebooks/ executes without error (so they never rot), and keeps its
outputs (so it reads as a tutorial): a cell that prints or draws has its output committed
(``python notebooks/execute.py`` writes them)."""

from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

NOTEBOOKS = sorted((Path(__file__).resolve().parents[1] / "notebooks").glob("*.ipynb"))
#: Seconds a cell may take: a guard against a hang only (the slowest cell, in
#: wind_pointing.ipynb, took 39 s on a loaded 2-core machine, load average 5.6).
CELL_HANG_GUARD_S = 1200


def test_there_are_notebooks():
    assert NOTEBOOKS


@pytest.mark.slow
@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_executes(path, monkeypatch):
    monkeypatch.delenv("MPLBACKEND", raising=False)  # the kernel draws inline, headless
    nb = nbformat.read(path, as_version=4)
    committed = [bool(c.get("outputs")) for c in nb.cells if c.cell_type == "code"]
    NotebookClient(
        nb,
        timeout=CELL_HANG_GUARD_S,
        kernel_name="python3",
        resources={"metadata": {"path": str(path.parent)}},
    ).execute()
    errors = [
        o
        for c in nb.cells
        if c.cell_type == "code"
        for o in c.get("outputs", [])
        if o.output_type == "error"
    ]
    assert not errors
    produced = [bool(c.get("outputs")) for c in nb.cells if c.cell_type == "code"]
    missing = [i for i, (a, b) in enumerate(zip(committed, produced, strict=True)) if b and not a]
    assert not missing, f"code cells {missing} print or draw but have no committed output"
