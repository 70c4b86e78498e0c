"""What a servo engineer measures on a scenario run: settling, overshoot, torque, errors.

One job: turn a :class:`rt70.telescope.scenario.ScenarioRun` (trajectory, axis errors, pointing
error, drive torques) into the numbers of the servo targets — settling time into the
1″ band, the settling time derived from the position loop's gains
(:func:`predicted_settling`), overshoot, peak torque against its limit, the pointing
drift and the tracking error after settling — and into lines of text.
"""

from __future__ import annotations

import numpy as np

from rt70.control.servo import CascadeGains
from rt70.telescope.scenario import ScenarioRun
from rt70.units import ARCSEC_PER_DEG, RAD_PER_ARCSEC

#: The settling band of the servo targets, arc seconds.
BAND_ARCSEC = 1.0


def settling_time(t: np.ndarray, error: np.ndarray, band: float = BAND_ARCSEC) -> float:
    """First time after which ``|error| ≤ band`` to the end of the run; NaN if never.

    The run must end inside the band and stay there (NaN if the last sample is outside).

    Parameters
    ----------
    t : numpy.ndarray, shape (n,)
        Sample times, s.
    error : numpy.ndarray, shape (n,)
        The error at each sample, arc seconds.
    band : float
        The settling band, arc seconds.
    """
    outside = np.flatnonzero(np.abs(error) > band)
    if outside.size == 0:
        return float(t[0])
    if outside[-1] == len(t) - 1:
        return float("nan")
    return float(t[outside[-1] + 1])


def predicted_settling(step_arcsec: float, gains: CascadeGains, band: float = BAND_ARCSEC) -> float:
    """Settling time of a step to ``band`` derived from the position loop's gains, s.

    The rigid-axis model the gains were designed on (:func:`rt70.control.servo.cascade_gains`),
    with the inner loops ideal: the axis rate follows ``K_p e + K_i ∫e`` clamped to the
    rate limit Ω. While ``K_p |e| > Ω`` the axis slews at Ω, the integral frozen
    (conditional integration); the loop turns linear at ``e_lin = Ω / K_p`` and then
    obeys ``ë + K_p ė + K_i e = 0`` from ``(e_lin, −Ω)``, whose poles are
    ``ω_p (1 ± √(1 − 4/ratio)) / 2`` (``K_p = ω_p``, ``K_i = ω_p²/ratio``): the slow one,
    0.28 ω_p at ratio 5, sets the tail. The time is the slew plus the first time after
    which the linear response stays inside ``band`` (evaluated exactly on a 5 ms grid).
    It neglects the rate loop's lag and the structure.

    Parameters
    ----------
    step_arcsec : float
        The step, arc seconds (its sign does not matter).
    gains : CascadeGains
        The axis's cascade (position-loop gains and rate limit).
    band : float
        The settling band, arc seconds.
    """
    import scipy.linalg

    step = abs(step_arcsec) * RAD_PER_ARCSEC
    w, omega, k_i = gains.kp_p, gains.rate_limit, gains.ki_p
    e_lin = min(step, omega / w)
    slew = (step - e_lin) / omega
    # x = [e, ∫e]: ė = −(K_p e + K_i ∫e), from e_lin with the integral at zero
    system = np.array([[-w, -k_i], [1.0, 0.0]])
    t = np.arange(0.0, 40.0 / min(w, k_i / w) + 0.005, 0.005)
    states = np.array([[e_lin], [0.0]])  # x(t_k) for k < m, then by doubling: P^m x(t_k)
    power = scipy.linalg.expm(system * 0.005)
    while states.shape[1] < t.size:
        states = np.hstack([states, power @ states])
        power = power @ power
    return float(slew + settling_time(t, states[0, : t.size] / RAD_PER_ARCSEC, band))


#: Metrics that are NaN when the run never settled (:func:`settling_time`) or the drive
#: has no gains to predict from; every other metric must be finite.
MAY_BE_NAN = (
    "settle_s",
    "axis_settle_s",
    "predicted_settle_s",
    "tracking_rms_arcsec",
    "tracking_max_after_settle_arcsec",
)


def _check_finite(m: dict[str, float]) -> None:
    from rt70.errors import Rt70Error

    bad = [k for k, v in m.items() if k not in MAY_BE_NAN and not np.isfinite(v)]
    if bad:
        raise Rt70Error(f"the scenario's {', '.join(bad)} is not finite: nothing to report")


def measure(run: ScenarioRun) -> dict[str, float]:
    """The scenario's numbers: settling, overshoot, peak torque, pointing and tracking errors.

    ``settle_s`` is the settling time of the pointing error (both components) into the
    1″ band; ``axis_settle_s`` of the stepped axis's encoder error; ``overshoot_pct``
    beyond the step on the stepped axis; ``pointing_drift_arcsec`` the largest pointing
    error of the run; ``tracking_rms_arcsec`` the rms pointing error after settling.
    """
    sc, t = run.scenario, run.result.t
    err = run.pointing_error
    m: dict[str, float] = {
        "pointing_drift_arcsec": float(run.pointing_error_total.max()),
        "final_pointing_arcsec": float(run.pointing_error_total[-1]),
        # NaN (never settled) wins: Python's max(0.0, nan) is 0.0
        "settle_s": float(np.max([settling_time(t, err[:, 0]), settling_time(t, err[:, 1])])),
        "static_misalignment_arcsec": run.static_misalignment,
        "wall_s": run.result.wall_time_s,
        "energy_drift": run.result.relative_drift,
    }
    for axis, tau in run.axis_torque.items():
        m[f"peak_torque_{axis}_Nm"] = float(np.abs(tau).max())
        m[f"peak_torque_{axis}_of_limit"] = float(np.abs(tau).max() / run.torque_limits[axis][1])
        m[f"holding_torque_{axis}_Nm"] = run.holding_torque[axis]
    for i, axis in enumerate(("azimuth", "elevation")):
        step = sc.step_deg[i] * ARCSEC_PER_DEG
        if step:
            e = run.axis_error[axis]
            m["axis_settle_s"] = settling_time(t, e)
            m["overshoot_pct"] = float(max(0.0, (-e * np.sign(step)).max()) / abs(step) * 100)
            m["step_arcsec"] = step
            gains = getattr(run.components[i], "g", None) if len(run.components) > i else None
            m["predicted_settle_s"] = (
                predicted_settling(step, gains) if gains is not None else float("nan")
            )
    if sc.rate_arcsec_s:
        settle = m["settle_s"]
        after = t >= settle if np.isfinite(settle) else np.zeros_like(t, dtype=bool)
        total = run.pointing_error_total
        m["tracking_rms_arcsec"] = (
            float(np.sqrt(np.mean(total[after] ** 2))) if after.any() else np.nan
        )
        m["tracking_max_after_settle_arcsec"] = float(total[after].max()) if after.any() else np.nan
    return m


def _inside(settle: float, t_end: float, what: str = "") -> str:
    """``inside 1″ from t = … s``, or that the run ended outside the band (NaN)."""
    if np.isfinite(settle):
        return f"inside {BAND_ARCSEC:g}″ from t = {settle:.3g} s"
    return f"not inside {BAND_ARCSEC:g}″ by the end of the run (t = {t_end:g} s{what})"


def summary_lines(run: ScenarioRun) -> list[str]:
    """The scenario's numbers as a few lines of text (``rt70 simulate``, the notebook).

    A settling time that is NaN (the run ended outside the band) reads "not inside …
    by the end of the run"; every other number must be finite.

    Raises
    ------
    Rt70Error
        If a number other than a settling time (or what follows from one) is NaN or
        infinite: it would otherwise be printed as ``nan``.
    """
    m, sc = run.metrics, run.scenario
    t_end = float(run.result.t[-1])
    _check_finite(m)
    lines = [
        f"pointing error (mirror axis vs its equilibrium at the reference): max "
        f"{m['pointing_drift_arcsec']:.3g}″, final {m['final_pointing_arcsec']:.3g}″, "
        + _inside(m["settle_s"], t_end),
        f"static gravity sag of the mirror axis (4.157, calibrated by a pointing model): "
        f"{m['static_misalignment_arcsec']:.4g}″",
    ]
    if "step_arcsec" in m:
        predicted = m["predicted_settle_s"]
        prediction = (
            f"predicted from the bandwidth {predicted:.3g} s"
            if np.isfinite(predicted)
            else "no prediction: the drive has no cascade gains"
        )
        lines.append(
            f"step {m['step_arcsec']:g}″: axis {_inside(m['axis_settle_s'], t_end)} "
            f"({prediction}), overshoot {m['overshoot_pct']:.3g} %"
        )
    if "tracking_rms_arcsec" in m:
        if np.isfinite(m["tracking_rms_arcsec"]):
            lines.append(
                f"tracking {sc.rate_arcsec_s:g}″/s: rms {m['tracking_rms_arcsec']:.3g}″, max "
                f"{m['tracking_max_after_settle_arcsec']:.3g}″ after settling"
            )
        else:
            lines.append(
                f"tracking {sc.rate_arcsec_s:g}″/s: no tracking error after settling, the "
                f"pointing error is {_inside(m['settle_s'], t_end)}"
            )
    for axis in run.axis_torque:
        lines.append(
            f"{axis}: holding {m[f'holding_torque_{axis}_Nm']:.3g} N·m, peak "
            f"{m[f'peak_torque_{axis}_Nm']:.3g} N·m = {m[f'peak_torque_{axis}_of_limit']:.1%} "
            f"of the peak limit {run.torque_limits[axis][1]:.3g} N·m"
        )
    r = run.result
    lines.append(
        f"energy balance drift {r.relative_drift:.2e} of {r.balance_scale:.4g} J; drives' "
        f"work on the structure {r.input_work[-1]:.4g} J"
    )
    return lines
