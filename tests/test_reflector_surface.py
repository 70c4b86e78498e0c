"""The reflector as a flexible body: surface nodes on both sides, the dish in the RT-70, homology.

What is checked (docs/surface.md):

- a modal body's node is a point carrier on both sides (``"<body>/node<n>"``): positions
  and Jacobians agree to rounding, and the Jacobian is the positions' derivative;
- the shipped ``rt70_mirror``: every surface output and its linearisation agree between
  the sides (target 1e-10 relative); the main mirror's link and the dish together have the
  listing's mass, centre and inertia (1e-12);
- the dish's modes augmented by its load shapes give the FE model's static response
  exactly, which its modes alone do not;
- gravity homology at the static equilibrium equals the closed form from the FE model's
  own static solutions, rotated by the dish frame's actual attitude (to the
  equilibrium's tolerance), and is zero at the rigging elevation;
- bad surfaces in a modal body file are refused by name.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse.linalg as spla

from rt70.errors import ExtensionError, UnknownLinkError
from rt70.fe.modal_body import clamped_modes
from rt70.linear.linearize import equilibrium
from rt70.model.antenna import pointing
from rt70.model.outputs import evaluate, output_matrix
from rt70.model.scene import load_scene, scene_from_text
from rt70.model.sides import side_of
from rt70.model.surface_outputs import reflector_surface, surface_outputs, surface_rms
from rt70.physics.aerodynamics import WindCondition
from rt70.reference import wind as ref_wind
from rt70.scenes import reflector_scenes as rs
from rt70.scenes import rt70_mirror as rm
from rt70.scenes.rt70_data import LISTING_BODIES
from rt70.surface.best_fit import fit_maps
from rt70.surface.pressure import nodal_forces
from rt70.telescope.homology import homology
from rt70.testing import assert_close
from rt70.textbook import wind as tb_wind
from rt70.urdf.modal_file import ModalArrays, read_modal_file, write_modal_file
from rt70.urdf.modal_record import Surface, node_point

RNG = np.random.default_rng(20261127)


@pytest.fixture(scope="module")
def mirror():
    return load_scene("rt70_mirror")


@pytest.fixture(scope="module")
def dish():
    return rm.rt70_dish()


def _small_state(scene, scale=0.3):
    """A random configuration: rigid coordinates of order 0.1, modal ones of ``scale``.

    Modal coordinates of 0.3 move the dish's nodes by millimetres, as its own weight
    does (the gravity equilibrium at 10° elevation has them up to 1.7, 30 mm at the
    rim). The surface outputs are differences of node positions some 90 m from the
    origin, so each side's rounding of those (``ε |p|`` ≈ 2e-14 m) sets their floor:
    at millimetres it is near 1e-11.
    """
    q = RNG.normal(0.0, 0.1, scene.textbook.nv)
    for m in scene.textbook.modal:
        q[m.coords] = RNG.normal(0.0, scale, m.modes)
    return q


def test_node_points_agree_on_both_sides_and_differentiate(mirror):
    body = mirror.description.modal_bodies[0]
    points = [
        (node_point(body.name, n), xyz) for n, xyz in ((40, (0.1, 0.2, 0.3)), (63, (0, 0, 0)))
    ]
    points.append(("main_mirror", (1.0, 2.0, 3.0)))
    q = _small_state(mirror)
    tb, ref = side_of(mirror, "textbook"), side_of(mirror, "reference")
    p_tb = tb.points.point_positions(tb.model, tb.data, q, points)
    p_ref = ref.points.point_positions(ref.model, ref.data, q, points)
    assert_close(p_tb, p_ref, rel=1e-13, scale=np.abs(p_tb).max())
    h = 1e-6
    for link, xyz in points:
        J_tb = np.vstack(tb.points.point_jacobian(tb.model, tb.data, q, link, xyz))
        J_ref = np.vstack(ref.points.point_jacobian(ref.model, ref.data, q, link, xyz))
        assert_close(J_tb, J_ref, rel=1e-12, scale=np.abs(J_tb).max())
        diff = np.empty((3, q.size))
        for i in range(q.size):
            e = np.zeros(q.size)
            e[i] = h
            plus = tb.points.point_position(tb.model, tb.data, q + e, link, xyz)
            minus = tb.points.point_position(tb.model, tb.data, q - e, link, xyz)
            diff[:, i] = (plus - minus) / (2 * h)
        assert_close(J_tb[:3], diff, rel=1e-7, scale=np.abs(J_tb).max())


def test_surface_outputs_agree_on_both_sides(mirror):
    surface = reflector_surface(mirror)
    outs = surface_outputs(surface)
    for _ in range(3):
        q = _small_state(mirror)
        tb = evaluate(mirror, q, outs, "textbook")
        ref = evaluate(mirror, q, outs, "reference")
        for name, value in tb.items():
            assert np.all(np.isfinite(value)) and np.abs(value).max() > 0.0, name
            assert_close(value, ref[name], rel=1e-10, scale=np.abs(value).max())
    q = _small_state(mirror)
    C_tb = output_matrix(mirror, q, outs, "textbook")
    C_ref = output_matrix(mirror, q, outs, "reference")
    assert_close(C_tb, C_ref, rel=1e-10, scale=np.abs(C_tb).max())


def test_outputs_are_the_fit_of_the_node_displacements(mirror):
    surface = reflector_surface(mirror)
    body = surface.body
    q = np.zeros(mirror.textbook.nv)
    eta = mirror.textbook.modal[0].coords
    q[eta] = RNG.normal(0.0, 1e-2, body.modes)
    values = evaluate(mirror, q, surface_outputs(surface, "s"), "textbook")
    delta = (body.shapes @ q[eta])[surface.nodes]  # the dish frame is the link's at q = 0
    h = np.sum(surface.maps.H * delta, axis=1)
    beta = surface.maps.P @ h
    assert_close(values["s_vertex_shift"], 1e3 * beta[:3], rel=1e-9, scale=1e3 * np.abs(beta).max())
    residual = 1e6 * (surface.maps.R @ h)
    assert_close(values["s_residual"], residual, rel=1e-9, scale=np.abs(residual).max())
    assert surface_rms(surface, values["s_residual"]) == pytest.approx(
        np.sqrt(surface.maps.weights @ values["s_residual"] ** 2), rel=1e-14
    )


def test_mirror_keeps_the_listings_mass_properties(mirror):
    listing = [b for b in LISTING_BODIES if b["name"] == "main_mirror"][0]
    desc = mirror.description
    inertial = desc.links["main_mirror"].inertial
    body = desc.modal_bodies[0]
    weld = [j for j in desc.joints if j.name == "main_dish_weld"][0]
    assert not np.any(weld.rpy)
    m_d, c_d, I_d = rs.rigid_properties(body.nodes + weld.xyz, body.masses)
    m_l, c_l, I_l = inertial.mass, np.asarray(inertial.com), np.asarray(inertial.inertia)
    m = m_d + m_l
    c = (m_d * c_d + m_l * c_l) / m
    total = rs._shifted(I_d, m_d, c_d - c) + rs._shifted(I_l, m_l, c_l - c)
    assert m == pytest.approx(listing["mass"], rel=1e-12)
    assert np.abs(c).max() <= 1e-12 * 35.0
    assert_close(total, np.diag(listing["moments"]), rel=1e-12, scale=max(listing["moments"]))
    assert m_d > 0.25 * m  # the dish is a real share of the mirror, not a token


def _static(dish, force):
    """The FE model's own static displacement (N, 3) under ``force`` (N, 3), hub held."""
    fe = dish.fe
    n = fe.M.shape[0]
    held = np.concatenate([fe.dofs_of(i) for i in dish.hub])
    free = np.setdiff1d(np.arange(n), held)
    u = np.zeros(n)
    u[free] = spla.spsolve(fe.K.tocsc()[free][:, free], force.ravel()[free])
    return u.reshape(-1, 3)


def test_load_shapes_make_the_static_response_exact(dish):
    patterns = rs.load_patterns(dish)
    body = rs.dish_body(dish, 6, "test")
    modes_only = clamped_modes(dish.fe, dish.hub, 6)
    for k in (0, 2, 5, 6):  # gravity along x and z; an axial pressure; a pitching one
        exact = _static(dish, patterns[k])
        scale = np.abs(exact).max()
        for b, expect_exact in ((body, True), (modes_only, False)):
            Phi = b.shapes.reshape(-1, b.shapes.shape[2])
            eta = np.linalg.solve(b.stiffness, Phi.T @ patterns[k].ravel())
            error = np.abs((Phi @ eta).reshape(-1, 3) - exact).max() / scale
            assert (error <= 1e-9) if expect_exact else (error > 1e-3), (k, error)


def test_homology_is_the_closed_form_in_the_dish_frame(mirror, dish):
    surface = reflector_surface(mirror)
    elevations, rigging = [15.0, 50.0, 85.0], 50.0
    curve = homology(mirror, surface, elevations, rigging)
    assert curve.rms_um[1] == 0.0 and np.all(curve.rms_um[[0, 2]] > 10.0)
    masses = dish.fe.M.diagonal()[::3]
    maps = fit_maps(dish.fe.node_xyz[dish.surface], dish.focal_length, dish.weights)
    unit = [  # h of the FE model's own static sag under 1 m/s² along the dish's x, y, z
        np.sum(maps.H * _static(dish, np.outer(masses, e))[dish.surface], axis=1) for e in np.eye(3)
    ]
    g = np.asarray(mirror.description.gravity)
    tb = side_of(mirror, "textbook")
    frame = [("main_dish_link", xyz) for xyz in np.vstack([np.zeros(3), np.eye(3)])]

    def closed_form(elevation):
        q = equilibrium(mirror, pointing(mirror, elevation), side="textbook")
        p = tb.points.point_positions(tb.model, tb.data, q, frame)
        R = (p[1:] - p[0]).T  # the dish frame's axes in ground axes, at the equilibrium
        g_dish = R.T @ g
        return sum(a * u for a, u in zip(g_dish, unit, strict=True))

    rigged = closed_form(rigging)
    for k, elevation in enumerate(elevations):
        residual = 1e6 * (maps.R @ (closed_form(elevation) - rigged))
        scale = max(np.abs(curve.residual_um).max(), 1.0)
        assert_close(curve.residual_um[k], residual, rel=1e-7, scale=scale)


def _with_surface(tmp_path, **changes):
    body = rs.dish_body(rm.rt70_dish(rings=1, ribs=6), 2, "test")
    surface = Surface(**{**body.surface.__dict__, **changes})
    path = tmp_path / "dish.npz"
    arrays = ModalArrays(
        body.nodes, body.masses, body.shapes, body.stiffness, body.damping, "", body.edges,
        surface=surface,
    )  # fmt: skip
    write_modal_file(path, arrays)
    return path


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"focal_length": 20.0}, "off the paraboloid"),
        ({"focal_length": -1.0}, "focal_length must be"),
        ({"weights": np.zeros(12)}, "surface_weights must be finite and > 0"),
        ({"nodes": np.array([0, 0, 1, 2, 3, 4])}, "distinct nodes"),
        ({"nodes": np.array([0, 1, 2, 3, 4, 99])}, "distinct nodes"),
    ],
)
def test_bad_surfaces_are_refused(tmp_path, changes, message):
    with pytest.raises(ExtensionError, match=message):
        _with_surface(tmp_path, **changes)


def test_a_file_with_part_of_a_surface_is_refused(tmp_path):
    path = _with_surface(tmp_path)
    with np.load(path) as archive:
        arrays = {k: archive[k] for k in archive.files if k != "focal_length"}
    np.savez(path, **arrays)
    with pytest.raises(ExtensionError, match="focal_length missing"):
        read_modal_file(path, "test")


def test_reference_side_names_a_node_it_does_not_place(mirror):
    ref = side_of(mirror, "reference")
    with pytest.raises(UnknownLinkError, match="not placed on the reference side"):
        ref.points.point_positions(
            ref.model, ref.data, np.zeros(ref.model.nv), [("main_dish/node9999", (0, 0, 0))]
        )


def test_a_scene_without_a_surface_is_refused_by_name():
    scene = scene_from_text('<robot name="bare"><link name="world"/></robot>', "bare")
    with pytest.raises(Exception, match="0 modal bodies have a reflecting surface"):
        reflector_surface(scene)


def test_the_pressure_carries_the_wrench_exactly():
    nodes = RNG.normal(0.0, 10.0, (40, 3))
    weights = RNG.uniform(0.5, 2.0, 40)
    force, moment, point = RNG.normal(0, 1e4, 3), RNG.normal(0, 1e5, 3), RNG.normal(0, 5, 3)
    f = nodal_forces(force, moment, point, nodes, weights)
    assert_close(f.sum(axis=0), force, rel=1e-13, scale=np.abs(force).max())
    total = np.cross(nodes - point, f).sum(axis=0)
    assert_close(total, moment, rel=1e-12, scale=np.abs(moment).max())
    with pytest.raises(Exception, match="on a line"):
        nodal_forces(force, moment, point, np.outer(np.arange(5.0), [1, 2, 3]), np.ones(5))


def test_wind_on_the_surface_agrees_and_moves_the_structure_as_the_wrench(mirror):
    condition = WindCondition(20.0, 30.0)
    q = _small_state(mirror, scale=0.0)
    tb = tb_wind.wind_forces(mirror.textbook, mirror.textbook_data, q, condition)
    ref = ref_wind.wind_forces(mirror.reference, mirror.reference_data, q, condition)
    spread = tb["main_mirror"]
    assert_close(spread, ref["main_mirror"], rel=1e-12, scale=np.abs(spread).max())
    wrench = tb_wind.wind_wrenches(mirror.textbook, mirror.textbook_data, q, condition)
    lumped = tb_wind._force(mirror.textbook, mirror.textbook_data, wrench["main_mirror"])
    rigid = np.ones(mirror.textbook.nv, dtype=bool)
    rigid[mirror.textbook.modal[0].coords] = False
    assert_close(spread[rigid], lumped[rigid], rel=1e-11, scale=np.abs(lumped).max())
    assert np.abs(spread[~rigid]).max() > 1e-6 * np.abs(lumped).max()  # it deforms the dish


@pytest.mark.parametrize(
    ("name", "fresh"),
    [("rt70_mirror", rm.rt70_mirror_body), ("antenna_12m_dish", None)],
)
def test_the_shipped_dish_files_are_the_generators(name, fresh):
    """The committed modal files against a fresh build, in what does not depend on the CPU.

    Mode shapes of equal frequencies (the dish's symmetric pairs) are any basis of their
    plane, so the modes are compared through the projector ``Φ Φᵀ M`` and ω².
    """
    if fresh is None:
        from rt70.scenes.antenna_dish import antenna_12m_dish_body as fresh
    body = load_scene(name).description.modal_bodies[0]
    new = fresh()
    assert_close(body.masses, new.masses, rel=1e-12, scale=new.masses.max())
    assert_close(np.diag(body.stiffness), np.diag(new.stiffness), rel=1e-9)
    assert np.array_equal(body.surface.nodes, new.surface.nodes)
    assert_close(body.surface.weights, new.surface.weights, rel=1e-14)

    def projector(shapes, masses):
        Phi = shapes.reshape(-1, shapes.shape[2])
        return Phi @ Phi.T * np.repeat(masses, 3)

    P = projector(new.shapes, new.masses)
    assert_close(projector(body.shapes, body.masses), P, rel=1e-7, scale=np.abs(P).max())


def test_the_12m_dish_keeps_the_reflectors_mass_and_centre():
    from rt70.scenes.antenna import antenna_urdf
    from rt70.scenes.antenna_presets import PRESETS
    from rt70.urdf import read_urdf_string

    rigid = read_urdf_string(antenna_urdf(PRESETS["antenna_12m"]), "rigid.urdf").links["reflector"]
    scene = load_scene("antenna_12m_dish")
    link = scene.description.links["reflector"].inertial
    body = scene.description.modal_bodies[0]
    weld = [j for j in scene.description.joints if j.name == "dish_weld"][0]
    m_d, c_d, _ = rs.rigid_properties(body.nodes + weld.xyz, body.masses)
    m = m_d + link.mass
    assert m == pytest.approx(rigid.inertial.mass, rel=1e-12)
    c = (m_d * c_d + link.mass * np.asarray(link.com)) / m
    assert_close(c, rigid.inertial.com, rel=1e-10, scale=1.0)
    assert reflector_surface(scene).focal_length == 4.8
