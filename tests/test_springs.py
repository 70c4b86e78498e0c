"""Spring and damper forces: conservative, and the book's strut-package matrix at q = 0."""

import numpy as np
import pytest

from rt70.model.scene import load_scene
from rt70.testing import assert_close
from rt70.textbook import forces
from rt70.textbook.kinematics import frame_pose
from rt70.textbook.spatial import placement, rpy_matrix


def _deformation_scale(td, bm) -> np.ndarray:
    """The size of the terms of each entry of δ (and row of ∂δ/∂q): for the translation,
    the two frames' distance from the ground origin (δ is a difference of positions);
    for the angles, 1 (a rotation's entries)."""
    size = max(np.linalg.norm(frame_pose(td, b, r, c)[1]) for b, r, c in _frames(bm))
    return np.r_[np.full(3, size), np.ones(3)]


def _frames(bm):
    return ((bm.body1, bm.r1, bm.c1), (bm.body2, bm.r2, bm.c2))


@pytest.fixture(scope="module")
def rt70_scene():
    return load_scene("rt70")


def package_matrix(struts, attr):
    """The book's package matrix Σ_s L_s C_s L_sᵀ, L_s = T(r_s)[c_s] (4.85)–(4.92)."""
    total = np.zeros((6, 6))
    for b in struts:
        L_s = placement(b.frame2.xyz, rpy_matrix(b.frame2.rpy))
        total += L_s @ getattr(b, attr) @ L_s.T
    return total


@pytest.mark.parametrize("package, body", [("platform_base", "base"), ("base_rigel", "rigel")])
def test_strut_package_linearises_to_book_matrix(rt70_scene, package, body):
    """At q = 0, −∂Q_c/∂q_j and −∂Q_d/∂q̇_j of a package equal Σ L_s C_s L_sᵀ, Σ L_s D_s L_sᵀ."""
    tm, td = rt70_scene.textbook, rt70_scene.textbook_data
    struts = [b for b in rt70_scene.description.bushings if b.package == package]
    assert len(struts) in (2, 4)
    j = tm.body_names.index(body)
    cols = tm.coords(j)
    q0 = np.zeros(tm.nv)
    from rt70.textbook.kinematics import update_structure

    update_structure(tm, td, q0)
    K = np.zeros((6, 6))
    Dm = np.zeros((6, 6))
    for bm in tm.bushings:
        if bm.name.startswith(package + "/"):
            d = forces.bushing_deformation(td, bm)
            scale = _deformation_scale(td, bm)
            assert_close(d.delta, np.zeros(6), rel=1e-14, scale=scale)  # at rest
            J = d.jacobian[:, cols]
            K += J.T @ bm.stiffness @ J
            Dm += J.T @ bm.damping @ J
    for mine, attr in ((K, "stiffness"), (Dm, "damping")):
        book = package_matrix(struts, attr)
        assert_close(mine, book, rel=1e-14, what=attr)
    # and the force itself has that slope (central differences, only the package's pair moves)
    h = 1e-7
    slope = np.zeros((6, 6))
    for c in range(6):
        dq = np.zeros(tm.nv)
        dq[cols.start + c] = h
        qc_plus, _ = forces.spring_damper_force(tm, td, dq, np.zeros(tm.nv))
        qc_minus, _ = forces.spring_damper_force(tm, td, -dq, np.zeros(tm.nv))
        slope[:, c] = (qc_plus - qc_minus)[cols] / (2 * h)
    other = np.zeros((6, 6))  # the stiffness of the other elements acting on this pair
    for bm in tm.bushings:
        if not bm.name.startswith(package + "/"):
            d = forces.bushing_deformation(td, bm)
            J = d.jacobian[:, cols]
            other += J.T @ bm.stiffness @ J
    book = package_matrix(struts, "stiffness")
    assert_close(-slope - other, book, rel=1e-6)


@pytest.mark.parametrize("name", ["rt70", "two_body_gravity", "rt70_elevation", "three_masses"])
def test_spring_force_is_minus_gradient_of_potential(name):
    """Q_c = −∂U/∂q (springs are conservative, formalism §4.4), checked by central differences."""
    scene = load_scene(name)
    tm, td = scene.textbook, scene.textbook_data
    rng = np.random.default_rng(7)
    q = rng.uniform(-0.3, 0.3, tm.nv)
    Qc, _ = forces.spring_damper_force(tm, td, q, np.zeros(tm.nv))
    h = 1e-6
    grad = np.empty(tm.nv)
    for i in range(tm.nv):
        e = np.zeros(tm.nv)
        e[i] = h
        grad[i] = (
            forces.spring_potential(tm, td, q + e) - forces.spring_potential(tm, td, q - e)
        ) / (2 * h)
    assert_close(-grad, Qc, rel=1e-6)


def test_damper_power_is_dissipative():
    """q̇ᵀ Q_d = −δ̇ᵀ D δ̇ ≤ 0 at any state."""
    scene = load_scene("rt70")
    tm, td = scene.textbook, scene.textbook_data
    rng = np.random.default_rng(3)
    for _ in range(5):
        q, qd = rng.uniform(-0.3, 0.3, tm.nv), rng.uniform(-1, 1, tm.nv)
        _, Qd = forces.spring_damper_force(tm, td, q, qd)
        assert qd @ Qd < 0.0


def test_direct_pair_bushing_deformation_is_pair_coordinates(rt70_scene):
    """A bushing between E_jc and E_j deforms by exactly q_j (the book's direct pair, (4.83))."""
    tm, td = rt70_scene.textbook, rt70_scene.textbook_data
    rng = np.random.default_rng(11)
    q = rng.uniform(-0.5, 0.5, tm.nv)
    from rt70.textbook.kinematics import update_structure

    update_structure(tm, td, q)
    for bm in tm.bushings:
        if "/" in bm.name:
            continue
        d = forces.bushing_deformation(td, bm)
        j = bm.body2
        scale = _deformation_scale(td, bm)
        assert_close(d.delta, q[tm.coords(j)], rel=1e-14, scale=scale, what=bm.name)
        expected = np.zeros((6, tm.nv))
        expected[:, tm.coords(j)] = np.eye(6)
        assert_close(d.jacobian, expected, rel=1e-14, scale=scale[:, None], what=bm.name)


def test_reference_rpy_formulas_are_pinocchios():
    """The batched rpy and inverse rpy Jacobian of rt70.reference equal pin.rpy's."""
    import pinocchio as pin

    from rt70 import reference

    scene = load_scene("rt70")
    ref, rd = scene.reference, scene.reference_data
    rng = np.random.default_rng(5)
    q = rng.uniform(-0.4, 0.4, ref.nv)  # the RT-70's book coordinates are Pinocchio's q
    delta, jac = reference.deformations(ref, rd, q)
    d = rd.pin_data
    for k, ((i1, P1), (i2, P2)) in enumerate(zip(ref.frames1, ref.frames2, strict=True)):
        M12 = (d.oMi[i1] * P1).actInv(d.oMi[i2] * P2)
        rho = pin.rpy.matrixToRpy(M12.rotation.T)
        size = max(np.linalg.norm((d.oMi[i] * P).translation) for i, P in ((i1, P1), (i2, P2)))
        scale = np.r_[np.full(3, size), np.ones(3)]  # as _deformation_scale, Pinocchio's frames
        assert_close(delta[k], np.r_[M12.translation, -rho], rel=1e-14, scale=scale)
        J1 = pin.getFrameJacobian(ref.pin_model, d, i1, P1, pin.LOCAL)
        J2 = pin.getFrameJacobian(ref.pin_model, d, i2, P2, pin.LOCAL)
        J_rel = J2 - M12.inverse().toActionMatrix() @ J1
        expected = np.r_[
            M12.rotation @ J_rel[:3],
            pin.rpy.computeRpyJacobianInverse(rho, pin.WORLD) @ J_rel[3:],
        ]
        assert_close(jac[k], expected, rel=1e-9)
