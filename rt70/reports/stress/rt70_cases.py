"""Stress families on RT-70 variants: stiffness, mass ratio, rigid modes.

The approach to gimbal lock is in :mod:`~rt70.reports.stress.gimbal_cases`. Each family
rewrites the RT-70's URDF (:mod:`rt70.reports.stress.edits`), measures every
variant (:mod:`~rt70.reports.stress.measures`), runs it capped
(:mod:`~rt70.reports.stress.runs`) and returns a :class:`~rt70.reports.stress.tables.Table`
with notes quoting its numbers.
"""

from __future__ import annotations

import numpy as np

from rt70.model.scene import Scene, scene_from_text
from rt70.reports.stress.edits import (
    rt70_text,
    scale_link_inertia,
    scale_springs,
    set_spring_entry,
)
from rt70.reports.stress.gimbal_cases import GIMBAL_BUSHING
from rt70.reports.stress.measures import (
    condition_number,
    cross_check_error,
    frequencies_hz,
    per_body_qdd_error,
)
from rt70.reports.stress.runs import SIM_RTOL, RunOutcome, Settings, run_capped
from rt70.reports.stress.tables import SIM_COLUMNS, Table, sim_fields, worst_value
from rt70.scenes.rt70_state import listing_initial_state


def rt70_case(text: str, name: str, settings: Settings) -> tuple[Scene, dict, RunOutcome]:
    """Scene, cond(A), f_max, cross-check and a capped run of an RT-70 variant.

    Parameters
    ----------
    text : str
        URDF text of the variant (the RT-70's, rewritten by
        :mod:`~rt70.reports.stress.edits`).
    name : str
        Name of the scene built from it.
    settings : Settings
        The report's sizes: cross-check samples, simulation span and cap.

    Returns
    -------
    tuple of (Scene, dict, RunOutcome)
        The scene; its row (``cond``, ``fmax`` Hz, ``xerr``, ``xq`` and the simulation's
        fields, :func:`~rt70.reports.stress.tables.sim_fields`); the capped run from the
        listing's initial state.
    """
    scene = scene_from_text(text, name)
    q0, v0 = listing_initial_state(scene)
    err, quantity, _ = cross_check_error(scene, settings.samples)
    freq = frequencies_hz(scene)
    run = run_capped(
        scene,
        (0.0, settings.span),
        (q0, v0),
        cap_s=settings.cap_s,
        max_evaluations=settings.max_evaluations,
    )
    row = {
        "cond": condition_number(scene, q0),
        "fmax": float(freq[-1]),
        "xerr": err,
        "xq": quantity,
        **sim_fields(run, settings.span),
    }
    return scene, row, run


def stiffness_cases(quick: bool = False) -> Table:
    """Every spring's stiffness × 10^k; damping × 0 and × 10^k."""
    settings = Settings.make(quick)
    table = Table(
        "Stiffness × 10^k, damping × 0 and × 10^k (RT-70)",
        "Every spring and strut of the RT-70 has its stiffness multiplied by 10^k and its "
        f"damping by 0 or by 10^k. f_max is the highest eigenfrequency of the undeformed "
        f"structure (springs only, q = 0). Simulation: {settings.span:g} s from the "
        f"listing's state, reference side, BDF, rtol {SIM_RTOL:g}, cap "
        f"{settings.max_evaluations} right-hand-side evaluations.",
        [
            ("k", "k"),
            ("damping", "damping"),
            ("fmax", "f_max Hz"),
            ("cond", "cond(A)"),
            ("xerr", "cross-check err"),
            ("xq", "worst quantity"),
            *SIM_COLUMNS,
        ],
    )
    base = rt70_text()
    for k in settings.stiffness_k:
        for label, d in (("× 0", 0.0), ("× 10^k", 10.0**k)):
            _, row, _ = rt70_case(scale_springs(base, 10.0**k, d), f"rt70_C1e{k}", settings)
            table.rows.append({"k": k, "damping": label, **row})
    damped = [r for r in table.rows if r["damping"] == "× 10^k"]
    undamped = [r for r in table.rows if r["damping"] == "× 0"]
    f0 = table.rows[0]["fmax"]
    table.notes.append(
        "f_max grows as 10^(k/2) (from "
        + ", ".join(f"{r['fmax']:.4g}" for r in damped)
        + f" Hz; ratio to k = 0: {damped[-1]['fmax'] / f0:.4g}); cond(A) does not depend "
        f"on the springs ({damped[0]['cond']:.3g} at the listing's state)."
    )
    table.notes.append(
        "The cross-check stays at rounding level at every k (worst "
        f"{worst_value(table.rows, 'xerr'):.2g}, relative to the largest entry of each quantity)."
    )
    over = [r for r in undamped if not r["sim"].startswith("ok")]
    finished = [r for r in undamped if r["sim"].startswith("ok")]
    text = (
        "Undamped, the error test makes BDF follow every oscillation of the stiffest "
        "modes (nothing damps them, so they cannot be stepped over)"
    )
    if finished:
        r0 = finished[0]
        per_period = r0["steps"] / (settings.span * r0["fmax"])
        text += (
            f": k = {r0['k']} takes {r0['steps']} steps, {per_period:.0f} per period of "
            f"f_max, and its energy balance drifts by {r0['drift']:.1g}, "
            f"{r0['drift'] / SIM_RTOL:.0f} × rtol (the integration error of the undamped "
            "oscillations accumulates)"
        )
        if over:
            worst = over[-1]
            needed = r0["steps"] * worst["fmax"] / r0["fmax"]
            text += (
                f"; k = {', '.join(str(r['k']) for r in over)} are over the cap (≈ "
                f"{over[0]['steps']} steps reached); k = {worst['k']} would need ≈ "
                f"{needed:.1g} steps"
            )
    elif over:
        text += f"; every run is over the cap (k = {', '.join(str(r['k']) for r in over)})"
    table.notes.append(text + ".")
    done = [r for r in damped if r["sim"].startswith("ok")]
    if done:
        table.notes.append(
            "Damped × 10^k: the stiff modes are overdamped and BDF steps over them; steps "
            + ", ".join(f"k={r['k']}: {r['steps']}" for r in done)
            + f"; worst energy drift {worst_value(done, 'drift'):.2g} (of the energy exchanged)."
        )
    return table


def mass_ratio_cases(quick: bool = False) -> Table:
    """The counterreflector's mass and inertia × 10^−k."""
    settings = Settings.make(quick)
    table = Table(
        "Mass ratio: counterreflector mass and inertia × 10^−k (RT-70)",
        "The counterreflector (2.3 t of a 1.57e6 kg structure) has its mass and inertia "
        "tensor multiplied by 10^−k. Same simulation as above.",
        [
            ("k", "k"),
            ("mass", "m_cr kg"),
            ("ratio", "m_cr / m_total"),
            ("fmax", "f_max Hz"),
            ("cond", "cond(A)"),
            ("xerr", "cross-check err"),
            ("xq", "worst quantity"),
            ("body", "q̈ err per body"),
            *SIM_COLUMNS,
        ],
    )
    base = rt70_text()
    for k in settings.mass_k:
        text = scale_link_inertia(base, "counterreflector", 10.0**-k)
        scene, row, _ = rt70_case(text, f"rt70_m1e-{k}", settings)
        model = scene.textbook
        m = float(model.mass[model.body_names.index("counterreflector")])
        row["body"] = per_body_qdd_error(scene, settings.samples)
        table.rows.append({"k": k, "mass": m, "ratio": m / float(model.mass.sum()), **row})
    first, last = table.rows[0], table.rows[-1]
    table.notes.append(
        f"cond(A) grows from {first['cond']:.3g} to {last['cond']:.3g} "
        f"(factor {last['cond'] / first['cond']:.3g} for a mass factor "
        f"{10.0 ** -last['k']:g}): the light body's rows and columns of A scale with its "
        "mass."
    )
    table.notes.append(
        f"f_max is another body's mode ({first['fmax']:.4g} Hz) until the "
        "counterreflector's own modes overtake it; from there it grows as 10^(k/2) "
        f"(→ {last['fmax']:.4g} Hz), and BDF needs only a few more steps "
        f"({first['steps']} → {last['steps']}): its damping grows relative to its mass, "
        "so the new fast modes are overdamped."
    )
    table.notes.append(
        "The cross-check does not degrade (worst "
        f"{worst_value(table.rows, 'xerr'):.2g}), even per body: 'q̈ err per body' is the "
        "largest error of each body's six accelerations relative to that body's own "
        f"largest |q̈| (worst {worst_value(table.rows, 'body'):.2g}). The ill-conditioning "
        "is a diagonal scaling (one body's rows × 10^−k), to which the Cholesky solve and "
        "ABA are insensitive: cond(A) overstates the error here."
    )
    return table


def rigid_mode_cases(quick: bool = False) -> Table:
    """Zero stiffness on a coordinate: rigid-body modes of the RT-70."""
    settings = Settings.make(quick)
    table = Table(
        "Zero stiffness on a coordinate (rigid-body modes, RT-70)",
        "The listing has two zero-stiffness coordinates already: the azimuth bearing "
        "(`ground_platform` rz = 0) and the elevation bearing (the platform–base struts' "
        "rx = 0). The variant also frees the counterreflector's spin (`"
        f"{GIMBAL_BUSHING}` rz stiffness and damping = 0). 'rigid modes': zero "
        "eigenvalues of the springs-only K at q = 0. Simulation as in the stiffness "
        "table.",
        [
            ("case", "case"),
            ("rigid", "rigid modes"),
            ("fmin", "lowest elastic Hz"),
            ("cond", "cond(A)"),
            ("xerr", "cross-check err"),
            ("spin", "counterreflector α(T) − α(0)"),
            *SIM_COLUMNS,
        ],
    )
    base = rt70_text()
    cases = [
        ("RT-70 as listed", base),
        ("+ counterreflector rz free", set_spring_entry(base, GIMBAL_BUSHING, 5, 0.0, 0.0)),
    ]
    for label, text in cases:
        scene, row, run = rt70_case(text, "rt70_rigid", settings)
        freq = frequencies_hz(scene)
        row.update(case=label, rigid=int(np.sum(freq == 0.0)), fmin=float(freq[freq > 0][0]))
        i = scene.textbook.coordinate_names.index("counterreflector_rz")
        if run.result is not None:
            row["spin"] = float(run.result.q[-1, i] - run.result.q[0, i])
        table.rows.append(row)
    table.notes.append(
        "Each zero stiffness adds one rigid-body mode ("
        + " → ".join(str(r["rigid"]) for r in table.rows)
        + "); A is unaffected and the integration is not harder: the freed coordinate is "
        "no longer pulled back (counterreflector α moves by "
        + " → ".join(f"{r['spin']:.2g}" for r in table.rows if "spin" in r)
        + " rad over the run)."
    )
    return table
