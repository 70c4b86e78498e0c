"""The RT-70 with its counterreflector on a flexible column (scene ``rt70_flexible``).

The column is a steel tube written as rigid finite elements (``<rt70:beam>``) in place
of the listing's direct pair rigel–counterreflector; its section is derived from the
pair's lateral stiffness (rt70.scenes.rt70_data.COUNTERREFLECTOR_COLUMN, docs/beams.md).
"""

from __future__ import annotations

import numpy as np

from rt70.model.scene import load_scene
from rt70.scenes.rt70_data import COUNTERREFLECTOR_COLUMN as COLUMN
from rt70.scenes.rt70_data import LISTING_DIRECT_PAIRS, LISTING_OPTICAL_POINTS
from rt70.testing import assert_close
from rt70.textbook import points


def test_the_column_has_the_pairs_lateral_stiffness():
    pair = next(p for p in LISTING_DIRECT_PAIRS if p["child"] == "counterreflector")
    lateral = 3.0 * COLUMN["E"] * COLUMN["Iy"] / COLUMN["length"] ** 3
    assert_close(lateral, pair["stiffness"][0], rel=1e-12)
    D = 1.0
    d = D - 2.0 * COLUMN["wall"]
    assert_close(COLUMN["Iy"], np.pi / 64.0 * (D**4 - d**4), rel=1e-12)
    assert_close(COLUMN["A"], np.pi / 4.0 * (D**2 - d**2), rel=1e-12)
    assert 8e-3 < COLUMN["wall"] < 1e-2


def test_the_counterreflector_sits_where_the_listing_puts_it():
    """At rest (every coordinate zero) the optical points are the servo scene's."""
    flexible, servo = load_scene("rt70_flexible"), load_scene("rt70_servo")
    where = [(p["link"], np.asarray(p["xyz"], dtype=float)) for p in LISTING_OPTICAL_POINTS]
    found = [
        points.point_positions(s.textbook, s.textbook_data, np.zeros(s.textbook.nv), where)
        for s in (flexible, servo)
    ]
    assert_close(found[0], found[1], rel=1e-14, scale=np.abs(found[1]).max())


def test_the_column_replaces_the_counterreflectors_pair():
    names = load_scene("rt70_flexible").coordinate_names
    assert not [n for n in names if n.startswith("counterreflector_")]
    column = [n for n in names if n.startswith("column_sde")]
    assert len(column) == 4 * int(COLUMN["segments"])  # ux, rx, ry, rz per sde
    assert len(names) == 42 - 6 + len(column)
