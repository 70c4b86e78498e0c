"""Dry friction of an axis (rt70.control.friction): the book's law, its regularisations, energy."""

from __future__ import annotations

import numpy as np
import pytest
from test_coupling import _rhs  # the right-hand side with the audit and the components

from rt70.control.friction import (
    AxisFriction,
    creep_speed,
    friction_slope,
    friction_torque,
    relay_torque,
    switched_rigid_axis,
)
from rt70.errors import Rt70Error
from rt70.model.scene import scene_from_text
from rt70.scenes.rt70_drives import FRICTION, KGF_M
from rt70.simulation.simulate import simulate
from rt70.testing import assert_close

TOP = FRICTION.top_speed


def test_law_at_the_books_points():
    """7·10⁴ kgf·m at rest (either direction), 1.5·10⁵ kgf·m (in the book's (1–2)·10⁵) at
    top speed, opposing the motion (book §2.4, p. 51)."""
    tiny = 1e-15 * TOP
    assert_close(relay_torque(FRICTION, tiny), -7e4 * KGF_M, rel=1e-12)
    assert_close(relay_torque(FRICTION, -tiny), 7e4 * KGF_M, rel=1e-12)
    at_top = -relay_torque(FRICTION, TOP) / KGF_M
    assert_close(at_top, 1.5e5, rel=1e-6)
    assert 1e5 <= at_top <= 2e5
    assert relay_torque(FRICTION, -TOP) == -relay_torque(FRICTION, TOP)  # sign · f(|ω|): exact
    # linear between the two points: the middle speed gives the middle torque
    mid = -relay_torque(FRICTION, 0.5 * TOP) / KGF_M
    assert_close(mid, 0.5 * (7e4 + 1.5e5), rel=1e-6)


@pytest.mark.parametrize("kind", ["linear", "tanh"])
def test_regularisation_tends_to_the_relay(kind):
    """Away from zero speed the regularised law tends to the relay as ω_ε → 0, and the
    creep under half the static torque shrinks in proportion to ω_ε."""
    F_s = FRICTION.static_torque
    for delta in (1e-3 * TOP, 1e-5 * TOP, 1e-7 * TOP):  # the law on |ω| ≥ δ
        speeds = np.concatenate([-np.logspace(0, 4, 60), np.logspace(0, 4, 60)]) * delta
        relay = relay_torque(FRICTION, speeds)
        wide = np.abs(friction_torque(FRICTION, speeds, 10 * delta, kind) - relay).max()
        narrow = friction_torque(FRICTION, speeds, 0.01 * delta, kind)
        assert wide > 0.8 * F_s  # ω_ε = 10 δ: near ω = δ the law is still far from the relay
        assert_close(narrow, relay, rel=1e-12, scale=F_s)  # ω_ε = δ / 100: the relay
    creep = [
        creep_speed(FRICTION, 0.5 * FRICTION.static_torque, w * TOP, kind) for w in (1e-4, 1e-6)
    ]
    expected = 0.5 if kind == "linear" else np.arctanh(0.5)  # ω_c / ω_ε, slope neglected
    assert_close(creep[0] / (1e-4 * TOP), expected, rel=1e-2)
    assert_close(creep[1] / creep[0], 1e-2, rel=1e-3)


def test_bad_requests():
    with pytest.raises(Rt70Error, match="regularisation"):
        friction_torque(FRICTION, 0.0, 1e-9, "sign")
    with pytest.raises(Rt70Error, match="width"):
        friction_torque(FRICTION, 0.0, 0.0)
    with pytest.raises(Rt70Error, match="below F_s"):
        creep_speed(FRICTION, 2 * FRICTION.static_torque, 1e-9)
    with pytest.raises(Rt70Error, match="no coordinate 'elevation'"):
        AxisFriction("f", ["azimuth"], "elevation", FRICTION, 1e-9)


J = 7.0e9  # kg·m²: about the RT-70 azimuth with its rotors (docs/drives.md)


def test_switched_reference_against_closed_forms():
    """From rest, a constant torque above F_s: ω = (τ−F_s)/k (1 − e^(−kt/J)); below F_s the
    axis never leaves rest."""
    t = np.linspace(0.0, 40.0, 81)
    tau = 1.2 * FRICTION.static_torque
    run = switched_rigid_axis(J, FRICTION, lambda s: tau, t)
    k = FRICTION.slope
    speed = (tau - FRICTION.static_torque) / k * (1 - np.exp(-k * t / J))
    assert_close(run.speed, speed, rel=1e-8)
    assert run.switches == 1
    still = switched_rigid_axis(J, FRICTION, lambda s: 0.9 * FRICTION.static_torque, t)
    assert not still.angle.any() and still.switches == 0


def _rotor(inertia, joint="continuous"):
    limit = '<limit lower="-7" upper="7" effort="1e12" velocity="1"/>'
    limit = limit if joint == "revolute" else ""
    return scene_from_text(
        f"""<robot name="r"><link name="g"/><link name="b"><inertial><mass value="1"/>
        <inertia ixx="{inertia}" iyy="{inertia}" izz="{inertia}" ixy="0" ixz="0" iyz="0"/>
        </inertial></link><joint name="azimuth" type="{joint}"><parent link="g"/>
        <child link="b"/><axis xyz="0 0 1"/>{limit}</joint></robot>""",
        "rotor",
    )


def test_regularised_run_converges_to_the_switched_motion():
    """A sinusoidal torque of 1.5 F_s makes the axis slip and stick; the regularised run's
    error against the exact switched motion falls ten-fold with ω_ε (measured: 0.060″ and
    0.0060″ for a linear zone of 1e-4 and 1e-5 of top speed over 2 s)."""
    scene = _rotor(J)
    t = np.linspace(0.0, 2.0, 201)

    def torque(s):
        return 1.5 * FRICTION.static_torque * np.sin(np.pi * s)

    exact = switched_rigid_axis(J, FRICTION, torque, t)
    assert exact.switches >= 2  # it sticks and slips again within the run
    errors = []
    for w in (1e-4, 1e-5):
        f = AxisFriction("f", scene.coordinate_names, "azimuth", FRICTION, w * TOP, "linear")
        run = simulate(
            scene, (0.0, 2.0), components=[f], t_eval=t, rtol=1e-6, atol=1e-12,
            inputs=lambda s, q, qd: np.array([torque(s)]),
        )  # fmt: skip
        errors.append(np.abs(run.q[:, 0] - exact.angle).max() / np.radians(1 / 3600))
    assert 0.02 < errors[0] < 0.1
    assert_close(errors[1], 0.1 * errors[0], rel=0.2)


def test_friction_dissipation_closes_the_energy_balance():
    """A spinning axis left to its friction stops; the kinetic energy lost is the heat the
    friction state counts, and the audit (friction power in the input work) balances."""
    scene = _rotor(J)
    f = AxisFriction("f", scene.coordinate_names, "azimuth", FRICTION, 1e-6 * TOP, "linear")
    w0 = 0.5 * TOP
    run = simulate(
        scene, (0.0, 20.0), x0=(np.zeros(1), np.array([w0])), components=[f], rtol=1e-8,
        atol=1e-13,
    )  # fmt: skip
    T0 = 0.5 * J * w0**2
    heat = run.states["f:dissipated"]
    assert_close(run.qd[-1, 0], 0.0, rel=1e-6, scale=w0)  # stopped (to the creep)
    assert_close(heat[-1], T0, rel=1e-6)
    assert_close(run.input_work[-1], -heat[-1], rel=1e-9)
    assert_close(run.balance, np.zeros_like(run.balance), rel=1e-6, scale=T0)
    # it stops within the time the relay law gives: t ≤ J ω₀ / F_s (slope helps)
    stop = run.t[np.flatnonzero(np.abs(run.qd[:, 0]) > 1e-3 * w0)[-1]]
    assert stop < J * w0 / FRICTION.static_torque


@pytest.mark.parametrize("kind", ["linear", "tanh"])
def test_slope_is_the_laws_derivative(kind):
    """Central differences of the law, with a step of 10⁻⁶ of the zone: in the zone, on
    its edge's either side, and far out on the sliding branch."""
    width = 1e-6 * TOP
    h = 1e-6 * width
    for speed in (0.0, 0.3 * width, -0.7 * width, 1.5 * width, -40.0 * width, 0.5 * TOP):
        diff = (
            friction_torque(FRICTION, speed + h, width, kind)
            - friction_torque(FRICTION, speed - h, width, kind)
        ) / (2 * h)
        slope = friction_slope(FRICTION, speed, width, kind)
        scale = FRICTION.static_torque / width
        assert_close(slope, diff, rel=1e-6, scale=scale, what=f"{kind} at {speed / width:g} ω_ε")
    assert friction_slope(FRICTION, 2 * width, width, "linear") == -FRICTION.slope
    assert friction_slope(FRICTION, width, width, "linear") < -0.9 * FRICTION.static_torque / width


def test_the_implicit_methods_get_the_zones_slope_not_a_differenced_one():
    """A zone narrower than the difference step (√ε ≈ 1.5·10⁻⁸ rad/s): the Jacobian's q̈
    and heat entries on the axis's speed are the law's own, as central differences with a
    step inside the zone give them; the friction is not differenced (a revolute axis:
    Pinocchio's analytic Jacobian covers it)."""
    scene = _rotor(J, "revolute")
    width = 1e-9
    f = AxisFriction("f", scene.coordinate_names, "azimuth", FRICTION, width, "linear")
    rhs = _rhs(scene, [f])
    x = np.r_[0.2, 0.4 * width, 0.0, 0.0, 0.0]  # q, q̇, audit (2), heat
    Jac = rhs.jacobian(0.0, x)
    assert rhs.coupling.analytic and not rhs.coupling.coupled
    h = 1e-4 * width
    e = np.zeros(x.size)
    e[1] = h
    column = (rhs(0.0, x + e) - rhs(0.0, x - e)) / (2 * h)
    zone = FRICTION.static_torque / width
    assert_close(Jac[1, 1], column[1], rel=1e-6, scale=zone / J)
    assert_close(Jac[4, 1], column[4], rel=1e-6, scale=abs(column[4]))
    assert Jac[1, 1] < -0.9 * zone / J  # the zone's slope, not the sliding branch's
