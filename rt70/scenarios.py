"""Servo scenarios of the RT-70: hold, 1° steps and sidereal tracking, closed on the model.

One job: run the telescope with its drives closed around the nonlinear model
(:func:`rt70.simulate.simulate` with :class:`rt70.servo.ServoDrive` components on the
pointing axes ``platform_rz`` = azimuth and ``base_rx`` = π/2 − elevation) and measure
what a servo engineer asks of it: settling time to 1″, overshoot, peak motor torque
against its limit, pointing error in arc seconds and the tracking error after settling
(issue 10, item 6 and the simulation half of item 4).

The run starts at rest in the static equilibrium of the pointing with the drives holding
(:func:`rt70.linear.linearize.equilibrium`): the motors' states hold the gravity torque
(:meth:`rt70.drives.DcDrive.holding`) and the cascade's integrators are preset to the
current and voltage that hold it, so a hold has no start-up transient.

The drives are built by a *drive factory* (:data:`DriveFactory`): the default,
:func:`servo_drives`, puts one :class:`~rt70.servo.ServoDrive` (with
back-calculation anti-windup, :class:`rt70.antiwindup.BackCalculationServo`) per axis on the
coordinates with the parameters of :mod:`rt70.scenes.rt70_drives` (the two motors of an
axis lumped, see :func:`drive_parameters`). Another factory (drives with friction and
backlash, or acting through the gear sector) is passed to :func:`run_scenario` in its
place; the measurements use only the trajectory, the axis coordinates and, where a
component has them, its ``reducer_torque`` and motor current.

Pointing error: the main mirror's focal axis ``n5`` (from its focus and vertex, (4.155),
ground axes) against the axis the structure has in static equilibrium at the
*reference* pointing — the source direction (4.153) less the gravity sag, which a
pointing model calibrates (:attr:`ScenarioRun.static_misalignment` reports it, (4.157)).
Its two components are the cross-elevation and elevation errors (:func:`sky_error`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from rt70.antiwindup import BackCalculationServo
from rt70.bondgraph.parameters import DriveParameters
from rt70.errors import Rt70Error
from rt70.geartrains import equivalent_drive
from rt70.linear.linearize import equilibrium, static_force
from rt70.outputs import Output, evaluate
from rt70.resources import check_time_series
from rt70.scene import Scene
from rt70.scenes.rt70_drives import ARCSEC, AZIMUTH_DRIVE, ELEVATION_DRIVE, AxisDrive
from rt70.scenes.rt70_optics import rt70_mirror_outputs, rt70_mirror_system
from rt70.scenes.rt70_state import (
    AZIMUTH_COORDINATE,
    ELEVATION_COORDINATE,
    POINTING_AXES,
    missing_axes,
    rt70_pointing,
)
from rt70.servo import CascadeGains, ServoDrive, cascade_gains
from rt70.servo_metrics import (  # noqa: F401  (re-exported: the scenario's numbers)
    BAND_ARCSEC,
    measure,
    predicted_settling,
    settling_time,
    summary_lines,
)
from rt70.simulate import SimulationResult, sample_channels, simulate
from rt70.states import StateComponent

#: The scenarios by name (``rt70 simulate --scenario``).
SCENARIOS = ("hold", "step-azimuth", "step-elevation", "track")
#: Sidereal tracking rate used by the ``track`` scenario, arc seconds per second (15″/s).
SIDEREAL_ARCSEC_PER_S = 15.0
#: Size of the step scenarios, degrees.
STEP_DEG = 1.0
#: Default length of each scenario, s.
DEFAULT_T_END = {"hold": 60.0, "step-azimuth": 40.0, "step-elevation": 25.0, "track": 40.0}
#: Position-loop bandwidths (Hz) and the ratio between nested loops chosen for the
#: RT-70 (see docs/servo-scenarios.md): the azimuth loops sit below the 0.92 Hz
#: locked-rotor resonance, the elevation loops below its 2.77 Hz one.
AXIS_TUNING = {"azimuth": (0.2, 5.0), "elevation": (0.5, 5.0)}
#: Start elevation of the scenarios when none is given, degrees.
DEFAULT_ELEVATION = 45.0
#: Force tolerance of the static equilibria (relative): rt70_servo's Newton residual
#: stalls at its rounding floor, 1.2e-10 at elevation 30° (above equilibrium's default
#: 1e-10); 1e-9 of the ~1e7 N·m gravity torque is 0.01 N·m, nothing to the pointing.
EQUILIBRIUM_TOL = 1e-9
#: Integration method of the scenarios (see :func:`run_scenario`).
METHOD = "LSODA"
#: Output name of the main mirror's focal axis in ground axes.
MIRROR_AXIS = "main_mirror_direction"

#: A reference of one axis: offset from the start pointing, degrees, as a function of t.
Reference = Callable[[float], float]
#: Builds the drive components: (scene, q0, held torques by coordinate, references in
#: coordinate radians by coordinate) -> components.
DriveFactory = Callable[
    [Scene, np.ndarray, dict[str, float], dict[str, Callable[[float], float]]],
    list[StateComponent],
]


def drive_parameters(axis: AxisDrive) -> DriveParameters:
    """One :class:`DcDrive`'s parameters for an axis's motors, lumped.

    The axis's ``n`` identical motors turn the same gear at the same speed; taken with
    their armatures in series (one current), they are one motor with ``n`` times the
    inductance, resistance, torque and back-EMF constants, rotor inertia and viscous
    friction (the time constants L_a/R_a and J_m R_a/(c_m c_e) are unchanged). The
    counter-torque between the two gear trains is not modelled here (a factory with the
    gear trains takes its place). ``J_l`` is the table's reference inertia of the axis.
    """
    p = axis.motor_parameters(axis.reference_inertia)
    return equivalent_drive(p, axis.motors_per_axis)


def axis_gains(axis: AxisDrive, position_hz: float, ratio: float) -> CascadeGains:
    """The cascade of one axis with the table's limits (:func:`rt70.servo.cascade_gains`).

    Current reference clamped to the peak torque (2 I_n per motor), axis rate to the
    table's rate limit, armature voltage to the motors' rated voltage (n U_n lumped).
    """
    p = drive_parameters(axis)
    return cascade_gains(
        p,
        axis.reference_inertia,
        position_hz=position_hz,
        ratio=ratio,
        current_limit=axis.motor.peak_torque / axis.motor.torque_constant,
        rate_limit=axis.servo.rate_limit,
        voltage_limit=axis.motors_per_axis * axis.motor.rated_voltage,
    )


def preset_servo_state(p: DriveParameters, gains: CascadeGains, angle: float, torque: float):
    """States of a :class:`ServoDrive` holding ``torque`` at ``angle`` at rest, loops settled.

    ``[I, α_m, ω_m]`` of :meth:`DcDrive.holding`, the position integral 0 (no rate
    asked), the rate integral giving the holding current ``I = K_i,v ∫e_v`` and the
    current integral the voltage ``R_a I = K_i,i ∫e_i``.
    """
    hold = ServoDrive.holding(p, angle, torque)
    return np.concatenate([hold, [0.0, hold[0] / gains.ki_v, p.R_a * hold[0] / gains.ki_i]])


def servo_tolerances(p: DriveParameters, axis_atol: float = 1e-9) -> np.ndarray:
    """Absolute tolerances of a ServoDrive's states matching ``axis_atol`` on its axis.

    Motor-side angles and speeds (and the rate integral) are ``i_r`` times the axis's,
    so their tolerance is ``i_r · axis_atol``; currents (and the current integral) get
    ``axis_atol · C_r / (c_m i_r)`` — the current whose torque twists the reducer by
    ``axis_atol``. The drive's default 1e-9 on every state asks the motor angle for
    1e-14 rad on the axis, below the rounding of the axis angle: at the zenith, where
    the motor angle is near zero and the relative tolerance does not help, BDF's step
    collapsed ("Required step size is less than spacing between numbers", 60 s hold at
    90°).
    """
    motor = p.i_r * axis_atol
    amp = axis_atol * p.C_r / (p.c_m * p.i_r)
    return np.array([amp, motor, motor, axis_atol, motor, amp])


def servo_drives(tuning: dict[str, tuple[float, float]] | None = None) -> DriveFactory:
    """The default factory: one ServoDrive per axis, on the coordinates, holding at start.

    Parameters
    ----------
    tuning : dict, optional
        ``{"azimuth": (position_hz, ratio), "elevation": (...)}``; default
        :data:`AXIS_TUNING`.
    """
    tuning = {**AXIS_TUNING, **(tuning or {})}

    def build(scene, q0, torques, references):
        names = scene.coordinate_names
        out: list[StateComponent] = []
        for coordinate, axis in (
            (AZIMUTH_COORDINATE, AZIMUTH_DRIVE),
            (ELEVATION_COORDINATE, ELEVATION_DRIVE),
        ):
            p = drive_parameters(axis)
            gains = axis_gains(axis, *tuning[axis.name])
            k = names.index(coordinate)
            initial = preset_servo_state(p, gains, q0[k], torques[coordinate])
            ref = references[coordinate]
            atol = servo_tolerances(p)
            out.append(
                BackCalculationServo(axis.name, names, coordinate, p, gains, ref, initial, atol)
            )
        return out

    return build


def tuning_text(tuning: dict[str, tuple[float, float]] | None = None) -> str:
    """The position-loop bandwidths in one phrase, e.g. ``position loops az 0.2 Hz, el 0.5 Hz``."""
    t = {**AXIS_TUNING, **(tuning or {})}
    return f"position loops az {t['azimuth'][0]:g} Hz, el {t['elevation'][0]:g} Hz"


def holding_excess(scene: Scene, elevation_deg: float, azimuth_deg: float = 0.0) -> str | None:
    """Why the drives cannot hold ``scene`` at a pointing, or None if they can.

    The static torque the drives must supply on each axis at the equilibrium of the
    pointing, against the table's nominal (continuous) drive torque. The RT-70 listing
    as printed needs 2.66× it on elevation at the horizon (docs/rt70-errata.md item 12).
    """
    held = rt70_pointing(elevation_deg, azimuth_deg)
    q0 = equilibrium(scene, held, tol=EQUILIBRIUM_TOL)
    Q0 = static_force(scene, q0)
    names = scene.coordinate_names
    for coordinate, axis in (
        (AZIMUTH_COORDINATE, AZIMUTH_DRIVE),
        (ELEVATION_COORDINATE, ELEVATION_DRIVE),
    ):
        torque = abs(float(Q0[names.index(coordinate)]))
        if torque > axis.nominal_torque:
            return (
                f"gravity torque {torque:.3g} N·m on {axis.name} at elevation {elevation_deg:g}° "
                f"exceeds the drive's nominal {axis.nominal_torque:.3g} N·m "
                "(docs/rt70-errata.md item 12)"
            )
    return None


@dataclass(frozen=True)
class Scenario:
    """What the axes are asked to do: offsets from the start pointing, degrees.

    Attributes
    ----------
    name : str
        One of :data:`SCENARIOS`.
    elevation_deg, azimuth_deg : float
        The start pointing.
    t_end : float
        Length of the run, s.
    azimuth : Reference
        Azimuth offset (degrees) as a function of t; likewise ``elevation``.
    step_deg : (float, float)
        The step on (azimuth, elevation), degrees (zero for hold and track).
    rate_arcsec_s : float
        Tracking rate in azimuth (0 but for track).
    """

    name: str
    elevation_deg: float
    azimuth_deg: float
    t_end: float
    azimuth: Reference
    elevation: Reference
    step_deg: tuple[float, float] = (0.0, 0.0)
    rate_arcsec_s: float = 0.0


def scenario(
    name: str, elevation_deg: float = 45.0, azimuth_deg: float = 0.0, t_end: float | None = None
) -> Scenario:
    """A scenario by name (:data:`SCENARIOS`) at a start pointing.

    ``step-elevation`` steps up by 1° (down at 90°: the zenith is the top of the range);
    ``track`` follows a source moving at 15″/s in azimuth, from rest (the loops acquire
    it); the steps are commanded at t = 0 (the reference holds its new value from the
    start).
    """
    if name not in SCENARIOS:
        raise Rt70Error(f"unknown scenario '{name}' (choose from {', '.join(SCENARIOS)})")
    if not 0.0 <= elevation_deg <= 90.0:
        raise Rt70Error(f"elevation must lie in [0, 90] degrees, got {elevation_deg!r}")
    t_end = DEFAULT_T_END[name] if t_end is None else float(t_end)
    if not (np.isfinite(t_end) and t_end > 0.0):
        raise Rt70Error(f"scenario length must be positive, got {t_end!r}")
    zero: Reference = lambda t: 0.0  # noqa: E731
    step_el = STEP_DEG if elevation_deg + STEP_DEG <= 90.0 else -STEP_DEG
    common = dict(name=name, elevation_deg=elevation_deg, azimuth_deg=azimuth_deg, t_end=t_end)
    if name == "hold":
        return Scenario(**common, azimuth=zero, elevation=zero)
    if name == "step-azimuth":
        return Scenario(
            **common, azimuth=lambda t: STEP_DEG, elevation=zero, step_deg=(STEP_DEG, 0.0)
        )
    if name == "step-elevation":
        return Scenario(
            **common, azimuth=zero, elevation=lambda t: step_el, step_deg=(0.0, step_el)
        )
    rate = SIDEREAL_ARCSEC_PER_S
    return Scenario(
        **common, azimuth=lambda t: rate * t / 3600.0, elevation=zero, rate_arcsec_s=rate
    )


def choose(
    scene: Scene,
    name: str | None,
    elevation_deg: float | None,
    azimuth_deg: float | None,
    t_end: float | None,
) -> tuple[Scenario | None, str | None]:
    """The scenario ``rt70 simulate`` runs on a scene, or None and why (a hint to print).

    A scene with the RT-70 axes whose drives can hold it down to the horizon runs
    ``name`` (default ``hold``) at the pointing (default elevation
    :data:`DEFAULT_ELEVATION`); one they cannot hold (the listing as printed, errata 12)
    runs the structural benchmark with a hint, or is refused if a scenario or a pointing
    was asked for; a scene without the axes runs the structural benchmark.

    Raises
    ------
    Rt70Error
        A scenario or pointing asked of a scene without the axes, or one the drives
        cannot hold at that pointing.
    """
    asked = name is not None or elevation_deg is not None or azimuth_deg is not None
    if missing_axes(scene.coordinate_names):
        if asked:
            raise Rt70Error(
                f"{scene.name}: --scenario/--elevation/--azimuth need the RT-70 pointing axes "
                f"({', '.join(POINTING_AXES)})"
            )
        return None, None
    elevation = DEFAULT_ELEVATION if elevation_deg is None else elevation_deg
    azimuth = azimuth_deg or 0.0
    excess = holding_excess(scene, elevation if asked else 0.0, azimuth)
    if excess is not None:
        if asked:
            raise Rt70Error(f"{scene.name}: {excess}")
        return None, (
            f"the drives cannot hold it ({excess}): running the structural benchmark with "
            "the axes free; 'rt70 simulate rt70_servo' runs the telescope held by its servo"
        )
    return scenario(name or "hold", elevation, azimuth, t_end), None


def mirror_axis_output(scene: Scene) -> Output:
    """The main mirror's focal axis ``(r5f − r5v)/|r5f − r5v|`` in ground axes (4.155)."""
    system = rt70_mirror_system(scene)

    def formula(p: np.ndarray) -> np.ndarray:
        d = p[0] - p[1]
        return d / np.linalg.norm(d)

    return Output(MIRROR_AXIS, "1", 3, (system.main_focus, system.main_vertex), formula)


def elevation_azimuth(axis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Elevation E and azimuth A (rad) of mirror-axis directions (rows).

    The inverse of the pointing's axis ``Rz(A) (0, −cos E, sin E)``
    (:func:`rt70.scenes.rt70_state.rt70_pointing`).
    """
    axis = np.atleast_2d(axis)
    return np.arcsin(np.clip(axis[:, 2], -1.0, 1.0)), np.arctan2(axis[:, 0], -axis[:, 1])


def sky_error(axis: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Cross-elevation and elevation error (arcsec) of mirror axes against targets (rows).

    ``[(A − A_t) cos E_t, E − E_t]``: what the encoders of an elevation-over-azimuth
    mount see on the sky (a move in azimuth alone has no elevation error, unlike a
    projection of the chord ``axis − target``, whose second-order term is 15″ at 1°).
    """
    e, a = elevation_azimuth(axis)
    e_t, a_t = elevation_azimuth(target)
    da = (a - a_t + np.pi) % (2 * np.pi) - np.pi
    return np.column_stack([da * np.cos(e_t), e - e_t]) / ARCSEC


@dataclass
class ScenarioRun:
    """A scenario's simulation and what was measured on it.

    Angles in arc seconds, torques in N·m (axis side), times in s. ``axis_error`` is the
    reference minus the axis angle (the encoder's error) per axis; ``pointing_error`` the
    mirror axis against the target axis, (n_t, 2): cross-elevation, elevation;
    ``pointing_error_total`` its angle. ``metrics`` holds the numbers of the summary.
    """

    scenario: Scenario
    result: SimulationResult
    axis_reference: dict[str, np.ndarray]
    axis_error: dict[str, np.ndarray]
    axis_torque: dict[str, np.ndarray]
    torque_limits: dict[str, tuple[float, float]]
    motor_current: dict[str, np.ndarray]
    pointing_error: np.ndarray
    pointing_error_total: np.ndarray
    static_misalignment: float
    holding_torque: dict[str, float]
    components: list[StateComponent] = field(default_factory=list)
    metrics: dict[str, float] = field(default_factory=dict)


def run_scenario(
    scene: Scene,
    sc: Scenario,
    drives: DriveFactory | None = None,
    rtol: float = 1e-6,
    samples_per_s: float = 20.0,
    backend: str = "pinocchio",
    method: str | None = None,
    progress: bool = False,
) -> ScenarioRun:
    """Simulate a scenario with the drives closed on the structure, and measure it.

    Parameters
    ----------
    scene : Scene
        A scene with the RT-70's pointing axes and main-mirror optical points
        (``rt70_servo``: the listing with its counterweight below the elevation axis).
    sc : Scenario
        From :func:`scenario`.
    drives : DriveFactory, optional
        Builds the drive components; default :func:`servo_drives`. A factory with a
        ``start(scene, held)`` method returns the start state and the holding torques
        itself (``(q0, {coordinate: torque})``, e.g. the equilibrium with a gear
        sector's force, :mod:`rt70.scene_servo`); otherwise the start is the
        equilibrium with the axes held by torques on their coordinates.
    rtol, backend, progress
        As :func:`rt70.simulate.simulate`.
    method : str, optional
        The integration method; default :data:`METHOD` (LSODA). scipy's BDF and Radau
        stop at random on a hold ("Required step size is less than spacing between
        numbers": measured at 30° and 90°, 60 s): at rest every Newton correction is
        rounding noise, their ratio reaches 1 and the iteration is declared diverging at
        any step size; LSODA's own test does not (60 s hold at 30°: 3.9e-7″, 17 s wall).
    samples_per_s : float
        Output samples per second of simulated time.
    """
    names = scene.coordinate_names
    missing = missing_axes(names)
    if missing:
        raise Rt70Error(f"{scene.name}: no RT-70 pointing axis '{missing[0]}': no servo scenario")
    drives = servo_drives() if drives is None else drives
    ia, ie = names.index(AZIMUTH_COORDINATE), names.index(ELEVATION_COORDINATE)
    held = rt70_pointing(sc.elevation_deg, sc.azimuth_deg)
    start = getattr(drives, "start", None)
    if start is None:
        q0 = equilibrium(scene, held, tol=EQUILIBRIUM_TOL)
        Q0 = static_force(scene, q0)
        torques = {c: -float(Q0[names.index(c)]) for c in held}  # what the drives supply
    else:  # a factory whose drives do not push on the coordinates alone
        q0, torques = start(scene, held)
    # references in coordinate radians: platform_rz = A, base_rx = π/2 − E
    a0, e0 = q0[ia], q0[ie]
    refs = {
        AZIMUTH_COORDINATE: lambda t: a0 + np.radians(sc.azimuth(t)),
        ELEVATION_COORDINATE: lambda t: e0 - np.radians(sc.elevation(t)),
    }
    components = drives(scene, q0, torques, refs)
    if sc.t_end * samples_per_s < 1.0:
        raise Rt70Error(
            f"{scene.name}: --t-end {sc.t_end:g}: a scenario is measured on samples every "
            f"{1 / samples_per_s:g} s; it must last at least that long"
        )
    n_t = np.ceil(sc.t_end * samples_per_s) + 1
    check_time_series(
        n_t,
        sample_channels(
            len(names), 2 + sum(len(c.names) for c in components), [mirror_axis_output(scene)]
        ),
        f"scenario '{sc.name}' sampled {samples_per_s:g} times a second",
        f"{scene.name}: --t-end {sc.t_end:g}",
    )
    n_t = int(n_t)
    t_eval = np.linspace(0.0, sc.t_end, n_t)
    result = simulate(
        scene,
        (0.0, sc.t_end),
        (q0, np.zeros(scene.textbook.nv)),
        backend=backend,
        method=METHOD if method is None else method,
        rtol=rtol,
        t_eval=t_eval,
        outputs=[mirror_axis_output(scene)],
        components=components,
        progress=progress,
    )
    if not result.success:
        raise Rt70Error(f"{scene.name}: scenario '{sc.name}': {result.message}")
    t = result.t
    reference = {
        "azimuth": np.array([refs[AZIMUTH_COORDINATE](x) for x in t]),
        "elevation": np.array([refs[ELEVATION_COORDINATE](x) for x in t]),
    }
    error = {
        "azimuth": (reference["azimuth"] - result.q[:, ia]) / ARCSEC,
        # elevation = π/2 − base_rx: its error is the coordinate's with the sign turned
        "elevation": -(reference["elevation"] - result.q[:, ie]) / ARCSEC,
    }
    e_ref = sc.elevation_deg + np.array([sc.elevation(x) for x in t])
    a_ref = sc.azimuth_deg + np.array([sc.azimuth(x) for x in t])
    rest = None if start is None else (lambda held: start(scene, held)[0])
    target = _target_axes(scene, q0, t, e_ref, a_ref, rest)
    n = result.outputs[MIRROR_AXIS]
    pointing = sky_error(n, target)
    cosang = np.clip((n * target).sum(1), -1.0, 1.0)
    total = np.arctan2(np.linalg.norm(np.cross(n, target), axis=1), cosang) / ARCSEC
    torque, current, limits = _drive_torques(components, result, names)
    static = _static_misalignment(scene, q0, sc)
    run = ScenarioRun(
        sc,
        result,
        reference,
        error,
        torque,
        limits,
        current,
        pointing,
        total,
        static,
        torques,
        list(components),
    )
    run.metrics = measure(run)
    return run


def _target_axes(scene, q0, t, e_ref, a_ref, rest=None) -> np.ndarray:
    """The main mirror's axis in equilibrium at the reference pointing, per sample.

    Equilibria at the distinct reference pointings of a few knots (first, last, and
    where the reference changes), linearly interpolated in between and normalised.
    ``rest(held)`` gives the equilibrium when the drive factory has its own start (the
    drives' forces in it); default the axes held by torques on their coordinates.
    """
    out = mirror_axis_output(scene)
    knots = np.unique(np.r_[0, np.linspace(0, len(t) - 1, 5).astype(int), len(t) - 1])
    cache: dict[tuple[float, float], np.ndarray] = {}
    axes = []
    for k in knots:
        key = (round(float(e_ref[k]), 12), round(float(a_ref[k]), 12))
        if key not in cache:
            held = rt70_pointing(*key)
            q = equilibrium(scene, held, tol=EQUILIBRIUM_TOL) if rest is None else rest(held)
            cache[key] = evaluate(scene, q, [out], "reference")[MIRROR_AXIS]
        axes.append(cache[key])
    axes = np.array(axes)
    # between knots, a step reference is constant after t = 0: interpolation is exact
    target = np.column_stack([np.interp(np.arange(len(t)), knots, axes[:, i]) for i in range(3)])
    return target / np.linalg.norm(target, axis=1, keepdims=True)


def _static_misalignment(scene: Scene, q0: np.ndarray, sc: Scenario) -> float:
    """(4.157) of the main mirror at the start equilibrium: the gravity sag, arc seconds."""
    outs = [o for o in rt70_mirror_outputs(scene, sc.elevation_deg, sc.azimuth_deg)]
    outs = [o for o in outs if o.name == "main_mirror_misalignment"]
    return float(evaluate(scene, q0, outs, "reference")["main_mirror_misalignment"][0])


def _drive_torques(components: Sequence[StateComponent], result, names):
    """Axis-side reducer torque and motor current of each drive that has them."""
    torque, current, limits = {}, {}, {}
    for c in components:
        if not hasattr(c, "reducer_torque"):
            continue
        axis = c.names[0].split(":")[0]
        s = np.column_stack([result.states[n] for n in c.names])
        torque[axis] = np.array(
            [c.reducer_torque(q, qd, x) for q, qd, x in zip(result.q, result.qd, s, strict=True)]
        )
        current[axis] = s[:, 0]
        table = AZIMUTH_DRIVE if c.index == names.index(AZIMUTH_COORDINATE) else ELEVATION_DRIVE
        peak = getattr(getattr(c, "g", None), "current_limit", np.inf) * c.p.c_m * c.p.i_r
        limits[axis] = (table.nominal_torque, float(peak))
    return torque, current, limits
