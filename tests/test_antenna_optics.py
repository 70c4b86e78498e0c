"""``<rt70:optics>``: the reflector system a scene declares, read strictly, and its outputs.

The RT-70's declaration gives the same mirror outputs as the book's explicit system
(:func:`rt70.scenes.rt70_optics.rt70_mirror_system`), the same design offset and source;
a single-reflector turret gets the main mirror's outputs alone; a wrong declaration is
refused with one line naming the file and the element.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rt70.errors import ExtensionError, SceneError
from rt70.linear.linearize import equilibrium
from rt70.model import antenna
from rt70.model.outputs import evaluate
from rt70.model.scene import load_scene, scene_from_text
from rt70.scenes import rt70_optics
from rt70.testing import MIN_REL, assert_close
from rt70.urdf import RT70_NS, read_urdf_string

#: A turret without gravity: azimuth about z, elevation about x, a dish with two points and
#: a feed on a slider; q = 0 looks at the zenith.
TURRET = f"""<robot name="turret" xmlns:rt70="{RT70_NS}">
  <link name="world"/>
  <link name="base"><inertial><mass value="10"/>
    <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="dish"><inertial><mass value="5"/>
    <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="feed"><inertial><mass value="1"/>
    <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="az" type="continuous"><parent link="world"/><child link="base"/>
    <axis xyz="0 0 1"/></joint>
  <joint name="el" type="revolute"><parent link="base"/><child link="dish"/>
    <origin xyz="0 0 2"/><axis xyz="1 0 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="slide" type="prismatic"><parent link="dish"/><child link="feed"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <rt70:joint_spring name="slide_spring" joint="slide" stiffness="100"/>
  <rt70:optical_point name="focus" link="dish" xyz="0 0 4.8"/>
  <rt70:optical_point name="vertex" link="dish" xyz="0 0 0"/>
  <rt70:optical_point name="sub_focus" link="feed" xyz="0 0 4.8"/>
  <rt70:optical_point name="sub_vertex" link="feed" xyz="0 0 5.2"/>
  <rt70:mount type="az-el">
    <rt70:axis name="azimuth" joint="az"/>
    <rt70:axis name="elevation" joint="el" zero_deg="90" sign="-1" min_deg="5" max_deg="88"/>
  </rt70:mount>
  OPTICS
</robot>"""

PRIME = """<rt70:optics type="prime_focus" reference_link="dish">
    <rt70:reflector role="primary" focus="focus" vertex="vertex"/>
  </rt70:optics>"""

CASSEGRAIN = """<rt70:optics type="cassegrain" reference_link="dish">
    <rt70:reflector role="primary" focus="focus" vertex="vertex"/>
    <rt70:reflector role="secondary" focus="sub_focus" vertex="sub_vertex" support="dish"/>
  </rt70:optics>"""


def _turret(optics: str = PRIME) -> str:
    return TURRET.replace("OPTICS", optics)


@pytest.mark.parametrize("name", ["rt70", "rt70_servo"])
def test_the_rt70_declaration_gives_the_book_s_mirror_outputs(name):
    scene = load_scene(name)
    system = antenna.mirror_system(scene)
    assert_close(
        system.design_offset, rt70_optics.DESIGN_FOCAL_OFFSET, rel=MIN_REL, scale=1.2, what="d"
    )
    assert system.azimuth_axis == ("platform", (0.0, 0.0, 1.0))
    assert system.elevation_axis == ("platform", (1.0, 0.0, 0.0))
    q = equilibrium(scene, antenna.pointing(scene, 45.0, 10.0))
    declared = antenna.pointing_outputs(scene, 45.0, 10.0)
    book = rt70_optics.rt70_mirror_outputs(scene, 45.0, 10.0)
    assert [o.name for o in declared] == [o.name for o in book]
    for side in ("textbook", "reference"):
        a, b = evaluate(scene, q, declared, side), evaluate(scene, q, book, side)
        for key, value in b.items():
            # the sources differ by the rounding of cos 90° (6e-17) in the book's formula
            assert_close(a[key], value, rel=1e-9, scale=max(1.0, np.abs(value).max()), what=key)


@pytest.mark.parametrize(("elevation", "azimuth"), [(0, 0), (30, -120), (45, 10), (89, 200)])
def test_the_source_is_the_book_s(elevation, azimuth):
    source = antenna.source(load_scene("rt70_servo"), elevation, azimuth)
    expected = rt70_optics.pointing_source(elevation, azimuth)
    assert_close(source, expected, rel=1e-12, scale=1.0, what="source")


def test_a_single_reflector_has_the_main_mirror_s_outputs():
    scene = scene_from_text(_turret(), "turret.urdf")
    outs = antenna.pointing_outputs(scene, 30.0, 40.0)
    assert [o.name for o in outs] == [
        "main_mirror_axis",
        "main_mirror_misalignment",
        "main_mirror_error",
        "pointing_correction",
    ]
    q = np.zeros(len(scene.coordinate_names))
    for joint, value in antenna.pointing(scene, 30.0, 40.0).items():
        q[scene.coordinate_names.index(joint)] = value
    for side in ("textbook", "reference"):
        values = evaluate(scene, q, outs, side)
        assert_close(values["main_mirror_axis"], [0, 0, 1], rel=MIN_REL, scale=1.0, what="axis")
        assert abs(values["main_mirror_misalignment"][0]) < 1e-6  # arcsec: aimed exactly
    # a turn of the elevation joint by 10″ shows as a 10″ elevation correction
    tilt = math.radians(10.0 / 3600.0)
    q[scene.coordinate_names.index("el")] += tilt
    correction = evaluate(scene, q, outs, "reference")["pointing_correction"]
    assert_close(abs(correction[1]), 10.0, rel=1e-6, scale=10.0, what="Δβ")
    assert abs(correction[0]) < 1e-6


def test_the_sky_frame_reads_back_a_pointing():
    scene = scene_from_text(_turret(CASSEGRAIN), "turret.urdf")
    frame = antenna.sky_frame(scene)
    for elevation, azimuth in [(5.0, 0.0), (30.0, 40.0), (60.0, -170.0), (88.0, 300.0)]:
        e, a = frame.angles(antenna.source(scene, elevation, azimuth))
        assert_close(math.degrees(e[0]), elevation, rel=1e-12, scale=90.0, what="E")
        turn = (math.degrees(a[0]) - azimuth + 180.0) % 360.0 - 180.0
        assert abs(turn) < 1e-9


def test_a_two_mirror_turret_has_a_design_offset_from_its_construction():
    scene = scene_from_text(_turret(CASSEGRAIN), "turret.urdf")
    system = antenna.mirror_system(scene)
    assert system.has_counterreflector
    assert_close(system.design_offset, (0.0, 0.0, 0.0), rel=MIN_REL, scale=4.8, what="d")
    assert len(antenna.pointing_outputs(scene, 30.0, 0.0)) == 11


@pytest.mark.parametrize(
    ("optics", "message"),
    [
        (PRIME.replace("prime_focus", "newtonian"), "the type is one of"),
        (PRIME.replace("prime_focus", "cassegrain"), "it needs exactly ['primary', 'secondary']"),
        (CASSEGRAIN.replace("cassegrain", "prime_focus"), "it needs exactly ['primary']"),
        (
            PRIME.replace('focus="focus"', 'focus="focal"'),
            "focus 'focal' is no <rt70:optical_point>",
        ),
        (PRIME.replace('vertex="vertex"', 'vertex="focus"'), "focus and vertex are one point"),
        (
            PRIME.replace('vertex="vertex"', 'vertex="sub_vertex"'),
            "a reflector's points are on its own link",
        ),
        (CASSEGRAIN.replace(' support="dish"', ""), "needs 'support'"),
        (CASSEGRAIN.replace('support="dish"', 'support="feed"'), "is the reflector's own link"),
        (CASSEGRAIN.replace('support="dish"', 'support="dsh"'), "dsh"),
        (PRIME.replace('reference_link="dish"', 'reference_link="disk"'), "disk"),
        (CASSEGRAIN.replace('role="secondary"', 'role="primary"'), "the role is repeated"),
        (PRIME.replace('role="primary"', 'role="main"'), "the role is one of"),
        (
            PRIME.replace('vertex="vertex"/>', 'vertex="vertex" support="base"/>'),
            "the primary reflector has no 'support'",
        ),
    ],
)
def test_a_wrong_optics_is_one_line_naming_the_element(optics, message):
    with pytest.raises(ExtensionError) as err:
        read_urdf_string(_turret(optics), "turret.urdf")
    text = str(err.value)
    assert "turret.urdf" in text and "<rt70:" in text and message in text and "\n" not in text


def test_a_scene_without_optics_is_refused_where_outputs_are_asked():
    scene = scene_from_text(_turret(""), "turret.urdf")
    with pytest.raises(SceneError, match=r"declares no reflector system: add an <rt70:optics>"):
        antenna.pointing_outputs(scene, 30.0)
    assert antenna.pointing(scene, 30.0)  # the mount alone still points it
