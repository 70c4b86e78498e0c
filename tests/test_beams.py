"""``<rt70:beam>``: rigid finite elements on both sides, against beam theory.

The expansion (links, joints, springs), its errors, and the frequencies of cantilevers
and free–free beams against the exact Rayleigh, Timoshenko and Euler–Bernoulli answers
of :mod:`rt70.fe.beam_theory`, with the measured order of convergence (docs/beams.md).
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from rt70.crosscheck.validate import cross_check
from rt70.errors import ExtensionError, UrdfError
from rt70.fe.beam_theory import UniformBeam, euler_bernoulli_roots
from rt70.model.scene import scene_from_text
from rt70.scenes.beam_scenes import STEEL_BAR, xz_bending_frequencies
from rt70.scenes.beam_scenes import beam_text as scenes_beam_text
from rt70.urdf import read_urdf_string
from rt70.urdf.beams import expand_beams

STEEL = STEEL_BAR


def beam_text(
    segments: int, free: bool = False, extra: str = "", length: float = 2.0, **props
) -> str:
    """A beam of :data:`STEEL` (with ``props``) clamped to the ground or free–free."""
    support = "free-free" if free else "cantilever"
    return scenes_beam_text(segments, support, length, {**STEEL, **props}, extra)


def rayleigh(length: float = 2.0, **props) -> UniformBeam:
    """The exact beam the division converges to: rotary inertia ρI, shear if given."""
    v = {**STEEL, **props}
    gas = v["G"] * v["Asz"] if "Asz" in v else None
    return UniformBeam(length, v["E"] * v["Iy"], v["rho"] * v["A"], v["rho"] * v["Iy"], gas)


def test_expansion_writes_links_joints_and_springs():
    desc = read_urdf_string(beam_text(4))
    (beam,) = desc.beams
    assert beam.links == [f"b_seg{i}" for i in range(5)]
    moving = [j for j in desc.joints if j.type != "fixed"]
    assert len(moving) == 4 * 4  # ux, rx, ry, rz per spring-damping element
    assert len(desc.joint_springs) == len(moving)
    mass = sum(link.inertial.mass for link in desc.links.values() if link.inertial)
    assert mass == pytest.approx(STEEL["rho"] * STEEL["A"] * 2.0, rel=1e-14)
    k = {s.joint: s.stiffness for s in desc.joint_springs}
    ell = 0.5
    assert k["b_sde1_ry"] == pytest.approx(STEEL["E"] * STEEL["Iy"] / ell, rel=1e-15)
    assert k["b_sde4_ux"] == pytest.approx(STEEL["E"] * STEEL["A"] / ell, rel=1e-15)
    assert k["b_sde2_rx"] == pytest.approx(STEEL["G"] * STEEL["J"] / ell, rel=1e-15)


def test_each_rigid_element_is_drawn_for_urdf_viewers():
    text = expand_beams(beam_text(2))
    radius = float(np.sqrt((STEEL["Iy"] + STEEL["Iz"]) / STEEL["A"]))
    assert text.count(f'<cylinder radius="{radius!r}" length="0.5"/>') == 2  # the half ends
    assert text.count(f'<cylinder radius="{radius!r}" length="1.0"/>') == 1


def test_expansion_is_idempotent_and_optional_coordinates_follow_the_attributes():
    text = beam_text(3, extra='Asy="8e-5" Asz="8e-5" axial="false" damping="1e-3"')
    once = expand_beams(text)
    assert expand_beams(once) == once
    desc = read_urdf_string(once)
    coords = {j.name.rsplit("_", 1)[1] for j in desc.joints if j.name.startswith("b_sde1_")}
    assert coords == {"uy", "uz", "rx", "ry", "rz"}
    spring = next(s for s in desc.joint_springs if s.joint == "b_sde1_uy")
    assert spring.damping == pytest.approx(1e-3 * spring.stiffness, rel=1e-15)
    assert expand_beams(beam_text(2).replace("rt70:beam", "rt70:gravity_x")) is not None


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ('E="-1.0"', 'E="-1.0" must be > 0'),
        ('segments="2.5"', 'segments="2.5" is not a whole number'),
        ('segments="0"', 'segments="0" is not a whole number'),
        ('axial="yes"', 'axial="yes" is not true or false'),
        ('nu="0.3"', "give the shear modulus G or Poisson's ratio nu"),
        ('nu="0.7"', 'nu="0.7" is not in (-1, 0.5]'),
        ('damping="-1"', 'damping="-1" is negative'),
        ('Asz="0"', 'Asz="0" must be > 0'),
        ('Ixx="1"', "Ixx"),
    ],
)
def test_bad_beams_are_refused_naming_the_file_and_element(change, message):
    attr = change.split("=")[0]
    drop = [attr, "G"] if change == 'nu="0.7"' else [attr]  # nu replaces G, or joins it
    text = re.sub(rf' ({"|".join(drop)})="[^"]*"', "", beam_text(2)).replace(
        "<rt70:beam ", f"<rt70:beam {change} "
    )
    with pytest.raises(ExtensionError) as err:
        read_urdf_string(text, source="leg.urdf")
    assert str(err.value).startswith("leg.urdf: ") and message in str(err.value)


def test_a_generated_name_taken_by_the_file_is_refused():
    text = beam_text(2).replace('<link name="world"/>', '<link name="world"/><link name="b_end"/>')
    with pytest.raises(ExtensionError, match="generated name 'b_end' is taken"):
        read_urdf_string(text, source="leg.urdf")


def test_unknown_parent_is_refused():
    with pytest.raises(UrdfError, match="nowhere"):
        read_urdf_string(beam_text(2).replace('parent="world"', 'parent="nowhere"'))


def test_poisson_ratio_gives_the_shear_modulus():
    text = beam_text(2).replace('G="81000000000.0"', 'nu="0.3"')
    (beam,) = read_urdf_string(text).beams
    assert beam.G == pytest.approx(2.1e11 / 2.6, rel=1e-15)


def test_both_sides_agree_on_a_beam_with_every_coordinate():
    text = beam_text(3, extra='Asy="8e-5" Asz="8e-5" damping="1e-3"', free=True)
    records = cross_check(scene_from_text(text), samples=3, repeat=1)
    assert len(records) > 10
    assert all(r.passed() for r in records), [r for r in records if not r.passed()]


def test_euler_bernoulli_roots():
    assert euler_bernoulli_roots("cantilever") == pytest.approx(
        [1.875104, 4.694091, 7.854757], 1e-6
    )
    assert euler_bernoulli_roots("free-free") == pytest.approx(
        [4.730041, 7.853205, 10.995608], 1e-6
    )


@pytest.mark.slow
def test_cantilever_converges_at_second_order_to_the_exact_beam():
    exact = rayleigh().frequencies("cantilever")
    errors = [
        xz_bending_frequencies(beam_text(n, extra='axial="false"')) / exact - 1 for n in (10, 20)
    ]
    order = np.log2(errors[0] / errors[1])
    assert np.all(errors[0] > 0) and np.all((1.9 < order) & (order < 2.1)), (errors, order)
    slender = rayleigh(length=20.0)  # L/r = 6900: rotary inertia shifts f3 by 3e-6
    eb = slender.euler_bernoulli("cantilever")
    assert np.all(np.abs(slender.frequencies("cantilever") / eb - 1) < 1e-5)
    at_default = xz_bending_frequencies(beam_text(10, extra='axial="false"', length=20.0)) / eb - 1
    assert np.all(np.abs(at_default) < [3e-3, 9e-3, 1.4e-2]), at_default


@pytest.mark.slow
def test_free_free_beam_converges_near_fourth_order_and_meets_1e_3_at_the_default():
    exact = rayleigh().frequencies("free-free")
    errors = [
        xz_bending_frequencies(beam_text(n, free=True, extra='axial="false"')) / exact - 1
        for n in (20, 40)
    ]
    order = np.log2(errors[0] / errors[1])
    assert np.all((3.5 < order) & (order < 4.2)), (errors, order)  # measured 3.76
    slender = rayleigh(length=20.0)
    eb = slender.euler_bernoulli("free-free")
    assert np.all(np.abs(slender.frequencies("free-free") / eb - 1) < 1e-5)
    text = beam_text(10, free=True, extra='axial="false"', length=20.0)
    at_default = xz_bending_frequencies(text) / eb - 1
    assert np.all(np.abs(at_default) < 1e-3), at_default


@pytest.mark.slow
def test_stubby_cantilever_converges_to_timoshenko():
    stubby = dict(A=4e-2, Iy=1.333e-4, Iz=1.333e-4, J=2.25e-4, Asz=4e-2 * 5 / 6, Asy=4e-2 * 5 / 6)
    exact = rayleigh(**stubby).frequencies("cantilever")
    shift = exact / rayleigh(**stubby).euler_bernoulli("cantilever") - 1
    assert shift[2] < -0.1  # L/h = 10: shear and rotary inertia lower f3 by 11 %
    extra = f'axial="false" Asy="{stubby["Asy"]!r}" Asz="{stubby["Asz"]!r}"'
    props = {k: v for k, v in stubby.items() if k not in ("Asy", "Asz")}
    errors = [
        xz_bending_frequencies(beam_text(n, extra=extra, **props)) / exact - 1 for n in (10, 20)
    ]
    order = np.log2(np.abs(errors[0] / errors[1]))
    assert np.all(np.abs(errors[1]) < 5e-3) and np.all(order > 1.8), (errors, order)


@pytest.mark.slow
def test_spin_up_stiffens_the_rigid_elements_and_the_linear_modes_diverge():
    """Ω_s = 6 rad/s, above the first frequency (3.8 rad/s): only the linear model runs away."""
    from rt70.reports.spin_up import tip_linear_modes, tip_rigid_elements

    times = np.linspace(0.0, 15.0, 31)
    beam = tip_rigid_elements(3, 6.0, times)
    linear = tip_linear_modes(3, 6.0, times)
    assert np.all(np.isfinite(beam)) and 0.1 < np.abs(beam).max() < 1.0  # bends, stays bounded
    assert np.abs(linear[~np.isnan(linear)]).max() > 100.0  # 10 m long: a runaway
