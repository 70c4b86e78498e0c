"""The figure of a servo scenario: what a servo engineer reads off a run.

Four panels over time (a :class:`rt70.telescope.scenarios.ScenarioRun`): each axis angle against
its reference (as the offset from the start pointing, arc seconds); the drives' torque on
their axes against the nominal and the peak limits; the pointing error of the main
mirror's axis in arc seconds (cross-elevation, elevation) with the ±1″ band; and the
energy balance of the simulation's audit (the drives' work on the structure, where it
went, and the residual). Agg-safe: the figure is returned, never shown.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from rt70.units import ARCSEC_PER_RAD


def servo_figure(run) -> Figure:
    """Axis angles, torques, pointing error and energy balance of a scenario run."""
    sc, r, m = run.scenario, run.result, run.metrics
    t = r.t
    fig = Figure(figsize=(10, 11), constrained_layout=True)
    ax_a, ax_t, ax_p, ax_e = fig.subplots(4, 1, sharex=True)
    fig.suptitle(
        f"{r.scene}: {sc.name} at elevation {sc.elevation_deg:g}°, azimuth "
        f"{sc.azimuth_deg:g}° — {r.method} ({r.side}), rtol {r.rtol:g}",
        fontsize=11,
    )
    # 1. axis angles vs reference: offsets from the start, arc seconds (elevation upward)
    signs = run.axis_signs  # coordinate = sign · (angle − zero)
    colors = {"azimuth": "C0", "elevation": "C1"}
    for axis, ref in run.axis_reference.items():
        angle = ref - run.axis_error[axis] * signs[axis] / ARCSEC_PER_RAD
        start = angle[0]
        s, c = signs[axis], colors[axis]
        ax_a.plot(
            t, s * (ref - start) * ARCSEC_PER_RAD, "--", color=c, lw=1.0, label=f"{axis} reference"
        )
        ax_a.plot(t, s * (angle - start) * ARCSEC_PER_RAD, color=c, lw=1.4, label=f"{axis} axis")
    ax_a.set_ylabel("offset from start, ″")
    ax_a.set_title("axis angles (encoders) against their references", fontsize=9)
    ax_a.legend(fontsize=8, ncol=2)
    # 2. torque on the axes vs limits
    for axis, tau in run.axis_torque.items():
        nominal, peak = run.torque_limits[axis]
        c = colors[axis]
        ax_t.plot(t, tau / 1e6, color=c, label=f"{axis} reducer torque")
        ax_t.axhline(peak / 1e6, color=c, ls=":", lw=0.8)
        ax_t.axhline(-peak / 1e6, color=c, ls=":", lw=0.8)
    first = next(iter(run.torque_limits.values()), None)
    if first is not None:
        for y in (first[0], -first[0]):
            ax_t.axhline(y / 1e6, color="k", ls="--", lw=0.8)
        ax_t.plot([], [], "k--", lw=0.8, label=f"nominal ±{first[0] / 1e6:.3g} MN·m")
        ax_t.plot([], [], "k:", lw=0.8, label=f"peak (current limit) ±{first[1] / 1e6:.3g} MN·m")
    ax_t.set_ylabel("torque on axis, MN·m")
    ax_t.set_title("drive torque against its limits (axis side)", fontsize=9)
    ax_t.legend(fontsize=8, ncol=2)
    # 3. pointing error, arcsec, symmetric log scale so 1″ and 1° both read
    err = run.pointing_error
    ax_p.plot(t, err[:, 0], color="C2", label="cross-elevation")
    ax_p.plot(t, err[:, 1], color="C3", label="elevation")
    ax_p.axhspan(-1.0, 1.0, color="0.85", zorder=0, label="±1″ target")
    ax_p.set_yscale("symlog", linthresh=1.0)
    settle = m.get("settle_s", np.nan)
    if np.isfinite(settle) and settle > t[0]:
        ax_p.axvline(settle, color="k", lw=0.8, ls="--", label=f"inside 1″ from {settle:.3g} s")
    title = f"pointing error of the main-mirror axis: max {m['pointing_drift_arcsec']:.3g}″"
    if "tracking_rms_arcsec" in m:
        title += f", rms after settling {m['tracking_rms_arcsec']:.3g}″"
    ax_p.set_title(title, fontsize=9)
    ax_p.set_ylabel("error, ″ (symlog)")
    ax_p.legend(fontsize=8, ncol=2)
    # 4. energy audit
    ax_e.plot(t, r.input_work, "k--", lw=2.0, label="drives' work on the structure W_u")
    for name, values in (
        ("kinetic T", r.kinetic),
        ("gravity U_g − U_g(0)", r.gravity - r.gravity[0]),
        ("elastic U_c − U_c(0)", r.elastic - r.elastic[0]),
        ("dissipated E_ψ", r.dissipated),
    ):
        ax_e.plot(t, values, label=name)
    ax_e.plot(t, r.balance, "k", lw=0.8, label="residual T + U + E_ψ − W_u − E(0)")
    ax_e.set_ylabel("energy, J")
    ax_e.set_xlabel("t, s")
    ax_e.set_title(
        f"energy balance of the structure: residual max {r.relative_drift:.2e} of "
        f"{r.balance_scale:.4g} J",
        fontsize=9,
    )
    ax_e.legend(fontsize=8, ncol=2)
    for ax in (ax_a, ax_t, ax_p, ax_e):
        ax.grid(True, alpha=0.3)
    return fig


def summary_figure(runs: dict, drift_target: float = 1.0) -> Figure:
    """The servo targets at a glance: hold drift vs elevation, steps, tracking error.

    ``runs`` maps names to :class:`rt70.telescope.scenarios.ScenarioRun` (holds at several
    elevations, the steps, the tracking run), as validation/servo_scenarios.py makes them.
    """
    fig = Figure(figsize=(11, 8), constrained_layout=True)
    (ax_h, ax_s), (ax_t, ax_q) = fig.subplots(2, 2)
    holds = sorted(
        (r.scenario.elevation_deg, r.metrics["pointing_drift_arcsec"])
        for r in runs.values()
        if r.scenario.name == "hold"
    )
    if holds:
        e, d = np.array(holds).T
        ax_h.semilogy(e, np.maximum(d, 1e-16), "o-", label="max pointing drift")
        ax_h.axhline(drift_target, color="r", ls="--", label=f"target {drift_target:g}″")
        t_end = next(r.scenario.t_end for r in runs.values() if r.scenario.name == "hold")
        ax_h.set_title(f"hold under gravity, {t_end:g} s: pointing drift", fontsize=9)
        ax_h.set_xlabel("elevation, °")
        ax_h.set_ylabel("drift, ″")
        ax_h.legend(fontsize=8)
    steps = [r for r in runs.values() if r.scenario.name.startswith("step")]
    for i, r in enumerate(steps):
        total = r.pointing_error_total
        m = r.metrics
        ax_s.semilogy(
            r.result.t,
            np.maximum(total, 1e-6),
            color=f"C{i}",
            label=f"{r.scenario.name}: inside 1″ at {m['settle_s']:.3g} s "
            f"(derived {m['predicted_settle_s']:.3g} s), overshoot {m['overshoot_pct']:.2g} %",
        )
        ax_s.axvline(m["predicted_settle_s"], color=f"C{i}", ls=":", lw=0.8)
    ax_s.axhline(1.0, color="r", ls="--", lw=0.8)
    ax_s.set_title("1° steps: pointing error (dotted: settling derived from bandwidth)", fontsize=9)
    ax_s.set_xlabel("t, s")
    ax_s.set_ylabel("pointing error, ″")
    ax_s.legend(fontsize=7)
    for r in runs.values():
        if r.scenario.name != "track":
            continue
        m = r.metrics
        ax_t.plot(r.result.t, r.pointing_error[:, 0], label="cross-elevation")
        ax_t.plot(r.result.t, r.pointing_error[:, 1], label="elevation")
        ax_t.axhspan(-1.0, 1.0, color="0.85", zorder=0, label="±1″")
        ax_t.set_yscale("symlog", linthresh=1.0)
        ax_t.set_title(
            f"tracking {r.scenario.rate_arcsec_s:g}″/s in azimuth: rms "
            f"{m['tracking_rms_arcsec']:.3g}″ after {m['settle_s']:.3g} s",
            fontsize=9,
        )
        ax_t.set_xlabel("t, s")
        ax_t.set_ylabel("pointing error, ″ (symlog)")
        ax_t.legend(fontsize=8)
        for axis, tau in r.axis_torque.items():
            ax_q.plot(r.result.t, tau / 1e6, label=f"{axis}")
        ax_q.set_title("tracking: drive torque on the axes, MN·m", fontsize=9)
        ax_q.set_xlabel("t, s")
        ax_q.legend(fontsize=8)
    for ax in (ax_h, ax_s, ax_t, ax_q):
        ax.grid(True, alpha=0.3)
    return fig
