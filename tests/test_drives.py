"""The DC drive as simulation states (rt70.control.drives) against its Lagrange form.

A rotor of inertia J_l on one joint, driven by the drive of formalism §4.5 through a
compliant reducer: the nonlinear simulation with the drive as an extra-state component
(its reducer torque pushed on the coordinate through the seam's ``force``) must follow
the linear equations of the same drive written independently in Lagrange form
(:func:`rt70.bondgraph.lagrange.drive_lagrange`, itself checked against the bond graph
to 1e-16): the load is one rigid body about a fixed axis, so the equations are linear.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rt70.bondgraph.lagrange import drive_lagrange
from rt70.bondgraph.parameters import DriveParameters
from rt70.control.drives import DcDrive
from rt70.errors import Rt70Error
from rt70.model.scene import scene_from_text
from rt70.simulation.simulate import simulate
from rt70.testing import assert_close

J_L = 2.0
ROTOR = f"""<robot name="rotor">
  <link name="ground"/>
  <link name="load"><inertial><mass value="1"/>
    <inertia ixx="1" iyy="1" izz="{J_L}" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="axis" type="continuous"><parent link="ground"/><child link="load"/>
    <axis xyz="0 0 1"/></joint>
</robot>"""

#: Labelled test values (not the RT-70's: docs/drives.md has those), well conditioned.
PARAMS = DriveParameters(
    L_a=0.01, R_a=1.0, c_m=0.5, c_e=0.5, J_m=0.01, D_m=1e-3,
    i_r=10.0, C_r=1e3, D_r=1.0, J_l=J_L, D_l=0.0,
)  # fmt: skip


def _linear_response(t: np.ndarray, voltage: float) -> np.ndarray:
    """[ρ̇ = I, α_m, α̇_m, α_l] of the Lagrange form under a constant voltage, from rest."""
    A, B = drive_lagrange(PARAMS, "voltage").first_order()  # x = [ρ, α_m, α_l, ρ̇, α̇_m, α̇_l]
    u = np.array([voltage, 0.0])
    sol = solve_ivp(
        lambda _t, x: A @ x + B @ u, (t[0], t[-1]), np.zeros(6), t_eval=t,
        method="DOP853", rtol=1e-12, atol=1e-14,
    )  # fmt: skip
    return np.column_stack([sol.y[3], sol.y[1], sol.y[4], sol.y[2]])


@pytest.mark.parametrize("side", ["reference", "textbook"])
def test_drive_on_a_rotor_follows_its_lagrange_form(side):
    scene = scene_from_text(ROTOR, "rotor")
    drive = DcDrive("az", scene.coordinate_names, "axis", PARAMS, voltage=12.0)
    t = np.linspace(0.0, 0.5, 101)
    run = simulate(
        scene, (0.0, 0.5), side=side, components=[drive], t_eval=t,
        method="DOP853", rtol=1e-11, atol=1e-13,
    )  # fmt: skip
    ref = _linear_response(t, 12.0)
    got = np.column_stack(
        [run.states["az:current"], run.states["az:motor_angle"],
         run.states["az:motor_speed"], run.q[:, 0]]
    )  # fmt: skip
    scale = np.abs(ref).max(axis=0)  # each column on its own size
    assert np.all(scale > 0)
    assert_close(got, ref, rel=1e-8, scale=scale)
    # the load turns, through the reducer: about α_m / i_r once the twist has settled
    assert_close(run.q[-1, 0], run.states["az:motor_angle"][-1] / PARAMS.i_r, rel=1e-2)
    # the drive's torque is input work in the energy audit: T + U_c − W_u stays balanced
    assert run.relative_drift < 1e-6


def test_holding_state_holds_a_torque_at_rest():
    """With the holding current and twist, a constant external torque is balanced."""
    scene = scene_from_text(ROTOR, "rotor")
    torque = 50.0
    s0 = DcDrive.holding(PARAMS, 0.3, torque)
    voltage = PARAMS.R_a * s0[0]  # at rest: U = R_a I
    drive = DcDrive("az", scene.coordinate_names, "axis", PARAMS, voltage, initial=s0)

    def external(_t, _q, _qd):  # the load the drive holds (e.g. gravity's moment)
        return np.array([-torque])

    run = simulate(
        scene, (0.0, 1.0), x0=(np.array([0.3]), np.zeros(1)), inputs=external,
        components=[drive], method="DOP853", rtol=1e-10,
    )  # fmt: skip
    held = np.ones(len(run.t))
    assert_close(run.q[:, 0], 0.3 * held, rel=1e-9)
    assert_close(run.states["az:current"], s0[0] * held, rel=1e-9)


def test_unknown_coordinate_is_refused():
    with pytest.raises(Rt70Error, match="no coordinate 'elevation'"):
        DcDrive("el", ["axis"], "elevation", PARAMS)
