"""Suite-wide settings: which tests the fast subset (``pytest -m "not slow"``) leaves out.

A test is slow when it takes over about 1.5 s on the development machine (it carries
``@pytest.mark.slow``), or when it uses one of :data:`SLOW_FIXTURES`: a module fixture
that builds something expensive once for its module (a wheel installed into a fresh
environment, a work–precision run, every robot surveyed, the book's report). Marking
only the first such test would move the fixture's cost to the next one. docs/testing.md.
"""

from __future__ import annotations

import os

import pytest

#: Module fixtures that take seconds to build: every test that uses one is slow.
SLOW_FIXTURES = frozenset({"installed", "quick_rows", "runs", "surveyed", "report", "budgets"})


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Mark the tests that use a fixture of :data:`SLOW_FIXTURES` as slow."""
    for item in items:
        if SLOW_FIXTURES.intersection(getattr(item, "fixturenames", ())):
            item.add_marker(pytest.mark.slow)


def pytest_configure(config: pytest.Config) -> None:
    """Every ``rt70`` command a test starts runs in its own interpreter, even where a warm
    process of this user runs (``rt70 warm``): the tests of the warm process start their own,
    without the later warm-up (a compile of a minute or more in the background when numba's
    cache lacks the compiled BDF; ``tests/test_warm.py`` tests it with a short command)."""
    os.environ["RT70_WARM"] = "0"
    os.environ["RT70_WARM_LATER"] = "0"
