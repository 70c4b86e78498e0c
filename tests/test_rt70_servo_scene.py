"""The rt70_servo scene: the listing with the counterweight below the elevation axis (errata 12)."""

from __future__ import annotations

import numpy as np
import pytest

from rt70 import reference
from rt70.model.scene import load_scene
from rt70.scenes import rt70_data
from rt70.scenes.rt70_drives import NOMINAL_TORQUE
from rt70.scenes.rt70_state import ELEVATION_COORDINATE
from rt70.testing import assert_close
from rt70.textbook import dynamics

G = 9.81  # the listing's gravity (rt70_data.LISTING_GRAVITY)


def test_only_the_counterweight_offset_differs():
    for listing, servo in zip(rt70_data.LISTING_BODIES, rt70_data.SERVO_BODIES, strict=True):
        changed = {k for k in listing if listing[k] != servo[k]}
        if listing["name"] == "counterweight":
            assert changed == {"offset"}
            assert servo["offset"] == (0.0, 0.0, -listing["offset"][2])
        else:
            assert not changed


@pytest.mark.parametrize("name, unbalance", [("rt70", 1.303435e8), ("rt70_servo", -2.033809e7)])
def test_gravity_moment_about_the_horizontal_elevation_axis(name, unbalance):
    """Both sides: the gravity moment on the elevation axis with the dish at the horizon."""
    scene = load_scene(name)
    names = scene.textbook.coordinate_names
    q = np.zeros(len(names))
    q[names.index(ELEVATION_COORDINATE)] = np.pi / 2  # elevation 0°
    k = names.index(ELEVATION_COORDINATE)
    textbook = dynamics.gravity_force(scene.textbook, scene.textbook_data, q)[k]
    pin_side = reference.gravity_force(scene.reference, scene.reference_data, q)[k]
    # rotating +β about x tips +z towards −y: gravity pushes the +z bodies on towards +β
    assert_close(textbook, unbalance, rel=1e-6)
    assert_close(pin_side, textbook, rel=1e-12)


def test_the_printed_counterweight_cannot_be_held_by_the_book_drive():
    """Errata 12: 2.66 × nominal torque as printed, 0.41 × with the counterweight below."""
    arms = {"mirror_base": 11.0, "main_mirror": 31.0, "rigel": 38.0, "counterreflector": 44.0}
    for bodies, ratio in ((rt70_data.LISTING_BODIES, 2.658), (rt70_data.SERVO_BODIES, -0.4148)):
        by_name = {b["name"]: b for b in bodies}
        moment = sum(by_name[n]["mass"] * d for n, d in arms.items())
        moment += by_name["counterweight"]["mass"] * by_name["counterweight"]["offset"][2]
        # the errata's numbers, to ±1 in their last printed digit (1e-3 of 2.658)
        assert_close(moment * G / NOMINAL_TORQUE, ratio, rel=4e-4)
