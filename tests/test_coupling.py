"""The components' couplings in the implicit methods' Jacobian (rt70/simulation/coupling.py).

A motor with a first-order current loop pushes a torque on the double pendulum's first
joint from its state and the joint's angle and rate. The completed Jacobian must be the
right-hand side's own, as central differences of the whole right-hand side give it, and
an implicit run with it must agree with an explicit one at a tight tolerance.
"""

from __future__ import annotations

import numpy as np

from rt70.model.scene import load_scene
from rt70.simulation.backends import BACKENDS
from rt70.simulation.simulate import _RightHandSide, simulate
from rt70.simulation.states import EnergyAudit, StateComponent, StateLayout
from rt70.testing import assert_close


class Motor(StateComponent):
    """Current ``i`` following a PD law of joint 0 (time constant τ); torque ``g·i`` on it."""

    names = ("current",)

    def __init__(self, n: int, kp: float = 40.0, kd: float = 6.0, tau: float = 0.01) -> None:
        self.n, self.kp, self.kd, self.tau = n, kp, kd, tau
        self.initial = np.array([0.3])
        self.atol = np.array([1e-9])

    def derivative(self, t, q, qd, s, forces):
        return np.array([(-self.kp * q[0] - self.kd * qd[0] - s[0]) / self.tau])

    def force(self, t, q, qd, s):
        Q = np.zeros(self.n)
        Q[0] = 2.0 * s[0] * np.cos(0.1 * q[0])  # a torque constant that varies with angle
        return Q


def _rhs(scene, components):
    backend = BACKENDS["reference"](scene)
    layout = StateLayout([EnergyAudit(1e-9), *components], backend.nv)
    return _RightHandSide(backend, layout, None, (0.0, 1.0), False)


def _central_jacobian(f, t, x, h=1e-6):
    cols = []
    for j in range(x.size):
        e = np.zeros(x.size)
        e[j] = h * max(1.0, abs(x[j]))
        cols.append((f(t, x + e) - f(t, x - e)) / (2 * e[j]))
    return np.column_stack(cols)


def test_the_completed_jacobian_is_the_right_hand_sides_own():
    scene = load_scene("double_pendulum")
    n = scene.textbook.nv
    rhs = _rhs(scene, [Motor(n)])
    x = np.r_[0.4, -0.2, 0.3, 0.7, 0.0, 0.0, 0.8]  # q, q̇, audit (2), current
    J = rhs.jacobian(0.0, x)
    reference = _central_jacobian(rhs, 0.0, x)
    rows = np.r_[n : 2 * n, 2 * n + 2]  # q̈ and the motor's row (the audit's stay zero)
    scale = np.max(np.abs(reference[rows]))
    assert_close(J[rows], reference[rows], rel=1e-6, scale=scale)
    assert np.array_equal(rhs.coupling.columns, [0, 2, 6])  # q0, q̇0 and the current
    assert np.abs(J[n, 6]) > 0.1 and np.abs(J[6, 0]) > 1.0  # the couplings are there


def test_without_pushing_components_nothing_is_differenced():
    scene = load_scene("double_pendulum")
    rhs = _rhs(scene, [])
    x = np.r_[0.4, -0.2, 0.3, 0.7, 0.0, 0.0]
    J = rhs.jacobian(0.0, x)
    assert rhs.coupling.empty and rhs.coupling.columns.size == 0
    assert not np.any(J[4:])


def test_a_run_with_the_motor_keeps_its_accuracy():
    """BDF with the completed Jacobian against DOP853 at a tight tolerance."""
    scene = load_scene("double_pendulum")
    n = scene.textbook.nv
    x0 = (np.array([0.4, -0.2]), np.array([0.3, 0.7]))
    t = np.linspace(0.0, 1.0, 11)
    stiff = simulate(scene, (0.0, 1.0), x0, method="BDF", rtol=1e-8, t_eval=t,
                     components=[Motor(n)])  # fmt: skip
    ref = simulate(scene, (0.0, 1.0), x0, method="DOP853", rtol=1e-12, t_eval=t,
                   components=[Motor(n)])  # fmt: skip
    assert stiff.success and ref.success
    assert_close(stiff.q, ref.q, rel=1e-5, scale=np.max(np.abs(ref.q)))
    assert_close(stiff.states["current"], ref.states["current"], rel=1e-5)


class Load(StateComponent):
    """A stateless load ``−k sin(q₁)`` on joint 1; ``held`` sets IN_JACOBIAN False."""

    names = ()

    def __init__(self, n: int, k: float = 30.0, held: bool = False) -> None:
        self.n, self.k = n, k
        self.initial, self.atol = np.zeros(0), np.zeros(0)
        self.IN_JACOBIAN = not held

    def derivative(self, t, q, qd, s, forces):
        return np.zeros(0)

    def force(self, t, q, qd, s):
        Q = np.zeros(self.n)
        Q[1] = -self.k * np.sin(q[1])
        return Q


def test_a_load_is_coupled_unless_it_asks_to_be_held():
    """A stateless load is differenced like a drive; IN_JACOBIAN = False holds it fixed
    (as the wind's load does), so its stiffness is missing from the q̈ rows."""
    scene = load_scene("double_pendulum")
    n = scene.textbook.nv
    x = np.r_[0.4, -0.2, 0.3, 0.7, 0.0, 0.0, 0.8]
    coupled = _rhs(scene, [Motor(n), Load(n)])
    J = coupled.jacobian(0.0, x)
    reference = _central_jacobian(coupled, 0.0, x)
    rows = np.r_[n : 2 * n, 2 * n + 2]
    assert_close(J[rows], reference[rows], rel=1e-6, scale=np.max(np.abs(reference[rows])))
    assert 1 in coupled.coupling.columns
    held = _rhs(scene, [Motor(n), Load(n, held=True)])
    J_held = held.jacobian(0.0, x)
    assert 1 not in held.coupling.columns and np.array_equal(held.coupling.columns, [0, 2, 6])
    alone = _rhs(scene, [Load(n)])  # a stateless load by itself is differenced too
    x_alone = np.r_[x[: 2 * n], 0.0, 0.0]
    J_alone = alone.jacobian(0.0, x_alone)
    reference = _central_jacobian(alone, 0.0, x_alone)
    assert not alone.coupling.empty and np.array_equal(alone.coupling.columns, [1])
    assert_close(J_alone[n : 2 * n], reference[n : 2 * n], rel=1e-6,
                 scale=np.max(np.abs(reference[n : 2 * n])))  # fmt: skip
    # the held load's stiffness M⁻¹ (−k cos q₁) e₁ is what the two Jacobians differ by
    M = held.backend.mass_matrix(x[:n])
    missing = np.linalg.solve(M, np.r_[0.0, -30.0 * np.cos(x[1])])
    assert_close(J[n : 2 * n, 1] - J_held[n : 2 * n, 1], missing, rel=1e-6,
                 scale=np.max(np.abs(missing)))  # fmt: skip


class ClampedMotor(Motor):
    """The motor's PD law clamped to ±limit: saturated, it ignores the joint's angle and rate."""

    def __init__(self, n: int, limit: float = 1.0) -> None:
        super().__init__(n)
        self.limit = limit

    def derivative(self, t, q, qd, s, forces):
        law = min(max(-self.kp * q[0] - self.kd * qd[0], -self.limit), self.limit)
        return np.array([(law - s[0]) / self.tau])


def test_a_dependence_hidden_by_a_clamp_at_the_start_is_kept():
    """The couplings are found at a saturated start, where the motor's law ignores q₀ and
    q̇₀; once the clamp lets go, the Jacobian must still hold them (a servo's rate loop
    at the start of a large step: its pattern left them out, and LSODA and CVODE stalled
    on rt70_servo's 1° azimuth step)."""
    scene = load_scene("double_pendulum")
    n = scene.textbook.nv
    rhs = _rhs(scene, [ClampedMotor(n)])
    saturated = np.r_[0.4, -0.2, 0.3, 0.7, 0.0, 0.0, 0.8]  # −kp q₀ − kd q̇₀ = −17.8
    rhs.jacobian(0.0, saturated)
    free = np.r_[0.01, -0.2, 0.02, 0.7, 0.0, 0.0, 0.1]  # −0.52: inside the clamp
    J = rhs.jacobian(0.0, free)
    reference = _central_jacobian(rhs, 0.0, free)
    rows = np.r_[n : 2 * n, 2 * n + 2]
    assert_close(J[rows], reference[rows], rel=1e-6, scale=np.max(np.abs(reference[rows])))
    assert abs(J[2 * n + 2, 0]) > 1.0  # −kp/τ: the angle reaches the current once free
