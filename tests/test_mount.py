"""``<rt70:mount>``: the pointing axes a scene declares, read strictly, and the pointings.

The RT-70's scenes declare theirs (azimuth ``platform_rz``, elevation ``base_rx = 90° − E``)
and give the same held coordinates as :func:`rt70.scenes.rt70_state.rt70_pointing`; a
wrong mount is refused with one line naming the file and the element; a scene without
one is refused where a pointing is asked for.
"""

from __future__ import annotations

import math

import pytest

from rt70.errors import ExtensionError, SceneError
from rt70.model.antenna import mount_of, pointing
from rt70.model.scene import load_scene, scene_from_text
from rt70.scenes.rt70_state import rt70_pointing
from rt70.testing import MIN_REL, assert_close
from rt70.urdf import RT70_NS, read_urdf_string

#: A turret: azimuth about z, elevation about x, and a slider that is no rotary axis.
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
    <axis xyz="1 0 0"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="slide" type="prismatic"><parent link="dish"/><child link="feed"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  MOUNT
</robot>"""

GOOD = """<rt70:mount type="az-el">
    <rt70:axis name="azimuth" joint="az"/>
    <rt70:axis name="elevation" joint="el" zero_deg="90" sign="-1" min_deg="5" max_deg="88"/>
  </rt70:mount>"""


def _turret(mount: str = GOOD):
    return TURRET.replace("MOUNT", mount)


def test_the_rt70_scenes_declare_their_axes():
    for name in ("rt70", "rt70_servo", "rt70_jack"):
        mount = mount_of(load_scene(name))
        assert mount.type == "az-el"
        assert [(a.name, a.joint, a.sign) for a in mount.axes] == [
            ("azimuth", "platform_rz", 1),
            ("elevation", "base_rx", -1),
        ]


@pytest.mark.parametrize(("elevation", "azimuth"), [(0, 0), (30, -120), (45, 10), (90, 359)])
def test_the_rt70_pointing_is_the_declared_one(elevation, azimuth):
    declared = pointing(load_scene("rt70_servo"), elevation, azimuth)
    expected = rt70_pointing(elevation, azimuth)
    assert declared.keys() == expected.keys()
    for joint, q in expected.items():
        assert_close(declared[joint], q, rel=MIN_REL, scale=math.pi, what=joint)


def test_a_mount_reads_its_convention_in_degrees():
    mount = read_urdf_string(_turret(), "turret.urdf").mount
    el = mount.axis("elevation")
    assert (el.joint, el.sign) == ("el", -1)
    assert_close(el.zero, math.pi / 2, rel=MIN_REL, scale=math.pi, what="zero")
    assert_close(
        (el.lower, el.upper), (math.radians(5), math.radians(88)), rel=MIN_REL, scale=math.pi
    )
    assert_close(el.angle(el.coordinate(0.3)), 0.3, rel=MIN_REL, scale=1.0, what="round trip")
    az = mount.axis("azimuth")
    assert (az.zero, az.sign, az.lower, az.upper) == (0.0, 1, -2 * math.pi, 2 * math.pi)


def test_a_pointing_outside_the_range_is_refused_naming_the_axis():
    scene = scene_from_text(_turret(), "turret")
    assert_close(pointing(scene, 60.0)["el"], math.radians(30), rel=MIN_REL, scale=math.pi)
    with pytest.raises(SceneError, match=r"elevation 89° lies outside .* 5…88°"):
        pointing(scene, 89.0)


def test_a_scene_without_a_mount_is_refused_where_a_pointing_is_asked():
    scene = scene_from_text(_turret(""), "turret")
    with pytest.raises(SceneError, match=r"turret: declares no pointing axes: add an <rt70:mount>"):
        pointing(scene, 45.0)


@pytest.mark.parametrize(
    ("mount", "message"),
    [
        (
            '<rt70:mount type="alt-az"><rt70:axis name="azimuth" joint="az"/></rt70:mount>',
            r"<rt70:mount type='alt-az'>: the type is one of 'az-el'",
        ),
        (
            '<rt70:mount type="az-el"><rt70:axis name="azimuth" joint="az"/></rt70:mount>',
            r"has the axes \['azimuth'\]: it needs exactly \['azimuth', 'elevation'\]",
        ),
        (
            '<rt70:mount type="az-el"><rt70:axis name="azimuth" joint="az"/>'
            '<rt70:axis name="elevation" joint="az"/></rt70:mount>',
            r"one joint turns two axes",
        ),
        (
            '<rt70:mount type="az-el"><rt70:axis name="azimuth" joint="az"/>'
            '<rt70:axis name="elevation" joint="slide"/></rt70:mount>',
            r"<rt70:axis name='elevation'>: joint 'slide' is prismatic, not rotary",
        ),
        (
            '<rt70:mount type="az-el"><rt70:axis name="azimuth" joint="az"/>'
            '<rt70:axis name="elevation" joint="nope"/></rt70:mount>',
            r"joint 'nope' does not exist",
        ),
        (
            '<rt70:mount type="az-el"><rt70:axis name="azimuth" joint="az" sign="2"/>'
            '<rt70:axis name="elevation" joint="el"/></rt70:mount>',
            r"sign is 1 or -1, got 2",
        ),
        (
            '<rt70:mount type="az-el"><rt70:axis name="azimuth" joint="az"/>'
            '<rt70:axis name="elevation" joint="el" min_deg="90" max_deg="0"/></rt70:mount>',
            r"min_deg 90 is not below max_deg 0",
        ),
        (
            '<rt70:mount type="az-el"><rt70:axis name="azimuth" joint="az" zero_dg="0"/>'
            '<rt70:axis name="elevation" joint="el"/></rt70:mount>',
            r"unknown attribute 'zero_dg' \(did you mean 'zero_deg'\?\)",
        ),
        (GOOD + GOOD, r"<robot> has more than one <rt70:mount>"),
    ],
    ids=[
        "type",
        "axes",
        "shared joint",
        "prismatic",
        "missing joint",
        "sign",
        "range",
        "misspelt",
        "two mounts",
    ],
)
def test_a_wrong_mount_is_refused_naming_file_and_element(mount, message):
    with pytest.raises(ExtensionError, match=message) as err:
        read_urdf_string(_turret(mount), "turret.urdf")
    assert str(err.value).startswith("turret.urdf: ")


#: Two drives for the turret (the elevation one on az: a servo naming it is refused).
DRIVES = """
  <rt70:drive name="az_drive" joint="az" L_a="0.01" R_a="0.5" c_m="1" c_e="1" J_m="0.01"
              D_m="0" i_r="100" C_r="1e6" D_r="0"/>
  <rt70:drive name="other" joint="az" L_a="0.01" R_a="0.5" c_m="1" c_e="1" J_m="0.01"
              D_m="0" i_r="100" C_r="1e6" D_r="0"/>"""

SERVO = (
    '<rt70:servo drive="az_drive" rate_limit_deg_s="2" torque_limit="500" '
    'voltage_limit="400" EXTRA/>'
)


def _servoed(servo: str) -> str:
    mount = GOOD.replace('<rt70:axis name="azimuth" joint="az"/>',
                         f'<rt70:axis name="azimuth" joint="az">{servo}</rt70:axis>')  # fmt: skip
    return _turret(mount + DRIVES)


def test_a_servo_reads_in_si_and_defaults_what_it_may():
    servo = read_urdf_string(_servoed(SERVO.replace(" EXTRA", "")), "t.urdf").mount.axes[0].servo
    assert (servo.drive, servo.torque_limit, servo.voltage_limit) == ("az_drive", 500.0, 400.0)
    assert_close(servo.rate_limit, math.radians(2.0), rel=MIN_REL, scale=1.0, what="rate")
    assert servo.position_bandwidth_hz is None and servo.reference_inertia is None
    assert servo.loop_ratio == 5.0 and servo.nominal_torque == 500.0
    assert servo.static_friction is None and servo.top_speed_friction is None


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        ('drive="nope"', r"drive 'nope' is no <rt70:drive> of the file \(az_drive, other\)"),
        ('loop_ratio="1"', r"loop_ratio=1 must be above 1"),
        ('position_bandwidth_hz="0"', r"position_bandwidth_hz=0 must be positive"),
        ('nominal_torque="-5"', r"nominal_torque=-5 must be positive"),
        ('static_friction="10"', r"give static_friction and top_speed_friction together"),
        (
            'static_friction="10" top_speed_friction="5"',
            r"give static_friction and top_speed_friction together, the second not below",
        ),
        ('bandwidth_hz="1"', r"unknown attribute 'bandwidth_hz'"),
    ],
)
def test_a_wrong_servo_is_one_line_naming_the_element(extra, message):
    servo = SERVO.replace("EXTRA", extra)
    if extra.startswith("drive="):
        servo = servo.replace('drive="az_drive" ', "")
    with pytest.raises(ExtensionError, match=message) as err:
        read_urdf_string(_servoed(servo), "t.urdf")
    assert "t.urdf" in str(err.value) and "\n" not in str(err.value)


def test_a_servo_on_a_drive_of_another_joint_is_refused():
    text = _servoed(SERVO.replace(" EXTRA", "")).replace(
        '<rt70:axis name="elevation" joint="el"',
        '<rt70:axis name="elevation" joint="el"><rt70:servo drive="other" rate_limit_deg_s="1" '
        'torque_limit="1" voltage_limit="1"/></rt70:axis><rt70:axis name="x" joint="el"',
    )
    with pytest.raises(
        ExtensionError, match=r"drive 'other' turns joint 'az', the axis turns 'el'"
    ):
        read_urdf_string(text, "t.urdf")
