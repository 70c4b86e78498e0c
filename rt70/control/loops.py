"""A DC drive closed around a linear structure, and the PI cascade in frequency analysis.

One job: the linear servo plant of one axis and the current–rate–position cascade
(:mod:`rt70.control.servo`) closed around it as linear blocks, with the Bode data and margins a
servo engineer reads. The RT-70's axes, drives and pointings are chosen in
:mod:`rt70.reports.servo_loops`; nothing here knows the telescope.

The plant of one axis (:class:`AxisPlant`) joins two linear models by python-control's
``interconnect`` (:func:`connect_drive`):

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

The cascade (:func:`cascade_system`) is linear: the limits and the anti-windup of
:class:`rt70.control.servo.ServoDrive` act only in saturation and are not part of a frequency
analysis. Each loop is broken at its error (:func:`loop_transfer`) with the other two
closed; margins come from python-control's ``stability_margins`` on the frequency
response (an ``FRD`` on :data:`FREQ_HZ`): never a transfer-function conversion of this
high-order, lightly damped plant (see :mod:`rt70.linear.plant`).
"""

from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np
import scipy.linalg

from rt70.bondgraph.parameters import DriveParameters
from rt70.control.servo import CascadeGains, cascade_gains
from rt70.errors import Rt70Error
from rt70.linear.plant import CoordinateInput, CoordinateOutput, LoadInput, plant, to_control
from rt70.model.outputs import Output
from rt70.model.scene import Scene
from rt70.physics.loads import Wrench

#: Frequencies of the margins and bandwidths, Hz: 200 points per decade, a step of 1.2 %,
#: a third of the half-power width 2ζ of the plant's least damped resonance (ζ ≈ 0.03).
FREQ_HZ = np.logspace(-3, 2, 1001)
#: Names of the pointing outputs: Δα, Δβ of (4.159)–(4.163), arc seconds.
POINTING = ("pointing_da", "pointing_db")
#: The cascade's errors, outermost first, and the signals each loop feeds back.
LOOPS = ("position", "rate", "current")
#: Adequate margins (antenna practice): gain margin, dB, and phase margin, degrees.
MIN_GM_DB = 6.0
MIN_PM_DEG = 30.0


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
    n = ss.n_states // 2
    k = list(ss.state_names).index(coordinate)
    rate = np.zeros((1, 2 * n))
    rate[0, n + k] = 1.0
    sys = to_control(ss)
    C = np.vstack([sys.C[:1], rate, sys.C[1:]])
    D = np.vstack([sys.D[:1], np.zeros((1, 2)), sys.D[1:]])
    load_inertia = float(ss.second_order.M[k, k]) if ss.second_order is not None else np.nan
    structure = control.ss(
        sys.A,
        sys.B,
        C,
        D,
        states=list(ss.state_names),
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


# ------------------------------------------------------------------------ the PI cascade


def pi_block(
    kp: float, ki: float, inp: str, out: str, scale: float = 1.0, name: str | None = None
) -> control.StateSpace:
    """``out = scale (kp e + ki ∫e)``: a PI controller as a state space (state ``integral``)."""
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
        outputs ``axis_angle``, :data:`POINTING`, ``voltage``, ``current``,
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
    """
    sys = cascade_system(ap, gains, loop)
    e = {"position": "e_p", "rate": "e_v", "current": "e_i"}[loop]
    return -sys[e, "w"]


def frequency_response(sys: control.StateSpace, freq_hz: np.ndarray = FREQ_HZ) -> np.ndarray:
    """Complex frequency response of a SISO state space at ``freq_hz`` (no TF conversion).

    ``C (jω − A)⁻¹ B + D`` through the complex Schur form ``A = Z T Zᴴ`` (backward
    stable, like python-control's per-frequency LU solve, but one triangular solve of
    O(n²) a frequency instead of a factorisation of O(n³)).
    """
    f = np.asarray(freq_hz, dtype=float)
    T, Z = scipy.linalg.schur(sys.A.astype(complex), output="complex")
    b = Z.conj().T @ sys.B[:, 0]
    c = sys.C[0] @ Z
    eye = np.eye(T.shape[0])
    H = np.empty(f.size, dtype=complex)
    for k, fk in enumerate(f):
        H[k] = c @ scipy.linalg.solve_triangular(2j * np.pi * fk * eye - T, b)
    return H + sys.D[0, 0]


@dataclass(frozen=True)
class Margins:
    """Gain and phase margins of a loop and where they are, from its frequency response.

    Attributes
    ----------
    gm_db : float
        Gain (increase) margin, dB: the least ``1/|L|`` over the phase crossovers where
        ``|L| < 1`` (inf if there is none).
    gm_down_db : float
        Gain-reduction margin, dB (negative): the largest ``1/|L|`` over the phase
        crossovers where ``|L| > 1`` — a nested loop broken inside a closed outer loop
        is conditionally stable (−inf if there is none).
    pm_deg : float
        Phase margin, degrees: the least phase distance ``180° − |∠L|`` of a gain
        crossover from −1.
    f_gc_hz : float
        The gain crossover with the least phase margin, Hz (NaN if none).
    f_pc_hz : float
        The phase crossover of ``gm_db``, Hz (NaN if none).
    """

    gm_db: float
    gm_down_db: float
    pm_deg: float
    f_gc_hz: float
    f_pc_hz: float

    @property
    def adequate(self) -> bool:
        """Both gain margins at least :data:`MIN_GM_DB`, PM at least :data:`MIN_PM_DEG`."""
        return bool(
            self.gm_db >= MIN_GM_DB and self.gm_down_db <= -MIN_GM_DB and self.pm_deg >= MIN_PM_DEG
        )


def margins(L: control.StateSpace, freq_hz: np.ndarray = FREQ_HZ) -> Margins:
    """Margins of the loop ``L``: python-control's ``stability_margins`` on its ``FRD``."""
    frd = control.frd(frequency_response(L, freq_hz), 2 * np.pi * freq_hz)
    gm, pm, _, w_pc, w_gc, _ = (np.atleast_1d(x) for x in control.stability_margins(frd, True))
    up, down = gm > 1.0, gm < 1.0
    gm_db = float(20 * np.log10(gm[up].min())) if up.any() else np.inf
    f_pc = float(w_pc[up][np.argmin(gm[up])]) / (2 * np.pi) if up.any() else np.nan
    gm_down_db = float(20 * np.log10(gm[down].max())) if down.any() else -np.inf
    if pm.size == 0:
        return Margins(gm_db, gm_down_db, np.inf, np.nan, f_pc)
    # python-control's pm is ∠L + 180° folded to (−180°, 180°]; the phase distance of a
    # gain crossover from −1 is 180° − |∠L| with ∠L in (−180°, 180°] (stability itself is
    # checked on the closed loop's poles)
    angle = pm % 360.0 - 180.0  # ∠L in [−180°, 180°)
    distance = 180.0 - np.abs(angle)
    k = int(np.argmin(distance))
    return Margins(gm_db, gm_down_db, float(distance[k]), float(w_gc[k]) / (2 * np.pi), f_pc)


def bandwidth_hz(T: control.StateSpace, freq_hz: np.ndarray = FREQ_HZ) -> float:
    """First frequency where ``|T|`` falls 3 dB below its low-frequency gain, Hz.

    Linear interpolation in log frequency between the grid points around the crossing;
    NaN if it never falls.
    """
    mag_db = 20 * np.log10(np.abs(frequency_response(T, freq_hz)))
    below = np.flatnonzero(mag_db < mag_db[0] - 3.0)
    if below.size == 0:
        return np.nan
    i = int(below[0])
    level = mag_db[0] - 3.0
    x0, x1 = np.log10(freq_hz[i - 1]), np.log10(freq_hz[i])
    t = (mag_db[i - 1] - level) / (mag_db[i - 1] - mag_db[i])
    return float(10 ** (x0 + t * (x1 - x0)))


def stable(sys: control.StateSpace) -> bool:
    """All poles strictly in the left half-plane."""
    return bool(np.all(np.real(control.poles(sys)) < 0.0))


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
    """:func:`rt70.control.servo.cascade_gains` for this plant's drive and rigid load inertia."""
    return cascade_gains(ap.parameters, ap.load_inertia, position_hz=position_hz, ratio=ratio)


def analyse_cascade(ap: AxisPlant, position_hz: float, ratio: float = 5.0) -> CascadeResult:
    """Margins of the three loops and the bandwidth reference → axis angle."""
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
