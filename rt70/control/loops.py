"""The current–rate–position PI cascade closed around the linear plant of one axis.

One job: the cascade of :mod:`rt70.control.servo` as linear blocks around an
:class:`rt70.control.axis_plant.AxisPlant`, with the margins and bandwidth a servo engineer
reads (:mod:`rt70.control.loop_measures`). The RT-70's axes, drives and pointings are chosen
in :mod:`rt70.reports.servo_loops`; nothing here knows the telescope.

The cascade (:func:`cascade_system`) is linear: the limits and the anti-windup of
:class:`rt70.control.servo.ServoDrive` act only in saturation and are not part of a frequency
analysis. Each loop is broken at its error (:func:`loop_transfer`) with the other two
closed; margins come from python-control's ``stability_margins`` on the frequency
response (:func:`rt70.control.loop_measures.margins`): never a transfer-function conversion
of this high-order, lightly damped plant (see :mod:`rt70.linear.plant`).
"""

from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np

from rt70.control.axis_plant import POINTING, AxisPlant
from rt70.control.loop_measures import Margins, bandwidth_hz, margins, stable
from rt70.control.servo import CascadeGains, cascade_gains
from rt70.errors import Rt70Error

#: The cascade's errors, outermost first, and the signals each loop feeds back.
LOOPS = ("position", "rate", "current")


def pi_block(
    kp: float, ki: float, inp: str, out: str, scale: float = 1.0, name: str | None = None
) -> control.StateSpace:
    """``out = scale (kp e + ki ∫e)``: a PI controller as a state space (state ``integral``).

    Parameters
    ----------
    kp : float
        Proportional gain K_p (output unit per input unit).
    ki : float
        Integral gain K_i (output unit per input unit and second).
    inp : str
        The input signal's name (the loop's error, or ``w`` for a broken loop).
    out : str
        The output signal's name.
    scale : float
        A factor on the output (the ratio i_r: an axis-rate reference to a motor-speed one).
    name : str, optional
        The block's system name.
    """
    return control.ss(
        [[0.0]],
        [[1.0]],
        [[scale * ki]],
        [[scale * kp]],
        inputs=[inp],
        outputs=[out],
        states=["integral"],
        name=name,
    )


def cascade_system(
    ap: AxisPlant, gains: CascadeGains, open_loop: str | None = None
) -> control.StateSpace:
    """The cascade around the plant, closed, or broken at one loop's error.

    Blocks: position PI on ``e_p = reference − axis_angle`` giving the motor-speed
    reference ``i_r·(rate reference)``; rate PI on ``e_v = speed_ref − motor_speed``
    giving ``current_ref``; current PI on ``e_i = current_ref − current`` giving the
    armature ``voltage`` (:class:`rt70.control.servo.ServoDrive` without its clamps).

    Parameters
    ----------
    ap : AxisPlant
        The plant (for the RT-70: :func:`rt70.reports.servo_loops.axis_plant`).
    gains : CascadeGains
        The loops' gains (:func:`cascade_design`).
    open_loop : {"position", "rate", "current"} or None
        Break this loop at its error: its PI reads the external input ``w`` instead of
        its error, and the error is an output.

    Returns
    -------
    control.StateSpace
        Inputs ``reference`` (rad), ``wind_torque`` (N·m), and ``w`` if a loop is open;
        outputs ``axis_angle``, :data:`~rt70.control.axis_plant.POINTING`, ``voltage``, ``current``,
        ``motor_speed``, ``e_p``, ``e_v``, ``e_i``.
    """
    if open_loop is not None and open_loop not in LOOPS:
        raise Rt70Error(f"unknown loop '{open_loop}' (one of {', '.join(LOOPS)})")
    g = gains

    def err(loop: str, name: str) -> str:
        return "w" if open_loop == loop else name

    blocks = [
        ap.system,
        control.summing_junction(["reference", "-axis_angle"], "e_p"),
        pi_block(g.kp_p, g.ki_p, err("position", "e_p"), "speed_ref", ap.parameters.i_r),
        control.summing_junction(["speed_ref", "-motor_speed"], "e_v"),
        pi_block(g.kp_v, g.ki_v, err("rate", "e_v"), "current_ref"),
        control.summing_junction(["current_ref", "-current"], "e_i"),
        pi_block(g.kp_i, g.ki_i, err("current", "e_i"), "voltage"),
    ]
    inputs = ["reference", "wind_torque"] + (["w"] if open_loop else [])
    outputs = ["axis_angle", *POINTING, "voltage", "current", "motor_speed", "e_p", "e_v", "e_i"]
    return control.interconnect(
        blocks, inplist=inputs, outlist=outputs, inputs=inputs, outputs=outputs, check_unused=False
    )


def loop_transfer(ap: AxisPlant, gains: CascadeGains, loop: str) -> control.StateSpace:
    """The loop transfer ``L = −e/w`` of one loop broken at its error, the others closed.

    With ``e = reference − feedback`` the loop closes as ``e = r − L e``: margins and
    crossovers are those of ``L`` (python-control's sign convention, negative feedback).

    Parameters
    ----------
    ap : AxisPlant
        The plant of one axis at one pointing (structure and drive).
    gains : CascadeGains
        The loops' gains.
    loop : {"position", "rate", "current"}
        The loop broken at its error.
    """
    sys = cascade_system(ap, gains, loop)
    e = {"position": "e_p", "rate": "e_v", "current": "e_i"}[loop]
    return -sys[e, "w"]


@dataclass(frozen=True)
class CascadeResult:
    """The cascade around one plant: gains, margins of each loop, closed-loop bandwidth."""

    gains: CascadeGains
    position_hz: float
    margins: dict[str, Margins]
    bandwidth_hz: float
    stable: bool

    @property
    def adequate(self) -> bool:
        """Stable, and every loop with adequate margins."""
        return self.stable and all(m.adequate for m in self.margins.values())


def cascade_design(ap: AxisPlant, position_hz: float, ratio: float = 5.0) -> CascadeGains:
    """:func:`rt70.control.servo.cascade_gains` for this plant's drive and rigid load inertia.

    Parameters
    ----------
    ap : AxisPlant
        The plant of one axis at one pointing (structure and drive).
    position_hz : float
        The design position-loop bandwidth, Hz.
    ratio : float
        Bandwidth ratio between a loop and the one inside it.
    """
    return cascade_gains(ap.parameters, ap.load_inertia, position_hz=position_hz, ratio=ratio)


def analyse_cascade(ap: AxisPlant, position_hz: float, ratio: float = 5.0) -> CascadeResult:
    """Margins of the three loops and the bandwidth reference → axis angle.

    Parameters
    ----------
    ap : AxisPlant
        The plant of one axis at one pointing (structure and drive).
    position_hz : float
        The design position-loop bandwidth, Hz.
    ratio : float
        Bandwidth ratio between a loop and the one inside it.
    """
    gains = cascade_design(ap, position_hz, ratio)
    closed = cascade_system(ap, gains)
    return CascadeResult(
        gains,
        position_hz,
        {loop: margins(loop_transfer(ap, gains, loop)) for loop in LOOPS},
        bandwidth_hz(closed["axis_angle", "reference"]),
        stable(closed),
    )


def reachable_position_hz(
    plants: list[AxisPlant],
    low: float = 0.02,
    high: float = 1.0,
    ratio: float = 5.0,
    steps: int = 12,
) -> float:
    """Largest design position bandwidth with adequate margins on every plant (bisection).

    Assumes adequacy is lost once as the design bandwidth rises (checked at ``low``);
    returns ``high`` if it is adequate there.

    Parameters
    ----------
    plants : list of AxisPlant
        The plants (e.g. one per pointing) the design must hold on.
    low, high : float
        The bracket of the design position bandwidth, Hz (adequate at ``low``).
    ratio : float
        Bandwidth ratio between a loop and the one inside it.
    steps : int
        Bisection steps (in log frequency).
    """

    def ok(hz: float) -> bool:
        return all(analyse_cascade(ap, hz, ratio).adequate for ap in plants)

    if not ok(low):
        raise Rt70Error(f"the PI cascade is not adequate even at {low} Hz")
    if ok(high):
        return high
    for _ in range(steps):
        mid = np.sqrt(low * high)
        low, high = (mid, high) if ok(mid) else (low, mid)
    return float(low)
