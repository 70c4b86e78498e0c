"""The floating-frame modal body (rt70.textbook.flexible) against its nodes in Pinocchio.

The textbook side writes a flexible body from its inertia invariants (FFRF); the same
body as N point masses, each on three prismatic joints from a floating frame, is a plain
Pinocchio model. With the nodes tied to the modes, ``u = Φ η`` — a linear, constant
change of variables ``[v; ω; u̇] = T [v; ω; η̇]``, ``T = diag(I₆, Φ)`` — the two must give

    M_FFRF(η) = Tᵀ M_nodes T,     h_FFRF(η, w) = Tᵀ h_nodes(T w),

for any number of modes k (the full basis and truncated ones alike), to rounding.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from rt70.testing import assert_close
from rt70.textbook.flexible import body_mass_matrix, inertia_invariants, velocity_terms

RNG = np.random.default_rng(20261127)


def nodal_model(nodes: np.ndarray, masses: np.ndarray) -> pin.Model:
    """A massless floating frame with each node a point mass on PX, PY, PZ joints."""
    model = pin.Model()
    base = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "frame")
    model.appendBodyToJoint(base, pin.Inertia.Zero(), pin.SE3.Identity())
    for n, (x, m) in enumerate(zip(nodes, masses, strict=True)):
        parent = base
        for axis, joint in enumerate((pin.JointModelPX(), pin.JointModelPY(), pin.JointModelPZ())):
            placement = pin.SE3(np.eye(3), x) if axis == 0 else pin.SE3.Identity()
            parent = model.addJoint(parent, joint, placement, f"node{n}_{axis}")
            mass = (
                pin.Inertia(m, np.zeros(3), np.zeros((3, 3))) if axis == 2 else pin.Inertia.Zero()
            )
            model.appendBodyToJoint(parent, mass, pin.SE3.Identity())
    model.gravity.setZero()
    return model


def body(n_nodes: int, k: int):
    """Random nodes, masses and k mode shapes (full basis when k = 3 N)."""
    nodes = RNG.uniform(-2.0, 2.0, (n_nodes, 3))
    masses = RNG.uniform(0.5, 3.0, n_nodes)
    shapes = RNG.normal(0.0, 0.1, (n_nodes, 3, k))
    return nodes, masses, shapes


def pinocchio_terms(model, nodes, shapes, eta, w):
    """M and h of the nodal model in the modal coordinates: Tᵀ M T and Tᵀ h(T w)."""
    data = model.createData()
    frame_pose = pin.SE3(pin.exp3(RNG.normal(0, 0.5, 3)), RNG.normal(0, 1.0, 3))
    u = np.einsum("naj,j->na", shapes, eta).ravel()
    q = np.concatenate([pin.SE3ToXYZQUAT(frame_pose), u])
    phi = shapes.reshape(-1, shapes.shape[2])  # node-major rows: 3 n + axis
    T = np.zeros((6 + phi.shape[0], 6 + phi.shape[1]))
    T[:6, :6] = np.eye(6)
    T[6:, 6:] = phi
    M = pin.crba(model, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    h = pin.nonLinearEffects(model, data, q, T @ w)
    return T.T @ M @ T, T.T @ h


@pytest.mark.parametrize(("n_nodes", "k"), [(4, 12), (6, 5), (10, 1)], ids=["full", "k5", "k1"])
def test_the_modal_body_is_its_nodes_tied_to_the_modes(n_nodes, k):
    nodes, masses, shapes = body(n_nodes, k)
    inv = inertia_invariants(nodes, masses, shapes)
    model = nodal_model(nodes, masses)
    for _ in range(3):
        eta = RNG.normal(0.0, 1.0, k)
        w = RNG.normal(0.0, 1.0, 6 + k)
        M_ref, h_ref = pinocchio_terms(model, nodes, shapes, eta, w)
        M = body_mass_matrix(inv, eta)
        assert_close(M, M_ref, rel=1e-13)
        # h sums products of w, M and ω × p of the size |M| |w|²: that is its scale
        assert_close(velocity_terms(inv, eta, w), h_ref, rel=1e-13, scale=np.abs(M).max() * (w @ w))


def test_the_kinetic_energy_is_the_nodes_own():
    nodes, masses, shapes = body(5, 4)
    inv = inertia_invariants(nodes, masses, shapes)
    eta, w = RNG.normal(0.0, 1.0, 4), RNG.normal(0.0, 1.0, 10)
    v, omega, eta_dot = w[:3], w[3:6], w[6:]
    r = nodes + np.einsum("naj,j->na", shapes, eta)
    node_velocity = v + np.cross(omega, r) + np.einsum("naj,j->na", shapes, eta_dot)
    energy = 0.5 * np.sum(masses * np.sum(node_velocity**2, axis=1))
    assert_close(0.5 * w @ body_mass_matrix(inv, eta) @ w, energy, rel=1e-14)


def test_with_every_mode_the_body_has_its_fe_models_frequencies_and_fewer_lie_above():
    from rt70.fe.truss import space_frame
    from rt70.reports.modal_truncation import body_frequencies, held_modes, nodal_frequencies

    fe = space_frame(3, 3)
    index = {node: i for i, node in enumerate(fe.node_ids)}
    held = held_modes(fe, tuple(index[fe.interfaces[f"corner_{c}"]] for c in (1, 2, 4)))
    reference = nodal_frequencies(fe)
    full = body_frequencies(held, held.omega2.size)
    assert held.omega2.size == 3 * fe.node_xyz.shape[0] - 6
    assert_close(full[6:], reference[6:], rel=1e-10, scale=np.abs(reference[6:]))
    assert np.all(full[:6] == 0.0)  # the frame carries the rigid motion: no stiffness
    errors = [body_frequencies(held, k)[6:11] / reference[6:11] - 1 for k in (8, 16, 32)]
    assert all(np.all(e > -1e-12) for e in errors)  # a Ritz basis: from above
    assert np.abs(errors[0]).max() > np.abs(errors[1]).max() > np.abs(errors[2]).max()
