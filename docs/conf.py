"""Sphinx configuration of rt70's documentation site (docs/about-docs.md says why Sphinx).

The source directory is the repository itself, so that the README, docs/ and the
results pages of validation/results/ link to each other by the same relative paths on
GitHub and on the site::

    .venv/bin/sphinx-build -c docs -W --keep-going . _site

Built with ``-t userpages`` it leaves out the API reference (the pages generated from
the docstrings of the package), so that the user pages can be held to no warnings on
their own (tests/test_front_door.py).
"""

from __future__ import annotations

from pathlib import Path

import rt70

ROOT = Path(__file__).resolve().parents[1]

project = "rt70"
author = "the rt70 authors"
copyright = "rt70 authors, MIT licence"  # noqa: A001 - Sphinx's name
release = version = rt70.__version__

# The README is the landing page: README.html, and index.html sends the reader to it.
root_doc = "README"
USER_PAGES = ["README.md", "CHANGELOG.md", "docs/*.md", "validation/results/*.md"]
API_PAGES = ["docs/api/**"]
include_patterns = USER_PAGES + ([] if tags.has("userpages") else API_PAGES)  # noqa: F821
exclude_patterns = ["docs/api/_generated/**"] if tags.has("userpages") else []  # noqa: F821

extensions = ["myst_parser"]
if not tags.has("userpages"):  # noqa: F821
    extensions += ["sphinx.ext.autodoc", "sphinx.ext.autosummary", "numpydoc"]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}

# GitHub's anchors (``urdf-extensions.md#errors``) resolve on the site too.
myst_heading_anchors = 4

# Docstrings are numpy style (Parameters / Returns / Raises / Attributes sections). Types
# are shown as written ("ndarray, shape (n, n)"), not turned into links: their words
# ("shape", "n") would link to unrelated attributes of the same name.
numpydoc_xref_param_type = False
numpydoc_attributes_as_param_list = True
numpydoc_show_class_members = False
autodoc_typehints = "signature"
autodoc_member_order = "bysource"
autodoc_default_options = {"members": True, "show-inheritance": True, "ignore-module-all": True}
# The class-based autodoc documents a type alias as "alias of ..." (_alias_signature).
autodoc_use_legacy_class_based = True
autosummary_generate = True
autosummary_ignore_module_all = True

# Offline: no intersphinx, no remote images; the theme ships its own assets.
html_theme = "furo"
html_title = f"rt70 {release}"
html_static_path: list[str] = []
html_copy_source = False
html_show_sourcelink = False


def _toctree() -> str:
    """The site's navigation, added to the README only when Sphinx reads it.

    GitHub shows the README as it is; the site needs a toctree in its root document.
    """
    pages = sorted(p.relative_to(ROOT).with_suffix("").as_posix() for p in ROOT.glob("docs/*.md"))
    guides = [p for p in pages if p in GUIDES]
    others = [p for p in pages if p not in GUIDES]
    results = sorted(
        p.relative_to(ROOT).with_suffix("").as_posix() for p in ROOT.glob("validation/results/*.md")
    )
    blocks = [
        ("Guides", [p for p in GUIDES if p in guides]),
        ("Topics", others),
        ("Results", results),
        ("Project", ["CHANGELOG"]),
    ]
    if not tags.has("userpages"):  # noqa: F821
        blocks.insert(2, ("API reference", ["docs/api/index"]))
    text = ""
    for caption, entries in blocks:
        body = "\n".join(entries)
        text += f"\n\n```{{toctree}}\n:hidden:\n:caption: {caption}\n\n{body}\n```\n"
    return text


#: The pages written for users by what they do, first in the navigation.
GUIDES = [
    "docs/servo-engineer",
    "docs/structural-engineer",
    "docs/python",
    "docs/commands",
    "docs/validation",
    "docs/simulation",
    "docs/performance",
    "docs/about-docs",
]


def _add_toctree(app, docname: str, source: list[str]) -> None:
    if docname == root_doc:
        source[0] += _toctree()


def _redirect_index(app, exception) -> None:
    if exception is None and app.builder.format == "html":
        (Path(app.outdir) / "index.html").write_text(
            '<!DOCTYPE html><meta charset="utf-8"><title>rt70</title>'
            '<meta http-equiv="refresh" content="0; url=README.html">'
            '<a href="README.html">rt70</a>\n',
            encoding="utf-8",
        )


def _alias_signature(app, what, name, obj, options, signature, return_annotation):
    """A module-level type alias (``Point = tuple[str, ...]``) has no signature.

    Python 3.11 takes ``tuple[str]`` for a class, so autodoc documents the alias as
    "alias of tuple[...]" with its ``#:`` comment, but would show ``tuple``'s
    constructor as its signature, and numpydoc's signature of it makes Sphinx 9's
    autosummary fail (an IndexError in ``_format_signatures``). ``(None, None)`` is the
    answer both accept as "no signature", and it stops numpydoc's handler.
    """
    import types

    return (None, None) if isinstance(obj, types.GenericAlias) else None


def setup(app):
    """Add the navigation to the README and send index.html to it; document type aliases."""
    if not tags.has("userpages"):  # noqa: F821
        app.connect("autodoc-process-signature", _alias_signature, priority=400)
    app.connect("source-read", _add_toctree)
    app.connect("build-finished", _redirect_index)
