"""What a servo scenario asks of the RT-70's axes, and what a run of it returns.

:class:`Scenario` (hold, 1° steps, sidereal tracking) and :func:`scenario` build the
references; :func:`choose` decides what ``rt70 simulate`` runs on a scene;
:class:`ScenarioRun` holds a run's simulation and measures (:mod:`rt70.telescope.scenarios`
runs it, :mod:`rt70.telescope.servo_metrics` measures it); the pointing error of the mirror
axis is :func:`sky_error`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from rt70.errors import Rt70Error
from rt70.model.antenna import SkyFrame, mirror_system, mount_of, optics_of
from rt70.model.outputs import Output
from rt70.model.scene import Scene
from rt70.simulation.result import SimulationResult
from rt70.simulation.states import StateComponent
from rt70.telescope.axis_servos import axis_servos, has_servos
from rt70.telescope.servo_tuning import holding_excess
from rt70.units import ARCSEC_PER_DEG, RAD_PER_ARCSEC

#: The scenarios by name (``rt70 simulate --scenario``).
SCENARIOS = ("hold", "step-azimuth", "step-elevation", "track")


#: Sidereal tracking rate used by the ``track`` scenario, arc seconds per second (15″/s).
SIDEREAL_ARCSEC_PER_S = 15.0


#: Size of the step scenarios, degrees.
STEP_DEG = 1.0


#: Default length of each scenario, s.
DEFAULT_T_END = {"hold": 60.0, "step-azimuth": 40.0, "step-elevation": 25.0, "track": 40.0}


#: Start elevation of the scenarios when none is given, degrees.
DEFAULT_ELEVATION = 45.0


#: Output name of the main mirror's focal axis in ground axes.
MIRROR_AXIS = "main_mirror_direction"


#: A reference of one axis: offset from the start pointing, degrees, as a function of t.
Reference = Callable[[float], float]


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

    Parameters
    ----------
    name : str
        One of :data:`SCENARIOS`.
    elevation_deg : float
        Start elevation, degrees, 0 to 90.
    azimuth_deg : float
        Start azimuth, degrees.
    t_end : float, optional
        Length, s (default :data:`DEFAULT_T_END` of the scenario).
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
        **common, azimuth=lambda t: rate * t / ARCSEC_PER_DEG, elevation=zero, rate_arcsec_s=rate
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

    Parameters
    ----------
    scene : Scene
        The scene ``rt70 simulate`` runs.
    name : str or None
        The scenario asked for (``--scenario``), or None.
    elevation_deg, azimuth_deg : float or None
        The pointing asked for, degrees, or None.
    t_end : float or None
        The length asked for, s, or None (the scenario's default).

    Raises
    ------
    Rt70Error
        A scenario or pointing asked of a scene without the axes, or one the drives
        cannot hold at that pointing.
    """
    asked = name is not None or elevation_deg is not None or azimuth_deg is not None
    if scene.description.mount is None or scene.description.optics is None:
        if asked:
            mount_of(scene)  # one line naming the element that is missing
            optics_of(scene)
        return None, None
    if not has_servos(scene):
        if asked:
            axis_servos(scene)  # one line naming the axis without its <rt70:servo>
        return None, (
            "its axes declare no <rt70:servo>: running the structural benchmark with the axes free"
        )
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
    system = mirror_system(scene)

    def formula(p: np.ndarray) -> np.ndarray:
        d = p[0] - p[1]
        return d / np.linalg.norm(d)

    return Output(MIRROR_AXIS, "1", 3, (system.main_focus, system.main_vertex), formula)


def sky_error(frame: SkyFrame, axis: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Cross-elevation and elevation error (arcsec) of mirror axes against targets (rows).

    ``[(A − A_t) cos E_t, E − E_t]`` with E, A read by the mount's
    :class:`~rt70.model.antenna.SkyFrame`: what the encoders of an elevation-over-azimuth
    mount see on the sky (a move in azimuth alone has no elevation error, unlike a
    projection of the chord ``axis − target``, whose second-order term is 15″ at 1°).

    Parameters
    ----------
    frame : rt70.model.antenna.SkyFrame
        The mount's sky frame (:func:`rt70.model.antenna.sky_frame`).
    axis, target : numpy.ndarray, shape (n, 3)
        Unit mirror axes and the target axes, ground axes.
    """
    e, a = frame.angles(axis)
    e_t, a_t = frame.angles(target)
    da = (a - a_t + np.pi) % (2 * np.pi) - np.pi
    return np.column_stack([da * np.cos(e_t), e - e_t]) / RAD_PER_ARCSEC


@dataclass
class ScenarioRun:
    """A scenario's simulation and what was measured on it.

    Angles in arc seconds, torques in N·m (axis side), times in s. ``axis_error`` is the
    reference minus the axis angle (the encoder's error) per axis; ``pointing_error`` the
    mirror axis against the target axis, (n_t, 2): cross-elevation, elevation;
    ``pointing_error_total`` its angle; ``holding_torque`` the drives' torque at the start,
    by axis. ``metrics`` holds the numbers of the summary; ``axis_signs`` each axis's
    ``sign`` (``<rt70:axis>``: its coordinate is ``sign · (angle − zero)``; the
    references are in coordinate radians).
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
    axis_signs: dict[str, int] = field(default_factory=dict)
