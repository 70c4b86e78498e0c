"""A gust record run through the nonlinear model and the linear closed loop, and compared.

One job: the check of the pointing budget's gust numbers (:mod:`rt70.telescope.pointing`) in the
time domain. One realisation of the Davenport gusts (:func:`rt70.wind.gusts.realise`,
reproducible by its seed) drives

- the **nonlinear** model: the scene's structure (Pinocchio), both drives with their
  servo cascades (:class:`rt70.telescope.scene_servo.SceneServoFactory`, anti-windup and clamps
  included) and the wind load exact in the speed, ``½ρ(v̄ + v′)²…``
  (:class:`rt70.wind.load.WindLoad`), started at rest in the windy equilibrium;
- the **linear** closed loop of the budget (:func:`rt70.telescope.pointing.gust_system`), by
  python-control's ``forced_response``.

Both read the record through the C² cubic spline of its samples
(:class:`rt70.wind.gusts.SmoothGust`): the nonlinear run at every evaluation, the linear
one on a grid :data:`REFINE` times finer than the samples (``forced_response``
interpolates linearly between its input samples, which differs from the spline by
``h²/8 · v″``, h the fine step).

Three rms values of each budget output's magnitude then compare: the nonlinear record's,
the linear record's (same gusts: they differ only by the model's nonlinearity, the
v′² term of the load and the solver's tolerance), and the Lyapunov value of the
budget (the ensemble rms, which a finite record estimates with a statistical error —
:func:`rt70.linear.covariance.sample_variance_error` gives it from the linear model).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

import control
import numpy as np

from rt70.errors import Rt70Error
from rt70.model.outputs import Output, evaluate
from rt70.model.scene import Scene
from rt70.telescope.pointing import (
    BUDGET_OUTPUTS,
    BudgetModel,
    PointingCase,
    budget_model,
    check_case,
)

#: Integration method and tolerance of the nonlinear run: SUNDIALS' BDF (rtol 1e-6 puts
#: atol at 1e-9 rad, 2e-4″). On 20 s at 5 m/s it took 3 543 evaluations and 53
#: Jacobians where LSODA took 8 004 and 954 (CVODE keeps a Jacobian while its Newton
#: iteration converges), and both stayed within 5e-5″ of a run at rtol 1e-9 (peak 11″).
METHOD = "CVODE"
RTOL = 1e-6
#: Gust sampling interval, s: Nyquist 5 Hz, above the modes the gusts excite (the
#: lowest locked-rotor modes lie at 0.4–2.4 Hz).
DT = 0.1
#: The linear loop's input grid is this many times finer than the gust samples.
REFINE = 10


@dataclass
class GustRun:
    """Records and rms values of one run (module docstring).

    ``nonlinear[name]`` and ``linear[name]`` are (n, 3) records of an output's change
    from the windy equilibrium; ``linear_exact_load[name]`` the linear loop's, fed the
    load's exact speed law ``v′ + v′²/2v̄`` (so that what is left against the nonlinear
    record is the structure's and the servo's nonlinearity); ``rms_*[name]`` the rms
    of its magnitude; ``rms_error[name]`` the standard deviation of a record's rms
    about the ensemble rms ``rms_lyapunov``.
    """

    case: PointingCase
    duration: float
    seed: int
    t: np.ndarray
    gust: np.ndarray
    nonlinear: dict[str, np.ndarray]
    linear: dict[str, np.ndarray]
    linear_exact_load: dict[str, np.ndarray]
    rms_nonlinear: dict[str, float]
    rms_linear: dict[str, float]
    rms_linear_exact_load: dict[str, float]
    rms_lyapunov: dict[str, float]
    rms_error: dict[str, float]
    seconds: float
    steps: int

    def to_dict(self) -> dict:
        """Plain JSON-ready values (no records)."""
        return {
            "duration_s": self.duration,
            "seed": self.seed,
            "gust_rms_m_s": float(np.sqrt(np.mean(self.gust**2))),
            "rms_nonlinear": self.rms_nonlinear,
            "rms_linear_same_gusts": self.rms_linear,
            "rms_linear_exact_load_law": self.rms_linear_exact_load,
            "max_difference_nonlinear_vs_linear_exact_load": {
                k: float(np.abs(self.nonlinear[k] - self.linear_exact_load[k]).max())
                for k in self.nonlinear
            },
            "rms_lyapunov": self.rms_lyapunov,
            "rms_statistical_error": self.rms_error,
            "nonlinear_seconds": self.seconds,
            "nonlinear_rhs_evaluations": self.steps,
        }


def _rms(y: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.sum(y * y, axis=1))))


#: Extra states of the nonlinear run per drive, at most (motor, servo, anti-windup).
STATES_PER_DRIVE = 8


def check_duration(
    scene: Scene, duration: float, dt: float = DT, outputs: Sequence[Output] = ()
) -> None:
    """Refuse a record whose samples (every ``dt`` over ``duration``) this machine cannot hold.

    Parameters
    ----------
    scene : Scene
        The scene run (its coordinates and drives set the states per sample).
    duration : float
        The record's length, s.
    dt : float
        The gust sampling interval, s.
    outputs : sequence of rt70.model.outputs.Output
        The outputs recorded with every sample.

    Raises
    ------
    rt70.errors.ResourceError
        Naming ``--duration`` (:func:`rt70.guards.resources.check_time_series`).
    """
    from rt70.guards.resources import check_time_series
    from rt70.simulation.simulate import sample_channels

    extra = 2 + STATES_PER_DRIVE * len(scene.description.drives)
    channels = sample_channels(scene.textbook.nv, extra, outputs) + 1  # and the gust
    source = f"{scene.name}: --duration {duration:g}"
    check_time_series(duration / dt + 1, channels, f"a gust record sampled every {dt:g} s", source)
    # the linear loop's states and outputs on its REFINE times finer input grid
    loop = 2 * scene.textbook.nv + extra + 3 * len(outputs) + 1
    check_time_series(REFINE * duration / dt + 1, loop, "the linear loop's record", source)


def gust_run(
    scene: Scene,
    case: PointingCase,
    duration: float,
    seed: int = 0,
    dt: float = DT,
    rtol: float = RTOL,
    progress: bool = False,
    model: BudgetModel | None = None,
) -> GustRun:
    """Run one gust record through both models (module docstring).

    Parameters
    ----------
    scene : Scene
        A scene with the RT-70's drives and wind elements (``rt70_servo``).
    case : PointingCase
        The pointing and the mean wind.
    duration : float
        The record's length, s (at least two samples).
    seed : int
        Seed of the gust record (:func:`rt70.wind.gusts.realise`).
    dt : float
        Gust sampling interval, s (:data:`DT`).
    rtol : float
        Relative tolerance of the nonlinear run (:data:`RTOL`).
    progress : bool
        Show the nonlinear run's progress bar on stderr.
    model : rt70.telescope.pointing.BudgetModel, optional
        The case's budget model if the budget was computed already (``rt70 pointing
        --duration``): its equilibria, loop and covariance are used as they are.

    Raises
    ------
    Rt70Error
        A bad case, a record shorter than two samples, or the integration failing.
    """
    from rt70.wind.gusts import GustFilter, realise

    check_case(case)
    if not (np.isfinite(duration) and duration >= 2 * dt):
        raise Rt70Error(f"gust run: duration must be at least {2 * dt:g} s, got {duration:g}")
    if model is None:
        model = budget_model(scene, case)
    elif model.case != case:
        raise Rt70Error(f"the budget model is of {model.case}, not of {case}")
    outputs = model.outputs
    check_duration(scene, duration, dt, outputs)
    series = realise(GustFilter(case.speed), duration, dt, seed)
    t, v = series.t, np.asarray(series.v)
    gust = series.smooth()
    nonlinear, seconds, steps = _nonlinear_run(scene, model, gust, rtol, progress)
    t_fine = np.linspace(t[0], t[-1], REFINE * (t.size - 1) + 1)
    v_fine = gust(t_fine)
    linear = _linear_response(model, t_fine, v_fine, REFINE)
    # the same linear loop fed the load's exact speed law: (v̄+v′)² − v̄² = 2v̄(v′ + v′²/2v̄)
    exact_load = _linear_response(model, t_fine, v_fine + v_fine**2 / (2.0 * case.speed), REFINE)
    lyap = model.gust_rms()
    return GustRun(
        case=case,
        duration=float(t[-1]),
        seed=seed,
        t=t,
        gust=v,
        nonlinear=nonlinear,
        linear=linear,
        linear_exact_load=exact_load,
        rms_nonlinear={k: _rms(y) for k, y in nonlinear.items()},
        rms_linear={k: _rms(y) for k, y in linear.items()},
        rms_linear_exact_load={k: _rms(y) for k, y in exact_load.items()},
        rms_lyapunov=lyap,
        rms_error=_rms_error(model, lyap, float(t[-1]), dt),
        seconds=seconds,
        steps=steps,
    )


def _rms_error(
    model: BudgetModel, lyap: dict[str, float], duration: float, dt: float
) -> dict[str, float]:
    """The standard deviation of a record's rms about the ensemble rms ``lyap``, per output.

    ``std(ŝ²) / (2 s)`` for a small relative error, ``std(ŝ²)`` of a record of
    ``duration`` seconds sampled every ``dt`` from the linear model
    (:func:`rt70.linear.covariance.sample_variance_error`).
    """
    from rt70.linear.covariance import sample_variance_error

    return {
        o.name: sample_variance_error(model.augmented, model.rows(o), duration, dt=dt)
        / (2.0 * lyap[o.name])
        for o in model.outputs
    }


def _nonlinear_run(
    scene: Scene, model: BudgetModel, gust, rtol: float, progress: bool
) -> tuple[dict[str, np.ndarray], float, int]:
    """The nonlinear model's record: ``(outputs' changes, wall seconds, evaluations)``.

    The scene's structure with both drives' servo cascades
    (:class:`rt70.telescope.scene_servo.SceneServoFactory`) and the wind load exact in
    the speed (:class:`rt70.wind.load.WindLoad`), at rest in the windy equilibrium held
    by its drives; each output as its change from that equilibrium.
    """
    from rt70.simulation.simulate import simulate
    from rt70.telescope.scene_servo import SceneServoFactory
    from rt70.wind.load import WindLoad

    factory = SceneServoFactory()
    couplings = factory.couplings(scene)
    names = scene.coordinate_names
    q0 = model.state.q_wind
    torques = {
        names[c.index]: float(k) for c, k in zip(couplings, model.state.torque_wind, strict=True)
    }
    held = {names[c.index]: float(q0[c.index]) for c in couplings}
    refs = {c: (lambda _t, v=v: v) for c, v in held.items()}
    components = [
        *factory(scene, q0, torques, refs),
        WindLoad(scene, model.windy.condition, gust),
    ]
    start = time.perf_counter()
    t = gust.series.t
    result = simulate(
        scene,
        (0.0, float(t[-1])),
        (q0, np.zeros(scene.textbook.nv)),
        method=METHOD,
        rtol=rtol,
        t_eval=t,
        outputs=model.outputs,
        components=components,
        progress=progress,
    )
    seconds = time.perf_counter() - start
    if not result.success:
        raise Rt70Error(f"{scene.name}: gust run: {result.message}")
    steady = evaluate(scene, q0, model.outputs, "reference")
    nonlinear = {o.name: result.outputs[o.name] - steady[o.name] for o in model.outputs}
    return nonlinear, seconds, int(getattr(result, "nfev", -1))


def _linear_response(
    model: BudgetModel, t: np.ndarray, u: np.ndarray, every: int = 1
) -> dict[str, np.ndarray]:
    """The budget's linear closed loop driven by the gust samples ``u`` (m/s) at times ``t``.

    python-control's ``forced_response``; each output's (n, 3) record by name, at every
    ``every``-th time.
    """
    outputs = model.outputs
    labels = [r for o in outputs for r in model.rows(o)]
    response = control.forced_response(model.loop[labels, "gust"], T=t, U=u)
    y = np.atleast_2d(response.outputs).T[::every]
    return {o.name: y[:, 3 * k : 3 * k + 3] for k, o in enumerate(outputs)}


__all__ = ["BUDGET_OUTPUTS", "GustRun", "gust_run"]
