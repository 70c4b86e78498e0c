"""The linear servo plant of one axis: a DC drive joined to a linearised structure.

One job: the plant a servo loop of one axis is closed around (:class:`AxisPlant`), two
linear models joined by python-control's ``interconnect`` (:func:`connect_drive`):

- the structure, linearised at an equilibrium (:func:`structure_plant`, on
  :func:`rt70.linear.plant.plant`), the driven axis coordinate free; inputs the reducer
  torque on the axis coordinate and a disturbance load (``wind_torque``, a
  :class:`rt70.physics.loads.Wrench` per unit input); outputs the axis angle and rate and a
  two-component pointing output (:data:`POINTING`, e.g. the corrections Δα, Δβ
  (4.159)–(4.163) in arc seconds);
- the drive (formalism §4.5, (4.137)–(4.143), :class:`rt70.control.drives.DcDrive` linear as it
  is; :func:`drive_block`): the armature ``L_a İ = u − R_a I − c_e ω_m``, the rotor
  ``J_m ω̇_m = c_m I − D_m ω_m − τ_r / i_r`` and the reducer torque
  ``τ_r = C_r (α_m / i_r − α) + D_r (ω_m / i_r − α̇)`` fed by the axis angle and rate.

The loops closed around it are :mod:`rt70.control.loops` (the PI cascade) and
:mod:`rt70.control.lqg`; the RT-70's axes and pointings are chosen in
:mod:`rt70.reports.servo_loops`: nothing here knows the telescope.
"""

from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np

from rt70.bondgraph.parameters import DriveParameters
from rt70.errors import Rt70Error
from rt70.linear.plant import CoordinateInput, CoordinateOutput, LoadInput, plant
from rt70.model.outputs import Output
from rt70.model.scene import Scene
from rt70.physics.loads import Wrench

#: Names of the pointing outputs: Δα, Δβ of (4.159)–(4.163), arc seconds.
POINTING = ("pointing_da", "pointing_db")


def drive_block(p: DriveParameters) -> control.StateSpace:
    """The DC drive (4.137)–(4.143) as a linear block fed by the axis angle and rate.

    States ``current``, ``motor_angle``, ``motor_speed``; inputs ``voltage`` (V),
    ``axis_angle`` (rad), ``axis_rate`` (rad/s); outputs ``reducer_torque`` (N·m, on the
    axis), ``current``, ``motor_speed``, ``motor_angle``.
    """
    A = np.array(
        [
            [-p.R_a / p.L_a, 0.0, -p.c_e / p.L_a],
            [0.0, 0.0, 1.0],
            [p.c_m / p.J_m, -p.C_r / p.i_r**2 / p.J_m, -(p.D_m + p.D_r / p.i_r**2) / p.J_m],
        ]
    )
    B = np.array(
        [
            [1.0 / p.L_a, 0.0, 0.0],
            [0.0, 0.0, 0.0],
            [0.0, p.C_r / p.i_r / p.J_m, p.D_r / p.i_r / p.J_m],
        ]
    )
    C = np.array([[0.0, p.C_r / p.i_r, p.D_r / p.i_r], [1, 0, 0], [0, 0, 1], [0, 1, 0]])
    D = np.zeros((4, 3))
    D[0, 1:] = -p.C_r, -p.D_r
    return control.ss(
        A,
        B,
        C,
        D,
        states=["current", "motor_angle", "motor_speed"],
        inputs=["voltage", "axis_angle", "axis_rate"],
        outputs=["reducer_torque", "current", "motor_speed", "motor_angle"],
        name="drive",
    )


def structure_plant(
    scene: Scene,
    q0: np.ndarray,
    coordinate: str,
    disturbance: Wrench,
    pointing: Output,
    locked: tuple[str, ...] = (),
) -> tuple[control.StateSpace, float]:
    """The structure about ``q0`` with its axis coordinate free, and its rigid inertia.

    Parameters
    ----------
    scene : Scene
        The structure.
    q0 : ndarray
        A static equilibrium (:func:`rt70.linear.linearize.equilibrium`).
    coordinate : str
        The driven axis coordinate (free in the plant).
    disturbance : Wrench
        The load of a unit ``wind_torque`` input (e.g. a torque about the axis on the
        dish).
    pointing : Output
        A two-component output (the pointing corrections), labelled :data:`POINTING`.
    locked : tuple of str
        Coordinates locked (e.g. the other axis).

    Returns
    -------
    (control.StateSpace, float)
        Inputs ``reducer_torque`` (on the axis coordinate) and ``wind_torque``; outputs
        ``axis_angle``, ``axis_rate`` and :data:`POINTING`. The load inertia is the
        mass matrix's diagonal entry of the axis coordinate (everything it turns, held
        rigid).
    """
    if pointing.size != len(POINTING):
        raise Rt70Error(f"{scene.name}: the pointing output must have {len(POINTING)} components")
    ss = plant(
        scene,
        q0,
        inputs=[
            CoordinateInput("reducer_torque", coordinate),
            LoadInput("wind_torque", disturbance),
        ],
        outputs=[CoordinateOutput("axis_angle", coordinate), pointing],
        locked=locked,
    )
    n = ss.nstates // 2
    k = ss.state_labels.index(coordinate)
    rate = np.zeros((1, 2 * n))
    rate[0, n + k] = 1.0
    C = np.vstack([ss.C[:1], rate, ss.C[1:]])
    D = np.vstack([ss.D[:1], np.zeros((1, 2)), ss.D[1:]])
    load_inertia = float(ss.second_order.M[k, k])
    structure = control.ss(
        ss.A,
        ss.B,
        C,
        D,
        states=ss.state_labels,
        inputs=["reducer_torque", "wind_torque"],
        outputs=["axis_angle", "axis_rate", *POINTING],
        name="structure",
    )
    return structure, load_inertia


def connect_drive(structure: control.StateSpace, p: DriveParameters) -> control.StateSpace:
    """The drive and a structure joined: the reducer torque in, the axis angle and rate back.

    ``structure`` has the input ``reducer_torque`` and the outputs ``axis_angle``,
    ``axis_rate``; its other inputs and outputs stay inputs and outputs of the result,
    with ``voltage`` in front and the drive's ``current``, ``motor_speed``,
    ``motor_angle`` and ``reducer_torque`` added to the outputs.
    """
    drive = drive_block(p)
    others_in = [n for n in structure.input_labels if n != "reducer_torque"]
    outputs = [
        "current",
        "motor_speed",
        "motor_angle",
        "reducer_torque",
        *structure.output_labels,
    ]
    return control.interconnect(
        [structure, drive],
        inplist=["voltage", *others_in],
        outlist=outputs,
        inputs=["voltage", *others_in],
        outputs=outputs,
        name="plant",
    )


@dataclass(frozen=True)
class AxisPlant:
    """The linear drive + structure of one axis at a pointing.

    Attributes
    ----------
    system : control.StateSpace
        Inputs ``voltage`` (V), ``wind_torque`` (N·m); outputs ``current`` (A),
        ``motor_speed`` (rad/s), ``motor_angle`` (rad), ``reducer_torque`` (N·m),
        ``axis_angle`` (rad), ``axis_rate`` (rad/s), :data:`POINTING` (arcsec).
    structure : control.StateSpace
        The structure alone (:func:`structure_plant`).
    parameters : DriveParameters
        The drive (for the RT-70: :func:`rt70.reports.servo_loops.drive_parameters`).
    axis : str
        Its name.
    elevation_deg, azimuth_deg : float
        The pointing.
    q0 : ndarray
        The equilibrium linearised about (all the scene's coordinates).
    """

    system: control.StateSpace
    structure: control.StateSpace
    parameters: DriveParameters
    axis: str
    elevation_deg: float
    azimuth_deg: float
    q0: np.ndarray

    @property
    def load_inertia(self) -> float:
        """The rigid structure's inertia about the axis, kg·m²."""
        return self.parameters.J_l
