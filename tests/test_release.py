"""The release's metadata agrees with itself (issue 22, part 5).

The version has one source, ``[project] version`` in pyproject.toml: ``rt70 --version``
and ``rt70.__version__`` read it from the installed package's metadata.
"""

from __future__ import annotations

import importlib.metadata
import tomllib
from pathlib import Path

import pytest

import rt70
from rt70.cli import main

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
VERSION = PYPROJECT["project"]["version"]


def test_version_option_prints_the_installed_version(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    captured = capsys.readouterr()
    assert captured.out == f"rt70 {VERSION}\n"
    assert captured.err == ""


def test_version_attribute_is_the_metadata_version():
    assert rt70.__version__ == importlib.metadata.version("rt70") == VERSION
    assert "__version__" in rt70.__all__
    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        rt70.no_such_name  # noqa: B018
