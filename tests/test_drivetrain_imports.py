"""The friction and gear-train modules are generic: they load none of the RT-70's tables."""

from __future__ import annotations

import pytest
from test_import_rules import RT70_MODULES, _loaded_with


@pytest.mark.parametrize("module", ["rt70.friction", "rt70.geartrains"])
def test_drive_train_elements_know_no_telescope(module):
    assert _loaded_with(module)  # the module is found
    bad = sorted(_loaded_with(module) & set(RT70_MODULES))
    assert not bad, f"{module} loads {bad}"


def test_the_rig_report_does_load_the_table():
    """The check above can fail: the report that builds the RT-70 rig loads the table."""
    assert "rt70.scenes.rt70_drives" in _loaded_with("rt70.reports.drivetrain")
