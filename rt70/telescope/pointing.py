"""The wind pointing budget: steady and gust errors of the mirror system with the servos closed.

One job: for one case (a pointing, a mean wind speed and direction) the answer an
antenna engineer asks of the model — how far the wind moves the beam, and which modes
do it. Three outputs of the mirror system (book 4.1.8, :mod:`rt70.model.optics`):

- ``main_mirror_error``: the main-mirror axis against the source (4.156), arc seconds;
- ``counterreflector_error``: the counterreflector's axis against the main mirror's
  (4.165), arc seconds;
- ``focal_offset``: the counterreflector's focus from the main mirror's (4.152), mm.

Each is a 3-vector; the budget gives its magnitude (for the two angles the radial
error, the component along the axis being second order).

**Steady wind.** The servos' integrators hold the encoders at the pointing, so the
steady state is the static equilibrium held by the drives
(:func:`rt70.telescope.scene_servo.scene_equilibrium`) with the wind's generalised force added
(:mod:`rt70.textbook.wind` / :mod:`rt70.reference.wind`, (4.132)–(4.136)). The steady
error is the outputs' change from the calm equilibrium: the gravity sag at the same
pointing is the pointing model's business, not the wind's.

**Gusts.** About the windy equilibrium the closed loop is linear
(:func:`rt70.control.scene_loop.closed_loop`: the structure, both drives and their PI
cascades); the gust v′ along the mean wind enters as the column ``∂Q_w/∂v = 2 Q_w/v̄``
(the load is quadratic in the speed) and the wind's aerodynamic stiffness
``−∂Q_w/∂q`` is added to K. Driven by the Davenport gust filter
(:mod:`rt70.wind.gusts`), the output covariance is one Lyapunov equation
(:mod:`rt70.linear.covariance`); its split over the modes of the closed loop names the
modes that contribute most.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from rt70.errors import Rt70Error
from rt70.linear import linearize as lin
from rt70.model.outputs import Output, column_labels, evaluate
from rt70.model.scene import Scene
from rt70.telescope.gust_modes import ModeShare, mode_shares

#: The budget's outputs (names of :func:`rt70.model.optics.mirror_outputs`), their units.
BUDGET_OUTPUTS = {
    "main_mirror_error": "arcsec",
    "counterreflector_error": "arcsec",
    "focal_offset": "mm",
}


@dataclass(frozen=True)
class PointingCase:
    """One case of the budget.

    Attributes
    ----------
    elevation_deg, azimuth_deg : float
        The pointing (``rt70 simulate`` conventions).
    speed : float
        Mean wind speed, m/s (> 0).
    direction_deg : float or None
        Azimuth the wind blows from, degrees
        (:class:`rt70.physics.aerodynamics.WindCondition`); None: the pointing's azimuth, a
        front wind into the dish.
    """

    elevation_deg: float = 45.0
    azimuth_deg: float = 0.0
    speed: float = 10.0
    direction_deg: float | None = None

    @property
    def direction(self) -> float:
        """The wind's direction, degrees."""
        return self.azimuth_deg if self.direction_deg is None else self.direction_deg


@dataclass
class PointingBudget:
    """Steady and gust errors of one case (module docstring).

    ``steady[name]`` and ``gust_rms[name]`` are magnitudes in the output's unit;
    ``steady_vector`` the steady change of each output's components; ``modes`` the
    :data:`rt70.telescope.gust_modes.TOP_MODES` modes with the largest share of the main
    mirror's gust variance; ``wind_torque`` the change of each drive's holding torque,
    N·m on its angle.
    """

    case: PointingCase
    steady: dict[str, float]
    steady_vector: dict[str, np.ndarray]
    gust_rms: dict[str, float]
    modes: list[ModeShare]
    wind_torque: dict[str, float]
    seconds: float
    extra: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """Plain JSON-ready values."""
        c = self.case
        return {
            "elevation_deg": c.elevation_deg,
            "azimuth_deg": c.azimuth_deg,
            "wind_speed": c.speed,
            "wind_direction_deg": c.direction,
            "units": dict(BUDGET_OUTPUTS),
            "steady": self.steady,
            "steady_vector": {k: v.tolist() for k, v in self.steady_vector.items()},
            "gust_rms": self.gust_rms,
            "modes": [m.__dict__ for m in self.modes],
            "wind_torque_Nm": self.wind_torque,
            "seconds": self.seconds,
            **self.extra,
        }


def budget_outputs(scene: Scene, case: PointingCase) -> list[Output]:
    """The mirror-system outputs of :data:`BUDGET_OUTPUTS` for the case's source.

    A single reflector (``<rt70:optics type="prime_focus">``) has the first only.
    """
    from rt70.model.antenna import pointing_outputs

    found = {o.name: o for o in pointing_outputs(scene, case.elevation_deg, case.azimuth_deg)}
    return [found[n] for n in BUDGET_OUTPUTS if n in found]  # a single reflector: the first


def _held(scene: Scene, case: PointingCase) -> dict[str, float]:
    from rt70.model.antenna import pointing

    return pointing(scene, case.elevation_deg, case.azimuth_deg)


def check_case(case: PointingCase) -> None:
    """Refuse a case with a non-finite value or a speed that is not positive."""
    values = [case.elevation_deg, case.azimuth_deg, case.speed, case.direction]
    if not np.isfinite(values).all():
        raise Rt70Error(f"pointing case must be finite, got {case}")
    if case.speed <= 0.0:
        raise Rt70Error(f"wind speed must be positive, got {case.speed:g} m/s")


def check_scene(scene: Scene) -> None:
    """Refuse a scene that cannot give a budget, before any work.

    It needs a ``<rt70:mount>`` whose azimuths are the wind's
    (:func:`rt70.model.antenna.check_wind_convention`), an ``<rt70:optics>``, a
    ``<rt70:drive>`` on each axis and at least one ``<rt70:wind>`` element.
    """
    from rt70.model.antenna import check_wind_convention, mirror_system
    from rt70.telescope.scene_servo import check_scene_drives

    mirror_system(scene)  # raises naming the missing <rt70:mount> or <rt70:optics>
    check_scene_drives(scene)
    if not scene.description.winds:
        raise Rt70Error(f"{scene.name}: no <rt70:wind> element: no wind load (see docs/wind.md)")
    check_wind_convention(scene)


class WindyScene:
    """A scene's wind at one condition on one side: the force, its stiffness, its gust column."""

    def __init__(self, scene: Scene, speed: float, direction_deg: float) -> None:
        from rt70.physics.aerodynamics import WindCondition
        from rt70.reference import wind as ref_wind

        if not scene.description.winds:
            raise Rt70Error(f"{scene.name}: no <rt70:wind> element: no wind load")
        self.scene = scene
        self.speed = speed
        self.condition = WindCondition(speed, direction_deg)
        model, data = scene.reference, scene.reference_data
        self._force = lambda q: ref_wind.wind_force(model, data, q, self.condition)

    def force(self, q: np.ndarray) -> np.ndarray:
        """The wind's generalised force at q (reference side), N or N·m."""
        return self._force(np.asarray(q, dtype=float))

    def stiffness(self, q: np.ndarray, h: float = lin.FD_STEP) -> np.ndarray:
        """``−∂Q_w/∂q`` by central differences: the aerodynamic stiffness (not symmetric)."""
        return lin.negative_jacobian(self.force, q, h)

    def gust_column(self, q: np.ndarray) -> np.ndarray:
        """``∂Q_w/∂v`` along the mean wind: ``2 Q_w / v̄`` (the load is quadratic in v)."""
        return 2.0 * self.force(q) / self.speed


def wind_inputs(scene: Scene, q0: np.ndarray, speed: float, direction_deg: float) -> list:
    """The linear plant's wind inputs at q0: one gust channel per exposed body, and all.

    ``wind:<element>`` is the generalised force of a unit gust (1 m/s along the mean
    wind of ``speed`` from ``direction_deg``) on that ``<rt70:wind>`` body alone,
    ``∂Q_w,e/∂v = 2 Q_w,e / v̄``; ``wind`` the same on every body at once (coherent
    gusts, the budget's input). For :func:`rt70.linear.plant.plant`: its
    disturbance-to-pointing transfer functions.

    Parameters
    ----------
    scene : Scene
        A scene with ``<rt70:wind>`` elements.
    q0 : numpy.ndarray, shape (nv,)
        The state linearised about, rad or m.
    speed : float
        Mean wind speed, m/s (> 0).
    direction_deg : float
        Azimuth the wind blows from, degrees.
    """
    from rt70.linear.plant import ForceInput
    from rt70.reference import wind as ref_wind

    if not speed > 0.0:
        raise Rt70Error(f"wind speed must be positive, got {speed:g} m/s")
    windy = WindyScene(scene, speed, direction_deg)
    q0 = np.asarray(q0, dtype=float)
    parts = ref_wind.wind_forces(scene.reference, scene.reference_data, q0, windy.condition)
    inputs = [ForceInput(f"wind:{name}", 2.0 * Q / speed) for name, Q in parts.items()]
    return [*inputs, ForceInput("wind", windy.gust_column(q0))]


@dataclass
class WindState:
    """The calm and the windy drive-held equilibria of a case."""

    q_calm: np.ndarray
    q_wind: np.ndarray
    torque_calm: np.ndarray
    torque_wind: np.ndarray
    drives: list[str]
    residual: float


def wind_equilibria(scene: Scene, case: PointingCase, windy: WindyScene) -> WindState:
    """The drive-held equilibria without and with the case's steady wind.

    Parameters
    ----------
    scene : Scene
        A scene with the RT-70's drives and wind elements.
    case : PointingCase
        The pointing held (:func:`rt70.telescope.scene_servo.scene_equilibrium`).
    windy : WindyScene
        The case's wind, whose force is the static load of the windy equilibrium.
    """
    from rt70.telescope.scene_servo import SceneServoFactory, scene_equilibrium

    couplings = SceneServoFactory(side="reference").couplings(scene)
    held = _held(scene, case)
    q0, K0, _ = scene_equilibrium(scene, couplings, held)
    q1, K1, res = scene_equilibrium(scene, couplings, held, load=windy.force)
    return WindState(q0, q1, K0, K1, [c.drive.name for c in couplings], res)


def _magnitude(v: np.ndarray) -> float:
    return float(np.linalg.norm(v))


def steady_errors(
    scene: Scene, outputs: list[Output], state: WindState
) -> tuple[dict[str, float], dict[str, np.ndarray]]:
    """The outputs' change from the calm to the windy equilibrium (reference side).

    Returns the magnitude of each change and the change itself, by output name.

    Parameters
    ----------
    scene : Scene
        The scene.
    outputs : list of Output
        The budget's outputs (:func:`budget_outputs`).
    state : WindState
        The calm and windy drive-held equilibria (:func:`wind_equilibria`).
    """
    calm = evaluate(scene, state.q_calm, outputs, "reference")
    windy = evaluate(scene, state.q_wind, outputs, "reference")
    vectors = {o.name: np.asarray(windy[o.name] - calm[o.name]) for o in outputs}
    return {k: _magnitude(v) for k, v in vectors.items()}, vectors


@dataclass
class WindyLinearization:
    """The linear model about the windy equilibrium, the wind's stiffness and gust column."""

    lm: lin.Linearization
    K_wind: np.ndarray
    gust_column: np.ndarray


def windy_linearization(scene: Scene, windy: WindyScene, state: WindState) -> WindyLinearization:
    """Linearise about the windy equilibrium, with the wind's stiffness and gust input.

    Parameters
    ----------
    scene : Scene
        The scene.
    windy : WindyScene
        The case's wind (its stiffness and gust column at the windy equilibrium).
    state : WindState
        The calm and windy drive-held equilibria (:func:`wind_equilibria`).
    """
    q = state.q_wind
    return WindyLinearization(lin.linearize(scene, q), windy.stiffness(q), windy.gust_column(q))


def windy_first_frequency(scene: Scene, w: WindyLinearization) -> float:
    """The first locked-rotor frequency in the wind, Hz: ``K + K_w`` with the motors held.

    The wind's aerodynamic stiffness is not symmetric: the frequencies are
    ``√λ / 2π`` of the eigenvalues λ of ``M⁻¹(K + K_w)`` (real parts; the imaginary ones
    are rounding-sized for the RT-70).
    """
    locked = lin.locked_rotor(scene, w.lm)
    lam = np.linalg.eigvals(np.linalg.solve(locked.M, locked.K + w.K_wind))
    lam = np.sort(lam.real)
    if lam[0] <= 0.0:
        raise Rt70Error(f"{scene.name}: the wind leaves a mode without stiffness")
    return float(np.sqrt(lam[0]) / (2.0 * np.pi))


def gust_system(scene: Scene, case: PointingCase, w: WindyLinearization, extra: list[Output] = ()):
    """The closed loop driven by the Davenport gust filter: unit white noise in, outputs out.

    Returns the augmented python-control ``StateSpace`` (input ``w``) and the closed
    loop alone (inputs ``<drive>_reference`` and ``gust``, m/s).

    Parameters
    ----------
    scene : Scene
        The scene with its drives (their servos close the loop).
    case : PointingCase
        The case: its outputs and the mean wind speed of the gust filter.
    w : WindyLinearization
        The linear model about the windy equilibrium (:func:`windy_linearization`).
    extra : list of Output
        More outputs after the budget's (a reflector's surface,
        :mod:`rt70.telescope.surface_budget`).
    """
    from rt70.control.scene_loop import closed_loop
    from rt70.linear.covariance import cascade_with_filter
    from rt70.telescope.scene_servo import scene_servos
    from rt70.wind.gusts import GustFilter

    loop = closed_loop(
        scene,
        w.lm,
        {"gust": w.gust_column},
        [*budget_outputs(scene, case), *extra],
        scene_servos(scene),
        K_extra=w.K_wind,
    )
    return cascade_with_filter(loop, GustFilter(case.speed).system, "gust"), loop


@dataclass
class BudgetModel:
    """Everything a case's budget is computed from, kept for the gust run to reuse.

    The wind at the case, its calm and windy drive-held equilibria, the budget's outputs,
    the linear model about the windy one, the closed loop (``loop``, inputs
    ``<drive>_reference`` and ``gust``) and the loop driven by the gust filter
    (``augmented``, input ``w``) with its state covariance ``P``; ``seconds`` to build;
    the reflector's surface outputs in the loop when the scene has a surface
    (``surface``, :mod:`rt70.telescope.surface_budget`).
    """

    case: PointingCase
    windy: WindyScene
    state: WindState
    outputs: list[Output]
    linear: WindyLinearization
    loop: object
    augmented: object
    P: np.ndarray
    seconds: float
    surface: object = None

    def output_covariance(self, outputs: list[Output]) -> np.ndarray:
        """The ensemble covariance of ``outputs``' components (all in the loop)."""
        labels = list(self.augmented.output_labels)
        idx = [labels.index(r) for o in outputs for r in self.rows(o)]
        C = self.augmented.C[idx]
        return C @ self.P @ C.T

    def rows(self, output: Output) -> list[str]:
        """The loop's output names of one budget output's components (``name:x`` …)."""
        return column_labels(output.name, output.size)

    def gust_rms(self) -> dict[str, float]:
        """The ensemble (Lyapunov) rms of each output's magnitude."""
        labels = list(self.augmented.output_labels)
        cov = self.augmented.C @ self.P @ self.augmented.C.T
        out = {}
        for o in self.outputs:
            idx = [labels.index(r) for r in self.rows(o)]
            out[o.name] = float(np.sqrt(np.trace(cov[np.ix_(idx, idx)])))
        return out


def budget_model(scene: Scene, case: PointingCase) -> BudgetModel:
    """Build the :class:`BudgetModel` of a case (module docstring)."""
    from rt70.linear.covariance import state_covariance
    from rt70.telescope.surface_budget import scene_surface_outputs

    check_case(case)
    start = time.perf_counter()
    windy = WindyScene(scene, case.speed, case.direction)
    state = wind_equilibria(scene, case, windy)
    linear = windy_linearization(scene, windy, state)
    surface = scene_surface_outputs(scene)
    augmented, loop = gust_system(scene, case, linear, surface[1] if surface else [])
    P = state_covariance(augmented)
    outputs = budget_outputs(scene, case)
    return BudgetModel(
        case, windy, state, outputs, linear, loop, augmented, P, time.perf_counter() - start,
        surface,
    )  # fmt: skip


def pointing_budget(
    scene: Scene, case: PointingCase, model: BudgetModel | None = None
) -> PointingBudget:
    """The budget of one case (module docstring).

    Its ``seconds`` count the model's building too, wherever it was built.

    Parameters
    ----------
    scene : Scene
        A scene with the RT-70's drives and wind elements (``rt70_servo``).
    case : PointingCase
        The pointing and the mean wind.
    model : BudgetModel, optional
        This case's model if already built (:func:`budget_model`).
    """
    if model is None:
        model = budget_model(scene, case)
    elif model.case != case:
        raise Rt70Error(f"the budget model is of {model.case}, not of {case}")
    start = time.perf_counter()
    state, linear, augmented = model.state, model.linear, model.augmented
    steady, vectors = steady_errors(scene, model.outputs, state)
    state_rms = np.sqrt(np.clip(np.diag(model.P), 0.0, None))
    main = next(o for o in model.outputs if o.name == "main_mirror_error")
    modes, quasi_static = mode_shares(
        augmented, model.rows(main), state_rms, linear.lm, state.drives
    )
    torque = {
        d: float(k1 - k0)
        for d, k0, k1 in zip(state.drives, state.torque_calm, state.torque_wind, strict=True)
    }
    return PointingBudget(
        case, steady, vectors, model.gust_rms(), modes, torque,
        model.seconds + time.perf_counter() - start,
        extra={
            "equilibrium_residual": state.residual,
            "quasi_static_share": quasi_static,
            "first_frequency_hz": windy_first_frequency(scene, linear),
        },
    )  # fmt: skip


#: What the budget's outputs are called in a table.
TITLES = {
    "main_mirror_error": "main-mirror axis vs source",
    "counterreflector_error": "counterreflector vs main-mirror axis",
    "focal_offset": "focus offset (CR focus vs main focus)",
}


def format_budget(scene_name: str, b: PointingBudget) -> str:
    """The budget of one case as a short table (what ``rt70 pointing`` prints)."""
    c = b.case
    lines = [
        f"{scene_name}: wind {c.speed:g} m/s from azimuth {c.direction:g}°, pointing "
        f"elevation {c.elevation_deg:g}°, azimuth {c.azimuth_deg:g}° — servos closed "
        f"({b.seconds:.2f} s)",
        f"  {'output':<40} {'steady':>10} {'gust rms':>10}  unit",
    ]
    for name, unit in BUDGET_OUTPUTS.items():
        if name not in b.steady:  # a single reflector has no secondary's outputs
            continue
        lines.append(
            f"  {TITLES[name]:<40} {b.steady[name]:>10.4g} {b.gust_rms[name]:>10.4g}  {unit}"
        )
    torques = ", ".join(f"{d} {t / 1e6:+.3g} MN·m" for d, t in b.wind_torque.items())
    lines.append(f"  steady wind torque on the drives: {torques}")
    share = b.extra.get("quasi_static_share", float("nan"))
    lines.append(
        f"  gust error of the main-mirror axis: {100 * share:.1f} % quasi-static (the wind's "
        "own slow variation); the loop modes that contribute most:"
    )
    for m in b.modes:
        lines.append(
            f"    {m.frequency_hz:8.4g} Hz  ζ {m.damping:6.3f}  {100 * m.share:6.1f} %  {m.label}"
        )
    return "\n".join(lines)
