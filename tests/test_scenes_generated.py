"""The committed scene files are exactly what rt70.scenes.generate writes, and load in Pinocchio."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from rt70.scenes import mechanisms, rt70_data
from rt70.scenes.generate import MODAL_FILES, SCENES, write_all
from rt70.scenes.pairs import pair_joint_names
from rt70.scenes.urdf_writer import RT70_NS
from rt70.testing import assert_close

URDF_DIR = Path(__file__).resolve().parents[1] / "urdf"
NS = {"rt70": RT70_NS}

EXPECTED_NV = {
    "rt70": 42,
    "rt70_servo": 42,
    "rt70_jack": 44,
    "rt70_flexible": 52,  # the counterreflector's pair replaced by 4 sdes of 4 coordinates
    "rt70_elevation": 6,
    "rt70_azimuth": 7,
    "rt70_azimuth_el90": 7,
    "double_pendulum": 2,
    "three_masses": 3,
    "two_body_gravity": 12,
    "gear_reducer": 5,
    "four_bar": 3,
    "crank_slider": 3,
    "antenna_12m": 6,
    "antenna_34m": 6,
    "slewing_truss": 1,  # Pinocchio's parser sees the slew joint; the modes are rt70's
    "rt70_mirror": 42,  # the listing's; the dish's modes are rt70's
    "antenna_12m_dish": 6,  # the preset's; the dish's modes are rt70's
}

RT70_BODIES = (
    "platform",
    "base",
    "counterweight",
    "mirror_base",
    "main_mirror",
    "rigel",
    "counterreflector",
)


def _model(name: str) -> pin.Model:
    return pin.buildModelFromUrdf(str(URDF_DIR / f"{name}.urdf"))


def test_every_scene_has_an_expected_size():
    assert set(SCENES) == set(EXPECTED_NV)


@pytest.mark.parametrize("name", sorted(SCENES))
def test_committed_file_equals_generator_output(name):
    path = URDF_DIR / f"{name}.urdf"
    assert path.is_file(), f"{path} missing: run python -m rt70.scenes.generate"
    assert path.read_text(encoding="utf-8") == SCENES[name](), (
        f"{path} is stale: run python -m rt70.scenes.generate"
    )


@pytest.mark.parametrize("name", sorted(SCENES))
def test_generator_is_deterministic(name):
    text = SCENES[name]()
    assert text == SCENES[name]()
    assert text.endswith("\n") and not text.endswith("\n\n")


@pytest.mark.parametrize("name", sorted(SCENES))
def test_pinocchio_loads_scene(name):
    model = _model(name)
    assert model.nq == EXPECTED_NV[name]
    assert model.nv == EXPECTED_NV[name]


@pytest.mark.parametrize("name", sorted(SCENES))
def test_scene_structure(name):
    text = SCENES[name]()
    assert f'xmlns:rt70="{RT70_NS}"' in text.splitlines()[3]
    root = ET.fromstring(text)
    links = root.findall("link")
    children = {j.find("child").get("link") for j in root.findall("joint")}
    roots = [link.get("name") for link in links if link.get("name") not in children]
    assert roots == ["world"]
    for joint in root.findall("joint"):
        assert joint.get("type") in ("revolute", "prismatic", "fixed")
        if joint.get("type") != "fixed":
            assert joint.find("axis") is not None and joint.find("limit") is not None
    beam_ends = {beam.get("name") + "_end" for beam in root.findall("rt70:beam", NS)}
    for link in links:
        inertial = link.find("inertial")
        if link.get("name") in ("world", *beam_ends) or link.get("name").endswith("_link"):
            assert inertial is None
            continue
        assert inertial is not None, link.get("name")
        assert float(inertial.find("mass").get("value")) > 0.0
        ie = inertial.find("inertia")
        tensor = np.array(
            [
                [float(ie.get(a)) for a in row]
                for row in (("ixx", "ixy", "ixz"), ("ixy", "iyy", "iyz"), ("ixz", "iyz", "izz"))
            ]
        )
        moments = np.linalg.eigvalsh(tensor)
        assert moments[0] > 0.0
        assert moments[2] <= moments[0] + moments[1]
    assert len(root.findall("rt70:gravity", NS)) == 1


def test_rt70_joint_order_is_the_books_pair_order():
    model = _model("rt70")
    names = [model.names[i] for i in range(1, model.njoints)]
    assert names == [n for body in RT70_BODIES for n in pair_joint_names(body)]
    assert tuple(b["name"] for b in rt70_data.LISTING_BODIES) == RT70_BODIES
    assert rt70_data.LISTING_Q0.shape == (42,)
    assert rt70_data.LISTING_V0.shape == (42,)


def test_rt70_elastic_elements():
    root = ET.fromstring(SCENES["rt70"]())
    bushings = {b.get("name"): b for b in root.findall("rt70:bushing", NS)}
    assert set(bushings) == {
        "ground_platform",
        "base_counterweight",
        "base_mirror_base",
        "mirror_base_main_mirror",
        "rigel_counterreflector",
    }
    ground = bushings["ground_platform"]
    assert ground.find("rt70:frame1", NS).get("xyz") == "0 0 25"
    assert float(ground.get("stiffness").split()[5]) == 0.0
    packages = {p.get("name"): p for p in root.findall("rt70:strut_package", NS)}
    points = {
        name: [s.get("xyz") for s in p.findall("rt70:strut", NS)] for name, p in packages.items()
    }
    assert points == {
        "platform_base": ["13.45 0 0", "-13.45 0 0"],
        "base_rigel": ["3 0 0.5", "-3 0 0.5", "0 3 0.5", "0 -3 0.5"],
    }
    for strut in packages["platform_base"].findall("rt70:strut", NS):
        assert float(strut.get("stiffness").split()[3]) == 0.0


def test_double_pendulum_reference_values():
    ref = mechanisms.DOUBLE_PENDULUM_REFERENCE
    model = _model("double_pendulum")
    model.gravity.linear = np.array([0.0, -9.81, 0.0])
    data = model.createData()
    q, v = np.array(ref["q"]), np.array(ref["v"])
    a = pin.crba(model, data, q)
    a = np.triu(a) + np.triu(a, 1).T
    g = pin.computeGeneralizedGravity(model, data, q)
    b = pin.nonLinearEffects(model, data, q, v) - g
    # the reference's 8 printed significant digits (18.865003: ±5e-7 of 18.9, 2.7e-8)
    assert_close(a, ref["A"], rel=3e-8, what="A")
    assert_close(b, ref["B"], rel=3e-8, what="B q̇")
    assert_close(g, ref["G"], rel=3e-8, what="G")


def _torsional_spectrum_hz(name: str) -> np.ndarray:
    """Natural frequencies of a chapter-2 scene: Pinocchio's mass matrix, URDF springs."""
    model = _model(name)
    data = model.createData()
    mass = pin.crba(model, data, pin.neutral(model))
    index = {f.name: f.parentJoint - 1 for f in model.frames if f.type == pin.FrameType.BODY}
    stiffness = np.zeros((model.nv, model.nv))
    for bushing in ET.fromstring(SCENES[name]()).findall("rt70:bushing", NS):
        values = [float(c) for c in bushing.get("stiffness").split()]
        assert values[:5] == [0.0] * 5
        row = np.zeros(model.nv)
        row[index[bushing.find("rt70:frame2", NS).get("link")]] += 1.0
        first = bushing.find("rt70:frame1", NS).get("link")
        if first != "world":
            row[index[first]] -= 1.0
        stiffness += values[5] * np.outer(row, row)
    omega2 = np.linalg.eigvals(np.linalg.solve(mass, stiffness)).real
    return np.sqrt(np.clip(np.sort(omega2), 0.0, None)) / (2.0 * np.pi)


def test_elevation_scene_reproduces_printed_spectrum():
    hz = _torsional_spectrum_hz("rt70_elevation")
    # printed to 4 decimals: ±1 in the last of them, on the spectrum's size (19.6 Hz)
    assert_close(hz, rt70_data.ELEVATION_SPECTRUM_HZ, rel=5e-6)


def test_write_all_writes_every_scene(tmp_path):
    written = write_all(tmp_path / "out")
    assert [p.name for p in written] == [f"{name}.urdf" for name in SCENES] + list(MODAL_FILES)
    for path, (name, build) in zip(written, SCENES.items(), strict=False):
        assert path.read_text(encoding="utf-8") == build(), name
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == sorted(p.name for p in written)


@pytest.mark.parametrize("name", ["rt70", "rt70_servo", "rt70_jack", "rt70_flexible"])
def test_rt70_scenes_draw_their_bodies(name):
    """Each listing body has a cylinder a URDF viewer draws (Pinocchio's parser reads it)."""
    _, _, visual = pin.buildModelsFromUrdf(str(URDF_DIR / f"{name}.urdf"))
    drawn = {g.name.rsplit("_", 1)[0] for g in visual.geometryObjects}
    assert set(RT70_BODIES) <= drawn
    mirror = next(g for g in visual.geometryObjects if g.name.startswith("main_mirror"))
    assert mirror.geometry.radius == 35.0
