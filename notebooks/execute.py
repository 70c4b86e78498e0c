"""Execute every notebook in this folder in place, keeping its outputs (text and figures).

Run after editing a notebook: ``python notebooks/execute.py``. The outputs are kept so the
notebooks read as tutorials on GitHub; tests/test_notebooks.py executes them again and
checks that every cell that prints or draws has its output committed.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import nbformat
from nbclient import NotebookClient


def main() -> int:
    os.environ.pop("MPLBACKEND", None)  # the kernel's inline backend embeds the figures
    for path in sorted(Path(__file__).resolve().parent.glob("*.ipynb")):
        nb = nbformat.read(path, as_version=4)
        NotebookClient(
            nb,
            timeout=600,
            kernel_name="python3",
            resources={"metadata": {"path": str(path.parent)}},
        ).execute()
        tmp = path.with_suffix(".ipynb.tmp")
        nbformat.write(nb, tmp)
        tmp.replace(path)  # atomic: a failed run leaves the notebook as it was
        print(f"executed {path.name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
