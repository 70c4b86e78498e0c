"""The front door: what ``import rt70`` exports, the README, and the documentation site.

- ``rt70`` exports the names a user starts with, each resolving to the object of the
  module it is defined in, and importing it stays light (a fresh interpreter, checked in
  ``sys.modules``).
- The README keeps its promises: the quick-start commands CI runs, at most 150 lines,
  every command's page, every link to a file that exists.
- The results pages are headed by the command, commit and date that made them.
- The site builds without a warning (docs/about-docs.md): the user pages alone, and the
  whole site with the API reference generated from the docstrings.
"""

from __future__ import annotations

import importlib
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import rt70

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"

#: name -> the module that defines it.
EXPORTS = {
    "Scene": "rt70.model.scene",
    "load_scene": "rt70.model.scene",
    "scene_from_text": "rt70.model.scene",
    "scene_names": "rt70.model.scene",
    "cross_check": "rt70.crosscheck.validate",
    "simulate": "rt70.simulation.simulate",
    "equilibrium": "rt70.linear.linearize",
    "linearize": "rt70.linear.linearize",
    "modes": "rt70.linear.modal",
    "plant": "rt70.linear.plant",
    "CoordinateInput": "rt70.linear.plant",
    "CoordinateOutput": "rt70.linear.plant",
    "rt70_pointing": "rt70.scenes.rt70_state",
}


# --- the package's exports ---------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(EXPORTS))
def test_each_export_is_the_object_of_its_module(name):
    assert name in rt70.__all__ and name in dir(rt70)
    assert getattr(rt70, name) is getattr(importlib.import_module(EXPORTS[name]), name)


def test_all_resolves_and_dir_shows_it():
    for name in rt70.__all__:
        assert getattr(rt70, name) is not None, name
    assert set(rt70.__all__) <= set(dir(rt70))
    assert isinstance(rt70.__version__, str)
    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        rt70.no_such_name  # noqa: B018 - the attribute access is the test


def test_submodules_still_import_through_the_package():
    """``from rt70 import reference`` (used across the package) finds the submodule."""
    from rt70 import reference

    assert reference.__name__ == "rt70.reference"


def _fresh(code: str) -> str:
    proc = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=False
    )
    assert proc.returncode == 0, proc.stderr
    return proc.stdout.strip()


def test_import_rt70_is_light():
    """``import rt70`` loads nothing of rt70 but its version and errors, no heavy library."""
    out = _fresh(
        "import sys, rt70\n"
        "heavy = ('pinocchio', 'scipy.integrate', 'matplotlib', 'numba', 'dask')\n"
        "print(sorted(m for m in sys.modules if m.split('.')[0] == 'rt70'))\n"
        "print(sorted(m for m in heavy if m in sys.modules))\n"
    )
    own, heavy = out.splitlines()
    assert own == "['rt70', 'rt70._version', 'rt70.errors']"
    assert heavy == "[]"


def test_reading_a_scene_through_the_package_loads_no_pinocchio():
    out = _fresh(
        "import sys, rt70\n"
        "scene = rt70.load_scene('three_masses')\n"
        "print(scene.coordinate_names)\n"
        "print(sorted(m for m in ('pinocchio', 'scipy.integrate', 'matplotlib')"
        " if m in sys.modules))\n"
    )
    assert out.splitlines()[-1] == "[]"


def test_reading_a_scene_with_wind_elements_fits_no_spline():
    """rt70_servo's wind elements name built-in coefficient tables; their splines (and
    scipy.interpolate, which imports scipy.optimize) wait for the first wind load."""
    out = _fresh(
        "import sys, rt70\n"
        "scene = rt70.load_scene('rt70_servo')\n"
        "print(len(scene.description.winds))\n"
        "print(sorted(m for m in ('scipy.interpolate', 'scipy.optimize') if m in sys.modules))\n"
    )
    count, loaded = out.splitlines()[-2:]
    assert int(count) > 0 and loaded == "[]"


# --- the README ----------------------------------------------------------------------------

QUICK_START = (
    "python3.11 -m venv .venv && .venv/bin/pip install -q . && .venv/bin/rt70 validate",
    "python3.11 -m venv .venv && .venv/bin/pip install -q -e '.[test]' && .venv/bin/pytest",
)


def test_readme_is_a_front_door():
    text = README.read_text(encoding="utf-8")
    assert len(text.splitlines()) <= 150
    for command in QUICK_START:
        assert f"\n{command}\n" in text, command
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert QUICK_START[1] in ci


def test_readme_lists_every_command_with_its_page():
    from rt70.cli.main import build_parser

    parser = build_parser()
    commands = next(a for a in parser._actions if a.dest == "command").choices
    text = README.read_text(encoding="utf-8")
    table = text[text.index("## Commands") : text.index("## Using it from Python")]
    for name in commands:
        row = re.search(rf"^\| `rt70 {name}\b.*\| \[[^]]+\]\(([^)#]+)[^)]*\) \|$", table, re.M)
        assert row, f"rt70 {name} has no row with a page in the README's table of commands"
        assert (ROOT / row.group(1)).is_file(), row.group(1)


#: A page named in a help text or message: "(docs: 'Title', docs/page.md".
PAGE_REFERENCE = re.compile(r"docs: '([^']+)',\s*(docs/[\w.-]+\.md)")


def _help_texts() -> str:
    """Every description, help and epilog of the ``rt70`` parser and its subcommands."""
    from rt70.cli.main import build_parser

    parser = build_parser()
    parsers = [parser, *next(a for a in parser._actions if a.dest == "command").choices.values()]
    texts = [t for p in parsers for t in (p.description, p.epilog) if t]
    texts += [a.help for p in parsers for a in p._actions if a.help]
    return "\n".join(texts)


def _page_references() -> list[tuple[str, str]]:
    sources = [p.read_text(encoding="utf-8") for p in sorted((ROOT / "rt70").rglob("*.py"))]
    found = PAGE_REFERENCE.findall("\n".join([_help_texts(), *sources]))
    # a title wrapped in a docstring is one title; one split across "..." "..." in the
    # source is seen whole in the parser's help texts
    return sorted({(" ".join(title.split()), page) for title, page in found if '"' not in title})


def test_help_texts_and_messages_name_pages_by_their_titles():
    """A user who installed with pip finds a page by its title on the site: each title
    named beside a docs path is that page's first heading."""
    references = _page_references()
    assert len(references) >= 8, references  # the search sees the help texts
    for title, page in references:
        path = ROOT / page
        assert path.is_file(), f"{page} (named with '{title}') does not exist"
        heading = path.read_text(encoding="utf-8").splitlines()[0].removeprefix("# ")
        assert heading == title or heading.startswith((f"{title}: ", f"{title} (")), (
            f"{page} is headed '{heading}', named as '{title}'"
        )


def _links(path: Path) -> list[str]:
    text = path.read_text(encoding="utf-8")
    text = re.sub(r"```.*?```", "", text, flags=re.S)
    return [m for m in re.findall(r"\]\(([^)\s]+)\)", text) if "://" not in m]


DOCS = sorted((ROOT / "docs").glob("*.md"))
RESULTS = sorted((ROOT / "validation" / "results").glob("*.md"))


@pytest.mark.parametrize("path", [README, *DOCS, *RESULTS], ids=lambda p: str(p.relative_to(ROOT)))
def test_relative_links_reach_files(path):
    for link in _links(path):
        target = link.split("#")[0]
        if target:
            assert (path.parent / target).exists(), f"{path.name}: {link}"


def test_readme_links_every_docs_page():
    text = README.read_text(encoding="utf-8")
    missing = [p.name for p in DOCS if f"(docs/{p.name}" not in text]
    assert not missing, f"pages the README does not link: {missing}"


#: No header: book.md is regenerated by tests/test_book.py and compared with the committed
#: file as a whole; README.md is the index of the others.
UNHEADED = ("book.md", "README.md")
HEADER = re.compile(r"> `[^`]+` · commit [0-9a-f]{7,40} · \d{4}-\d{2}-\d{2}")


@pytest.mark.parametrize(
    "path", [p for p in RESULTS if p.name not in UNHEADED], ids=lambda p: p.name
)
def test_results_page_is_headed_by_command_commit_and_date(path):
    lines = path.read_text(encoding="utf-8").splitlines()
    assert lines[0].startswith("# ")
    assert HEADER.fullmatch(lines[2]), lines[2]


# --- the documentation site ----------------------------------------------------------------


def _build(out: Path, *options: str) -> subprocess.CompletedProcess:
    """``sphinx-build -c docs -W --keep-going . OUT`` (docs/about-docs.md)."""
    return subprocess.run(
        [sys.executable, "-m", "sphinx", "-c", "docs", "-W", "--keep-going", "-q"]
        + [*options, ".", str(out)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=False,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )


@pytest.mark.slow
def test_the_user_pages_build_in_the_sites_theme_without_a_warning(tmp_path):
    """README, docs/, results and changelog as the site shows them (Furo): every link,
    anchor, table and toctree resolves."""
    proc = _build(tmp_path / "site", "-j", "auto", "-t", "userpages")
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "site" / "README.html").is_file()
    assert (tmp_path / "site" / "docs" / "validation.html").is_file()


@pytest.mark.slow
def test_the_whole_site_builds_without_a_warning(tmp_path):
    """The user pages and the API reference generated from the docstring of every public
    module: every link, anchor, table, toctree and docstring resolves.

    Written in Sphinx's ``basic`` theme: Furo draws the whole navigation tree into each
    of the ~250 pages, which doubled this build (197 s against 95 s, measured); the
    theme adds no content, and the test above builds the user pages in Furo.
    """
    proc = _build(tmp_path / "site", "-j", "auto", "-D", "html_theme=basic")
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "site" / "README.html").is_file()
    assert (tmp_path / "site" / "docs" / "api" / "_generated" / "rt70.linear.plant.html").is_file()
