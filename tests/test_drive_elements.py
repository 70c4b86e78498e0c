"""Drives as scene elements (``<rt70:drive>``): reading, refusals, and both sides' kinematics.

The angle θ_d each drive's reducer acts on and its generalised force ``Q = K ∂θ_d/∂q``
are computed independently by the textbook side (book forward pass, S·U) and the
reference side (Pinocchio placements, Jᵀf); they must agree to rounding on the RT-70 at
random states, the gradient must be the derivative of the angle, and the sector must
be the book's force K/r along the counterweight's y (4.150).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import rt70.cli.main
from rt70.control.drives import DcDrive, scene_drive, scene_drives
from rt70.errors import ExtensionError, Rt70Error
from rt70.model.scene import load_scene
from rt70.reference import drives as ref_drives
from rt70.scenes.rt70_drives import AZIMUTH_DRIVE, ELEVATION_DRIVE
from rt70.scenes.rt70_scenes import lumped_drive
from rt70.scenes.rt70_state import rt70_pointing
from rt70.testing import MIN_REL, assert_close
from rt70.textbook import drives as tb_drives
from rt70.urdf import read_urdf_string

TURRET = Path(__file__).parent / "data" / "turret_drives.urdf"


@pytest.fixture(scope="module")
def servo():
    return load_scene("rt70_servo")


def _pointed(scene, elevation_deg: float, azimuth_deg: float, rng, size: float) -> np.ndarray:
    """q at a pointing, every other coordinate a random deformation of ``size``."""
    names = scene.coordinate_names
    q = size * rng.standard_normal(len(names))
    for name, value in rt70_pointing(elevation_deg, azimuth_deg).items():
        q[names.index(name)] = value
    return q


# --- reading ---------------------------------------------------------------------------


def test_rt70_servo_has_the_two_drives_of_the_parameter_table(servo):
    drives = {d.name: d for d in servo.description.drives}
    assert sorted(drives) == ["azimuth", "elevation"]
    for axis, joint in ((AZIMUTH_DRIVE, "platform_rz"), (ELEVATION_DRIVE, "base_rx")):
        d = drives[axis.name]
        assert d.joint == joint
        for key, value in lumped_drive(axis).items():
            assert_close(getattr(d, key), value, rel=MIN_REL, what=key)
    assert drives["azimuth"].sector is None
    s = drives["elevation"].sector
    assert (s.link, s.stator, s.radius) == ("counterweight", "platform", 16.0)
    assert s.direction.tolist() == [0.0, 1.0, 0.0] and s.axis.tolist() == [1.0, 0.0, 0.0]


def test_the_listing_as_printed_has_no_drives():
    assert load_scene("rt70").description.drives == []


def test_lumped_motor_keeps_the_axis_torque_and_reflected_inertia():
    """n motors in parallel: c_m (n I_n) i_r is the axis's torque, n J_m i_r² docs/drives.md's."""
    p = lumped_drive(AZIMUTH_DRIVE)
    m, n = AZIMUTH_DRIVE.motor, AZIMUTH_DRIVE.motors_per_axis
    torque = p["c_m"] * n * m.rated_current * p["i_r"]
    assert_close(torque, AZIMUTH_DRIVE.nominal_torque, rel=1e-5)
    assert_close(p["J_m"] * p["i_r"] ** 2, AZIMUTH_DRIVE.reflected_motor_inertia, rel=1e-14)
    # the same stall current at the rated voltage: R_a/n carries n times one motor's
    stall = n * m.rated_voltage / m.armature_resistance
    assert_close(m.rated_voltage / p["R_a"], stall, rel=1e-14)


PARAMS = 'L_a="1" R_a="1" c_m="1" c_e="1" J_m="1" D_m="0" i_r="10" C_r="100" D_r="1"'
SECTOR = (
    '<rt70:sector link="cw" stator="platform" xyz="0 0 0" direction="0 1 0" axis="1 0 0" '
    'radius="1"/>'
)
ZERO_RATIO = PARAMS.replace('i_r="10"', 'i_r="0"')
NEGATIVE_DAMPING = PARAMS.replace('D_r="1"', 'D_r="-1"')
ZERO_RADIUS = SECTOR.replace('radius="1"', 'radius="0"')

BAD = {
    "no-joint": (f'<rt70:drive name="d" {PARAMS}/>', "lacks attribute 'joint'"),
    "unknown-joint": (f'<rt70:drive name="d" joint="ghost" {PARAMS}/>', "'ghost' does not exist"),
    "missing-parameter": (
        '<rt70:drive name="d" joint="az" L_a="1" R_a="1"/>',
        "<rt70:drive name='d'> lacks attribute 'c_m'",
    ),
    "zero-ratio": (
        f'<rt70:drive name="d" joint="az" {ZERO_RATIO}/>',
        "i_r=0 must be positive",
    ),
    "negative-damping": (
        f'<rt70:drive name="d" joint="az" {NEGATIVE_DAMPING}/>',
        "D_r=-1 must be non-negative",
    ),
    "twice": (
        f'<rt70:drive name="azimuth" joint="az" {PARAMS}/>',
        "two drives named 'azimuth'",
    ),
    "sector-unknown-link": (
        f'<rt70:drive name="d" joint="el" {PARAMS}>{SECTOR.replace("cw", "ghost", 1)}</rt70:drive>',
        "<rt70:drive name='d'> <rt70:sector>: link 'ghost' does not exist",
    ),
    "sector-on-its-stator": (
        f'<rt70:drive name="d" joint="el" {PARAMS}>{SECTOR.replace("platform", "cw")}</rt70:drive>',
        "link and stator are both 'cw'",
    ),
    "sector-not-tangent": (
        f'<rt70:drive name="d" joint="el" {PARAMS}>{SECTOR.replace("0 1 0", "1 1 0")}</rt70:drive>',
        "not orthogonal to axis",
    ),
    "sector-zero-radius": (
        f'<rt70:drive name="d" joint="el" {PARAMS}>{ZERO_RADIUS}</rt70:drive>',
        "radius=0 must be positive",
    ),
    "sector-on-prismatic": (
        f'<rt70:drive name="d" joint="cw_y" {PARAMS}>{SECTOR}</rt70:drive>',
        "joint 'cw_y' is prismatic",
    ),
    "two-sectors": (
        f'<rt70:drive name="d" joint="el" {PARAMS}>{SECTOR}{SECTOR}</rt70:drive>',
        "more than one <rt70:sector>",
    ),
}


@pytest.mark.parametrize("name", list(BAD))
def test_bad_drive_is_refused_naming_file_and_element(name, tmp_path, capsys):
    element, needle = BAD[name]
    text = TURRET.read_text(encoding="utf-8").replace("</robot>", element + "\n</robot>")
    path = tmp_path / f"{name}.urdf"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ExtensionError) as excinfo:
        read_urdf_string(text, source=str(path))
    message = str(excinfo.value)
    assert message.startswith(f"{path}: ") and needle in message, message
    capsys.readouterr()
    assert rt70.cli.main.main(["validate", str(path)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err == [f"rt70: error: {message}"]


# --- both sides ------------------------------------------------------------------------


def test_sides_agree_on_angle_and_force_of_the_rt70_drives(servo):
    """θ_d and Q = K ∂θ_d/∂q, textbook against Pinocchio, at random pointings and states."""
    rng = np.random.default_rng(7)
    for _ in range(6):
        q = _pointed(servo, rng.uniform(5, 90), rng.uniform(-180, 180), rng, 1e-3)
        for drive in servo.description.drives:
            K = rng.uniform(-1, 1) * 1e7
            tb, ref = (servo.textbook, servo.textbook_data), (servo.reference, servo.reference_data)
            a_tb, Q_tb = tb_drives.drive_force(*tb, q, drive, K)
            a_ref, Q_ref = ref_drives.drive_force(*ref, q, drive, K)
            # an angle from unit rotations: its rounding is absolute, on the scale of π
            assert_close(a_tb, a_ref, rel=1e-12, scale=np.pi, what=drive.name)
            assert_close(Q_tb, Q_ref, rel=1e-10, what=drive.name)


@pytest.mark.parametrize("drive_name", ["azimuth", "elevation"])
def test_force_is_the_gradient_of_the_angle(servo, drive_name):
    """Q at unit torque against central differences of θ_d (each side its own θ_d)."""
    drive = next(d for d in servo.description.drives if d.name == drive_name)
    rng = np.random.default_rng(3)
    q = _pointed(servo, 40.0, 30.0, rng, 1e-3)
    h = 1e-6
    sides = (
        (tb_drives, servo.textbook, servo.textbook_data),
        (ref_drives, servo.reference, servo.reference_data),
    )
    for kin, model, data in sides:
        _, grad = kin.drive_force(model, data, q, drive)
        fd = np.empty_like(q)
        for i in range(q.size):
            e = np.zeros_like(q)
            e[i] = h
            up = kin.drive_angle(model, data, q + e, drive)
            down = kin.drive_angle(model, data, q - e, drive)
            fd[i] = (up - down) / (2 * h)
        assert_close(fd, grad, rel=1e-8)


def test_mesh_angle_is_the_elevation_when_undeformed(servo):
    """θ_d = base_rx, and the azimuth's θ_d = platform_rz, with the bushings undeformed."""
    rng = np.random.default_rng(5)
    for elevation, azimuth in ((90.0, 0.0), (30.0, 120.0), (5.0, -70.0)):
        q = _pointed(servo, elevation, azimuth, rng, 0.0)
        for drive in servo.description.drives:
            for kin, model, data in (
                (tb_drives, servo.textbook, servo.textbook_data),
                (ref_drives, servo.reference, servo.reference_data),
            ):
                angle = kin.drive_angle(model, data, q, drive)
                axis = q[servo.coordinate_names.index(drive.joint)]
                assert_close(angle, axis, rel=1e-14, scale=np.pi)  # as above


def test_sector_is_the_book_force_on_the_counterweight(servo):
    """(4.150): undeformed, the mesh force is K/r along the counterweight's y, and its
    virtual work on a turn of the elevation axis is K per radian; the azimuth torque's
    generalised force is K on platform_rz alone (4.143)."""
    names = servo.coordinate_names
    q = _pointed(servo, 35.0, 50.0, np.random.default_rng(0), 0.0)
    drives = {d.name: d for d in servo.description.drives}
    K = 4.9e7
    model, data = servo.textbook, servo.textbook_data
    mesh = tb_drives.sector_mesh(model, data, drives["elevation"])
    link = tb_drives.link_pose(model, data, q, "counterweight")
    stator = tb_drives.link_pose(model, data, q, "platform")
    wrenches = mesh.wrenches("counterweight", "platform", (0, 0, 0), K, link, stator)
    force = np.asarray(wrenches[0].force)
    assert_close(np.linalg.norm(force), K / 16.0, rel=1e-14)
    assert_close(force, K / 16.0 * link[0][:, 1], rel=1e-14, scale=K / 16.0)
    assert_close(np.asarray(wrenches[1].force), -force, rel=MIN_REL)
    _, Q = tb_drives.drive_force(model, data, q, drives["elevation"], K)
    assert_close(Q[names.index("base_rx")], K, rel=1e-12)
    _, Q = ref_drives.drive_force(servo.reference, servo.reference_data, q, drives["azimuth"], K)
    expected = np.zeros(len(names))
    expected[names.index("platform_rz")] = K
    assert_close(Q, expected, rel=1e-9)  # on the scale K


def test_positive_torque_drives_both_axes_positive(servo):
    """A positive reducer torque pushes platform_rz and base_rx the positive way."""
    names = servo.coordinate_names
    q = _pointed(servo, 60.0, 10.0, np.random.default_rng(1), 1e-4)
    for drive in servo.description.drives:
        _, Q = ref_drives.drive_force(servo.reference, servo.reference_data, q, drive, 1.0)
        assert Q[names.index(drive.joint)] > 0.99


# --- the scene's drives as components --------------------------------------------------


def test_scene_drive_on_a_joint_is_the_coordinate_drive():
    """The azimuth element as a component pushes what DcDrive(coordinate=...) pushes."""
    scene = load_scene(TURRET)
    rng = np.random.default_rng(2)
    q, qd, s = rng.standard_normal(4), rng.standard_normal(4), rng.standard_normal(3)
    for side in ("textbook", "reference"):
        az = scene_drives(scene, side, voltage=5.0)[0]
        plain = DcDrive("azimuth", scene.coordinate_names, "az", az.p, 5.0)
        assert az.names == plain.names and az.index == plain.index == 0
        # the reducer torque's terms C_r (|α_m|/i_r + |α|) + D_r (|ω_m|/i_r + |α̇|), ∂α/∂q = 1
        p = az.p
        terms = p.C_r * (abs(s[1]) / p.i_r + abs(q[0])) + p.D_r * (abs(s[2]) / p.i_r + abs(qd[0]))
        force = az.force(0.0, q, qd, s)
        assert_close(force, plain.force(0.0, q, qd, s), rel=MIN_REL, scale=terms, what=side)
        rates = az.derivative(0.0, q, qd, s, None)
        assert_close(rates, plain.derivative(0.0, q, qd, s, None), rel=MIN_REL, what=side)


def test_scene_drives_refuse_unknown_names():
    scene = load_scene(TURRET)
    with pytest.raises(Rt70Error, match="no drive named ghost"):
        scene_drives(scene, "textbook", voltage={"ghost": 1.0})
    with pytest.raises(Rt70Error, match=r"no drive named ghost \(drives: azimuth, elevation\)"):
        scene_drive(scene, "ghost")
    assert scene_drive(scene, "elevation").sector.link == "cw"
    with pytest.raises(Rt70Error, match="unknown side 'numpy'"):
        scene_drives(scene, "numpy")
    with pytest.raises(Rt70Error, match="give a coordinate or a coupling"):
        DcDrive("d", None, None, scene_drives(scene, "textbook")[0].p)
