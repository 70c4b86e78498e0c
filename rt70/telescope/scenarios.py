"""Servo scenarios of an antenna: hold, 1° steps and sidereal tracking, closed on the model.

One job: run the telescope with its drives closed around the nonlinear model
(:func:`rt70.simulation.simulate.simulate` with :class:`rt70.control.servo.ServoDrive` components
on the axes of the scene's ``<rt70:mount>``) and measure
what a servo engineer asks of it: settling time to 1″, overshoot, peak motor torque
against its limit, pointing error in arc seconds and the tracking error after settling.

The run starts at rest in the static equilibrium of the pointing with the drives holding
(:func:`rt70.linear.linearize.equilibrium`): the motors' states hold the gravity torque
(:meth:`rt70.control.drives.DcDrive.holding`) and the cascade's integrators are preset to the
current and voltage that hold it, so a hold has no start-up transient.

The drives are built by a *drive factory* (:data:`DriveFactory`): the default,
:func:`servo_drives`, puts one :class:`~rt70.control.servo.ServoDrive` (with
back-calculation anti-windup, :class:`rt70.control.antiwindup.BackCalculationServo`) per
axis on the coordinates, with the motor and reducer of the ``<rt70:drive>`` its
``<rt70:servo>`` names, and the servo's limits and design
(:mod:`rt70.telescope.axis_servos`). Another factory (drives with friction and
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

from collections.abc import Sequence

import numpy as np

from rt70.control.friction import AxisFriction
from rt70.errors import Rt70Error
from rt70.guards.resources import check_time_series
from rt70.linear.linearize import equilibrium, static_force
from rt70.model.antenna import mount_of, pointing, pointing_outputs, sky_frame
from rt70.model.outputs import evaluate
from rt70.model.scene import Scene
from rt70.model.sides import refuses_backend
from rt70.simulation.simulate import sample_channels, simulate
from rt70.simulation.states import StateComponent
from rt70.telescope.axis_servos import axis_servos
from rt70.telescope.scenario import (
    DEFAULT_ELEVATION,
    DEFAULT_T_END,
    MIRROR_AXIS,
    SCENARIOS,
    SIDEREAL_ARCSEC_PER_S,
    STEP_DEG,
    Reference,
    Scenario,
    ScenarioRun,
    choose,
    mirror_axis_output,
    scenario,
    sky_error,
)
from rt70.telescope.servo_design import declared_tuning, tuning_text
from rt70.telescope.servo_metrics import (
    BAND_ARCSEC,
    measure,
    predicted_settling,
    settling_time,
    summary_lines,
)
from rt70.telescope.servo_tuning import (
    EQUILIBRIUM_TOL,
    DriveFactory,
    axis_gains,
    drive_parameters,
    holding_excess,
    preset_servo_state,
    servo_drives,
    servo_tolerances,
)
from rt70.units import RAD_PER_ARCSEC

#: The scenarios' API: the run (:func:`run_scenario`) with the scenario's definitions
#: (:mod:`rt70.telescope.scenario`), its measurements (:mod:`rt70.telescope.servo_metrics`)
#: and the drives' tuning (:mod:`rt70.telescope.servo_tuning`), importable from one place.
__all__ = [
    "BAND_ARCSEC",
    "DEFAULT_ELEVATION",
    "DEFAULT_T_END",
    "DriveFactory",
    "EQUILIBRIUM_TOL",
    "METHOD",
    "MIRROR_AXIS",
    "Reference",
    "SCENARIOS",
    "SIDEREAL_ARCSEC_PER_S",
    "STEP_DEG",
    "Scenario",
    "ScenarioRun",
    "axis_gains",
    "choose",
    "declared_tuning",
    "drive_parameters",
    "holding_excess",
    "measure",
    "mirror_axis_output",
    "predicted_settling",
    "preset_servo_state",
    "run_scenario",
    "scenario",
    "servo_drives",
    "servo_tolerances",
    "settling_time",
    "sky_error",
    "summary_lines",
    "tuning_text",
]

#: Integration method of the scenarios: SUNDIALS' BDF. scipy's BDF and Radau stop at
#: random on a hold ("Required step size is less than spacing between numbers": measured
#: at 30° and 90°, 60 s): at rest every Newton correction is rounding noise, their ratio
#: reaches 1 and the iteration is declared diverging at any step size. CVODE first asks
#: whether the correction is within the tolerance, as LSODA does, and keeps its Jacobian
#: while the iteration converges: it takes a fraction of LSODA's evaluations and
#: Jacobians on every scenario (docs/servo-scenarios.md, validation/servo_speed.py).
METHOD = "CVODE"


@refuses_backend
def run_scenario(
    scene: Scene,
    sc: Scenario,
    drives: DriveFactory | None = None,
    rtol: float = 1e-6,
    samples_per_s: float = 20.0,
    side: str = "reference",
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
        sector's force, :mod:`rt70.telescope.scene_servo`); otherwise the start is the
        equilibrium with the axes held by torques on their coordinates.
    rtol : float
        Relative tolerance of the integration (:func:`rt70.simulation.simulate.simulate`).
    samples_per_s : float
        Output samples per second of simulated time.
    side : {"reference", "textbook"}
        Which side evaluates the mechanics (:mod:`rt70.model.sides`).
    method : str, optional
        The integration method; default :data:`METHOD` (CVODE, and why).
    progress : bool
        Show a progress bar on stderr.
    """
    mount_of(scene)  # one line naming the element a scene without axes lacks
    drives = servo_drives() if drives is None else drives
    start = _start(scene, sc, drives)
    q0, torques, _ = start
    refs = _axis_references(scene, sc, q0)
    components = drives(scene, q0, torques, refs)
    t_eval = _sample_times(scene, sc, samples_per_s, components)
    result = simulate(
        scene,
        (0.0, sc.t_end),
        (q0, np.zeros(scene.textbook.nv)),
        side=side,
        method=METHOD if method is None else method,
        rtol=rtol,
        t_eval=t_eval,
        outputs=[mirror_axis_output(scene)],
        components=components,
        progress=progress,
    )
    if not result.success:
        hint = _friction_hint(components, result.method)
        raise Rt70Error(f"{scene.name}: scenario '{sc.name}': {result.message}{hint}")
    run = _measured(scene, sc, result, refs, start, components)
    run.metrics = measure(run)
    return run


def _friction_hint(components: Sequence[StateComponent], method: str) -> str:
    """What to try when a run with dry friction stops (docs/servo-scenarios.md)."""
    if method == "LSODA" or not any(isinstance(c, AxisFriction) for c in components):
        return ""
    return (
        f" (dry friction: {method} can fail where an axis breaks away after sticking; "
        "try --method LSODA, docs/servo-scenarios.md 'Dry friction')"
    )


def _start(scene: Scene, sc: Scenario, drives: DriveFactory) -> tuple:
    """``(q0, holding torques, rest)``: the start at the scenario's pointing.

    The drive factory's own start if it has one, else the static equilibrium with the
    axes held by torques on their coordinates. ``rest(held)`` gives the same kind of
    equilibrium at another pointing, and q0 at the start's own (a hold's reference).
    """
    names = scene.coordinate_names
    held = pointing(scene, sc.elevation_deg, sc.azimuth_deg)
    start = getattr(drives, "start", None)
    if start is None:
        q0 = equilibrium(scene, held, tol=EQUILIBRIUM_TOL)
        Q0 = static_force(scene, q0)
        torques = {c: -float(Q0[names.index(c)]) for c in held}  # what the drives supply

        def solve(other: dict[str, float]) -> np.ndarray:
            return equilibrium(scene, other, tol=EQUILIBRIUM_TOL)

    else:  # a factory whose drives do not push on the coordinates alone
        q0, torques = start(scene, held)

        def solve(other: dict[str, float]) -> np.ndarray:
            return start(scene, other)[0]

    return q0, torques, (lambda other: q0 if other == held else solve(other))


def _axis_references(scene: Scene, sc: Scenario, q0: np.ndarray) -> dict[str, Reference]:
    """The axes' references in coordinate radians, by joint: ``q0 + sign · offset``.

    ``sign`` is the mount axis's (``q = sign · (angle − zero)``, ``<rt70:axis>``).
    """
    names = scene.coordinate_names
    offsets = {"azimuth": sc.azimuth, "elevation": sc.elevation}
    refs = {}
    for axis in mount_of(scene).axes:
        start, sign, offset = q0[names.index(axis.joint)], axis.sign, offsets[axis.name]
        refs[axis.joint] = lambda t, a=start, s=sign, f=offset: a + s * np.radians(f(t))
    return refs


def _sample_times(
    scene: Scene, sc: Scenario, samples_per_s: float, components: Sequence[StateComponent]
) -> np.ndarray:
    """The output times, ``samples_per_s`` a second, after checking memory holds them."""
    if sc.t_end * samples_per_s < 1.0:
        raise Rt70Error(
            f"{scene.name}: --t-end {sc.t_end:g}: a scenario is measured on samples every "
            f"{1 / samples_per_s:g} s; it must last at least that long"
        )
    n_t = np.ceil(sc.t_end * samples_per_s) + 1
    check_time_series(
        n_t,
        sample_channels(
            len(scene.coordinate_names),
            2 + sum(len(c.names) for c in components),
            [mirror_axis_output(scene)],
        ),
        f"scenario '{sc.name}' sampled {samples_per_s:g} times a second",
        f"{scene.name}: --t-end {sc.t_end:g}",
    )
    return np.linspace(0.0, sc.t_end, int(n_t))


def _measured(
    scene: Scene,
    sc: Scenario,
    result,
    refs: dict[str, Reference],
    start: tuple,
    components: Sequence[StateComponent],
) -> ScenarioRun:
    """What the run measured: the axes' errors, the pointing error, the drives' torques.

    The pointing error is the main mirror's axis against the target axis: its axis in
    equilibrium at the reference pointing (:func:`_target_axes`); ``start`` is
    :func:`_start`'s.
    """
    names = scene.coordinate_names
    q0, torques, rest = start
    t = result.t
    reference, error = {}, {}
    for axis in mount_of(scene).axes:
        reference[axis.name] = np.array([refs[axis.joint](x) for x in t])
        # the angle's error: the coordinate's times the axis's sign (q = sign·(angle − zero))
        k = names.index(axis.joint)
        error[axis.name] = axis.sign * (reference[axis.name] - result.q[:, k]) / RAD_PER_ARCSEC
    e_ref = sc.elevation_deg + np.array([sc.elevation(x) for x in t])
    a_ref = sc.azimuth_deg + np.array([sc.azimuth(x) for x in t])
    target = _target_axes(scene, q0, t, e_ref, a_ref, rest)
    n = result.outputs[MIRROR_AXIS]
    sky = sky_error(sky_frame(scene), n, target)
    cosang = np.clip((n * target).sum(1), -1.0, 1.0)
    total = np.arctan2(np.linalg.norm(np.cross(n, target), axis=1), cosang) / RAD_PER_ARCSEC
    torque, current, limits = _drive_torques(scene, components, result)
    static = _static_misalignment(scene, q0, sc)
    _record_series(result, {"elevation": e_ref, "azimuth": a_ref}, error, sky, total)
    for axis in torque:
        result.series[f"torque:{axis}"], result.series_units[f"torque:{axis}"] = torque[axis], "N·m"
        result.series[f"current:{axis}"], result.series_units[f"current:{axis}"] = (
            current[axis],
            "A",
        )
    return ScenarioRun(
        sc,
        result,
        reference,
        error,
        torque,
        limits,
        current,
        sky,
        total,
        static,
        {a.name: torques[a.joint] for a in mount_of(scene).axes},
        list(components),
        axis_signs={a.name: a.sign for a in mount_of(scene).axes},
    )


def _record_series(result, reference_deg: dict, error: dict, sky, total) -> None:
    """What the run prints, kept with it: references, encoder and pointing errors."""
    for axis, values in reference_deg.items():
        result.series[f"reference:{axis}"], result.series_units[f"reference:{axis}"] = (
            np.asarray(values, dtype=float),
            "deg",
        )
    for axis, values in error.items():
        result.series[f"encoder_error:{axis}"] = values
        result.series_units[f"encoder_error:{axis}"] = "arcsec"
    pointing = {"cross_elevation": sky[:, 0], "elevation": sky[:, 1], "total": total}
    for name, values in pointing.items():
        result.series[f"pointing_error:{name}"] = values
        result.series_units[f"pointing_error:{name}"] = "arcsec"


def _target_axes(scene, q0, t, e_ref, a_ref, rest) -> np.ndarray:
    """The main mirror's axis in equilibrium at the reference pointing, per sample.

    Equilibria at the distinct reference pointings of a few knots (first, last, and
    where the reference changes), linearly interpolated in between and normalised.
    ``rest(held)`` gives the equilibrium (:func:`_start`: the drive factory's, with the
    drives' forces in it, or the axes held by torques on their coordinates).
    """
    out = mirror_axis_output(scene)
    knots = np.unique(np.r_[0, np.linspace(0, len(t) - 1, 5).astype(int), len(t) - 1])
    cache: dict[tuple[float, float], np.ndarray] = {}
    axes = []
    for k in knots:
        key = (round(float(e_ref[k]), 12), round(float(a_ref[k]), 12))
        if key not in cache:
            held = pointing(scene, *key)
            q = rest(held)
            cache[key] = evaluate(scene, q, [out], "reference")[MIRROR_AXIS]
        axes.append(cache[key])
    axes = np.array(axes)
    # between knots, a step reference is constant after t = 0: interpolation is exact
    target = np.column_stack([np.interp(np.arange(len(t)), knots, axes[:, i]) for i in range(3)])
    return target / np.linalg.norm(target, axis=1, keepdims=True)


def _static_misalignment(scene: Scene, q0: np.ndarray, sc: Scenario) -> float:
    """(4.157) of the main mirror at the start equilibrium: the gravity sag, arc seconds."""
    outs = [o for o in pointing_outputs(scene, sc.elevation_deg, sc.azimuth_deg)]
    outs = [o for o in outs if o.name == "main_mirror_misalignment"]
    return float(evaluate(scene, q0, outs, "reference")["main_mirror_misalignment"][0])


def _drive_torques(scene: Scene, components: Sequence[StateComponent], result):
    """Axis-side reducer torque and motor current of each drive that has them."""
    names = scene.coordinate_names
    servos = {names.index(d.axis.joint): d for d in axis_servos(scene).values()}
    torque, current, limits = {}, {}, {}
    for c in components:
        if not hasattr(c, "reducer_torque"):
            continue
        axis = servos[c.index].axis.name
        s = np.column_stack([result.states[n] for n in c.names])
        torque[axis] = np.array(
            [c.reducer_torque(q, qd, x) for q, qd, x in zip(result.q, result.qd, s, strict=True)]
        )
        current[axis] = s[:, 0]
        peak = getattr(getattr(c, "g", None), "current_limit", np.inf) * c.p.c_m * c.p.i_r
        limits[axis] = (servos[c.index].servo.nominal_torque, float(peak))
    return torque, current, limits
