"""The release's metadata agrees with itself (issue 22, part 5).

The version has one source, ``rt70/_version.py``: pyproject.toml reads it into the
package's metadata (``dynamic``), ``rt70 --version`` and ``rt70.__version__`` import it;
CHANGELOG.md's latest release and CITATION.cff name the same version and date. The wheel's contents
(the ``py.typed`` marker) are checked in tests/test_packaging.py.
"""

from __future__ import annotations

import importlib.metadata
import re
import tomllib
from pathlib import Path

import pytest
import yaml

import rt70
from rt70.cli.main import main

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
VERSION = re.search(
    r'^__version__ = "(\d+\.\d+\.\d+)"$',
    (ROOT / "rt70" / "_version.py").read_text(encoding="utf-8"),
    re.M,
).group(1)


def test_pyproject_reads_the_one_version():
    assert "version" not in PYPROJECT["project"]
    assert PYPROJECT["project"]["dynamic"] == ["version"]
    dynamic = PYPROJECT["tool"]["setuptools"]["dynamic"]["version"]
    assert dynamic == {"attr": "rt70._version.__version__"}


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


def _latest_release() -> tuple[str, str]:
    """Version and date of CHANGELOG.md's first ``## [X.Y.Z] - YYYY-MM-DD`` heading."""
    text = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    match = re.search(r"^## \[(\d+\.\d+\.\d+)\] - (\d{4}-\d{2}-\d{2})$", text, re.M)
    assert match, "CHANGELOG.md has no release heading '## [X.Y.Z] - YYYY-MM-DD'"
    return match.group(1), match.group(2)


def test_changelog_latest_release_is_the_version():
    assert _latest_release()[0] == VERSION


def test_citation_names_this_release():
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    assert cff["cff-version"] == "1.2.0"
    assert str(cff["version"]) == VERSION
    assert str(cff["date-released"]) == _latest_release()[1]
    assert cff["license"] == PYPROJECT["project"]["license"] == "MIT"
    assert cff["authors"] == [{"name": "the rt70 developers"}]
    (book,) = cff["references"]
    assert book["type"] == "book" and book["year"] == 2007


def test_license_file_is_the_mit_licence_named_in_pyproject():
    text = (ROOT / "LICENSE").read_text(encoding="utf-8")
    assert text.startswith("MIT License\n\nCopyright (c) 2026 the rt70 developers\n")
    assert PYPROJECT["project"]["license-files"] == ["LICENSE"]
